//! `record --trigger` on the demo bus (tokio time paused: deterministic): a simulated drive
//! faulted through the `sim` control words fires `incident emcy` (the demo drives are not enabled, so no `drive_fault`: its EMCY is the incident), and the window file
//! holds exactly the frames a full capture of the same bus has in that window: none lost
//! between the ring and the file. The flight recorder's handle is listen-only.

use cotui::analysis::filter::NoNames;
use cotui::analysis::trigger::Trigger;
use cotui::bus::Event;
use cotui::cli::trigger::{Flight, Settings};
use cotui::cli::trigger_live::capture;
use cotui::command::record::LogFormat;
use cotui::log::{LogReader, Outcome};
use cotui::sim::Simulation;
use cotui::sim::control::Control;
use cotui::sim::demo::Demo;
use serde_json::Value;
use std::time::Duration;

#[tokio::test(start_paused = true)]
async fn a_faulted_drive_gives_a_window_with_every_frame_of_the_bus_in_it() {
    let dir = std::env::temp_dir().join(format!("cotui-trigger-live-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = Demo::spawn(Simulation::demo(), true);
    let mut all = d.bus.subscribe();
    let expr = "incident emcy";
    let settings = Settings {
        expr: expr.into(),
        pre_ms: 1000,
        post_ms: 500,
    };
    let decoder = cotui::cli::bind::decoder(&[], &[]).unwrap();
    let trigger = Trigger::parse(expr, &NoNames).unwrap();
    let mut flight = Flight::new(trigger, decoder, &settings, Some(&dir), LogFormat::Candump).unwrap();
    let fault = async {
        tokio::time::sleep(Duration::from_secs(3)).await;
        let frames = {
            let mut sim = d.sim.lock().unwrap();
            Control::parse("fault 2 0x2310")
                .unwrap()
                .apply(&mut sim, d.nodes.now_ns())
                .1
        };
        for f in frames {
            d.nodes.send(&f).await.unwrap();
        }
    };
    // One window, then stop (the capture also stops itself at 20 s if the trigger never fires).
    let (got, ()) = tokio::join!(
        capture(&d.bus, &mut flight, Some(1), Some(20_000), std::future::pending()),
        fault
    );
    let got = got.unwrap();
    assert_eq!((got.windows, got.dropped), (1, 0));
    let side = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .unwrap();
    let side: Value = serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
    assert_eq!(side["hits"][0]["what"], "incident emcy node 2", "{side}");
    assert!(
        side["diagnosis"]
            .as_array()
            .unwrap()
            .iter()
            .any(|i| i["kind"] == "emcy"),
        "{side}"
    );
    let us = |key: &str| (side[key].as_f64().unwrap() * 1e6).round() as u64;
    let (start, end) = (us("start"), us("end"));
    let file = std::fs::read(dir.join(side["file"].as_str().unwrap())).unwrap();
    let mut r = LogReader::new(&file[..]).unwrap();
    let mut window = Vec::new();
    while let Some((_, o)) = r.next_line().unwrap() {
        if let Outcome::Frame(f) = o {
            window.push((f.ts_ns / 1000, f.id, f.payload().to_vec()));
        }
    }
    // Everything the bus carried in [start, end], from a subscription of its own.
    let mut want = Vec::new();
    while let Some(Ok(e)) = all.try_next() {
        if let Event::Frame(f) = e
            && (start..=end).contains(&(f.ts_ns / 1000))
        {
            want.push((f.ts_ns / 1000, f.id, f.payload().to_vec()));
        }
    }
    assert!(want.len() > 20, "{} frames", want.len());
    assert_eq!(side["frames"].as_u64().unwrap() as usize, want.len());
    assert_eq!(window, want);
    // The EMCY of the fault is in it.
    assert!(
        window
            .iter()
            .any(|(_, id, data)| *id == 0x82 && data[..2] == [0x10, 0x23])
    );
}

/// SIGTERM during a window closes it with what it has: the file and its sidecar are whole,
/// the sidecar says the window was cut short. A trigger that does not parse says its column.
#[test]
fn sigterm_closes_the_open_window_and_a_bad_trigger_says_its_column() {
    use std::process::{Command, Stdio};
    let bin = env!("CARGO_BIN_EXE_cotui");
    let dir = std::env::temp_dir().join(format!("cotui-trigger-term-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    let args = [
        "record",
        "demo",
        "--trigger",
        "id 702",
        "--pre",
        "100ms",
        "--post",
        "1h",
        "-o",
        d,
    ];
    let child = Command::new(bin)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the window's first frames to be on disk (written at least every 100 ms).
    let log = loop {
        let found = std::fs::read_dir(&dir).ok().and_then(|r| {
            r.map(|e| e.unwrap().path())
                .find(|p| p.extension().is_some_and(|e| e == "log"))
        });
        if let Some(p) = found
            && std::fs::read_to_string(&p).unwrap().lines().count() >= 3
        {
            break p;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    // SAFETY: plain kill(2) on our own child.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("1 window(s) written to"));
    let side: Value = serde_json::from_str(&std::fs::read_to_string(log.with_extension("json")).unwrap()).unwrap();
    assert_eq!(side["cut_short"], true);
    let lines = std::fs::read_to_string(&log).unwrap().lines().count();
    assert_eq!(side["frames"].as_u64().unwrap() as usize, lines);
    assert!(side["hits"][0]["what"] == "id 702", "{side}");

    let out = Command::new(bin)
        .args(["record", "demo", "--trigger", "node 2 and sdo nonsense", "-o", d])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("column 16: unknown word `nonsense`"), "{err}");
}
