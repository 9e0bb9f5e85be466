//! `run` on the simulated demo bus in-process (tokio time paused: deterministic): waits,
//! delays, raw frames and NMT steps, and listen-only sending nothing.

use cotui::bus::BusError;
use cotui::command::run::{plan, run};
use cotui::command::{CommandError, execute, parse_command};
use cotui::frame::Frame;
use cotui::od::bind::Bindings;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;

/// A profile whose procedures use every step kind, bound to node 2.
const PROFILE: &str = r#"{
  "format": 1,
  "name": "run-test",
  "extends": ["cia402"],
  "procedures": {
    "enable_checked": {
      "description": "enable with a wait after each controlword",
      "params": [ { "name": "speed", "default": 0 } ],
      "steps": [
        { "nmt": "start" },
        { "sdo_write": { "object": "0x60FF", "value": "speed" } },
        { "sdo_write": { "object": "0x6040", "value": "0x06" } },
        { "wait": { "object": "0x6041", "mask": "0x006F", "equals": "0x0021", "timeout_ms": 500 } },
        { "sdo_write": { "object": "0x6040", "value": "0x07" } },
        { "sdo_write": { "object": "0x6040", "value": "0x0F" } },
        { "wait": { "mask": "0x006F", "equals": "0x0027", "timeout_ms": 500 } },
        { "delay_ms": 100 },
        { "frame": { "id": "0x200 + node", "data": "0F 00 {i32:speed}" } }
      ]
    },
    "velocity": {
      "params": [ { "name": "speed" }, { "name": "accel", "default": 100 } ],
      "steps": [ { "sdo_write": { "object": "0x60FF", "value": "speed" } } ]
    },
    "start_all": {
      "steps": [ { "nmt": { "command": "start", "node": "0" } } ]
    },
    "never": {
      "steps": [ { "wait": { "object": "0x6041", "mask": "0x006F", "equals": "0x0008", "timeout_ms": 300 } } ]
    }
  }
}"#;

fn bindings() -> Bindings {
    let read = |_: &std::path::Path| Ok(PROFILE.into());
    let mut b = Bindings::new();
    b.bind_profile(2, "run-test.json", &read).unwrap();
    assert!(b.warnings().is_empty(), "{:?}", b.warnings());
    b
}

#[tokio::test(start_paused = true)]
async fn waits_delays_and_raw_frames_run_in_order() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = bindings();
    let dict = b.dictionary(2);
    let args = [("speed".to_string(), "500".to_string())];
    let p = plan(dict, 2, "enable_checked", &args).unwrap();
    let mut rx = d.bus.subscribe();
    let mut lines = Vec::new();
    let run = run(&d.bus, dict, &p, 500, &mut |l| lines.push(l.to_string()))
        .await
        .unwrap();
    let v = serde_json::to_value(run).unwrap();
    assert_eq!(v["ok"], true);
    assert_eq!(v["steps"][3]["kind"], "wait");
    assert!(
        v["steps"][6]["result"]["text"]
            .as_str()
            .unwrap()
            .contains("Operation enabled"),
        "{v}"
    );
    assert_eq!(v["steps"][8]["frame"], "202#0F00F4010000");
    assert_eq!(lines[0], "step 1/9: nmt start to node 2  [000#0102]");
    assert!(lines[1].starts_with("  -> "), "{lines:?}");
    // The raw frame went out as planned and the drive follows the RPDO it carries.
    let mut sent = Vec::new();
    while let Some(Ok(f)) = rx.try_recv() {
        if f.id == 0x202 {
            sent.push(f.payload().to_vec());
        }
    }
    assert_eq!(sent, vec![vec![0x0F, 0, 0xF4, 0x01, 0, 0]]);
}

