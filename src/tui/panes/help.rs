//! The help popup: the keys of the keymap in force, every palette command with its syntax
//! (the commander's from their clap declarations) and the filter language, scrollable.

use super::{block, header};
use crate::tui::keymap::{Action, Keymap};
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::Line;
use ratatui::widgets::{Clear, Paragraph};
use std::cell::Cell;

/// The palette's own commands (besides the commander's), with their syntax.
pub const PALETTE_SYNTAX: &[(&str, &str)] = &[
    ("filter EXPR", "Set the filter (empty: clear it)"),
    ("search EXPR", "Search (same language as the filter)"),
    ("goto N", "Frame N (a replay plays or seeks to just after it)"),
    ("time SECONDS", "Time from the first frame (a replay seeks there)"),
    (
        "time [MODE]",
        "Trace time column: start, absolute, delta, delta-id, mark (none: the next)",
    ),
    ("speed X", "Replay speed: 0 = as fast as possible, else 0.01 to 1000"),
    ("pause", "Pause the capture / replay"),
    ("resume", "Resume it"),
    ("rewind", "Replay: start over from the first frame"),
    ("loop", "Replay: loop at the end (on/off)"),
    ("plot NODE INDEX:SUB", "Plot a signal of a node"),
    (
        "plot mode lanes|normalised|shared|range LO HI",
        "Plot y axes: a lane each, 0..1, one per unit, fixed",
    ),
    (
        "export FILE [--format candump|jsonl|pcapng] [--force]",
        "Write the rows the view shows",
    ),
    (
        "export plot FILE.csv [--all] [--force]",
        "The plotted signals as CSV (visible window; --all: every point)",
    ),
    (
        "export watch FILE.csv [--force]",
        "The Watch pane's rounds as CSV (as cotui watch --format csv)",
    ),
    (
        "watch NODE OBJ... [--every DUR] [--timeout DUR] | off",
        "Live/demo: poll objects by SDO in the Watch pane (0); off: stop every poll",
    ),
    (
        "record start FILE [--force|--append]",
        "Live/demo: record the frames received to a candump -l log",
    ),
    ("record stop", "End the recording"),
    (
        "trigger EXPR [--pre DUR] [--post DUR] | off",
        "Mark the hits of a trigger (n/N walk them; record start: only its windows)",
    ),
    (
        "bookmarks",
        "List the bookmarks (open FILE: kept in FILE.cotui-bookmarks.json)",
    ),
    (
        "expect NODE=FILE.dcf ... | off",
        "Compare the node's boots with a DCF (boot stories: B), as diagnose --expect",
    ),
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
        "iface can1",
        "frames of one interface (iface can1 node 5: node 5 of can1)",
    ),
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

/// The help popup's state: shown, scrolled, searched.
#[derive(Default)]
pub struct HelpPopup {
    /// The popup is shown.
    shown: bool,
    /// The first line shown.
    scroll: usize,
    /// Lines visible and the largest scroll at the last draw.
    fit: Cell<(usize, usize)>,
    /// Text width at the last draw (the lines wrap by it).
    width: Cell<usize>,
    /// The text searched for (case ignored); empty: none.
    query: String,
    /// Keys go to the query (after the filter or search key).
    typing: bool,
}

