//! The Plot pane: a numeric PDO signal or SDO-read value over time.

use super::{Component, Ctx, Outcome, block};
use crate::analysis::trace::Trace;
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::Line;
use ratatui::widgets::{Axis, Chart, Dataset, GraphType, Paragraph};

/// The Plot pane's state: which series it shows.
#[derive(Default)]
pub struct PlotPane {
    /// Index into the series keys.
    pub series: usize,
}

impl PlotPane {
    /// Shows the next (or previous) series, going round.
    pub fn step(&mut self, trace: &Trace, forward: bool) {
        let n = trace.series.keys().len().max(1);
        self.series = if forward {
            (self.series + 1) % n
        } else {
            (self.series + n - 1) % n
        };
    }

    /// Shows the series of `node` `index`:`sub`; false when no such series was seen.
    pub fn select(&mut self, trace: &Trace, node: u8, index: u16, sub: u8) -> bool {
        match trace.series.keys().iter().position(|k| *k == (node, index, sub)) {
            Some(at) => {
                self.series = at;
                true
            }
            None => false,
        }
    }
}

impl Component for PlotPane {
    /// The plot has no rows: `[`/`]` choose the series (handled by the application).
    fn handle(&mut self, _action: Action, _ctx: &Ctx) -> Outcome {
        Outcome::Ignored
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        render(self.series, ctx, f, area, focused);
    }
}

/// Draws series number `sel`.
fn render(sel: usize, ctx: &Ctx, f: &mut Frame, area: Rect, focused: bool) {
    let trace = ctx.trace;
    let keys = trace.series.keys();
    let Some(key) = keys.get(sel.min(keys.len().saturating_sub(1))) else {
        f.render_widget(block(" Plot ", focused), area);
        let inner = block("", true).inner(area);
        f.render_widget(
            Paragraph::new("no numeric signal seen yet (PDO signals need a mapping; SDO reads count too)"),
            inner,
        );
        return;
    };
    let Some(line) = trace.series.get(key) else { return };
    let t0 = super::start_ns(trace) as f64 / 1e9;
    let points: Vec<(f64, f64)> = line.points.iter().map(|(t, v)| (t - t0, *v)).collect();
    let (mut lo, mut hi) = points
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), (_, v)| (lo.min(*v), hi.max(*v)));
    if lo > hi {
        (lo, hi) = (0.0, 1.0);
    }
    if (hi - lo).abs() < f64::EPSILON {
        lo -= 1.0;
        hi += 1.0;
    }
    let (x0, x1) = (
        points.first().map(|p| p.0).unwrap_or(0.0),
        points
            .last()
            .map(|p| p.0)
            .unwrap_or(1.0)
            .max(points.first().map(|p| p.0 + 1e-3).unwrap_or(1.0)),
    );
    let object = format!("0x{:04X}:{:02X}", key.1, key.2);
    let name = if line.name == object {
        String::new()
    } else {
        format!(" {}", line.name)
    };
    let title = format!(
        " Plot {}/{}: node {} {object}{name} ({} points) ",
        sel.min(keys.len() - 1) + 1,
        keys.len(),
        key.0,
        points.len()
    );
    let data = [Dataset::default()
        .marker(Marker::Braille)
        .graph_type(GraphType::Line)
        .style(Style::default().fg(Color::Cyan))
        .data(&points)];
    let chart = Chart::new(data.to_vec())
        .block(block(&title, focused))
        .x_axis(
            Axis::default()
                .bounds([x0, x1])
                .labels([Line::raw(format!("{x0:.1}s")), Line::raw(format!("{x1:.1}s"))]),
        )
        .y_axis(
            Axis::default()
                .bounds([lo, hi])
                .labels([Line::raw(format!("{lo:.0}")), Line::raw(format!("{hi:.0}"))]),
        );
    f.render_widget(chart, area);
}
