//! Screen layout: the main pane (tabs) on the left, compact nodes and detail on the right
//! (or the Detail pane toggled in below the main pane on a narrow terminal), status bar and
//! prompt line at the bottom.

use super::app::App;
use super::panes::{self, Pane};
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;

/// Width from which the side column is shown.
const SIDE_MIN_WIDTH: u16 = 110;

/// Draws the whole screen.
pub fn draw(f: &mut Frame, app: &mut App) {
    let area = f.area();
    // A question waiting for a key wraps onto the lines it needs (within reason).
    let max = panes::status::QUESTION_LINES.min(area.height as usize / 4).max(1);
    let asked = panes::status::question_lines(app, area.width, max).map_or(1, |l| l.len().clamp(1, max));
    let [tabs, body, bar, line] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(0),
        Constraint::Length(1),
        Constraint::Length(asked as u16),
    ])
    .areas(area);
    let (main, side) = if area.width >= SIDE_MIN_WIDTH {
        let [m, s] = Layout::horizontal([Constraint::Min(0), Constraint::Length(area.width * 2 / 7)]).areas(body);
        (m, Some(s))
    } else {
        (body, None)
    };
    app.screen_mut().layout_mut().side = side.is_some();
    // Too narrow for the side column: the Detail pane, when toggled, goes below the main pane.
    let (main, below) = if side.is_none() && app.screen().detail().shown() {
        let [m, d] = Layout::vertical([Constraint::Percentage(40), Constraint::Percentage(60)]).areas(main);
        (m, Some(d))
    } else {
        (main, None)
    };
    // Each tab padded by a space both sides; on a narrow screen (80 columns) one space apart,
    // and narrower still the long titles shortened. Keys 1 to 9, then 0.
    let width = |short: bool| -> usize { Pane::ALL.iter().map(|p| p.title_fit(short).chars().count() + 3).sum() };
    let pad = if width(false) + Pane::ALL.len() > usize::from(tabs.width) {
        ""
    } else {
        " "
    };
    let short = width(false) > usize::from(tabs.width);
    let spans: Vec<Span> = Pane::ALL
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let s = format!(" {} {}{pad}", (i + 1) % 10, p.title_fit(short));
            if *p == app.focus() {
                Span::styled(s, Style::default().bg(Color::White).fg(Color::Black))
            } else {
                Span::raw(s)
            }
        })
        .collect();
    f.render_widget(Paragraph::new(Line::from(spans)), tabs);

    // Where the selectable rows are, for paging and mouse clicks.
    let inner = panes::block("", true).inner(main);
    let trace_pane = app.screen().panes().trace();
    let (rows, strip) = trace_pane.split(app.trace(), main);
    let tail = trace_pane.tail_positions(app.trace(), strip);
    let table = match app.focus() {
        Pane::Trace => rows,
        Pane::Plot => Rect::default(),
        _ => Rect {
            y: inner.y.saturating_add(1),
            height: inner.height.saturating_sub(1),
            ..inner
        },
    };
    app.screen_mut().layout_mut().table = table;
    app.prepare(table.height as usize, rows.height as usize, &tail);
    app.screen_mut()
        .log_popup_mut()
        .set_size(panes::messages::height(body), panes::messages::width(body));

    let app = &*app;
    let (screen, trace) = (app.screen(), app.trace());
    let ctx = app.ctx();
    screen.panes().get(app.focus()).render(f, main, &ctx, true);
    let selected = app.selected();
    if let Some(side) = side {
        let n = trace.nodes.len().clamp(1, 12) as u16 + 2;
        let [nodes, detail] = Layout::vertical([Constraint::Length(n), Constraint::Min(0)]).areas(side);
        panes::nodes::render_compact(trace, f, nodes);
        screen.detail().render(trace, selected, f, detail);
    }
    if let Some(below) = below {
        screen.detail().render(trace, selected, f, below);
    }
    panes::status::render(app, f, bar, line);
    if screen.log_popup().shown() {
        screen.log_popup().render(screen.messages(), f, body);
    }
    if screen.help().shown() {
        screen.help().render(app.keymap(), f, body);
    }
}
