//! The Plot pane: numeric PDO signals and SDO-read values over one time axis.
//!
//! Several signals share the axis (legend with colours); state signals (objects with value
//! texts or named bits, booleans) are drawn as steps, never as slopes; objects with named
//! bits (statusword, controlword) get one lane per bit. A cursor reads every signal's
//! value at its time; the window zooms and pans within the span seen. Only the points in
//! the window are touched per draw (binary search, then at most four per column).

use super::picker::SignalPicker;
use super::{Component, Ctx, block, fit};
use crate::analysis::series::{self, Line as Series, SeriesKey, TimeWindow};
use crate::analysis::trace::Trace;
use crate::od::{DataType, ObjectInfo, format_number};
use crate::tui::event::Queue;
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Chart, Dataset, GraphType, Paragraph, Wrap};
use std::cell::Cell;

/// Colours of the signals, in the order they were added.
const COLORS: [Color; 6] = [
    Color::Cyan,
    Color::Yellow,
    Color::LightMagenta,
    Color::LightGreen,
    Color::LightRed,
    Color::LightBlue,
];

/// Signals one plot shows at most.
pub const MAX_SIGNALS: usize = COLORS.len();

/// The Plot pane's state: the signals, the window, the cursor, the picker.
#[derive(Default)]
pub struct PlotPane {
    /// The signals shown, in the order added; empty: the first series seen.
    signals: Vec<SeriesKey>,
    /// The time window (seconds, the frames' time base); None: the whole span, following
    /// new data.
    window: Option<TimeWindow>,
    /// The cursor's time (seconds, the frames' time base).
    cursor: Option<f64>,
    /// The signal picker, while open.
    picker: Option<SignalPicker>,
    /// Columns of the time axis at the last draw (the cursor moves one column a key).
    columns: Cell<usize>,
    /// The times (ns) of the trigger's hits, drawn as vertical marks.
    hits: Vec<u64>,
}

impl PlotPane {
    /// The trigger's hits to mark (ns, rising; empty: no trigger).
    pub fn set_hits(&mut self, hits: Vec<u64>) {
        self.hits = hits;
    }

    /// The signals drawn: those chosen that exist, else the first series.
    pub fn shown(&self, trace: &Trace) -> Vec<SeriesKey> {
        let chosen: Vec<SeriesKey> = self
            .signals
            .iter()
            .copied()
            .filter(|k| trace.series.get(k).is_some())
            .collect();
        if chosen.is_empty() {
            trace.series.keys().into_iter().take(1).collect()
        } else {
            chosen
        }
    }

    /// Replaces the last signal by the next (or previous) series, going round.
    pub fn step(&mut self, trace: &Trace, forward: bool) {
        let keys = trace.series.keys();
        if keys.is_empty() {
            return;
        }
        let mut shown = self.shown(trace);
        let last = shown.pop().and_then(|k| keys.iter().position(|x| *x == k)).unwrap_or(0);
        let n = keys.len();
        let next = if forward { (last + 1) % n } else { (last + n - 1) % n };
        shown.retain(|k| *k != keys[next]);
        shown.push(keys[next]);
        self.signals = shown;
    }

    /// Shows only the series of `node` `index`:`sub` (of every interface with such a
    /// node); false when no such series was seen.
    pub fn select(&mut self, trace: &Trace, node: u8, index: u16, sub: u8) -> bool {
        let keys: Vec<SeriesKey> = trace
            .series
            .keys()
            .into_iter()
            .filter(|k| (k.0.node, k.1, k.2) == (node, index, sub))
            .collect();
        let ok = !keys.is_empty();
        if ok {
            self.signals = keys;
        }
        ok
    }

    /// Adds `key` to the plot, or takes it away when shown; the oldest signal makes room
    /// when [`MAX_SIGNALS`] are shown.
    pub fn toggle(&mut self, trace: &Trace, key: SeriesKey) {
        let mut shown = self.shown(trace);
        if let Some(at) = shown.iter().position(|k| *k == key) {
            shown.remove(at);
        } else {
            if shown.len() >= MAX_SIGNALS {
                shown.remove(0);
            }
            shown.push(key);
        }
        self.signals = shown;
    }

