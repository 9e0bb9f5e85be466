//! The commander against the simulated demo bus (tokio time paused: deterministic).

use cotui::bus::BusError;
use cotui::command::drive::drive;
use cotui::command::nmt::nmt;
use cotui::command::sdo::{download, upload};
use cotui::command::{CommandError, DriveAction, NmtAction};
use cotui::decode::cia402::DriveState;
use cotui::decode::heartbeat::NmtState;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use std::time::Duration;

const T: u64 = 500;

fn demo() -> Demo {
    Demo::spawn(Simulation::demo(), false)
}

#[tokio::test(start_paused = true)]
async fn sdo_expedited_segmented_and_block_reads() {
    let d = demo();
    let sw = upload(&d.bus, 2, 0x6041, 0, false, T).await.unwrap();
    assert_eq!(sw, vec![0x50, 0x02]);
    let name = upload(&d.bus, 3, 0x1008, 0, false, T).await.unwrap();
    assert_eq!(
        String::from_utf8(name).unwrap(),
        "cotui simulated Syn-tron-like DS servo"
    );
    let blob = upload(&d.bus, 2, 0x2000, 0, true, T).await.unwrap();
    let want: Vec<u8> = (0..200u32).map(|i| (i * 7 + 2) as u8).collect();
    assert_eq!(blob, want);
    let by_block = upload(&d.bus, 2, 0x1008, 0, true, T).await.unwrap();
    assert_eq!(by_block, b"cotui simulated AIMOTOR-like servo");
}

#[tokio::test(start_paused = true)]
async fn sdo_writes_of_every_kind_read_back() {
    let d = demo();
    download(&d.bus, 2, 0x1017, 0, vec![0xE8, 0x03], false, T)
        .await
        .unwrap();
    assert_eq!(upload(&d.bus, 2, 0x1017, 0, false, T).await.unwrap(), vec![0xE8, 0x03]);
    let seg: Vec<u8> = (0..50).collect();
    download(&d.bus, 2, 0x2000, 0, seg.clone(), false, T).await.unwrap();
    assert_eq!(upload(&d.bus, 2, 0x2000, 0, false, T).await.unwrap(), seg);
    let blk: Vec<u8> = (0..255).rev().collect();
    download(&d.bus, 3, 0x2000, 0, blk.clone(), true, T).await.unwrap();
    assert_eq!(upload(&d.bus, 3, 0x2000, 0, true, T).await.unwrap(), blk);
}

