//! The panes, one module each, plus the shared styles.

pub mod detail;
pub mod help;
pub mod messages;
pub mod nodes;
pub mod plot;
pub mod sdo;
pub mod stats;
pub mod status;
pub mod trace;

use crate::decode::Kind;
use ratatui::style::{Color, Modifier, Style};
use ratatui::widgets::{Block, BorderType, Borders};

/// The colour of a kind in the trace.
pub fn kind_color(kind: Kind) -> Color {
    match kind {
        Kind::Nmt => Color::Magenta,
        Kind::Sync => Color::DarkGray,
        Kind::Emcy => Color::Red,
        Kind::Time => Color::Gray,
        Kind::Tpdo => Color::Green,
        Kind::Rpdo => Color::LightGreen,
        Kind::SdoTx => Color::Cyan,
        Kind::SdoRx => Color::LightCyan,
        Kind::Heartbeat => Color::Blue,
        Kind::Lss => Color::Yellow,
        Kind::ErrorFrame => Color::LightRed,
        Kind::Other => Color::White,
    }
}

/// Style of the selected row.
pub fn selected() -> Style {
    Style::default().add_modifier(Modifier::REVERSED)
}

/// Style of a table header.
pub fn header() -> Style {
    Style::default().add_modifier(Modifier::BOLD)
}

/// A pane frame with a title; focused panes get a thick border.
pub fn block(title: &str, focused: bool) -> Block<'_> {
    Block::default()
        .borders(Borders::ALL)
        .border_type(if focused { BorderType::Thick } else { BorderType::Plain })
        .title(title)
}

/// Seconds as `1.234 s`, `12.3 ms` or `45 µs`.
pub fn duration(secs: f64) -> String {
    if secs >= 1.0 {
        format!("{secs:.3} s")
    } else if secs >= 1e-3 {
        format!("{:.1} ms", secs * 1e3)
    } else {
        format!("{:.0} µs", secs * 1e6)
    }
}

/// Cuts `s` to `width` characters, marking the cut with `…`.
pub fn fit(s: &str, width: usize) -> String {
    if s.chars().count() <= width {
        s.to_string()
    } else if width == 0 {
        String::new()
    } else {
        s.chars().take(width - 1).chain(std::iter::once('…')).collect()
    }
}

#[cfg(test)]
pub(crate) mod testutil {
    //! Helpers for the pane rendering tests.
    use crate::analysis::trace::Trace;
    use crate::decode::Decoder;
    use crate::frame::Frame;
    use crate::od::Dictionary;
    use crate::tui::app::{App, SourceInfo, SourceKind};
    use crate::tui::keymap::Keymap;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    /// A small fixed capture: boot-ups, NMT start, a PDO mapping written by SDO, heartbeats,
    /// statusword PDOs (switched on, then operation enabled), an SDO abort, an EMCY.
    pub fn frames() -> Vec<Frame> {
        let mut v = Vec::new();
        let mut t = 1_700_000_000_000_000_000u64;
        let mut add = |id: u32, data: &[u8], dt_ms: u64| {
            t += dt_ms * 1_000_000;
            let mut f = Frame::classic(id, data);
            f.ts_ns = t;
            v.push(f);
        };
        add(0x701, &[0x00], 0);
        add(0x702, &[0x00], 1);
        add(0x000, &[0x01, 0x00], 5);
        add(0x601, &[0x40, 0x17, 0x10, 0x00, 0, 0, 0, 0], 1);
        add(0x581, &[0x4B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0], 1);
        // Map TPDO1 of node 1 to the statusword (the decoder learns it from these writes).
        add(0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0], 1);
        add(0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0], 1);
        add(0x601, &[0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60], 1);
        add(0x581, &[0x60, 0x00, 0x1A, 0x01, 0, 0, 0, 0], 1);
        add(0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x01, 0, 0, 0], 1);
        add(0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0], 1);
        add(0x602, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0], 1);
        add(0x582, &[0x80, 0x41, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06], 2);
        for i in 0..6u8 {
            add(0x080, &[], 10);
            add(0x181, &[0x37 - (i < 3) as u8 * 4, 0x02], 1);
            add(0x201, &[0x0F, 0x00, i, 0, 0, 0], 1);
            add(0x701, &[0x05], 1);
            add(0x702, &[0x7F], 1);
        }
        add(0x082, &[0x10, 0x23, 0x11, 0, 0, 0, 0, 0], 3);
        v
    }

    /// An app holding [`frames`] (fully ingested), default keymap.
    pub fn app() -> App {
        let mut trace = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        trace.ifaces.intern("can0");
        for f in frames() {
            trace.push(&f);
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("test.log", SourceKind::Open, rx, None);
        src.done = true;
        App::new(trace, Keymap::default_map(), src)
    }

    /// Renders the whole screen of `app` at `w`×`h` and returns the text.
    pub fn screen(app: &mut App, w: u16, h: u16) -> String {
        let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
        term.draw(|f| crate::tui::ui::draw(f, app)).unwrap();
        let buf = term.backend().buffer().clone();
        let mut out = String::new();
        for y in 0..buf.area.height {
            let line: String = (0..buf.area.width).map(|x| buf[(x, y)].symbol().to_string()).collect();
            out.push_str(line.trim_end());
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod render_tests;
