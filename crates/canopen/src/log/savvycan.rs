//! SavvyCAN CSV logs (its "GVRET" CSV, SavvyCAN's own save format):
//!
//! ```text
//! Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8
//! 166064000,0000021A,false,Rx,0,8,FE,36,12,FE,69,05,07,AD,
//! ```
//! Times are microseconds, the id hex without `0x`, `Extended` `true`/`false`, `Dir` `Rx`
//! or `Tx` (older files have no `Dir` column), `Bus` a number (frames go to `can0`,
//! `can1`, ...), `LEN` the data length (above 8: a CAN FD frame), then one hex byte per
//! column (empty columns past `LEN` are left alone). The columns are taken from the header.

mod fast;

use super::lex::{IfaceCache, dec_u32, err, hex_u32, trim_end};
use super::{Line, ParseError, SkipReason};
use crate::frame::{FD_LENS, Flags, Frame, Interfaces};

/// How every SavvyCAN CSV header starts.
pub(crate) const HEADER_START: &[u8] = b"Time Stamp,ID,Extended,";

/// Parser state: the columns of the header. Use one parser with one [`Interfaces`] table.
#[derive(Debug, Default)]
pub struct Parser {
    /// Column of `Dir`, `Bus`, `LEN` and the first data byte, once the header is read.
    columns: Option<Columns>,
    iface: IfaceCache,
    /// The bus of the last row the fast path read and its interface index.
    last_bus: Option<(u32, u16)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Columns {
    dir: Option<usize>,
    bus: Option<usize>,
    len: usize,
    data: usize,
}

/// The columns of the header SavvyCAN writes: `Time Stamp,ID,Extended,Dir,Bus,LEN,D1,...`.
const DEFAULT_COLUMNS: Columns = Columns {
    dir: Some(3),
    bus: Some(4),
    len: 5,
    data: 6,
};

/// The most columns read from one row (64 data bytes and the leading ones).
const MAX_FIELDS: usize = 80;

impl Parser {
    /// A parser (it learns the columns from the header line).
    pub fn new() -> Self {
        Parser::default()
    }

