//! A capture of two buses (`can0`, `can1`), each with a node 5 heartbeating, is two
//! buses: node 5 on can1 goes silent for good while node 5 on can0 goes on, and an SDO
//! request to node 2 on can0 is answered only on can1. A node is (interface, node-ID) in
//! every view (issue 25, item 1).

use crate::run::cotui;

const LOG: &str = "tests/fixtures/two_buses.log";

fn stdout(args: &[&str]) -> String {
    let out = cotui(args, None);
    assert!(
        out.status.success(),
        "cotui {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

#[test]
fn an_sdo_request_on_can0_never_pairs_with_an_answer_on_can1() {
    let text = stdout(&["decode", "--transactions", LOG]);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    // The request on can0 stays unanswered; the answer on can1 has no request there.
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("can0 node 2: Upload 0x6041:00") && l.ends_with(": incomplete")),
        "{text}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("can1 node 2: Upload 0x6041:00") && l.contains("[unmatched response]")),
        "{text}"
    );
    assert!(!text.contains("1.000 ms): ok"), "paired across interfaces: {text}");

    let json = stdout(&["decode", "--transactions", "--format", "jsonl", LOG]);
    let rows: Vec<serde_json::Value> = json.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let on = |iface: &str| {
        rows.iter()
            .find(|r| r["iface"] == iface)
            .unwrap_or_else(|| panic!("{iface}: {json}"))
    };
    assert_eq!(on("can0")["outcome"], "incomplete");
    assert_eq!(on("can0")["frames"], serde_json::json!([12]));
    assert_eq!(on("can1")["frames"], serde_json::json!([13]));
    assert_eq!(on("can1")["problems"][0]["kind"], "unmatched_response", "{json}");
}

#[test]
fn diagnose_reports_node_5_on_can1_silent_and_nothing_about_can0() {
    let report = stdout(&["diagnose", LOG]);
    assert!(report.starts_with("Needs attention: 2 open"), "{report}");
    assert!(
        report.contains("OPEN       Node 5 (can1): Went silent and never came back"),
        "{report}"
    );
    assert!(!report.contains("came back each time"), "{report}");
    assert!(!report.contains("Node 5 (can0)"), "{report}");
    // The request on can0 is unanswered there.
    assert!(report.contains("OPEN       Node 2 (can0): No answer"), "{report}");

    let json = stdout(&["diagnose", "--format", "jsonl", LOG]);
    let incidents: Vec<serde_json::Value> = json.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let silent: Vec<_> = incidents.iter().filter(|i| i["kind"] == "silent").collect();
    assert_eq!(silent.len(), 1, "{json}");
    assert_eq!(silent[0]["node"], 5);
    assert_eq!(silent[0]["iface"], "can1");
    assert_eq!(silent[0]["status"], "open");
    assert!(incidents.iter().all(|i| i["kind"] != "silent_back"), "{json}");
}

#[test]
fn the_summary_has_a_row_per_node_of_each_interface() {
    let text = stdout(&["decode", "--summary", LOG]);
    assert!(text.contains("\n  can0 node 5          101  heartbeat=101\n"), "{text}");
    assert!(text.contains("\n  can1 node 5           11  heartbeat=11\n"), "{text}");
    assert!(text.contains("\n  can0 node 2            1  sdo_rx=1\n"), "{text}");
    assert!(text.contains("\n  can1 node 2            1  sdo_tx=1\n"), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&stdout(&["decode", "--summary", "--format", "jsonl", LOG])).unwrap();
    assert_eq!(json["by_node"]["can0/5"]["heartbeat"], 101);
    assert_eq!(json["by_node"]["can1/5"]["heartbeat"], 11);
    assert!(json["by_node"].get("5").is_none(), "{json}");
}

/// `by_iface`: each bus's own frames, bits, load, busiest 100 ms and longest burst, besides
/// the whole capture's `bus` figures; the text summary lists them `by bus:`.
#[test]
fn the_summary_has_the_bus_figures_of_each_interface() {
    let json: serde_json::Value =
        serde_json::from_str(&stdout(&["decode", "--summary", "--format", "jsonl", LOG])).unwrap();
    let buses = json["by_iface"].as_array().unwrap();
    let names: Vec<&str> = buses.iter().map(|b| b["iface"].as_str().unwrap()).collect();
    assert_eq!(names, ["can0", "can1"], "{json}");
    let node_bits = |key: &str| json["bus"]["by_node"][key].as_u64().unwrap();
    let (can0, can1) = (&buses[0], &buses[1]);
    // can0: 101 heartbeats and the SDO request; can1: 11 heartbeats and the answer.
    assert_eq!(
        (can0["frames"].as_u64(), can1["frames"].as_u64()),
        (Some(102), Some(12))
    );
    assert_eq!(can0["bits"].as_u64(), Some(node_bits("can0/5") + node_bits("can0/2")));
    assert_eq!(can1["bits"].as_u64(), Some(node_bits("can1/5") + node_bits("can1/2")));
    assert_eq!(
        can0["bits"].as_u64().unwrap() + can1["bits"].as_u64().unwrap(),
        json["bus"]["bits"].as_u64().unwrap()
    );
    // can0 spans 10 s (100.000 to 110.000), can1 1 s (100.050 to 101.050), at 500 kbit/s.
    let load = |b: &serde_json::Value, span_s: f64| b["bits"].as_u64().unwrap() as f64 / (500_000.0 * span_s);
    assert!(
        (can0["load"].as_f64().unwrap() - load(can0, 10.0)).abs() < 1e-6,
        "{can0}"
    );
    assert!(
        (can1["load"].as_f64().unwrap() - load(can1, 1.0)).abs() < 1e-6,
        "{can1}"
    );
    // can1's busiest 100 ms: the SDO answer (100.521) and the heartbeat after it (100.550),
    // not can0's frames in between.
    let heartbeat = node_bits("can1/5") / 11;
    let busiest = (node_bits("can1/2") + heartbeat) as f64 / 50_000.0;
    assert!(
        (can1["busiest_100ms"].as_f64().unwrap() - busiest).abs() < 1e-6,
        "{can1}"
    );
    assert!(json["bus"]["busiest_100ms"].as_f64().unwrap() > busiest);
    for b in buses {
        assert_eq!(
            (b["bitrate"].as_u64(), b["bitrate_source"].as_str()),
            (Some(500_000), Some("assumed"))
        );
        assert!(b["longest_burst_ms"].as_f64().unwrap() > 0.0);
    }
    let text = stdout(&["decode", "--summary", LOG]);
    let at = text.find("by bus:\n").unwrap_or_else(|| panic!("{text}"));
    let rows: Vec<&str> = text[at..].lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{text}");
    assert!(rows[0].starts_with("  can0            102 frames "), "{text}");
    assert!(rows[1].starts_with("  can1             12 frames "), "{text}");
    assert!(
        rows[1].contains(&format!("busiest 100 ms {:.2} %", busiest * 100.0)),
        "{text}"
    );
    // One bus: one entry (the capture's figures), no `by bus:` lines.
    let one: serde_json::Value = serde_json::from_str(&stdout(&[
        "decode",
        "--summary",
        "--format",
        "jsonl",
        "tests/fixtures/heartbeat_stops.log",
    ]))
    .unwrap();
    assert_eq!(one["by_iface"].as_array().map(Vec::len), Some(1), "{one}");
    assert_eq!(one["by_iface"][0]["bits"], one["bus"]["bits"]);
    assert_eq!(one["by_iface"][0]["busiest_100ms"], one["bus"]["busiest_100ms"]);
    assert!(!stdout(&["decode", "--summary", "tests/fixtures/heartbeat_stops.log"]).contains("by bus:"));
}

