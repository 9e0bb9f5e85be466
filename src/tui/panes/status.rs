//! The status bar (source, frames, rate, drops, filter, stop-all key) and the prompt line.

use crate::tui::app::{App, SourceKind};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::widgets::Paragraph;

/// A replay's position: ` 45% 12.3 s / 27.0 s` (percent of the frames, log time from the
/// first frame), only the time until the log is measured, nothing before the first frame.
fn replay_position(app: &App) -> String {
    match app.source.replay {
        (Some(p), Some(e)) if e.frames > 0 => format!(
            " {}% {:.1} s / {:.1} s",
            p.frames * 100 / e.frames,
            p.ts_ns.saturating_sub(e.first_ns) as f64 / 1e9,
            e.last_ns.saturating_sub(e.first_ns) as f64 / 1e9
        ),
        (Some(p), _) if p.frames > 0 => {
            format!(" {:.1} s", p.ts_ns.saturating_sub(app.start_ns()) as f64 / 1e9)
        }
        _ => String::new(),
    }
}

/// The status bar text.
pub fn text(app: &App) -> String {
    let src = match app.source.kind {
        SourceKind::Open => format!("open {}", app.source.name),
        SourceKind::Replay { speed } => {
            let x = if speed <= 0.0 {
                "max".to_string()
            } else {
                speed.to_string()
            };
            let looping = if app.source.looping { " loop" } else { "" };
            format!("replay {}{} ×{x}{looping}", app.source.name, replay_position(app))
        }
        SourceKind::Live { listen_only } => {
            format!(
                "live {}{}",
                app.source.name,
                if listen_only { " (listen-only)" } else { "" }
            )
        }
        SourceKind::Demo { listen_only } => {
            format!("demo bus{}", if listen_only { " (listen-only)" } else { "" })
        }
    };
    let state = if app.source.done || app.source.replay_at_end() {
        " (end)"
    } else if app.source.paused {
        " (paused)"
    } else {
        ""
    };
    let rec = app
        .recording
        .as_ref()
        .map(|r| format!(" | REC {} ({} frames)", r.file, r.count()))
        .unwrap_or_default();
    let view = &app.panes.trace.view;
    let filter = if view.filter.is_empty() {
        String::new()
    } else {
        let p = view.progress(&app.trace);
        let prog = if p < 100 { format!(" {p}%") } else { String::new() };
        format!(
            " | filter: {} ({} rows{prog})",
            view.filter.source,
            app.panes.trace.len(&app.trace)
        )
    };
    let search = app
        .search
        .as_ref()
        .map(|s| format!(" | {}", s.summary(&app.trace)))
        .unwrap_or_default();
    let stop = app
        .keymap
        .key_for(Action::StopAll)
        .map(|k| format!(" | stop all: {k}"))
        .unwrap_or_default();
    let help = app
        .keymap
        .key_for(Action::Help)
        .map(|k| format!(" | help: {k}"))
        .unwrap_or_default();
    format!(
        "{src}{state}{rec} | {} frames | {:.0} fr/s | drops {}{filter}{search}{stop}{help}",
        app.trace.len(),
        app.rate,
        app.source.drops
    )
}

/// Draws the status bar and, below it, the prompt or the last message.
pub fn render(app: &App, f: &mut Frame, bar: Rect, line: Rect) {
    let (txt, bg) = match (&app.source.bus_error, &app.prompt.editing, &app.message) {
        // While typing, the bar shows what the line will do (preview or error).
        (_, Some(_), Some(m)) => (m.clone(), Color::Magenta),
        // The error (with its fix) first, so a narrow terminal still shows it.
        (Some(e), _, _) => (format!("{e} | {}", text(app)), Color::Red),
        _ => (text(app), Color::Blue),
    };
    f.render_widget(Paragraph::new(txt).style(Style::default().bg(bg).fg(Color::White)), bar);
    if app.prompt.render(f, line) {
        return;
    }
    if let Some(m) = &app.message {
        f.render_widget(
            Paragraph::new(m.as_str()).style(Style::default().fg(Color::Yellow)),
            line,
        );
    }
}
