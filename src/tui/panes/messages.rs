//! The message log popup: every result, event and error with its time, newest at the
//! bottom, wrapped to the popup's width; ↑↓ select an entry (the view follows it), enter
//! shows the selected entry whole, `y` copies it (see `Screen::copy_entry`).

use super::block;
use crate::tui::keymap::Action;
use crate::tui::messages::{Level, Messages, wrap};
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Clear, Paragraph};

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

/// Characters a log line gets in the popup over `area`.
pub fn width(area: Rect) -> usize {
    popup(area).width.saturating_sub(2) as usize
}

/// The message log popup's state.
#[derive(Default)]
pub struct MessagesPopup {
    /// The popup is shown.
    shown: bool,
    /// The selected entry by its number since the session began (entries dropped from the
    /// front count); `None` follows the newest.
    selected: Option<u64>,
    /// The selected entry is shown whole, scrolled this many lines down.
    whole: Option<usize>,
    /// Lines the popup showed at once in the last draw.
    page: usize,
    /// Characters a line got in the last draw.
    width: usize,
}

impl MessagesPopup {
    /// True while the popup is shown.
    pub fn shown(&self) -> bool {
        self.shown
    }

    /// Notes the room the popup gets at the next draw: `page` lines of `width` characters.
    pub fn set_size(&mut self, page: usize, width: usize) {
        self.page = page;
        self.width = width;
    }

    /// Shows the popup at the newest entry.
    pub fn open(&mut self) {
        self.shown = true;
        self.selected = None;
        self.whole = None;
    }

    /// Shows or hides the popup (at the newest entry).
    pub fn toggle(&mut self) {
        let shown = !self.shown;
        self.open();
        self.shown = shown;
    }

    /// Position in `log` of the selected entry (None when the log is empty).
    pub fn index(&self, log: &Messages) -> Option<usize> {
        let last = log.len().checked_sub(1)?;
        Some(match self.selected {
            None => last,
            Some(n) => (n.saturating_sub(log.dropped) as usize).min(last),
        })
    }

    fn lines_of(&self, log: &Messages, i: usize) -> usize {
        log.get(i).map_or(0, |e| e.wrapped(self.width.max(20)).len())
    }

    /// Selects or scrolls in the popup over `log`; false when `action` is not for it.
    pub fn handle(&mut self, action: Action, log: &Messages) -> bool {
        let page = self.page.max(1);
        if let Some(down) = self.whole {
            let len = self
                .index(log)
                .and_then(|i| log.get(i))
                .map_or(0, |e| whole_lines(&e.text, self.width).len() + 1);
            let max = len.saturating_sub(page);
            let down = match action {
                Action::Up => down.saturating_sub(1),
                Action::Down => down + 1,
                Action::PageUp => down.saturating_sub(page),
                Action::PageDown => down + page,
                Action::Top => 0,
                Action::Bottom => max,
                Action::Back | Action::Expand => {
                    self.whole = None;
                    return true;
                }
                Action::Messages => {
                    self.shown = false;
                    return true;
                }
                _ => return false,
            };
            self.whole = Some(down.min(max));
            return true;
        }
        let Some(i) = self.index(log) else {
            return matches!(action, Action::Back | Action::Messages) && {
                self.shown = false;
                true
            };
        };
        let last = log.len() - 1;
        let to = match action {
            Action::Up => i.saturating_sub(1),
            Action::Down => i + 1,
            Action::PageUp => {
                let (mut j, mut n) = (i, 0);
                while j > 0 && n < page {
                    n += self.lines_of(log, j);
                    j -= 1;
                }
                j
            }
            Action::PageDown => {
                let (mut j, mut n) = (i, 0);
                while j <= last && n < page {
                    n += self.lines_of(log, j);
                    j += 1;
                }
                j
            }
            Action::Top => 0,
            Action::Bottom => usize::MAX,
            Action::Expand => {
                self.whole = Some(0);
                return true;
            }
            Action::Back | Action::Messages => {
                self.shown = false;
                return true;
            }
            _ => return false,
        };
        // Moving down onto the newest follows the log again.
        let follow = to >= last && matches!(action, Action::Down | Action::PageDown | Action::Bottom);
        self.selected = (!follow).then(|| log.dropped + to.min(last) as u64);
        true
    }

