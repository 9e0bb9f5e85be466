//! The Problems pane: the diagnosis of `cotui diagnose`, kept up to date as frames arrive.
//! One row per incident, open first; `expand` opens an incident (cause, timeline, what to
//! check first, why it matters) and, on a timeline step, shows that frame in the trace;
//! `show_frames` shows the selected incident's frames in the trace one after the other.

use super::boots::BootsView;
use super::{Component, Ctx, ListState, Selected, block, fit, header, selected};
use crate::analysis::{Incident, Problem, Status};
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Wrap};

/// Which incident the frame jumps go through, and the step shown last.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Jump {
    node: Option<u8>,
    problem: Problem,
    first_ns: u64,
    step: usize,
}

/// The Problems pane's state: the incidents as of the last change, the selection, and the
/// incident opened.
#[derive(Default)]
pub struct ProblemsPane {
    /// Scroll state (incidents, or the timeline steps of the opened one).
    list: ListState,
    /// The opened incident (index into the ranked list).
    opened: Option<usize>,
    incidents: Vec<Incident>,
    /// The trace's diagnosis version the incidents were built at.
    version: Option<u64>,
    jump: Option<Jump>,
    /// The boot stories, shown in place of the incidents while `showing_boots`.
    boots: BootsView,
    showing_boots: bool,
}

/// Seconds since the first frame, as `12.345`.
fn secs(t_ns: u64, origin: u64) -> String {
    format!("{:.3}", t_ns.saturating_sub(origin) as f64 / 1e9)
}

fn color(s: Status) -> Color {
    match s {
        Status::Open => Color::Red,
        Status::Recovered => Color::Green,
        Status::Warning => Color::Yellow,
        Status::Info => Color::Cyan,
    }
}

/// The title, and the cause when the title does not already say it.
fn headline(inc: &Incident) -> String {
    match &inc.cause {
        Some(c) if !inc.title.contains(c.as_str()) => format!("{} — {c}", inc.title),
        _ => inc.title.clone(),
    }
}

/// The status as the list shows it.
fn status_text(s: Status) -> &'static str {
    match s {
        Status::Open => "OPEN",
        Status::Recovered => "RECOVERED",
        Status::Warning => "WARNING",
        Status::Info => "INFO",
    }
}

impl ProblemsPane {
    /// The incidents as last built.
    pub fn incidents(&self) -> &[Incident] {
        &self.incidents
    }

    /// Rebuilds the incidents when the diagnosis changed since the last time.
    pub fn refresh(&mut self, ctx: &Ctx) {
        if self.version == Some(ctx.trace.diagnosis_version) {
            return;
        }
        self.version = Some(ctx.trace.diagnosis_version);
        // Keep the same incident selected while the ranking changes.
        let key = |i: &Incident| (i.node, i.problem, i.first_ns);
        let was = self.incidents.get(self.list.selected).map(key);
        let was_open = self.opened.and_then(|o| self.incidents.get(o)).map(key);
        self.incidents = ctx.trace.diagnosis.incidents();
        let find =
            |k: Option<(Option<u8>, Problem, u64)>| k.and_then(|k| self.incidents.iter().position(|i| key(i) == k));
        if let Some(o) = self.opened {
            self.opened = find(was_open).or(Some(o).filter(|o| *o < self.incidents.len()));
        } else if let Some(i) = find(was) {
            self.list.selected = i;
        }
    }

    fn len(&self) -> usize {
        match self.opened {
            Some(o) => self.incidents.get(o).map_or(0, |i| i.events.len()),
            None => self.incidents.len(),
        }
    }

    /// The incident under the selection (the opened one when one is open).
    fn current(&self) -> Option<&Incident> {
        self.incidents.get(self.opened.unwrap_or(self.list.selected))
    }

    /// The trace position of the next frame of the selected incident: its first frame, then
    /// the next one at each call (round again after the last).
    fn next_frame(&mut self) -> Option<usize> {
        let inc = self.current()?;
        let steps = inc.events.len();
        if steps == 0 {
            return None;
        }
        let same = |j: &Jump| (j.node, j.problem, j.first_ns) == (inc.node, inc.problem, inc.first_ns);
        let step = match self.jump {
            Some(j) if same(&j) => (j.step + 1) % steps,
            _ => 0,
        };
        let frame = inc.events[step].frame;
        self.jump = Some(Jump {
            node: inc.node,
            problem: inc.problem,
            first_ns: inc.first_ns,
            step,
        });
        Some(frame.saturating_sub(1) as usize)
    }
}

