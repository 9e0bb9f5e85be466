//! The SDO pane: one row per transfer (start time, object, value, duration, outcome,
//! abort text), the newest selected until the user moves the selection (as the trace
//! follows); `expand` opens a transfer's frames.

use super::{Component, Ctx, ListState, Selected, block, duration, fit, header, selected};
use crate::analysis::trace::Trace;
use crate::sdo::{Outcome, Transaction};
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// Width of the time column: seconds since the first frame of the trace, as the trace
/// pane counts them, to the millisecond.
const TIME: usize = 10;

/// Widths of the name and value columns in a pane `width` wide: the value takes what the
/// fixed columns and 20 columns of outcome leave (at least 20), the name 24 (16 when narrow,
/// none below 100 columns: the outcome, ok or the abort, matters more at a bench).
pub fn widths(width: usize) -> (usize, usize) {
    let avail = width.saturating_sub(30 + TIME + 1);
    let name = if avail >= 80 {
        24
    } else if width >= 100 {
        16
    } else {
        0
    };
    (name, avail.saturating_sub(name + 20).max(20))
}

/// Width of the interface column: shown only when the capture has several interfaces,
/// so that node 5 of can0 and node 5 of can1 tell apart (0 otherwise).
fn iface_width(trace: &Trace) -> usize {
    let names = trace.ifaces.names();
    if names.len() > 1 {
        names.iter().map(|n| n.chars().count()).max().unwrap_or(0).min(12) + 1
    } else {
        0
    }
}

/// One transfer as a table row.
pub fn row_text(trace: &Trace, t: &Transaction, width: usize) -> String {
    let iw = iface_width(trace);
    if iw > 0 {
        let iface = fit(trace.ifaces.name(t.iface), iw - 1);
        let rest = row_columns(trace, t, width.saturating_sub(iw));
        return fit(&format!("{iface:<w$} {rest}", w = iw - 1), width);
    }
    row_columns(trace, t, width)
}

/// The columns of a row after the interface.
fn row_columns(trace: &Trace, t: &Transaction, width: usize) -> String {
    let dict = trace.decoder().dictionary(t.node);
    let name = dict.name(t.index, t.sub).unwrap_or("");
    let value = if t.outcome == Outcome::Ok && !t.data.is_empty() && !t.is_partial() {
        crate::decode::sdo::value::view(dict, t.index, t.sub, &t.data).text
    } else if let Some(size) = t.cut_short_of() {
        // Ended before the announced size came: how much did.
        format!("{} of {size} bytes", t.len())
    } else {
        String::new()
    };
    let outcome = match &t.outcome {
        Outcome::Aborted { code, text, .. } => format!("abort {code:08X} {text}"),
        Outcome::ProtocolError(e) => format!("error: {e}"),
        o => o.as_str().to_string(),
    };
    let dir = if t.direction == crate::sdo::TransferDirection::Upload {
        "read "
    } else {
        "write"
    };
    // A transfer the capture caught mid-way: its object was never seen.
    let (object, name) = if t.is_partial() {
        ("????:??".to_string(), "(partial: started before the capture)")
    } else {
        (format!("{:04X}:{:02X}", t.index, t.sub), name)
    };
    let (nw, vw) = widths(width);
    let time = t.start_ns.saturating_sub(super::start_ns(trace)) as f64 / 1e9;
    let text = format!(
        "{time:>TIME$.3} {:>3} {} {} {}{:<vw$} {:>9} {}",
        t.node,
        dir,
        object,
        name_cell(name, nw),
        fit(&value, vw),
        duration(t.duration_ns() as f64 / 1e9),
        outcome
    );
    fit(&text, width)
}

/// The name cell and its gap, or nothing when the column is not shown (`nw` 0).
fn name_cell(name: &str, nw: usize) -> String {
    if nw == 0 {
        String::new()
    } else {
        format!("{:<nw$} ", fit(name, nw))
    }
}

#[cfg(test)]
#[test]
fn the_value_column_widens_with_the_pane() {
    assert_eq!(widths(78), (0, 20));
    assert_eq!(widths(100), (16, 23));
    assert_eq!(widths(124), (24, 39));
    assert_eq!(widths(211), (24, 126));
}

fn color(t: &Transaction) -> Color {
    match t.outcome {
        Outcome::Ok if t.problems.is_empty() => Color::Cyan,
        Outcome::Ok => Color::Yellow,
        Outcome::Incomplete => Color::Gray,
        _ => Color::Red,
    }
}

/// The SDO pane's state: the selection, whether it follows the newest transfer, and the
/// transfer opened to its frames.
pub struct SdoPane {
    /// Scroll state (transfers, or the frames of the opened transfer).
    list: ListState,
    /// Select the newest transfer as transfers come (until the selection is moved; `end`
    /// follows again).
    follow: bool,
    /// The transfer opened to its frames (index into the transactions).
    expanded: Option<usize>,
}

impl Default for SdoPane {
    fn default() -> SdoPane {
        SdoPane {
            list: ListState::default(),
            follow: true,
            expanded: None,
        }
    }
}

