//! The message log popup: every result, event and error with its time, newest at the
//! bottom, scrollable.

use super::block;
use crate::tui::keymap::Action;
use crate::tui::messages::{Level, Messages};
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

/// The message log popup's state.
#[derive(Default)]
pub struct MessagesPopup {
    /// The popup is shown.
    pub shown: bool,
    /// Lines the log is scrolled up from its end.
    pub back: usize,
    /// Lines the popup showed at once in the last draw.
    pub page: usize,
}

impl MessagesPopup {
    /// Shows the popup at the newest lines.
    pub fn open(&mut self) {
        self.shown = true;
        self.back = 0;
    }

    /// Shows or hides the popup (at the newest lines).
    pub fn toggle(&mut self) {
        self.shown = !self.shown;
        self.back = 0;
    }

    /// Scrolls or closes the popup over a log of `len` lines; false when `action` is not for it.
    pub fn handle(&mut self, action: Action, len: usize) -> bool {
        let page = self.page.max(1);
        let back = &mut self.back;
        match action {
            Action::Up => *back += 1,
            Action::Down => *back = back.saturating_sub(1),
            Action::PageUp => *back += page,
            Action::PageDown => *back = back.saturating_sub(page),
            Action::Top => *back = len,
            Action::Bottom => *back = 0,
            Action::Back | Action::Messages => self.shown = false,
            _ => return false,
        }
        self.back = self.back.min(len.saturating_sub(self.page));
        true
    }

    /// Draws the popup showing `log` over `area`.
    pub fn render(&self, log: &Messages, f: &mut Frame, area: Rect) {
        render(log, self.back, f, area);
    }
}

/// Draws `log`, scrolled `back` lines up from its end, in a popup over `area`.
fn render(log: &Messages, back: usize, f: &mut Frame, area: Rect) {
    let r = popup(area);
    f.render_widget(Clear, r);
    let lines = log.lines();
    let height = height(area);
    let first = first_line(lines.len(), height, back);
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
        log.len(),
        if log.dropped > 0 {
            format!(", {} oldest dropped", log.dropped)
        } else {
            String::new()
        }
    );
    f.render_widget(Paragraph::new(body).block(block(&title, true)), r);
}
