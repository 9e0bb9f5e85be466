//! The Trace pane: one row per frame of the view, coloured by kind, with a tail strip of
//! the newest frames while scrolled back. It owns the view (the filter in force), the
//! search, the selection and follow mode, the decoded rows of the visible window, and the
//! trigger in force (its hits marked `*` after the time).

use super::trace_time::{self, TimeMode};
use super::{Component, Ctx, ListState, block, fit, header, kind_color, selected};
use crate::analysis::filter::Filter;
use crate::analysis::trace::Trace;
use crate::analysis::view::View;
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use crate::tui::rows::{Row, RowCache};
use crate::tui::trigger::TriggerScan;
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use std::collections::BTreeSet;
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
    /// What the time column shows.
    time_mode: TimeMode,
    /// Bookmarked trace positions.
    marks: BTreeSet<usize>,
    /// The current bookmark (last set or jumped to) and its timestamp: what the `mark` time
    /// mode counts from.
    mark: Option<(usize, u64)>,
    /// The trigger in force (`:trigger EXPR`).
    trigger: Option<TriggerScan>,
    /// The bookmarks loaded from the sidecar file, with their timestamps.
    loaded: Vec<(usize, u64)>,
}

impl Default for TracePane {
    fn default() -> TracePane {
        TracePane {
            view: View::default(),
            list: ListState::default(),
            follow: true,
            rows: RowCache::default(),
            time_mode: TimeMode::default(),
            marks: BTreeSet::new(),
            mark: None,
            trigger: None,
            loaded: Vec::new(),
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
        let mut more = self.view.advance(trace, budget);
        let mut changed = self.view.len(trace) != before;
        if let Some(t) = &mut self.trigger {
            let hits = t.hits().len();
            more |= t.advance(trace, budget);
            changed |= t.hits().len() != hits;
        }
        (more, changed)
    }

    /// The capture clock reached `now_ns` with no new frame: the trigger's time-only hits
    /// (see [`TriggerScan::tick`]); true when one was found.
    pub fn trigger_tick(&mut self, trace: &Trace, now_ns: u64) -> bool {
        self.trigger.as_mut().is_some_and(|t| t.tick(trace, now_ns))
    }

    /// The trigger in force.
    pub fn trigger(&self) -> Option<&TriggerScan> {
        self.trigger.as_ref()
    }

    /// Puts `trigger` in force (none: `:trigger off`).
    pub fn set_trigger(&mut self, trigger: Option<TriggerScan>) {
        self.trigger = trigger;
    }

    /// What the time column shows.
    pub fn time_mode(&self) -> TimeMode {
        self.time_mode
    }

    /// Shows the time column in `mode`.
    pub fn set_time_mode(&mut self, mode: TimeMode) {
        self.time_mode = mode;
    }

    /// Bookmarked trace positions, rising.
    pub fn marks(&self) -> impl Iterator<Item = usize> + '_ {
        self.marks.iter().copied()
    }

    /// Bookmarked trace positions with their timestamps (those of frames not arrived yet:
    /// as loaded).
    pub fn marks_with_times(&self, trace: &Trace) -> Vec<(usize, u64)> {
        self.marks
            .iter()
            .map(|&p| {
                let ns = match self.loaded.iter().find(|(q, _)| *q == p) {
                    Some((_, ns)) if p >= trace.store.len() => *ns,
                    _ if p < trace.store.len() => trace.store.packed(p).ts_ns,
                    _ => 0,
                };
                (p, ns)
            })
            .collect()
    }

    /// Bookmarks as loaded from a sidecar file (position, timestamp).
    pub fn set_marks(&mut self, marks: Vec<(usize, u64)>) {
        self.marks = marks.iter().map(|(p, _)| *p).collect();
        self.mark = marks.first().copied();
        self.loaded = marks;
    }

    /// Sets a bookmark on the selected frame, or removes the one there.
    fn toggle_mark(&mut self, trace: &Trace) {
        let Some(pos) = self.selected_position(trace) else {
            return;
        };
        if self.marks.remove(&pos) {
            if self.mark.is_some_and(|(m, _)| m == pos) {
                self.mark = self.marks.iter().next().map(|&p| (p, trace.store.packed(p).ts_ns));
            }
        } else {
            self.marks.insert(pos);
            self.mark = Some((pos, trace.store.packed(pos).ts_ns));
        }
    }

    /// Selects the next bookmark after the selected frame (wrapping to the first).
    fn next_mark(&mut self, trace: &Trace, page: usize) {
        let from = self.selected_position(trace);
        let next = from
            .and_then(|p| self.marks.range(p + 1..).next())
            .or_else(|| self.marks.iter().next())
            .copied();
        if let Some(pos) = next {
            self.mark = Some((pos, trace.store.packed(pos).ts_ns));
            self.select_position(trace, pos, page);
        }
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
        let time = Time {
            mode: self.time_mode,
            mark_ns: self.mark.map(|(_, ns)| ns),
            marked: self.marks.contains(&pos),
            hit: self.trigger.as_ref().is_some_and(|t| t.is_hit(pos)),
        };
        cells(self.row(pos), pos, width, &time)
    }

    /// The title: follow state, time mode, bookmarks.
    fn title(&self, paused: bool) -> String {
        let mut marks: Vec<String> = self.marks.iter().take(6).map(|p| format!("#{}", p + 1)).collect();
        if self.marks.len() > 6 {
            marks.push(format!("+{}", self.marks.len() - 6));
        }
        format!(
            " Trace {}{} [time: {}]{} ",
            if self.follow { "[follow]" } else { "[scrolled]" },
            if paused { " [paused]" } else { "" },
            self.time_mode.name(),
            if marks.is_empty() {
                String::new()
            } else {
                format!(" [marks {}]", marks.join(" "))
            }
        )
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
            Action::TimeMode => {
                self.time_mode = self.time_mode.next();
                true
            }
            Action::Bookmark => {
                self.toggle_mark(ctx.trace);
                true
            }
            Action::NextBookmark => {
                self.next_mark(ctx.trace, ctx.page);
                true
            }
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
        let title = self.title(ctx.paused);
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

/// How the time column reads: the mode, the current bookmark's time, this row is marked.
struct Time {
    mode: TimeMode,
    mark_ns: Option<u64>,
    marked: bool,
    /// This row is a hit of the trigger in force.
    hit: bool,
}

impl Time {
    /// The time cell of `row`, `width` wide with `decimals`, and a trailing space.
    fn cell(&self, row: &Row, width: usize, decimals: usize) -> Span<'static> {
        let text = format!(
            "{}{}",
            trace_time::format(self.mode, &row.stamps, self.mark_ns, width, decimals),
            if self.hit { '*' } else { ' ' }
        );
        if self.marked {
            Span::styled(text, Style::default().fg(Color::Black).bg(Color::Yellow))
        } else if self.hit {
            Span::styled(text, Style::default().fg(Color::LightRed))
        } else {
            Span::raw(text)
        }
    }
}

/// The cells of one row: the decoded `row` of trace position `pos`, or just its number.
fn cells(row: Option<&Row>, pos: usize, width: u16, time: &Time) -> Vec<Span<'static>> {
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
            time.cell(r, 9, 3).content.into_owned(),
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
        let [_, cob, kind, node, data] = cols;
        return vec![
            time.cell(r, 9, 3),
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
        time.cell(r, 12, 6),
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
