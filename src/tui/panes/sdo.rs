//! The SDO pane: one row per transfer (object, value, duration, outcome, abort text);
//! `expand` opens a transfer's frames.

use super::{block, duration, fit, header, selected};
use crate::sdo::{Outcome, Transaction};
use crate::tui::app::App;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// One transfer as a table row.
pub fn row_text(app: &App, t: &Transaction, width: usize) -> String {
    let dict = app.trace.decoder().dictionary(t.node);
    let name = dict.name(t.index, t.sub).unwrap_or("");
    let value = if t.outcome == Outcome::Ok && !t.data.is_empty() && !t.is_partial() {
        crate::decode::sdo::value::view(dict, t.index, t.sub, &t.data).text
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
    let text = format!(
        "{:>3} {} {} {:<24} {:<20} {:>9} {}",
        t.node,
        dir,
        object,
        fit(name, 24),
        fit(&value, 20),
        duration(t.duration_ns() as f64 / 1e9),
        outcome
    );
    fit(&text, width)
}

fn color(t: &Transaction) -> Color {
    match t.outcome {
        Outcome::Ok if t.problems.is_empty() => Color::Cyan,
        Outcome::Ok => Color::Yellow,
        Outcome::Incomplete => Color::Gray,
        _ => Color::Red,
    }
}

/// Draws the pane.
pub fn render(app: &App, f: &mut Frame, area: Rect, focused: bool) {
    let l = app.sdo_list;
    if let Some(t) = app.sdo_expanded.and_then(|i| app.trace.transactions.get(i)) {
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
        let t0 = app.start_ns();
        let decoded = app.trace.decode_positions(&positions);
        let lines: Vec<Line> = positions
            .iter()
            .zip(decoded)
            .enumerate()
            .map(|(i, (p, d))| {
                let fr = app.trace.store.frame(*p);
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
        return;
    }
    let title = format!(" SDO transfers ({}) ", app.trace.transactions.len());
    f.render_widget(block(&title, focused), area);
    let inner = block("", true).inner(area);
    if inner.height == 0 {
        return;
    }
    let mut lines = vec![Line::styled(
        fit(
            &format!(
                "{:>3} {} {:<7} {:<24} {:<20} {:>9} outcome",
                "nd", "dir  ", "object", "name", "value", "duration"
            ),
            inner.width as usize,
        ),
        header(),
    )];
    for (i, t) in app
        .trace
        .transactions
        .iter()
        .enumerate()
        .skip(l.offset)
        .take(inner.height as usize - 1)
    {
        let line = Line::styled(row_text(app, t, inner.width as usize), Style::default().fg(color(t)));
        lines.push(if i == l.selected { line.style(selected()) } else { line });
    }
    if app.trace.transactions.is_empty() {
        lines.push(Line::raw("no SDO transfer seen yet"));
    }
    f.render_widget(Paragraph::new(lines), inner);
}
