//! The transmit list (`send IFACE --list FILE`) and the watch list (`watch IFACE NODE
//! OBJ...`) on the demo bus: per-entry counts by the frames' receive timestamps, located
//! errors, the listen-only refusal, a stop-all disabling every entry, and the watch CSV.

use crate::run::cotui_json;
use cotui::command::{execute, execute_until, parse_command};
use cotui::frame::{Direction, Frame};
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use std::process::Command;

/// Writes `text` to a fresh file named after `name`; its path.
fn list_file(name: &str, text: &str) -> String {
    let path = std::env::temp_dir().join(format!("cotui-list-{name}-{}.json", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

const LIST: &str = r#"{
  "entries": [
    { "frame": "123#11", "every_ms": 20, "comment": "fast" },
    { "rpdo": "rpdo1", "node": 2, "signals": { "Controlword": "0x06", "Target velocity": 500 },
      "every_ms": 50 },
    { "frame": "124#22", "count": 3 },
    { "frame": "000#0100", "enabled": false, "comment": "NMT start, by hand" }
  ]
}"#;

/// Frames with the payload and id of `what` (candump compact form) among `frames`.
fn of<'a>(frames: &'a [Frame], what: &str) -> Vec<&'a Frame> {
    frames
        .iter()
        .filter(|f| cotui::command::candump(f) == what && f.direction() == Direction::Tx)
        .collect()
}

#[tokio::test(start_paused = true)]
async fn each_entry_is_sent_on_its_period_counted_by_receive_timestamps() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = cotui::cli::bind::bindings_on(cotui::connect::DEMO, &[], &[]).unwrap();
    let mut watch = d.bus.subscribe();
    let path = list_file("periods", LIST);
    let cmd = parse_command(&format!("send --list {path} --duration 1000")).unwrap();
    let o = execute(&d.bus, &cmd, &b).await.unwrap();
    let mut frames = Vec::new();
    while let Some(Ok(f)) = watch.try_recv() {
        frames.push(f);
    }
    let first = frames.iter().find(|f| f.direction() == Direction::Tx).unwrap().ts_ns;
    let in_window = |fs: Vec<&Frame>| fs.iter().filter(|f| f.ts_ns - first < 1_000_000_000).count() as f64;
    for (what, period) in [("123#11", 20.0), ("202#0600F4010000", 50.0)] {
        let n = in_window(of(&frames, what));
        let expected = 1000.0 / period;
        assert!(
            (n - expected).abs() <= 0.15 * expected,
            "{what}: {n} frames, expected {expected}"
        );
    }
    assert_eq!(of(&frames, "124#22").len(), 3);
    assert!(of(&frames, "000#0100").is_empty(), "a disabled entry was sent");
    let j = o.json();
    let sent: Vec<u64> = j["entries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["sent"].as_u64().unwrap())
        .collect();
    assert_eq!(sent, [50, 20, 3, 0], "{j}");
    assert_eq!(j["entries"][1]["frame"], "202#0600F4010000");
    assert_eq!(j["entries"][1]["what"], "RPDO1 node 2 202#0600F4010000");
    assert_eq!(j["entries"][0]["comment"], "fast");
    assert_eq!(j["entries"][3]["enabled"], false);
    // The drive took the RPDO's values.
    let v = execute(&d.bus, &parse_command("sdo read 2 0x60FF").unwrap(), &b)
        .await
        .unwrap();
    assert_eq!(v.json()["value"], 500);
}

#[tokio::test(start_paused = true)]
async fn a_stop_all_seen_on_the_bus_disables_every_entry() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = cotui::cli::bind::bindings_on(cotui::connect::DEMO, &[], &[]).unwrap();
    let path = list_file("stop", LIST);
    let cmd = parse_command(&format!("send --list {path}")).unwrap();
    let other = d.vbus.endpoint(false);
    let bus = d.bus.clone();
    let (b2, cmd2) = (b.clone(), cmd.clone());
    let list = tokio::spawn(async move {
        let progress = cotui::command::cyclic::Progress::default();
        execute_until(&bus, &cmd2, &b2, progress, std::future::pending()).await
    });
    tokio::time::sleep(std::time::Duration::from_millis(300)).await;
    // Another program's stop-all: a quick stop of node 2 by SDO.
    let stop = parse_command("stop 2 --listen 50").unwrap();
    let _ = execute(&other, &stop, &b).await;
    let o = list.await.unwrap().unwrap();
    let j = o.json();
    assert!(
        j["stopped_by"].as_str().unwrap().contains("quick stop of node 2"),
        "{j}"
    );
    let sent = j["entries"][0]["sent"].as_u64().unwrap();
    assert!((10..=20).contains(&sent), "{j}");
    assert!(o.text.contains("every entry disabled"), "{}", o.text);
}

