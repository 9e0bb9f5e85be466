//! The Trace pane: one row per frame of the view, coloured by kind, with a tail strip of
//! the newest frames while scrolled back. It owns the view (the filter in force), the
//! search, the selection and follow mode, and the decoded rows of the visible window.

use super::{Component, Ctx, ListState, block, fit, header, kind_color, selected};
use crate::analysis::filter::Filter;
use crate::analysis::trace::Trace;
use crate::analysis::view::View;
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use crate::tui::rows::{Row, RowCache};
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use std::time::Duration;

/// Rows of the tail strip.
pub const TAIL: usize = 3;

/// The Trace pane's state.
pub struct TracePane {
    /// The filtered view of the trace.
    view: View,
    /// Scroll state (rows of the view).
    list: ListState,
    /// Follow the newest frame.
    follow: bool,
    /// Decoded rows of the visible window.
    rows: RowCache,
}

impl Default for TracePane {
    fn default() -> TracePane {
        TracePane {
            view: View::default(),
            list: ListState::default(),
            follow: true,
            rows: RowCache::default(),
        }
    }
}

impl TracePane {
    /// The filtered view (what an export writes).
    pub fn view(&self) -> &View {
        &self.view
    }

    /// The filter in force.
    pub fn filter(&self) -> &Filter {
        &self.view.filter
    }

    /// Follows the newest frame (`true`) or stays on the selection.
    pub fn set_follow(&mut self, on: bool) {
        self.follow = on;
    }

    /// True while following the newest frame.
    pub fn following(&self) -> bool {
        self.follow
    }

    /// Scans the view on for up to `budget` (settled first when the source `done`);
    /// returns (work is left, rows changed).
    pub fn work(&mut self, trace: &Trace, done: bool, budget: Duration) -> (bool, bool) {
        if done {
            self.view.settle();
        }
        let before = self.view.len(trace);
        let more = self.view.advance(trace, budget);
        (more, self.view.len(trace) != before)
    }

    /// Rows in the view.
    pub fn len(&self, trace: &Trace) -> usize {
        self.view.len(trace)
    }

    /// Forgets every frame (the source started over); the filter stays.
    pub fn reset(&mut self) {
        self.view = View::new(self.view.filter.clone());
        self.rows = RowCache::default();
        self.list = ListState::default();
    }

    /// The trace position of the selected row.
    pub fn selected_position(&self, trace: &Trace) -> Option<usize> {
        let n = self.len(trace);
        (n > 0).then(|| self.view.position(self.list.selected.min(n - 1)))
    }

    /// Selects the row of trace position `pos` (or the nearest before it) and stops following.
    pub fn select_position(&mut self, trace: &Trace, pos: usize, page: usize) {
        self.follow = false;
        self.list.selected = self.view.row_of(pos);
        self.list.clamp(self.len(trace), page);
    }

    /// Shows the rows `filter` keeps, the selected frame staying selected when it still shows.
    pub fn set_filter(&mut self, trace: &Trace, filter: Filter, page: usize) {
        let pos = self.selected_position(trace);
        self.view = View::new(filter);
        self.view.advance(trace, Duration::from_millis(30));
        self.list.selected = pos.map(|p| self.view.row_of(p)).unwrap_or(0);
        self.list.clamp(self.len(trace), page);
        self.rows = RowCache::default();
    }

    /// Shows every frame and selects trace position `pos`.
    pub fn show(&mut self, trace: &Trace, pos: usize, page: usize) {
        self.view = View::new(Filter::default());
        self.select_position(trace, pos, page);
    }

    /// Before drawing: pins the selection to the newest row in follow mode and decodes the
    /// visible window (`height` rows) and the tail strip.
    pub fn prepare(&mut self, trace: &Trace, height: usize, tail: &[usize]) {
        let n = self.len(trace);
        if self.follow {
            self.list.selected = n.saturating_sub(1);
        }
        self.list.clamp(n, height);
        let mut positions: Vec<usize> = (self.list.offset..(self.list.offset + height).min(n))
            .map(|r| self.view.position(r))
            .collect();
        positions.extend_from_slice(tail);
        positions.sort_unstable();
        positions.dedup();
        self.rows.fill(trace, &positions);
    }

    /// The decoded row for a trace position, when it is in the visible window.
    pub fn row(&self, pos: usize) -> Option<&Row> {
        self.rows.get(pos)
    }

    /// Splits the pane into the table rows and the tail strip (empty when following).
    pub fn split(&self, trace: &Trace, area: Rect) -> (Rect, Rect) {
        let inner = block("", true).inner(area);
        let body = Rect {
            y: inner.y.saturating_add(1),
            height: inner.height.saturating_sub(1),
            ..inner
        };
        let tail = if !self.follow && self.len(trace) > body.height as usize && body.height as usize > TAIL * 3 {
            TAIL as u16 + 1
        } else {
            0
        };
        let [rows, strip] = Layout::vertical([Constraint::Min(0), Constraint::Length(tail)]).areas(body);
        (rows, strip)
    }

