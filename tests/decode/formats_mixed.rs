//! Several logs of different formats in one run: one capture split round-robin into a
//! candump log, a BLF, a TRC 2.1 and an ASC file (the last three written by cotui's own
//! writers) decodes, diagnoses and lists transactions exactly as the whole capture does:
//! frames are merged by time across the files whatever their format.
//!
//! The capture's times count from its start (as ASC's do: cotui reads ASC times as seconds
//! since the measurement's start), and the ASC part holds the first frame.

use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("formats_mixed");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn cotui(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui")).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The fixture with its times counted from its first frame, and its four parts.
fn split() -> (String, [String; 4]) {
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/cia301_mix.log")).unwrap();
    let lines: Vec<(u64, &str)> = src
        .lines()
        .map(|l| {
            let (ts, rest) = l.strip_prefix('(').unwrap().split_once(") ").unwrap();
            let (s, us) = ts.split_once('.').unwrap();
            (s.parse::<u64>().unwrap() * 1_000_000 + us.parse::<u64>().unwrap(), rest)
        })
        .collect();
    let first = lines[0].0;
    let mut parts: [String; 4] = Default::default();
    let mut whole = String::new();
    for (i, (us, rest)) in lines.iter().enumerate() {
        let t = us - first;
        let line = format!("({}.{:06}) {rest}\n", t / 1_000_000, t % 1_000_000);
        whole.push_str(&line);
        // The ASC part (3) takes the first frame: its times count from it.
        parts[(i + 3) % 4].push_str(&line);
    }
    let whole_path = tmp("whole.log");
    std::fs::write(&whole_path, &whole).unwrap();
    let mut paths: [String; 4] = Default::default();
    for (i, (part, format)) in parts.iter().zip(["candump", "blf", "trc", "asc"]).enumerate() {
        let log = tmp(&format!("part{i}.log"));
        std::fs::write(&log, part).unwrap();
        let out = tmp(&format!("part{i}.{format}"));
        if format == "candump" {
            std::fs::copy(&log, &out).unwrap();
        } else {
            cotui(&[
                "decode",
                "--format",
                format,
                "-o",
                out.to_str().unwrap(),
                log.to_str().unwrap(),
            ]);
        }
        paths[i] = out.display().to_string();
    }
    (whole_path.display().to_string(), paths)
}

#[test]
fn a_candump_blf_trc_and_asc_file_read_together_are_the_whole_capture() {
    let (whole, parts) = split();
    let parts: Vec<&str> = parts.iter().map(String::as_str).collect();
    let run = |args: &[&str], files: &[&str]| cotui(&[args, files].concat());
    // Frames: the same, in the same order (line numbers are each file's own: left out;
    // TRC's `$STARTTIME` holds days to 12 decimals: its times agree within 1 µs).
    let frames = |out: String| -> Vec<(f64, String)> {
        out.lines()
            .map(|l| {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                let o = v.as_object_mut().unwrap();
                o.remove("line");
                let t = o.remove("t").unwrap().as_f64().unwrap();
                (t, v.to_string())
            })
            .collect()
    };
    let want = frames(run(&["decode", "--format", "jsonl"], &[&whole]));
    let got = frames(run(&["decode", "--format", "jsonl"], &parts));
    assert_eq!(want.len(), 54);
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!((g.0 - w.0).abs() < 1e-6 && g.1 == w.1, "{g:?} vs {w:?}");
    }
    // Transfers span the files: an SDO request in one, its response in another.
    let want = run(&["decode", "--transactions"], &[&whole]);
    assert!(want.contains("Upload 0x1008:00"), "{want}");
    assert_eq!(run(&["decode", "--transactions"], &parts), want);
    // The diagnosis: the same incidents (their evidence names lines of each file: left out).
    let incidents = |out: String| -> Vec<(String, String)> {
        out.lines()
            .map(|l| {
                let v: serde_json::Value = serde_json::from_str(l).unwrap();
                (v["kind"].to_string(), v["title"].to_string())
            })
            .collect()
    };
    let want = incidents(run(&["diagnose", "--format", "jsonl"], &[&whole]));
    assert!(want.len() >= 3, "{want:?}");
    assert_eq!(incidents(run(&["diagnose", "--format", "jsonl"], &parts)), want);
}
