//! The Objects pane on the in-process demo bus (the simulated drives answer SDO): find an
//! object by typing, `enter` reads it and its value shows in the row; `e` opens the palette
//! with the write command, typed; `record start`/`record stop` from the palette write the
//! frames received to a candump log that reads back.

use cotui::analysis::trace::Trace;
use cotui::decode::Decoder;
use cotui::frame::NodeKey;
use cotui::tui::app::{App, SourceInfo, SourceKind};
use cotui::tui::keymap::Keymap;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// The demo's drive: node 2 of its one bus.
const NODE2: NodeKey = NodeKey::new(0, 2);

fn key(a: &mut App, code: KeyCode) {
    a.key(KeyEvent::new(code, KeyModifiers::NONE));
}

fn typed(a: &mut App, text: &str) {
    for c in text.chars() {
        key(a, KeyCode::Char(c));
    }
}

fn screen(a: &mut App) -> String {
    crate::screen::screen_at(a, 160, 40)
}

fn until(a: &mut App, what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    crate::screen::until_at(a, (160, 40), what, f)
}

/// The TUI on the demo bus, as `cotui demo` starts it (shared with `own_reads`).
pub(crate) fn demo_app() -> App {
    let bindings = cotui::cli::bind::bindings_on("demo", &[], &[]).unwrap();
    let trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
    let (rx, req) = cotui::tui::live::start(&["demo".into()], false, bindings.clone(), None, Default::default());
    let src = SourceInfo::live("demo", SourceKind::Demo { listen_only: false }, rx, req);
    let mut a = App::new(trace, Keymap::default_map(), src);
    a.set_bindings(bindings);
    a
}

#[test]
fn objects_pane_reads_an_object_of_a_demo_drive_and_prefills_its_write() {
    let mut a = demo_app();
    until(&mut a, "node 2 to be listed", |a, _| {
        a.trace().nodes.iter().any(|(n, _)| n.node == 2)
    });
    key(&mut a, KeyCode::Char('6'));
    // Node 2 (the Nodes selection may be another node: `]` picks the next one).
    for _ in 0..4 {
        if screen(&mut a).contains("Objects · node 2 aimotor > cia402") {
            break;
        }
        key(&mut a, KeyCode::Char(']'));
    }
    let s = screen(&mut a);
    assert!(s.contains("Objects · node 2 aimotor > cia402"), "{s}");
    key(&mut a, KeyCode::Char('/'));
    typed(&mut a, "6060");
    key(&mut a, KeyCode::Enter);
    let s = until(&mut a, "the find to narrow the rows", |_, s| s.contains("find `6060`"));
    assert!(s.contains("6060:00   Modes of operation"), "{s}");
    // Nothing was read of it yet by anyone: the demo only exchanges PDOs and heartbeats.
    key(&mut a, KeyCode::Enter);
    let s = until(&mut a, "the value read", |a, _| {
        a.trace()
            .values
            .get(NODE2, 0x6060, 0)
            .and_then(|e| e.last.as_ref())
            .is_some_and(|s| s.via == cotui::analysis::values::Via::Upload)
    });
    let row = s
        .lines()
        .find(|l| l.contains("6060:00"))
        .unwrap_or_default()
        .to_string();
    let shown = a
        .trace()
        .values
        .get(NODE2, 0x6060, 0)
        .and_then(|e| e.text(a.trace().decoder().dictionary(2), 0x6060, 0))
        .unwrap();
    assert!(row.contains(&shown), "{row} / {shown}");
    assert!(row.contains(" ms"), "its age: {row}");
    let raw = a
        .trace()
        .values
        .get(NODE2, 0x6060, 0)
        .unwrap()
        .last
        .as_ref()
        .unwrap()
        .value
        .to_string();
    // `e`: the palette holds the typed write command with the value read.
    key(&mut a, KeyCode::Char('e'));
    let p = a.screen().prompt().editing.as_ref().expect("the palette is open");
    assert_eq!(p.text, format!("sdo write 2 0x6060:0x00 {raw} --type i8"));
    assert!(
        a.message().unwrap_or("").contains("will send: 602#2F606000"),
        "{:?}",
        a.message()
    );
    key(&mut a, KeyCode::Esc);
}

