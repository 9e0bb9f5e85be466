//! The fast path for PEAK TRC 2.x data lines, as cotui's `TrcWriter` and PCAN-View write
//! them: `      1         0.100 DT  1      0181 Rx -  2    11 22`.
//!
//! The columns are read in `$COLUMNS` order as [`Parser`] reads them, each one token of
//! the shape it is written in (a `secs.frac` offset, a decimal bus and length, a hex id),
//! then the data bytes as hex pairs; what follows the bytes is read past, as the general
//! parser reads past it. Other versions, types other than `DT`, `FD`, `FB`, `FE` and `BI`,
//! tabs, other widths or a bad digit return `None`: the general parser reads the line.

use super::super::cursor::Cursor;
use super::{Kind, Parser, Version, set_id, set_length, v2_kind};
use crate::frame::{Flags, Frame, Interfaces};

impl Parser {
    /// Reads a common 2.x data line at the start of `buf` into `frame`; returns the bytes
    /// it took, its line end included, or `None` when [`Parser::parse_line`] must read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        if !matches!(self.version, Version::V2_0 | Version::V2_1) {
            return None;
        }
        let mut c = Cursor::new(buf);
        c.skip_spaces();
        if c.peek()? == b';' {
            return None;
        }
        let mut f = Frame::default();
        let (mut offset, mut bus, mut kind, mut id, mut dlc, mut len) = (0, 1, None, None, None, None);
        for (k, &col) in self.columns[..self.n_columns].iter().enumerate() {
            if col == b'D' {
                break;
            }
            if k > 0 {
                c.spaces()?;
            }
            match col {
                b'O' => offset = c.seconds_ns()? / 1000,
                b'T' => match v2_kind(c.word()?) {
                    k @ Kind::Frame { rtr: false, .. } => kind = Some(k),
                    _ => return None,
                },
                b'B' => bus = c.decimal(9)? as u32,
                b'I' => id = Some(c.hex(8)?),
                b'd' => match c.word()? {
                    b"Rx" => {}
                    b"Tx" => f.flags.set(Flags::TX, true),
                    _ => return None,
                },
                b'L' => dlc = Some((c.decimal(9)? as u32, 0)),
                b'l' => len = Some((c.decimal(9)? as u32, 0)),
                _ => {
                    c.word()?;
                }
            }
        }
        let Some(Kind::Frame { fd, brs, esi, rtr, .. }) = kind else {
            return None;
        };
        let (raw, digits) = id?;
        set_id(&mut f, raw, digits)?;
        set_length(&mut f, [fd, brs, esi, rtr], dlc, len, 0).ok()?;
        let ts_ns = self.start_ns.saturating_add(offset);
        c.spaced_frame_end(&mut f, (&mut self.channels, bus), ts_ns, ifaces, frame)
    }
}
