//! Golden tests of `cotui decode`: the real binary over fixture logs, compared with
//! reviewed output in insta snapshots (tests/decode/snapshots/). After an intended
//! change: `cargo insta test --test decode --review` (or `INSTA_UPDATE=always cargo test
//! --test decode` and review the diff).

use crate::run::cotui;
use std::process::Command;

fn check(fixture: &str, mode: &str, args: &[&str]) {
    let log = format!("tests/fixtures/{fixture}.log");
    let mut all = vec!["decode"];
    all.extend_from_slice(args);
    all.push(&log);
    let out = cotui(&all, None);
    assert!(
        out.status.success(),
        "cotui {all:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got = String::from_utf8(out.stdout).expect("UTF-8 output");
    assert!(got.is_empty() || got.ends_with('\n'), "output ends without a newline");
    insta::assert_snapshot!(format!("{fixture}_{}", mode.replace('.', "_")), got);
}

#[test]
fn cia301_mix_all_modes() {
    check("cia301_mix", "txt", &[]);
    check("cia301_mix", "jsonl", &["--format", "jsonl"]);
    check("cia301_mix", "transactions", &["--transactions"]);
    check("cia301_mix", "summary", &["--summary"]);
}

#[test]
fn pdo_mapping_learned_from_sdo_traffic() {
    check("pdo_learning", "txt", &[]);
    check("pdo_learning", "jsonl", &["--format", "jsonl"]);
    check("pdo_learning", "transactions", &["--transactions", "--format", "jsonl"]);
}

#[test]
fn sniffed_mapping_keeps_its_source_in_jsonl() {
    let out = cotui(
        &["decode", "--format", "jsonl", "tests/fixtures/pdo_learning.log"],
        None,
    );
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // Before the remapping the TPDO is raw; afterwards it arrives on the moved COB-ID 0x1C2.
    assert_eq!(lines[0]["pdo"]["signals"], serde_json::json!([]));
    let moved = lines.iter().find(|l| l["id"] == 0x1C2).expect("frame on 0x1C2");
    assert_eq!(moved["kind"], "tpdo");
    assert_eq!(moved["node"], 2);
    assert_eq!(moved["pdo"]["num"], 1);
    assert_eq!(moved["pdo"]["signals"][0]["name"], "Statusword");
    assert_eq!(moved["pdo"]["signals"][0]["value"], 0x0237);
    assert_eq!(moved["pdo"]["signals"][1]["index"], 0x606C);
    assert_eq!(moved["pdo"]["signals"][1]["value"], 15000);
    assert!(
        moved["pdo"]["mapping_source"]
            .as_str()
            .unwrap()
            .starts_with("sniffed @ 1700000100.0")
    );
}

#[test]
fn bad_lines_warn_with_line_numbers_and_the_rest_decodes() {
    let log = "(1.000000) can0 705#05\n(2.000000) can0 7G5#05\n# comment\n(3.000000) can0 000#0102\n";
    let out = cotui(&["decode", "-"], Some(log));
    assert_eq!(out.status.code(), Some(0));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stdout.lines().count(), 2, "{stdout}");
    assert!(stdout.contains("Heartbeat node 5: Operational"));
    assert!(stdout.contains("NMT Start remote node -> node 2"));
    assert!(stderr.contains("-:2: warning:"), "{stderr}");
}

#[test]
fn unreadable_input_exits_2() {
    let out = cotui(&["decode", "tests/fixtures/does-not-exist.log"], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("does-not-exist.log"));
}

#[test]
fn profile_binding_errors_are_usage_errors() {
    let out = cotui(
        &[
            "decode",
            "--profile",
            "2=no-such-profile",
            "tests/fixtures/cia301_mix.log",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-profile"));
}

#[test]
fn a_reader_that_stops_early_ends_cotui_quietly() {
    use std::io::{BufRead, BufReader, Write};
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn cotui");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        for i in 0..200_000u32 {
            if writeln!(stdin, "({}.000000) can0 705#05", i + 1).is_err() {
                break;
            }
        }
    });
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.contains("Heartbeat node 5: Operational"), "{first}");
    // The pipe is closed here, like `cotui decode big.log | head -1`.
    let out = child.wait_with_output().expect("wait");
    writer.join().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn events_of_nodes_that_die_reboot_and_come_back() {
    check("node_liveness", "events", &["--events"]);
    check("node_liveness", "events.jsonl", &["--events", "--format", "jsonl"]);
    check("heartbeat_stops", "events", &["--events"]);
    check(
        "heartbeat_stops",
        "eds.events",
        &["--events", "--eds", "7=tests/fixtures/eds/minimal.eds"],
    );
}

