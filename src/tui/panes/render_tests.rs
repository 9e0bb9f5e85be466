//! Rendering tests: every pane on a fixed capture, snapshotted with TestBackend.

use super::testutil::{app, app_of_log, screen};
use crate::tui::keymap::Action;
use crate::tui::panes::Pane;

#[test]
fn trace_pane_shows_decoded_rows_and_the_status_bar() {
    let mut a = app();
    let s = screen(&mut a, 140, 30);
    assert!(s.contains("Trace [follow]"), "{s}");
    assert!(s.contains("Heartbeat node 2: Pre-operational"), "{s}");
    assert!(s.contains("register 0x11 [generic, communication]"), "{s}");
    assert!(s.contains("open test.log (end) | 44 frames"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn scrolled_back_trace_keeps_a_tail_strip_of_the_newest_frames() {
    let mut a = app();
    let _ = screen(&mut a, 140, 20);
    a.act(Action::Top);
    let s = screen(&mut a, 140, 20);
    assert!(s.contains("Trace [scrolled]"), "{s}");
    assert!(s.contains("── newest"), "{s}");
    assert!(s.contains("EMCY node 2"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn nodes_pane_shows_states_heartbeat_and_emcy() {
    let mut a = app();
    a.screen_mut().focus_on(Pane::Nodes);
    let s = screen(&mut a, 160, 14);
    assert!(s.contains("Operational"), "{s}");
    assert!(s.contains("Pre-operational"), "{s}");
    assert!(s.contains("Operation enabled"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn nodes_pane_marks_a_silent_node_lost_in_red_with_its_age() {
    let mut a = app();
    a.screen_mut().focus_on(Pane::Nodes);
    // 100 ms later node 1 (0x1017 = 100 ms, read by SDO) is on time; node 2 (every 14 ms,
    // measured) was due 21 ms after its last heartbeat.
    let mut f = crate::frame::Frame::classic(0x701, &[0x05]);
    f.ts_ns = a.trace().nodes.now_ns() + 100_000_000;
    a.capture_mut().trace_mut().push(&f);
    let s = screen(&mut a, 160, 14);
    assert!(s.contains("  1 Operational       14/100 ms"), "{s}");
    assert!(
        s.contains("  2 LOST 0.1 s          14/? ms  103.0 ms    1    1 -"),
        "{s}"
    );
    // At 160 columns the profile shows; the frame rate gives way first.
    assert!(s.contains("last emcy      profile"), "{s}");
    assert!(!s.lines().nth(2).unwrap_or("").contains("fr/s"), "{s}");
    insta::assert_snapshot!(s);
    // The whole row is white on red, in the main pane and in the compact list.
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(160, 14)).unwrap();
    term.draw(|fr| crate::tui::ui::draw(fr, &mut a)).unwrap();
    let buf = term.backend().buffer().clone();
    let lost_cells: Vec<(u16, u16)> = (0..buf.area.height)
        .flat_map(|y| (0..buf.area.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            buf[(x, y)].symbol() == "L"
                && buf[(x + 1, y)].symbol() == "O"
                && buf[(x + 2, y)].symbol() == "S"
                && buf[(x + 3, y)].symbol() == "T"
        })
        .collect();
    assert_eq!(lost_cells.len(), 2, "{s}");
    for (x, y) in lost_cells {
        assert_eq!(buf[(x, y)].bg, ratatui::style::Color::Red);
        assert_eq!(buf[(x, y)].fg, ratatui::style::Color::White);
    }
}

/// A capture of two buses, each with a node 5 (tests/fixtures/two_buses.log): node 5 on
/// can1 goes silent for good while node 5 on can0 goes on.
fn two_bus_app() -> crate::tui::app::App {
    use crate::decode::Decoder;
    use crate::od::Dictionary;
    two_bus_app_with(Decoder::new(Dictionary::default(), Vec::new()))
}

/// [`two_bus_app`] decoding with `decoder`.
fn two_bus_app_with(decoder: crate::decode::Decoder) -> crate::tui::app::App {
    log_app("two_buses.log", decoder)
}

/// An app holding the candump log `tests/fixtures/NAME`, read to its end.
fn log_app(name: &str, decoder: crate::decode::Decoder) -> crate::tui::app::App {
    use crate::analysis::trace::Trace;
    use crate::tui::app::{SourceInfo, SourceKind};
    let mut trace = Trace::new(decoder, 500_000);
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    for line in text.lines() {
        let mut ifaces = std::mem::take(&mut trace.ifaces);
        if let Ok(crate::log::Line::Frame(f)) = crate::log::candump::parse_line(line.as_bytes(), &mut ifaces) {
            trace.ifaces = ifaces;
            trace.push(&f);
        } else {
            trace.ifaces = ifaces;
        }
    }
    let (_tx, rx) = std::sync::mpsc::channel();
    let mut src = SourceInfo::new(name, SourceKind::Open, rx, None);
    src.done = true;
    crate::tui::app::App::new(trace, crate::tui::keymap::Keymap::default_map(), src)
}

/// tests/fixtures/sync_cycles.log: SYNC every 10 ms (one period of 12.5 ms), TPDO1 of
/// nodes 1 and 2 synchronous, a window of 2000 µs from the second cycle on, one TPDO late
/// in the second and in the fifth cycle.
#[test]
fn sync_cycles_show_lanes_per_tpdo_and_the_keys_jump_to_the_slowest_and_late_cycles() {
    use crate::decode::Decoder;
    use crate::od::Dictionary;
    let mut a = log_app("sync_cycles.log", Decoder::new(Dictionary::default(), Vec::new()));
    a.act(Action::SyncCycles);
    assert_eq!(a.focus(), Pane::Stats, "the cycles key brings the Stats pane up");
    let s = screen(&mut a, 120, 20);
    assert!(
        s.contains("SYNC cycles: 6, period mean 10.500 ms, slowest 12.500 ms, 2 late TPDOs in 2 cycles"),
        "{s}"
    );
    assert!(s.contains("   start s  period ms  ctr late      181     182"), "{s}");
    assert!(s.contains("     0.020     10.000    2    1     +400  +3500!"), "{s}");
    assert!(s.contains("     0.052     10.000    5    1   +2600!    +900"), "{s}");
    assert!(
        s.contains("     0.062          -    6    0     +400    +900"),
        "the last cycle: {s}"
    );
    // TPDO2 of node 1 is event-driven: no lane.
    assert!(!s.contains("281"), "{s}");
    insta::assert_snapshot!("sync_cycles_120x20", s);
    let row = |a: &crate::tui::app::App| match a.selected() {
        Some(crate::tui::panes::Selected::Frame(p)) => p,
        other => panic!("{other:?}"),
    };
    // The slowest cycle (12.5 ms) opens with the SYNC at frame 19 (0-based position).
    a.act(Action::SlowestCycle);
    let sync = |a: &crate::tui::app::App, pos: usize| a.trace().store.frame(pos).id;
    let slow = row(&a);
    assert_eq!((slow, sync(&a, slow)), (19, 0x080));
    // The Trace pane's selection went to that SYNC, the focus stayed.
    assert_eq!((a.focus(), a.selected_position()), (Pane::Stats, Some(19)));
    // Detail shows the selected cycle's SYNC.
    let s = screen(&mut a, 120, 20);
    assert!(s.contains("SYNC counter 4"), "{s}");
    // The late jumps: the second cycle, the fifth, then round again.
    let mut late = Vec::new();
    for _ in 0..3 {
        a.act(Action::NextLateCycle);
        late.push(row(&a));
    }
    assert_eq!(late, [11, 22, 11]);
    // Enter shows the selected cycle's SYNC frame in the trace.
    a.act(Action::Expand);
    assert_eq!(a.focus(), Pane::Trace);
    assert_eq!(a.selected_position(), Some(11));
    // The cycles key again: the receive list.
    a.act(Action::SyncCycles);
    assert!(screen(&mut a, 120, 20).contains("Receive list by cob-id"));
}

#[test]
fn nodes_pane_shows_node_5_of_each_interface_with_its_interface() {
    let mut a = two_bus_app();
    a.screen_mut().focus_on(Pane::Nodes);
    let s = screen(&mut a, 160, 14);
    assert!(s.contains("iface  id nmt"), "{s}");
    let row = |iface: &str| {
        s.lines()
            .find(|l| l.contains(&format!("{iface}    5 ")))
            .unwrap_or_else(|| panic!("no row of node 5 on {iface}: {s}"))
            .to_string()
    };
    assert!(row("can0").contains("Operational"), "{s}");
    assert!(row("can1").contains("LOST"), "{s}");
    // can0 rows come first, then can1's.
    let at = |needle: &str| s.find(needle).unwrap();
    assert!(at("can0    5 ") < at("can1    5 "), "{s}");
}

#[test]
fn sdo_pane_names_the_interface_of_each_transfer_when_there_are_several() {
    let mut a = two_bus_app();
    a.capture_mut().trace_mut().end_of_input();
    a.screen_mut().focus_on(Pane::Sdo);
    let s = screen(&mut a, 160, 14);
    assert!(s.contains("iface       time  nd"), "{s}");
    // The request on can0 is never answered there: its "answer" came on can1.
    let row = |iface: &str| {
        s.lines()
            .find(|l| l.contains(&format!("┃{iface} ")) && l.contains("6041:00"))
            .unwrap_or_else(|| panic!("no 6041 row on {iface}: {s}"))
            .to_string()
    };
    assert!(row("can0").contains("incomplete"), "{s}");
    assert!(row("can1").contains(" ok"), "{s}");
}

#[test]
fn sdo_pane_lists_transfers_and_expands_to_frames() {
    let mut a = app();
    a.screen_mut().focus_on(Pane::Sdo);
    let s = screen(&mut a, 140, 14);
    assert!(s.contains("1017:00"), "{s}");
    assert!(s.contains("abort 06020000"), "{s}");
    insta::assert_snapshot!("sdo_list", s);
    // The list follows the newest transfer; the first is opened from the top.
    a.act(Action::Top);
    a.act(Action::Expand);
    let s = screen(&mut a, 140, 14);
    assert!(s.contains("SDO transfer 1017:00 node 1"), "{s}");
    // Detail shows the selected frame of the transfer, not the newest frame of the trace.
    assert!(s.contains("frame 4  t 0.007000 s"), "{s}");
    insta::assert_snapshot!("sdo_expanded", s);
    a.act(Action::Down);
    let s = screen(&mut a, 140, 14);
    assert!(s.contains("frame 5  t 0.008000 s"), "{s}");
}

/// One expedited read of 0x1018:sub from node 1, `dt_ms` after the newest frame.
fn read_identity(a: &mut crate::tui::app::App, sub: u8, dt_ms: u64) {
    let t = a.trace().store.packed(a.trace().len() - 1).ts_ns + dt_ms * 1_000_000;
    for (i, (id, data)) in [
        (0x601, [0x40, 0x18, 0x10, sub, 0, 0, 0, 0]),
        (0x581, [0x43, 0x18, 0x10, sub, 0x78, 0x56, 0x34, 0x12]),
    ]
    .into_iter()
    .enumerate()
    {
        let mut f = crate::frame::Frame::classic(id, &data);
        f.ts_ns = t + i as u64 * 1_000_000;
        a.capture_mut().trace_mut().push(&f);
    }
}

/// The selected row of the SDO pane (drawn reversed).
fn selected_sdo_row(a: &mut crate::tui::app::App) -> String {
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(140, 16)).unwrap();
    term.draw(|f| crate::tui::ui::draw(f, a)).unwrap();
    let buf = term.backend().buffer().clone();
    let rows: Vec<String> = (0..buf.area.height)
        .filter(|&y| buf[(5, y)].modifier.contains(ratatui::style::Modifier::REVERSED))
        .map(|y| (0..100).map(|x| buf[(x, y)].symbol().to_string()).collect())
        .collect();
    assert_eq!(rows.len(), 1, "{rows:?}");
    rows[0].clone()
}

#[test]
fn the_sdo_pane_has_a_time_column_and_follows_the_newest_transfer_until_scrolled() {
    let mut a = app();
    a.screen_mut().focus_on(Pane::Sdo);
    let s = screen(&mut a, 140, 16);
    // Trace time, as the trace pane counts it: the 0x1017 read is frame 4, at 0.007 s.
    assert!(s.contains("      time  nd dir   object"), "{s}");
    assert!(s.contains("     0.007   1 read  1017:00"), "{s}");
    assert!(selected_sdo_row(&mut a).contains("6041:00"));
    // A new transfer comes: the selection goes with it.
    read_identity(&mut a, 1, 100);
    let row = selected_sdo_row(&mut a);
    assert!(row.contains("     0.204   1 read  1018:01"), "{row}");
    // Scrolled up, the selection stays where the user put it while transfers come.
    a.act(Action::Up);
    read_identity(&mut a, 2, 10);
    assert!(selected_sdo_row(&mut a).contains("6041:00"));
    assert!(screen(&mut a, 140, 16).contains("1018:02"));
    // `end` follows again.
    a.act(Action::Bottom);
    read_identity(&mut a, 3, 10);
    assert!(selected_sdo_row(&mut a).contains("1018:03"));
}

#[test]
fn at_80x24_enter_toggles_the_detail_pane_below_the_trace() {
    let mut a = app();
    let s = screen(&mut a, 80, 24);
    assert!(!s.contains("Detail"), "{s}");
    a.run_command("goto 5");
    a.act(Action::Expand);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("Detail"), "{s}");
    assert!(s.contains("frame 5  t 0.008000 s"), "{s}");
    assert!(s.contains("bits 7-5 scs = 2"), "{s}");
    insta::assert_snapshot!(s);
    // The selection moves under it; esc closes it.
    a.act(Action::Down);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("frame 6  t 0.009000 s"), "{s}");
    a.act(Action::Back);
    let s = screen(&mut a, 80, 24);
    assert!(!s.contains("Detail"), "{s}");
}

#[test]
fn at_80x24_the_detail_pane_follows_the_sdo_pane_selection() {
    let mut a = app();
    let _ = screen(&mut a, 80, 24);
    a.act(Action::Expand);
    a.act(Action::PaneSdo);
    let s = screen(&mut a, 80, 24);
    // The newest transfer is selected (the pane follows), then the first.
    assert!(s.contains("Upload 0x6041:00"), "{s}");
    a.act(Action::Top);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("Upload 0x1017:00"), "{s}");
    a.act(Action::Expand);
    a.act(Action::Down);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("SDO transfer 1017:00 node 1"), "{s}");
    assert!(s.contains("frame 5  t 0.008000 s"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn detail_pane_breaks_the_selected_frame_into_fields() {
    let mut a = app();
    a.run_command("goto 5");
    let s = screen(&mut a, 150, 30);
    assert!(s.contains("bits 7-5 scs = 2"), "{s}");
    insta::assert_snapshot!(s);
}

/// canworks' example frame in the Detail pane: the identifier split, then the frame on the
/// wire field by field with its 3 stuff bits and figures.
#[test]
fn detail_pane_shows_the_frame_on_the_wire() {
    let mut a = app();
    let mut f = crate::frame::Frame::classic(0x185, &[0x25, 0x00, 0xEA, 0x00]);
    f.ts_ns = a.trace().nodes.now_ns() + 1_000_000;
    a.capture_mut().trace_mut().push(&f);
    a.run_command("goto 45");
    let s = screen(&mut a, 150, 40);
    assert!(s.contains("0x185 = 3 x 0x80 + 5: TPDO1 node 5"), "{s}");
    // (The figures wrap at the pane's width.)
    assert!(s.contains("on the wire: 79 bits (+ 3 intermission),"), "{s}");
    assert!(s.contains("3 stuff bits, CRC-15 0x47DC, 158.0 µs at"), "{s}");
    assert!(s.contains("SOF 0  ID 00110000101  RTR 0  IDE 0  r0"), "{s}");
    insta::assert_snapshot!(s);
    // The 3 stuff bits are the only highlighted (yellow) bits.
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(150, 40)).unwrap();
    term.draw(|fr| crate::tui::ui::draw(fr, &mut a)).unwrap();
    let buf = term.backend().buffer().clone();
    let stuffed: Vec<&str> = buf
        .content()
        .iter()
        .filter(|c| c.fg == ratatui::style::Color::Yellow && matches!(c.symbol(), "0" | "1"))
        .map(|c| c.symbol())
        .collect();
    assert_eq!(stuffed, ["1", "1", "0"], "{s}");
}

#[test]
fn detail_pane_shows_statusword_bits_of_a_mapped_pdo() {
    let mut a = app();
    a.run_command("search kind tpdo");
    let s = screen(&mut a, 150, 30);
    assert!(s.contains("0x6041:00"), "{s}");
    assert!(s.contains("0000001000110011b Switched on"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn stats_pane_shows_rates_and_bus_load() {
    let mut a = app();
    a.screen_mut().focus_on(Pane::Stats);
    let s = screen(&mut a, 140, 24);
    assert!(s.contains("bus load"), "{s}");
    assert!(s.contains("701"), "{s}");
    insta::assert_snapshot!(s);
}

/// A live session on a vcan (no bit rate): the load is counted at 500 kbit/s assumed, and
/// the Stats pane says why; on a configured interface it says whose rate it is.
#[test]
fn stats_pane_says_where_the_bit_rate_came_from() {
    use crate::output::busload::Bitrate;
    let frames = super::testutil::frames();
    let vcan = Bitrate::of_live(None, &[("vcan0", Err("reports no bit rate".to_string()))]);
    let mut a = super::testutil::app_at(&frames, vcan);
    a.screen_mut().focus_on(Pane::Stats);
    let s = screen(&mut a, 160, 12);
    assert!(
        s.contains("bus load 0.7% at 500 kbit/s (assumed: vcan0 reports no bit rate), 44 fr"),
        "{s}"
    );
    let can0 = Bitrate::of_live(None, &[("can0", Ok(250_000))]);
    let mut a = super::testutil::app_at(&frames, can0);
    a.screen_mut().focus_on(Pane::Stats);
    let s = screen(&mut a, 160, 12);
    assert!(s.contains("bus load 1.4% at 250 kbit/s (of can0), 44 fr"), "{s}");
}

#[test]
fn receive_list_shows_latest_data_periods_and_labels_sorted_by_a_key() {
    let mut a = app();
    a.act(Action::Sort);
    assert_eq!(a.focus(), Pane::Stats, "the sort key brings the receive list up");
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("Receive list by count"), "{s}");
    // 0x701 (7 heartbeats) first; its latest data and label.
    assert!(
        s.contains("701    67.3    4 ms   16.7 ms  05                       Heartbeat node 1: Ope…"),
        "{s}"
    );
    insta::assert_snapshot!("receive_list_by_count_80x24", s);
    a.act(Action::Sort);
    a.act(Action::Sort);
    let s = screen(&mut a, 160, 48);
    assert!(s.contains("Receive list by last heard"), "{s}");
    assert!(s.contains("count rate/s     age    period    jitter"), "wide: {s}");
    let first = s.lines().nth(3).unwrap_or("");
    assert!(first.contains("082  "), "the EMCY came last: {s}");
    // The Detail pane shows the selected COB-ID's latest frame.
    assert!(s.contains("EMCY node 2: 0x2310"), "{s}");
    insta::assert_snapshot!("receive_list_by_last_heard_160x48", s);
}

#[test]
fn receive_list_at_80x24_shows_the_age_and_dims_a_stale_row() {
    use ratatui::style::{Color, Modifier};
    let mut a = app();
    a.screen_mut().focus_on(Pane::Stats);
    // 100 ms after the capture's last frame only node 1's heartbeat comes again: 0x181
    // (every 14 ms) is 7 periods late, stale; 0x701 was heard just now.
    let end = a.trace().nodes.now_ns();
    let mut f = crate::frame::Frame::classic(0x701, &[0x05]);
    f.ts_ns = end + 100_000_000;
    a.capture_mut().trace_mut().push(&f);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("cob  rate/s     age    period  data"), "{s}");
    assert!(s.contains("181    29.4  106 ms   14.0 ms  37 02"), "{s}");
    assert!(s.contains("701    39.2    0 ms   29.1 ms  05"), "{s}");
    insta::assert_snapshot!("receive_list_stale_80x24", s);
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(80, 24)).unwrap();
    term.draw(|fr| crate::tui::ui::draw(fr, &mut a)).unwrap();
    let buf = term.backend().buffer().clone();
    let row = |id: &str| {
        (0..buf.area.height)
            .find(|&y| (0..3).all(|i| buf[(1 + i as u16, y)].symbol() == &id[i..i + 1]))
            .unwrap_or_else(|| panic!("a row for {id}: {s}"))
    };
    let dim = |y: u16, x: u16| buf[(x, y)].fg == Color::DarkGray && buf[(x, y)].modifier.contains(Modifier::DIM);
    // Every cell of the stale row is dim, the COB-ID, the age and the changed data bytes.
    let (stale, alive) = (row("181"), row("701"));
    assert!((1..79).all(|x| dim(stale, x)), "{s}");
    assert!(!(1..79).any(|x| dim(alive, x)), "{s}");
    // A COB-ID seen once has no period: not dimmed.
    assert!(!dim(row("082"), 1), "{s}");
}

#[test]
fn receive_list_highlights_the_bytes_that_changed() {
    let mut a = app();
    a.screen_mut().focus_on(Pane::Stats);
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(100, 20)).unwrap();
    term.draw(|fr| crate::tui::ui::draw(fr, &mut a)).unwrap();
    let buf = term.backend().buffer().clone();
    // RPDO1 0x201: 0F 00 05 00 00 00 after 0F 00 04 ...: only byte 2 changed.
    let row = (0..buf.area.height)
        .find(|&y| buf[(1, y)].symbol() == "2" && buf[(2, y)].symbol() == "0" && buf[(3, y)].symbol() == "1")
        .expect("a row for 0x201");
    let x0 = (0..buf.area.width)
        .find(|&x| buf[(x, row)].symbol() == "0" && buf[(x + 1, row)].symbol() == "F")
        .unwrap();
    let hot: Vec<bool> = (0..6)
        .map(|i| buf[(x0 + 3 * i, row)].fg == ratatui::style::Color::Yellow)
        .collect();
    assert_eq!(hot, [false, false, true, false, false, false]);
}

#[test]
fn plot_pane_draws_a_series() {
    let mut a = app();
    a.act(Action::NextSeries);
    assert_eq!(a.focus(), Pane::Plot);
    let s = screen(&mut a, 100, 20);
    assert!(s.contains("Plot: 1 of 2 signals"), "{s}");
    assert!(s.contains("end 0.098 s  n1 0x6041:00 = 567"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn help_lists_the_keymap_in_force() {
    let mut a = app();
    a.act(Action::Help);
    let s = screen(&mut a, 120, 50);
    assert!(s.contains("ctrl-c, q"), "{s}");
    assert!(s.contains("Quit"), "{s}");
    insta::assert_snapshot!(s);
}

#[test]
fn help_at_80x24_scrolls_to_the_palette_commands_and_the_filter_language() {
    let mut a = app();
    a.act(Action::Help);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("down/up, pagedown/pageup scroll (1-19 of"), "{s}");
    // Page down to the end: the last lines of the filter language show.
    for _ in 0..20 {
        a.act(Action::PageDown);
    }
    let end = screen(&mut a, 80, 24);
    assert!(end.contains("( ... )"), "{end}");
    insta::assert_snapshot!("help_80x24_end", end);
    // Every line was on screen at some scroll position.
    a.act(Action::Top);
    let mut seen = String::new();
    for _ in 0..20 {
        seen.push_str(&screen(&mut a, 80, 24));
        a.act(Action::PageDown);
    }
    for want in [
        "ctrl-c, q",
        "r                 Replay: start over",
        "goto N",
        "export FILE [--format candump|jsonl|pcapng] [--force]",
        "sdo write [OPTIONS] <NODE> <OBJECT> <VALUE>",
        "stop [OPTIONS] [NODES]...",
        "id 180/780",
        "abort, abort 0x0602",
        "not a, !a",
    ] {
        assert!(seen.contains(want), "{want}");
    }
    a.act(Action::Back);
    assert!(!screen(&mut a, 80, 24).contains("Help"));
}

#[test]
fn filter_prompt_and_errors_show_in_the_bottom_line() {
    let mut a = app();
    a.set_filter("kind bogus");
    let s = screen(&mut a, 140, 12);
    assert!(s.contains("filter: column 6: unknown kind `bogus`"), "{s}");
    a.set_filter("node 2 hb");
    let s = screen(&mut a, 140, 12);
    assert!(s.contains("filter: node 2 hb (7 rows)"), "{s}");
}

#[test]
fn any_size_renders_without_panicking() {
    let mut a = app();
    for pane in Pane::ALL {
        a.screen_mut().focus_on(pane);
        *a.screen_mut().help_mut() = Default::default();
        if pane == Pane::Stats {
            a.screen_mut().help_mut().show();
        }
        for (w, h) in [
            (0, 0),
            (1, 1),
            (2, 3),
            (10, 4),
            (20, 6),
            (40, 10),
            (80, 24),
            (300, 100),
            (5, 80),
        ] {
            let _ = screen(&mut a, w, h);
        }
    }
}

#[test]
fn a_replay_shows_its_position_and_progress_in_the_status_line() {
    use crate::tui::app::SourceKind;
    use crate::tui::source::{Extent, Position};
    let mut a = app();
    let frames = super::testutil::frames();
    a.capture_mut().source_mut().kind = SourceKind::Replay { speed: 2.0 };
    a.capture_mut().source_mut().done = false;
    a.capture_mut().source_mut().paused = true;
    let first = frames[0].ts_ns;
    a.capture_mut().source_mut().replay = (
        Some(Position {
            frames: 22,
            ts_ns: frames[21].ts_ns,
        }),
        Some(Extent {
            frames: frames.len() as u64,
            first_ns: first,
            last_ns: frames.last().unwrap().ts_ns,
        }),
    );
    let s = screen(&mut a, 80, 24);
    let status: String = s.lines().rev().take(2).collect::<Vec<_>>().join("\n");
    assert!(
        status.contains("replay test.log 50% 0.0 s / 0.1 s ×2 (paused)"),
        "{status}"
    );
    insta::assert_snapshot!(status);
    // At the end it says so, and a log not measured yet shows only the time.
    a.capture_mut().source_mut().paused = false;
    a.capture_mut().source_mut().replay.0 = Some(Position {
        frames: frames.len() as u64,
        ts_ns: frames.last().unwrap().ts_ns,
    });
    assert!(screen(&mut a, 80, 24).contains("replay test.log 100% 0.1 s / 0.1 s ×2 (end)"));
    a.capture_mut().source_mut().replay.1 = None;
    assert!(screen(&mut a, 80, 24).contains("replay test.log 0.1 s ×2 |"));
}

/// The plot of [`plot_app`] with `keys` typed (through the keymap) first.
fn plot_screen(keys: &str, w: u16, h: u16) -> (crate::tui::app::App, String) {
    typed_plot(super::testutil::plot_app(), keys, w, h)
}

/// The plot of `a` with `keys` typed (through the keymap) first.
fn typed_plot(mut a: crate::tui::app::App, keys: &str, w: u16, h: u16) -> (crate::tui::app::App, String) {
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    a.screen_mut().focus_on(Pane::Plot);
    let _ = screen(&mut a, w, h);
    for c in keys.chars() {
        let code = match c {
            '\n' => KeyCode::Enter,
            '>' => KeyCode::Right,
            '<' => KeyCode::Left,
            c => KeyCode::Char(c),
        };
        a.key(KeyEvent::new(code, KeyModifiers::NONE));
    }
    let s = screen(&mut a, w, h);
    (a, s)
}

#[test]
fn plot_picker_filters_signals_as_the_user_types() {
    let (_, s) = plot_screen("pvel", 80, 24);
    assert!(s.contains("Pick signals (1 of 3)"), "{s}");
    assert!(s.contains("> vel_"), "{s}");
    assert!(s.contains("node 1   6044:00  vl velocity actual value [rpm]"), "{s}");
    insta::assert_snapshot!("plot_picker_80x24", s);
    let (_, s) = plot_screen("p", 160, 48);
    assert!(s.contains("Pick signals (3 of 3)"), "{s}");
    insta::assert_snapshot!("plot_picker_160x48", s);
}

#[test]
fn plot_shows_signals_on_one_axis_with_units_legend_and_bit_lanes() {
    // The statusword is shown first; the picker adds the velocity and the mode.
    let (a, s) = plot_screen("pvel\npmodes\n", 160, 48);
    let n1 = crate::frame::NodeKey::new(0, 1);
    assert_eq!(
        a.screen().panes().plot().shown(a.trace()),
        [(n1, 0x6041, 0), (n1, 0x6044, 0), (n1, 0x6061, 0)]
    );
    assert!(s.contains("Plot: 3 of 3 signals"), "{s}");
    assert!(s.contains("n1 vl velocity actual value [rpm]"), "legend: {s}");
    assert!(s.contains("rpm"), "unit on the axis: {s}");
    assert!(s.contains(" 2 Operation enabled"), "bit lane: {s}");
    assert!(s.contains(" 3 Fault"), "bit lane: {s}");
    assert!(
        s.contains("end 0.410 s  n1 Statusword = 0x0238  n1 vl velocity actual value = 0 rpm  n1 Modes of"),
        "{s}"
    );
    insta::assert_snapshot!("plot_three_signals_160x48", s);
}

#[test]
fn plot_cursor_reads_values_and_zoom_narrows_the_window() {
    // Right places the cursor mid-window, then moves it one column at a time.
    let (_, s) = plot_screen("pvel\n>>>>>", 80, 24);
    assert!(s.contains("cursor 0.2"), "{s}");
    assert!(s.contains("n1 Statusword = 0x0237"), "{s}");
    // Not every lane fits at 80x24: the bits that change and those set come first.
    assert!(s.contains(" 3 Fault") && s.contains(" 9 Remote"), "{s}");
    assert!(!s.contains(" 7 Warning"), "{s}");
    insta::assert_snapshot!("plot_cursor_80x24", s);
    let (mut a, s) = plot_screen("pvel\n>zz", 80, 24);
    assert!(s.contains("Plot: 2 of 3 signals, lanes 0.1"), "{s}");
    // Home shows the whole span again.
    a.act(crate::tui::keymap::Action::Top);
    let s = screen(&mut a, 80, 24);
    assert!(
        s.contains("Plot: 2 of 3 signals, lanes ━") && !s.contains("lanes 0.1"),
        "{s}"
    );
}

#[test]
fn help_search_brings_the_first_line_found_to_the_top() {
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    let mut a = app();
    a.act(Action::Help);
    let _ = screen(&mut a, 80, 24);
    for c in "/loop".chars() {
        a.key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE));
    }
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("find: loop_ (2 lines)"), "{s}");
    let first = s.lines().nth(2).unwrap_or("");
    assert!(first.contains("Replay: loop at the end (on/off)"), "{s}");
    insta::assert_snapshot!("help_search_80x24", s);
}

#[test]
fn problems_pane_lists_the_incidents_and_opens_one_at_80x24() {
    let mut a = app();
    a.act(Action::PaneProblems);
    assert_eq!(a.focus(), Pane::Problems);
    let s = screen(&mut a, 80, 24);
    // Node 2 refused the read of 0x6041:00 and sent an EMCY; nothing recovered.
    // 80 columns: the long tab titles are shortened.
    assert!(s.contains("8 Probl 9 Trans 0 Watch"), "{s}");
    assert!(s.contains("Problems (2 open, 0 recovered, 0 warnings)"), "{s}");
    assert!(s.contains("OPEN      Node 2"), "{s}");
    insta::assert_snapshot!("problems_80x24_list", s);
    a.act(Action::Down);
    a.act(Action::Expand);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("What happened"), "{s}");
    assert!(s.contains("Check first"), "{s}");
    assert!(s.contains("Why it matters"), "{s}");
    insta::assert_snapshot!("problems_80x24_opened", s);
}

#[test]
fn boot_stories_list_each_boot_and_open_one_with_its_steps_and_findings() {
    let mut a = app_of_log("tests/fixtures/boot/boots_differ.log");
    // From the trace: `boots` goes to the Problems pane and shows the stories.
    a.act(Action::Boots);
    assert_eq!(a.focus(), Pane::Problems);
    let s = screen(&mut a, 120, 24);
    assert!(s.contains("Boot stories (2 boots, 1 with findings)"), "{s}");
    let row = |s: &str, boot: &str| s.lines().find(|l| l.contains(boot)).unwrap_or_default().to_string();
    let first = row(&s, "Node 5              1");
    assert!(first.contains("0.000        0.100     6        0  -"), "{s}");
    let second = row(&s, "Node 5              2");
    assert!(second.contains("1.000        1.200     7        5  boot 1"), "{s}");
    insta::assert_snapshot!("boot_stories_120x24_list", s);
    // The second boot opened: its steps as `diagnose --boots` tells them, then the findings.
    a.act(Action::Down);
    a.act(Action::Expand);
    let s = screen(&mut a, 120, 24);
    assert!(
        s.contains("Node 5, boot 2 at 1.000 s, operational at 1.200 s (heartbeat)"),
        "{s}"
    );
    assert!(
        s.contains("1.130 s  #19      write 0x1400:02 = 0xFE  refused: Invalid value"),
        "{s}"
    );
    assert!(s.contains("missing: 0x1800:02 not written, boot 1 wrote 0x01"), "{s}");
    insta::assert_snapshot!("boot_stories_120x24_opened", s);
    // Enter on the third step (the write of 0x1017:00, frame 15) shows it in the trace.
    a.act(Action::Down);
    a.act(Action::Down);
    a.act(Action::Expand);
    assert_eq!(a.focus(), Pane::Trace);
    assert_eq!(a.selected_position(), Some(14));
    // Back in the pane, `back` closes the boot, `boots` again shows the incidents.
    a.act(Action::PaneProblems);
    a.act(Action::Back);
    let s = screen(&mut a, 120, 24);
    assert!(s.contains("Boot stories (2 boots"), "{s}");
    a.act(Action::Boots);
    let s = screen(&mut a, 120, 24);
    assert!(s.contains("Problems (2 open"), "{s}");
}

#[test]
fn expect_in_the_palette_compares_the_boots_with_a_dcf_and_off_forgets_it() {
    let mut a = app_of_log("tests/fixtures/boot/boots_agree.log");
    a.act(Action::Boots);
    let s = screen(&mut a, 120, 24);
    assert!(s.contains("Boot stories (2 boots, 0 with findings)"), "{s}");
    // The DCF wants 0x2002:00 = 5, which neither boot writes (as `diagnose --expect`).
    a.run_command("expect 5=tests/fixtures/boot/node5.dcf");
    assert_eq!(
        a.message(),
        Some("expect: configuration expected of node 5 (the boot stories compare it: B)")
    );
    let s = screen(&mut a, 120, 24);
    assert!(
        s.contains("Boot stories (2 boots, 2 with findings; expected configuration of node 5)"),
        "{s}"
    );
    let row = |s: &str, boot: &str| s.lines().find(|l| l.contains(boot)).unwrap_or_default().to_string();
    assert!(row(&s, "Node 5              1").contains("1  expected "), "{s}");
    assert!(row(&s, "Node 5              2").contains("1  boot 1 + expected"), "{s}");
    insta::assert_snapshot!("boot_stories_expected_120x24_list", s);
    a.act(Action::Expand);
    let s = screen(&mut a, 120, 24);
    insta::assert_snapshot!("boot_stories_expected_120x24_opened", s);
    // A file that is not there changes nothing and says why.
    a.run_command("expect 5=tests/fixtures/boot/nothing_here.dcf");
    assert!(
        a.message()
            .unwrap_or_default()
            .starts_with("expect: tests/fixtures/boot/nothing_here.dcf: "),
        "{:?}",
        a.message()
    );
    a.run_command("expect off");
    a.act(Action::Back);
    let s = screen(&mut a, 120, 24);
    assert!(s.contains("Boot stories (2 boots, 0 with findings)"), "{s}");
}

#[test]
fn problems_pane_shows_a_boot_that_differs_with_its_findings_as_steps() {
    let mut a = app_of_log("tests/fixtures/boot/boots_differ.log");
    a.act(Action::PaneProblems);
    let s = screen(&mut a, 160, 40);
    assert!(
        s.contains("OPEN      Node 5           1    1.000    1.000  Boot 2 configured otherwise than boot 1 (1 different, 1 missing,"),
        "{s}"
    );
    a.act(Action::Expand);
    let s = screen(&mut a, 160, 40);
    for step in [
        "Boot 2 began",
        "0x1017:00 written 0x00C8, boot 1 wrote 0x0064",
        "0x2001:00 written 0x01, boot 1 did not write it",
        "0x1400:02 write of 0xFE refused: Invalid value for parameter (download only)",
        "0x2000:01 write of 0x00000007 not answered",
        "0x1800:02 not written, boot 1 wrote 0x01",
    ] {
        assert!(s.contains(step), "{step}: {s}");
    }
}

#[test]
fn problems_pane_at_160x48_and_its_frames_in_the_trace() {
    let mut a = app();
    a.act(Action::PaneProblems);
    let s = screen(&mut a, 160, 48);
    assert!(
        s.contains("A value could not be read — 0x6041:00: Object does not exist"),
        "{s}"
    );
    insta::assert_snapshot!("problems_160x48_list", s);
    // The first incident is the refused read (frame 13, the abort): `show_frames` shows it
    // in the trace; pressing it again in the trace goes on to the incident's next frame.
    let first = a.screen().panes().problems.incidents()[0].clone();
    a.act(Action::ShowFrames);
    assert_eq!(a.focus(), Pane::Trace);
    assert_eq!(a.selected_position(), Some(first.events[0].frame as usize - 1));
    a.act(Action::ShowFrames);
    let next = first.events.get(1).unwrap_or(&first.events[0]).frame as usize - 1;
    assert_eq!(a.selected_position(), Some(next));
    // Enter on a timeline step of the opened incident shows that frame.
    a.act(Action::PaneProblems);
    let _ = screen(&mut a, 160, 48);
    a.act(Action::Expand);
    a.act(Action::Expand);
    assert_eq!(a.focus(), Pane::Trace);
    assert_eq!(a.selected_position(), Some(first.events[0].frame as usize - 1));
}

#[test]
fn lss_fastscan_confirmation_at_80x24_shows_the_key_first_and_wraps_the_rest() {
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    let mut a = app();
    for c in ":lss fastscan".chars() {
        a.key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE));
    }
    a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
    let s = screen(&mut a, 80, 24);
    let lines: Vec<&str> = s.lines().collect();
    assert_eq!(lines.len(), 24, "{s}");
    // The key hint starts the question; the reason wraps below, whole.
    let at = lines
        .iter()
        .position(|l| l.starts_with("y send · any other key cancels  "))
        .unwrap_or_else(|| panic!("{s}"));
    let question = lines[at..].join(" ");
    assert!(
        question.contains("LSS fastscan addresses every LSS slave (in configuration state, or not yet configured):"),
        "{s}"
    );
    assert!(at >= 20, "the question takes the bottom lines: {s}");
    assert!(
        lines[at - 1].starts_with("open test.log"),
        "the status bar stays above it: {s}"
    );
    insta::assert_snapshot!("lss_fastscan_confirmation_80x24", s);
    // The hint is drawn as a key: black on yellow.
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(80, 24)).unwrap();
    term.draw(|fr| crate::tui::ui::draw(fr, &mut a)).unwrap();
    let buf = term.backend().buffer().clone();
    assert_eq!(buf[(0, at as u16)].bg, ratatui::style::Color::Yellow);
    // Answered, the bottom is one line again.
    a.key(KeyEvent::new(KeyCode::Char('n'), KeyModifiers::NONE));
    let s = screen(&mut a, 80, 24);
    assert!(s.lines().nth(22).unwrap_or("").starts_with("open test.log"), "{s}");
    assert_eq!(s.lines().nth(23), Some("not sent"), "{s}");
}