#[test]
fn the_command_line_reports_per_entry_counts_and_refuses_bad_lists() {
    let path = list_file("cli", LIST);
    let (rc, v, err) = cotui_json(&["send", "demo", "--list", &path, "--duration", "1000", "--json"]);
    assert_eq!(rc, 0, "{err}");
    for e in v["entries"].as_array().unwrap().iter().take(2) {
        // By the receive timestamps: as many frames as periods between the first and the last.
        let (seen, span, period) = (
            e["seen"].as_f64().unwrap(),
            e["seen_span_ms"].as_f64().unwrap(),
            e["every_ms"].as_f64().unwrap(),
        );
        let expected = span / period + 1.0;
        assert!((seen - expected).abs() <= 0.15 * expected, "{e}");
        assert_eq!(e["sent"], e["seen"], "{e}");
    }
    assert_eq!(v["entries"][2]["sent"], 3);
    let (rc, v, _) = cotui_json(&["send", "demo", "--list", &path, "--listen-only", "--json"]);
    assert_eq!((rc, &v["error"]), (2, &serde_json::json!("bus")));
    let bad = list_file(
        "bad",
        "{\"entries\": [\n  {\"frame\": \"601#40\"},\n  {\"frame\": \"601#4G\"},\n  {\"frame\": \"1#\"},\n  {\"frame\": \"601#40\", \"every_ms\": 0}\n]}",
    );
    let (rc, _, err) = cotui_json(&["send", "demo", "--list", &bad]);
    assert_eq!(rc, 1);
    assert!(
        err.contains(&format!("{bad}: entry 2 (line 3): `601#4G` is not a frame")),
        "{err}"
    );
    assert!(
        err.contains(&format!("{bad}: entry 3 (line 4): `1#` is not a frame")),
        "{err}"
    );
    assert!(
        err.contains(&format!("{bad}: entry 4 (line 5): `every_ms` is 0")),
        "{err}"
    );
    let signal = list_file(
        "signal",
        "{\"entries\": [\n  {\"rpdo\": \"rpdo1\", \"node\": 2,\n   \"signals\": {\"Speed\": 3}}\n]}",
    );
    let (rc, v, _) = cotui_json(&["send", "demo", "--list", &signal, "--json"]);
    assert_eq!(rc, 1);
    let m = v["message"].as_str().unwrap();
    assert!(
        m.starts_with(&format!("{signal}: entry 1 (line 2): unknown object `Speed`")),
        "{m}"
    );
    assert!(m.contains("RPDO1 of node 2 maps: Controlword (0x6040:00)"), "{m}");
}

#[test]
fn watch_writes_a_csv_row_per_round_with_the_objects_named() {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args([
            "watch",
            "demo",
            "2",
            "0x6041",
            "0x6064",
            "--every",
            "50",
            "--duration",
            "1000",
            "--format",
            "csv",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("time_s,2:0x6041 Statusword,2:0x6064 Position actual value")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 20 periods in the second; a busy machine may skip some, never add any.
    assert!((10..=21).contains(&rows.len()), "{text}");
    let mut last_t = -1.0;
    for r in &rows {
        assert_eq!(r.len(), 3, "{text}");
        let t: f64 = r[0].parse().unwrap();
        assert!(t > last_t && t < 1.2, "{text}");
        last_t = t;
        // The demo drive's statusword (a number) and position.
        assert!(r[1].parse::<u16>().is_ok() && r[2].parse::<i64>().is_ok(), "{text}");
    }
}

#[test]
fn a_missing_node_times_out_in_its_column_and_a_missing_object_is_absent_once() {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args([
            "watch",
            "demo",
            "2",
            "0x6041",
            "0x2999",
            "9",
            "0x6041",
            "--every",
            "100",
            "--duration",
            "650",
            "--timeout",
            "50",
            "--format",
            "csv",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert!(rows.len() >= 3, "{text}");
    assert_eq!(rows[0][2], "absent", "{text}");
    for r in &rows {
        assert!(r[1].parse::<u16>().is_ok(), "node 2 went on: {text}");
        assert_eq!(r[3], "timeout", "{text}");
    }
    assert!(rows[1..].iter().all(|r| r[2].is_empty()), "polled again: {text}");
    let (rc, v, _) = cotui_json(&["watch", "demo", "2", "0x6041", "0x2999", "--duration", "200", "--json"]);
    assert_eq!(rc, 0);
    assert_eq!(v["objects"][1]["absent"], true, "{v}");
    assert_eq!(v["objects"][0]["name"], "Statusword", "{v}");
    let (rc, _, err) = cotui_json(&["watch", "demo", "2", "Nonsense", "--duration", "200"]);
    assert_eq!(rc, 1);
    assert!(err.contains("node 2: unknown object `Nonsense`"), "{err}");
}