#[test]
fn record_start_and_stop_from_the_palette_write_the_frames_received() {
    let dir = std::env::temp_dir().join(format!("cotui-objects-rec-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("rec.log");
    let _ = std::fs::remove_file(&file);
    let mut a = demo_app();
    until(&mut a, "frames", |a, _| a.trace().len() > 10);
    a.run_command(&format!("record start {}", file.display()));
    let s = until(&mut a, "REC in the status line", |a, s| {
        a.capture().recording().is_some_and(|r| r.count() >= 50) && s.contains(&format!("REC {}", file.display()))
    });
    assert!(s.contains(" frames) |"), "{s}");
    let before = a.trace().len();
    a.run_command("record stop");
    let msg = a.message().map(str::to_string).unwrap_or_default();
    assert!(msg.starts_with("record: stopped, "), "{msg}");
    let n: u64 = msg["record: stopped, ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(a.capture().recording().is_none());
    // Whole candump -l lines, as many as said, each a frame the trace has.
    let text = std::fs::read_to_string(&file).unwrap();
    assert_eq!(text.lines().count() as u64, n);
    for l in text.lines() {
        let mut w = l.split(' ');
        let (ts, iface, frame) = (w.next().unwrap(), w.next().unwrap(), w.next().unwrap());
        assert!(ts.starts_with('(') && ts.ends_with(')'), "{l}");
        assert_eq!(iface, "demo", "{l}");
        assert!(frame.contains('#'), "{l}");
    }
    assert!(n as usize <= before);
    // An existing file is refused without --force; stop when not recording says so.
    a.run_command(&format!("record start {}", file.display()));
    assert!(
        a.message().unwrap_or("").contains("exists; --force overwrites it"),
        "{:?}",
        a.message()
    );
    a.run_command("record stop");
    assert_eq!(a.message(), Some("record: not recording"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn read_all_reads_what_drive_2_has_with_progress_and_lists_the_failures() {
    let mut a = demo_app();
    until(&mut a, "node 2 to be listed", |a, _| {
        a.trace().nodes.iter().any(|(n, _)| n.node == 2)
    });
    key(&mut a, KeyCode::Char('6'));
    for _ in 0..4 {
        if screen(&mut a).contains("Objects · node 2 aimotor > cia402") {
            break;
        }
        key(&mut a, KeyCode::Char(']'));
    }
    key(&mut a, KeyCode::Char('R'));
    let started = a.message().map(str::to_string).unwrap_or_default();
    assert!(
        started.starts_with("read all node 2: reading ")
            && started.ends_with(" objects one after the other (R again stops)"),
        "{started}"
    );
    let total = started["read all node 2: reading ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    let s = until(&mut a, "progress in the title", |_, s| s.contains(" · read all "));
    assert!(s.contains(&format!(" of {total}")), "{s}");
    until(&mut a, "the read-all to end", |a, _| {
        !a.screen().panes().objects().reading_all()
    });
    let summary = a
        .screen()
        .messages()
        .iter()
        .map(|e| e.text.clone())
        .find(|t| t.starts_with("read all node 2: ") && t.contains(" entries read, "))
        .expect("a summary in the message log");
    // Every line read was understood (the sub-index goes out in hex); the failures are the
    // node's answers: objects or sub-indexes it does not have.
    assert!(!summary.contains("unknown object"), "{summary}");
    for l in summary.lines().skip(1) {
        assert!(l.contains("does not exist"), "{l}");
    }
    // Every identity entry was read, and the drive's own objects.
    for (i, s) in [(0x1000, 0), (0x1018, 1), (0x1018, 2), (0x6060, 0), (0x2002, 1)] {
        let e = a.trace().values.get(NODE2, i, s).and_then(|e| e.last.as_ref());
        assert!(e.is_some(), "0x{i:04X}:{s:02X} read\n{summary}");
    }
}
