//! The SDO pane: one row per transfer (start time, object, value, duration, outcome,
//! abort text), the newest selected until the user moves the selection (as the trace
//! follows); `expand` opens a transfer as a sequence diagram (`sdo_seq.rs`).

use super::sdo_seq::Sequence;
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
/// transfer opened as a sequence diagram.
pub struct SdoPane {
    /// Scroll state (transfers, or the rows of the opened transfer's diagram).
    list: ListState,
    /// Select the newest transfer as transfers come (until the selection is moved; `end`
    /// follows again).
    follow: bool,
    /// The transfer opened as a sequence diagram.
    opened: Option<Sequence>,
}

impl Default for SdoPane {
    fn default() -> SdoPane {
        SdoPane {
            list: ListState::default(),
            follow: true,
            opened: None,
        }
    }
}

impl SdoPane {
    /// The opened transfer and its diagram, if any.
    fn opened(&self, trace: &Trace) -> Option<(&Sequence, Transaction)> {
        let s = self.opened.as_ref()?;
        Some((s, trace.transactions.get(s.transfer)?))
    }

    /// Rows of the list: transfers, or the rows of the opened transfer's diagram.
    fn len(&self, trace: &Trace) -> usize {
        match self.opened {
            Some(_) => self.opened(trace).map(|(s, t)| s.len(&t)).unwrap_or(0),
            None => trace.transactions.len(),
        }
    }

    /// The trace position of the frame of the selected arrow of the opened transfer.
    fn selected_frame(&self, trace: &Trace) -> Option<usize> {
        let (s, _) = self.opened(trace)?;
        s.position(self.list.selected)
    }
}

impl Component for SdoPane {
    /// Moves the selection; `expand` opens the selected transfer as a sequence diagram,
    /// and on an arrow shows its frame in the trace (and so in Detail); `back` closes the
    /// diagram.
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            if action == Action::Bottom && self.opened.is_none() {
                self.follow = true;
            }
            return true;
        }
        match action {
            Action::Expand if self.opened.is_none() => {
                if let Some(s) = Sequence::open(ctx.trace, self.list.selected) {
                    self.follow = false;
                    self.opened = Some(s);
                    self.list = ListState::default();
                }
                true
            }
            Action::Expand => match self.selected_frame(ctx.trace) {
                Some(pos) => q.answer(Event::Show(pos)),
                None => true,
            },
            Action::Back => match self.opened.take() {
                Some(s) => {
                    let t = s.transfer;
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
        if self.follow && self.opened.is_none() {
            self.list.selected = n.saturating_sub(1);
        }
        self.list.clamp(n, height);
    }

    /// The selected transfer, or the frame of the selected arrow of the opened one.
    fn selected(&self, ctx: &Ctx) -> Option<Selected> {
        match self.opened {
            Some(_) => self.selected_frame(ctx.trace).map(Selected::Frame),
            None => Some(Selected::Transfer(self.list.selected)),
        }
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        match self.opened(ctx.trace) {
            Some((s, t)) => {
                f.render_widget(block(&Sequence::title(&t), focused), area);
                let inner = block("", true).inner(area);
                let l = self.list;
                let lines = s.lines(
                    ctx.trace,
                    &t,
                    inner.width as usize,
                    inner.height as usize,
                    l.offset,
                    l.selected,
                );
                f.render_widget(Paragraph::new(lines), inner);
            }
            None => self.render_transfers(f, area, ctx, focused),
        }
    }
}

impl SdoPane {
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
        let rows = l.offset..trace.transactions.len().min(l.offset + inner.height as usize - 1);
        for (i, t) in rows.clone().zip(trace.transactions.iter_from(rows.start)) {
            let line = Line::styled(
                row_text(trace, &t, inner.width as usize),
                Style::default().fg(color(&t)),
            );
            lines.push(if i == l.selected { line.style(selected()) } else { line });
        }
        if trace.transactions.is_empty() {
            lines.push(Line::raw("no SDO transfer seen yet"));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}
