//! `cotui record demo demo2 -o FILE`: one recording of two independent simulated buses.
//! Every format keeps each frame's bus (candump names, pcapng interfaces as tshark reads
//! them, ASC/TRC/BLF channels 1 and 2 read back by `cotui decode`), holds the frames asked
//! for and lists them by receive time.

use serde_json::Value;
use std::process::Command;

const FRAMES: usize = 40;

fn cotui(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cotui")).args(args).output().unwrap()
}

/// Records `FRAMES` frames of demo and demo2 as `format` into a fresh file; its path.
fn record(format: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cotui-rec-buses-{}-{format}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("two.{format}"));
    let n = FRAMES.to_string();
    let p = path.to_str().unwrap();
    let out = cotui(&[
        "record", "demo", "demo2", "-o", p, "--count", &n, "--format", format, "--force", "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["frames"], FRAMES as u64, "{report}");
    path
}

/// (interface, time) of every frame of `path` as `cotui decode --format jsonl` reads it.
fn decoded(path: &std::path::Path) -> Vec<(String, f64)> {
    let out = cotui(&["decode", path.to_str().unwrap(), "--format", "jsonl"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).unwrap();
            (v["iface"].as_str().unwrap().to_string(), v["t"].as_f64().unwrap())
        })
        .collect()
}

/// Both buses' frames, `FRAMES` in all, by time.
fn assert_two_buses_by_time(frames: &[(String, f64)], names: [&str; 2], what: &str) {
    assert_eq!(frames.len(), FRAMES, "{what}: {frames:?}");
    for name in names {
        assert!(
            frames.iter().any(|(i, _)| i == name),
            "{what}: no frame of {name}: {frames:?}"
        );
    }
    assert!(
        frames.iter().all(|(i, _)| names.contains(&i.as_str())),
        "{what}: {frames:?}"
    );
    assert!(
        frames.windows(2).all(|w| w[0].1 <= w[1].1),
        "{what}: not by time: {frames:?}"
    );
}

#[test]
fn candump_lines_keep_each_frames_interface_in_time_order() {
    let path = record("candump");
    let text = std::fs::read_to_string(&path).unwrap();
    // Padded as `candump -l demo demo2` pads: `(t)  demo 080#`.
    assert!(text.lines().any(|l| l.contains(")  demo ")), "{text}");
    assert!(text.lines().any(|l| l.contains(") demo2 ")), "{text}");
    assert_two_buses_by_time(&decoded(&path), ["demo", "demo2"], "candump");
    std::fs::remove_dir_all(path.parent().unwrap()).ok();
}

#[test]
fn asc_trc_and_blf_put_the_buses_on_channels_1_and_2() {
    for format in ["asc", "trc", "blf"] {
        let path = record(format);
        // The readers name channel N `can(N-1)`.
        assert_two_buses_by_time(&decoded(&path), ["can0", "can1"], format);
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }
}

#[test]
fn pcapng_has_one_interface_per_bus_as_tshark_reads_it() {
    let path = record("pcapng");
    let out = Command::new("tshark")
        .args(["-r", path.to_str().unwrap(), "-T", "fields"])
        .args(["-e", "frame.interface_name", "-e", "frame.time_epoch"])
        .output()
        .expect("tshark (scripts/install-test-deps.sh installs it)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let frames: Vec<(String, f64)> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| {
            let (name, t) = l.split_once('\t').unwrap();
            (name.to_string(), t.parse().unwrap())
        })
        .collect();
    assert_two_buses_by_time(&frames, ["demo", "demo2"], "pcapng (tshark)");
    std::fs::remove_dir_all(path.parent().unwrap()).ok();
}

#[test]
fn an_interface_named_twice_is_refused() {
    let out = cotui(&["record", "demo", "demo", "-o", "-", "--count", "1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("demo is given twice"));
}
