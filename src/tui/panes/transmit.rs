//! The Transmit pane: the entries of a transmit list (`--transmit FILE`, the format of
//! `send --list`, [`crate::command::transmit_list`]), each with the exact frame it sends,
//! its period, whether it is enabled and how many frames went out. Its keys ask the
//! application ([`crate::tui::transmit`]) to toggle, add, edit, delete and save entries.

use super::{Component, Ctx, ListState, block, fit, header, selected};
use crate::command::transmit_list::Resolved;
use crate::command::transmit_run::{ListProgress, lock_all};
use crate::tui::event::{Event, Queue, TransmitAsk};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::{Constraint, Rect};
use ratatui::style::{Color, Style};
use ratatui::widgets::{Row, Table};
use std::path::PathBuf;

/// One entry of the list: its JSON text (what is saved) and what it resolves to, or why not.
#[derive(Clone, Debug)]
pub(crate) struct TxRow {
    pub(crate) raw: String,
    pub(crate) entry: Result<Resolved, String>,
    /// Frames sent by the lists sent before the current one (a change restarts the list).
    pub(crate) sent_before: u64,
}

/// The Transmit pane's state.
#[derive(Default)]
pub struct TransmitPane {
    /// The list file (`w` saves there).
    pub(crate) file: Option<PathBuf>,
    pub(crate) rows: Vec<TxRow>,
    /// The counts of the list being sent: one per resolved row, in order.
    pub(crate) progress: ListProgress,
    list: ListState,
    /// The row the prompt edits (None: the prompt adds one).
    pub(crate) editing: Option<usize>,
}

impl TransmitPane {
    /// The selected row, if there is one.
    pub(crate) fn selected_row(&self) -> Option<usize> {
        (self.list.selected < self.rows.len()).then_some(self.list.selected)
    }

    /// Selects row `k` (after adding one).
    pub(crate) fn select(&mut self, k: usize) {
        self.list.selected = k;
    }

    /// Frames sent so far by row `k` (bad rows: none).
    pub fn sent(&self, k: usize) -> u64 {
        let Some(row) = self.rows.get(k) else { return 0 };
        let slot = self.rows[..k].iter().filter(|r| r.entry.is_ok()).count();
        let now = lock_all(&self.progress).get(slot).map_or(0, |t| t.sent);
        row.sent_before + if row.entry.is_ok() { now } else { 0 }
    }

    /// The entries as they are, in order (the rows that resolve).
    pub(crate) fn entries(&self) -> Vec<Resolved> {
        self.rows.iter().filter_map(|r| r.entry.clone().ok()).collect()
    }

    /// The text of the list file: `{"entries": [...]}`, one entry a line.
    pub(crate) fn file_text(&self) -> String {
        let lines: Vec<String> = self.rows.iter().map(|r| format!("    {}", r.raw)).collect();
        format!("{{\n  \"entries\": [\n{}\n  ]\n}}\n", lines.join(",\n"))
    }
}

/// `every 100 ms`, `once`, `5 times`, `every 10 ms, 50 times`.
fn schedule_text(e: &Resolved) -> String {
    match (e.schedule.every_ms, e.schedule.count) {
        (Some(p), Some(n)) => format!("every {p} ms, {n}×"),
        (Some(p), None) => format!("every {p} ms"),
        (None, Some(n)) => format!("{n}× at once"),
        (None, None) => "once".into(),
    }
}

impl Component for TransmitPane {
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(d) = ListState::movement(action, ctx.page) {
            self.list.scroll(d, self.rows.len(), ctx.page);
            return true;
        }
        let k = self.selected_row();
        let ask = match (action, k) {
            (Action::Pause, Some(k)) => TransmitAsk::Toggle(k),
            (Action::TransmitAdd, _) => TransmitAsk::Add,
            (Action::EditObject, Some(k)) => TransmitAsk::Edit(k),
            (Action::TransmitDelete, Some(k)) => TransmitAsk::Delete(k),
            (Action::SlowestCycle, _) => TransmitAsk::Save,
            (Action::Pause | Action::EditObject | Action::TransmitDelete, None) => {
                return q.answer(Event::Note("transmit: no entry (a: add one)".into()));
            }
            _ => return false,
        };
        q.answer(Event::Transmit(ask))
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, self.rows.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, self.rows.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, _ctx: &Ctx) {
        self.list.clamp(self.rows.len(), height);
    }

    fn render(&self, f: &mut Frame, area: Rect, _ctx: &Ctx, focused: bool) {
        let file = self
            .file
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_else(|| "no file".into());
        let title = format!(" Transmit — {file} — space: on/off  a: add  e: edit  d: delete  w: save ");
        let height = area.height.saturating_sub(3) as usize;
        let mut rows: Vec<Row> = self
            .rows
            .iter()
            .enumerate()
            .skip(self.list.offset)
            .take(height.max(1))
            .map(|(k, r)| {
                let cells = match &r.entry {
                    Ok(e) => vec![
                        format!("{}", k + 1),
                        if e.enabled { "on" } else { "off" }.to_string(),
                        e.what.clone(),
                        schedule_text(e),
                        self.sent(k).to_string(),
                        e.comment.clone().unwrap_or_default(),
                    ],
                    Err(why) => vec![
                        format!("{}", k + 1),
                        "bad".into(),
                        fit(&r.raw, 40),
                        String::new(),
                        String::new(),
                        why.clone(),
                    ],
                };
                let style = match (&r.entry, k == self.list.selected && focused) {
                    (_, true) => selected(),
                    (Err(_), _) => Style::default().fg(Color::Red),
                    (Ok(e), _) if e.enabled => Style::default().fg(Color::Green),
                    _ => Style::default(),
                };
                Row::new(cells).style(style)
            })
            .collect();
        if self.rows.is_empty() {
            rows.push(Row::new([
                String::new(),
                String::new(),
                "no entries (a: add one)".into(),
            ]));
        }
        let table = Table::new(
            rows,
            [
                Constraint::Length(3),
                Constraint::Length(3),
                Constraint::Min(30),
                Constraint::Length(16),
                Constraint::Length(7),
                Constraint::Min(10),
            ],
        )
        .header(Row::new(["#", "on", "frame", "period", "sent", "comment"]).style(header()))
        .block(block(&title, focused));
        f.render_widget(table, area);
    }
}