#[test]
fn events_name_the_interface_of_each_node() {
    let text = stdout(&["decode", "--events", LOG]);
    let lost: Vec<&str> = text.lines().filter(|l| l.contains("heartbeat_lost")).collect();
    assert_eq!(lost.len(), 1, "{text}");
    assert!(lost[0].contains("node   5 (can1)  heartbeat_lost"), "{text}");
    assert!(!text.contains("heartbeat_back"), "{text}");
    let json = stdout(&["decode", "--events", "--format", "jsonl", LOG]);
    let events: Vec<serde_json::Value> = json.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let lost: Vec<_> = events.iter().filter(|e| e["event"] == "heartbeat_lost").collect();
    assert_eq!(lost.len(), 1, "{json}");
    assert_eq!(
        (lost[0]["node"].clone(), lost[0]["iface"].clone()),
        (5.into(), "can1".into())
    );
}

#[test]
fn a_capture_of_one_interface_prints_no_interface() {
    let text = stdout(&["decode", "--summary", "tests/fixtures/heartbeat_stops.log"]);
    assert!(text.contains("\n  node 5 ") && !text.contains("can0 node"), "{text}");
    let json = stdout(&[
        "decode",
        "--events",
        "--format",
        "jsonl",
        "tests/fixtures/heartbeat_stops.log",
    ]);
    assert!(!json.contains("\"iface\""), "{json}");
}

/// The capture, then a read of node 5's heartbeat period (0x1017) on each bus, answered
/// 100 ms on can0 and 200 ms on can1, through a trace keeping every view (the TUI's).
fn trace_with_reads() -> cotui::analysis::trace::Trace {
    use cotui::decode::Decoder;
    let log = std::fs::read_to_string(LOG).unwrap();
    let reads = [
        "(1700000112.000000) can0 605#4017100000000000",
        "(1700000112.001000) can0 585#4B17100064000000",
        "(1700000112.002000) can1 605#4017100000000000",
        "(1700000112.003000) can1 585#4B171000C8000000",
    ];
    let mut trace = cotui::analysis::trace::Trace::new(Decoder::new(Default::default(), Vec::new()), 500_000);
    for line in log.lines().chain(reads) {
        let parsed = cotui::log::candump::parse_line(line.as_bytes(), &mut trace.ifaces);
        if let Ok(cotui::log::Line::Frame(f)) = parsed {
            trace.push(&f);
        }
    }
    trace
}

#[test]
fn values_and_series_of_node_5_on_each_bus_are_kept_apart() {
    use cotui::frame::NodeKey;
    let trace = trace_with_reads();
    let (can0, can1) = (NodeKey::new(0, 5), NodeKey::new(1, 5));
    assert_eq!(trace.ifaces.name(1), "can1");
    let last = |node| {
        let e = trace.values.get(node, 0x1017, 0).and_then(|e| e.last.as_ref());
        e.map(|s| s.value.clone())
    };
    // (The default dictionary does not type 0x1017: the bytes as read.)
    assert_eq!(last(can0), Some(cotui::od::Value::Bytes(vec![100, 0])));
    assert_eq!(last(can1), Some(cotui::od::Value::Bytes(vec![200, 0])));
    assert_eq!(trace.values.node(can0).count(), 1);
    let values = |node| {
        let line = trace.series.get(&(node, 0x1017, 0));
        line.map(|l| l.points.iter().map(|p| p.1).collect::<Vec<f64>>())
    };
    assert_eq!(values(can0), Some(vec![100.0]));
    assert_eq!(values(can1), Some(vec![200.0]));
    let fives: Vec<NodeKey> = trace
        .series
        .keys()
        .into_iter()
        .map(|k| k.0)
        .filter(|k| k.node == 5)
        .collect();
    assert_eq!(fives, [can0, can1]);
}
