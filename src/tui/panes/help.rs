//! The help popup: the keys of the keymap in force, every palette command with its syntax
//! (the commander's from their clap declarations) and the filter language, scrollable.

use super::{block, header};
use crate::tui::keymap::{Action, Keymap};
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Clear, Paragraph};
use std::cell::Cell;

/// The palette's own commands (besides the commander's), with their syntax.
pub const PALETTE_SYNTAX: &[(&str, &str)] = &[
    ("filter EXPR", "Set the filter (empty: clear it)"),
    ("search EXPR", "Search (same language as the filter)"),
    ("goto N", "Frame N (a replay plays or seeks to just after it)"),
    ("time SECONDS", "Time from the first frame (a replay seeks there)"),
    ("speed X", "Replay speed: 0 = as fast as possible, else 0.01 to 1000"),
    ("pause", "Pause the capture / replay"),
    ("resume", "Resume it"),
    ("rewind", "Replay: start over from the first frame"),
    ("plot NODE INDEX:SUB", "Plot a signal of a node"),
    (
        "export FILE [--format candump|jsonl|pcapng] [--force]",
        "Write the rows the view shows",
    ),
    (
        "record start FILE [--force|--append]",
        "Live/demo: record the frames received to a candump -l log",
    ),
    ("record stop", "End the recording"),
    ("help", "This help"),
    ("messages", "The message log"),
    ("quit", "Quit"),
    (
        "jobs [stop ID]",
        "Cyclic jobs (send/sync/pdo --every): list, or stop one",
    ),
    (
        "sim fault NODE CODE | silence|resume|reboot NODE | mains NODE on|off | status",
        "Demo: make a simulated drive fail (EMCY + Fault, no heartbeat, boot-up)",
    ),
];

/// The filter language, one line per form.
const FILTER_SYNTAX: &[(&str, &str)] = &[
    ("node 3, node 2-5", "frames of a node, of a range of nodes"),
    (
        "sdo, kind hb",
        "frames of a kind (nmt sync emcy time tpdo rpdo pdo sdo hb lss ...)",
    ),
    ("id 181, id 700-77f", "a COB-ID (hex), a range of them"),
    ("id 180/780", "an ID mask: id & 0x780 == 0x180"),
    ("tx, rx", "frames cotui sent, frames received"),
    (
        "time 1.5-3, time 10-",
        "seconds from the first frame (both ends included)",
    ),
    (
        "6041:00, Statusword",
        "frames that carry the object (SDO or mapped PDO)",
    ),
    ("Statusword & 0x8", "... whose raw value has a bit of the mask set"),
    ("Velocity actual value > 1000", "... compared: == != < <= > >="),
    (
        "abort, abort 0x0602",
        "SDO frames of aborted transfers (by code prefix)",
    ),
    ("\"free text\"", "the decoded label contains the text"),
    ("a b, a and b", "both"),
    ("a or b", "either (or binds loosest)"),
    ("not a, !a", "not (binds tightest)"),
    ("( ... )", "grouping"),
];

/// The help popup's state: shown, scrolled.
#[derive(Default)]
pub struct HelpPopup {
    /// The popup is shown.
    pub shown: bool,
    /// The first line shown.
    scroll: usize,
    /// Lines visible and the largest scroll at the last draw.
    fit: Cell<(usize, usize)>,
}

impl HelpPopup {
    /// `help` shows or hides the popup, `back` closes it, row and page moves scroll it
    /// while it is shown; false when `action` is not for it.
    pub fn handle(&mut self, action: Action) -> bool {
        let (page, max) = self.fit.get();
        let page = page.max(1);
        match action {
            Action::Help => {
                self.shown = !self.shown;
                self.scroll = 0;
            }
            Action::Back if self.shown => self.shown = false,
            _ if !self.shown => return false,
            Action::Down => self.scroll = (self.scroll + 1).min(max),
            Action::Up => self.scroll = self.scroll.saturating_sub(1),
            Action::PageDown => self.scroll = (self.scroll + page).min(max),
            Action::PageUp => self.scroll = self.scroll.saturating_sub(page),
            Action::Top => self.scroll = 0,
            Action::Bottom => self.scroll = max,
            _ => return false,
        }
        true
    }

