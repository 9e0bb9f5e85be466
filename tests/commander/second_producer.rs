//! `sync` and `nmt` listen before they send: on the demo bus (its SYNC producer every 100 ms,
//! its NMT master's start of all nodes 0.8 s after power-on) they refuse with exit 2, naming
//! what they heard and sending nothing, and `--force` sends anyway and reports it. Through
//! the library on one demo bus (tokio time paused) and through the real binary.

use crate::run::cotui;
use cotui::bus::{Bus, Subscription};
use cotui::command::{CommandError, execute, parse_command};
use cotui::frame::{Direction, Frame};
use cotui::od::bind::Bindings;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;

/// The ids of the frames this handle sent, seen on `rx` until a marker frame it sends now
/// (so every frame sent before the marker has been seen, without waiting on a clock).
async fn sent_ids(bus: &Bus, rx: &mut Subscription) -> Vec<u32> {
    bus.send(&Frame::classic(0x7FF, &[0xEE])).await.unwrap();
    let mut ids = Vec::new();
    loop {
        let f = rx.recv().await.unwrap();
        if f.direction() != Direction::Tx {
            continue;
        }
        if f.id == 0x7FF {
            return ids;
        }
        ids.push(f.id);
    }
}

async fn run(d: &Demo, line: &str) -> Result<serde_json::Value, CommandError> {
    let b = Bindings::new();
    execute(&d.bus, &parse_command(line).unwrap(), &b)
        .await
        .map(|o| o.json())
}

#[tokio::test(start_paused = true)]
async fn sync_refuses_beside_the_demos_sync_producer_and_force_sends() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut rx = d.bus.subscribe();
    let e = run(&d, "sync --period 10 --count 2").await.unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let text = e.to_string();
    assert!(
        text.starts_with("refused, nothing sent: another SYNC producer is on the bus: 0x080 heard "),
        "{text}"
    );
    assert!(text.contains(" ms of listening, the last "), "{text}");
    assert!(
        text.ends_with("; --force sends anyway, --listen 0 skips listening"),
        "{text}"
    );
    let json = e.to_json();
    assert_eq!(json["error"], "other_producer");
    assert_eq!(json["other_producer"]["cob_id"], 0x080);
    assert_eq!(json["other_producer"]["producer"], "SYNC producer");
    assert_eq!(json["other_producer"]["listened_ms"], 300);
    assert!(json["other_producer"]["heard"].as_u64().unwrap() >= 2, "{json}");
    assert_eq!(sent_ids(&d.bus, &mut rx).await, Vec::<u32>::new());

    let sent = run(&d, "sync --period 10 --count 2 --force").await.unwrap();
    assert_eq!(sent["count"], 2);
    assert_eq!(sent["other_producer"]["cob_id"], 0x080);
    assert_eq!(sent_ids(&d.bus, &mut rx).await, [0x080, 0x080]);

    // --listen 0 does not listen: nothing heard, sent.
    let sent = run(&d, "sync --period 10 --count 1 --listen 0").await.unwrap();
    assert_eq!(sent["other_producer"], serde_json::Value::Null);
    assert_eq!(sent_ids(&d.bus, &mut rx).await, [0x080]);
}

#[tokio::test(start_paused = true)]
async fn a_stop_while_listening_ends_the_command_at_once_with_nothing_sent() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut rx = d.bus.subscribe();
    let b = Bindings::new();
    for line in [
        "sync --period 10 --listen 5s --force",
        "nmt start 2 --listen 5s --force",
    ] {
        // Ctrl-C 150 ms into a 5 s window: no waiting for the window, even with --force.
        let stop = tokio::time::sleep(std::time::Duration::from_millis(150));
        let cmd = parse_command(line).unwrap();
        let e = cotui::command::execute_until(&d.bus, &cmd, &b, Default::default(), stop)
            .await
            .unwrap_err();
        assert_eq!(e.exit_code(), 2, "{line}");
        let j = e.to_json();
        assert_eq!(j["error"], "stopped", "{line}: {j}");
        assert_eq!(j["listened_ms"], 150, "{line}: {j}");
        assert!(e.to_string().ends_with("before sending: nothing sent"), "{e}");
        assert_eq!(sent_ids(&d.bus, &mut rx).await, Vec::<u32>::new(), "{line}");
    }
}

#[tokio::test(start_paused = true)]
async fn nmt_refuses_when_the_demos_nmt_master_is_heard_and_force_sends() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut rx = d.bus.subscribe();
    // The master's start at 0.8 s falls inside 2 s of listening.
    let e = run(&d, "nmt start 2 --listen 2s").await.unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let text = e.to_string();
    assert!(
        text.starts_with(
            "refused, nothing sent: another NMT master is on the bus: 0x000 heard 1 time in 2000 ms of listening, the last 8"
        ),
        "{text}"
    );
    assert_eq!(e.to_json()["other_producer"]["heard"], 1);
    assert_eq!(sent_ids(&d.bus, &mut rx).await, Vec::<u32>::new());

    // Once: 300 ms later on, nobody else commands; sent.
    let sent = run(&d, "nmt preop 2").await.unwrap();
    assert_eq!(sent["other_producer"], serde_json::Value::Null);
    assert_eq!(sent_ids(&d.bus, &mut rx).await, [0x000]);
}

#[tokio::test(start_paused = true)]
async fn nmt_force_sends_and_reports_the_other_master() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut rx = d.bus.subscribe();
    let sent = run(&d, "nmt stop 2 --listen 2s --force").await.unwrap();
    let other = &sent["other_producer"];
    assert_eq!((other["cob_id"].as_u64(), other["heard"].as_u64()), (Some(0), Some(1)));
    assert_eq!(other["producer"], "NMT master");
    assert_eq!(sent_ids(&d.bus, &mut rx).await, [0x000]);
}

#[tokio::test(start_paused = true)]
async fn listen_only_refuses_before_listening() {
    let d = Demo::spawn(Simulation::demo(), true);
    // The NMT master would be heard in 2 s; listen-only is what refuses.
    for line in ["nmt start 2 --listen 2s", "sync --period 10 --count 1"] {
        let e = run(&d, line).await.unwrap_err();
        assert_eq!(e, CommandError::Bus(cotui::bus::BusError::ListenOnly), "{line}");
    }
}

#[test]
fn the_command_line_refuses_with_exit_2_and_force_sends() {
    let (rc, out, err) = cotui(&["sync", "demo", "--period", "10", "--count", "1"]);
    assert_eq!((rc, out.as_str()), (2, ""), "{err}");
    assert!(
        err.starts_with("cotui sync: refused, nothing sent: another SYNC producer is on the bus: 0x080 heard "),
        "{err}"
    );
    let (rc, out, err) = cotui(&["sync", "demo", "--period", "10", "--count", "1", "--force"]);
    assert_eq!(rc, 0, "{err}");
    assert!(out.starts_with("SYNC 080: 1 frame sent"), "{out}");
    assert!(
        out.contains("\nsent anyway (--force): another SYNC producer is on the bus: 0x080 heard "),
        "{out}"
    );
}
