//! `cotui diagnose` against a peer: canopen-lens (PyPI 0.5.1, installed by
//! scripts/install-test-deps.sh) explains a candump log in plain words. On its own two
//! example logs (`canopen-lens examples` writes them), every incident it reports — node,
//! status and kind of problem — must be among cotui's incidents; where cotui says more, the
//! test names what and why.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh directory with canopen-lens's example logs.
fn examples() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cotui-diagnose-peer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new("canopen-lens")
        .arg("examples")
        .current_dir(&dir)
        .output()
        .unwrap_or_else(|e| panic!("canopen-lens is required (scripts/install-test-deps.sh installs it): {e}"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    dir
}

/// canopen-lens's incidents of `log` (its `-s result.json`).
fn lens(dir: &Path, log: &str) -> Vec<Value> {
    let json = dir.join(format!("{log}.json"));
    let out = Command::new("canopen-lens")
        .args([log, "-s", json.to_str().unwrap(), "--lang", "en", "--no-color"])
        .current_dir(dir)
        .output()
        .expect("run canopen-lens");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    v["incidents"].as_array().unwrap().clone()
}

/// cotui's incidents of `log`.
fn cotui(dir: &Path, log: &str) -> Vec<Value> {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["diagnose", "--format", "jsonl", log])
        .current_dir(dir)
        .output()
        .expect("run cotui");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The kind of problem a canopen-lens title names, in cotui's words (`kind`).
fn lens_kind(title: &str) -> &'static str {
    if title.starts_with("No answer") {
        "missing"
    } else if title.starts_with("Went silent and never came back") {
        "silent"
    } else if title.starts_with("Went silent for") {
        "silent_back"
    } else if title.starts_with("A setting was not applied") {
        "sdo_refused"
    } else if title.starts_with("Stopped") || title.starts_with("All axes stopped") {
        "drive_fault"
    } else if title.contains("CAN bus error") {
        "bus_errors"
    } else {
        panic!("a canopen-lens title this test does not know yet: {title:?}")
    }
}

/// (node, status, kind) of every canopen-lens incident has a cotui incident; returns the
/// cotui incidents left over (those canopen-lens does not report).
fn compare(dir: &Path, log: &str) -> (Vec<Value>, Vec<Value>) {
    let theirs = lens(dir, log);
    let mut ours = cotui(dir, log);
    assert!(!theirs.is_empty(), "{log}: canopen-lens reports nothing");
    let mut matched = Vec::new();
    for t in &theirs {
        let node = t["node"].as_u64().filter(|n| *n != 0);
        let kind = lens_kind(t["title"].as_str().unwrap());
        let status = t["status"].as_str().unwrap();
        let pos = ours
            .iter()
            .position(|o| o["node"].as_u64() == node && o["kind"] == kind && o["status"] == status)
            .unwrap_or_else(|| {
                panic!(
                    "{log}: canopen-lens reports node {node:?} {kind} {status} ({}), cotui does not: {ours:#?}",
                    t["title"]
                )
            });
        if kind == "drive_fault" {
            assert_eq!(ours[pos]["axes"], t["axes"], "{log}: axes of node {node:?}");
        }
        matched.push(ours.remove(pos));
    }
    (matched, ours)
}

#[test]
fn every_canopen_lens_incident_is_found_by_cotui() {
    let dir = examples();

    let (matched, extra) = compare(&dir, "sample_cia402.log");
    assert!(extra.is_empty(), "cotui reports more on sample_cia402.log: {extra:#?}");
    let by = |kind: &str, node: u64| {
        matched
            .iter()
            .find(|i| i["kind"] == kind && i["node"] == node)
            .unwrap_or_else(|| panic!("{kind} {node}"))
    };
    // Where cotui says more than canopen-lens, and why it is right:
    // - node 3's heartbeat stops, but its TPDO1 goes on to the end of the log: the node is
    //   alive, only its heartbeat stopped (canopen-lens: "went silent").
    let silent = by("silent", 3);
    assert_eq!(
        silent["title"],
        "Heartbeat stopped for good, while the node still sends other messages"
    );
    // - node 2's fault: the same reading (EMCY 0x2310, reset #1 failed, #2 worked), with the
    //   frame of each reset in the timeline.
    let fault = by("drive_fault", 2);
    assert_eq!(
        fault["title"],
        "Stopped: continuous over-current → recovered on reset #2 (1 failed reset)"
    );
    // - the bus: two error frames in the log (4.10 s and 5.98 s), canopen-lens counts one.
    let bus = matched.iter().find(|i| i["kind"] == "bus_errors").unwrap();
    assert_eq!(bus["count"], 2);

    let (matched, extra) = compare(&dir, "sample_amr_2wheel.log");
    assert!(
        extra.is_empty(),
        "cotui reports more on sample_amr_2wheel.log: {extra:#?}"
    );
    // Both axes of node 1 fault 0.5 ms apart with no EMCY: one incident, the E-stop/STO
    // check first; cotui also lists the fault reset that cleared it.
    let texts: Vec<&str> = matched[0]["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["text"].as_str().unwrap())
        .collect();
    assert!(texts.contains(&"Fault reset #1 sent (controlword bit 7)"), "{texts:?}");
    assert!(matched[0]["check"][0].as_str().unwrap().contains("STO"));
    let _ = std::fs::remove_dir_all(&dir);
}