#[tokio::test(start_paused = true)]
async fn sdo_aborts_carry_the_servers_code() {
    let d = demo();
    let e = upload(&d.bus, 2, 0x2345, 0, false, T).await.unwrap_err();
    assert_eq!(e.exit_code(), 3);
    assert!(
        matches!(
            e,
            CommandError::Abort {
                code: 0x0602_0000,
                by_server: true,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("Object does not exist"), "{e}");
    let e = download(&d.bus, 2, 0x6041, 0, vec![0, 0], false, T).await.unwrap_err();
    assert!(matches!(e, CommandError::Abort { code: 0x0601_0002, .. }), "{e:?}");
    let e = download(&d.bus, 2, 0x1018, 9, vec![0; 4], true, T).await.unwrap_err();
    assert!(matches!(e, CommandError::Abort { code: 0x0609_0011, .. }), "{e:?}");
    let e = download(&d.bus, 2, 0x6040, 0, vec![1, 2, 3, 4, 5], false, T)
        .await
        .unwrap_err();
    assert!(matches!(e, CommandError::Abort { code: 0x0607_0012, .. }), "{e:?}");
    assert_eq!(e.to_json()["abort_code"], 0x0607_0012);
    assert_eq!(
        e.to_json()["abort_text"],
        "Data type does not match, length of service parameter too high"
    );
}

#[tokio::test(start_paused = true)]
async fn sdo_to_a_missing_node_times_out() {
    let d = demo();
    let e = upload(&d.bus, 9, 0x1000, 0, false, 200).await.unwrap_err();
    assert_eq!(e.exit_code(), 4);
    assert!(e.to_string().contains("node 9 did not answer within 200 ms"), "{e}");
}

#[tokio::test(start_paused = true)]
async fn enable_disable_quick_stop_and_fault_reset() {
    let d = demo();
    let r = drive(&d.bus, 2, DriveAction::Enable, T).await.unwrap();
    assert_eq!(r.state, DriveState::OperationEnabled);
    assert_eq!(
        r.steps.iter().map(|s| s.controlword).collect::<Vec<_>>(),
        vec![6, 7, 0x0F]
    );
    assert_eq!(r.report().statusword, "0x1637");
    let r = drive(&d.bus, 2, DriveAction::QuickStop, T).await.unwrap();
    assert_eq!(r.state, DriveState::QuickStopActive);
    let r = drive(&d.bus, 2, DriveAction::Enable, T).await.unwrap();
    assert_eq!(r.steps.first().map(|s| s.controlword), Some(0));
    assert_eq!(r.state, DriveState::OperationEnabled);
    let r = drive(&d.bus, 2, DriveAction::Disable, T).await.unwrap();
    assert_eq!(r.state, DriveState::ReadyToSwitchOn);
    // A fault: EMCY, Fault state; `enable` resets it first.
    let mut rx = d.bus.subscribe();
    d.sim.lock().unwrap().drive_mut(2).unwrap().inject_fault(0x2310);
    tokio::time::sleep(Duration::from_millis(50)).await;
    let r = drive(&d.bus, 2, DriveAction::Status, T).await.unwrap();
    assert_eq!(r.state, DriveState::Fault);
    assert_eq!(r.error_code, Some(0x2310));
    let r = drive(&d.bus, 2, DriveAction::Enable, T).await.unwrap();
    assert_eq!(
        r.steps.iter().map(|s| s.controlword).collect::<Vec<_>>(),
        vec![0x80, 6, 7, 0x0F]
    );
    assert_eq!(r.state, DriveState::OperationEnabled);
    let mut emcy = Vec::new();
    while let Some(Ok(f)) = rx.try_recv() {
        if f.id == 0x82 {
            emcy.push(f.payload().to_vec());
        }
    }
    assert_eq!(
        emcy,
        vec![vec![0x10, 0x23, 0x03, 0, 0, 0, 0, 0], vec![0, 0, 0, 0, 0, 0, 0, 0]]
    );
}

#[tokio::test(start_paused = true)]
async fn failures_say_why() {
    let d = demo();
    d.sim.lock().unwrap().drive_mut(3).unwrap().set_mains(false);
    let e = drive(&d.bus, 3, DriveAction::Enable, T).await.unwrap_err();
    assert_eq!(e.exit_code(), 5);
    assert!(
        e.to_string().contains("switch on (0x07) failed: voltage not enabled"),
        "{e}"
    );
    d.sim.lock().unwrap().drive_mut(3).unwrap().set_mains(true);
    drive(&d.bus, 3, DriveAction::Mode(0), T).await.unwrap();
    let e = drive(&d.bus, 3, DriveAction::Enable, T).await.unwrap_err();
    assert!(e.to_string().contains("mode not set"), "{e}");
    nmt(&d.bus, NmtAction::Stop, 3, true, 2000).await.unwrap();
    let e = drive(&d.bus, 3, DriveAction::Status, T).await.unwrap_err();
    assert!(e.to_string().contains("NMT not operational"), "{e}");
    assert!(
        e.to_json()["reason"]
            .as_str()
            .unwrap()
            .starts_with("NMT not operational")
    );
}

#[tokio::test(start_paused = true)]
async fn nmt_wait_confirms_by_heartbeat_and_boot_up() {
    let d = demo();
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let seen = nmt(&d.bus, NmtAction::PreOp, 2, true, 2000).await.unwrap();
    assert_eq!(seen.get(&2), Some(&NmtState::PreOperational));
    let seen = nmt(&d.bus, NmtAction::ResetNode, 0, true, 500).await.unwrap();
    assert_eq!(seen.keys().copied().collect::<Vec<_>>(), vec![2, 3]);
    let e = nmt(&d.bus, NmtAction::Start, 7, true, 300).await.unwrap_err();
    assert!(
        e.to_string().contains("no heartbeat showing Operational from node 7"),
        "{e}"
    );
}

#[tokio::test(start_paused = true)]
async fn operational_drives_send_pdos_on_sync_and_follow_rpdos() {
    let d = demo();
    drive(&d.bus, 2, DriveAction::Enable, T).await.unwrap();
    tokio::time::sleep(Duration::from_millis(1200)).await;
    // RPDO1: controlword 0x0F + target velocity 1000 units/s.
    let f = cotui::frame::Frame::classic(0x202, &[0x0F, 0, 0xE8, 0x03, 0, 0]);
    d.bus.send(&f).await.unwrap();
    tokio::time::sleep(Duration::from_millis(2000)).await;
    let v = upload(&d.bus, 2, 0x606C, 0, false, T).await.unwrap();
    assert_eq!(i32::from_le_bytes(v.try_into().unwrap()), 1000);
    let mut rx = d.bus.subscribe();
    tokio::time::sleep(Duration::from_millis(150)).await;
    let mut tpdo2 = None;
    while let Some(Ok(g)) = rx.try_recv() {
        if g.id == 0x282 {
            tpdo2 = Some(g);
        }
    }
    let tpdo2 = tpdo2.expect("TPDO2 after SYNC");
    let vel = i32::from_le_bytes(tpdo2.payload()[4..8].try_into().unwrap());
    assert_eq!(vel, 1000);
    let pos = i32::from_le_bytes(tpdo2.payload()[0..4].try_into().unwrap());
    assert!(pos > 1000, "position integrates velocity: {pos}");
}

#[tokio::test(start_paused = true)]
async fn listen_only_sends_nothing_whatever_the_command() {
    let d = Demo::spawn(Simulation::demo(), true);
    let mut watch = d.vbus.endpoint(true).subscribe();
    tokio::time::sleep(Duration::from_millis(50)).await;
    while watch.try_recv().is_some() {}
    let bus = &d.bus;
    let errs = [
        upload(bus, 2, 0x6041, 0, false, T).await.unwrap_err(),
        download(bus, 2, 0x6040, 0, vec![6, 0], true, T).await.unwrap_err(),
        nmt(bus, NmtAction::Start, 0, true, T).await.unwrap_err(),
        drive(bus, 2, DriveAction::Enable, T).await.unwrap_err(),
    ];
    for e in errs {
        assert_eq!(e, CommandError::Bus(BusError::ListenOnly));
        assert_eq!(e.exit_code(), 2);
    }
    // Every palette command that sends fails the same way; record only listens.
    let b = cotui::cli::bind::bindings_on(cotui::connect::DEMO, &[], &[]).unwrap();
    for line in [
        "send 601#4041600000000000",
        "send 123#R --every 10 --count 3",
        "sync --period 10 --counter 4",
        "pdo 2 send rpdo1 Controlword=0x0F --every 10",
        "nmt reset-node 0",
        "sdo read 3 0x1008 --block",
        "sdo write 3 0x2000 \"01 02\" --type octets",
        "drive 3 quick-stop",
        "drive 3 mode csv",
    ] {
        let cmd = cotui::command::parse_command(line).unwrap();
        let got = cotui::command::execute(bus, &cmd, &b).await;
        assert_eq!(got.unwrap_err(), CommandError::Bus(BusError::ListenOnly), "{line}");
    }
    let log = std::env::temp_dir().join(format!("cotui-lo-{}.log", std::process::id()));
    let rec = cotui::command::parse_command(&format!("record -o {} --count 3", log.display())).unwrap();
    let o = cotui::command::execute(bus, &rec, &b).await.unwrap();
    assert_eq!(o.json()["frames"], 3);
    std::fs::remove_file(&log).unwrap();
    // Only the simulated nodes talk: no SDO request, no RPDO, no NMT but the master's start.
    let mut seen = 0;
    while let Some(Ok(f)) = watch.try_recv() {
        seen += 1;
        assert!(!(0x600..0x680).contains(&f.id), "SDO request on the bus: {f:?}");
        assert!(
            !((0x200..0x580).contains(&f.id) && f.id & 0x80 == 0),
            "RPDO on the bus: {f:?}"
        );
        assert!(f.id != 0 || f.payload() == [1, 0], "NMT command on the bus: {f:?}");
    }
    assert!(seen > 0, "the watcher saw the nodes' traffic");
}

#[tokio::test(start_paused = true)]
async fn listen_only_scan_lists_the_nodes_heard_without_asking_them() {
    let d = Demo::spawn(Simulation::demo(), true);
    let mut watch = d.vbus.endpoint(true).subscribe();
    let nodes = cotui::command::scan::scan(&d.bus, 1500, false, T).await.unwrap();
    let found: Vec<(u8, Option<NmtState>, Option<u32>)> =
        nodes.iter().map(|n| (n.node, n.nmt, n.device_type)).collect();
    // The demo's NMT master starts every node 0.8 s after power-on, so the last
    // heartbeats of a 1.5 s listen say Operational; identity stays unknown (no SDO asked).
    assert_eq!(
        found,
        [
            (2, Some(NmtState::Operational), None),
            (3, Some(NmtState::Operational), None)
        ]
    );
    while let Some(Ok(f)) = watch.try_recv() {
        assert!(!(0x600..0x680).contains(&f.id), "an SDO request went out: {f:?}");
    }
    let probe = cotui::command::scan::scan(&d.bus, 100, true, T).await.unwrap_err();
    assert_eq!(probe, CommandError::Bus(BusError::ListenOnly));
}

#[tokio::test(start_paused = true)]
async fn our_requests_come_back_tx_and_decode_like_received_frames() {
    let d = demo();
    let mut rx = d.bus.subscribe();
    upload(&d.bus, 2, 0x6041, 0, false, T).await.unwrap();
    let mut dec = cotui::decode::Decoder::new(cotui::od::Dictionary::default(), vec![]);
    let mut seen = Vec::new();
    while let Some(Ok(f)) = rx.try_recv() {
        let decoded = dec.decode(&f);
        if f.id == 0x602 || f.id == 0x582 {
            seen.push((f.id, f.direction(), decoded.kind));
        }
    }
    use cotui::decode::Kind;
    use cotui::frame::Direction;
    assert_eq!(
        seen,
        vec![(0x602, Direction::Tx, Kind::SdoRx), (0x582, Direction::Rx, Kind::SdoTx)]
    );
}

#[tokio::test(start_paused = true)]
async fn palette_lines_run_through_execute() {
    let d = demo();
    let b = cotui::od::bind::Bindings::new();
    let run = |line: &str| cotui::command::parse_command(line).unwrap();
    let o = cotui::command::execute(&d.bus, &run("sdo read 2 statusword"), &b)
        .await
        .unwrap();
    assert_eq!(o.json()["value"], 0x0250);
    assert_eq!(
        o.text,
        "node 2 0x6041:00 Statusword = 0x0250 (Switch on disabled [voltage enabled, switch on disabled, remote]) (data 5002)"
    );
    let o = cotui::command::execute(&d.bus, &run("sdo write 2 \"Target velocity\" -500"), &b)
        .await
        .unwrap();
    assert_eq!(o.json()["data"], "0CFEFFFF");
    let o = cotui::command::execute(&d.bus, &run("drive 2 enable"), &b)
        .await
        .unwrap();
    assert!(
        o.text.starts_with("node 2: Operation enabled (statusword 0x"),
        "{}",
        o.text
    );
    let e = cotui::command::execute(&d.bus, &run("sdo write 2 0x2000 12"), &b)
        .await
        .unwrap_err();
    assert!(e.to_string().contains("give --type"), "{e}");
}

/// The frames `rx` has queued.
fn drain(rx: &mut cotui::bus::Subscription) -> Vec<cotui::frame::Frame> {
    std::iter::from_fn(|| rx.try_recv()).filter_map(Result::ok).collect()
}

/// The controlwords we wrote to `node` by SDO among `frames`.
fn controlwords_sent(frames: &[cotui::frame::Frame], node: u8) -> Vec<u16> {
    frames
        .iter()
        .filter(|f| f.direction() == cotui::frame::Direction::Tx && f.id == 0x600 + node as u32)
        .filter(|f| f.payload()[..4] == [0x2B, 0x40, 0x60, 0])
        .map(|f| u16::from_le_bytes([f.payload()[4], f.payload()[5]]))
        .collect()
}

#[tokio::test(start_paused = true)]
async fn stop_finds_every_powered_drive_whatever_enabled_it_and_confirms_each() {
    use cotui::command::stop::{StopOptions, stop};
    let d = demo();
    nmt(&d.bus, NmtAction::Start, 0, false, T).await.unwrap();
    // Node 2 enabled by the drive command, node 3 by raw controlword writes.
    drive(&d.bus, 2, DriveAction::Enable, T).await.unwrap();
    for cw in [6u16, 7, 0x0F] {
        download(&d.bus, 3, 0x6040, 0, cw.to_le_bytes().to_vec(), false, T)
            .await
            .unwrap();
    }
    tokio::time::sleep(Duration::from_millis(50)).await;
    assert_eq!(
        d.sim.lock().unwrap().drive(3).unwrap().state(),
        DriveState::OperationEnabled
    );
    let mut rx = d.bus.subscribe();
    let report = stop(&d.bus, &[], 1200, StopOptions::default()).await.unwrap();
    assert!(report.all_stopped(), "{}", report.text());
    assert_eq!(report.nodes.iter().map(|n| n.node).collect::<Vec<_>>(), [2, 3]);
    for n in &report.nodes {
        assert_eq!(n.state, Some(DriveState::SwitchOnDisabled), "{}", n.text());
        assert_eq!(n.sent, [0x0002, 0x0000]);
    }
    let text = report.text();
    assert!(text.starts_with("2 drive(s) stopped and confirmed\n"), "{text}");
    assert!(text.contains("node 3: stopped, Switch on disabled"), "{text}");
    let frames = drain(&mut rx);
    for node in [2, 3] {
        assert_eq!(
            d.sim.lock().unwrap().drive(node).unwrap().state(),
            DriveState::SwitchOnDisabled
        );
        assert_eq!(controlwords_sent(&frames, node), [0x0002, 0x0000]);
    }
    // A second stop finds nothing powered and sends no controlword.
    let mut rx = d.bus.subscribe();
    let again = stop(&d.bus, &[], 1200, StopOptions::default()).await.unwrap();
    assert!(again.nodes.is_empty() && again.idle.len() == 2, "{}", again.text());
    assert_eq!(controlwords_sent(&drain(&mut rx), 2), Vec::<u16>::new());
}

#[tokio::test(start_paused = true)]
async fn stop_waits_for_the_quick_stop_ramp_before_disabling_voltage() {
    use cotui::command::stop::{StopOptions, stop};
    let d = demo();
    nmt(&d.bus, NmtAction::Start, 0, false, T).await.unwrap();
    drive(&d.bus, 2, DriveAction::Enable, T).await.unwrap();
    download(&d.bus, 2, 0x60FF, 0, 2000i32.to_le_bytes().to_vec(), false, T)
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let mut rx = d.bus.subscribe();
    let r = stop(&d.bus, &[2], 0, StopOptions::default()).await.unwrap();
    assert!(r.all_stopped(), "{}", r.text());
    let frames = drain(&mut rx);
    assert_eq!(controlwords_sent(&frames, 2), [0x0002, 0x0000]);
    // Between the two controlwords the drive was read braking in Quick stop active: the
    // stop waited for the ramp instead of cutting the power at speed.
    let at = |cw: u8| {
        frames
            .iter()
            .position(|f| f.id == 0x602 && f.payload()[..5] == [0x2B, 0x40, 0x60, 0, cw])
    };
    let (qs, dv) = (at(2).unwrap(), at(0).unwrap());
    let braking = frames[qs..dv]
        .iter()
        .filter(|f| f.id == 0x582 && f.payload()[..4] == [0x4B, 0x41, 0x60, 0])
        .map(|f| DriveState::from_statusword(u16::from_le_bytes([f.payload()[4], f.payload()[5]])))
        .collect::<Vec<_>>();
    assert_eq!(braking.first(), Some(&DriveState::QuickStopActive), "{braking:?}");
    assert!(frames[dv].ts_ns - frames[qs].ts_ns >= 50_000_000, "the ramp took time");
    let drive = d.sim.lock().unwrap().drive(2).unwrap().state();
    assert_eq!(drive, DriveState::SwitchOnDisabled);
}

#[tokio::test(start_paused = true)]
async fn stop_of_a_silent_or_faulted_node_is_not_confirmed_and_exits_5() {
    use cotui::command::stop::{StopOptions, stop};
    let d = demo();
    nmt(&d.bus, NmtAction::Start, 0, false, T).await.unwrap();
    drive(&d.bus, 3, DriveAction::Enable, T).await.unwrap();
    d.sim.lock().unwrap().drive_mut(3).unwrap().inject_fault(0x2310);
    tokio::time::sleep(Duration::from_millis(50)).await;
    let r = stop(&d.bus, &[3, 9], 0, StopOptions::default()).await.unwrap();
    assert!(!r.all_stopped());
    let text = r.text();
    assert!(text.starts_with("2 of 2 drive(s) NOT confirmed stopped"), "{text}");
    assert!(
        text.contains("node 3: NOT confirmed stopped: in Fault (statusword 0x") && text.contains("error code 0x2310"),
        "{text}"
    );
    assert!(
        text.contains("node 9: NOT confirmed stopped: no SDO answer to controlword 0x0002 and no heartbeat"),
        "{text}"
    );
    let e = r.into_result().unwrap_err();
    assert_eq!(e.exit_code(), 5);
    let j = e.to_json();
    assert_eq!(
        (j["ok"].as_bool(), j["error"].as_str()),
        (Some(false), Some("not_stopped"))
    );
    assert_eq!(j["nodes"][1]["node"], 9);
    assert_eq!(j["nodes"][1]["stopped"], false);
}

#[tokio::test(start_paused = true)]
async fn listen_only_stop_says_nothing_can_be_sent_and_sends_nothing() {
    let d = Demo::spawn(Simulation::demo(), true);
    let mut watch = d.vbus.endpoint(true).subscribe();
    tokio::time::sleep(Duration::from_millis(50)).await;
    while watch.try_recv().is_some() {}
    let b = cotui::od::bind::Bindings::new();
    for line in ["stop", "stop 2 3"] {
        let cmd = cotui::command::parse_command(line).unwrap();
        let e = cotui::command::execute(&d.bus, &cmd, &b).await.unwrap_err();
        assert_eq!(e.exit_code(), 5, "{line}");
        assert!(e.to_string().contains("listen-only — NOTHING was sent"), "{e}");
        assert_eq!(e.to_json()["listen_only"], true);
    }
    while let Some(Ok(f)) = watch.try_recv() {
        assert!(!(0x600..0x680).contains(&f.id), "SDO request on the bus: {f:?}");
    }
}

/// A profile with a procedure that enables the drive, pauses, and enables it again.
const SLOW_PROFILE: &str = r#"{
  "format": 1,
  "name": "slow-test",
  "extends": ["cia402"],
  "procedures": {
    "slowpv": {
      "description": "enable, wait, enable again (what stop-all must cancel)",
      "steps": [
        { "sdo_write": { "object": "0x6040", "value": "0x06" } },
        { "sdo_write": { "object": "0x6040", "value": "0x07" } },
        { "sdo_write": { "object": "0x6040", "value": "0x0F" } },
        { "delay_ms": 1500 },
        { "sdo_write": { "object": "0x6040", "value": "0x06" } },
        { "sdo_write": { "object": "0x6040", "value": "0x07" } },
        { "sdo_write": { "object": "0x6040", "value": "0x0F" } }
      ]
    }
  }
}"#;

/// The TUI's live task on the demo bus (a real thread and clock): stop-all during a
/// procedure's delay cancels the procedure, stops the drive, and nothing of the procedure is
/// sent afterwards.
#[test]
fn stop_all_in_the_live_task_cancels_a_running_procedure_first() {
    use cotui::command::stop::StopOptions;
    use cotui::tui::live::{Request, start};
    use cotui::tui::source::Feed;
    use std::collections::BTreeSet;
    use std::time::Instant;
    let read = |_: &std::path::Path| Ok(SLOW_PROFILE.into());
    let mut b = cotui::od::bind::Bindings::new();
    b.bind_profile(2, "slow.json", &read).unwrap();
    let (feed, req) = start(&["demo".into()], false, b, None, Default::default());
    let command = cotui::command::parse_command("run 2 slowpv").unwrap();
    req.send(Request::Run {
        line: "run 2 slowpv".into(),
        command,
    })
    .unwrap();
    // Frames in order; the index of the stop's first controlword and of its result.
    let mut cws: Vec<(u16, bool)> = Vec::new();
    let mut results = Vec::new();
    let (mut stopped_at, mut stop_sent) = (None, false);
    let give_up = Instant::now() + Duration::from_secs(60);
    while Instant::now() < give_up {
        match feed.recv_timeout(Duration::from_millis(100)) {
            Ok(Feed::Frames { frames: batch, .. }) => {
                for f in batch {
                    let p = f.payload();
                    if f.id == 0x602 && f.direction() == cotui::frame::Direction::Tx && p[..4] == [0x2B, 0x40, 0x60, 0]
                    {
                        cws.push((u16::from_le_bytes([p[4], p[5]]), stop_sent));
                    }
                }
            }
            Ok(Feed::Result(_, text)) => results.push(text),
            Ok(Feed::Stopped(_, text, failed)) => {
                assert!(failed.is_empty(), "every drive confirmed stopped: {text}");
                results.push(text);
            }
            Ok(_) | Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(e) => panic!("feed ended: {e}"),
        }
        // Stop once the procedure's first enable went out (it is in its delay then).
        if !stop_sent && cws.iter().any(|(cw, _)| *cw == 0x0F) {
            req.send(Request::StopAll {
                nodes: BTreeSet::new(),
                options: StopOptions::default(),
            })
            .unwrap();
            stop_sent = true;
            stopped_at = Some(Instant::now());
        }
        // Watch well past the end of the procedure's delay before judging.
        if stopped_at.is_some_and(|t| t.elapsed() > Duration::from_millis(2500)) && !results.is_empty() {
            break;
        }
    }
    let after: Vec<u16> = cws.iter().filter(|(_, after)| *after).map(|(cw, _)| *cw).collect();
    assert_eq!(
        after,
        [0x0002, 0x0000],
        "only the stop's controlwords after the stop: {cws:?}"
    );
    let text = results.join("\n");
    assert!(text.contains("cancelled: run 2 slowpv"), "{text}");
    assert!(text.contains("node 2: stopped, Switch on disabled"), "{text}");
    assert!(
        !text.contains("slowpv: `slowpv`"),
        "the procedure never finished: {text}"
    );
}

#[tokio::test(start_paused = true)]
async fn scan_probe_asks_every_node_id_once_all_at_once() {
    let d = demo();
    let mut rx = d.bus.subscribe();
    let start = tokio::time::Instant::now();
    // No listening: every node is found by the probe.
    let nodes = cotui::command::scan::scan(&d.bus, 0, true, T).await.unwrap();
    let took = start.elapsed();
    let found: Vec<(u8, Option<u32>, bool)> = nodes
        .iter()
        .map(|n| (n.node, n.device_type.map(|t| t & 0xFFFF), n.identity[0].is_some()))
        .collect();
    assert_eq!(found, [(2, Some(402), true), (3, Some(402), true)]);
    // One timeout for the silent node-IDs, then the two identifications at once.
    assert!(
        took >= Duration::from_millis(T) && took < Duration::from_millis(2 * T),
        "{took:?}"
    );
    let frames = drain(&mut rx);
    for node in 1..=127u32 {
        let asks = frames
            .iter()
            .filter(|f| f.direction() == cotui::frame::Direction::Tx && f.id == 0x600 + node)
            .filter(|f| f.payload()[..4] == [0x40, 0x00, 0x10, 0])
            .count();
        assert_eq!(asks, 1, "0x1000 reads sent to node {node}");
    }
}
