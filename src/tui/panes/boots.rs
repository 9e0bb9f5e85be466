//! The boot stories, shown in the Problems pane (`boots` toggles them): each node's boots
//! (boot-up or an NMT reset, up to Operational) with their writes and NMT commands and what
//! differs from the reference boot, the same stories as `cotui diagnose --boots`. `expand`
//! opens a boot, and on one of its steps shows that frame in the trace.

use super::{Ctx, ListState, Selected, block, fit, header, selected};
use crate::analysis::boot_story::Boot;
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// The boots as of the last change of the diagnosis, the selection and the boot opened.
#[derive(Default)]
pub(super) struct BootsView {
    list: ListState,
    opened: Option<usize>,
    boots: Vec<Boot>,
    /// The nodes with an expected configuration (`--expect`, `:expect`).
    expected: Vec<u8>,
    /// The trace's diagnosis version the boots were built at.
    version: Option<u64>,
}

/// `0.000` seconds since `origin`.
fn secs(t_ns: u64, origin: u64) -> String {
    format!("{:.3}", t_ns.saturating_sub(origin) as f64 / 1e9)
}

/// `Node 5`, with the interface when the capture has several (`Node 5 (can1)`).
fn node_place(ctx: &Ctx, b: &Boot) -> String {
    if ctx.trace.ifaces.names().len() > 1 {
        format!("Node {} ({})", b.node.node, ctx.trace.ifaces.name(b.node.iface))
    } else {
        format!("Node {}", b.node.node)
    }
}

impl BootsView {
    /// Rebuilds the stories when the diagnosis changed since the last time.
    pub(super) fn refresh(&mut self, ctx: &Ctx) {
        if self.version == Some(ctx.trace.diagnosis_version) {
            return;
        }
        self.version = Some(ctx.trace.diagnosis_version);
        self.boots = ctx.trace.diagnosis.clone().finish_with_boots().1;
        self.expected = ctx.trace.diagnosis.expected_nodes();
        if self.opened.is_some_and(|o| o >= self.boots.len()) {
            self.opened = None;
        }
    }

    /// Rows to move over: the boots, or the opened boot's steps.
    pub(super) fn len(&self) -> usize {
        match self.opened {
            Some(o) => self.boots.get(o).map_or(0, |b| b.steps.len()),
            None => self.boots.len(),
        }
    }

    fn current(&self) -> Option<&Boot> {
        self.boots.get(self.opened.unwrap_or(self.list.selected))
    }

    /// `expand` opens a boot, or shows the selected step's frame; `back` closes it.
    pub(super) fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.list.scroll(delta, self.len(), ctx.page);
            return true;
        }
        match action {
            Action::Expand if self.opened.is_none() => {
                if self.list.selected < self.boots.len() {
                    self.opened = Some(self.list.selected);
                    self.list = ListState::default();
                }
                true
            }
            Action::Expand => match self.current().and_then(|b| b.steps.get(self.list.selected)) {
                Some(s) => q.answer(Event::Show(s.frame().saturating_sub(1) as usize)),
                None => true,
            },
            Action::Back => match self.opened.take() {
                Some(o) => {
                    self.list = ListState {
                        selected: o,
                        offset: o.saturating_sub(3),
                    };
                    true
                }
                None => false,
            },
            _ => false,
        }
    }

    pub(super) fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, self.len(), ctx.page);
    }

    pub(super) fn fit(&mut self, height: usize, ctx: &Ctx) {
        self.refresh(ctx);
        self.list.clamp(self.len(), height);
    }

    /// The selected step's frame, or the boot's first frame.
    pub(super) fn selected(&self) -> Option<Selected> {
        let b = self.current()?;
        let frame = match self.opened {
            Some(_) => b.steps.get(self.list.selected)?.frame(),
            None => b.frame,
        };
        Some(Selected::Frame(frame.saturating_sub(1) as usize))
    }

    pub(super) fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let origin = super::start_ns(ctx.trace);
        match self.opened.and_then(|o| self.boots.get(o)) {
            Some(b) => self.render_boot(b, origin, f, area, focused),
            None => self.render_list(origin, f, area, ctx, focused),
        }
    }

    fn render_list(&self, origin: u64, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let differ = self.boots.iter().filter(|b| !b.findings.is_empty()).count();
        let against = crate::tui::expect::nodes_text(&self.expected)
            .map_or(String::new(), |list| format!("; expected configuration of node {list}"));
        let title = format!(
            " Boot stories ({} boots, {differ} with findings{against}) ",
            self.boots.len()
        );
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let width = inner.width as usize;
        let mut lines = vec![Line::styled(
            fit(
                &format!(
                    "{:<16} {:>4} {:>9} {:>12} {:>5} {:>8}  reference",
                    "node", "boot", "at s", "operational", "steps", "findings"
                ),
                width,
            ),
            header(),
        )];
        let l = self.list;
        for (i, b) in self
            .boots
            .iter()
            .enumerate()
            .skip(l.offset)
            .take(inner.height as usize - 1)
        {
            let op = b.operational.map_or("no".to_string(), |o| secs(o.t_ns, origin));
            let expected = self.expected.contains(&b.node.node);
            let reference = match (b.reference, expected) {
                (Some(r), true) => format!("boot {r} + expected"),
                (Some(r), false) => format!("boot {r}"),
                (None, true) => "expected".to_string(),
                (None, false) => "-".to_string(),
            };
            let text = format!(
                "{:<16} {:>4} {:>9} {:>12} {:>5} {:>8}  {reference}",
                node_place(ctx, b),
                b.number,
                secs(b.t_ns, origin),
                op,
                b.steps.len(),
                b.findings.len()
            );
            let colour = if b.findings.is_empty() {
                Color::Reset
            } else {
                Color::Red
            };
            let line = Line::styled(fit(&text, width), Style::default().fg(colour));
            lines.push(if i == l.selected { line.style(selected()) } else { line });
        }
        if self.boots.is_empty() {
            lines.push(Line::raw(format!("no boot seen in {} frames", ctx.trace.len())));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }

    /// The opened boot as `cotui diagnose --boots` tells it, its steps selectable.
    fn render_boot(&self, b: &Boot, origin: u64, f: &mut Frame, area: Rect, focused: bool) {
        let mut text = String::new();
        b.write_text(origin, &mut text);
        let mut rows = text.lines();
        let title = format!(" {} ", rows.next().unwrap_or_default());
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        let width = inner.width as usize;
        // The steps come first, one line each, then what differs.
        let lines: Vec<Line> = rows
            .enumerate()
            .skip(self.list.offset)
            .take(inner.height as usize)
            .map(|(i, r)| {
                let line = if i < b.steps.len() || b.findings.is_empty() {
                    Line::raw(fit(r.trim_start(), width))
                } else {
                    Line::styled(fit(r.trim_start(), width), Style::default().fg(Color::Red))
                };
                if i == self.list.selected && i < b.steps.len() {
                    line.style(selected())
                } else {
                    line
                }
            })
            .collect();
        f.render_widget(Paragraph::new(lines), inner);
    }
}
