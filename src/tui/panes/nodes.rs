//! The Nodes pane: one row per node with NMT state (or LOST and for how long), heartbeat
//! timing, missed deadlines, boot-ups, the last EMCY, CiA 402 state and mode, frame rate
//! and profile.

use super::{Component, Ctx, ListState, block, duration, fit, header, selected};
use crate::analysis::NodeLiveness;
use crate::analysis::nodes::NodeInfo;
use crate::analysis::trace::Trace;
use crate::decode::cia402::mode_name;
use crate::decode::heartbeat::NmtState;
use crate::frame::NodeKey;
use crate::tui::event::{Event, Queue};
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

/// The columns: header, width, right-aligned, and the order they give way in on a narrow
/// pane (0: never; then 1 first). What a bench reads first stays: the id, the NMT state and
/// the heartbeat (period, age, misses); the frame rate and the profile go first. The last
/// EMCY and the profile are cut to fit instead (to [`FLEX_MIN`]) once the others are placed.
const COLUMNS: [(&str, usize, bool, u8); 11] = [
    ("id", 3, true, 0),
    ("nmt", 15, false, 0),
    ("hb meas/cfg", 11, true, 0),
    ("hb age", 9, true, 0),
    ("miss", 4, true, 0),
    ("boot", 4, true, 3),
    ("cia402 state", 22, false, 5),
    ("mode", 14, false, 4),
    ("last emcy", 18, false, 6),
    ("fr/s", 7, true, 1),
    ("profile", 10, false, 2),
];

/// The narrowest the last EMCY and profile columns get.
const FLEX_MIN: usize = 8;

/// The columns shown in `width` characters and their widths (cut columns get less).
pub fn layout(width: usize) -> Vec<(usize, usize)> {
    let flex = |i: usize| COLUMNS[i].0 == "last emcy" || COLUMNS[i].0 == "profile";
    let mut shown: Vec<usize> = (0..COLUMNS.len()).collect();
    let need = |shown: &[usize]| -> usize {
        shown
            .iter()
            .map(|&i| if flex(i) { FLEX_MIN } else { COLUMNS[i].1 } + 1)
            .sum::<usize>()
            - 1
    };
    let mut order: Vec<usize> = (0..COLUMNS.len()).filter(|&i| COLUMNS[i].3 > 0).collect();
    order.sort_by_key(|&i| COLUMNS[i].3);
    for drop in order {
        if need(&shown) <= width {
            break;
        }
        shown.retain(|&i| i != drop);
    }
    let mut spare = width.saturating_sub(need(&shown));
    shown
        .into_iter()
        .map(|i| {
            let w = if flex(i) {
                let extra = spare.min(COLUMNS[i].1 - FLEX_MIN);
                spare -= extra;
                FLEX_MIN + extra
            } else {
                COLUMNS[i].1
            };
            (i, w)
        })
        .collect()
}

