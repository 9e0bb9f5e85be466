//! The Problems pane: the TUI's live diagnosis is the one `cotui diagnose` prints (every
//! golden fixture, frame by frame through the trace), and in the real binary a replayed
//! log with a fault shows its incident in tab 8, opens it, and jumps to its frames.

use crate::tmux::Session;
use cotui::analysis::trace::Trace;
use cotui::cli::bind::decoder;
use cotui::frame::json::write_line;
use cotui::log::{LogReader, Outcome};
use std::io::BufReader;
use std::process::Command;

/// The incidents of the trace's live diagnosis after every frame of `path`, as JSON lines.
fn live_diagnosis(path: &str) -> String {
    let file = std::fs::File::open(path).unwrap();
    let mut reader = LogReader::new(BufReader::new(file)).unwrap();
    // The decoder `cotui open` and `cotui diagnose` use when nothing is bound.
    let mut trace = Trace::new(decoder(&[], &[]).unwrap(), 500_000);
    while let Some((_, outcome)) = reader.next_line().unwrap() {
        if let Outcome::Frame(f) = outcome {
            for name in reader.interfaces().names() {
                trace.ifaces.intern(name);
            }
            trace.push(&f);
        }
    }
    let origin = trace.diagnosis.origin_ns();
    let mut out = Vec::new();
    for i in trace.diagnosis.incidents() {
        write_line(&mut out, &i.to_json(origin));
    }
    String::from_utf8(out).unwrap()
}

#[test]
fn the_live_diagnosis_equals_cotui_diagnose_on_every_fixture() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/diagnose");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        // Fixtures that need a profile bound are covered by the golden tests.
        if !name.ends_with(".log") || name.starts_with("profile_") {
            continue;
        }
        let path = path.to_string_lossy().to_string();
        let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["diagnose", "--format", "jsonl", &path])
            .output()
            .unwrap();
        let want = String::from_utf8(out.stdout).unwrap();
        assert!(!want.is_empty(), "{name}: cotui diagnose found nothing");
        assert_eq!(live_diagnosis(&path), want, "{name}");
        seen += 1;
    }
    assert!(seen >= 8, "only {seen} fixtures");
}

#[test]
fn a_replay_shows_a_drive_fault_and_a_silent_node_in_the_problems_pane() {
    // Node 5 faults (EMCY 0x2310, statusword 0x0008) and heartbeats stop after 1 s; the log
    // then stays quiet until one SYNC at 60 s: the replay clock finds node 5 silent while
    // the bus is quiet.
    let bin = env!("CARGO_BIN_EXE_cotui");
    let name = format!("cotui-problems-{}", std::process::id());
    let log = std::env::temp_dir().join(format!("{name}.log"));
    let mut text = String::from("(1700000000.000000) can0 705#00\n");
    for i in 1..=10u64 {
        let us = i * 100_000;
        text.push_str(&format!(
            "({}.{:06}) can0 705#05\n",
            1_700_000_000 + us / 1_000_000,
            us % 1_000_000
        ));
        if i == 3 {
            text.push_str("(1700000000.310000) can0 605#4000100000000000\n");
            text.push_str("(1700000000.311000) can0 585#4300100092010200\n");
            text.push_str("(1700000000.320000) can0 185#3702\n");
        }
        if i == 5 {
            text.push_str("(1700000000.510000) can0 085#1023030000000000\n");
            text.push_str("(1700000000.520000) can0 185#0800\n");
        }
    }
    text.push_str("(1700000060.000000) can0 080#\n");
    std::fs::write(&log, text).unwrap();
    let s = Session::start(
        &name,
        &format!("{bin} replay {}; echo cotui-exit=$?; sleep 60", log.display()),
    );
    s.keys(&["8"]);
    let t = s.wait_for("node 5 to be found silent", |t| {
        t.contains("Went silent and never came back")
    });
    assert!(t.contains("8 Problems"), "{t}");
    assert!(t.contains("OPEN      Node 5"), "{t}");
    assert!(t.contains("Stopped: continuous over-current"), "{t}");
    // Open the drive fault: its timeline names the frames, then enter shows one in the trace.
    let rows: Vec<&str> = t.lines().filter(|l| l.contains("OPEN      Node 5")).collect();
    let fault_first = rows[0].contains("over-current");
    if !fault_first {
        s.keys(&["Down"]);
    }
    s.keys(&["Enter"]);
    let t = s.wait_for("the incident opened", |t| t.contains("Check first"));
    assert!(t.contains("What happened"), "{t}");
    assert!(t.contains("#10 "), "{t}");
    s.keys(&["Escape", "t"]);
    let t = s.wait_for("the trace at the incident's first frame", |t| {
        t.contains("Trace [scrolled]")
    });
    assert!(t.contains("EMCY node 5"), "{t}");
    s.keys(&["q"]);
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    let _ = std::fs::remove_file(&log);
}
