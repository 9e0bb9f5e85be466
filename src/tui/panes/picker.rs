//! The signal picker popup of the Plot pane: every series seen, filtered as the user types
//! (fuzzy, by node, index, name and alias); enter adds the selected signal to the plot or
//! takes it away.

use super::{block, fit, selected};
use crate::analysis::series::SeriesKey;
use crate::analysis::trace::Trace;
use crate::tui::fuzzy;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Clear, Paragraph};

/// One signal the picker offers.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// The series.
    key: SeriesKey,
    /// What is matched and shown: node, index:sub, name, alias, unit.
    text: String,
}

/// Every series of `trace` as picker candidates, in series order.
pub fn candidates(trace: &Trace) -> Vec<Candidate> {
    trace
        .series
        .keys()
        .into_iter()
        .map(|key @ (node, index, sub)| {
            let node = node.node;
            let dict = trace.decoder().dictionary(node);
            let name = dict
                .name(index, sub)
                .map(str::to_string)
                .or_else(|| trace.series.get(&key).map(|l| l.name.clone()))
                .unwrap_or_default();
            let info = dict.object(index, sub);
            let alias = info
                .and_then(|o| o.alias.as_deref())
                .map(|a| format!(" ({a})"))
                .unwrap_or_default();
            let unit = info
                .and_then(|o| o.unit.as_deref())
                .map(|u| format!(" [{u}]"))
                .unwrap_or_default();
            Candidate {
                key,
                text: format!("node {node:<3} {index:04X}:{sub:02X}  {name}{alias}{unit}"),
            }
        })
        .collect()
}

/// The candidates matching `query`, best first (series order among equals).
pub fn matching(query: &str, candidates: Vec<Candidate>) -> Vec<Candidate> {
    let mut scored: Vec<(i64, usize, Candidate)> = candidates
        .into_iter()
        .enumerate()
        .filter_map(|(i, c)| fuzzy::score(query, &c.text).map(|s| (s, i, c)))
        .collect();
    scored.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    scored.into_iter().map(|(_, _, c)| c).collect()
}

/// What a key did in the picker.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PickerEdit {
    /// Still picking.
    Editing,
    /// Closed without a choice.
    Closed,
    /// Add this signal to the plot, or take it away when shown.
    Toggle(SeriesKey),
}

/// The picker's state: the text typed and the selected match.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SignalPicker {
    /// The filter typed.
    query: String,
    /// The selected match (index into the matches).
    selected: usize,
}

impl SignalPicker {
    /// Handles a key: characters filter, up/down choose, enter picks, esc closes.
    pub fn key(&mut self, ev: KeyEvent, trace: &Trace) -> PickerEdit {
        let found = matching(&self.query, candidates(trace));
        match ev.code {
            KeyCode::Esc => return PickerEdit::Closed,
            KeyCode::Char('c') if ev.modifiers.contains(KeyModifiers::CONTROL) => return PickerEdit::Closed,
            KeyCode::Enter => {
                return match found.get(self.selected) {
                    Some(c) => PickerEdit::Toggle(c.key),
                    None => PickerEdit::Editing,
                };
            }
            KeyCode::Down => self.selected = (self.selected + 1).min(found.len().saturating_sub(1)),
            KeyCode::Up => self.selected = self.selected.saturating_sub(1),
            KeyCode::PageDown => self.selected = (self.selected + 10).min(found.len().saturating_sub(1)),
            KeyCode::PageUp => self.selected = self.selected.saturating_sub(10),
            KeyCode::Backspace => {
                self.query.pop();
                self.selected = 0;
            }
            KeyCode::Char(c) if !ev.modifiers.contains(KeyModifiers::CONTROL) => {
                self.query.push(c);
                self.selected = 0;
            }
            _ => {}
        }
        PickerEdit::Editing
    }

    /// Draws the popup over `area`; `shown` are the signals on the plot (marked).
    pub fn render(&self, trace: &Trace, shown: &[SeriesKey], f: &mut Frame, area: Rect) {
        let all = candidates(trace);
        let total = all.len();
        let found = matching(&self.query, all);
        let w = area.width.min(90);
        let h = (found.len() as u16 + 3).clamp(5, area.height.max(5)).min(area.height);
        let r = Rect {
            x: area.x + (area.width - w) / 2,
            y: area.y + (area.height - h) / 2,
            width: w,
            height: h,
        };
        let title = format!(
            " Pick signals ({} of {total}) — enter adds/removes, esc closes ",
            found.len()
        );
        f.render_widget(Clear, r);
        let inner = block("", true).inner(r);
        f.render_widget(block(&title, true), r);
        let width = inner.width as usize;
        let rows = (inner.height as usize).saturating_sub(1);
        let sel = self.selected.min(found.len().saturating_sub(1));
        let offset = (sel + 1).saturating_sub(rows);
        let mut lines = vec![Line::from(vec![
            Span::styled("> ", Style::default().fg(Color::Yellow)),
            Span::raw(self.query.clone()),
            Span::styled("_", Style::default().fg(Color::Yellow)),
        ])];
        if found.is_empty() {
            lines.push(Line::raw(if total == 0 {
                "no numeric signal seen yet"
            } else {
                "no signal matches"
            }));
        }
        for (i, c) in found.iter().enumerate().skip(offset).take(rows) {
            let mark = if shown.contains(&c.key) { "● " } else { "  " };
            let line = Line::raw(fit(&format!("{mark}{}", c.text), width));
            lines.push(if i == sel { line.style(selected()) } else { line });
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::NodeKey;

    fn c(node: u8, index: u16, text: &str) -> Candidate {
        Candidate {
            key: (NodeKey::new(0, node), index, 0),
            text: text.into(),
        }
    }

    #[test]
    fn matching_ranks_and_filters_by_any_part() {
        let all = vec![
            c(1, 0x1017, "node 1   1017:00  Producer heartbeat time [ms]"),
            c(1, 0x6041, "node 1   6041:00  Statusword"),
            c(2, 0x6041, "node 2   6041:00  Statusword"),
            c(1, 0x606C, "node 1   606C:00  Velocity actual value [rpm]"),
        ];
        let keys = |q: &str| -> Vec<SeriesKey> { matching(q, all.clone()).iter().map(|c| c.key).collect() };
        let n = |node| NodeKey::new(0, node);
        assert_eq!(keys("stw"), [(n(1), 0x6041, 0), (n(2), 0x6041, 0)]);
        assert_eq!(keys("stw node 2"), [(n(2), 0x6041, 0)]);
        assert_eq!(keys("rpm"), [(n(1), 0x606C, 0)]);
        assert_eq!(keys("606c"), [(n(1), 0x606C, 0)]);
        assert_eq!(keys("zz"), Vec::<SeriesKey>::new());
        assert_eq!(keys("").len(), 4);
    }
}