#[test]
fn dcf_load_confirmation_at_160_columns_shows_the_key_and_all_of_the_reason() {
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    let mut a = app();
    for c in ":dcf load 5 node5.dcf --store".chars() {
        a.key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE));
    }
    a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
    let s = screen(&mut a, 160, 24);
    let lines: Vec<&str> = s.lines().collect();
    let at = lines
        .iter()
        .position(|l| {
            l.starts_with("y send · any other key cancels  dcf load writes node 5's configuration from node5.dcf:")
        })
        .unwrap_or_else(|| panic!("{s}"));
    let question = lines[at..].join(" ");
    assert!(question.contains("stores (0x1010:01)"), "{s}");
    assert!(!question.contains('…'), "nothing cut: {s}");
}

/// The demo's own bindings come from `cli::bind` (test code only: `tui` does not use `cli`).
#[cfg(test)]
mod demo {
    use super::{Pane, screen};

    /// Issue 24 item 13: on the demo bus the Nodes pane names the profile each drive is bound
    /// to (not the simulator's layer, `demo`) and shows the heartbeat period the device's
    /// dictionary gives as default before anyone has read 0x1017.
    #[test]
    fn nodes_pane_on_the_demo_shows_the_bound_profiles_and_the_default_heartbeat() {
        use crate::analysis::trace::Trace;
        use crate::decode::Decoder;
        use crate::tui::app::{App, SourceInfo, SourceKind};
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let mut trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
        trace.ifaces.intern("can0");
        let base = 1_700_000_000_000_000_000u64;
        let mut sim = crate::sim::Simulation::demo();
        let mut push = |frames: Vec<crate::frame::Frame>, now: u64| {
            for mut f in frames {
                f.ts_ns = base + now;
                trace.push(&f);
            }
        };
        let boot = sim.power_on(0);
        push(sim.settle(boot, 0), 0);
        for k in 1..=120u64 {
            let now = k * 10_000_000;
            let out = sim.tick(now);
            push(sim.settle(out, now), now);
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("sim.log", SourceKind::Open, rx, None);
        src.done = true;
        let mut a = App::new(trace, crate::tui::keymap::Keymap::default_map(), src);
        a.screen_mut().focus_on(Pane::Nodes);
        let s = screen(&mut a, 200, 14);
        let row = |node: &str| {
            s.lines()
                .find(|l| l.contains(&format!("┃  {node} Operational")))
                .unwrap_or_else(|| panic!("no row for node {node}: {s}"))
                .to_string()
        };
        let (two, three) = (row("2"), row("3"));
        assert!(two.contains(" 500/500 ms ") && two.contains(" aimotor "), "{s}");
        assert!(three.contains(" 500/500 ms ") && three.contains(" syntron-ds "), "{s}");
        assert!(!s.contains(" demo "), "{s}");
    }
}

#[test]
fn message_log_at_80x24_wraps_long_entries_scrolls_to_the_oldest_and_shows_one_whole() {
    use crate::tui::messages::Level;
    use std::time::{Duration, SystemTime};
    let mut a = app();
    let t = SystemTime::UNIX_EPOCH + Duration::from_secs(3600);
    a.screen_mut().messages_mut().push(t, Level::Info, "the oldest entry");
    for i in 0..30 {
        a.screen_mut()
            .messages_mut()
            .push(t, Level::Info, &format!("filler {i}"));
    }
    let preview = "pdo 2 map tpdo1: will send: 602#2F00 1A 00 00 00 00 00 · 602#23 00 1A 01 10 00 41 60 · 602#2F 00 1A 00 01 00 00 00 · 602#2F 00 18 02 02 00 00 00 (node 2 must be pre-operational)";
    a.screen_mut().messages_mut().push(t, Level::Info, preview);
    a.act(Action::Messages);
    let s = screen(&mut a, 80, 24);
    // Every word of the long preview is on screen, in order, once the lines are joined.
    // (The popup's text starts at column 5, after the time stamp column, 14 wide.)
    let joined: String = s
        .lines()
        .map(|l| {
            l.chars()
                .skip(5 + 14)
                .take(70 - 14)
                .collect::<String>()
                .trim()
                .to_string()
        })
        .collect::<Vec<_>>()
        .join(" ");
    assert!(joined.contains("(node 2 must be pre-operational)"), "{s}");
    assert!(joined.contains("602#2F 00 18 02 02 00 00 00"), "{s}");
    insta::assert_snapshot!("message_log_80x24_wrapped", s);
    // Home reaches the oldest entry; End comes back to the newest.
    a.act(Action::Top);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("the oldest entry"), "{s}");
    assert!(!s.contains("pre-operational)"), "{s}");
    a.act(Action::Bottom);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("pre-operational)"), "{s}");
    // Page up repeatedly also gets there.
    for _ in 0..10 {
        a.act(Action::PageUp);
    }
    assert!(screen(&mut a, 80, 24).contains("the oldest entry"));
    // Enter shows the selected entry whole, even one taller than the popup.
    a.act(Action::Bottom);
    let scan: String = (1..=40).map(|n| format!("node {n}: 0x{n:08X}\n")).collect();
    a.screen_mut()
        .messages_mut()
        .push(t, Level::Info, &format!("lss fastscan: 40 found\n{scan}"));
    a.act(Action::Expand);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("lss fastscan: 40 found"), "{s}");
    assert!(s.contains("entry 33 of 33"), "{s}");
    a.act(Action::Bottom);
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("node 40: 0x00000028"), "{s}");
    a.act(Action::Back);
    let s = screen(&mut a, 80, 24);
    assert!(a.screen().log_popup().shown() && !s.contains("entry 33 of 33"), "{s}");
}

