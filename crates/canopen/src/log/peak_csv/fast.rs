//! The fast path for PEAK CSV `DT` rows in the default column order, as PEAK-Converter
//! writes them: `1,1841.300,1,Rx,DT,0181,-,2,11,22,,,`.
//!
//! Once the first row has set the delimiter, it reads the message number, a `secs.frac`
//! time offset, a decimal bus, `Rx` or `Tx`, `DT`, a hex id, the reserved cell, the length
//! and the data bytes as hex pairs, one a cell; the cells after the bytes are read past, as
//! the general parser reads past them. Other types, named column orders, blanks, quotes,
//! decimal commas, a missing bus or a bad digit return `None`: [`Parser::parse_line`]
//! reads the row.

use super::super::cursor::Cursor;
use super::super::trc::{set_id, set_length};
use super::{DEFAULT_COLUMNS, Parser};
use crate::frame::{Flags, Frame, Interfaces};

impl Parser {
    /// Reads a common `DT` row at the start of `buf` into `frame`; returns the bytes it
    /// took, its line end included, or `None` when [`Parser::parse_line`] must read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        let d = self.delim?;
        if self.columns != DEFAULT_COLUMNS {
            return None;
        }
        let mut c = Cursor::new(buf);
        c.decimal(19)?;
        c.byte(d)?;
        let offset = c.seconds_ns()? / 1000;
        c.byte(d)?;
        let bus = c.decimal(9)? as u32;
        c.byte(d)?;
        let mut f = Frame::default();
        match c.take_while(|b| b.is_ascii_alphabetic()) {
            b"Rx" => {}
            b"Tx" => f.flags.set(Flags::TX, true),
            _ => return None,
        }
        c.byte(d)?;
        if c.take_while(|b| b.is_ascii_alphabetic()) != b"DT" {
            return None;
        }
        c.byte(d)?;
        let (id, digits) = c.hex(8)?;
        set_id(&mut f, id, digits)?;
        c.byte(d)?;
        c.take_while(|b| b != d && b != b'\r' && b != b'\n');
        c.byte(d)?;
        let len = c.decimal(2)? as u32;
        set_length(&mut f, [false; 4], None, Some((len, 0)), 0).ok()?;
        for k in 0..f.len as usize {
            c.byte(d)?;
            f.data[k] = c.hex_pair()?;
        }
        let end = match c.line_end() {
            Some(end) => end,
            None => {
                c.byte(d)?;
                c.rest_of_line()?
            }
        };
        f.iface = self.channels.get(ifaces, bus, 0).ok()?;
        f.ts_ns = self.start_ns.saturating_add(offset);
        self.rows = true;
        *frame = f;
        Some(end)
    }
}
