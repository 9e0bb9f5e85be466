//! The Plot pane: numeric PDO signals and SDO-read values over one time axis.
//!
//! Value signals are laid out by [`PlotMode`]: each in its own lane with its own y axis
//! (the default), normalised 0..1 on one axis, one axis per unit, or a fixed range; so a
//! constant 0x1000 next to a velocity never flattens it. State signals (objects with value
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
    /// How the value axes are laid out.
    mode: PlotMode,
    /// The times (ns) of the trigger's hits, drawn as vertical marks.
    hits: Vec<u64>,
}

/// How the plot lays out the value signals' y axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PlotMode {
    /// Each signal in its own horizontal lane, with its own y axis and unit.
    #[default]
    Lanes,
    /// One axis, each signal scaled 0..1 over the visible window.
    Normalised,
    /// One axis per unit: signals of the same unit share it (different units: one lane each).
    Shared,
    /// One axis with a fixed y range (in the signals' units).
    Range(f64, f64),
}

impl PlotMode {
    /// Parses `lanes`, `normalised` (`normalized`), `shared` or `range LO HI`.
    pub fn parse(words: &str) -> Option<PlotMode> {
        let w: Vec<&str> = words.split_whitespace().collect();
        match w[..] {
            ["lanes"] => Some(PlotMode::Lanes),
            ["normalised" | "normalized"] => Some(PlotMode::Normalised),
            ["shared"] => Some(PlotMode::Shared),
            ["range", lo, hi] => {
                let (lo, hi) = (lo.parse::<f64>().ok()?, hi.parse::<f64>().ok()?);
                (lo.is_finite() && hi.is_finite() && lo < hi).then_some(PlotMode::Range(lo, hi))
            }
            _ => None,
        }
    }

    /// The mode the cycle key goes to: lanes, normalised, shared, lanes (a range: lanes).
    pub fn next(self) -> PlotMode {
        match self {
            PlotMode::Lanes => PlotMode::Normalised,
            PlotMode::Normalised => PlotMode::Shared,
            PlotMode::Shared | PlotMode::Range(..) => PlotMode::Lanes,
        }
    }

    /// The mode's name, as the title and `plot mode` say it.
    pub fn name(self) -> String {
        match self {
            PlotMode::Lanes => "lanes".into(),
            PlotMode::Normalised => "normalised".into(),
            PlotMode::Shared => "shared".into(),
            PlotMode::Range(lo, hi) => format!("range {} {}", format_number(lo), format_number(hi)),
        }
    }
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

    /// The y axis layout.
    pub fn mode(&self) -> PlotMode {
        self.mode
    }

    /// Sets the y axis layout.
    pub fn set_mode(&mut self, mode: PlotMode) {
        self.mode = mode;
    }