#[test]
fn every_pane_at_80x24() {
    // What a bench reads first must be on each 80x24 screen.
    let wants: [(Pane, &[&str]); 8] = [
        (Pane::Trace, &["Heartbeat node 2: Pre-operational", "| help: ?"]),
        (
            Pane::Nodes,
            &["hb meas/cfg", "hb age", "miss", "14/100 ms", "Pre-operational"],
        ),
        (Pane::Sdo, &["1017:00", "64 00 (100)", "ok", "abort 06020000"]),
        (Pane::Stats, &["701"]),
        (Pane::Plot, &[]),
        (Pane::Objects, &[]),
        (Pane::Pdo, &[]),
        (Pane::Problems, &[]),
    ];
    for (pane, want) in wants {
        let mut a = app();
        a.screen_mut().focus_on(pane);
        let s = screen(&mut a, 80, 24);
        for w in want {
            assert!(s.contains(w), "{pane:?}: {w}\n{s}");
        }
        assert!(s.lines().nth(22).unwrap_or("").ends_with("help: ?"), "{pane:?}\n{s}");
        insta::assert_snapshot!(format!("pane_{pane:?}_80x24").to_lowercase(), s);
    }
}

#[test]
fn an_open_file_shows_neither_a_frame_rate_nor_the_stop_all_key_and_a_bus_does() {
    use crate::tui::app::SourceKind;
    let mut a = app();
    let s = screen(&mut a, 160, 12);
    let bar = |s: &str| {
        s.lines()
            .rev()
            .find(|l| l.contains(" frames"))
            .unwrap_or("")
            .to_string()
    };
    assert!(
        bar(&s).contains("open test.log (end) | 44 frames | drops 0 | help: ?"),
        "{s}"
    );
    assert!(!s.contains("fr/s") && !s.contains("stop all"), "{s}");
    for (kind, rate, stop) in [
        (SourceKind::Demo { listen_only: false }, true, true),
        (SourceKind::Live { listen_only: false }, true, true),
        (SourceKind::Replay { speed: 1.0 }, true, true),
    ] {
        let name = format!("{kind:?}");
        a.capture_mut().source_mut().kind = kind;
        let b = bar(&screen(&mut a, 160, 12));
        assert_eq!(b.contains(" fr/s | drops 0"), rate, "{name}: {b}");
        assert_eq!(b.contains("stop all: ctrl-s"), stop, "{name}: {b}");
    }
}

