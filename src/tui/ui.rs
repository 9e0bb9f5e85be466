//! Screen layout: the main pane (tabs) on the left, compact nodes and detail on the right,
//! status bar and prompt line at the bottom.

use super::app::{App, Pane};
use super::panes;
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
    let [tabs, body, bar, line] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(0),
        Constraint::Length(1),
        Constraint::Length(1),
    ])
    .areas(area);
    let (main, side) = if area.width >= SIDE_MIN_WIDTH {
        let [m, s] = Layout::horizontal([Constraint::Min(0), Constraint::Length(area.width * 2 / 7)]).areas(body);
        (m, Some(s))
    } else {
        (body, None)
    };
    let spans: Vec<Span> = Pane::ALL
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let s = format!(" {} {} ", i + 1, p.title());
            if *p == app.pane {
                Span::styled(s, Style::default().bg(Color::White).fg(Color::Black))
            } else {
                Span::raw(s)
            }
        })
        .collect();
    f.render_widget(Paragraph::new(Line::from(spans)), tabs);

    // Where the selectable rows are, for paging and mouse clicks.
    let inner = panes::block("", true).inner(main);
    app.layout.table = match app.pane {
        Pane::Trace => panes::trace::split(app, main).0,
        Pane::Plot => Rect::default(),
        _ => Rect {
            y: inner.y.saturating_add(1),
            height: inner.height.saturating_sub(1),
            ..inner
        },
    };
    let (rows, strip) = panes::trace::split(app, main);
    app.prepare(rows.height as usize, &panes::trace::tail_positions(app, strip));
    let n_nodes = app.trace.nodes.len();
    let n_stats = app.trace.stats.len();
    let n_sdo = match app.sdo_expanded.and_then(|t| app.trace.transactions.get(t)) {
        Some(t) => t.frames.len(),
        None => app.trace.transactions.len(),
    };
    let h = app.layout.table.height as usize;
    app.nodes_list.clamp(n_nodes, h);
    app.stats_list.clamp(n_stats, h);
    app.sdo_list.clamp(n_sdo, h);

    app.layout.messages = panes::messages::height(body);
    let app = &*app;
    match app.pane {
        Pane::Trace => panes::trace::render(app, f, main, true),
        Pane::Nodes => panes::nodes::render(app, f, main, true),
        Pane::Sdo => panes::sdo::render(app, f, main, true),
        Pane::Stats => panes::stats::render(app, f, main, true),
        Pane::Plot => panes::plot::render(app, f, main, true),
    }
    if let Some(side) = side {
        let n = app.trace.nodes.len().clamp(1, 12) as u16 + 2;
        let [nodes, detail] = Layout::vertical([Constraint::Length(n), Constraint::Min(0)]).areas(side);
        panes::nodes::render_compact(app, f, nodes);
        panes::detail::render(app, f, detail);
    }
    panes::status::render(app, f, bar, line);
    if app.messages_shown {
        panes::messages::render(app, f, body);
    }
    if app.help {
        panes::help::render(app, f, body);
    }
}