    /// Gives a key to the signal picker while it is open; false when it is not (the key is
    /// someone else's).
    pub fn picker_key(&mut self, ev: crossterm::event::KeyEvent, trace: &Trace) -> bool {
        use super::picker::PickerEdit;
        let Some(picker) = self.picker.as_mut() else {
            return false;
        };
        match picker.key(ev, trace) {
            PickerEdit::Editing => {}
            PickerEdit::Closed => self.picker = None,
            PickerEdit::Toggle(k) => {
                self.toggle(trace, k);
                self.picker = None;
            }
        }
        true
    }

    /// Opens the signal picker.
    pub fn open_picker(&mut self) {
        self.picker = Some(SignalPicker::default());
    }

    /// The time span of the signals shown (at least a millisecond wide).
    fn span(&self, trace: &Trace) -> Option<TimeWindow> {
        let (lo, hi) = self
            .shown(trace)
            .iter()
            .filter_map(|k| trace.series.get(k)?.span())
            .fold(None, |acc: Option<(f64, f64)>, (a, b)| {
                Some(acc.map_or((a, b), |(x, y)| (x.min(a), y.max(b))))
            })?;
        Some(TimeWindow {
            start: lo,
            end: hi.max(lo + series::MIN_WINDOW),
        })
    }

    /// The window drawn: the one chosen, else the whole span.
    fn window_in(&self, span: TimeWindow) -> TimeWindow {
        self.window.unwrap_or(span)
    }

    /// Moves the cursor by `columns` columns; the window pans to keep it visible.
    fn move_cursor(&mut self, columns: f64, span: TimeWindow) {
        let win = self.window_in(span);
        let step = win.width() / self.columns.get().max(1) as f64;
        let c = match self.cursor {
            Some(c) => (c + columns * step).clamp(span.start, span.end),
            None => win.start + win.width() / 2.0,
        };
        self.cursor = Some(c);
        if c < win.start || c > win.end {
            let d = if c < win.start { c - win.start } else { c - win.end };
            self.set_window(win.pan(d / win.width(), span), span);
        }
    }

    /// Sets the window; the whole span means following the data again.
    fn set_window(&mut self, w: TimeWindow, span: TimeWindow) {
        self.window = (w != span).then_some(w);
    }
}

impl Component for PlotPane {
    /// The seek keys move the cursor (a replay still seeks from the other panes and with
    /// `time`/`goto`), zoom keys zoom around it, page keys pan, `top` shows the whole span,
    /// `bottom` puts the cursor on the newest value, `back` removes the cursor, `expand`
    /// opens the picker.
    fn handle(&mut self, action: Action, ctx: &Ctx, _q: &mut Queue) -> bool {
        if action == Action::Expand || action == Action::PlotPick {
            self.open_picker();
            return true;
        }
        let Some(span) = self.span(ctx.trace) else {
            return false;
        };
        let win = self.window_in(span);
        match action {
            Action::SeekForward => self.move_cursor(1.0, span),
            Action::SeekBack => self.move_cursor(-1.0, span),
            Action::ZoomIn | Action::ZoomOut => {
                let f = if action == Action::ZoomIn { 0.5 } else { 2.0 };
                let around = self.cursor.unwrap_or(win.start + win.width() / 2.0);
                self.set_window(win.zoom(f, around, span), span);
            }
            Action::PageDown | Action::PageUp => {
                let d = if action == Action::PageDown { 0.5 } else { -0.5 };
                let moved = win.pan(d, span);
                if let Some(c) = self.cursor.as_mut() {
                    *c += moved.start - win.start;
                }
                self.set_window(moved, span);
            }
            Action::Top => {
                self.window = None;
                self.cursor = None;
            }
            Action::Bottom => {
                self.cursor = Some(span.end);
                if span.end > win.end {
                    self.set_window(win.pan((span.end - win.end) / win.width(), span), span);
                }
            }
            Action::Back if self.cursor.is_some() => self.cursor = None,
            _ => return false,
        }
        true
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        render(self, ctx.trace, f, area, focused);
        if let Some(p) = &self.picker {
            p.render(ctx.trace, &self.shown(ctx.trace), f, area);
        }
    }
}