    /// Parses one line: the header, or a frame row.
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        let s = trim_end(line);
        if s.is_empty() {
            return Ok(Line::Skip(SkipReason::Blank));
        }
        let mut fields = [(0usize, &s[..0]); MAX_FIELDS];
        let mut n = 0;
        let mut at = 0;
        for field in s.split(|&b| b == b',') {
            if n == MAX_FIELDS {
                return Err(err(at, "more columns than a CAN FD frame has"));
            }
            fields[n] = (at, field);
            n += 1;
            at += field.len() + 1;
        }
        let fields = &fields[..n];
        if s.starts_with(HEADER_START) {
            let col = |name: &[u8]| fields.iter().position(|(_, f)| *f == name);
            let len = col(b"LEN").ok_or_else(|| err(0, "SavvyCAN header without a LEN column"))?;
            self.columns = Some(Columns {
                dir: col(b"Dir"),
                bus: col(b"Bus"),
                len,
                data: len + 1,
            });
            return Ok(Line::Skip(SkipReason::Header));
        }
        let c = self
            .columns
            .ok_or_else(|| err(0, "a row before the SavvyCAN header line"))?;
        let field = |i: usize| {
            fields
                .get(i)
                .copied()
                .ok_or_else(|| err(s.len(), "row with fewer columns than its header"))
        };
        let (at, ts) = field(0)?;
        let us = ts
            .iter()
            .try_fold(0u64, |v, &b| {
                b.is_ascii_digit()
                    .then(|| v.checked_mul(10)?.checked_add(u64::from(b - b'0')))
                    .flatten()
            })
            .filter(|_| !ts.is_empty())
            .ok_or_else(|| err(at, "expected a time stamp in microseconds"))?;
        let mut f = Frame {
            ts_ns: us.checked_mul(1000).ok_or_else(|| err(at, "time stamp too large"))?,
            ..Frame::default()
        };
        let (at, ext) = field(2)?;
        let ext = match ext {
            b"true" | b"1" => true,
            b"false" | b"0" => false,
            _ => return Err(err(at, "expected true or false")),
        };
        let (at, id) = field(1)?;
        let id = hex_u32(id).ok_or_else(|| err(at, "expected a hex CAN id"))?;
        if id > if ext { 0x1FFF_FFFF } else { 0x7FF } {
            return Err(err(at, "CAN id out of range"));
        }
        f.id = id;
        f.flags.set(Flags::EXT, ext);
        if let Some(d) = c.dir {
            let (at, dir) = field(d)?;
            match dir {
                b"Rx" => {}
                b"Tx" => f.flags.set(Flags::TX, true),
                _ => return Err(err(at, "expected Rx or Tx")),
            }
        }
        let (at, len) = field(c.len)?;
        let len = dec_u32(len)
            .filter(|&n| n <= 64)
            .ok_or_else(|| err(at, "expected a data length"))? as u8;
        if len > 8 {
            if !FD_LENS.contains(&len) {
                return Err(err(at, "CAN FD data of a length no DLC gives"));
            }
            f.flags.set(Flags::FD, true);
        }
        f.len = len;
        for k in 0..len as usize {
            let (at, byte) = field(c.data + k)?;
            f.data[k] = hex_u32(byte)
                .filter(|&b| b <= 0xFF && !byte.is_empty())
                .ok_or_else(|| err(at, "expected a hex data byte"))? as u8;
        }
        let bus = match c.bus {
            Some(b) => {
                let (at, bus) = field(b)?;
                dec_u32(bus)
                    .filter(|&n| n < 1000)
                    .ok_or_else(|| err(at, "expected a bus number"))?
            }
            None => 0,
        };
        let (name, n) = bus_name(bus);
        f.iface = self.iface.get(ifaces, &name[..n], 0)?;
        Ok(Line::Frame(f))
    }
}

/// The interface name of bus `bus` (below 1000): `can0`, `can12`; the name's bytes and
/// its length.
fn bus_name(bus: u32) -> ([u8; 6], usize) {
    let mut name = *b"can000";
    let digits = if bus >= 100 {
        3
    } else if bus >= 10 {
        2
    } else {
        1
    };
    for k in 0..digits {
        name[3 + digits - 1 - k] = b'0' + (bus / 10u32.pow(k as u32) % 10) as u8;
    }
    (name, 3 + digits)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(text: &str) -> Vec<Result<Line, ParseError>> {
        let (mut p, mut ifaces) = (Parser::new(), Interfaces::default());
        text.lines().map(|l| p.parse_line(l.as_bytes(), &mut ifaces)).collect()
    }

    #[test]
    fn rows_take_their_columns_from_the_header() {
        let got = frames(
            "Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8\n166064000,0000021A,false,Tx,1,2,FE,36,,,,,,,\nTime Stamp,ID,Extended,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8\n5,18FF0102,true,0,1,AA,\n",
        );
        let Ok(Line::Frame(a)) = got[1] else { panic!("{got:?}") };
        assert_eq!(
            (a.ts_ns, a.id, a.payload(), a.direction()),
            (166_064_000_000, 0x21A, &[0xFE, 0x36][..], crate::frame::Direction::Tx)
        );
        let Ok(Line::Frame(b)) = got[3] else { panic!("{got:?}") };
        assert!(b.is_ext() && b.id == 0x18FF_0102 && b.payload() == [0xAA]);
        let bad = frames("Time Stamp,ID,Extended,Dir,Bus,LEN,D1\n1,800,false,Rx,0,1,AA\n1,1,maybe,Rx,0,0\n");
        assert_eq!(bad[1], Err(err(2, "CAN id out of range")));
        assert_eq!(bad[2], Err(err(4, "expected true or false")));
    }
}