#[test]
fn y_in_the_message_log_copies_the_selected_entry_whole_and_says_copied() {
    use crate::tui::messages::Level;
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    let y = KeyEvent::new(KeyCode::Char('y'), KeyModifiers::NONE);
    let mut a = app();
    let t = std::time::SystemTime::UNIX_EPOCH;
    let scan: String = (1..=30).map(|n| format!("node {n}: 0x{n:08X}\n")).collect();
    let scan = format!("lss fastscan: 30 found\n{scan}");
    a.screen_mut().messages_mut().push(t, Level::Info, &scan);
    a.screen_mut().messages_mut().push(t, Level::Warn, "the newest entry");
    a.act(Action::Messages);
    a.act(Action::Up);
    a.key(y);
    assert_eq!(a.screen_mut().take_clipboard().as_deref(), Some(scan.as_str()));
    let s = screen(&mut a, 80, 24);
    assert!(s.contains("copied the "), "{s}");
    assert!(s.contains("(31 lines) to the clipboard"), "{s}");
    // From the whole-entry view too; the log keeps the same two entries.
    a.act(Action::Down);
    a.act(Action::Expand);
    a.key(y);
    assert_eq!(a.screen_mut().take_clipboard().as_deref(), Some("the newest entry"));
    assert_eq!(a.screen().messages().len(), 2);
    // Without the popup `y` copies nothing.
    a.act(Action::Messages);
    assert!(!a.screen().log_popup().shown());
    a.key(y);
    assert_eq!(a.screen_mut().take_clipboard(), None);
    assert_eq!(a.message(), Some("copy: only in the message log (m)"));
}