/// What the plot knows of one signal shown.
struct Shown<'a> {
    key: SeriesKey,
    line: &'a Series,
    info: Option<&'a ObjectInfo>,
    name: String,
    color: Color,
}

impl Shown<'_> {
    /// Drawn as steps: value texts, named bits, booleans, or the CiA 402 state objects.
    fn is_state(&self) -> bool {
        matches!(self.key.1, 0x6040 | 0x6041 | 0x6060 | 0x6061)
            || self
                .info
                .is_some_and(|o| !o.values.is_empty() || !o.bits.is_empty() || o.data_type == DataType::Boolean)
    }

    /// Named bits, each drawn in a lane of its own.
    fn bits(&self) -> Option<&std::collections::BTreeMap<u8, String>> {
        self.info.map(|o| &o.bits).filter(|b| !b.is_empty())
    }

    fn scale(&self) -> f64 {
        self.info.and_then(|o| o.scale).unwrap_or(1.0)
    }

    fn unit(&self) -> Option<&str> {
        self.info.and_then(|o| o.unit.as_deref())
    }

    /// A raw value as the readout shows it: hex for bit sets, the value text, the unit.
    fn text(&self, raw: f64) -> String {
        if self.bits().is_some() {
            return format!("0x{:04X}", raw as i64 as u64 & 0xFFFF);
        }
        let mut s = format_number(raw * self.scale());
        if let Some(u) = self.unit() {
            s = format!("{s} {u}");
        }
        if let Some(t) = self.info.and_then(|o| o.values.get(&(raw as i64))) {
            s = format!("{s} ({t})");
        }
        s
    }
}

/// Draws the pane.
fn render(p: &PlotPane, trace: &Trace, f: &mut Frame, area: Rect, focused: bool) {
    let shown: Vec<Shown> = p
        .shown(trace)
        .into_iter()
        .enumerate()
        .filter_map(|(i, key)| {
            let line = trace.series.get(&key)?;
            let dict = trace.decoder().dictionary(key.0.node);
            Some(Shown {
                key,
                line,
                info: dict.object(key.1, key.2),
                name: format!("n{} {}", key.0.node, dict.name(key.1, key.2).unwrap_or(&line.name)),
                color: COLORS[i % COLORS.len()],
            })
        })
        .collect();
    let (Some(span), false) = (p.span(trace), shown.is_empty()) else {
        f.render_widget(block(" Plot ", focused), area);
        let inner = block("", true).inner(area);
        f.render_widget(
            Paragraph::new("no numeric signal seen yet (PDO signals need a mapping; SDO reads count too)"),
            inner,
        );
        return;
    };
    let win = p.window_in(span);
    let t0 = super::start_ns(trace) as f64 / 1e9;
    let zoom = if p.window.is_some() {
        format!(" {}–{} s", secs(win.start - t0), secs(win.end - t0))
    } else {
        String::new()
    };
    let hits_in: Vec<f64> = p
        .hits
        .iter()
        .map(|&ns| ns as f64 / 1e9)
        .filter(|t| (win.start..=win.end).contains(t))
        .collect();
    let marks = if p.hits.is_empty() {
        String::new()
    } else {
        format!(", {} trigger hits shown", hits_in.len())
    };
    let title = format!(" Plot: {} of {} signals{zoom}{marks} ", shown.len(), trace.series.len());
    f.render_widget(block(&title, focused), area);
    let inner = block("", true).inner(area);
    if inner.height < 3 || inner.width < 20 {
        return;
    }
    let (bits, values): (Vec<&Shown>, Vec<&Shown>) = shown.iter().partition(|s| s.bits().is_some());
    let lane_rows: u16 = bits.iter().map(|s| s.bits().map_or(0, |b| b.len() as u16) + 1).sum();
    let readout_text = readout_line(&shown, p.cursor, win, t0);
    let readout_h = (readout_text.width() as u16).div_ceil(inner.width).clamp(1, 3);
    let body = inner.height.saturating_sub(readout_h);
    let lanes_h = if values.is_empty() {
        body
    } else {
        lane_rows.min(body / 2)
    };
    let [chart_area, lanes_area, readout] = Layout::vertical([
        Constraint::Length(body - lanes_h),
        Constraint::Length(lanes_h),
        Constraint::Length(readout_h),
    ])
    .areas(inner);
    let label_w = (inner.width / 4).clamp(8, 24);
    p.columns.set((inner.width - label_w - 1).max(1) as usize);
    if !values.is_empty() {
        chart(&values, win, t0, p.cursor, &hits_in, f, chart_area);
    }
    if !bits.is_empty() {
        lanes(&bits, win, p.cursor, label_w, f, lanes_area);
    }
    f.render_widget(Paragraph::new(readout_text).wrap(Wrap { trim: false }), readout);
}

