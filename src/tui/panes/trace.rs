//! The Trace pane: one row per frame of the view, coloured by kind, with a tail strip of
//! the newest frames while scrolled back.

use super::{block, fit, header, kind_color, selected};
use crate::tui::app::App;
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;

/// Rows of the tail strip.
pub const TAIL: usize = 3;

/// Splits the pane into the table rows and the tail strip (empty when following).
pub fn split(app: &App, area: Rect) -> (Rect, Rect) {
    let inner = block("", true).inner(area);
    let body = Rect {
        y: inner.y.saturating_add(1),
        height: inner.height.saturating_sub(1),
        ..inner
    };
    let tail = if !app.follow && app.view_len() > body.height as usize && body.height as usize > TAIL * 3 {
        TAIL as u16 + 1
    } else {
        0
    };
    let [rows, strip] = Layout::vertical([Constraint::Min(0), Constraint::Length(tail)]).areas(body);
    (rows, strip)
}

/// Trace positions shown in the tail strip.
pub fn tail_positions(app: &App, strip: Rect) -> Vec<usize> {
    if strip.height == 0 {
        return Vec::new();
    }
    let n = app.view_len();
    (n.saturating_sub(TAIL)..n).map(|r| app.view.position(r)).collect()
}

fn cells(app: &App, pos: usize, width: u16) -> Vec<Span<'static>> {
    let Some(r) = app.row(pos) else {
        return vec![Span::raw(format!("{:>12}", pos + 1))];
    };
    let color = kind_color(r.kind);
    let used = 12 + 1 + 9 + 1 + 9 + 1 + 3 + 1 + 23 + 1;
    let label_w = (width as usize).saturating_sub(used);
    let mut label = fit(&r.label, label_w);
    if r.malformed.is_some() && label_w > 2 {
        label = format!("! {}", fit(&r.label, label_w - 2));
    }
    vec![
        Span::raw(format!("{:>12.6} ", r.time)),
        Span::styled(format!("{:<9} ", r.cob), Style::default().fg(color)),
        Span::styled(format!("{:<9} ", r.kind.as_str()), Style::default().fg(color)),
        Span::raw(format!("{:>3} ", r.node)),
        Span::raw(format!("{:<23} ", r.data)),
        Span::styled(
            label,
            Style::default().fg(if r.malformed.is_some() { Color::LightRed } else { color }),
        ),
    ]
}

/// Draws the pane; `App::prepare` must have made the rows.
pub fn render(app: &App, f: &mut Frame, area: Rect, focused: bool) {
    let title = format!(
        " Trace {}{} ",
        if app.follow { "[follow]" } else { "[scrolled]" },
        if app.source.paused { " [paused]" } else { "" }
    );
    f.render_widget(block(&title, focused), area);
    let inner = block("", true).inner(area);
    if inner.height == 0 {
        return;
    }
    let head = Rect { height: 1, ..inner };
    f.render_widget(
        Paragraph::new(Line::styled(
            format!(
                "{:>12} {:<9} {:<9} {:>3} {:<23} label",
                "time", "cob-id", "kind", "nd", "data"
            ),
            header(),
        )),
        head,
    );
    let (rows, strip) = split(app, area);
    let l = app.trace_list;
    let lines: Vec<Line> = (l.offset..(l.offset + rows.height as usize).min(app.view_len()))
        .map(|r| {
            let line = Line::from(cells(app, app.view.position(r), rows.width));
            if r == l.selected { line.style(selected()) } else { line }
        })
        .collect();
    f.render_widget(Paragraph::new(lines), rows);
    if strip.height > 0 {
        let mut lines = vec![Line::styled(
            fit(&format!("── newest {:─<200}", " "), strip.width as usize),
            Style::default().fg(Color::DarkGray),
        )];
        lines.extend(
            tail_positions(app, strip)
                .into_iter()
                .map(|p| Line::from(cells(app, p, strip.width))),
        );
        f.render_widget(Paragraph::new(lines), strip);
    }
}
