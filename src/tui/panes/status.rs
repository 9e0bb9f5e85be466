//! The status bar (source, frames, rate, drops, filter, stop-all key) and the prompt line.

use crate::tui::app::{App, SourceKind};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;

/// The most lines a question (a confirmation waiting for a key) takes at the bottom.
pub const QUESTION_LINES: usize = 6;

/// A question waiting for a key, wrapped to `width` columns: the key hint first (black on
/// yellow), then what it is about, word by word; at most `max` lines, the last cut with `…`.
pub fn question_lines(app: &App, width: u16, max: usize) -> Option<Vec<Line<'static>>> {
    let (hint, text) = app.question()?;
    Some(wrap_question(&hint, &text, width as usize, max.max(1)))
}

fn wrap_question(hint: &str, text: &str, width: usize, max: usize) -> Vec<Line<'static>> {
    let width = width.max(1);
    let key = Style::default()
        .fg(Color::Black)
        .bg(Color::Yellow)
        .add_modifier(Modifier::BOLD);
    let hint: String = hint.chars().take(width).collect();
    let mut rows: Vec<String> = Vec::new();
    let mut cur = String::new();
    let mut used = hint.chars().count();
    // Words longer than a line are split into pieces of a line.
    let words = text.split_whitespace().flat_map(|w| {
        let chars: Vec<char> = w.chars().collect();
        chars
            .chunks(width)
            .map(|c| c.iter().collect::<String>())
            .collect::<Vec<_>>()
    });
    for w in words {
        let n = w.chars().count();
        let gap = if used == 0 {
            0
        } else if rows.is_empty() && cur.is_empty() {
            2
        } else {
            1
        };
        if used > 0 && used + gap + n > width {
            rows.push(std::mem::take(&mut cur));
            used = 0;
        } else if gap > 0 {
            cur.push_str(&" ".repeat(gap));
            used += gap;
        }
        cur.push_str(&w);
        used += n;
    }
    rows.push(cur);
    let mut lines: Vec<Line<'static>> = rows
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            let text = Span::styled(r, Style::default().fg(Color::Yellow));
            if i == 0 {
                Line::from(vec![Span::styled(hint.clone(), key), text])
            } else {
                Line::from(text)
            }
        })
        .collect();
    if lines.len() > max {
        lines.truncate(max);
        if let Some(last) = lines.last_mut().and_then(|l| l.spans.last_mut()) {
            let mut t: String = last.content.to_string();
            let keep = t.chars().count().min(width.saturating_sub(1));
            t = t.chars().take(keep).collect();
            t.push('…');
            last.content = t.into();
        }
    }
    lines
}

