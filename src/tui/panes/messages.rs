//! The message log popup: every result, event and error with its time, newest at the
//! bottom, scrollable.

use super::block;
use crate::tui::app::App;
use crate::tui::messages::Level;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::{Clear, Paragraph};

/// The first line shown when the log is scrolled `back` lines up from its end in a window of
/// `height` lines holding `len` lines.
pub fn first_line(len: usize, height: usize, back: usize) -> usize {
    len.saturating_sub(height).saturating_sub(back)
}

/// Where the popup goes over `area` (most of it: the log wants width).
fn popup(area: Rect) -> Rect {
    Rect {
        x: area.x + area.width / 20,
        y: area.y + area.height / 10,
        width: area.width - area.width / 10,
        height: area.height - area.height / 5,
    }
}

/// Log lines the popup shows at once over `area`.
pub fn height(area: Rect) -> usize {
    popup(area).height.saturating_sub(2) as usize
}

/// Draws the popup over `area`.
pub fn render(app: &App, f: &mut Frame, area: Rect) {
    let r = popup(area);
    f.render_widget(Clear, r);
    let lines = app.messages.lines();
    let height = height(area);
    let first = first_line(lines.len(), height, app.messages_back);
    let body: Vec<Line> = if lines.is_empty() {
        vec![Line::raw(
            "no messages yet: command results, node and bus events appear here",
        )]
    } else {
        lines
            .into_iter()
            .skip(first)
            .take(height)
            .map(|(level, text)| {
                let color = match level {
                    Level::Info => Color::Reset,
                    Level::Warn => Color::Yellow,
                    Level::Error => Color::LightRed,
                };
                Line::styled(text, Style::default().fg(color))
            })
            .collect()
    };
    let title = format!(
        " Messages ({}{}) — ↑↓ scroll, esc closes ",
        app.messages.len(),
        if app.messages.dropped > 0 {
            format!(", {} oldest dropped", app.messages.dropped)
        } else {
            String::new()
        }
    );
    f.render_widget(Paragraph::new(body).block(block(&title, true)), r);
}
