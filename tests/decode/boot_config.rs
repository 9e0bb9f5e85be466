//! Boot stories and `boot_config` incidents: `cotui diagnose` (and `--boots`, `--expect`,
//! `--check`) over hand-written boots of node 5 (tests/fixtures/boot/) and over real
//! ros2_canopen master boots in ../shared/realworld/logs/.

use super::run::cotui;
use serde_json::{Value, json};

const AGREE: &str = "tests/fixtures/boot/boots_agree.log";
const DIFFER: &str = "tests/fixtures/boot/boots_differ.log";
const DCF: &str = "tests/fixtures/boot/node5.dcf";

/// The JSON lines of `cotui diagnose --format jsonl ARGS`, with the exit status.
fn jsonl(args: &[&str]) -> (Vec<Value>, i32) {
    let mut all = vec!["diagnose", "--format", "jsonl"];
    all.extend_from_slice(args);
    let out = cotui(&all, None);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    (lines, out.status.code().unwrap_or(-1))
}

/// The `boot_config` incidents among `incidents`.
fn boot_config(incidents: &[Value]) -> Vec<&Value> {
    incidents.iter().filter(|i| i["kind"] == "boot_config").collect()
}

#[test]
fn two_boots_that_agree_give_no_finding_and_check_passes() {
    let (incidents, code) = jsonl(&["--check", AGREE]);
    assert_eq!(code, 0, "{incidents:?}");
    assert!(boot_config(&incidents).is_empty(), "{incidents:?}");
    let (boots, _) = jsonl(&["--boots", AGREE]);
    let brief: Vec<(u64, u64, Value, usize, usize)> = boots
        .iter()
        .map(|b| {
            let writes = b["steps"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|s| s["kind"] == "write")
                .count();
            (
                b["node"].as_u64().unwrap(),
                b["boot"].as_u64().unwrap(),
                b["reference"].clone(),
                writes,
                b["findings"].as_array().unwrap().len(),
            )
        })
        .collect();
    assert_eq!(brief, [(5, 1, Value::Null, 4, 0), (5, 2, json!(1), 4, 0)]);
    assert_eq!(boots[1]["operational_by"], "heartbeat");
    let text = String::from_utf8(cotui(&["diagnose", "--boots", AGREE], None).stdout).unwrap();
    assert!(text.starts_with("2 boots of 1 node, 0 with findings.\n"), "{text}");
    assert!(
        text.contains("Node 5, boot 2 at 1.000 s, operational at 1.200 s (heartbeat)\n      1.000 s  #13      NMT reset node\n      1.100 s  #14      boot-up\n      1.110 s  #15      write 0x1017:00 = 0x0064\n"),
        "{text}"
    );
    assert!(text.ends_with("  Agrees with boot 1.\n"), "{text}");
}

