//! The fast path for candump's screen lines with absolute or zero-based times (`-ta`,
//! `-tz`): ` (1700000000.000100)  can0  181   [2]  11 22`.
//!
//! It reads `(secs.frac)`, the interface name, a 3- or 8-digit hex id, `[n]` and n data
//! bytes as hex pairs, each after spaces, and the line end right after them. Delta times
//! (`-td`, summed up by the parser), lines without a time and other shapes (`-x`
//! columns, FD lengths, `remote request`, `ERRORFRAME`, an ASCII column or annotation,
//! tabs, a bad digit) return `None` and [`Parser::parse_line`] reads the line.

use super::super::cursor::Cursor;
use super::Parser;
use crate::frame::{Flags, Frame, Interfaces};

impl Parser {
    /// Reads a common line at the start of `buf` into `frame`; returns the bytes it took,
    /// its line end included, or `None` when [`Parser::parse_line`] must read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        if self.delta {
            return None;
        }
        let mut c = Cursor::new(buf);
        c.skip_spaces();
        c.byte(b'(')?;
        let ts_ns = c.seconds_ns()?;
        c.byte(b')')?;
        c.spaces()?;
        let name = c.iface_name(&self.iface)?;
        c.spaces()?;
        let (id, flags) = c.can_id()?;
        let mut f = Frame {
            ts_ns,
            id,
            flags: Flags(flags),
            ..Frame::default()
        };
        c.spaces()?;
        c.byte(b'[')?;
        f.len = c.decimal(1).filter(|&n| n <= 8)? as u8;
        c.byte(b']')?;
        c.spaced_bytes(&mut f.data[..f.len as usize])?;
        let end = c.line_end()?;
        f.iface = name.index(&mut self.iface, ifaces)?;
        *frame = f;
        self.tail = false;
        Some(end)
    }
}