    /// The time window drawn (None: nothing to draw).
    pub fn visible_window(&self, trace: &Trace) -> Option<TimeWindow> {
        self.span(trace).map(|s| self.window_in(s))
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
        if action == Action::PlotMode {
            self.mode = self.mode.next();
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
    let (bits, values): (Vec<&Shown>, Vec<&Shown>) = shown.iter().partition(|s| s.bits().is_some());
    let groups = groups(&values, p.mode);
    let mode = match p.mode {
        PlotMode::Shared if groups.len() > 1 => "shared: units differ, one lane per unit".to_string(),
        m => m.name(),
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
    let title = format!(
        " Plot: {} of {} signals, {mode}{zoom}{marks} ",
        shown.len(),
        trace.series.len()
    );
    f.render_widget(block(&title, focused), area);
    let inner = block("", true).inner(area);
    if inner.height < 3 || inner.width < 20 {
        return;
    }
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
    let scale = match p.mode {
        PlotMode::Normalised => Scale::Normalised,
        PlotMode::Range(lo, hi) => Scale::Fixed(lo, hi),
        PlotMode::Lanes | PlotMode::Shared => Scale::Auto,
    };
    let areas =
        Layout::vertical(vec![Constraint::Ratio(1, groups.len().max(1) as u32); groups.len()]).split(chart_area);
    let axes = Axes {
        win,
        t0,
        scale,
        time_labels: false,
        hits: &hits_in,
    };
    let plots: Vec<Plotted> = groups
        .iter()
        .map(|g| plotted(g, axes, chart_area.width as usize * 2))
        .collect();
    // As wide in every lane (the bottom one's first time label widens its own).
    let first_time = format!("{:.3}s", win.start - t0).chars().count();
    let y_label_w = plots
        .iter()
        .flat_map(|p| p.labels())
        .map(|l| l.chars().count())
        .fold(first_time, usize::max);
    for (i, ((group, plot), area)) in groups.iter().zip(&plots).zip(areas.iter()).enumerate() {
        let axes = Axes {
            time_labels: i + 1 == groups.len(),
            ..axes
        };
        chart(group, plot, axes, y_label_w, p.cursor, f, *area);
    }
    if !bits.is_empty() {
        lanes(&bits, axes, p.cursor, label_w, f, lanes_area);
    }
    f.render_widget(Paragraph::new(readout_text).wrap(Wrap { trim: false }), readout);
}

/// Seconds with three decimals.
fn secs(s: f64) -> String {
    format!("{s:.3}")
}

/// The value signals split into the charts drawn one above the other: one per signal
/// (lanes), one per unit (shared), else all on one.
fn groups<'a, 'b>(values: &[&'a Shown<'b>], mode: PlotMode) -> Vec<Vec<&'a Shown<'b>>> {
    match mode {
        PlotMode::Lanes => values.iter().map(|s| vec![*s]).collect(),
        PlotMode::Shared => {
            let mut out: Vec<Vec<&Shown>> = Vec::new();
            for s in values {
                match out.iter_mut().find(|g| g[0].unit() == s.unit()) {
                    Some(g) => g.push(s),
                    None => out.push(vec![*s]),
                }
            }
            out
        }
        PlotMode::Normalised | PlotMode::Range(..) if values.is_empty() => Vec::new(),
        PlotMode::Normalised | PlotMode::Range(..) => vec![values.to_vec()],
    }
}

/// How one chart scales its values.
#[derive(Clone, Copy)]
enum Scale {
    /// From the lowest to the highest value in the window.
    Auto,
    /// Each signal 0..1 over its own lowest and highest value in the window.
    Normalised,
    /// A fixed range.
    Fixed(f64, f64),
}

/// The axes of one chart: the window, the time base, the scale, whether this chart
/// carries the time labels (the bottom one), and the trigger's hits (seconds) to mark.
#[derive(Clone, Copy)]
struct Axes<'a> {
    win: TimeWindow,
    t0: f64,
    scale: Scale,
    time_labels: bool,
    hits: &'a [f64],
}

/// Lowest and highest of `pts`' values (a flat line: ±1 around it; none: 0..1).
fn bounds<'a>(pts: impl Iterator<Item = &'a (f64, f64)>) -> (f64, f64) {
    let (mut lo, mut hi) = pts.fold((f64::MAX, f64::MIN), |(lo, hi), (_, v)| (lo.min(*v), hi.max(*v)));
    if lo > hi {
        (lo, hi) = (0.0, 1.0);
    }
    if (hi - lo).abs() < f64::EPSILON {
        lo -= 1.0;
        hi += 1.0;
    }
    (lo, hi)
}

/// One chart's points (as drawn: scaled, normalised, steps) and its value bounds.
struct Plotted {
    data: Vec<Vec<(f64, f64)>>,
    lo: f64,
    hi: f64,
}

impl Plotted {
    /// The value axis labels (lowest, highest).
    fn labels(&self) -> [String; 2] {
        [format_number(self.lo), format_number(self.hi)]
    }
}

/// The points of `values` in the window, `columns` wide, scaled as `axes` says.
fn plotted(values: &[&Shown], axes: Axes, columns: usize) -> Plotted {
    let Axes { win, t0, scale, .. } = axes;
    let mut data: Vec<Vec<(f64, f64)>> = values
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
    let (lo, hi) = match scale {
        Scale::Auto => bounds(data.iter().flatten()),
        Scale::Fixed(lo, hi) => (lo, hi),
        Scale::Normalised => {
            for d in &mut data {
                let (a, b) = bounds(d.iter());
                for p in d.iter_mut() {
                    p.1 = (p.1 - a) / (b - a);
                }
            }
            (0.0, 1.0)
        }
    };
    Plotted { data, lo, hi }
}

/// Signals on one chart: the time axis, the legend, units (or the scale) on the value axis
/// (its labels `label_w` wide, so that lanes share the time columns), the cursor as a
/// vertical line.
fn chart(values: &[&Shown], p: &Plotted, axes: Axes, label_w: usize, cursor: Option<f64>, f: &mut Frame, area: Rect) {
    let Axes {
        win, t0, scale, hits, ..
    } = axes;
    let Plotted { data, lo, hi } = p;
    let (lo, hi) = (*lo, *hi);
    let cursor_line: Vec<(f64, f64)> = cursor
        .filter(|c| (win.start..=win.end).contains(c))
        .map(|c| vec![(c - t0, lo), (c - t0, hi)])
        .unwrap_or_default();
    // One line per column at most: hits closer than a column draw the same mark.
    let step = (win.end - win.start) / (area.width as usize * 2).max(1) as f64;
    let mut hit_lines: Vec<[(f64, f64); 2]> = Vec::new();
    for &h in hits {
        if hit_lines.last().is_none_or(|l| h - t0 - l[0].0 >= step) {
            hit_lines.push([(h - t0, lo), (h - t0, hi)]);
        }
    }
    let mut sets: Vec<Dataset> = values
        .iter()
        .zip(data)
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
    let y_title = match scale {
        Scale::Normalised => "normalised".to_string(),
        Scale::Auto | Scale::Fixed(..) => units.join(", "),
    };
    let (x0, x1) = (win.start - t0, win.end - t0);
    let mut x_axis = Axis::default().bounds([x0, x1]);
    if axes.time_labels {
        x_axis = x_axis.labels([
            Line::raw(format!("{x0:.3}s")),
            Line::raw(format!("{:.3}s", (x0 + x1) / 2.0)),
            Line::raw(format!("{x1:.3}s")),
        ]);
    }
    let chart = Chart::new(sets)
        .hidden_legend_constraints((Constraint::Ratio(2, 3), Constraint::Ratio(2, 3)))
        .x_axis(x_axis)
        .y_axis(
            Axis::default()
                .title(y_title)
                .bounds([lo, hi])
                .labels(p.labels().map(|l| Line::raw(format!("{l:<label_w$}")))),
        );
    f.render_widget(chart, area);
}

/// One lane per named bit: `█` set, `▁` clear, `▒` both within a column, blank before the
/// first value; the cursor's column is shown reversed, a trigger hit's column marked `▼`
/// above the lanes and on a red ground in them.
fn lanes(bits: &[&Shown], axes: Axes, cursor: Option<f64>, label_w: u16, f: &mut Frame, area: Rect) {
    let win = axes.win;
    let cols = area.width.saturating_sub(label_w + 1) as usize;
    let width = win.width() / cols.max(1) as f64;
    let col_of = |t: f64| (((t - win.start) / width) as usize).min(cols.saturating_sub(1));
    let cursor_col = cursor.filter(|c| (win.start..=win.end).contains(c)).map(col_of);
    // The trigger's hits: a `▼` above the signal's lanes, its cells marked in every lane.
    let mut hit_cols = vec![false; cols];
    for &h in axes.hits {
        if let Some(c) = hit_cols.get_mut(col_of(h)) {
            *c = true;
        }
    }
    let mut out: Vec<Line> = Vec::new();
    for s in bits {
        let Some(names) = s.bits() else { continue };
        let bold = Style::default().fg(s.color).add_modifier(Modifier::BOLD);
        if hit_cols.contains(&true) {
            let label = fit(&s.name, label_w as usize);
            let marks: String = hit_cols.iter().map(|&h| if h { '▼' } else { ' ' }).collect();
            out.push(Line::from(vec![
                Span::styled(format!("{label:<w$} ", w = label_w as usize), bold),
                Span::styled(marks, Style::default().fg(Color::LightRed)),
            ]));
        } else {
            out.push(Line::styled(fit(&s.name, area.width as usize), bold));
        }
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
                let mut style = Style::default().fg(s.color);
                if Some(c) == cursor_col {
                    style = style.add_modifier(Modifier::REVERSED);
                } else if hit_cols[c] {
                    style = style.bg(Color::LightRed);
                }
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