#[test]
fn a_second_boot_that_differs_has_one_finding_of_each_kind_and_check_fails() {
    let (incidents, code) = jsonl(&["--check", DIFFER]);
    assert_eq!(code, 1, "--check: a boot differs");
    let found = boot_config(&incidents);
    assert_eq!(found.len(), 1, "{incidents:?}");
    let inc = found[0];
    assert_eq!(inc["node"], 5);
    assert_eq!(inc["status"], "open");
    assert_eq!(
        inc["title"],
        "Boot 2 configured otherwise than boot 1 (1 different, 1 missing, 1 extra, 1 refused, 1 unanswered)"
    );
    assert_eq!(
        inc["findings"],
        json!([
            {"against": "reference", "frame": 15, "index": "0x1017", "kind": "different", "reference": "0x0064",
             "reference_boot": 1, "subindex": 0, "t": 1.11, "value": "0x00C8"},
            {"abort": "Invalid value for parameter (download only)", "against": "reference", "frame": 19,
             "index": "0x1400", "kind": "refused", "reference": "0xFE", "reference_boot": 1, "subindex": 2,
             "t": 1.13, "value": "0xFE"},
            {"against": "reference", "frame": null, "index": "0x1800", "kind": "missing", "reference": "0x01",
             "reference_boot": 1, "subindex": 2, "t": null, "value": null},
            {"against": "reference", "frame": 21, "index": "0x2000", "kind": "unanswered", "reference": "0x00000007",
             "reference_boot": 1, "subindex": 1, "t": 1.14, "value": "0x00000007"},
            {"against": "reference", "frame": 17, "index": "0x2001", "kind": "extra", "reference_boot": 1,
             "subindex": 0, "t": 1.12, "value": "0x01"},
        ])
    );
    // The findings are the incident's steps, in frame order (the Problems pane shows them).
    let steps: Vec<&str> = inc["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["text"].as_str().unwrap())
        .collect();
    assert_eq!(
        steps,
        [
            "Boot 2 began",
            "0x1017:00 written 0x00C8, boot 1 wrote 0x0064",
            "0x2001:00 written 0x01, boot 1 did not write it",
            "0x1400:02 write of 0xFE refused: Invalid value for parameter (download only)",
            "0x2000:01 write of 0x00000007 not answered",
            "0x1800:02 not written, boot 1 wrote 0x01",
        ]
    );
    let text = String::from_utf8(cotui(&["diagnose", DIFFER], None).stdout).unwrap();
    assert!(
        text.contains("OPEN       Node 5: Boot 2 configured otherwise than boot 1 (1 different,"),
        "{text}"
    );
}

#[test]
fn a_boot_cut_short_by_the_end_of_the_capture_has_no_missing_writes() {
    // Boot 2 writes 0x1017, then 0x1800:02 gets no answer before the capture ends; the
    // reference's 0x1400:02 and 0x2000:01 are not "missing" (the boot did not finish).
    let (incidents, code) = jsonl(&["--check", "tests/fixtures/boot/boot_cut.log"]);
    assert_eq!(code, 1);
    let found = boot_config(&incidents);
    assert_eq!(found.len(), 1, "{incidents:?}");
    assert_eq!(
        found[0]["findings"],
        json!([{"against": "reference", "frame": 17, "index": "0x1800", "kind": "unanswered", "reference": "0x01",
                "reference_boot": 1, "subindex": 2, "t": 1.12, "value": "0x01"}])
    );
    let text =
        String::from_utf8(cotui(&["diagnose", "--boots", "tests/fixtures/boot/boot_cut.log"], None).stdout).unwrap();
    assert!(
        text.contains("Node 5, boot 2 at 1.000 s, did not reach operational\n"),
        "{text}"
    );
    assert!(
        text.contains("      1.120 s  #17      write 0x1800:02 = 0x01  not answered\n"),
        "{text}"
    );
}

#[test]
fn across_the_files_of_one_run_the_first_files_boot_is_the_reference() {
    // boots_differ.log cut in two: the first file holds boot 1, the second boot 2.
    let (incidents, code) = jsonl(&[
        "--check",
        "tests/fixtures/boot/run_part1.log",
        "tests/fixtures/boot/run_part2.log",
    ]);
    assert_eq!(code, 1);
    let found = boot_config(&incidents);
    assert_eq!(found.len(), 1, "{incidents:?}");
    assert_eq!(
        found[0]["title"],
        "Boot 2 configured otherwise than boot 1 (1 different, 1 missing, 1 extra, 1 refused, 1 unanswered)"
    );
}

#[test]
fn expect_compares_every_boot_with_the_dcf() {
    // Both boots write what the DCF says except 0x2002 (not its default); 0x2000:01 is at
    // its default and is written with it; 0x1018:01 is read-only.
    let (incidents, code) = jsonl(&["--check", "--expect", &format!("5={DCF}"), AGREE]);
    assert_eq!(code, 1);
    let found = boot_config(&incidents);
    let titles: Vec<&str> = found.iter().map(|i| i["title"].as_str().unwrap()).collect();
    assert_eq!(
        titles,
        [
            "Boot 1 configured otherwise than the DCF (1 missing)",
            "Boot 2 configured otherwise than the DCF (1 missing)",
        ]
    );
    assert_eq!(
        found[0]["findings"],
        json!([{"against": "expected", "expected": "0x0005", "frame": null, "index": "0x2002", "kind": "missing",
                "subindex": 0, "t": null, "value": null}])
    );
    let (incidents, _) = jsonl(&["--expect", &format!("5={DCF}"), DIFFER]);
    let found = boot_config(&incidents);
    let second = found
        .iter()
        .find(|i| i["title"].as_str().unwrap().starts_with("Boot 2"))
        .unwrap();
    let dcf: Vec<(String, String, Value, Value)> = second["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["against"] == "expected")
        .map(|f| {
            (
                f["kind"].as_str().unwrap().to_string(),
                format!("{}:{}", f["index"].as_str().unwrap(), f["subindex"]),
                f["value"].clone(),
                f["expected"].clone(),
            )
        })
        .collect();
    let row = |k: &str, o: &str, v: Value, e: Value| (k.to_string(), o.to_string(), v, e);
    assert_eq!(
        dcf,
        [
            row("different", "0x1017:0", json!("0x00C8"), json!("0x0064")),
            row("refused", "0x1400:2", json!("0xFE"), json!("0xFE")),
            row("missing", "0x1800:2", Value::Null, json!("0x01")),
            row("unanswered", "0x2000:1", json!("0x00000007"), json!("0x00000007")),
            row("extra", "0x2001:0", json!("0x01"), Value::Null),
            row("missing", "0x2002:0", Value::Null, json!("0x0005")),
        ]
    );
}

#[test]
fn a_dcf_whose_type_disagrees_with_the_dictionary_names_the_object_and_line() {
    let out = cotui(
        &["diagnose", "--expect", "5=tests/fixtures/boot/bad_type.dcf", AGREE],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(
        err,
        "cotui diagnose: tests/fixtures/boot/bad_type.dcf:7: 0x1017:00 Producer heartbeat time: DataType U32 in the DCF, U16 in the node's EDS/dictionary\n"
    );
}

#[test]
fn the_tui_refuses_an_expect_dcf_that_disagrees_with_the_dictionary_before_it_starts() {
    // `open --expect` reads the DCF as `diagnose --expect` does, and says why before any
    // terminal is taken.
    let out = cotui(&["open", "--expect", "5=tests/fixtures/boot/bad_type.dcf", AGREE], None);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        "cotui: --expect: tests/fixtures/boot/bad_type.dcf:7: 0x1017:00 Producer heartbeat time: DataType U32 in the DCF, U16 in the node's EDS/dictionary\n"
    );
}

/// (node, boot, operational_by, writes, NMT commands, findings) of each boot of `--boots`.
fn stories(path: &str) -> Vec<(u64, u64, Value, usize, usize, usize)> {
    let (boots, code) = jsonl(&["--boots", path]);
    assert_eq!(code, 0, "{path}");
    boots
        .iter()
        .map(|b| {
            let count = |k: &str| b["steps"].as_array().unwrap().iter().filter(|s| s["kind"] == k).count();
            (
                b["node"].as_u64().unwrap(),
                b["boot"].as_u64().unwrap(),
                b["operational_by"].clone(),
                count("write"),
                count("nmt"),
                b["findings"].as_array().unwrap().len(),
            )
        })
        .collect()
}

#[test]
fn real_ros2_canopen_master_boots_decode_into_stories() {
    // Issue 225: node 1 boots up, the master resets communication of all nodes (000#8200),
    // nodes 4, 3, 2 boot up; the master only reads 0x1000/0x1018 (no writes) and sends
    // SYNC; no heartbeat or TPDO shows Operational, so no boot is complete (no reference).
    let null = Value::Null;
    assert_eq!(
        stories("../shared/realworld/logs/ros2_canopen_issue225_boot.log"),
        [
            (1, 1, null.clone(), 0, 0, 0),
            (1, 2, null.clone(), 0, 1, 0),
            (2, 1, null.clone(), 0, 1, 0),
            (3, 1, null.clone(), 0, 1, 0),
            (4, 1, null.clone(), 0, 1, 0),
        ]
    );
    // Issue 46: the same reset, node 2 boots up (frame 33) and sends TPDO 0x182: its boot
    // is complete; the master's reads of 0x1000 are no configuration writes.
    let path = "../shared/realworld/logs/ros2_canopen_issue46_boot.txt";
    assert_eq!(
        stories(path),
        [
            (1, 1, null.clone(), 0, 0, 0),
            (1, 2, null.clone(), 0, 1, 0),
            (2, 1, json!("TPDO"), 0, 1, 0),
        ]
    );
    let (incidents, _) = jsonl(&[path]);
    assert!(boot_config(&incidents).is_empty(), "{incidents:?}");
}