    /// Trace positions shown in the tail strip.
    pub fn tail_positions(&self, trace: &Trace, strip: Rect) -> Vec<usize> {
        if strip.height == 0 {
            return Vec::new();
        }
        let n = self.len(trace);
        (n.saturating_sub(TAIL)..n).map(|r| self.view.position(r)).collect()
    }

    fn cells(&self, pos: usize, width: u16) -> Vec<Span<'static>> {
        cells(self.row(pos), pos, width)
    }
}

impl Component for TracePane {
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            if action == Action::Bottom {
                self.follow = true;
            }
            return true;
        }
        match action {
            Action::Expand => q.answer(Event::Detail),
            _ => false,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.follow = false;
        self.list.scroll(delta, self.len(ctx.trace), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.follow = false;
        self.list.click(row, self.len(ctx.trace), ctx.page);
    }

    /// Draws the pane; [`TracePane::prepare`] must have made the rows.
    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let title = format!(
            " Trace {}{} ",
            if self.follow { "[follow]" } else { "[scrolled]" },
            if ctx.paused { " [paused]" } else { "" }
        );
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let head = Rect { height: 1, ..inner };
        let heading = if compact(inner.width) {
            format!(
                "{:>9} {:<4} {:<6} {:>3} {:<16} label",
                "time", "cob", "kind", "nd", "data"
            )
        } else {
            format!(
                "{:>12} {:<9} {:<9} {:>3} {:<23} label",
                "time", "cob-id", "kind", "nd", "data"
            )
        };
        f.render_widget(Paragraph::new(Line::styled(heading, header())), head);
        let (rows, strip) = self.split(ctx.trace, area);
        let l = self.list;
        let lines: Vec<Line> = (l.offset..(l.offset + rows.height as usize).min(self.len(ctx.trace)))
            .map(|r| {
                let line = Line::from(self.cells(self.view.position(r), rows.width));
                if r == l.selected { line.style(selected()) } else { line }
            })
            .collect();
        f.render_widget(Paragraph::new(lines), rows);
        if strip.height > 0 {
            let mut lines = vec![Line::styled(
                fit(&format!("── newest {:─<200}", " "), strip.width as usize),
                Style::default().fg(Color::DarkGray),
            )];
            lines.extend(
                self.tail_positions(ctx.trace, strip)
                    .into_iter()
                    .map(|p| Line::from(self.cells(p, strip.width))),
            );
            f.render_widget(Paragraph::new(lines), strip);
        }
    }
}

/// Below this width the columns before the label narrow (time in ms, 3-digit COB-IDs,
/// short kinds, data bytes unspaced) so the label, what a bench reads, keeps most of the row.
const COMPACT_BELOW: u16 = 90;

fn compact(width: u16) -> bool {
    width < COMPACT_BELOW
}

/// The cells of one row: the decoded `row` of trace position `pos`, or just its number.
fn cells(row: Option<&Row>, pos: usize, width: u16) -> Vec<Span<'static>> {
    let Some(r) = row else {
        return vec![Span::raw(format!("{:>12}", pos + 1))];
    };
    let color = kind_color(r.kind);
    if compact(width) {
        let kind = match r.kind {
            crate::decode::Kind::Heartbeat => "hb",
            crate::decode::Kind::ErrorFrame => "error",
            k => k.as_str(),
        };
        let cols = [
            format!("{:>9.3} ", r.time),
            format!("{:<4} ", r.cob),
            format!("{:<6} ", kind),
            format!("{:>3} ", r.node),
            format!("{:<16} ", r.data.replace(' ', "")),
        ];
        let used: usize = cols.iter().map(|c| c.chars().count()).sum();
        let label_w = (width as usize).saturating_sub(used);
        let label = if r.malformed.is_some() && label_w > 2 {
            format!("! {}", fit(&r.label, label_w - 2))
        } else {
            fit(&r.label, label_w)
        };
        let [time, cob, kind, node, data] = cols;
        return vec![
            Span::raw(time),
            Span::styled(cob, Style::default().fg(color)),
            Span::styled(kind, Style::default().fg(color)),
            Span::raw(node),
            Span::raw(data),
            Span::styled(
                label,
                Style::default().fg(if r.malformed.is_some() { Color::LightRed } else { color }),
            ),
        ];
    }
    let used = 12 + 1 + 9 + 1 + 9 + 1 + 3 + 1 + 23 + 1;
    let label_w = (width as usize).saturating_sub(used);
    let mut label = fit(&r.label, label_w);
    if r.malformed.is_some() && label_w > 2 {
        label = format!("! {}", fit(&r.label, label_w - 2));
    }
    vec![
        Span::raw(format!("{:>12.6} ", r.time)),
        Span::styled(format!("{:<9} ", r.cob), Style::default().fg(color)),
        Span::styled(format!("{:<9} ", r.kind.as_str()), Style::default().fg(color)),
        Span::raw(format!("{:>3} ", r.node)),
        Span::raw(format!("{:<23} ", r.data)),
        Span::styled(
            label,
            Style::default().fg(if r.malformed.is_some() { Color::LightRed } else { color }),
        ),
    ]
}
