//! The `--json` contract of every commander command: one insta snapshot per command's
//! answer, for a good run and for a failure, on the demo bus (docs/COMMANDER.md names the
//! fields). Timings the machine decides (measured periods, jitter) and temporary paths
//! are replaced by placeholders; every other field is pinned, names and values.

use crate::run::cotui_json;
use serde_json::Value;

/// Replaces what a run on a busy machine changes: measured times and the temp folder.
fn stable(v: &mut Value, tmp: &str) {
    match v {
        Value::Object(map) => {
            for (key, value) in map.iter_mut() {
                let measured = [
                    "jitter",
                    "mean_period",
                    "elapsed",
                    "took",
                    "duration_ms",
                    "after_ms",
                    "span",
                ]
                .iter()
                .any(|m| key.contains(m));
                if measured && value.is_number() {
                    *value = Value::String("[measured]".into());
                } else {
                    stable(value, tmp);
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(|i| stable(i, tmp)),
        Value::String(s) if s.contains(tmp) => *s = s.replace(tmp, "[tmp]"),
        Value::String(s) if s.contains(" ms after it began") => *s = heard_at_measured(s),
        _ => {}
    }
}

/// `..., the last 801 ms after it began; ...` (another producer heard): the time measured.
fn heard_at_measured(s: &str) -> String {
    let (head, tail) = s.split_once(" ms after it began").unwrap_or((s, ""));
    let head = head.trim_end_matches(|c: char| c.is_ascii_digit());
    format!("{head}[measured] ms after it began{tail}")
}

/// Runs `cotui ARGS --json`, checks the exit status and snapshots the JSON answer.
fn pinned(name: &str, args: &[&str], status: i32, tmp: &str) {
    let mut line: Vec<&str> = args.to_vec();
    line.push("--json");
    let (rc, mut json, stderr) = cotui_json(&line);
    assert_eq!(rc, status, "cotui {}: {json} {stderr}", line.join(" "));
    assert!(
        json.is_object(),
        "cotui {}: not one JSON object: {stderr}",
        line.join(" ")
    );
    stable(&mut json, tmp);
    let pretty = serde_json::to_string_pretty(&json).unwrap();
    let command = format!("cotui {}", line.join(" ")).replace(tmp, "[tmp]");
    insta::assert_snapshot!(name, pretty, &command);
}

#[test]
fn every_command_answers_json_as_documented() {
    let dir = std::env::temp_dir().join(format!("cotui-json-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tmp = dir.to_str().unwrap();
    let dcf = format!("{tmp}/node2.dcf");
    let log = format!("{tmp}/three.log");
    let list = format!("{tmp}/list.json");
    std::fs::write(
        &list,
        r#"{"entries": [{"frame": "123#11", "count": 2, "comment": "twice"},
            {"rpdo": "rpdo1", "node": 2, "signals": {"Controlword": "0x06"}},
            {"frame": "000#0100", "enabled": false}]}"#,
    )
    .unwrap();
    let bad_list = format!("{tmp}/bad_list.json");
    std::fs::write(&bad_list, "{\"entries\": [\n  {\"frame\": \"123#1\"}\n]}").unwrap();
    let cases: Vec<(&str, Vec<&str>, i32)> = vec![
        ("nmt", vec!["nmt", "demo", "start", "2", "--wait"], 0),
        ("nmt_no_such_bus", vec!["nmt", "can9", "start", "2"], 2),
        ("sdo_read", vec!["sdo", "read", "demo", "2", "0x6041"], 0),
        ("sdo_read_abort", vec!["sdo", "read", "demo", "2", "0x2345:1"], 3),
        ("sdo_read_usage", vec!["sdo", "read", "demo", "2"], 1),
        (
            "sdo_write",
            vec!["sdo", "write", "demo", "2", "0x6060", "1", "--type", "i8"],
            0,
        ),
        (
            "sdo_write_abort",
            vec!["sdo", "write", "demo", "2", "0x6041", "6", "--type", "u16"],
            3,
        ),
        ("drive_status", vec!["drive", "demo", "2", "status"], 0),
        ("drive_enable", vec!["drive", "demo", "2", "enable"], 0),
        (
            "drive_no_such_node",
            vec!["drive", "demo", "9", "enable", "--timeout", "100"],
            4,
        ),
        ("scan", vec!["scan", "demo"], 0),
        ("lss_switch", vec!["lss", "demo", "switch", "config"], 0),
        ("lss_inquire_timeout", vec!["lss", "demo", "inquire", "all"], 4),
        ("send", vec!["send", "demo", "123#11", "--count", "2"], 0),
        ("send_bad_frame", vec!["send", "demo", "123#1"], 1),
        ("send_list", vec!["send", "demo", "--list", &list], 0),
        ("send_list_bad_entry", vec!["send", "demo", "--list", &bad_list], 1),
        (
            "watch",
            vec![
                "watch",
                "demo",
                "2",
                "0x6041",
                "0x2999",
                "--duration",
                "1000",
                "--every",
                "5000",
            ],
            0,
        ),
        ("watch_unknown_object", vec!["watch", "demo", "2", "Nonsense"], 1),
        (
            "sync",
            vec!["sync", "demo", "--period", "10", "--count", "2", "--listen", "0"],
            0,
        ),
        (
            "sync_reserved_cob_id",
            vec!["sync", "demo", "--period", "10", "--count", "2", "--cob-id", "0x602"],
            1,
        ),
        ("nmt_no_wait", vec!["nmt", "demo", "preop", "2"], 0),
        // The demo's NMT master starts all nodes 0.8 s after power-on.
        (
            "nmt_other_master",
            vec!["nmt", "demo", "preop", "2", "--listen", "2s"],
            2,
        ),
        (
            "nmt_other_master_force",
            vec!["nmt", "demo", "preop", "2", "--listen", "2s", "--force"],
            0,
        ),
        (
            "pdo_send",
            vec!["pdo", "demo", "2", "send", "rpdo1", "Controlword=0x0F", "--count", "1"],
            0,
        ),
        ("run_dry_run", vec!["run", "demo", "2", "csp", "--dry-run"], 0),
        ("pdo_read", vec!["pdo", "demo", "2"], 0),
        (
            "pdo_map_dry_run",
            vec!["pdo", "demo", "2", "map", "tpdo1", "0x6041", "--dry-run"],
            0,
        ),
        (
            "pdo_map_reserved",
            vec!["pdo", "demo", "2", "map", "tpdo1", "0x6041", "--cob-id", "0x602"],
            1,
        ),
        ("stop", vec!["stop", "demo", "2"], 0),
        ("run_list", vec!["run", "demo", "2"], 0),
        ("run_unknown", vec!["run", "demo", "2", "no-such-procedure"], 1),
        ("record", vec!["record", "demo", "-o", &log, "--count", "3"], 0),
        ("record_exists", vec!["record", "demo", "-o", &log, "--count", "3"], 1),
        ("dcf_save", vec!["dcf", "save", "demo", "2", "-o", &dcf], 0),
        ("dcf_diff", vec!["dcf", "diff", "demo", "2", &dcf], 0),
        (
            "dcf_diff_missing",
            vec!["dcf", "diff", "demo", "2", "/nonexistent.dcf"],
            1,
        ),
        (
            "dcf_load_dry_run",
            vec!["dcf", "load", "demo", "2", &dcf, "--dry-run"],
            0,
        ),
        (
            "dcf_load_missing",
            vec!["dcf", "load", "demo", "2", "/nonexistent.dcf"],
            1,
        ),
        (
            "scan_probe_listen_only",
            vec!["scan", "demo", "--probe", "--listen-only"],
            2,
        ),
        ("stop_listen_only", vec!["stop", "demo", "2", "--listen-only"], 5),
        (
            "sync_listen_only",
            vec!["sync", "demo", "--period", "10", "--count", "2", "--listen-only"],
            2,
        ),
        ("lss_select_words", vec!["lss", "demo", "select", "1", "2", "3"], 1),
        ("pdo_read_no_node", vec!["pdo", "demo", "9", "--timeout", "100"], 4),
        ("pdo_map", vec!["pdo", "demo", "2", "map", "tpdo1", "0x6041"], 0),
        (
            "pdo_send_unknown_signal",
            vec!["pdo", "demo", "2", "send", "rpdo1", "Nope=1"],
            1,
        ),
        ("run_csp", vec!["run", "demo", "2", "csp"], 0),
        ("run_listen_only", vec!["run", "demo", "2", "csp", "--listen-only"], 2),
    ];
    for (name, args, status) in cases {
        pinned(name, &args, status, tmp);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
