//! The Watch pane: the objects `:watch NODE OBJ...` polls by SDO (CANopen Magic's watch
//! list), one row each: node, object, the last value (with its unit), min and max, the age
//! of the value, the period, and the last abort or timeout (absent: not polled again).
//! Its keys ask the application ([`crate::tui::watch`]) to add, delete, or open a row's
//! object in the Objects pane.

use super::{Component, Ctx, ListState, block, fit, header, selected};
use crate::tui::event::{Event, Queue, WatchAsk};
use crate::tui::keymap::Action;
use crate::tui::watch_board::{SharedBoard, WatchRow, lock};
use ratatui::Frame;
use ratatui::layout::{Constraint, Rect};
use ratatui::style::{Color, Style};
use ratatui::widgets::{Row, Table};

/// The Watch pane's state: the board the bus task fills, and the selection.
#[derive(Default)]
pub struct WatchPane {
    pub(crate) board: SharedBoard,
    list: ListState,
}

impl WatchPane {
    /// The selected row, if there is one.
    pub(crate) fn selected_row(&self) -> Option<usize> {
        (self.list.selected < self.len()).then_some(self.list.selected)
    }

    fn len(&self) -> usize {
        lock(&self.board).rows.len()
    }
}

/// The value's age at capture time `now_ns`: `0.4 s`, `-` before the first value.
fn age(r: &WatchRow, now_ns: u64) -> String {
    match r.at_ns {
        Some(t) => format!("{:.1} s", now_ns.saturating_sub(t) as f64 / 1e9),
        None => "-".into(),
    }
}

/// What the row's state column says: absent, stopped, the last failure, or nothing.
fn state(r: &WatchRow) -> String {
    let w = &r.watched;
    let last = w.last_error.clone().unwrap_or_default();
    match (w.absent, r.group) {
        (true, _) => format!("not polled again: {last}"),
        (false, None) if last.is_empty() => "stopped".into(),
        (false, None) => format!("stopped; last: {last}"),
        (false, Some(_)) if last.is_empty() => String::new(),
        (false, Some(_)) => format!("{} failed; last: {last}", w.failures),
    }
}

/// The object column: `0x6041 Statusword` (`:sub` when not 0).
fn object(r: &WatchRow) -> String {
    let w = &r.watched;
    let sub = if w.sub == 0 {
        String::new()
    } else {
        format!(":{}", w.sub)
    };
    let name = w.name.as_ref().map(|n| format!(" {n}")).unwrap_or_default();
    format!("0x{:04X}{sub}{name}", w.index)
}

impl Component for WatchPane {
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(d) = ListState::movement(action, ctx.page) {
            self.list.scroll(d, self.len(), ctx.page);
            return true;
        }
        let k = self.selected_row();
        let ask = match (action, k) {
            (Action::TransmitAdd, k) => {
                WatchAsk::Add(k.and_then(|k| lock(&self.board).rows.get(k).map(|r| r.watched.node)))
            }
            (Action::TransmitDelete, Some(k)) => WatchAsk::Delete(k),
            (Action::Expand, Some(k)) => WatchAsk::Open(k),
            (Action::TransmitDelete | Action::Expand, None) => {
                return q.answer(Event::Note("watch: nothing watched (a: add objects)".into()));
            }
            _ => return false,
        };
        q.answer(Event::Watch(ask))
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, self.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, self.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, _ctx: &Ctx) {
        let len = self.len();
        self.list.clamp(len, height);
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let board = lock(&self.board);
        let polling = board
            .rows
            .iter()
            .filter(|r| r.group.is_some() && !r.watched.absent)
            .count();
        let title = format!(
            " Watch — {} objects, {polling} polled — a: add  d: delete  enter: open in Objects ",
            board.rows.len()
        );
        let now = ctx.trace.nodes.now_ns();
        let height = area.height.saturating_sub(3) as usize;
        let mut rows: Vec<Row> = board
            .rows
            .iter()
            .enumerate()
            .skip(self.list.offset)
            .take(height.max(1))
            .map(|(k, r)| {
                let w = &r.watched;
                let cells = vec![
                    w.node.to_string(),
                    fit(&object(r), 30),
                    match (&w.last_text, w.absent) {
                        (Some(t), _) => t.clone(),
                        (None, true) => "absent".into(),
                        (None, false) => "-".into(),
                    },
                    w.min_text.clone().unwrap_or_default(),
                    w.max_text.clone().unwrap_or_default(),
                    age(r, now),
                    format!("{} ms", r.every_ms),
                    state(r),
                ];
                let style = match (k == self.list.selected && focused, w.absent, &w.last_error) {
                    (true, _, _) => selected(),
                    (_, true, _) => Style::default().fg(Color::DarkGray),
                    (_, _, Some(_)) => Style::default().fg(Color::Yellow),
                    _ => Style::default(),
                };
                Row::new(cells).style(style)
            })
            .collect();
        if board.rows.is_empty() {
            rows.push(Row::new([
                String::new(),
                "nothing watched (a: add)".into(),
                ":watch NODE OBJ... [--every DUR] [--timeout DUR]".into(),
            ]));
        }
        let table = Table::new(
            rows,
            [
                Constraint::Length(4),
                Constraint::Length(30),
                Constraint::Fill(2),
                Constraint::Length(10),
                Constraint::Length(10),
                Constraint::Length(7),
                Constraint::Length(8),
                Constraint::Fill(3),
            ],
        )
        .header(
            Row::new([
                "node",
                "object",
                "value",
                "min",
                "max",
                "age",
                "every",
                "last abort / timeout",
            ])
            .style(header()),
        )
        .block(block(&title, focused));
        f.render_widget(table, area);
    }
}
