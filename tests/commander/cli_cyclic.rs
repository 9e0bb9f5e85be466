//! `send`, `sync` and `pdo send`: through the real binary on the demo bus, and through the
//! library on one demo bus (tokio time paused) to see what the nodes make of the frames.

use crate::run::cotui_json;
use cotui::command::{execute, parse_command};
use cotui::frame::Direction;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use std::process::Command;
use std::time::Duration;

#[test]
fn send_counts_frames_and_measures_the_period() {
    let (rc, v, err) = cotui_json(&[
        "send",
        "demo",
        "601#4041600000000000",
        "--count",
        "3",
        "--every",
        "10",
        "--json",
    ]);
    assert_eq!(rc, 0, "{err}");
    assert_eq!((v["count"].as_u64(), v["seen"].as_u64()), (Some(3), Some(3)));
    assert_eq!(v["what"], "601#4041600000000000");
    assert_eq!(v["period_ms"], 10);
    assert!(
        v["mean_period_ms"].as_f64().is_some() && v["jitter_max_ms"].as_f64().is_some(),
        "{v}"
    );
    let (rc, v, _) = cotui_json(&["send", "demo", "601#40", "--listen-only", "--json"]);
    assert_eq!((rc, &v["error"]), (2, &serde_json::json!("bus")));
    let (rc, _, err) = cotui_json(&["send", "demo", "601#4G"]);
    assert_eq!(rc, 1);
    assert!(err.contains("is not a frame (column 6"), "{err}");
}

#[test]
fn pdo_send_encodes_through_the_mapping_and_names_the_signals() {
    let (rc, v, err) = cotui_json(&[
        "pdo",
        "demo",
        "2",
        "send",
        "rpdo1",
        "Controlword=0x0F",
        "Target velocity=500",
        "--json",
    ]);
    assert_eq!(rc, 0, "{err}");
    assert_eq!(v["what"], "RPDO1 node 2 202#0F00F4010000");
    assert_eq!(v["count"], 1);
    let (rc, out, _) = {
        let o = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["pdo", "demo", "2", "send", "rpdo1", "Target velocity=-1"])
            .output()
            .unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stdout).to_string(), ())
    };
    assert_eq!(rc, Some(0));
    assert!(
        out.contains("202#0000FFFFFFFF: 1 frame sent; not given, sent as 0: Controlword"),
        "{out}"
    );
    let (rc, _, err) = cotui_json(&["pdo", "demo", "2", "send", "rpdo1", "Speed=3"]);
    assert_eq!(rc, 1);
    assert!(
        err.contains("RPDO1 of node 2 maps: Controlword (0x6040:00), Target velocity (0x60FF:00)"),
        "{err}"
    );
}

#[tokio::test(start_paused = true)]
async fn the_drive_takes_the_rpdo_values() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = cotui::cli::bind::bindings_on(cotui::connect::DEMO, &[], &[]).unwrap();
    let start = parse_command("nmt start 2 --wait").unwrap();
    execute(&d.bus, &start, &b).await.unwrap();
    let pdo = parse_command("pdo 2 send rpdo1 Controlword=0x06 \"Target velocity=500\" --every 10 --count 3").unwrap();
    let o = execute(&d.bus, &pdo, &b).await.unwrap();
    assert_eq!(o.json()["count"], 3);
    let read = |object: &str| parse_command(&format!("sdo read 2 {object}")).unwrap();
    let v = execute(&d.bus, &read("0x60FF"), &b).await.unwrap();
    assert_eq!(v.json()["value"], 500);
    let cw = execute(&d.bus, &read("0x6040"), &b).await.unwrap();
    assert_eq!(cw.json()["value"], 6);
}

#[tokio::test(start_paused = true)]
async fn sync_counts_1_to_n_at_the_period() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = cotui::od::bind::Bindings::new();
    let mut watch = d.bus.subscribe();
    let sync = parse_command("sync --period 10 --counter 2 --count 5 --force").unwrap();
    let o = execute(&d.bus, &sync, &b).await.unwrap();
    assert_eq!(
        (o.json()["count"].as_u64(), o.json()["seen"].as_u64()),
        (Some(5), Some(5))
    );
    let mean = o.json()["mean_period_ms"].as_f64().unwrap();
    assert!((9.5..10.5).contains(&mean), "{mean}");
    tokio::time::sleep(Duration::from_millis(1)).await;
    let mut counters = Vec::new();
    while let Some(Ok(f)) = watch.try_recv() {
        if f.id == 0x080 && f.direction() == Direction::Tx {
            counters.push(f.payload().to_vec());
        }
    }
    assert_eq!(counters, [[1], [2], [1], [2], [1]]);
    assert!(
        o.text.starts_with("SYNC 080: 5 frames sent every 10 ms, mean period"),
        "{}",
        o.text
    );
}