/// A replay's position: ` 45% 12.3 s / 27.0 s` (percent of the frames, log time from the
/// first frame), only the time until the log is measured, nothing before the first frame.
fn replay_position(app: &App) -> String {
    match app.source().replay {
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

/// A live session of several interfaces: each bus's load over the last second and its
/// condition, one field each (` | can0 12.3% error-active | can1 0.0% bus-off`); nothing
/// for one interface or a log.
fn buses(app: &App) -> String {
    let live = matches!(app.source().kind, SourceKind::Live { .. } | SourceKind::Demo { .. });
    let names = app.trace().ifaces.names();
    if !live || names.len() < 2 {
        return String::new();
    }
    let mut out = String::new();
    for (i, name) in names.iter().enumerate() {
        let i = i as u16;
        let state = app.source().buses.get(&i).map_or("waiting", |b| b.0);
        let load = app.trace().stats.iface_load_percent(i);
        out.push_str(&format!(" | {name} {load:.1}% {state}"));
    }
    out
}

/// The status bar text.
pub fn text(app: &App) -> String {
    let src = match app.source().kind {
        SourceKind::Open => format!("open {}", app.source().name),
        SourceKind::Replay { speed } => {
            let x = if speed <= 0.0 {
                "max".to_string()
            } else {
                speed.to_string()
            };
            let looping = if app.source().looping { " loop" } else { "" };
            format!("replay {}{} ×{x}{looping}", app.source().name, replay_position(app))
        }
        SourceKind::Live { listen_only } => {
            format!(
                "live {}{}",
                app.source().name,
                if listen_only { " (listen-only)" } else { "" }
            )
        }
        SourceKind::Demo { listen_only } => {
            format!("demo bus{}", if listen_only { " (listen-only)" } else { "" })
        }
    };
    let state = if app.source().done || app.source().replay_at_end() {
        " (end)"
    } else if app.source().paused {
        " (paused)"
    } else {
        ""
    };
    let rec = app
        .capture()
        .recording()
        .map(|r| {
            let gate = r
                .gated()
                .map(|t| format!(", windows of trigger {t}"))
                .unwrap_or_default();
            format!(" | REC {} ({} frames{gate})", r.file, r.count())
        })
        .unwrap_or_default();
    let view = app.screen().view();
    let filter = if view.filter.is_empty() {
        String::new()
    } else {
        let p = view.progress(app.trace());
        let prog = if p < 100 { format!(" {p}%") } else { String::new() };
        format!(
            " | filter: {} ({} rows{prog})",
            view.filter.source,
            view.len(app.trace())
        )
    };
    let search = app
        .screen()
        .search()
        .map(|s| format!(" | {}", s.summary(app.trace())))
        .unwrap_or_default();
    let trigger = app
        .screen()
        .trigger()
        .map(|t| format!(" | {}", t.summary(app.trace())))
        .unwrap_or_default();
    // A loaded log has no bus to stop and no live rate: it was read as fast as it could be.
    let file = matches!(app.source().kind, SourceKind::Open);
    let stop = app
        .keymap()
        .key_for(Action::StopAll)
        .filter(|_| !file)
        .map(|k| format!(" | stop all: {k}"))
        .unwrap_or_default();
    let rate = if file {
        String::new()
    } else {
        format!(" | {:.0} fr/s", app.capture().rate())
    };
    let help = app
        .keymap()
        .key_for(Action::Help)
        .map(|k| format!(" | help: {k}"))
        .unwrap_or_default();
    format!(
        "{src}{state}{rec} | {} frames{rate} | drops {}{}{filter}{search}{trigger}{stop}{help}",
        app.trace().len(),
        app.source().drops,
        buses(app)
    )
}

/// `bar` (a status bar text) made to fit `width` columns without losing its key hints (the
/// ` | stop all: …` and ` | help: …` at its end): first the file name `path` is shortened
/// from the left with `…` (its end, the file's own name, stays), then whole fields before the
/// hints go from the end, then the rest is cut with `…`.
pub fn fit_bar(bar: &str, path: &str, width: usize) -> String {
    let len = |s: &str| s.chars().count();
    if len(bar) <= width {
        return bar.to_string();
    }
    let at = bar
        .rfind(" | stop all: ")
        .or_else(|| bar.rfind(" | help: "))
        .unwrap_or(bar.len());
    let (body, hints) = bar.split_at(at);
    let room = width.saturating_sub(len(hints));
    let mut body = body.to_string();
    let over = len(&body).saturating_sub(room);
    if over > 0
        && !path.is_empty()
        && let Some(i) = body.find(path)
    {
        // Keep at least the last 16 characters of the path (the file name).
        let keep = len(path).saturating_sub(over + 1).max(16.min(len(path)));
        if keep < len(path) {
            let tail: String = path.chars().skip(len(path) - keep).collect();
            body.replace_range(i..i + path.len(), &format!("…{tail}"));
        }
    }
    // Then whole ` | ` fields from the end (never the source), then a cut.
    while len(&body) > room {
        match body.rfind(" | ") {
            Some(i) if i > 0 => body.truncate(i),
            _ => break,
        }
    }
    if len(&body) > room {
        body = super::fit(&body, room);
    }
    let out = format!("{body}{hints}");
    if len(&out) > width {
        super::fit(&out, width)
    } else {
        out
    }
}

/// Draws the status bar and, below it, the prompt or the last message.
pub fn render(app: &App, f: &mut Frame, bar: Rect, line: Rect) {
    let (txt, bg) = match (&app.source().bus_error, app.screen().prompt().editing(), app.message()) {
        // While typing, the bar shows what the line will do (preview or error).
        (_, Some(_), Some(m)) => (m.to_string(), Color::Magenta),
        // The error (with its fix) first, so a narrow terminal still shows it.
        (Some(e), _, _) => (format!("{e} | {}", text(app)), Color::Red),
        _ => (text(app), Color::Blue),
    };
    let path = match app.source().kind {
        SourceKind::Open | SourceKind::Replay { .. } => app.source().name.as_str(),
        _ => "",
    };
    let txt = fit_bar(&txt, path, bar.width as usize);
    f.render_widget(Paragraph::new(txt).style(Style::default().bg(bg).fg(Color::White)), bar);
    if let Some(lines) = question_lines(app, line.width, line.height as usize) {
        f.render_widget(Paragraph::new(lines), line);
        return;
    }
    if app.screen().prompt().render(f, line) {
        return;
    }
    if let Some(m) = app.message() {
        f.render_widget(Paragraph::new(m).style(Style::default().fg(Color::Yellow)), line);
    }
}

#[cfg(test)]
mod tests {
    use super::{fit_bar, wrap_question};

    #[test]
    fn the_status_bar_shortens_the_path_from_the_left_and_keeps_the_key_hints() {
        let bar = "open /home/bench/captures/2026-11-30/line3/drive_commissioning.log (end) | 44 frames | 0 fr/s | drops 0 | stop all: ctrl-s | help: ?";
        let path = "/home/bench/captures/2026-11-30/line3/drive_commissioning.log";
        let s = fit_bar(bar, path, 80);
        assert_eq!(
            s,
            "open …ommissioning.log (end) | 44 frames | 0 fr/s | stop all: ctrl-s | help: ?"
        );
        assert!(s.ends_with(" | stop all: ctrl-s | help: ?"), "{s}");
        // Narrower: the path keeps its file name, fields go, the hints stay whole.
        let s = fit_bar(bar, path, 60);
        assert_eq!(s, "open …ommissioning.log (end) | stop all: ctrl-s | help: ?");
        assert!(s.chars().count() <= 60, "{s}");
        // What fits is left alone.
        assert_eq!(fit_bar("demo bus | help: ?", "", 80), "demo bus | help: ?");
    }

    fn text(lines: &[ratatui::text::Line]) -> Vec<String> {
        lines
            .iter()
            .map(|l| l.spans.iter().map(|s| s.content.as_ref()).collect())
            .collect()
    }

    #[test]
    fn a_question_wraps_by_words_after_its_key_hint_and_cuts_at_the_last_line_allowed() {
        let l = wrap_question("y send", "one two three four", 16, 6);
        assert_eq!(text(&l), ["y send  one two", "three four"]);
        // A word longer than a line is split; past `max` lines the last is marked cut.
        let l = wrap_question("y", "aaaaaaaaaaaa bb cc dd", 5, 3);
        assert_eq!(text(&l), ["y", "aaaaa", "aaaa…"]);
        assert_eq!(text(&wrap_question("y send", "", 3, 2)), ["y s"]);
    }
}