#[test]
fn nodes_and_objects_keep_the_two_node_5s_apart() {
    // The two buses' node 5 each answer a read of their heartbeat time, with different values.
    let bindings = crate::od::bind::Bindings::new();
    let mut a = two_bus_app_with(crate::decode::Decoder::from_bindings(&bindings));
    let t = a.trace().store.packed(a.trace().len() - 1).ts_ns;
    for (k, (iface, ms)) in [("can0", 100u16), ("can1", 250)].into_iter().enumerate() {
        let iface = a.trace().ifaces.names().iter().position(|n| n == iface).unwrap() as u16;
        let v = ms.to_le_bytes();
        for (i, (id, data)) in [
            (0x605, [0x40, 0x17, 0x10, 0x00, 0, 0, 0, 0]),
            (0x585, [0x4B, 0x17, 0x10, 0x00, v[0], v[1], 0, 0]),
        ]
        .into_iter()
        .enumerate()
        {
            let mut f = crate::frame::Frame::classic(id, &data);
            f.ts_ns = t + (2 * k + i + 1) as u64 * 1_000_000;
            f.iface = iface;
            a.capture_mut().trace_mut().push(&f);
        }
    }
    a.capture_mut().trace_mut().end_of_input();
    a.screen_mut().focus_on(Pane::Nodes);
    let s = screen(&mut a, 120, 8);
    insta::assert_snapshot!("two_buses_nodes", s);
    // Node 5 of can1 selected: the Objects pane shows its own value, not can0's.
    a.act(Action::Down);
    a.act(Action::PaneObjects);
    a.screen_mut().find_objects("heartbeat");
    let s = screen(&mut a, 120, 10);
    assert!(s.contains("Objects · node 5 on can1"), "{s}");
    assert!(s.contains("250") && !s.contains(" 100 "), "{s}");
    insta::assert_snapshot!("two_buses_objects_node_5_on_can1", s);
    a.act(Action::PaneNodes);
    a.act(Action::Up);
    a.act(Action::PaneObjects);
    let s = screen(&mut a, 120, 10);
    assert!(s.contains("Objects · node 5 on can0"), "{s}");
    assert!(s.contains("100") && !s.contains(" 250 "), "{s}");
    insta::assert_snapshot!("two_buses_objects_node_5_on_can0", s);
}