    /// Draws the popup for `keymap` over `area`.
    pub fn render(&self, keymap: &Keymap, f: &mut Frame, area: Rect) {
        let w = area.width.min(100);
        let body = lines(keymap, w.saturating_sub(2) as usize);
        let h = (body.len() as u16 + 2).min(area.height);
        let r = Rect {
            x: area.x + (area.width - w) / 2,
            y: area.y + (area.height - h) / 2,
            width: w,
            height: h,
        };
        let visible = h.saturating_sub(2) as usize;
        let max = body.len().saturating_sub(visible);
        self.fit.set((visible, max));
        let top = self.scroll.min(max);
        let scroll = if max > 0 {
            let end = (top + visible).min(body.len());
            format!(", {} scroll ({}-{end} of {})", keymap_keys(keymap), top + 1, body.len())
        } else {
            String::new()
        };
        let title = format!(" Help — esc closes{scroll} ");
        f.render_widget(Clear, r);
        let text: Vec<Line> = body.into_iter().skip(top).take(visible).collect();
        f.render_widget(Paragraph::new(text).block(block(&title, true)), r);
    }
}

/// The keys that scroll, as the title names them (`down/up, pagedown/pageup`).
fn keymap_keys(keymap: &Keymap) -> String {
    let k = |a| keymap.key_for(a).unwrap_or_default();
    format!(
        "{}/{}, {}/{}",
        k(Action::Down),
        k(Action::Up),
        k(Action::PageDown),
        k(Action::PageUp)
    )
}

/// The help text at `width` columns: keys, palette commands, filter language.
pub fn lines(keymap: &Keymap, width: usize) -> Vec<Line<'static>> {
    let mut out = vec![Line::styled("keys", header())];
    for (a, keys) in keymap.help() {
        pair(&mut out, &keys.join(", "), a.help(), 18, width);
    }
    out.push(Line::raw(""));
    out.push(Line::styled(
        "palette commands (: opens the palette, tab completes)",
        header(),
    ));
    for (syntax, about) in PALETTE_SYNTAX {
        pair(&mut out, syntax, about, 30, width);
    }
    // The palette records with `record start`/`record stop` (above), not the CLI's `record -o`.
    for (syntax, about) in crate::command::syntax::usages() {
        if !syntax.starts_with("record ") {
            pair(&mut out, &syntax, &about, 30, width);
        }
    }
    out.push(Line::raw(""));
    out.push(Line::styled(
        "filter and search language (/ and ctrl-f, cotui decode --filter)",
        header(),
    ));
    for (form, about) in FILTER_SYNTAX {
        pair(&mut out, form, about, 30, width);
    }
    out
}

/// `left` in a column of `col`, then `right`; when they do not fit on one line of `width`,
/// `right` goes on the lines below, indented and wrapped at words.
fn pair(out: &mut Vec<Line<'static>>, left: &str, right: &str, col: usize, width: usize) {
    let left_len = left.chars().count();
    let pad = col.max(left_len + 1);
    if pad + right.chars().count() <= width {
        out.push(Line::raw(format!("{left:<pad$}{right}")));
        return;
    }
    out.push(Line::raw(left.to_string()));
    let indent = 4.min(width / 4);
    let mut line = String::new();
    for word in right.split_whitespace() {
        if !line.is_empty() && indent + line.chars().count() + 1 + word.chars().count() > width {
            out.push(Line::raw(format!("{:indent$}{line}", "")));
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        out.push(Line::raw(format!("{:indent$}{line}", "")));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_palette_command_has_its_syntax_in_the_help() {
        for word in crate::tui::app::PALETTE_COMMANDS {
            assert!(
                PALETTE_SYNTAX
                    .iter()
                    .any(|(s, _)| s.split_whitespace().next() == Some(word)),
                "{word} has no syntax line"
            );
        }
        let text: Vec<String> = lines(&Keymap::default_map(), 80)
            .iter()
            .map(|l| l.to_string())
            .collect();
        for word in crate::command::syntax::commander_words() {
            assert!(
                text.iter().any(|l| l.starts_with(&format!("{word} "))),
                "{word} missing"
            );
        }
        assert!(text.iter().all(|l| l.chars().count() <= 80), "{text:#?}");
    }

    #[test]
    fn scrolling_stops_at_both_ends() {
        let mut h = HelpPopup::default();
        assert!(!h.handle(Action::Down));
        h.handle(Action::Help);
        h.fit.set((20, 50));
        h.handle(Action::Up);
        assert_eq!(h.scroll, 0);
        h.handle(Action::PageDown);
        h.handle(Action::Down);
        assert_eq!(h.scroll, 21);
        for _ in 0..5 {
            h.handle(Action::PageDown);
        }
        assert_eq!(h.scroll, 50);
        h.handle(Action::PageUp);
        assert_eq!(h.scroll, 30);
        h.handle(Action::Top);
        assert_eq!(h.scroll, 0);
    }
}
