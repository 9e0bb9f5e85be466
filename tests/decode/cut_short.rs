//! A segmented transfer cut short says how much of the size its initiate announced came:
//! `7 of 64 bytes` in the text of `decode --transactions`, `size_announced` beside `len`
//! in its JSON (left out on transfers that are not cut short).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn transactions(log: &Path, format: &str) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--transactions", "--format", format])
        .arg(log)
        .output()
        .expect("run cotui");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("UTF-8")
}

/// A download to node 3 announcing 64 bytes that ends (with the capture) after one
/// 7-byte segment, then a complete expedited read.
fn capture() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cotui-cut-short-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cut.log");
    let log = "\
(1700000000.000000) can0 602#4018100100000000
(1700000000.001000) can0 582#4318100178563412
(1700000000.010000) can0 603#2101700140000000
(1700000000.011000) can0 583#6001700100000000
(1700000000.012000) can0 603#0000800000C0C000
(1700000000.013000) can0 583#2000000000000000
";
    std::fs::write(&path, log).unwrap();
    path
}

#[test]
fn a_download_the_capture_cut_short_says_7_of_64_bytes() {
    let path = capture();
    let text = transactions(&path, "text");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert!(lines[0].contains("(expedited, 4 bytes, 1.000 ms): ok"), "{text}");
    assert!(
        lines[1].starts_with("Download 0x7001:01 (segmented, 7 of 64 bytes, 3.000 ms): incomplete"),
        "{text}"
    );
    let json: Vec<Value> = transactions(&path, "jsonl")
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(json[1]["len"], 7);
    assert_eq!(json[1]["size"], 64);
    assert_eq!(json[1]["size_announced"], 64);
    // A transfer that got all it announced has no such field.
    assert_eq!(json[0]["size"], 4);
    assert!(json[0].get("size_announced").is_none(), "{}", json[0]);
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}

#[test]
fn the_canopennode_flood_download_says_7_of_64_bytes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let Some(log) = [
        root.join("../shared/realworld/logs"),
        root.join("../../shared/realworld/logs"),
    ]
    .into_iter()
    .map(|d| d.join("canopennode_issue486_flood.txt"))
    .find(|p| p.is_file()) else {
        println!("note: ../shared/realworld/logs not found; skipped");
        return;
    };
    let text = transactions(&log, "text");
    assert!(
        text.starts_with("Download 0x7000:01 (segmented, 7 of 64 bytes, 0.000 ms): protocol error"),
        "{text}"
    );
    let v: Value = serde_json::from_str(transactions(&log, "jsonl").lines().next().unwrap()).unwrap();
    assert_eq!(
        (v["len"].as_u64(), v["size_announced"].as_u64()),
        (Some(7), Some(64)),
        "{v}"
    );
}