/// Seconds with three decimals.
fn secs(s: f64) -> String {
    format!("{s:.3}")
}

/// The value signals on one chart: a shared time axis, the legend, units on the value axis,
/// the cursor as a vertical line, the trigger's hits (`hits`, seconds) as red ones.
fn chart(values: &[&Shown], win: TimeWindow, t0: f64, cursor: Option<f64>, hits: &[f64], f: &mut Frame, area: Rect) {
    let columns = area.width as usize * 2;
    let data: Vec<Vec<(f64, f64)>> = values
        .iter()
        .map(|s| {
            let pts: Vec<(f64, f64)> = series::decimate(s.line.window(win.start, win.end), win.start, win.end, columns)
                .into_iter()
                .map(|(t, v)| (t.max(win.start) - t0, v * s.scale()))
                .collect();
            if s.is_state() {
                let until = s.line.span().map_or(win.end, |(_, e)| e.min(win.end)) - t0;
                series::steps(&pts, until)
            } else {
                pts
            }
        })
        .collect();
    let (mut lo, mut hi) = data
        .iter()
        .flatten()
        .fold((f64::MAX, f64::MIN), |(lo, hi), (_, v)| (lo.min(*v), hi.max(*v)));
    if lo > hi {
        (lo, hi) = (0.0, 1.0);
    }
    if (hi - lo).abs() < f64::EPSILON {
        lo -= 1.0;
        hi += 1.0;
    }
    let cursor_line: Vec<(f64, f64)> = cursor
        .filter(|c| (win.start..=win.end).contains(c))
        .map(|c| vec![(c - t0, lo), (c - t0, hi)])
        .unwrap_or_default();
    // One line per column at most: hits closer than a column draw the same mark.
    let step = (win.end - win.start) / columns.max(1) as f64;
    let mut hit_lines: Vec<[(f64, f64); 2]> = Vec::new();
    for &h in hits {
        if hit_lines.last().is_none_or(|l| h - t0 - l[0].0 >= step) {
            hit_lines.push([(h - t0, lo), (h - t0, hi)]);
        }
    }
    let mut sets: Vec<Dataset> = values
        .iter()
        .zip(&data)
        .map(|(s, d)| {
            let unit = s.unit().map(|u| format!(" [{u}]")).unwrap_or_default();
            Dataset::default()
                .name(format!("{}{unit}", s.name))
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(Style::default().fg(s.color))
                .data(d)
        })
        .collect();
    if !cursor_line.is_empty() {
        sets.push(
            Dataset::default()
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(Style::default().fg(Color::White))
                .data(&cursor_line),
        );
    }
    for l in &hit_lines {
        sets.push(
            Dataset::default()
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(Style::default().fg(Color::LightRed))
                .data(l),
        );
    }
    let mut units: Vec<&str> = values.iter().filter_map(|s| s.unit()).collect();
    units.dedup();
    let (x0, x1) = (win.start - t0, win.end - t0);
    let chart = Chart::new(sets)
        .hidden_legend_constraints((Constraint::Ratio(2, 3), Constraint::Ratio(2, 3)))
        .x_axis(Axis::default().bounds([x0, x1]).labels([
            Line::raw(format!("{x0:.3}s")),
            Line::raw(format!("{:.3}s", (x0 + x1) / 2.0)),
            Line::raw(format!("{x1:.3}s")),
        ]))
        .y_axis(
            Axis::default()
                .title(units.join(", "))
                .bounds([lo, hi])
                .labels([Line::raw(format_number(lo)), Line::raw(format_number(hi))]),
        );
    f.render_widget(chart, area);
}