impl Component for ProblemsPane {
    /// Moves the selection; `expand` opens an incident, and on a timeline step shows its
    /// frame in the trace; `show_frames` goes through the incident's frames; `back` closes.
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if action == Action::Boots {
            self.showing_boots = !self.showing_boots;
            self.boots.refresh(ctx);
            return true;
        }
        if self.showing_boots && action != Action::ShowFrames {
            return self.boots.handle(action, ctx, q);
        }
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return true;
        }
        match action {
            Action::Expand if self.opened.is_none() => {
                if self.list.selected < self.incidents.len() {
                    self.opened = Some(self.list.selected);
                    self.list = ListState::default();
                }
                true
            }
            Action::Expand => {
                let step = self.current().and_then(|i| i.events.get(self.list.selected));
                match step {
                    Some(s) => q.answer(Event::Show(s.frame.saturating_sub(1) as usize)),
                    None => true,
                }
            }
            Action::ShowFrames => match self.next_frame() {
                Some(pos) => q.answer(Event::Show(pos)),
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

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, self.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        if self.showing_boots {
            return self.boots.click(row, ctx);
        }
        self.list.click(row, self.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, ctx: &Ctx) {
        self.refresh(ctx);
        self.list.clamp(self.len(), height);
        if self.showing_boots {
            self.boots.fit(height, ctx);
        }
    }

    /// The frame of the selected timeline step, or the incident's first frame (the boot's
    /// step or first frame while the boot stories show).
    fn selected(&self, _ctx: &Ctx) -> Option<Selected> {
        if self.showing_boots {
            return self.boots.selected();
        }
        let inc = self.current()?;
        let step = match self.opened {
            Some(_) => inc.events.get(self.list.selected),
            None => inc.events.first(),
        }?;
        Some(Selected::Frame(step.frame.saturating_sub(1) as usize))
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        if self.showing_boots {
            return self.boots.render(f, area, ctx, focused);
        }
        match self.opened.and_then(|o| self.incidents.get(o)) {
            Some(inc) => self.render_incident(inc, f, area, ctx, focused),
            None => self.render_list(f, area, ctx, focused),
        }
    }
}

impl ProblemsPane {
    /// Draws the ranked list (only the visible rows).
    fn render_list(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let count = |s: Status| self.incidents.iter().filter(|i| i.status == s).count();
        let mut title = format!(
            " Problems ({} open, {} recovered, {} warnings",
            count(Status::Open),
            count(Status::Recovered),
            count(Status::Warning)
        );
        match count(Status::Info) {
            0 => {}
            1 => title.push_str(", 1 note"),
            n => title.push_str(&format!(", {n} notes")),
        }
        title.push_str(") ");
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let width = inner.width as usize;
        let mut lines = vec![Line::styled(
            fit(
                &format!(
                    "{:<9} {:<12} {:>5} {:>8} {:>8}  problem",
                    "status", "where", "count", "first s", "last s"
                ),
                width,
            ),
            header(),
        )];
        let origin = super::start_ns(ctx.trace);
        let l = self.list;
        for (i, inc) in self
            .incidents
            .iter()
            .enumerate()
            .skip(l.offset)
            .take(inner.height as usize - 1)
        {
            let text = format!(
                "{:<9} {:<12} {:>5} {:>8} {:>8}  {}",
                status_text(inc.status),
                fit(&inc.place(), 12),
                inc.count,
                secs(inc.first_ns, origin),
                secs(inc.last_ns, origin),
                headline(inc)
            );
            let line = Line::styled(fit(&text, width), Style::default().fg(color(inc.status)));
            lines.push(if i == l.selected { line.style(selected()) } else { line });
        }
        if self.incidents.is_empty() {
            lines.push(Line::raw(format!("no problem found in {} frames", ctx.trace.len())));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }

    /// Draws the opened incident: cause, timeline (selectable), check first, why.
    fn render_incident(&self, inc: &Incident, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let title = format!(" {} {}: {} ", status_text(inc.status), inc.place(), inc.title);
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        let width = inner.width as usize;
        let origin = super::start_ns(ctx.trace);
        let mut lines = Vec::new();
        if let Some(c) = &inc.cause {
            lines.push(Line::raw(format!("Cause: {c}")));
        }
        let times = match inc.count {
            1 => "once".to_string(),
            n => format!("{n} times"),
        };
        lines.push(Line::raw(format!(
            "{times}, first {} s, last {} s",
            secs(inc.first_ns, origin),
            secs(inc.last_ns, origin)
        )));
        lines.push(Line::styled("What happened (enter: show the frame)", header()));
        for (i, e) in inc.events.iter().enumerate() {
            let text = format!("{:>10} s  #{:<7} {}", secs(e.t_ns, origin), e.frame, e.text);
            let line = Line::raw(fit(&text, width));
            lines.push(if i == self.list.selected {
                line.style(selected())
            } else {
                line
            });
        }
        lines.push(Line::styled("Check first", header()));
        for (i, c) in inc.check.iter().enumerate() {
            lines.push(Line::raw(format!("{}. {c}", i + 1)));
        }
        lines.push(Line::styled("Why it matters", header()));
        lines.push(Line::raw(inc.why.clone()));
        f.render_widget(Paragraph::new(lines).wrap(Wrap { trim: false }), inner);
    }
}
