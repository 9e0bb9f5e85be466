//! The Stats pane: per COB-ID count, rate, period and jitter; bus load from the bit rate.

use super::{Component, Ctx, ListState, Outcome, block, duration, header, selected};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// The Stats pane's state: the selection.
#[derive(Default)]
pub struct StatsPane {
    /// Scroll state.
    pub list: ListState,
}

impl Component for StatsPane {
    /// Moves the selection; `expand` shows the selected COB-ID's frames in the trace.
    fn handle(&mut self, action: Action, ctx: &Ctx) -> Outcome {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return Outcome::Done;
        }
        match action {
            Action::Expand => match ctx.trace.stats.iter().nth(self.list.selected) {
                Some(((_, id), _)) => Outcome::Filter(format!("id {id:X}")),
                None => Outcome::Done,
            },
            _ => Outcome::Ignored,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, ctx.trace.stats.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, ctx.trace.stats.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, ctx: &Ctx) {
        self.list.clamp(ctx.trace.stats.len(), height);
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let st = &ctx.trace.stats;
        let title = format!(
            " Stats — bus load {:.1}% at {} kbit/s ({} frames in the last second) ",
            st.load_percent(),
            st.bitrate() / 1000,
            st.window_frames(&ctx.trace.store)
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
        let l = self.list;
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
}
