//! The Stats pane: per COB-ID count, rate, period and jitter; bus load from the bit rate.

use super::{block, duration, header, selected};
use crate::tui::app::App;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// Draws the pane.
pub fn render(app: &App, f: &mut Frame, area: Rect, focused: bool) {
    let st = &app.trace.stats;
    let title = format!(
        " Stats — bus load {:.1}% at {} kbit/s ({} frames in the last second) ",
        st.load_percent(),
        st.bitrate() / 1000,
        st.window_frames(&app.trace.store)
    );
    f.render_widget(block(&title, focused), area);
    let inner = block("", true).inner(area);
    if inner.height == 0 {
        return;
    }
    let mut lines = vec![Line::styled(
        format!(
            "{:<9} {:>10} {:>9} {:>10} {:>10}",
            "cob-id", "count", "rate/s", "period", "jitter"
        ),
        header(),
    )];
    let l = app.stats_list;
    for (i, ((ext, id), s)) in st.iter().enumerate().skip(l.offset).take(inner.height as usize - 1) {
        let cob = if *ext { format!("{id:08X}") } else { format!("{id:03X}") };
        let line = Line::raw(format!(
            "{:<9} {:>10} {:>9.1} {:>10} {:>10}",
            cob,
            s.count,
            s.rate(),
            s.period().map(duration).unwrap_or_else(|| "-".into()),
            s.jitter().map(duration).unwrap_or_else(|| "-".into()),
        ));
        lines.push(if i == l.selected { line.style(selected()) } else { line });
    }
    f.render_widget(Paragraph::new(lines), inner);
}
