//! The SDO pane's sequence diagram: `enter` on a transfer opens it as arrows between a
//! client and a server column, one per frame (toggle, block seqno, ackseq, the abort in red
//! where it happened, "no answer" when none came), and `enter` on an arrow shows that frame
//! in the trace and Detail. Logs loaded as `cotui open` loads them, drawn with TestBackend.

use crate::agreement::{opened, realworld};
use cotui::tui::app::App;
use cotui::tui::keymap::Action;
use cotui::tui::panes::Pane;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::buffer::Buffer;
use ratatui::style::Color;
use std::path::Path;

/// The screen of `app`, `w` x `h`, as the terminal holds it.
fn buffer(app: &mut App, w: u16, h: u16) -> Buffer {
    let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
    term.draw(|f| cotui::tui::ui::draw(f, app)).unwrap();
    term.backend().buffer().clone()
}

/// The text of a screen, one line per row, trailing blanks cut.
fn text(buf: &Buffer) -> String {
    let mut out = String::new();
    for y in 0..buf.area.height {
        let line: String = (0..buf.area.width).map(|x| buf[(x, y)].symbol().to_string()).collect();
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

/// The screen of `app` as text.
fn draw(app: &mut App, w: u16, h: u16) -> String {
    text(&buffer(app, w, h))
}

/// The focused (left) pane of a drawn screen: its rows from the title to the bottom
/// border, cut at its right border (no status line, which names the log's full path).
fn pane(screen: &str) -> String {
    let rows: Vec<&str> = screen.lines().skip_while(|l| !l.starts_with('┏')).collect();
    let width = rows.first().and_then(|l| l.chars().position(|c| c == '┓')).unwrap_or(0) + 1;
    let end = rows.iter().position(|l| l.starts_with('┗')).unwrap_or(rows.len());
    let cut: Vec<String> = rows[..=end.min(rows.len().saturating_sub(1))]
        .iter()
        .map(|l| l.chars().take(width).collect())
        .collect();
    cut.join("\n")
}

/// `tests/fixtures/cia301_mix.log` loaded: an expedited write and read, a segmented
/// upload (0x1008 of node 3), an aborted read (0x2000 of node 4), a segmented download
/// and a request never answered (node 5).
fn mix() -> App {
    opened(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cia301_mix.log"))
}

/// The index of node `node`'s first transfer of `index` among the app's transfers.
fn transfer(app: &App, node: u8, index: u16) -> usize {
    let all = &app.trace().transactions;
    all.iter()
        .position(|t| t.node == node && t.index == index)
        .unwrap_or_else(|| panic!("no transfer {index:04X} of node {node} among {}", all.len()))
}

/// Opens transfer `i` of the SDO pane as a sequence diagram.
fn open_diagram(app: &mut App, i: usize) {
    app.act(Action::PaneSdo);
    app.act(Action::Top);
    for _ in 0..i {
        app.act(Action::Down);
    }
    app.act(Action::Expand);
}

#[test]
fn an_expedited_read_is_a_request_arrow_and_a_response_arrow_with_the_data() {
    let mut app = mix();
    let i = transfer(&app, 2, 0x6041);
    open_diagram(&mut app, i);
    let s = draw(&mut app, 120, 10);
    assert!(s.contains("SDO transfer 6041:00 node 2 — expedited upload, ok"), "{s}");
    assert!(s.contains("client (0x602)"), "{s}");
    assert!(s.contains("server (0x582)"), "{s}");
    assert!(s.contains("│ initiate upload 0x6041:00 ──"), "{s}");
    assert!(s.contains("│←─"), "{s}");
    assert!(s.contains(" upload response 0x6041:00 2 bytes 37 02 │"), "{s}");
    assert!(!s.contains("no answer"), "{s}");
    insta::assert_snapshot!(pane(&s));
}

#[test]
fn a_segmented_upload_shows_each_segment_with_its_toggle() {
    let mut app = mix();
    let i = transfer(&app, 3, 0x1008);
    open_diagram(&mut app, i);
    let s = draw(&mut app, 120, 14);
    assert!(s.contains("segmented upload, ok"), "{s}");
    assert!(s.contains("upload response 0x1008:00 size 16"), "{s}");
    for (request, segment) in [
        ("segment request toggle=0 ", "segment toggle=0 7 bytes │"),
        ("segment request toggle=1 ", "segment toggle=1 7 bytes │"),
    ] {
        assert!(s.contains(request), "{s}");
        assert!(s.contains(segment), "{s}");
    }
    assert!(s.contains("segment toggle=0 2 bytes last │"), "{s}");
    insta::assert_snapshot!(pane(&s));
}

#[test]
fn an_aborted_read_ends_with_the_abort_in_red_where_it_happened() {
    let mut app = mix();
    let i = transfer(&app, 4, 0x2000);
    open_diagram(&mut app, i);
    let buf = buffer(&mut app, 120, 10);
    let s = text(&buf);
    assert!(
        s.contains("SDO transfer 2000:00 node 4 — upload, aborted by the server"),
        "{s}"
    );
    let y = s
        .lines()
        .position(|l| l.contains("ABORT 0x06020000 Object does not exist"))
        .unwrap_or_else(|| panic!("{s}"));
    // The abort row follows the request row, and it is drawn red.
    assert!(
        s.lines().nth(y - 1).unwrap().contains("initiate upload 0x2000:00"),
        "{s}"
    );
    let x = s.lines().nth(y).unwrap().chars().position(|c| c == 'A').unwrap() as u16;
    assert_eq!(buf[(x, y as u16)].fg, Color::Red, "{s}");
    insta::assert_snapshot!(pane(&s));
}

#[test]
fn a_request_never_answered_ends_with_no_answer() {
    let mut app = mix();
    let i = transfer(&app, 5, 0x1000);
    open_diagram(&mut app, i);
    let s = draw(&mut app, 120, 8);
    assert!(s.contains("incomplete"), "{s}");
    assert!(s.contains("initiate upload 0x1000:00"), "{s}");
    assert!(s.contains("no answer from the server"), "{s}");
    insta::assert_snapshot!(pane(&s));
}

#[test]
fn a_block_download_shows_segment_numbers_and_the_acknowledge() {
    let Some(rw) = realworld() else {
        println!("note: ../shared/realworld/logs not found; skipped");
        return;
    };
    let mut app = opened(&rw.join("canopendemo_sdo_block_interlaced.txt"));
    // Node 4's transfer: caught in its first sub-block, segments 111 to 127 from the
    // client, then the server's acknowledge, then the next sub-block from segment 1.
    let all = &app.trace().transactions;
    let i = all
        .iter()
        .position(|t| t.node == 4)
        .unwrap_or_else(|| panic!("{}", all.len()));
    open_diagram(&mut app, i);
    let s = draw(&mut app, 120, 30);
    assert!(s.contains("SDO transfer ????:?? node 4 — block download"), "{s}");
    assert!(s.contains("client (0x604)"), "{s}");
    assert!(s.contains("│ block seq 111 ──"), "{s}");
    assert!(s.contains("│ block seq 127 ──"), "{s}");
    assert!(s.contains(" block ack ackseq=127 blksize=127 │"), "{s}");
    let ack = s.find("block ack ackseq=127").unwrap();
    assert!(s[ack..].contains("│ block seq 1 ──"), "{s}");
    // The other node's frames, interlaced on the bus, are not in this diagram.
    assert!(!s.contains("0x583"), "{s}");
    insta::assert_snapshot!(pane(&s));
    // `end` goes to the last row: the capture ends in a sub-block, unanswered.
    app.act(Action::Bottom);
    let s = draw(&mut app, 120, 30);
    assert!(s.contains("│ block seq 21 ──"), "{s}");
    assert!(s.contains("no answer from the server"), "{s}");
    assert!(!s.contains("block seq 111"), "{s}");
}

#[test]
fn enter_on_an_arrow_shows_its_frame_in_the_trace_and_detail() {
    let mut app = mix();
    let i = transfer(&app, 3, 0x1008);
    let second = app.trace().transactions.get(i).expect("the transfer").frames[1];
    open_diagram(&mut app, i);
    app.act(Action::Down);
    let s = draw(&mut app, 160, 30);
    // Detail follows the selected arrow already.
    assert!(s.contains(&format!("frame {second}  t ")), "{s}");
    app.act(Action::Expand);
    let s = draw(&mut app, 160, 30);
    assert_eq!(app.focus(), Pane::Trace);
    assert!(s.contains(&format!("frame {second}  t ")), "{s}");
    assert!(s.contains("Upload response 0x1008:00"), "{s}");
    // Back in the SDO pane the diagram is still open; `back` returns to the list.
    app.act(Action::PaneSdo);
    assert!(draw(&mut app, 160, 30).contains("segmented upload, ok"));
    app.act(Action::Back);
    let s = draw(&mut app, 160, 30);
    assert!(s.contains("SDO transfers ("), "{s}");
}

#[test]
fn a_block_upload_has_the_segments_from_the_server_and_the_acknowledge_from_the_client() {
    let Some(rw) = realworld() else {
        println!("note: ../shared/realworld/logs not found; skipped");
        return;
    };
    let mut app = opened(&rw.join("canopendemo_sdo_block_interlaced.txt"));
    let all = &app.trace().transactions;
    let i = all
        .iter()
        .position(|t| t.node == 3)
        .unwrap_or_else(|| panic!("{}", all.len()));
    open_diagram(&mut app, i);
    let s = draw(&mut app, 120, 40);
    assert!(s.contains("SDO transfer ????:?? node 3 — block upload"), "{s}");
    assert!(s.contains("client (0x603)"), "{s}");
    // The client acknowledges (→) the sub-block the server sent (←).
    assert!(s.contains("│ block ack ackseq=127 blksize=127 ──"), "{s}");
    assert!(s.contains("─ block seq 1 │"), "{s}");
    assert!(!s.contains("│ block seq"), "{s}");
    insta::assert_snapshot!(pane(&s));
}
