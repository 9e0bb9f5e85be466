//! `pdo NODE` and `pdo NODE map ...` on the demo bus: the library with tokio time paused
//! (what the drive sends after a remap, decoded), the real binary for dry runs, refusals and
//! listen-only.

use crate::run::cotui_json;
use cotui::command::{execute, parse_command};
use cotui::decode::{Body, Decoder};
use cotui::frame::Direction;
use cotui::od::MappingSource;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use serde_json::json;
use std::time::Duration;

fn bindings() -> cotui::od::Bindings {
    cotui::cli::bind::bindings_on(cotui::connect::DEMO, &[], &[]).unwrap()
}

#[tokio::test(start_paused = true)]
async fn reads_every_pdo_of_a_demo_drive_in_words() {
    let d = Demo::spawn(Simulation::demo(), false);
    let o = execute(&d.bus, &parse_command("pdo 2").unwrap(), &bindings())
        .await
        .unwrap();
    let json = o.json();
    let pdos = json["pdos"].as_array().unwrap();
    let names: Vec<&str> = pdos.iter().map(|p| p["pdo"].as_str().unwrap()).collect();
    // 1..4 of each (the drive has no fifth: the read stops at the missing 0x1404 / 0x1804).
    assert_eq!(
        names,
        ["rpdo1", "rpdo2", "rpdo3", "rpdo4", "tpdo1", "tpdo2", "tpdo3", "tpdo4"]
    );
    let tpdo1 = &pdos[4];
    assert_eq!(tpdo1["cob_id"]["id"], 0x182);
    assert_eq!(tpdo1["cob_id"]["valid"], true);
    assert_eq!(tpdo1["transmission"], "synchronous, every SYNC");
    assert_eq!(tpdo1["inhibit_ms"], 0.0);
    assert_eq!(tpdo1["event_ms"], 0);
    assert_eq!(
        tpdo1["mapping"],
        json!([
            {"index": 0x6041, "sub": 0, "bits": 16, "name": "Statusword", "unit": null},
            {"index": 0x6061, "sub": 0, "bits": 8, "name": "Modes of operation display", "unit": null}
        ])
    );
    assert_eq!(pdos[0]["transmission"], "event-driven (device profile)");
    assert_eq!(pdos[6]["cob_id"]["valid"], false);
    assert_eq!(pdos[6]["mapping"], json!([]));
    assert!(
        o.text
            .contains("TPDO1  COB-ID 0x182, synchronous, every SYNC (1), inhibit 0 ms, event timer off"),
        "{}",
        o.text
    );
    assert!(o.text.contains("TPDO3  COB-ID 0x382 (invalid)"), "{}", o.text);
    assert!(o.text.contains("0x60FF:00 Target velocity, 32 bits"), "{}", o.text);
}

#[tokio::test(start_paused = true)]
async fn after_map_tpdo1_the_drive_sends_and_the_decoder_decodes_the_new_signals() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = bindings();
    let mut watch = d.bus.subscribe();
    execute(&d.bus, &parse_command("nmt start 2 --wait").unwrap(), &b)
        .await
        .unwrap();
    let map = parse_command("pdo 2 map tpdo1 Statusword 0x6064 --type sync:2 --event 50 --inhibit 1.5ms").unwrap();
    let o = execute(&d.bus, &map, &b).await.unwrap();
    assert_eq!(o.json()["verified"], true, "{}", o.json());
    assert_eq!(o.json()["comm"]["transmission_type"], 2);
    assert_eq!(o.json()["comm"]["inhibit_100us"], 15);
    assert_eq!(o.json()["comm"]["event_ms"], 50);
    // CiA 301: COB-ID invalid, the communication parameters while invalid, count 0,
    // entries, count, COB-ID valid again (the order `dcf load` writes too).
    let json = o.json();
    let order: Vec<&str> = json["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["object"].as_str().unwrap())
        .collect();
    assert_eq!(
        order,
        [
            "0x1800:01",
            "0x1800:02",
            "0x1800:03",
            "0x1800:05",
            "0x1A00:00",
            "0x1A00:01",
            "0x1A00:02",
            "0x1A00:00",
            "0x1800:01"
        ]
    );
    assert!(
        o.text
            .starts_with("TPDO1 of node 2 mapped (9 writes, read back): COB-ID 0x182, synchronous, every 2 SYNCs (2)"),
        "{}",
        o.text
    );
    // The drive's next TPDO1s (every 2nd SYNC), through a decoder that saw the whole bus.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let mut decoder = Decoder::from_bindings(&b);
    let mut after = Vec::new();
    let mut remapped = false;
    while let Some(Ok(f)) = watch.try_recv() {
        if f.id == 0x602 && f.direction() == Direction::Tx && f.data[..4] == [0x23, 0x00, 0x18, 0x01] {
            remapped = f.data[7] & 0x80 == 0; // the COB-ID written valid again
        }
        let dec = decoder.decode(&f);
        if remapped && f.id == 0x182 {
            after.push((f.len, dec));
        }
    }
    assert!(after.len() >= 2, "TPDO1 sent after the remap: {}", after.len());
    let (len, last) = after.last().unwrap();
    assert_eq!(*len, 6);
    assert!(
        last.label.starts_with("TPDO1 node 2: Statusword=0x") && last.label.contains(", Position actual value="),
        "{}",
        last.label
    );
    let Body::Pdo(p) = &last.body else {
        panic!("{:?}", last.body)
    };
    assert!(
        matches!(p.source, Some(MappingSource::Configured { .. })),
        "{:?}",
        p.source
    );
    let j = serde_json::to_value(p.to_json()).unwrap();
    assert!(
        j["mapping_source"]
            .as_str()
            .unwrap()
            .starts_with("configured by cotui @"),
        "{j}"
    );
    // Reading the mapping back (the verification, or `pdo 2`) keeps it "configured"; a
    // decoder that saw only a read learns it as "read from node".
    let mut fresh = Decoder::from_bindings(&cotui::od::Bindings::new());
    execute(&d.bus, &parse_command("pdo 2").unwrap(), &b).await.unwrap();
    while let Some(Ok(f)) = watch.try_recv() {
        decoder.decode(&f);
        fresh.decode(&f);
    }
    let m = decoder.mapping(cotui::frame::NodeKey::new(0, 2), true, 1).unwrap();
    assert!(matches!(m.source, MappingSource::Configured { .. }), "{:?}", m.source);
    let m = fresh.mapping(cotui::frame::NodeKey::new(0, 2), true, 1).unwrap();
    assert!(matches!(m.source, MappingSource::ReadFromNode { .. }), "{:?}", m.source);
    assert_eq!(m.entries.len(), 2);
}

