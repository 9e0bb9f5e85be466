//! The fast path for python-can CSV rows whose timestamp is written `secs.frac`:
//! `1700000000.000100,0x181,0,0,0,2,ESI=`.
//!
//! The fields are lexed straight from the reader's buffer (a `secs.frac` time, a hex id
//! with or without `0x`, three `0`/`1` flags, the DLC digits, the base64 data up to the
//! line end) and handed to the general parser's own [`Parser::fill`]; other shapes
//! (exponents, blanks, extra fields, a bad digit) return `None` and
//! [`Parser::parse_line`] reads the line.

use super::super::cursor::Cursor;
use super::Parser;
use crate::frame::{Frame, Interfaces};

impl Parser {
    /// Reads a common row at the start of `buf` into `frame`; returns the bytes it took,
    /// its line end included, or `None` when [`Parser::parse_line`] must read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        let mut c = Cursor::new(buf);
        let ts_ns = c.seconds_ns()?;
        c.byte(b',')?;
        let id_at = c.pos();
        if c.rest().starts_with(b"0x") {
            c.advance(2);
        }
        let (raw, _) = c.hex(8)?;
        let mut flags = [false; 3];
        for flag in &mut flags {
            c.byte(b',')?;
            *flag = c.byte(b'1').is_some();
            if !*flag {
                c.byte(b'0')?;
            }
        }
        c.byte(b',')?;
        let dlc = (c.pos(), c.take_while(|b| b.is_ascii_digit()));
        c.byte(b',')?;
        let data = (c.pos(), c.take_while(super::is_base64));
        let end = c.line_end()?;
        let mut f = Frame {
            ts_ns,
            ..Frame::default()
        };
        self.fill(&mut f, ifaces, (id_at, raw), flags, dlc, data).ok()?;
        *frame = f;
        Some(end)
    }
}
