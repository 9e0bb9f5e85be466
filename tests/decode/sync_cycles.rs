//! `cotui decode --sync-cycles` (issue 29, item 2): one record per SYNC period with its
//! synchronous TPDOs, their time after the SYNC and the late ones. The fixture sends SYNC
//! every 10 ms (one period of 12.5 ms), TPDO1 of nodes 1 and 2 (made synchronous by
//! writes of 0x1800 sub 2 = 1), TPDO2 of node 1 event-driven (0x1801 sub 2 = 255), and
//! an SDO write of 0x1007 = 2000 µs after the first cycle; one TPDO of each node comes
//! after that window.

use crate::run::cotui;
use serde_json::{Value, json};

const LOG: &str = "tests/fixtures/sync_cycles.log";
/// A real boot log with 20 SYNCs about 10 ms apart and no TPDO.
const REAL: &str = "../shared/realworld/logs/ros2_canopen_issue225_boot.log";

fn stdout(args: &[&str]) -> String {
    let out = cotui(args, None);
    assert!(
        out.status.success(),
        "cotui {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

fn cycles(path: &str) -> Vec<Value> {
    let text = stdout(&["decode", "--sync-cycles", "--format", "jsonl", path]);
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect()
}

/// (COB-ID, offset µs, late) of each TPDO of a cycle.
fn lanes(c: &Value) -> Vec<(u64, u64, bool)> {
    let frames = c["frames"].as_array().expect("frames");
    frames
        .iter()
        .map(|f| {
            (
                f["cob_id"].as_u64().unwrap(),
                f["offset_us"].as_u64().unwrap(),
                f["late"].as_bool().unwrap(),
            )
        })
        .collect()
}

#[test]
fn each_cycle_lists_its_synchronous_tpdos_with_offsets_and_marks_the_late_ones() {
    let c = cycles(LOG);
    assert_eq!(c.len(), 6, "{c:?}");
    let first = &c[0];
    assert_eq!(first["iface"], "can0");
    // The SYNC's time, exact to the ns (as the frame JSONL writes times).
    let raw = stdout(&["decode", "--sync-cycles", "--format", "jsonl", LOG]);
    assert!(
        raw.starts_with(r#"{"iface":"can0","start":1700000000.010000000,"#),
        "{raw}"
    );
    assert!(raw.contains(r#""start":1700000000.052500000,"#), "{raw}");
    assert_eq!(first["period_ms"], json!(10.0));
    assert_eq!(first["counter"], json!(1));
    // Before the write of 0x1007 no window is known: nothing is late.
    assert_eq!(first["window_us"], Value::Null);
    assert_eq!(first["late"], json!(0));
    assert_eq!(
        first["frames"][0],
        json!({"cob_id": 0x181, "node": 1, "pdo": 1, "offset_us": 400, "late": false})
    );
    assert_eq!(lanes(first), [(0x181, 400, false), (0x182, 900, false)]);

    assert_eq!(c[1]["window_us"], json!(2000));
    assert_eq!(lanes(&c[1]), [(0x181, 400, false), (0x182, 3500, true)]);
    assert_eq!(c[1]["late"], json!(1));
    // TPDO2 of node 1 (0x281) is event-driven: no lane.
    assert_eq!(lanes(&c[2]), [(0x181, 500, false), (0x182, 1100, false)]);
    assert_eq!(c[3]["period_ms"], json!(12.5), "the slowest cycle");
    assert_eq!(lanes(&c[4]), [(0x182, 900, false), (0x181, 2600, true)]);
    // The last cycle has no next SYNC.
    assert_eq!(c[5]["period_ms"], Value::Null);
    assert_eq!(c[5]["counter"], json!(6));
    let late: Vec<u64> = c.iter().map(|c| c["late"].as_u64().unwrap()).collect();
    assert_eq!(late, [0, 1, 0, 0, 1, 0]);
}

#[test]
fn the_text_table_ends_with_the_summary() {
    let text = stdout(&["decode", "--sync-cycles", LOG]);
    insta::assert_snapshot!("sync_cycles_text", text);
    assert!(
        text.contains("slowest: can0 at 1700000000.040000 s (12.500 ms)"),
        "{text}"
    );
    assert!(text.contains("late: 2 TPDOs in 2 cycles"), "{text}");
}

#[test]
fn a_real_boot_log_has_twenty_cycles_of_about_10_ms_and_nothing_late() {
    let c = cycles(REAL);
    assert_eq!(c.len(), 20);
    let periods: Vec<f64> = c.iter().filter_map(|c| c["period_ms"].as_f64()).collect();
    assert_eq!(periods.len(), 19);
    assert!(periods.iter().all(|p| (9.7..10.1).contains(p)), "{periods:?}");
    let mean = periods.iter().sum::<f64>() / periods.len() as f64;
    assert!((mean - 10.0).abs() < 0.05, "{mean}");
    assert!(
        c.iter()
            .all(|c| c["late"] == 0 && c["window_us"].is_null() && c["counter"].is_null())
    );
    let text = stdout(&["decode", "--sync-cycles", REAL]);
    assert!(
        text.contains("cycles: 20\nperiod: mean 9.988 ms, max 10.061 ms\n"),
        "{text}"
    );
}

#[test]
fn sync_cycles_write_text_or_jsonl_only() {
    let out = cotui(&["decode", "--sync-cycles", "--format", "pcapng", "-o", "-", LOG], None);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--sync-cycles writes text or jsonl"), "{err}");
    let out = cotui(&["decode", "--sync-cycles", "--summary", LOG], None);
    assert_eq!(out.status.code(), Some(1), "clap refuses the pair");
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"));
}

#[test]
fn a_tpdo_event_driven_by_its_eds_default_has_no_lane() {
    // The EDS gives 0x1800 sub 2 = 254 (event-driven): node 3's TPDO1 is not in the
    // cycle; node 4's, of unknown type, is.
    let log = "(1.000000) can0 080#\n(1.000300) can0 183#01\n(1.000500) can0 184#02\n(1.010000) can0 080#\n";
    let eds = "3=../shared/realworld/eds/canopennode_DS301_profile.eds";
    let out = cotui(
        &["decode", "--sync-cycles", "--format", "jsonl", "--eds", eds, "-"],
        Some(log),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let first: Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    assert_eq!(lanes(&first), [(0x184, 500, false)], "{text}");
}