#[test]
fn a_lost_event_is_dated_one_and_a_half_periods_after_the_last_heartbeat() {
    let out = cotui(
        &[
            "decode",
            "--events",
            "--format",
            "jsonl",
            "tests/fixtures/node_liveness.log",
        ],
        None,
    );
    let events: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let of = |node: u64, event: &str| -> Vec<&serde_json::Value> {
        events
            .iter()
            .filter(|e| e["node"] == node && e["event"] == event)
            .collect()
    };
    // 0x1017 = 300 ms written by SDO at .551; the last heartbeat is at 101.401.
    let lost = of(5, "heartbeat_lost");
    assert_eq!(lost.len(), 2, "{events:?}");
    assert_eq!(lost[0]["period_ms"], 300.0);
    assert_eq!(lost[0]["period_source"], "sdo");
    assert_eq!(lost[0]["silent_ms"], 450.0);
    assert!((lost[0]["t"].as_f64().unwrap() - 1700000101.851).abs() < 1e-6);
    // The reboot forgets the SDO value: after it the period is measured (100 ms).
    let boot = of(5, "boot_up");
    assert_eq!(boot[1]["rebooted"], true);
    assert_eq!(boot[1]["was_lost"], true);
    assert_eq!(lost[1]["period_source"], "measured");
    assert_eq!(lost[1]["period_ms"], 100.0);
    assert_eq!(of(5, "heartbeat_back")[0]["silent_ms"], 1000.0);
    let guard = of(2, "heartbeat_lost");
    assert_eq!(guard[0]["guarding"], true);
    assert_eq!(of(3, "emcy")[0]["code"], 0x2310);
    assert_eq!(of(3, "sdo_abort")[0]["code"], 0x0602_0000);
    let bus: Vec<&str> = events
        .iter()
        .filter(|e| e["event"] == "bus_state")
        .map(|e| e["to"].as_str().unwrap())
        .collect();
    assert_eq!(bus, ["error_warning", "bus_off", "error_active"]);
    assert!(
        events
            .iter()
            .filter(|e| e["event"] == "bus_state")
            .all(|e| e["node"].is_null())
    );
}

#[test]
fn identity_objects_and_cob_ids_decode_in_hex_with_the_device_profile() {
    // Reads of 0x1000, 0x1018:01, 0x1018:02 from node 2 and 0x1000 from node 1, a TPDO
    // COB-ID written, and a CiA 402 device type without a drive type.
    let log = "(1.000000) can0 602#4000100000000000\n\
               (1.000500) can0 582#4300100092010200\n\
               (1.001000) can0 602#4018100100000000\n\
               (1.001500) can0 582#4318100100030000\n\
               (1.002000) can0 602#4018100200000000\n\
               (1.002500) can0 582#4318100244460000\n\
               (1.003000) can0 601#4000100000000000\n\
               (1.003500) can0 581#43001000FE030000\n\
               (1.004000) can0 602#2301180182010080\n\
               (1.004500) can0 582#6001180100000000\n\
               (1.005000) can0 603#4000100000000000\n\
               (1.005500) can0 583#4300100092010000\n";
    let out = cotui(&["decode", "-"], Some(log));
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines[1].ends_with("Device type = 0x00020192 (CiA 402, servo drive)"),
        "{text}"
    );
    assert!(lines[3].ends_with("Vendor-ID = 0x00000300"), "{text}");
    assert!(lines[5].ends_with("Product code = 0x00004644"), "{text}");
    assert!(
        lines[7].ends_with("Device type = 0x000003FE (device profile 1022)"),
        "{text}"
    );
    assert!(
        lines[8].ends_with("COB-ID used by TPDO = 0x80000182 (COB-ID 0x182, invalid/disabled)"),
        "{text}"
    );
    assert!(lines[11].ends_with("Device type = 0x00000192 (CiA 402)"), "{text}");
    // JSON lines: `value` stays the number, `value_text` and the label carry the hex.
    let out = cotui(&["decode", "--format", "jsonl", "-"], Some(log));
    let lines: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines[1]["sdo"]["value"], 131474);
    assert_eq!(lines[1]["sdo"]["value_text"], "0x00020192 (CiA 402, servo drive)");
    assert_eq!(lines[3]["sdo"]["value"], 768);
    assert_eq!(lines[3]["sdo"]["value_text"], "0x00000300");
    // Transactions say the same.
    let out = cotui(&["decode", "--transactions", "-"], Some(log));
    let tx = String::from_utf8(out.stdout).unwrap();
    assert!(
        tx.contains(
            "Upload 0x1000:00 Device type = 0x00020192 (CiA 402, servo drive) (expedited, 4 bytes, 0.500 ms): ok"
        ),
        "{tx}"
    );
    assert!(tx.contains("Vendor-ID = 0x00000300 (expedited"), "{tx}");
}