#[tokio::test(start_paused = true)]
async fn a_refusal_says_why_with_the_nmt_state() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = bindings();
    execute(&d.bus, &parse_command("nmt start 2 --wait").unwrap(), &b)
        .await
        .unwrap();
    let e = execute(
        &d.bus,
        &parse_command("pdo 2 map tpdo5 0x6041 --cob-id 0x481").unwrap(),
        &b,
    )
    .await
    .unwrap_err();
    assert_eq!(e.exit_code(), 3);
    let m = e.to_string();
    assert!(m.contains("0x06020000"), "{m}");
    assert!(m.contains("the node has no 0x1804:01: TPDO5 may not exist"), "{m}");
    assert!(m.contains("node 2 is operational (its heartbeat says so)"), "{m}");
    assert_eq!(e.to_json()["error"], "sdo_abort");
}

/// Node 20 on its own endpoint of the demo bus: an expedited SDO server that keeps every
/// write, but reads TPDO1's transmission type (0x1800:02) back as 1 whatever was written.
fn lying_node(d: &Demo) {
    let peer = d.vbus.endpoint(false);
    let mut rx = peer.subscribe();
    tokio::spawn(async move {
        let mut store = std::collections::HashMap::from([((0x1800u16, 1u8), 0x194u32)]);
        while let Ok(f) = rx.recv().await {
            if f.id != 0x614 || f.direction() == Direction::Tx {
                continue;
            }
            let (c, index, sub) = (f.data[0], u16::from_le_bytes([f.data[1], f.data[2]]), f.data[3]);
            let mut answer = [0u8; 8];
            answer[1..4].copy_from_slice(&f.data[1..4]);
            if c == 0x40 {
                let v = if (index, sub) == (0x1800, 2) {
                    1
                } else {
                    store.get(&(index, sub)).copied().unwrap_or(0)
                };
                answer[0] = 0x43;
                answer[4..].copy_from_slice(&v.to_le_bytes());
            } else {
                let v = u32::from_le_bytes([f.data[4], f.data[5], f.data[6], f.data[7]]);
                store.insert((index, sub), v);
                answer[0] = 0x60;
            }
            let _ = peer.send(&cotui::frame::Frame::classic(0x594, &answer)).await;
        }
    });
}

#[tokio::test(start_paused = true)]
async fn a_read_back_that_differs_exits_6() {
    let d = Demo::spawn(Simulation::demo(), false);
    lying_node(&d);
    let cmd = parse_command("pdo 20 map tpdo1 0x6041 --type 255").unwrap();
    let e = execute(&d.bus, &cmd, &bindings()).await.unwrap_err();
    assert_eq!(e.exit_code(), 6, "{e}");
    assert_eq!(
        e.to_string(),
        "TPDO1 of node 20 differs from what was written: transmission type reads 0x1 after writing 0xFF"
    );
    let j = e.to_json();
    assert_eq!(
        (&j["ok"], &j["error"], &j["verified"]),
        (&json!(false), &json!("differs"), &json!(false))
    );
    assert_eq!(j["reason"], "transmission type reads 0x1 after writing 0xFF");
    assert_eq!(j["comm"]["transmission_type"], 1);
    assert_eq!(j["steps"].as_array().unwrap().len(), 6);
}

