//! The Nodes pane: one row per node with NMT state (or LOST and for how long), heartbeat
//! timing, missed deadlines, boot-ups, the last EMCY, CiA 402 state and mode, frame rate
//! and profile.

use super::{Component, Ctx, ListState, Outcome, block, duration, fit, header, selected};
use crate::analysis::NodeLiveness;
use crate::analysis::nodes::NodeInfo;
use crate::analysis::trace::Trace;
use crate::decode::cia402::mode_name;
use crate::decode::heartbeat::NmtState;
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// The style of a node's row: white on red while lost, else coloured by NMT state.
pub fn row_style(live: Option<&NodeLiveness>) -> Style {
    match live {
        Some(l) if l.is_lost() => Style::default()
            .fg(Color::White)
            .bg(Color::Red)
            .add_modifier(Modifier::BOLD),
        _ => Style::default().fg(match live.and_then(|l| l.state) {
            Some(NmtState::Operational) => Color::Green,
            Some(NmtState::PreOperational) => Color::Yellow,
            Some(NmtState::Stopped) => Color::Red,
            _ => Color::Gray,
        }),
    }
}

/// The state cell: `LOST 4.2 s` (time since the last heartbeat) while lost, else the
/// NMT state.
fn state_text(live: Option<&NodeLiveness>, now_ns: u64) -> String {
    match live {
        Some(l) if l.is_lost() => {
            let since = l.last_heartbeat_ns.or(l.lost_at_ns).unwrap_or(now_ns);
            format!("LOST {:.1} s", now_ns.saturating_sub(since) as f64 / 1e9)
        }
        _ => live
            .and_then(|l| l.state)
            .map(|s| s.text())
            .unwrap_or_else(|| "-".into()),
    }
}

/// The row text of one node; `now_ns` is the capture time (for ages).
pub fn row_text(id: u8, n: &NodeInfo, live: Option<&NodeLiveness>, now_ns: u64) -> String {
    let measured = live.and_then(NodeLiveness::measured_ns);
    let configured = live.and_then(|l| l.configured_ms.or(l.default_ms));
    let hb = match (measured, configured) {
        (Some(p), Some(c)) => format!("{}/{} ms", p / 1_000_000, c),
        (Some(p), None) => format!("{}/? ms", p / 1_000_000),
        (None, Some(c)) => format!("-/{c} ms"),
        (None, None) => "-".into(),
    };
    let age = live
        .and_then(|l| l.last_heartbeat_ns)
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
        state_text(live, now_ns),
        hb,
        age,
        live.map_or(0, |l| l.missed),
        live.map_or(0, |l| l.boot_ups),
        n.drive.map(|d| d.text()).unwrap_or("-"),
        fit(n.mode.map(mode_name).unwrap_or("-"), 14),
        fit(&emcy, 18),
        n.rate(),
        fit(if n.profile.is_empty() { "-" } else { &n.profile }, 10),
        "",
    )
}

/// The Nodes pane's state: the selection.
#[derive(Default)]
pub struct NodesPane {
    /// Scroll state.
    pub list: ListState,
}

impl Component for NodesPane {
    /// Moves the selection; `expand` shows the selected node's frames in the trace.
    fn handle(&mut self, action: Action, ctx: &Ctx) -> Outcome {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return Outcome::Done;
        }
        match action {
            Action::Expand => match ctx.trace.nodes.iter().nth(self.list.selected) {
                Some((n, _)) => Outcome::Filter(format!("node {n}")),
                None => Outcome::Done,
            },
            _ => Outcome::Ignored,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, ctx.trace.nodes.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, ctx.trace.nodes.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, ctx: &Ctx) {
        self.list.clamp(ctx.trace.nodes.len(), height);
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        f.render_widget(block(&title(ctx.trace), focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let trace = ctx.trace;
        let now = trace.nodes.now_ns();
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
        let l = self.list;
        for (i, (id, n)) in trace
            .nodes
            .iter()
            .enumerate()
            .skip(l.offset)
            .take(inner.height as usize - 1)
        {
            let live = trace.nodes.liveness(*id);
            let line = Line::styled(row_text(*id, n, live, now), row_style(live));
            lines.push(if i == l.selected && focused {
                line.style(selected())
            } else {
                line
            });
        }
        if trace.nodes.is_empty() {
            lines.push(Line::raw("no node seen yet"));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}

/// The pane title, with the frames of node-IDs without CANopen evidence ("other").
fn title(trace: &Trace) -> String {
    match trace.nodes.other_frames() {
        0 => " Nodes ".to_string(),
        n => format!(" Nodes · {n} other frames "),
    }
}

/// Draws the compact list beside the main pane: id, NMT state, drive state.
pub fn render_compact(trace: &Trace, f: &mut Frame, area: Rect) {
    f.render_widget(block(&title(trace), false), area);
    let inner = block("", true).inner(area);
    let now = trace.nodes.now_ns();
    let lines: Vec<Line> = trace
        .nodes
        .iter()
        .take(inner.height as usize)
        .map(|(id, n)| {
            let emcy = if n.last_emcy.is_some() { " EMCY" } else { "" };
            let live = trace.nodes.liveness(*id);
            Line::styled(
                fit(
                    &format!(
                        "{:>3} {:<15} {}{}",
                        id,
                        state_text(live, now),
                        n.drive.map(|d| d.text()).unwrap_or(""),
                        emcy
                    ),
                    inner.width as usize,
                ),
                row_style(live),
            )
        })
        .collect();
    f.render_widget(Paragraph::new(lines), inner);
}
