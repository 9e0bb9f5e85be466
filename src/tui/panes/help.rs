//! The help popup, generated from the keymap in force.

use super::{block, header};
use crate::tui::keymap::{Action, Keymap};
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Clear, Paragraph};

/// The help popup's state.
#[derive(Default)]
pub struct HelpPopup {
    /// The popup is shown.
    pub shown: bool,
}

impl HelpPopup {
    /// `help` shows or hides the popup, `back` closes it; false when `action` is not for it.
    pub fn handle(&mut self, action: Action) -> bool {
        match action {
            Action::Help => self.shown = !self.shown,
            Action::Back if self.shown => self.shown = false,
            _ => return false,
        }
        true
    }
}

/// The help lines: one per bound action.
pub fn lines(keymap: &Keymap) -> Vec<String> {
    keymap
        .help()
        .into_iter()
        .map(|(a, keys)| format!("{:<18} {}", keys.join(", "), a.help()))
        .collect()
}

/// Draws the popup for `keymap` centred in `area`.
pub fn render(keymap: &Keymap, f: &mut Frame, area: Rect) {
    let body = lines(keymap);
    let w = (body.iter().map(|l| l.chars().count()).max().unwrap_or(20) as u16 + 4).min(area.width);
    let h = (body.len() as u16 + 4).min(area.height);
    let r = Rect {
        x: area.x + (area.width - w) / 2,
        y: area.y + (area.height - h) / 2,
        width: w,
        height: h,
    };
    f.render_widget(Clear, r);
    let mut text = vec![Line::styled(
        "keys (filter language: node N, kind K, id X, IIII:SS, abort, emcy, \"text\")",
        header(),
    )];
    text.push(Line::raw(""));
    text.extend(body.into_iter().map(Line::raw));
    f.render_widget(Paragraph::new(text).block(block(" Help — esc closes ", true)), r);
}