#[tokio::test(start_paused = true)]
async fn over_64_bits_nothing_is_sent() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut watch = d.bus.subscribe();
    let cmd = parse_command("pdo 2 map tpdo2 0x6064 0x606C 0x6041").unwrap();
    let e = execute(&d.bus, &cmd, &bindings()).await.unwrap_err();
    assert_eq!(e.exit_code(), 1);
    assert!(
        e.to_string()
            .contains("80 bits mapped (32 bits + 32 bits + 16 bits), more than the 64 bits"),
        "{e}"
    );
    tokio::time::sleep(Duration::from_millis(10)).await;
    while let Some(Ok(f)) = watch.try_recv() {
        assert_ne!(f.direction(), Direction::Tx, "sent {f:?}");
    }
}

#[test]
fn dry_run_prints_the_frames_and_needs_no_bus() {
    let args = [
        "pdo",
        "demo",
        "2",
        "map",
        "tpdo1",
        "0x6041",
        "0x6064",
        "--dry-run",
        "--json",
    ];
    let (rc, v, err) = cotui_json(&[&args[..], &["--listen-only"]].concat());
    assert_eq!(rc, 0, "{err}");
    let frames: Vec<&str> = v["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["frame"].as_str().unwrap())
        .collect();
    assert_eq!(
        frames,
        [
            "602#2300180182010080",
            "602#2F001A0000000000",
            "602#23001A0110004160",
            "602#23001A0220006460",
            "602#2F001A0002000000",
            "602#2300180182010000"
        ]
    );
    assert_eq!(v["dry_run"], true);
    // No interface needed at all.
    let (rc, _, err) = cotui_json(&["pdo", "nosuchcan9", "2", "map", "tpdo1", "0x6041", "--dry-run"]);
    assert_eq!(rc, 0, "{err}");
}

#[test]
fn listen_only_cannot_read_or_map_and_bad_lines_are_refused() {
    let (rc, v, _) = cotui_json(&["pdo", "demo", "2", "map", "tpdo1", "0x6041", "--listen-only", "--json"]);
    assert_eq!((rc, &v["error"]), (2, &json!("bus")));
    let (rc, v, _) = cotui_json(&["pdo", "demo", "2", "--listen-only", "--json"]);
    assert_eq!((rc, &v["error"]), (2, &json!("bus")));
    let (rc, _, err) = cotui_json(&["pdo", "demo", "2", "map", "tpdo1", "0x6064", "0x606C", "0x6041"]);
    assert_eq!(rc, 1);
    assert!(
        err.contains("more than the 64 bits a PDO carries; nothing sent"),
        "{err}"
    );
    let (rc, _, err) = cotui_json(&["pdo", "demo", "2", "map", "tpdo1", "0x6041", "--count", "2"]);
    assert_eq!(rc, 1);
    assert!(err.contains("--count does not go with `pdo map`"), "{err}");
}

/// Issue 24 item 6: after `pdo 2 map tpdo1 0x6041 --type sync:2` the demo drive sends
/// TPDO1 on every second SYNC only, as the transmission type says.
#[tokio::test(start_paused = true)]
async fn a_tpdo_mapped_sync_2_comes_on_every_second_sync() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = bindings();
    execute(&d.bus, &parse_command("nmt start 2 --wait").unwrap(), &b)
        .await
        .unwrap();
    let map = parse_command("pdo 2 map tpdo1 0x6041 --type sync:2").unwrap();
    let o = execute(&d.bus, &map, &b).await.unwrap();
    assert_eq!(o.json()["verified"], true, "{}", o.json());
    let mut watch = d.bus.subscribe();
    tokio::time::sleep(Duration::from_millis(1_050)).await;
    let mut seen = String::new();
    while let Some(Ok(f)) = watch.try_recv() {
        match f.id {
            0x080 => seen.push('S'),
            0x182 => {
                assert_eq!(f.len, 2, "only the statusword is mapped now");
                seen.push('T');
            }
            _ => {}
        }
    }
    // SYNC every 100 ms: ten in the second, TPDO1 after every other one.
    let gaps: Vec<usize> = seen.split('T').skip(1).map(str::len).collect();
    assert!(seen.matches('T').count() >= 4, "{seen}");
    assert!(
        gaps[..gaps.len() - 1].iter().all(|g| *g == 2),
        "TPDO1 (T) after every second SYNC (S): {seen}"
    );
}
