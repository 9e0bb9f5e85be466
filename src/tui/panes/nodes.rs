//! The Nodes pane: one row per node with NMT state, heartbeat timing, boot-ups, the last
//! EMCY, CiA 402 state and mode, frame rate and profile.

use super::{block, duration, fit, header, selected};
use crate::decode::cia402::mode_name;
use crate::decode::heartbeat::NmtState;
use crate::tui::app::App;
use crate::tui::nodes::NodeInfo;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

fn nmt_color(s: Option<NmtState>) -> Color {
    match s {
        Some(NmtState::Operational) => Color::Green,
        Some(NmtState::PreOperational) => Color::Yellow,
        Some(NmtState::Stopped) => Color::Red,
        _ => Color::Gray,
    }
}

fn nmt_text(n: &NodeInfo) -> String {
    n.nmt.map(|s| s.text()).unwrap_or_else(|| "-".into())
}

/// The row text of one node; `now_ns` is the newest frame's time (for ages).
pub fn row_text(id: u8, n: &NodeInfo, now_ns: u64) -> String {
    let hb = match (n.period_ns, n.configured_ms) {
        (Some(p), Some(c)) => format!("{}/{} ms", p / 1_000_000, c),
        (Some(p), None) => format!("{}/? ms", p / 1_000_000),
        (None, Some(c)) => format!("-/{c} ms"),
        (None, None) => "-".into(),
    };
    let age = n
        .last_heartbeat_ns
        .map(|t| duration(now_ns.saturating_sub(t) as f64 / 1e9))
        .unwrap_or_else(|| "-".into());
    let emcy = n
        .last_emcy
        .as_ref()
        .map(|(_, c, t)| format!("{c:04X} {t}"))
        .unwrap_or_else(|| "-".into());
    format!(
        "{:>3} {:<15} {:>11} {:>9} {:>4} {:>4} {:<22} {:<14} {:<18} {:>7.1} {:<10} {}",
        id,
        nmt_text(n),
        hb,
        age,
        n.missed,
        n.boot_ups,
        n.drive.map(|d| d.text()).unwrap_or("-"),
        fit(n.mode.map(mode_name).unwrap_or("-"), 14),
        fit(&emcy, 18),
        n.rate(),
        fit(if n.profile.is_empty() { "-" } else { &n.profile }, 10),
        "",
    )
}

/// Draws the full pane.
pub fn render(app: &App, f: &mut Frame, area: Rect, focused: bool) {
    f.render_widget(block(" Nodes ", focused), area);
    let inner = block("", true).inner(area);
    if inner.height == 0 {
        return;
    }
    let now = app
        .trace
        .store
        .len()
        .checked_sub(1)
        .map(|i| app.trace.store.packed(i).ts_ns)
        .unwrap_or(0);
    let mut lines = vec![Line::styled(
        format!(
            "{:>3} {:<15} {:>11} {:>9} {:>4} {:>4} {:<22} {:<14} {:<18} {:>7} {:<10}",
            "id",
            "nmt",
            "hb meas/cfg",
            "hb age",
            "miss",
            "boot",
            "cia402 state",
            "mode",
            "last emcy",
            "fr/s",
            "profile"
        ),
        header(),
    )];
    let l = app.nodes_list;
    for (i, (id, n)) in app
        .trace
        .nodes
        .iter()
        .enumerate()
        .skip(l.offset)
        .take(inner.height as usize - 1)
    {
        let line = Line::styled(row_text(*id, n, now), Style::default().fg(nmt_color(n.nmt)));
        lines.push(if i == l.selected && focused {
            line.style(selected())
        } else {
            line
        });
    }
    if app.trace.nodes.is_empty() {
        lines.push(Line::raw("no node seen yet"));
    }
    f.render_widget(Paragraph::new(lines), inner);
}

/// Draws the compact list beside the main pane: id, NMT state, drive state.
pub fn render_compact(app: &App, f: &mut Frame, area: Rect) {
    f.render_widget(block(" Nodes ", false), area);
    let inner = block("", true).inner(area);
    let lines: Vec<Line> = app
        .trace
        .nodes
        .iter()
        .take(inner.height as usize)
        .map(|(id, n)| {
            let emcy = if n.last_emcy.is_some() { " EMCY" } else { "" };
            Line::styled(
                fit(
                    &format!(
                        "{:>3} {:<15} {}{}",
                        id,
                        nmt_text(n),
                        n.drive.map(|d| d.text()).unwrap_or(""),
                        emcy
                    ),
                    inner.width as usize,
                ),
                Style::default().fg(nmt_color(n.nmt)),
            )
        })
        .collect();
    f.render_widget(Paragraph::new(lines), inner);
}