impl SdoPane {
    /// The opened transfer, if any.
    fn opened<'t>(&self, trace: &'t Trace) -> Option<&'t Transaction> {
        self.expanded.and_then(|i| trace.transactions.get(i))
    }

    /// Rows of the list: transfers, or the frames of the opened transfer.
    fn len(&self, trace: &Trace) -> usize {
        match self.expanded {
            Some(_) => self.opened(trace).map(|t| t.frames.len()).unwrap_or(0),
            None => trace.transactions.len(),
        }
    }

    /// The trace position of the selected frame of the opened transfer.
    fn selected_frame(&self, trace: &Trace) -> Option<usize> {
        let seq = self.opened(trace)?.frames.get(self.list.selected)?;
        Some(seq.saturating_sub(1) as usize)
    }
}

impl Component for SdoPane {
    /// Moves the selection; `expand` opens the selected transfer to its frames, and on a
    /// frame shows it in the trace; `back` closes the transfer.
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            if action == Action::Bottom && self.expanded.is_none() {
                self.follow = true;
            }
            return true;
        }
        match action {
            Action::Expand if self.expanded.is_none() => {
                if !ctx.trace.transactions.is_empty() {
                    self.follow = false;
                    self.expanded = Some(self.list.selected);
                    self.list = ListState::default();
                }
                true
            }
            Action::Expand => match self.selected_frame(ctx.trace) {
                Some(pos) => q.answer(Event::Show(pos)),
                None => true,
            },
            Action::Back => match self.expanded.take() {
                Some(t) => {
                    self.list = ListState {
                        selected: t,
                        offset: t.saturating_sub(3),
                    };
                    true
                }
                None => false,
            },
            _ => false,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.follow = false;
        self.list.scroll(delta, self.len(ctx.trace), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.follow = false;
        self.list.click(row, self.len(ctx.trace), ctx.page);
    }

    /// Keeps the selection visible; when following, on the newest transfer.
    fn fit(&mut self, height: usize, ctx: &Ctx) {
        let n = self.len(ctx.trace);
        if self.follow && self.expanded.is_none() {
            self.list.selected = n.saturating_sub(1);
        }
        self.list.clamp(n, height);
    }

    /// The selected transfer, or the selected frame of the opened one.
    fn selected(&self, ctx: &Ctx) -> Option<Selected> {
        match self.expanded {
            Some(_) => self.selected_frame(ctx.trace).map(Selected::Frame),
            None => Some(Selected::Transfer(self.list.selected)),
        }
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        match self.opened(ctx.trace) {
            Some(t) => self.render_frames(t, f, area, ctx, focused),
            None => self.render_transfers(f, area, ctx, focused),
        }
    }
}

impl SdoPane {
    /// Draws the frames of the opened transfer `t`.
    fn render_frames(&self, t: &Transaction, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let l = self.list;
        let title = format!(" SDO transfer {:04X}:{:02X} node {} — frames ", t.index, t.sub, t.node);
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        let positions: Vec<usize> = t
            .frames
            .iter()
            .skip(l.offset)
            .take(inner.height as usize)
            .map(|s| s.saturating_sub(1) as usize)
            .collect();
        let t0 = super::start_ns(ctx.trace);
        let decoded = ctx.trace.decode_positions(&positions);
        let lines: Vec<Line> = positions
            .iter()
            .zip(decoded)
            .enumerate()
            .map(|(i, (p, d))| {
                let fr = ctx.trace.store.frame(*p);
                let text = format!(
                    "{:>12.6} {:03X} {:<23} {}",
                    fr.ts_ns.saturating_sub(t0) as f64 / 1e9,
                    fr.id,
                    crate::frame::hex::spaced(fr.payload()),
                    d.label
                );
                let line = Line::raw(fit(&text, inner.width as usize));
                if i + l.offset == l.selected {
                    line.style(selected())
                } else {
                    line
                }
            })
            .collect();
        f.render_widget(Paragraph::new(lines), inner);
    }

    /// Draws the list of transfers.
    fn render_transfers(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let l = self.list;
        let trace = ctx.trace;
        let title = format!(" SDO transfers ({}) ", trace.transactions.len());
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let iw = iface_width(trace);
        let (nw, vw) = widths((inner.width as usize).saturating_sub(iw));
        let iface = if iw > 0 {
            format!("{:<w$} ", "iface", w = iw - 1)
        } else {
            String::new()
        };
        let mut lines = vec![Line::styled(
            fit(
                &format!(
                    "{iface}{:>TIME$} {:>3} {} {:<7} {}{:<vw$} {:>9} outcome",
                    "time",
                    "nd",
                    "dir  ",
                    "object",
                    name_cell("name", nw),
                    "value",
                    "duration"
                ),
                inner.width as usize,
            ),
            header(),
        )];
        for (i, t) in trace
            .transactions
            .iter()
            .enumerate()
            .skip(l.offset)
            .take(inner.height as usize - 1)
        {
            let line = Line::styled(row_text(trace, t, inner.width as usize), Style::default().fg(color(t)));
            lines.push(if i == l.selected { line.style(selected()) } else { line });
        }
        if trace.transactions.is_empty() {
            lines.push(Line::raw("no SDO transfer seen yet"));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}
