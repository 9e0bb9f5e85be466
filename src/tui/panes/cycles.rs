//! The SYNC cycles view of the Stats pane (`sync_cycles` toggles it): one row per SYNC
//! period (time since the first frame, period, SYNC counter, late TPDOs), then one lane per
//! synchronous TPDO COB-ID of the visible cycles with its time after the SYNC, the late
//! ones red with `!`. `slowest_cycle` selects the cycle of the longest period,
//! `next_late_cycle` the next one with a late TPDO (each selects the cycle's SYNC frame in
//! the Trace pane too); `expand` shows that frame in the trace. Cycles come from [`crate::analysis::sync_cycles`].

use super::{Ctx, ListState, Selected, block, fit, header, selected};
use crate::analysis::sync_cycles::Cycle;
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;

/// Columns of a lane.
const LANE: usize = 8;

/// The SYNC cycles view's state: the selection, and whether a late jump was made (the
/// first one goes to the first late cycle, the selected one included).
#[derive(Default)]
pub(crate) struct CyclesView {
    list: ListState,
    jumped: bool,
}

/// Milliseconds as `10.000`.
fn ms(ns: u64) -> String {
    format!("{:.3}", ns as f64 / 1e6)
}

impl CyclesView {
    fn len(ctx: &Ctx) -> usize {
        ctx.trace.cycles.len()
    }

    /// Selects cycle `i`, shown about a third down the page, and its SYNC frame in the
    /// Trace pane.
    fn select(&mut self, i: usize, ctx: &Ctx, q: &mut Queue) {
        self.list.selected = i;
        self.list.offset = i.saturating_sub(ctx.page / 3);
        self.list.clamp(Self::len(ctx), ctx.page);
        if let Some(c) = ctx.trace.cycles.get(i) {
            q.push(Event::Select(c.sync_pos as usize));
        }
    }

    /// Moves the selection; the jumps; `expand` shows the SYNC frame in the trace.
    pub(crate) fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return true;
        }
        let cycles = &ctx.trace.cycles;
        match action {
            Action::SlowestCycle => match cycles.slowest() {
                Some(i) => self.select(i, ctx, q),
                None => q.push(Event::Note("no SYNC cycle with a period yet".into())),
            },
            Action::NextLateCycle => {
                let after = self.jumped.then_some(self.list.selected);
                match cycles.next_late(after) {
                    Some(i) => {
                        self.jumped = true;
                        self.select(i, ctx, q);
                    }
                    None => q.push(Event::Note("no SYNC cycle with a late TPDO".into())),
                }
            }
            Action::Expand => {
                if let Some(c) = cycles.get(self.list.selected) {
                    q.push(Event::Show(c.sync_pos as usize));
                }
            }
            _ => return false,
        }
        true
    }

    /// Moves the selection by `delta` rows.
    pub(crate) fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, Self::len(ctx), ctx.page);
    }

    /// Selects the `row`-th visible row.
    pub(crate) fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, Self::len(ctx), ctx.page);
    }

    /// Keeps the selection within the cycles and visible.
    pub(crate) fn fit(&mut self, height: usize, ctx: &Ctx) {
        self.list.clamp(Self::len(ctx), height);
    }

    /// The selected cycle's SYNC frame.
    pub(crate) fn selected(&self, ctx: &Ctx) -> Option<Selected> {
        let c = ctx.trace.cycles.get(self.list.selected)?;
        Some(Selected::Frame(c.sync_pos as usize))
    }

    pub(crate) fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let cycles = &ctx.trace.cycles;
        let t = ctx.trace.cycles.totals();
        let mut title = format!(" SYNC cycles: {}", t.cycles);
        if let Some((max, _, _)) = t.slowest {
            let mean = t.period_sum_ns / t.periods.max(1);
            title.push_str(&format!(", period mean {} ms, slowest {} ms", ms(mean), ms(max)));
        }
        title.push_str(&format!(
            ", {} late TPDOs in {} cycles (w: slowest, x: next late, enter: its SYNC) ",
            t.late_frames, t.late_cycles
        ));
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let width = inner.width as usize;
        let several = ctx.trace.ifaces.names().len() > 1;
        let l = self.list;
        let shown = l.offset..cycles.len().min(l.offset + inner.height as usize - 1);
        let rows: Vec<(usize, Cycle)> = shown.filter_map(|i| Some((i, cycles.get(i)?))).collect();
        // The lanes: the COB-IDs of the visible cycles' TPDOs.
        let mut lanes: Vec<u32> = rows
            .iter()
            .flat_map(|(_, c)| c.frames.iter().map(|s| s.cob_id))
            .collect();
        lanes.sort_unstable();
        lanes.dedup();
        let mut head = String::new();
        if several {
            head.push_str(&format!("{:<7}", "iface"));
        }
        head.push_str(&format!(
            "{:>10} {:>10} {:>4} {:>4} ",
            "start s", "period ms", "ctr", "late"
        ));
        for cob in &lanes {
            head.push_str(&format!("{:>LANE$}", format!("{cob:03X}")));
        }
        let mut lines = vec![Line::styled(fit(&head, width), header())];
        let origin = super::start_ns(ctx.trace);
        let late = Style::default().fg(Color::Red).add_modifier(Modifier::BOLD);
        for (i, c) in rows {
            let mut left = String::new();
            if several {
                left.push_str(&format!("{:<7}", fit(ctx.trace.ifaces.name(c.iface), 6)));
            }
            left.push_str(&format!(
                "{:>10} {:>10} {:>4} {:>4} ",
                format!("{:.3}", c.start_ns.saturating_sub(origin) as f64 / 1e9),
                c.period_ns.map_or_else(|| "-".into(), ms),
                c.counter.map_or_else(|| "-".into(), |n| n.to_string()),
                c.late()
            ));
            let mut spans = vec![Span::raw(left)];
            for cob in &lanes {
                spans.push(match c.frames.iter().find(|s| s.cob_id == *cob) {
                    Some(s) if s.late => Span::styled(format!("{:>LANE$}", format!("+{}!", s.offset_us)), late),
                    Some(s) => Span::raw(format!("{:>LANE$}", format!("+{}", s.offset_us))),
                    None => Span::raw(format!("{:>LANE$}", "-")),
                });
            }
            let line = Line::from(spans);
            lines.push(if i == l.selected {
                line.patch_style(selected())
            } else {
                line
            });
        }
        if cycles.is_empty() {
            lines.push(Line::raw(format!("no SYNC in {} frames", ctx.trace.len())));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}