#[test]
fn the_time_key_cycles_the_trace_time_modes_shown_in_the_title() {
    let mut a = app();
    let _ = screen(&mut a, 170, 14);
    a.act(Action::Top);
    for _ in 0..3 {
        a.act(Action::Down);
    }
    a.act(Action::Bookmark);
    // Frame 4 (0x601 at 7 ms) is marked; the next 0x601 comes 2 ms after it.
    let expect = [
        ("start", "    0.007000 601"),
        ("absolute", "22:13:20.007 601"),
        ("delta", "   +0.001000 601"),
        ("delta-id", "   +0.002000 601"),
        ("mark", "   -0.007000 701"),
    ];
    for (i, (mode, cell)) in expect.into_iter().enumerate() {
        let s = screen(&mut a, 170, 14);
        assert!(s.contains(&format!("[time: {mode}]")), "{s}");
        assert!(s.contains(cell), "{mode}: {s}");
        insta::assert_snapshot!(format!("trace_time_mode_{i}_{mode}"), s);
        a.act(Action::TimeMode);
    }
}

#[test]
fn bookmarks_are_listed_in_the_title_and_the_jump_key_walks_them_wrapping() {
    let mut a = app();
    let _ = screen(&mut a, 170, 14);
    a.act(Action::Top);
    a.act(Action::Down);
    a.act(Action::Bookmark);
    for _ in 0..4 {
        a.act(Action::Down);
    }
    a.act(Action::Bookmark);
    a.act(Action::Top);
    a.act(Action::NextBookmark);
    assert_eq!(a.selected_position(), Some(1));
    a.act(Action::NextBookmark);
    assert_eq!(a.selected_position(), Some(5));
    a.act(Action::NextBookmark);
    assert_eq!(a.selected_position(), Some(1), "wraps to the first");
    let s = screen(&mut a, 170, 14);
    assert!(s.contains("[marks #2 #6]"), "{s}");
    insta::assert_snapshot!(s);
    // Set again on a marked frame: removed.
    a.act(Action::Bookmark);
    let s = screen(&mut a, 170, 14);
    assert!(s.contains("[marks #6]"), "{s}");
}

