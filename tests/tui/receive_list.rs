//! The receive list (Stats pane) of the real binary in tmux: the bytes that changed since
//! the previous frame of a COB-ID are highlighted (yellow, bold), and the sort key orders
//! the rows by count.

use crate::tmux::Options;
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_cotui");

/// The screen text without escape sequences.
fn plain(s: &str) -> String {
    let mut out = String::new();
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c == '\x1b' {
            for d in chars.by_ref() {
                if d.is_ascii_alphabetic() {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The characters of a captured line, each with whether it is drawn in yellow (SGR 33 or
/// 38;5;3; reset by 0, 39 or an empty list).
fn yellow_cells(line: &str) -> Vec<(char, bool)> {
    let mut out = Vec::new();
    let mut yellow = false;
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        if c != '\x1b' {
            out.push((c, yellow));
            continue;
        }
        let mut seq = String::new();
        for d in chars.by_ref() {
            if d.is_ascii_alphabetic() {
                break;
            }
            seq.push(d);
        }
        let params: Vec<&str> = seq.trim_start_matches('[').split(';').collect();
        let mut i = 0;
        while i < params.len() {
            match params[i] {
                "" | "0" | "39" => yellow = false,
                "33" => yellow = true,
                "38" if params.get(1 + i) == Some(&"5") => {
                    yellow = params.get(i + 2) == Some(&"3");
                    i += 2;
                }
                _ => {}
            }
            i += 1;
        }
    }
    out
}

#[test]
fn receive_list_highlights_changed_bytes_and_sorts_by_count() {
    let dir = std::env::temp_dir().join(format!("cotui-rxlist-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // 0x181 three times (byte 1 changes last), 0x3A0 once, 0x701 twice.
    let log = "(1.000000) can0 701#05\n\
               (1.010000) can0 181#1122334455\n\
               (1.020000) can0 181#1122334455\n\
               (1.030000) can0 3A0#0102\n\
               (1.040000) can0 181#11AA334455\n\
               (1.050000) can0 701#05\n";
    std::fs::write(dir.join("rx.log"), log).unwrap();
    let name = format!("cotui-rxlist-{}", std::process::id());
    let s = Options::default()
        .size(160, 30)
        .key_delay(Duration::ZERO)
        .colours()
        .start(&name, &format!("cd {} && {BIN} open rx.log; sleep 60", dir.display()));
    s.wait_for("the trace", |t| plain(t).contains("6 frames"));
    s.type_text("4");
    let screen = s.wait_for("the receive list", |t| plain(t).contains("Receive list by cob-id"));
    let row = screen
        .lines()
        .find(|l| plain(l).contains("181        3"))
        .unwrap_or_else(|| panic!("a row for 0x181:\n{}", plain(&screen)));
    // Only AA (byte 1, the one that changed) is drawn in yellow.
    let cells = yellow_cells(row);
    let want: Vec<char> = "11 AA 33 44 55".chars().collect();
    let at = cells
        .windows(want.len())
        .position(|w| w.iter().map(|(c, _)| *c).eq(want.iter().copied()))
        .unwrap_or_else(|| panic!("{row:?}"));
    let hot: String = cells[at..at + 14]
        .iter()
        .map(|(_, y)| if *y { 'y' } else { '.' })
        .collect();
    assert_eq!(hot, "...yy.........", "{row:?}");
    // The sort key: most frames first.
    s.type_text("s");
    let screen = plain(&s.wait_for("the sort by count", |t| plain(t).contains("Receive list by count")));
    let order: Vec<&str> = screen
        .lines()
        .filter_map(|l| l.strip_prefix('┃'))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|w| ["181", "701", "3A0"].contains(w))
        .collect();
    assert_eq!(order, ["181", "701", "3A0"], "{screen}");
    s.type_text("q");
    let _ = std::fs::remove_dir_all(&dir);
}