/// One lane per named bit: `█` set, `▁` clear, `▒` both within a column, blank before the
/// first value; the cursor's column is shown reversed.
fn lanes(bits: &[&Shown], win: TimeWindow, cursor: Option<f64>, label_w: u16, f: &mut Frame, area: Rect) {
    let cols = area.width.saturating_sub(label_w + 1) as usize;
    let width = win.width() / cols.max(1) as f64;
    let cursor_col = cursor
        .filter(|c| (win.start..=win.end).contains(c))
        .map(|c| (((c - win.start) / width) as usize).min(cols.saturating_sub(1)));
    let mut out: Vec<Line> = Vec::new();
    for s in bits {
        let Some(names) = s.bits() else { continue };
        out.push(Line::styled(
            fit(&s.name, area.width as usize),
            Style::default().fg(s.color).add_modifier(Modifier::BOLD),
        ));
        // Per column: (seen low, seen high) of every bit, from the value held at the
        // column's start and each point inside it.
        let pts = s.line.window(win.start, win.end);
        let mut seen = vec![[0u16; 2]; cols];
        let mut held: Option<u16> = None;
        let mut i = 0;
        for (c, cell) in seen.iter_mut().enumerate() {
            let end = win.start + (c + 1) as f64 * width;
            let start = end - width;
            while i < pts.len() && pts[i].0 <= start {
                held = Some(pts[i].1 as i64 as u16);
                i += 1;
            }
            let mut vals: Vec<u16> = held.into_iter().collect();
            while i < pts.len() && pts[i].0 <= end {
                held = Some(pts[i].1 as i64 as u16);
                vals.push(pts[i].1 as i64 as u16);
                i += 1;
            }
            for v in vals {
                cell[0] |= !v;
                cell[1] |= v;
            }
        }
        // When the lanes do not all fit: the bits that change in the window first, then
        // those set, shown in bit order.
        let room = (area.height as usize).saturating_sub(out.len());
        let mut chosen: Vec<(&u8, &String)> = names.iter().collect();
        if chosen.len() > room {
            let rank = |bit: u8| {
                let mask = 1u16 << (bit & 15);
                let low = seen.iter().any(|c| c[0] & mask != 0);
                let high = seen.iter().any(|c| c[1] & mask != 0);
                (!(low && high), !high)
            };
            chosen.sort_by_key(|(b, _)| (rank(**b), **b));
            chosen.truncate(room);
            chosen.sort_by_key(|(b, _)| **b);
        }
        for (bit, name) in chosen {
            let mask = 1u16 << (*bit & 15);
            let label = fit(&format!("{bit:>2} {name}"), label_w as usize);
            let mut spans = vec![Span::raw(format!("{label:<w$} ", w = label_w as usize))];
            for (c, cell) in seen.iter().enumerate() {
                let ch = match (cell[0] & mask != 0, cell[1] & mask != 0) {
                    (true, true) => "▒",
                    (false, true) => "█",
                    (true, false) => "▁",
                    (false, false) => " ",
                };
                let style = if Some(c) == cursor_col {
                    Style::default().fg(s.color).add_modifier(Modifier::REVERSED)
                } else {
                    Style::default().fg(s.color)
                };
                spans.push(Span::styled(ch, style));
            }
            out.push(Line::from(spans));
        }
    }
    f.render_widget(Paragraph::new(out), area);
}

/// The readout (wrapped when long): at the cursor (or the window's end) the time and every signal's value.
fn readout_line(shown: &[Shown], cursor: Option<f64>, win: TimeWindow, t0: f64) -> Line<'static> {
    let (at, what) = match cursor {
        Some(c) => (c, "cursor"),
        None => (win.end, "end"),
    };
    let mut spans = vec![Span::styled(
        format!("{what} {} s", secs(at - t0)),
        Style::default().add_modifier(Modifier::BOLD),
    )];
    for s in shown {
        let v = s.line.at(at).map(|v| s.text(v)).unwrap_or_else(|| "-".into());
        spans.push(Span::raw("  "));
        spans.push(Span::styled(format!("{} = {v}", s.name), Style::default().fg(s.color)));
    }
    Line::from(spans)
}
