//! Several logs as one capture: `split_bus_a.log` and `split_bus_b.log` are the two buses of
//! `two_buses.log`, each recorded apart and both named `can0`. Given together, their frames
//! merge by time; by default a name met in both files is one bus (a log split in parts), and
//! with `--iface-per-file` each file's `can0` is its own bus, `FILE:can0`, so the analysis is
//! that of `two_buses.log` (issue 25, item 2).

use crate::run::cotui;
use serde_json::Value;

const A: &str = "tests/fixtures/split_bus_a.log";
const B: &str = "tests/fixtures/split_bus_b.log";

fn stdout(args: &[&str]) -> String {
    let out = cotui(args, None);
    assert!(
        out.status.success(),
        "cotui {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// (kind, node, iface, status) of each incident of `diagnose --format jsonl`.
fn incidents(args: &[&str]) -> Vec<(String, u64, Option<String>, String)> {
    let mut all = vec!["diagnose", "--format", "jsonl"];
    all.extend_from_slice(args);
    stdout(&all)
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).expect("a JSON line");
            (
                v["kind"].as_str().unwrap_or_default().to_string(),
                v["node"].as_u64().unwrap_or_default(),
                v["iface"].as_str().map(String::from),
                v["status"].as_str().unwrap_or_default().to_string(),
            )
        })
        .collect()
}

#[test]
fn frames_of_several_logs_come_out_in_time_order_whatever_the_order_of_the_files() {
    let text = stdout(&["decode", B, A]);
    let times: Vec<&str> = text.lines().map(|l| l.split(')').next().unwrap_or_default()).collect();
    assert_eq!(times.len(), 114, "every frame of both files: {text}");
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "in time order:\n{text}");
    assert_eq!(
        &times[..3],
        ["(1700000100.000000", "(1700000100.050000", "(1700000100.100000"]
    );
    // One bus by default: the one name, as each file had it.
    assert!(text.lines().all(|l| l.contains(" can0 ")), "{text}");
}

#[test]
fn logs_of_one_bus_are_one_bus_by_default() {
    // Node 5's heartbeats of both files are one node's: it never goes silent for good, and
    // the SDO answer in one file pairs with the request in the other.
    let found = incidents(&[A, B]);
    assert!(
        !found.iter().any(|(k, n, _, s)| k == "silent" && *n == 5 && s == "open"),
        "{found:?}"
    );
    let tx = stdout(&["decode", "--transactions", A, B]);
    assert!(
        tx.starts_with("Upload 0x6041:00 Statusword = 0x0237") && tx.trim_end().ends_with(": ok"),
        "{tx}"
    );
}

#[test]
fn with_iface_per_file_two_buses_recorded_apart_stay_apart() {
    let found = incidents(&["--iface-per-file", A, B]);
    let b = format!("{B}:can0");
    assert!(
        found.contains(&("silent".into(), 5, Some(b.clone()), "open".into())),
        "node 5 of the second file's bus went silent for good: {found:?}"
    );
    // The same analysis as the capture of both buses in one file, interface names aside.
    let one_file = incidents(&["tests/fixtures/two_buses.log"]);
    let rename = |i: Option<String>| i.map(|i| i.replace(&format!("{A}:can0"), "can0").replace(&b, "can1"));
    let renamed: Vec<_> = found.into_iter().map(|(k, n, i, s)| (k, n, rename(i), s)).collect();
    assert_eq!(renamed, one_file);
    let tx = stdout(&["decode", "--transactions", "--iface-per-file", A, B]);
    assert!(
        tx.contains(&format!("{A}:can0 node 2: Upload 0x6041:00")) && tx.contains(": incomplete"),
        "{tx}"
    );
}