#[tokio::test(start_paused = true)]
async fn a_wait_that_never_matches_fails_with_the_last_value_read() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = bindings();
    let dict = b.dictionary(2);
    let p = plan(dict, 2, "never", &[]).unwrap();
    let e = run(&d.bus, dict, &p, 500, &mut |_| {}).await.unwrap_err();
    assert_eq!(e.exit_code(), 5);
    let msg = e.to_string();
    assert!(msg.contains("not reached in 300 ms; last read 0x6041:00 = "), "{msg}");
    assert!(msg.contains("Switch on disabled"), "{msg}");
    assert_eq!(e.to_json()["failed_step"], 1);
}

#[tokio::test(start_paused = true)]
async fn listen_only_sends_nothing() {
    let d = Demo::spawn(Simulation::demo(), true);
    let mut watch = d.vbus.endpoint(false).subscribe();
    let b = bindings();
    let dict = b.dictionary(2);
    let p = plan(dict, 2, "enable_checked", &[]).unwrap();
    let mut lines = Vec::new();
    let e = run(&d.bus, dict, &p, 500, &mut |l| lines.push(l.to_string()))
        .await
        .unwrap_err();
    assert_eq!(e, CommandError::Bus(BusError::ListenOnly));
    assert!(lines.is_empty(), "{lines:?}");
    tokio::time::sleep(std::time::Duration::from_millis(200)).await;
    let mut ours: Vec<Frame> = Vec::new();
    while let Some(Ok(f)) = watch.try_recv() {
        if f.id == 0x000 || f.id == 0x602 || f.id == 0x202 {
            ours.push(f);
        }
    }
    assert!(ours.is_empty(), "{ours:?}");
}

#[tokio::test(start_paused = true)]
async fn the_palette_runs_a_line_and_shows_the_summary_first() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = bindings();
    let cmd = parse_command("run 2 enable_checked speed=5").unwrap();
    let o = execute(&d.bus, &cmd, &b).await.unwrap();
    let lines: Vec<&str> = o.text.lines().collect();
    assert_eq!(lines[0], "`enable_checked` on node 2: 9 steps done");
    assert_eq!(lines[1], "step 1/9: nmt start to node 2  [000#0102]");
    assert_eq!(o.json()["steps"][1]["frame"], "602#23FF600005000000");
    let cmd = parse_command("run 2 enable_checked --dry-run").unwrap();
    let o = execute(&d.bus, &cmd, &b).await.unwrap();
    assert!(
        o.text
            .starts_with("dry run of `enable_checked` on node 2: 9 steps, nothing sent\n")
    );
}

#[test]
fn palette_preview_names_waits_and_asks_before_a_broadcast() {
    let b = bindings();
    let p = cotui::tui::palette::plan("run 2 enable_checked speed=1", &b, |_| None).unwrap();
    assert!(
        p.preview.contains(
            "602#2B40600006000000, wait until 0x6041:00 Statusword & 0x006F == 0x0021 (at most 500 ms), 602#2B40600007000000"
        ),
        "{}",
        p.preview
    );
    assert!(p.preview.ends_with("delay 100 ms, 202#0F0001000000"), "{}", p.preview);
    assert_eq!(p.confirm, None);
    let p = cotui::tui::palette::plan("run 2 start_all", &b, |_| None).unwrap();
    assert_eq!(p.preview, "000#0100");
    assert_eq!(p.confirm.as_deref(), Some("`start_all` sends nmt start to all nodes"));
}

#[test]
fn a_required_parameter_must_be_given() {
    let b = bindings();
    let dict = b.dictionary(2);
    assert_eq!(
        plan(dict, 2, "velocity", &[]).unwrap_err().to_string(),
        "`velocity` needs speed=VALUE; its parameters: speed=(required), accel=100"
    );
    let p = plan(dict, 2, "velocity", &[("speed".into(), "-1".into())]).unwrap();
    assert_eq!(p.params, vec![("speed".to_string(), -1), ("accel".to_string(), 100)]);
    assert_eq!(p.steps[0].frame.as_deref(), Some("602#23FF6000FFFFFFFF"));
}
