//! `:trigger EXPR` in the TUI (hits marked in the Trace, the status line, `n`/`N`) and the
//! bookmarks kept beside a log opened with `cotui open`.

use super::testutil::{app_of_log, screen};
use crate::tui::app::App;
use crate::tui::keymap::Action;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// The fixture's EMCY frames: lines 18, 19 and 20 (0x085 and twice 0x082).
const LOG: &str = "tests/fixtures/cia301_mix.log";

fn type_keys(a: &mut App, keys: &str) {
    for c in keys.chars() {
        let code = if c == '\n' { KeyCode::Enter } else { KeyCode::Char(c) };
        a.key(KeyEvent::new(code, KeyModifiers::NONE));
    }
}

/// The rows of the trace with the hit marker (`*` right after the time).
fn marked_rows(s: &str) -> Vec<String> {
    s.lines()
        .filter(|l| l.chars().nth(13) == Some('*'))
        .map(str::to_string)
        .collect()
}

#[test]
fn trigger_emcy_marks_exactly_the_emcy_rows_and_says_how_many_hits() {
    let mut a = app_of_log(LOG);
    type_keys(&mut a, ":trigger emcy\n");
    let s = screen(&mut a, 160, 70);
    let rows = marked_rows(&s);
    assert_eq!(rows.len(), 3, "{s}");
    for r in &rows {
        assert!(r.contains(" emcy "), "{r}");
    }
    let emcy_rows = s.lines().filter(|l| l.contains(" emcy ") && l.contains("08")).count();
    assert_eq!(emcy_rows, 3, "{s}");
    assert!(s.contains("trigger emcy: armed, 3 hits"), "{s}");
    type_keys(&mut a, ":trigger off\n");
    let s = screen(&mut a, 160, 70);
    assert!(marked_rows(&s).is_empty(), "{s}");
    assert!(!s.contains("armed"), "{s}");
}

#[test]
fn n_and_shift_n_walk_the_trigger_hits_and_wrap() {
    let mut a = app_of_log(LOG);
    type_keys(&mut a, ":trigger emcy --pre 2s --post 1s\n");
    a.act(Action::Top);
    let mut said = Vec::new();
    for k in ["n", "n", "n", "n", "N"] {
        type_keys(&mut a, k);
        said.push(a.message().unwrap_or_default().to_string());
    }
    assert_eq!(
        said,
        [
            "trigger hit 1 of 3 at frame 18",
            "trigger hit 2 of 3 at frame 19",
            "trigger hit 3 of 3 at frame 20",
            "trigger hit 1 of 3 at frame 18 (wrapped around)",
            "trigger hit 3 of 3 at frame 20 (wrapped around)",
        ]
    );
    let s = screen(&mut a, 160, 70);
    assert!(s.contains("trigger hit 3 of 3 at frame 20"), "{s}");
}

#[test]
fn a_bad_trigger_shows_its_column_in_the_status_bar_and_keeps_none() {
    let mut a = app_of_log(LOG);
    type_keys(&mut a, ":trigger node 3 and kind bogus\n");
    let s = screen(&mut a, 160, 30);
    assert!(s.contains("trigger: column 17: unknown kind `bogus`"), "{s}");
    assert!(a.screen().trigger().is_none());
    type_keys(&mut a, ":trigger emcy --pre soon\n");
    assert!(
        a.message().unwrap_or_default().contains("`soon` is not a duration"),
        "{:?}",
        a.message()
    );
}

#[test]
fn a_bookmark_goes_to_the_sidecar_file_and_comes_back_when_the_log_is_opened_again() {
    let dir = std::env::temp_dir().join(format!("cotui-ttrig-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("mix.log");
    std::fs::copy(format!("{}/{LOG}", env!("CARGO_MANIFEST_DIR")), &log).unwrap();
    let mut a = app_of_log(LOG);
    a.screen_mut().keep_bookmarks(&log);
    a.act(Action::Top);
    for _ in 0..4 {
        a.act(Action::Down);
    }
    a.act(Action::Bookmark);
    let side = dir.join("mix.log.cotui-bookmarks.json");
    let text = std::fs::read_to_string(&side).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(json["bookmarks"][0]["frame"], 5, "{text}");
    assert_eq!(json["bookmarks"][0]["t_ns"], 1_700_000_000_005_000_000u64, "{text}");

    let mut again = app_of_log(LOG);
    again.screen_mut().keep_bookmarks(&log);
    let s = screen(&mut again, 160, 30);
    assert!(s.contains("[marks #5]"), "{s}");
    type_keys(&mut again, ":bookmarks\n");
    assert_eq!(again.message(), Some("1 bookmarks: #5 at 0.004000 s"));

    // The list is in the message log too, open now; closed, the keys go to the trace again.
    assert!(screen(&mut again, 160, 30).contains("bookmark #5 at 0.004000 s"));
    again.act(Action::Back);
    // Cleared: the file says so.
    again.act(Action::Top);
    for _ in 0..4 {
        again.act(Action::Down);
    }
    again.act(Action::Bookmark);
    let text = std::fs::read_to_string(&side).unwrap();
    assert!(text.contains("\"bookmarks\": []"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_plot_title_counts_the_trigger_hits_in_its_window() {
    let mut a = super::testutil::plot_app();
    a.screen_mut().focus_on(crate::tui::panes::Pane::Plot);
    let before = screen(&mut a, 120, 30);
    assert!(!before.contains("trigger hits"), "{before}");
    // The drive faults at its 35th TPDO: 5 TPDOs carry the fault bit.
    type_keys(&mut a, ":trigger Statusword & 0x0008\n");
    a.screen_mut().focus_on(crate::tui::panes::Pane::Plot);
    let s = screen(&mut a, 120, 30);
    assert!(s.contains("trigger Statusword & 0x0008: armed, 5 hits"), "{s}");
    assert!(s.contains("5 trigger hits shown"), "{s}");
    // The statusword's bit lanes: a mark above each hit's column (one column holds two
    // hits here), and in each of them the Fault bit is set (`▒`: it rose in that column).
    let row = |name: &str| -> Vec<char> { s.lines().find(|l| l.contains(name)).unwrap().chars().collect() };
    let (head, fault) = (row("n1 Statusword"), row(" 3 Fault"));
    let marked: Vec<usize> = head
        .iter()
        .enumerate()
        .filter(|(_, c)| **c == '▼')
        .map(|(i, _)| i)
        .collect();
    assert_eq!(marked.len(), 5, "{s}");
    assert!(marked.iter().all(|&i| matches!(fault[i], '█' | '▒')), "{s}");
    let rose = fault.iter().position(|c| matches!(*c, '█' | '▒')).unwrap();
    assert_eq!(marked[0], rose, "the first hit is where the fault sets: {s}");
}
