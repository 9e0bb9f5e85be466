//! The Transmit pane on the in-process demo bus: a list loaded as `--transmit FILE` does,
//! its enabled entry's frames reach the bus (seen in the trace, marked TX) and the pane's
//! count follows them; its disabled entry sends nothing; a bad entry is shown as bad.

use crate::objects_demo::demo_app;
use cotui::frame::Direction;
use cotui::tui::keymap::Action;

#[test]
fn an_enabled_entry_is_sent_on_the_demo_bus_and_counted_in_the_pane() {
    let path = std::env::temp_dir().join(format!("cotui-tx-demo-{}.json", std::process::id()));
    std::fs::write(
        &path,
        r#"{"entries": [
  {"frame": "3F1#C0FFEE", "every_ms": 20, "count": 5, "comment": "five frames"},
  {"frame": "3F2#01", "every_ms": 10, "enabled": false},
  {"frame": "3F3#XY"}
]}"#,
    )
    .unwrap();
    let mut a = demo_app();
    a.load_transmit(&path).unwrap();
    a.act(Action::PaneTransmit);
    let ours = |a: &cotui::tui::app::App, id: u32| {
        let store = &a.trace().store;
        (0..store.len())
            .map(|i| store.frame(i))
            .filter(|f| f.id == id && f.direction() == Direction::Tx)
            .map(|f| f.ts_ns)
            .collect::<Vec<u64>>()
    };
    let s = crate::screen::until_at(&mut a, (160, 30), "five frames sent", |a, s| {
        ours(a, 0x3F1).len() == 5 && s.lines().any(|l| l.contains("3F1#C0FFEE") && l.contains(" 5 "))
    });
    let ts = ours(&a, 0x3F1);
    // On the 20 ms grid, by the bus timestamps: at least 4 periods from the first to the
    // fifth (a tick missed on a busy machine is dropped, never sent in a burst). A late
    // frame may be followed closely by the next one on the grid, but never two: frames
    // k apart are at least k - 1 periods apart.
    let span_ms = (ts[4] - ts[0]) as f64 / 1e6;
    assert!((75.0..=2000.0).contains(&span_ms), "span {span_ms} ms: {ts:?}");
    for i in 0..ts.len() {
        for j in i + 2..ts.len() {
            let least = (j - i - 1) as u64 * 20_000_000 - 2_000_000;
            assert!(ts[j] - ts[i] >= least, "frames {i} and {j} in a burst: {ts:?}");
        }
    }
    assert!(ours(&a, 0x3F2).is_empty(), "the disabled entry was sent");
    assert!(s.contains("five frames"), "{s}");
    let bad = s.lines().find(|l| l.contains("3F3#XY")).unwrap_or_default();
    assert!(bad.contains("bad"), "{s}");
}