/// The cells of `cells` (one per column) laid out as `layout` says.
fn join(cells: &[String], layout: &[(usize, usize)]) -> String {
    layout
        .iter()
        .map(|&(i, w)| {
            let c = fit(&cells[i], w);
            if COLUMNS[i].2 {
                format!("{c:>w$}")
            } else {
                format!("{c:<w$}")
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
        .trim_end()
        .to_string()
}

/// The row text of one node in `width` characters; `now_ns` is the capture time (for ages).
pub fn row_text(id: u8, n: &NodeInfo, live: Option<&NodeLiveness>, now_ns: u64, width: usize) -> String {
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
    let cells = [
        id.to_string(),
        state_text(live, now_ns),
        hb,
        age,
        live.map_or(0, |l| l.missed).to_string(),
        live.map_or(0, |l| l.boot_ups).to_string(),
        n.drive.map(|d| d.text()).unwrap_or("-").to_string(),
        n.mode.map(mode_name).unwrap_or("-").to_string(),
        emcy,
        format!("{:.1}", n.rate()),
        if n.profile.is_empty() {
            "-".into()
        } else {
            n.profile.clone()
        },
    ];
    join(&cells, &layout(width))
}

/// The Nodes pane's state: the selection.
#[derive(Default)]
pub struct NodesPane {
    /// Scroll state.
    list: ListState,
}

impl NodesPane {
    /// The node (on its interface) of the selected row, if there is one.
    pub fn selected_node(&self, trace: &Trace) -> Option<NodeKey> {
        trace.nodes.iter().nth(self.list.selected).map(|(n, _)| *n)
    }
}

impl Component for NodesPane {
    /// Moves the selection; `expand` shows the selected node's frames in the trace (of its
    /// own interface when there are several).
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return true;
        }
        match action {
            Action::Expand => match ctx.trace.nodes.iter().nth(self.list.selected) {
                // Several interfaces: that node on its own bus only.
                Some((n, _)) if ctx.trace.ifaces.names().len() > 1 => q.answer(Event::Filter(format!(
                    "iface {} and node {}",
                    ctx.trace.ifaces.name(n.iface),
                    n.node
                ))),
                Some((n, _)) => q.answer(Event::Filter(format!("node {}", n.node))),
                None => true,
            },
            _ => false,
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
        // Several interfaces: each row starts with its node's interface (rows come grouped
        // per interface, in node-ID order within each).
        let bus = BusColumn::of(trace);
        let width = (inner.width as usize).saturating_sub(bus.width());
        let heads: Vec<String> = COLUMNS.iter().map(|c| c.0.to_string()).collect();
        let mut lines = vec![Line::styled(
            format!("{}{}", bus.cell("iface"), join(&heads, &layout(width))),
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
            let text = format!(
                "{}{}",
                bus.cell(trace.ifaces.name(id.iface)),
                row_text(id.node, n, live, now, width)
            );
            let line = Line::styled(text, row_style(live));
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

/// The interface column shown before the others when the trace has several interfaces.
struct BusColumn(usize);

impl BusColumn {
    /// As wide as the longest interface name (5 to 12), or absent while every node is on
    /// one interface.
    fn of(trace: &Trace) -> BusColumn {
        let mut ifaces = trace.nodes.iter().map(|(k, _)| k.iface);
        let first = ifaces.next();
        if !ifaces.any(|i| Some(i) != first) {
            return BusColumn(0);
        }
        let names = trace.ifaces.names();
        BusColumn(names.iter().map(|n| n.chars().count()).max().unwrap_or(0).clamp(5, 12))
    }
    /// Characters taken, with the space after it.
    fn width(&self) -> usize {
        if self.0 == 0 { 0 } else { self.0 + 1 }
    }
    /// `text` fitted to the column, with the space after it ("" without the column).
    fn cell(&self, text: &str) -> String {
        if self.0 == 0 {
            return String::new();
        }
        let w = self.0;
        format!("{:<w$} ", fit(text, w))
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
    let bus = BusColumn::of(trace);
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
                        "{}{:>3} {:<15} {}{}",
                        bus.cell(trace.ifaces.name(id.iface)),
                        id.node,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_give_way_rate_and_profile_first_and_the_heartbeat_stays() {
        let names = |w: usize| -> Vec<&str> { layout(w).iter().map(|(i, _)| COLUMNS[*i].0).collect() };
        let full = names(200);
        assert_eq!(full.len(), COLUMNS.len());
        let all: usize = COLUMNS.iter().map(|c| c.1 + 1).sum::<usize>() - 1;
        assert_eq!(layout(all).iter().map(|(_, w)| w + 1).sum::<usize>() - 1, all);
        // A 160-column terminal leaves the Nodes pane 113 columns: the rate goes first.
        let at_160 = names(113);
        assert!(!at_160.contains(&"fr/s"), "{at_160:?}");
        assert!(at_160.contains(&"boot") && at_160.contains(&"profile") && at_160.contains(&"miss"));
        assert!(layout(113).iter().map(|(_, w)| w + 1).sum::<usize>() - 1 <= 113);
        // 80 columns: id, state and the whole heartbeat stay; rate and profile are gone.
        let at_80 = names(78);
        for keep in ["id", "nmt", "hb meas/cfg", "hb age", "miss"] {
            assert!(at_80.contains(&keep), "{keep}: {at_80:?}");
        }
        assert!(!at_80.contains(&"fr/s") && !at_80.contains(&"profile"), "{at_80:?}");
        assert!(layout(78).iter().map(|(_, w)| w + 1).sum::<usize>() - 1 <= 78);
        // Even at 50 the heartbeat columns are the last to go.
        assert_eq!(names(50), ["id", "nmt", "hb meas/cfg", "hb age", "miss"]);
    }
}
