//! The Stats pane, a receive list in the manner of PCAN-View: one row per COB-ID with its
//! rate over the last second, its age (capture time since its last frame), its period
//! (mean, then on wider terminals count, jitter, min, max and last), the latest data with
//! the bytes that changed since the previous frame of that COB-ID highlighted, and the
//! decoded label; the bus load from the bit rate in the title. A row whose age passed 3 of
//! its periods is dimmed (stale). A key cycles the sort.

use super::{Component, Ctx, ListState, block, duration, fit, header, selected};
use crate::analysis::stats::{IdStats, Stats};
use crate::analysis::trace::Trace;
use crate::output::busload::BitrateSource;
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use std::cell::RefCell;
use std::collections::HashMap;

/// The order of the rows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sort {
    /// By COB-ID, rising.
    #[default]
    Id,
    /// Most frames first.
    Count,
    /// Shortest mean period first (single frames last).
    Period,
    /// Most recently heard first.
    Last,
}

impl Sort {
    /// The next order in the cycle.
    pub fn next(self) -> Sort {
        match self {
            Sort::Id => Sort::Count,
            Sort::Count => Sort::Period,
            Sort::Period => Sort::Last,
            Sort::Last => Sort::Id,
        }
    }

    /// The name the title shows.
    pub fn name(self) -> &'static str {
        match self {
            Sort::Id => "cob-id",
            Sort::Count => "count",
            Sort::Period => "period",
            Sort::Last => "last heard",
        }
    }
}

/// A COB-ID: extended flag and identifier.
pub type CobKey = (bool, u32);

/// The rows in `sort` order (ties by COB-ID).
pub fn sorted(stats: &Stats, sort: Sort) -> Vec<(CobKey, IdStats)> {
    let mut rows: Vec<(CobKey, IdStats)> = stats.iter().map(|(k, s)| (*k, *s)).collect();
    match sort {
        Sort::Id => {}
        Sort::Count => rows.sort_by_key(|r| std::cmp::Reverse(r.1.count)),
        Sort::Period => rows.sort_by(|a, b| {
            let p = |s: &IdStats| s.period().unwrap_or(f64::INFINITY);
            p(&a.1).total_cmp(&p(&b.1))
        }),
        Sort::Last => rows.sort_by_key(|r| std::cmp::Reverse(r.1.last_ns)),
    }
    rows
}

/// Which bytes of `cur` differ from `prev` (all of them without a previous frame; bytes
/// beyond the previous length count as changed).
pub fn changed(prev: Option<&[u8]>, cur: &[u8]) -> Vec<bool> {
    cur.iter()
        .enumerate()
        .map(|(i, b)| prev.and_then(|p| p.get(i)) != Some(b))
        .collect()
}

/// The Stats pane's state: the selection, the sort, the labels decoded; or the SYNC
/// cycles view in its place.
#[derive(Default)]
pub struct StatsPane {
    /// The SYNC cycles view, shown instead of the receive list while `show_cycles`.
    cycles: super::cycles::CyclesView,
    show_cycles: bool,
    /// Scroll state.
    list: ListState,
    /// The order of the rows.
    sort: Sort,
    /// Decoded labels by store position (the rows last drawn), so a row is decoded once
    /// per new frame of its COB-ID.
    labels: RefCell<HashMap<usize, String>>,
}

