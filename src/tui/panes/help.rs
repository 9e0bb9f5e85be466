//! The help popup, generated from the keymap in force.

use super::{block, header};
use crate::tui::app::App;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Clear, Paragraph};

/// The help lines: one per bound action.
pub fn lines(app: &App) -> Vec<String> {
    app.keymap
        .help()
        .into_iter()
        .map(|(a, keys)| format!("{:<18} {}", keys.join(", "), a.help()))
        .collect()
}

/// Draws the popup centred in `area`.
pub fn render(app: &App, f: &mut Frame, area: Rect) {
    let body = lines(app);
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
