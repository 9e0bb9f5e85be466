//! The Watch pane on the in-process demo bus: `:watch` polls a simulated drive by SDO, the
//! rows show its values (min/max), the object it lacks as absent and asked once, the values
//! become Plot series, `export watch` writes the CSV of `cotui watch`, and stop-all ends
//! the polls: no upload request of ours after its report.

use crate::objects_demo::demo_app;
use cotui::analysis::trace::Trace;
use cotui::frame::Direction;
use cotui::tui::app::App;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// Our upload requests to node 2 for `index`, by trace position.
fn requests(t: &Trace, index: u16) -> usize {
    let store = &t.store;
    (0..store.len())
        .map(|i| store.frame(i))
        .filter(|f| f.id == 0x602 && f.direction() == Direction::Tx && f.data[0] == 0x40)
        .filter(|f| u16::from_le_bytes([f.data[1], f.data[2]]) == index)
        .count()
}

fn until(a: &mut App, what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    crate::screen::until_at(a, (200, 30), what, f)
}

#[test]
fn a_watch_on_the_demo_polls_shows_plots_exports_and_stop_all_ends_it() {
    let mut a = demo_app();
    a.run_command("watch 2 Statusword 0x6064 0x2FFF --every 50ms");
    a.key(KeyEvent::new(KeyCode::Char('0'), KeyModifiers::NONE));
    let s = until(&mut a, "five rounds polled", |a, s| {
        requests(a.trace(), 0x6064) >= 5 && s.contains("not polled again")
    });
    let row = |what: &str| s.lines().find(|l| l.contains(what)).unwrap_or_default().to_string();
    assert!(row("Statusword").contains("0x"), "{s}");
    assert!(row("0x2FFF").contains("absent"), "{s}");
    assert_eq!(requests(a.trace(), 0x2FFF), 1, "the absent object is asked once");
    // The values read are series of the Plot pane's picker.
    let keys = a.trace().series.keys();
    assert!(keys.iter().any(|k| (k.0.node, k.1, k.2) == (2, 0x6064, 0)), "{keys:?}");
    // The CSV of `cotui watch --format csv`.
    let file = std::env::temp_dir().join(format!("cotui-watch-demo-{}.csv", std::process::id()));
    std::fs::remove_file(&file).ok();
    a.run_command(&format!("export watch {}", file.display()));
    let csv = std::fs::read_to_string(&file).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0], "time_s,2:0x6041 Statusword,2:0x6064 Position actual value,2:0x2FFF",
        "{csv}"
    );
    assert!(lines.len() >= 6, "{csv}");
    assert!(lines[1].starts_with("0.000,") && lines[1].ends_with(",absent"), "{csv}");
    assert!(lines[2].ends_with(','), "not polled again: an empty cell: {csv}");
    std::fs::remove_file(&file).ok();
    // Stop-all: the polls end before the stop's report comes back, none after.
    a.key(KeyEvent::new(KeyCode::Char('s'), KeyModifiers::CONTROL));
    until(&mut a, "the stop-all report", |a, _| {
        a.screen()
            .messages()
            .iter()
            .any(|m| m.text.contains("cancelled: the Watch pane's polls"))
    });
    let (after, t_stop) = (requests(a.trace(), 0x6064), a.trace().nodes.now_ns());
    // Ten periods of bus time later, by the capture clock.
    until(&mut a, "500 ms of bus time", |a, _| {
        a.trace().nodes.now_ns() > t_stop + 500_000_000
    });
    assert_eq!(requests(a.trace(), 0x6064), after, "a poll after the stop");
    let s = until(&mut a, "the rows stopped", |_, s| s.contains("0 polled"));
    assert!(s.contains("stopped"), "{s}");
}
