//! The Plot pane: a numeric PDO signal or SDO-read value over time.

use super::block;
use crate::tui::app::App;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::Line;
use ratatui::widgets::{Axis, Chart, Dataset, GraphType, Paragraph};

/// Draws the pane.
pub fn render(app: &App, f: &mut Frame, area: Rect, focused: bool) {
    let keys = app.trace.series.keys();
    let Some(key) = keys.get(app.series_sel.min(keys.len().saturating_sub(1))) else {
        f.render_widget(block(" Plot ", focused), area);
        let inner = block("", true).inner(area);
        f.render_widget(
            Paragraph::new("no numeric signal seen yet (PDO signals need a mapping; SDO reads count too)"),
            inner,
        );
        return;
    };
    let Some(line) = app.trace.series.get(key) else { return };
    let t0 = app.start_ns() as f64 / 1e9;
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
        app.series_sel.min(keys.len() - 1) + 1,
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