/// A whole block download of `len` bytes to 0x1F50:01 of node 1 (blksize 127, CRC),
/// one frame every 100 µs: initiate, sub-blocks and their acknowledges, end, end response.
fn block_download(len: usize) -> Vec<crate::frame::Frame> {
    use crate::sdo::SdoCommand;
    use crate::sdo::codec::{encode, sub_block};
    let data: Vec<u8> = (0..len).map(|i| (i * 7 + 3) as u8).collect();
    // CRC-16/XMODEM, as CiA 301 block transfers carry it.
    let crc = data.iter().fold(0u16, |mut crc, &b| {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
        crc
    });
    let mut cmds = vec![
        (
            0x601,
            SdoCommand::BlockDownloadInitiate {
                index: 0x1F50,
                sub: 1,
                crc: true,
                size: Some(len as u32),
            },
        ),
        (
            0x581,
            SdoCommand::BlockDownloadInitiateResponse {
                index: 0x1F50,
                sub: 1,
                crc: true,
                blksize: 127,
            },
        ),
    ];
    let mut pos = 0;
    while pos < len {
        let (segments, n) = sub_block(&data, pos, 127);
        let ackseq = segments.len() as u8;
        cmds.extend(segments.into_iter().map(|s| (0x601, s)));
        cmds.push((0x581, SdoCommand::BlockDownloadAck { ackseq, blksize: 127 }));
        pos += n;
    }
    let unused = ((7 - len % 7) % 7) as u8;
    cmds.push((0x601, SdoCommand::BlockDownloadEnd { unused, crc }));
    cmds.push((0x581, SdoCommand::BlockDownloadEndResponse));
    cmds.iter()
        .enumerate()
        .map(|(i, (id, c))| {
            let mut f = crate::frame::Frame::classic(*id, &encode(c));
            f.ts_ns = 1_700_000_000_000_000_000 + i as u64 * 100_000;
            f
        })
        .collect()
}

