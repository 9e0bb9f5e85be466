//! The fast path for Vector ASC classic frame lines, as Vector tools, python-can and
//! cotui's `AscWriter` write them: `   0.000100 1  181             Rx   d 2 11 22`.
//!
//! It reads a `secs.frac` time, a decimal channel, a hex id (`x` for 29 bits), `Rx` or
//! `Tx`, `d`, a one-digit DLC and the data bytes as hex pairs, each after spaces; what
//! follows the bytes (`Length = …`) is read past, as the general parser reads past it.
//! With `base dec` or `timestamps relative`, and for other shapes (remote frames, `CANFD`,
//! events, tabs, other widths, a bad digit), it returns `None` and [`Parser::parse_line`]
//! reads the line.

use super::super::cursor::Cursor;
use super::Parser;
use crate::frame::{Flags, Frame, Interfaces};

impl Parser {
    /// Reads a common classic frame line at the start of `buf` into `frame`; returns the
    /// bytes it took, its line end included, or `None` when [`Parser::parse_line`] must
    /// read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        if self.decimal || self.relative {
            return None;
        }
        let mut c = Cursor::new(buf);
        c.skip_spaces();
        let ts = c.seconds_ns()?;
        c.spaces()?;
        let channel = c.decimal(9)? as u32;
        c.spaces()?;
        let (id, _) = c.hex(8)?;
        let ext = c.byte(b'x').or_else(|| c.byte(b'X')).is_some();
        if id > if ext { 0x1FFF_FFFF } else { 0x7FF } {
            return None;
        }
        c.spaces()?;
        let tx = match c.word()? {
            b"Rx" => false,
            b"Tx" => true,
            _ => return None,
        };
        c.spaces()?;
        c.byte(b'd')?;
        c.spaces()?;
        let (dlc, _) = c.hex(1)?;
        let mut f = Frame {
            id,
            len: (dlc as u8).min(8),
            raw_dlc: if dlc > 8 { dlc as u8 } else { 0 },
            ..Frame::default()
        };
        f.flags.set(Flags::EXT, ext);
        f.flags.set(Flags::TX, tx);
        let ts_ns = self.start_ns.saturating_add(ts);
        c.spaced_frame_end(&mut f, (&mut self.channels, channel), ts_ns, ifaces, frame)
    }
}
