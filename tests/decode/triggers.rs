//! `cotui decode --trigger`: each window file holds exactly the source frames inside its
//! window, overlapping windows are merged, the sidecar tells the trigger, the hits and the
//! window's diagnosis; a trigger that does not parse says its column.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn cotui(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run cotui")
}

/// A candump -l log: a PDO every 10 ms for 8 s from t = 100 s, node 5's EMCY at `emcys` (ms
/// after the start), each line with its time in ms.
fn log(emcys: &[u64]) -> Vec<(u64, String)> {
    let mut lines = Vec::new();
    for ms in (0..8000u64).step_by(10) {
        let t = 100_000 + ms;
        lines.push((
            t,
            format!("({:010}.{:03}000) can0 185#{:02X}00", t / 1000, t % 1000, ms % 256),
        ));
        if emcys.contains(&ms) {
            lines.push((
                t,
                format!("({:010}.{:03}000) can0 085#1081110000000000", t / 1000, t % 1000),
            ));
        }
    }
    lines
}

/// A fresh scratch directory of this test.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cotui-trigger-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn windows(dir: &Path) -> Vec<(Value, Vec<String>)> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    names.sort();
    names
        .iter()
        .map(|p| {
            let side: Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
            let file = dir.join(side["file"].as_str().unwrap());
            let lines = std::fs::read_to_string(file)
                .unwrap()
                .lines()
                .map(String::from)
                .collect();
            (side, lines)
        })
        .collect()
}

#[test]
fn each_window_holds_exactly_the_source_frames_inside_it_and_overlaps_merge() {
    let dir = scratch("merge");
    // --pre 1s --post 500ms: EMCY at 1.0 s opens [0.0, 1.5]; 1.3 s is inside (to 1.8); 2.7 s
    // reaches back to 1.7 (merged, to 3.2); 5.0 s is a window of its own, [4.0, 5.5].
    let src = log(&[1000, 1300, 2700, 5000]);
    let path = dir.join("in.log");
    std::fs::write(&path, src.iter().map(|(_, l)| format!("{l}\n")).collect::<String>()).unwrap();
    let out_dir = dir.join("out");
    let out = cotui(&[
        "decode",
        "--trigger",
        "emcy",
        "--pre",
        "1s",
        "--post",
        "500ms",
        "-o",
        out_dir.to_str().unwrap(),
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let got = windows(&out_dir);
    let want = [(101_000 - 1000, 103_200, 3), (105_000 - 1000, 105_500, 1)];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for ((side, lines), (from, to, hits)) in got.iter().zip(want) {
        assert_eq!(side["start"].as_f64().unwrap(), from as f64 / 1000.0);
        assert_eq!(side["end"].as_f64().unwrap(), to as f64 / 1000.0);
        assert_eq!(side["hits"].as_array().unwrap().len(), hits);
        assert_eq!(side["trigger"], "emcy");
        assert_eq!(side["format"], "candump");
        let inside: Vec<String> = src
            .iter()
            .filter(|(t, _)| (from..=to).contains(t))
            .map(|(_, l)| l.clone())
            .collect();
        assert_eq!(lines, &inside, "window {from}..{to}");
        assert_eq!(side["frames"].as_u64().unwrap(), inside.len() as u64);
        assert_eq!(side["diagnosis"][0]["kind"], "emcy", "{side}");
    }
    // Named by the trigger's time and kind.
    assert_eq!(got[0].0["file"], "19700101T000141.000Z-emcy.log");
}

#[test]
fn jsonl_without_a_directory_gives_a_line_per_window_and_a_bad_trigger_its_column() {
    let dir = scratch("jsonl");
    let path = dir.join("in.log");
    let src = log(&[2000, 6000]);
    std::fs::write(&path, src.iter().map(|(_, l)| format!("{l}\n")).collect::<String>()).unwrap();
    let p = path.to_str().unwrap();
    let out = cotui(&[
        "decode",
        "--trigger",
        "node 5 and emcy",
        "--pre",
        "200ms",
        "--post",
        "0.1s",
        "--format",
        "jsonl",
        p,
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(
        (lines[0]["start"].as_f64(), lines[0]["end"].as_f64()),
        (Some(101.8), Some(102.1))
    );
    // 20 PDOs before, the EMCY, its PDO, 10 after.
    assert_eq!(lines[0]["frames"], 32);
    assert_eq!(lines[1]["hits"][0]["what"], "node 5 and emcy");
    let out = cotui(&[
        "decode",
        "--trigger",
        "emcy then node 5 bogus within 2s",
        "--format",
        "jsonl",
        p,
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("column 18: unknown word `bogus`"), "{err}");
    // `A then B within`: B counts only within its time after A.
    let out = cotui(&[
        "decode",
        "--trigger",
        "emcy then id 185 within 30ms",
        "--pre",
        "0",
        "--post",
        "0",
        "--format",
        "jsonl",
        p,
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert_eq!(lines[0]["hits"][0]["what"], "emcy then id 185");
    assert_eq!(lines[0]["hits"][0]["t"], 102.01);
}
