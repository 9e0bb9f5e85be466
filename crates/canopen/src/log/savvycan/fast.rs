//! The fast path for SavvyCAN CSV rows of a classic frame in the columns SavvyCAN writes
//! (`Time Stamp,ID,Extended,Dir,Bus,LEN,D1,...`): `166064000,0000021A,false,Rx,0,2,FE,36,`.
//!
//! It reads the microseconds, a hex id, `true`/`false`/`1`/`0`, `Rx` or `Tx`, a decimal
//! bus, a length up to 8 and that many two-digit hex bytes, one a cell, then at most eight
//! empty cells up to the line end. Other headers' column orders, FD lengths, one-digit
//! bytes, cells with text after the data, blanks or a bad digit return `None`:
//! [`Parser::parse_line`] reads the row.

use super::super::cursor::Cursor;
use super::{DEFAULT_COLUMNS, Parser, bus_name};
use crate::frame::{Flags, Frame, Interfaces};

/// Empty cells the fast path reads past after the data (SavvyCAN pads to `D8`).
const PADDING_MAX: usize = 8;

impl Parser {
    /// Reads a common row at the start of `buf` into `frame`; returns the bytes it took,
    /// its line end included, or `None` when [`Parser::parse_line`] must read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        if self.columns != Some(DEFAULT_COLUMNS) {
            return None;
        }
        let mut c = Cursor::new(buf);
        let ts_ns = c.long_decimal()?.checked_mul(1000)?;
        c.byte(b',')?;
        let (id, _) = c.hex(8)?;
        c.byte(b',')?;
        let ext = match c.take_while(|b| b.is_ascii_alphanumeric()) {
            b"true" | b"1" => true,
            b"false" | b"0" => false,
            _ => return None,
        };
        if id > if ext { 0x1FFF_FFFF } else { 0x7FF } {
            return None;
        }
        let mut f = Frame {
            ts_ns,
            id,
            ..Frame::default()
        };
        f.flags.set(Flags::EXT, ext);
        c.byte(b',')?;
        match c.take_while(|b| b.is_ascii_alphabetic()) {
            b"Rx" => {}
            b"Tx" => f.flags.set(Flags::TX, true),
            _ => return None,
        }
        c.byte(b',')?;
        let bus = c.decimal(3)? as u32;
        c.byte(b',')?;
        let len = c.decimal(1)?;
        if len > 8 {
            return None;
        }
        f.len = len as u8;
        for k in 0..f.len as usize {
            c.byte(b',')?;
            f.data[k] = c.hex_pair()?;
        }
        let mut padding = 0;
        let end = loop {
            if let Some(end) = c.line_end() {
                break end;
            }
            c.byte(b',')?;
            padding += 1;
            if padding > PADDING_MAX {
                return None;
            }
        };
        f.iface = match self.last_bus {
            Some((last, iface)) if last == bus => iface,
            _ => {
                let (name, n) = bus_name(bus);
                let iface = self.iface.get(ifaces, &name[..n], 0).ok()?;
                self.last_bus = Some((bus, iface));
                iface
            }
        };
        *frame = f;
        Some(end)
    }
}