impl Component for StatsPane {
    /// Moves the selection; `sort` cycles the order; `expand` shows the selected COB-ID's
    /// frames in the trace.
    /// `sync_cycles` shows the SYNC cycles instead (again: the receive list), and the
    /// cycle jumps show them; there `sort` goes back to the receive list.
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        match action {
            Action::SyncCycles => {
                self.show_cycles = !self.show_cycles;
                return true;
            }
            Action::SlowestCycle | Action::NextLateCycle => self.show_cycles = true,
            Action::Sort if self.show_cycles => {
                self.show_cycles = false;
                return true;
            }
            _ => {}
        }
        if self.show_cycles {
            return self.cycles.handle(action, ctx, q);
        }
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return true;
        }
        match action {
            Action::Sort => {
                self.sort = self.sort.next();
                true
            }
            Action::Expand => match sorted(&ctx.trace.stats, self.sort).get(self.list.selected) {
                Some(((_, id), _)) => q.answer(Event::Filter(format!("id {id:X}"))),
                None => true,
            },
            _ => false,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        if self.show_cycles {
            return self.cycles.scroll(delta, ctx);
        }
        self.list.scroll(delta, ctx.trace.stats.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        if self.show_cycles {
            return self.cycles.click(row, ctx);
        }
        self.list.click(row, ctx.trace.stats.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, ctx: &Ctx) {
        if self.show_cycles {
            return self.cycles.fit(height, ctx);
        }
        self.list.clamp(ctx.trace.stats.len(), height);
    }

    /// The Detail view shows the selected COB-ID's latest frame.
    fn selected(&self, ctx: &Ctx) -> Option<super::Selected> {
        if self.show_cycles {
            return self.cycles.selected(ctx);
        }
        let rows = sorted(&ctx.trace.stats, self.sort);
        rows.get(self.list.selected)
            .map(|(_, s)| super::Selected::Frame(s.last_pos))
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        if self.show_cycles {
            return self.cycles.render(f, area, ctx, focused);
        }
        let st = &ctx.trace.stats;
        let rate = st.bitrate();
        // A rate given with --bitrate goes without saying; else where it came from.
        let assumed = if rate.source == BitrateSource::Option {
            String::new()
        } else {
            format!(" ({})", rate.said())
        };
        let names = ctx.trace.ifaces.names();
        let load = if names.len() > 1 {
            // Several buses: each one's load (the bit rate is the same for all).
            let each: Vec<String> = (0..names.len() as u16)
                .map(|i| format!("{} {:.1}%", names[i as usize], st.iface_load_percent(i)))
                .collect();
            each.join(", ")
        } else {
            format!("{:.1}%", st.load_percent())
        };
        let title = format!(
            " Receive list by {} — bus load {load} at {} kbit/s{assumed}, {} fr in the last 1 s ",
            self.sort.name(),
            rate.bps / 1000,
            st.window_frames()
        );
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        // A wider COB-ID column once an extended one is seen; the columns that fit.
        let cw = if st.iter().any(|((ext, _), _)| *ext) { 9 } else { 4 };
        let cols = columns(inner.width as usize, cw);
        let mut head = format!("{:<cw$}", "cob");
        for c in &cols {
            head.push_str(&format!(" {:>w$}", c.name(), w = c.width()));
        }
        head.push_str(&format!("  {:<23}  label", "data"));
        let mut lines = vec![Line::styled(fit(&head, inner.width as usize), header())];
        let l = self.list;
        let now = st.now_ns();
        let rows: Vec<(CobKey, IdStats)> = sorted(st, self.sort)
            .into_iter()
            .skip(l.offset)
            .take(inner.height as usize - 1)
            .collect();
        let labels = self.labels(ctx.trace, &rows);
        for (i, ((ext, id), s)) in rows.iter().enumerate() {
            let cob = if *ext { format!("{id:08X}") } else { format!("{id:03X}") };
            let mut left = format!("{cob:<cw$}");
            for c in &cols {
                left.push_str(&format!(" {:>w$}", c.cell(s, st), w = c.width()));
            }
            left.push_str("  ");
            let cur = ctx.trace.store.frame(s.last_pos);
            let prev = s.prev_pos.map(|p| ctx.trace.store.frame(p));
            let mut spans = vec![Span::raw(left)];
            spans.extend(data_spans(prev.as_ref().map(|p| p.payload()), cur.payload()));
            let label = labels.get(&s.last_pos).map(String::as_str).unwrap_or("");
            let used: usize = spans.iter().map(|s| s.content.chars().count()).sum();
            spans.push(Span::raw(fit(label, (inner.width as usize).saturating_sub(used))));
            if s.stale(now) {
                // Stale: the whole row dim grey, changed bytes included.
                for sp in &mut spans {
                    sp.style = sp.style.patch(stale());
                }
            }
            let line = Line::from(spans);
            lines.push(if i + l.offset == l.selected {
                line.patch_style(selected())
            } else {
                line
            });
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}

impl StatsPane {
    /// The labels of the rows' last frames: those decoded before, the others decoded now
    /// in one forward walk; labels of rows no longer shown are dropped.
    fn labels(&self, trace: &Trace, rows: &[(CobKey, IdStats)]) -> HashMap<usize, String> {
        let mut cache = self.labels.borrow_mut();
        let mut want: Vec<usize> = rows.iter().map(|(_, s)| s.last_pos).collect();
        want.sort_unstable();
        let missing: Vec<usize> = want.iter().copied().filter(|p| !cache.contains_key(p)).collect();
        for (pos, d) in missing.iter().zip(trace.decode_positions(&missing)) {
            cache.insert(*pos, d.label);
        }
        cache.retain(|p, _| want.binary_search(p).is_ok());
        cache.clone()
    }
}

/// The style of a stale row (its age passed 3 of its periods).
pub fn stale() -> Style {
    Style::default().fg(Color::DarkGray).add_modifier(Modifier::DIM)
}

/// A column of the receive list between the COB-ID and the data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Column {
    /// Frames seen.
    Count,
    /// Frames in the last second of capture time.
    Rate,
    /// Capture time since the last frame.
    Age,
    /// Mean period.
    Period,
    /// The last period.
    Last,
    /// Shortest period.
    Min,
    /// Longest period.
    Max,
    /// Standard deviation of the period.
    Jitter,
}

impl Column {
    /// Left to right as drawn.
    const ORDER: [Column; 8] = [
        Column::Count,
        Column::Rate,
        Column::Age,
        Column::Period,
        Column::Jitter,
        Column::Min,
        Column::Max,
        Column::Last,
    ];
    /// Which columns a narrow terminal keeps first: whether a COB-ID is alive (age), its
    /// cycle time and rate, then the count and the cycle time's spread.
    const PRIORITY: [Column; 8] = [
        Column::Age,
        Column::Period,
        Column::Rate,
        Column::Count,
        Column::Jitter,
        Column::Min,
        Column::Max,
        Column::Last,
    ];

    fn name(self) -> &'static str {
        match self {
            Column::Count => "count",
            Column::Rate => "rate/s",
            Column::Age => "age",
            Column::Period => "period",
            Column::Last => "last",
            Column::Min => "min",
            Column::Max => "max",
            Column::Jitter => "jitter",
        }
    }

    fn width(self) -> usize {
        match self {
            Column::Count => 7,
            Column::Rate => 6,
            Column::Age => 7,
            _ => 9,
        }
    }

    fn cell(self, s: &IdStats, st: &Stats) -> String {
        let now_ns = st.now_ns();
        let d = |x: Option<f64>| x.map(duration).unwrap_or_else(|| "-".into());
        match self {
            Column::Count => s.count.to_string(),
            Column::Rate => format!("{:.1}", st.rate(s)),
            Column::Age => age(s.age(now_ns)),
            Column::Period => d(s.period()),
            Column::Last => d(s.last_period()),
            Column::Min => d(s.min_period()),
            Column::Max => d(s.max_period()),
            Column::Jitter => d(s.jitter()),
        }
    }
}

/// The label keeps at least this many columns before another column is shown.
const LABEL_MIN: usize = 20;

/// The columns shown in a pane `width` wide with a COB-ID column `cob_width` wide: in
/// [`Column::PRIORITY`] order while the label keeps [`LABEL_MIN`] columns, drawn in
/// [`Column::ORDER`].
pub fn columns(width: usize, cob_width: usize) -> Vec<Column> {
    // The COB-ID, two spaces, 23 columns of data, two spaces.
    let mut free = width.saturating_sub(cob_width + 27 + LABEL_MIN);
    let mut keep = Vec::new();
    for c in Column::PRIORITY {
        if c.width() + 1 > free {
            break;
        }
        free -= c.width() + 1;
        keep.push(c);
    }
    Column::ORDER.into_iter().filter(|c| keep.contains(c)).collect()
}

/// An age in at most 7 columns: `40 ms`, `2.5 s`, `125 s`, `2.1 h`.
pub fn age(secs: f64) -> String {
    if secs < 1.0 {
        format!("{:.0} ms", secs * 1e3)
    } else if secs < 100.0 {
        format!("{secs:.1} s")
    } else if secs < 3600.0 {
        format!("{secs:.0} s")
    } else {
        format!("{:.1} h", secs / 3600.0)
    }
}

/// The data bytes in hex, 23 columns wide; bytes that changed are yellow and bold.
fn data_spans(prev: Option<&[u8]>, cur: &[u8]) -> Vec<Span<'static>> {
    let hot = Style::default().fg(Color::Yellow).add_modifier(Modifier::BOLD);
    let shown = &cur[..cur.len().min(8)];
    let mut spans = Vec::new();
    for (i, (b, c)) in shown.iter().zip(changed(prev, shown)).enumerate() {
        if i > 0 {
            spans.push(Span::raw(" "));
        }
        let text = format!("{b:02X}");
        spans.push(if c { Span::styled(text, hot) } else { Span::raw(text) });
    }
    // 23 columns of data, then two spaces before the label.
    let mut pad = 25 - (shown.len() * 3).saturating_sub(1);
    if cur.len() > 8 {
        spans.push(Span::raw("…"));
        pad = pad.saturating_sub(1);
    }
    spans.push(Span::raw(" ".repeat(pad)));
    spans
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::store::Store;
    use crate::decode::Kind;
    use crate::frame::Frame;

    #[test]
    fn changed_bytes_are_those_that_differ_from_the_previous_frame() {
        assert_eq!(changed(Some(&[1, 2, 3]), &[1, 9, 3, 4]), [false, true, false, true]);
        assert_eq!(changed(None, &[1, 2]), [true, true]);
        assert_eq!(changed(Some(&[1, 2]), &[]), Vec::<bool>::new());
    }

    #[test]
    fn each_sort_orders_the_rows_as_named() {
        let mut store = Store::new();
        let mut st = Stats::new(500_000);
        // 0x181 every 10 ms (5 frames), 0x701 every 100 ms (2), 0x080 once, last.
        let mut push = |id: u32, ms: u64| {
            let mut f = Frame::classic(id, &[0]);
            f.ts_ns = ms * 1_000_000;
            let at = store.push(&f, Kind::Other, None);
            st.add(&store.frame(at), at, None);
        };
        for (id, ms) in [(0x701, 0), (0x181, 0), (0x181, 10), (0x181, 20), (0x181, 30)] {
            push(id, ms);
        }
        push(0x181, 40);
        push(0x701, 100);
        push(0x080, 120);
        let ids = |s: Sort| -> Vec<u32> { sorted(&st, s).iter().map(|((_, id), _)| *id).collect() };
        assert_eq!(ids(Sort::Id), [0x080, 0x181, 0x701]);
        assert_eq!(ids(Sort::Count), [0x181, 0x701, 0x080]);
        assert_eq!(ids(Sort::Period), [0x181, 0x701, 0x080]);
        assert_eq!(ids(Sort::Last), [0x080, 0x701, 0x181]);
        assert_eq!(Sort::Last.next(), Sort::Id);
    }

    #[test]
    fn narrow_panes_keep_age_period_and_rate_and_wide_ones_show_the_spread() {
        use Column::*;
        // An 80-column terminal: 78 inside the frame.
        assert_eq!(columns(78, 4), [Rate, Age, Period]);
        assert_eq!(columns(98, 4), [Count, Rate, Age, Period, Jitter]);
        assert_eq!(columns(160, 4), [Count, Rate, Age, Period, Jitter, Min, Max, Last]);
        // Extended COB-IDs take 5 more columns.
        assert_eq!(columns(78, 9), [Age, Period]);
        assert_eq!(columns(10, 4), []);
        assert_eq!(
            [age(0.04), age(2.54), age(125.0), age(7560.0)],
            ["40 ms", "2.5 s", "125 s", "2.1 h"]
        );
    }
}
