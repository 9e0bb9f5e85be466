//! The PDO pane: per node, each RPDO/TPDO with its COB-ID, transmission type in words,
//! inhibit and event time, SYNC start and mapped signals, and where the mapping came from
//! (profile, EDS, learned on the bus, configured by cotui, read from the node). Below the
//! table, the selected PDO's signals. Rows come from the decoder's state
//! ([`crate::analysis::pdos`]), built for the visible window only.

use super::{Component, Ctx, ListState, block, fit, header, selected};
use crate::analysis::pdos::{keys, rows};
use crate::decode::pdo_config::entry_text;
use crate::tui::event::{Event, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

/// Column widths of the table (the signals take the rest).
const WIDTHS: [usize; 8] = [4, 6, 18, 30, 8, 9, 10, 24];
/// Lines kept below the table for the selected PDO's signals.
const SIGNAL_LINES: u16 = 7;

/// The PDO pane's state: the selection.
#[derive(Default)]
pub struct PdoPane {
    /// Scroll state.
    list: ListState,
}

impl PdoPane {
    fn len(ctx: &Ctx) -> usize {
        keys(ctx.trace.decoder()).len()
    }
}

impl Component for PdoPane {
    /// Moves the selection; `expand` shows the selected PDO's frames in the trace.
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return true;
        }
        match action {
            Action::Expand => {
                let d = ctx.trace.decoder();
                let Some(key) = keys(d).get(self.list.selected).copied() else {
                    return true;
                };
                let row = &rows(d, &[key])[0];
                let cob = row.comm.as_ref().and_then(|c| c.cob());
                match cob
                    .map(|c| (c.id, c.extended))
                    .or(row.id.predefined_cob(row.node).map(|c| (c, false)))
                {
                    Some((id, true)) => q.answer(Event::Filter(format!("id {id:08X}"))),
                    Some((id, false)) => q.answer(Event::Filter(format!("id {id:X}"))),
                    None => true,
                }
            }
            _ => false,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, Self::len(ctx), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, Self::len(ctx), ctx.page);
    }

    fn fit(&mut self, height: usize, ctx: &Ctx) {
        let table = height.saturating_sub(SIGNAL_LINES as usize + 1).max(1);
        self.list.clamp(Self::len(ctx), table);
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        let d = ctx.trace.decoder();
        let all = keys(d);
        let title = format!(" PDO — {} known (enter: its frames in the trace) ", all.len());
        f.render_widget(block(&title, focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let below = if inner.height > SIGNAL_LINES + 3 {
            SIGNAL_LINES
        } else {
            0
        };
        let table_rows = (inner.height - below).saturating_sub(1) as usize;
        let width = inner.width as usize;
        let heads = [
            "node",
            "pdo",
            "cob-id",
            "transmission",
            "inhibit",
            "event",
            "sync start",
            "mapping from",
            "signals",
        ];
        let line = |cells: &[String]| {
            let mut s = String::new();
            for (i, c) in cells.iter().enumerate() {
                match WIDTHS.get(i) {
                    Some(w) => s.push_str(&format!("{:<w$} ", fit(c, *w))),
                    None => s.push_str(c),
                }
            }
            fit(&s, width)
        };
        let mut lines = vec![Line::styled(line(&heads.map(str::to_string)), header())];
        if all.is_empty() {
            lines.push(Line::raw(fit(
                "no PDO known yet: bind a profile or EDS, read a node's PDOs (`pdo NODE`), or capture SDO mapping writes",
                width,
            )));
        }
        let l = self.list;
        let window: Vec<_> = all.iter().skip(l.offset).take(table_rows).copied().collect();
        let dict = |node: u8| ctx.trace.decoder().dictionary(node);
        for (k, row) in rows(d, &window).into_iter().enumerate() {
            let cells = row.cells(|i, s| dict(row.node).name(i, s).map(str::to_string));
            let text = Line::raw(line(&cells));
            lines.push(if l.offset + k == l.selected {
                text.style(selected())
            } else {
                text
            });
        }
        let table_height = (inner.height - below).min(lines.len() as u16);
        f.render_widget(
            Paragraph::new(lines),
            Rect {
                height: table_height,
                ..inner
            },
        );
        if below == 0 {
            return;
        }
        let Some(key) = all.get(l.selected).copied() else {
            return;
        };
        let row = &rows(d, &[key])[0];
        let mut detail = vec![Line::styled(
            fit(
                &format!(
                    "node {} {}: {}",
                    row.node,
                    row.id.title(),
                    row.source_text(super::start_ns(ctx.trace))
                        .map_or("no mapping known".into(), |s| format!("mapping {s}"))
                ),
                width,
            ),
            header(),
        )];
        if let Some(c) = &row.comm {
            detail.push(Line::raw(fit(&format!("  {}", c.text()), width)));
        }
        if let Some(m) = &row.mapping {
            detail.extend(
                m.entries
                    .iter()
                    .map(|e| Line::raw(fit(&format!("  {}", entry_text(e, dict(row.node))), width))),
            );
        }
        let y = inner.y + inner.height - below;
        f.render_widget(
            Paragraph::new(detail),
            Rect {
                y,
                height: below,
                ..inner
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::screen;
    use crate::analysis::trace::Trace;
    use crate::decode::Decoder;
    use crate::frame::{Flags, Frame};
    use crate::tui::app::{App, SourceInfo, SourceKind};
    use crate::tui::keymap::{Action, Keymap};
    use crate::tui::panes::Pane;

    /// The demo's two drives (mappings from the simulator's dictionary), then cotui remaps
    /// TPDO1 of node 2 (its SDO requests marked TX) to statusword + position, every 2nd
    /// SYNC, and another client sets node 3's TPDO2 event timer.
    fn app() -> App {
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let mut trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
        trace.ifaces.intern("can0");
        let mut t = 1_700_000_000_000_000_000u64;
        let mut push = |id: u32, data: &[u8], tx: bool| {
            t += 1_000_000;
            let mut f = Frame::classic(id, data);
            f.ts_ns = t;
            f.flags.set(Flags::TX, tx);
            trace.push(&f);
        };
        let writes: [(u32, [u8; 8]); 7] = [
            (0x602, [0x23, 0x00, 0x18, 0x01, 0x82, 0x01, 0x00, 0x80]),
            (0x602, [0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0]),
            (0x602, [0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60]),
            (0x602, [0x23, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x64, 0x60]),
            (0x602, [0x2F, 0x00, 0x1A, 0x00, 0x02, 0, 0, 0]),
            (0x602, [0x2F, 0x00, 0x18, 0x02, 0x02, 0, 0, 0]),
            (0x602, [0x23, 0x00, 0x18, 0x01, 0x82, 0x01, 0x00, 0x00]),
        ];
        for (id, req) in writes {
            push(id, &req, true);
            push(id - 0x80, &[0x60, req[1], req[2], req[3], 0, 0, 0, 0], false);
        }
        push(0x603, &[0x2B, 0x01, 0x18, 0x05, 0x64, 0x00, 0, 0], false);
        push(0x583, &[0x60, 0x01, 0x18, 0x05, 0, 0, 0, 0], false);
        push(0x182, &[0x37, 0x02, 0x10, 0x27, 0x00, 0x00], false);
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("demo.log", SourceKind::Open, rx, None);
        src.done = true;
        let mut a = App::new(trace, Keymap::default_map(), src);
        a.screen_mut().focus_on(Pane::Pdo);
        a
    }

    #[test]
    fn pdo_pane_lists_each_pdo_with_its_parameters_and_mapping_source() {
        let mut a = app();
        let s = screen(&mut a, 230, 20);
        assert!(s.lines().next().unwrap().contains(" 7 PDO "), "{s}");
        assert!(s.contains("PDO — 11 known"), "{s}");
        let row = |s: &str, node: &str, pdo: &str| {
            s.lines()
                .find(|l| l.contains(&format!("┃{node:<4} {pdo:<6}")))
                .unwrap_or_default()
                .to_string()
        };
        let tpdo1 = row(&s, "2", "TPDO1");
        for want in [
            "0x182",
            "synchronous, every 2 SYNCs (2)",
            "configured",
            "Statusword, Position actual value",
        ] {
            assert!(tpdo1.contains(want), "{want}: {tpdo1}\n{s}");
        }
        assert!(row(&s, "2", "RPDO1").contains("profile demo simulator"), "{s}");
        insta::assert_snapshot!(s);
        // The selected PDO's signals below; enter shows its frames.
        for _ in 0..2 {
            a.act(Action::Down);
        }
        let s = screen(&mut a, 230, 20);
        assert!(s.contains("node 2 TPDO1: mapping configured by cotui @"), "{s}");
        assert!(s.contains("  0x6064:00 Position actual value, 32 bits [Pul]"), "{s}");
        a.act(Action::Expand);
        assert_eq!(a.focus(), Pane::Trace);
        let s = screen(&mut a, 230, 20);
        assert!(s.contains("filter: id 182"), "{s}");
        assert!(s.contains("TPDO1 node 2: Statusword=0x0237"), "{s}");
        assert!(s.contains("Position actual value=10000"), "{s}");
    }

    #[test]
    fn tiny_areas_and_no_pdos_do_not_panic() {
        let mut a = super::super::testutil::app();
        a.screen_mut().focus_on(Pane::Pdo);
        for (w, h) in [(0, 0), (10, 3), (40, 8), (80, 24)] {
            let _ = screen(&mut a, w, h);
        }
        let s = screen(&mut a, 120, 16);
        assert!(s.contains("PDO — 1 known"), "{s}");
        assert!(s.contains("node 1 TPDO1: mapping sniffed @ 0.014000 s"), "{s}");
    }
}