    /// Draws the popup showing `log` over `area`.
    pub fn render(&self, log: &Messages, f: &mut Frame, area: Rect) {
        let r = popup(area);
        f.render_widget(Clear, r);
        let height = height(area);
        let width = width(area);
        let count = format!(
            "{}{}",
            log.len(),
            if log.dropped > 0 {
                format!(", {} oldest dropped", log.dropped)
            } else {
                String::new()
            }
        );
        let Some(sel) = self.index(log) else {
            let body = Paragraph::new("no messages yet: command results, node and bus events appear here");
            f.render_widget(body.block(block(" Messages (0) — esc closes ", true)), r);
            return;
        };
        if let (Some(down), Some(e)) = (self.whole, log.get(sel)) {
            let mut lines = vec![Line::styled(
                format!(
                    "{} (entry {} of {})",
                    crate::tui::messages::clock(e.at),
                    sel + 1,
                    log.len()
                ),
                Style::default().add_modifier(Modifier::BOLD),
            )];
            let style = Style::default().fg(color(e.level));
            lines.extend(whole_lines(&e.text, width).into_iter().map(|l| Line::styled(l, style)));
            let body: Vec<Line> = lines.into_iter().skip(down).take(height).collect();
            let title = " Message — ↑↓ scroll · y: copy · enter/esc back to the log ";
            f.render_widget(Paragraph::new(body).block(block(title, true)), r);
            return;
        }
        // The selected entry at the bottom, older ones above it; newer ones fill what is
        // left when the oldest is reached; an entry taller than the popup shows its start.
        let lines_of = |i: usize| log.get(i).map_or(Vec::new(), |e| e.wrapped(width));
        let styled = |i: usize, ls: Vec<String>| -> Vec<Line<'static>> {
            let level = log.get(i).map_or(Level::Info, |e| e.level);
            let style = Style::default().fg(color(level));
            ls.into_iter()
                .enumerate()
                .map(|(k, l)| {
                    if i == sel && k == 0 {
                        let cut = l.char_indices().nth(12).map_or(l.len(), |(b, _)| b);
                        let stamp = Span::styled(l[..cut].to_string(), style.add_modifier(Modifier::REVERSED));
                        Line::from(vec![stamp, Span::styled(l[cut..].to_string(), style)])
                    } else {
                        Line::styled(l, style)
                    }
                })
                .collect()
        };
        let mine = lines_of(sel);
        let mut body: Vec<Line> = styled(sel, mine);
        body.truncate(height);
        let mut j = sel;
        while body.len() < height && j > 0 {
            j -= 1;
            let mut above = styled(j, lines_of(j));
            let room = height - body.len();
            if above.len() > room {
                above.drain(..above.len() - room);
            }
            above.append(&mut body);
            body = above;
        }
        let mut j = sel + 1;
        while body.len() < height && j < log.len() {
            body.extend(styled(j, lines_of(j)));
            j += 1;
        }
        body.truncate(height);
        let title = format!(" Messages ({count}) — ↑↓ select · enter: whole · y: copy · esc closes ");
        f.render_widget(Paragraph::new(body).block(block(&title, true)), r);
    }
}

/// An entry's text wrapped to `width`, for the whole-entry view.
fn whole_lines(text: &str, width: usize) -> Vec<String> {
    text.lines().flat_map(|l| wrap(l, width.max(8))).collect()
}

fn color(level: Level) -> Color {
    match level {
        Level::Info => Color::Reset,
        Level::Warn => Color::Yellow,
        Level::Error => Color::LightRed,
    }
}