#[test]
fn a_block_download_of_thousands_of_frames_opens_as_a_sequence_diagram_with_its_crc() {
    // 20000 bytes: 2858 segments in 23 sub-blocks, the last of 64 segments.
    let mut a = super::testutil::app_of(&block_download(20_000));
    assert_eq!(a.trace().transactions.len(), 1);
    let t = a.trace().transactions.get(0).expect("one transfer");
    assert!(t.is_ok(), "{t:?}");
    a.screen_mut().focus_on(Pane::Sdo);
    let _ = screen(&mut a, 140, 14);
    let opened = std::time::Instant::now();
    a.act(Action::Expand);
    let s = screen(&mut a, 140, 14);
    println!("opened 2885 frames and drew the window in {:?}", opened.elapsed());
    assert!(s.contains("SDO transfer 1F50:01 node 1 — block download, ok"), "{s}");
    assert!(
        s.contains("│ initiate block download 0x1F50:01 size 20000 crc ──"),
        "{s}"
    );
    assert!(s.contains(" block download response 0x1F50:01 blksize=127 │"), "{s}");
    assert!(s.contains("│ block seq 1 ──"), "{s}");
    insta::assert_snapshot!("sdo_sequence_block_download_start", s);
    // The end: the last sub-block's last segment, its acknowledge, the CRC.
    let drew = std::time::Instant::now();
    a.act(Action::Bottom);
    let s = screen(&mut a, 140, 14);
    println!("moved to the end and drew in {:?}", drew.elapsed());
    assert!(s.contains("+288.100 ms │ block seq 64 last ──"), "{s}");
    assert!(s.contains(" block ack ackseq=64 blksize=127 │"), "{s}");
    assert!(s.contains("│ end block crc 0x"), "{s}");
    assert!(s.contains(" end block response │"), "{s}");
    assert!(!s.contains("no answer"), "{s}");
    insta::assert_snapshot!("sdo_sequence_block_download_end", s);
}

/// The rows of the Plot pane's chart area from `s` (the lines starting with the pane's
/// border), and how many of them have a braille dot in the columns right of the y axis.
fn rows_with_dots(s: &str) -> usize {
    s.lines()
        .filter(|l| l.contains('│'))
        .filter(|l| l.chars().any(|c| ('\u{2801}'..='\u{28FF}').contains(&c)))
        .count()
}

#[test]
fn plot_lanes_keep_a_ramp_readable_next_to_a_constant() {
    // Position 0x1000 constant, velocity a ramp: each its own lane, own axis and unit.
    let (a, s) = typed_plot(super::testutil::constant_and_ramp_app(), "pvel\n", 100, 30);
    let n1 = crate::frame::NodeKey::new(0, 1);
    assert_eq!(
        a.screen().panes().plot().shown(a.trace()),
        [(n1, 0x6064, 0), (n1, 0x606C, 0)]
    );
    assert!(s.contains("Plot: 2 of 2 signals, lanes"), "{s}");
    assert!(s.contains("4096"), "the constant's own axis: {s}");
    assert!(s.contains("975"), "the ramp's own axis: {s}");
    // The ramp climbs over every row of its lane (shared with the constant: 6 of 22).
    assert!(rows_with_dots(&s) >= 9, "{s}");
    insta::assert_snapshot!("plot_lanes_100x30", s);
}

#[test]
fn plot_normalised_and_range_modes_scale_the_axis() {
    let app = super::testutil::constant_and_ramp_app;
    // P cycles lanes → normalised: one axis 0..1, the ramp still spans it.
    let (_, s) = typed_plot(app(), "pvel\nP", 100, 30);
    assert!(s.contains("Plot: 2 of 2 signals, normalised"), "{s}");
    assert!(s.contains("│normalised"), "the axis title: {s}");
    assert!(rows_with_dots(&s) > 8, "{s}");
    assert!(
        s.lines().any(|l| l.starts_with("┃1 ") && l.contains("│normalised")),
        "{s}"
    );
    assert!(s.lines().any(|l| l.starts_with("┃0 ")), "{s}");
    insta::assert_snapshot!("plot_normalised_100x30", s);
    // Then shared: neither has a unit, so they share one axis (the ramp flat by the
    // constant: what the other modes avoid).
    let (_, s) = typed_plot(app(), "pvel\nPP", 100, 30);
    assert!(s.contains("Plot: 2 of 2 signals, shared ━"), "{s}");
    assert!(rows_with_dots(&s) <= 7, "{s}");
    // rpm and no unit are never mixed on one axis: one lane per unit, said in the title.
    let (_, s) = plot_screen("pvel\npmodes\nPP", 160, 48);
    assert!(
        s.contains("Plot: 3 of 3 signals, shared: units differ, one lane per unit"),
        "{s}"
    );
    // `plot mode range 0 100`: a fixed axis; the palette says the mode.
    let (mut a, _) = typed_plot(app(), "pvel\n", 100, 30);
    a.run_command("plot mode range 0 100");
    let s = screen(&mut a, 100, 30);
    assert!(s.contains("Plot: 2 of 2 signals, range 0 100"), "{s}");
    a.run_command("plot mode sideways");
    let s = screen(&mut a, 100, 30);
    assert!(
        s.contains("plot: usage `plot mode lanes|normalised|shared|range LO HI`"),
        "{s}"
    );
}