impl HelpPopup {
    /// `help` shows or hides the popup, `back` closes it, row and page moves scroll it
    /// while it is shown, the filter and search keys start typing a text to find, the
    /// match keys go to its next and previous line; false when `action` is not for it.
    pub fn handle(&mut self, action: Action, keymap: &Keymap) -> bool {
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
            Action::Filter | Action::Search => {
                self.typing = true;
                self.query.clear();
            }
            Action::NextMatch => self.find(keymap, self.scroll + 1, true),
            Action::PrevMatch => self.find(keymap, self.scroll.saturating_sub(1), false),
            _ => return false,
        }
        true
    }

    /// True while the popup is shown.
    pub fn shown(&self) -> bool {
        self.shown
    }

    /// Shows the popup (`help` in the palette).
    pub fn show(&mut self) {
        self.shown = true;
    }

    /// True while keys go to the text to find.
    pub fn typing(&self) -> bool {
        self.typing
    }

    /// A key while typing the text to find: characters add to it (the first line holding
    /// it comes to the top), backspace takes away, enter keeps it, esc drops it.
    pub fn type_key(&mut self, ev: KeyEvent, keymap: &Keymap) {
        match ev.code {
            KeyCode::Esc => {
                self.typing = false;
                self.query.clear();
            }
            KeyCode::Enter => self.typing = false,
            KeyCode::Backspace => {
                self.query.pop();
                self.find(keymap, 0, true);
            }
            KeyCode::Char(c) if !ev.modifiers.contains(KeyModifiers::CONTROL) => {
                self.query.push(c);
                self.find(keymap, 0, true);
            }
            _ => {}
        }
    }

    /// Scrolls to the first line holding the query from line `from` on (or back from it),
    /// going round; stays when no line holds it.
    fn find(&mut self, keymap: &Keymap, from: usize, forward: bool) {
        let hits = matches(&lines(keymap, self.width.get().max(20)), &self.query);
        let next = if forward {
            hits.iter().find(|&&i| i >= from).or(hits.first())
        } else {
            hits.iter().rev().find(|&&i| i <= from).or(hits.last())
        };
        if let Some(&i) = next {
            self.scroll = i;
        }
    }

    /// Draws the popup for `keymap` over `area`.
    pub fn render(&self, keymap: &Keymap, f: &mut Frame, area: Rect) {
        let w = area.width.min(100);
        self.width.set(w.saturating_sub(2) as usize);
        let body = lines(keymap, w.saturating_sub(2) as usize);
        let hits = matches(&body, &self.query);
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
        let title = match (self.typing, self.query.is_empty()) {
            (true, _) => format!(
                " Help — find: {}_ ({} lines), enter keeps, esc drops ",
                self.query,
                hits.len()
            ),
            (false, false) => format!(
                " Help — `{}`: {} lines, n/N — esc closes{scroll} ",
                self.query,
                hits.len()
            ),
            (false, true) => format!(" Help — esc closes{scroll} "),
        };
        f.render_widget(Clear, r);
        let hot = Style::default().fg(Color::Yellow).add_modifier(Modifier::BOLD);
        let text: Vec<Line> = body
            .into_iter()
            .enumerate()
            .skip(top)
            .take(visible)
            .map(|(i, l)| {
                if hits.binary_search(&i).is_ok() {
                    l.style(hot)
                } else {
                    l
                }
            })
            .collect();
        f.render_widget(Paragraph::new(text).block(block(&title, true)), r);
    }
}

/// The lines of `body` holding `query` (case ignored), rising; none for an empty query.
fn matches(body: &[Line], query: &str) -> Vec<usize> {
    if query.is_empty() {
        return Vec::new();
    }
    let q = query.to_lowercase();
    body.iter()
        .enumerate()
        .filter(|(_, l)| l.to_string().to_lowercase().contains(&q))
        .map(|(i, _)| i)
        .collect()
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
        for word in crate::tui::commands::PALETTE_COMMANDS {
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
    fn typing_finds_lines_and_match_keys_go_round() {
        let k = Keymap::default_map();
        let mut h = HelpPopup::default();
        h.handle(Action::Help, &k);
        h.width.set(98);
        assert!(h.handle(Action::Filter, &k));
        assert!(h.typing);
        for c in "ZOOM".chars() {
            h.type_key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE), &k);
        }
        let body = lines(&k, 98);
        let hits = matches(&body, "zoom");
        assert_eq!(hits.len(), 2, "zoom in and zoom out");
        assert_eq!(h.scroll, hits[0]);
        h.type_key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE), &k);
        assert!(!h.typing && h.query == "ZOOM");
        h.handle(Action::NextMatch, &k);
        assert_eq!(h.scroll, hits[1]);
        h.handle(Action::NextMatch, &k);
        assert_eq!(h.scroll, hits[0], "round to the first");
        h.handle(Action::PrevMatch, &k);
        assert_eq!(h.scroll, hits[1], "round back to the last");
        assert!(body[hits[1]].to_string().contains("Plot: zoom out"));
    }

    #[test]
    fn scrolling_stops_at_both_ends() {
        let mut h = HelpPopup::default();
        let k = Keymap::default_map();
        assert!(!h.handle(Action::Down, &k));
        h.handle(Action::Help, &k);
        h.fit.set((20, 50));
        h.handle(Action::Up, &k);
        assert_eq!(h.scroll, 0);
        h.handle(Action::PageDown, &k);
        h.handle(Action::Down, &k);
        assert_eq!(h.scroll, 21);
        for _ in 0..5 {
            h.handle(Action::PageDown, &k);
        }
        assert_eq!(h.scroll, 50);
        h.handle(Action::PageUp, &k);
        assert_eq!(h.scroll, 30);
        h.handle(Action::Top, &k);
        assert_eq!(h.scroll, 0);
    }
}
