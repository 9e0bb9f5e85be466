//! PEAK TRC logs (PCAN-View, PCAN-Explorer, python-can's `TRCWriter`), versions 1.0 to 2.1,
//! after PEAK's "PCAN-Trace File Format" description.
//!
//! ```text
//! ;$FILEVERSION=2.1
//! ;$STARTTIME=45244.9258101852
//! ;$COLUMNS=N,O,T,B,I,d,R,L,D
//!       1         0.100 DT  1      0181 Rx -  2    11 22
//!       2         0.200 FB  2  18FF0102 Tx -  9    00 01 02 03 04 05 06 07 08 09 0A 0B
//!       3         0.300 RR  1      0701 Rx -  1
//!       4         0.400 ST  1           Rx    00 00 00 08
//!       5         0.500 ER  1           Rx    04 00 02 00 00
//!       6         0.600 EC  1           Rx    02 81
//! ```
//! Header lines start with `;`: `$FILEVERSION` picks the line layout (none: 1.0),
//! `$STARTTIME` (days since 1899-12-30, as UTC) is added to every message's time offset
//! (milliseconds), `$COLUMNS` names the 2.x columns in their order (`N` number, `O` offset,
//! `T` type, `B` bus, `I` id, `d` direction, `R` reserved, `l` data length, `L` DLC, `D`
//! data). The 1.x layouts: 1.0 `N) time id dlc data`, 1.1 `N) time type id dlc data`, 1.2
//! `N) time bus type id dlc data`, 1.3 `N) time bus type id - dlc data`.
//!
//! Choices: bus N is interface `can{N-1}` (no bus column: `can0`), as for ASC channels;
//! ids of more than 4 digits are 29-bit; `RTR` in place of the data (1.x) or type `RR` is a
//! remote frame; types `FD`, `FB` (BRS), `FE` (ESI), `BI` (BRS and ESI) are CAN FD frames,
//! their `L` a DLC up to 15 (`l`: the length); status lines (1.x `Warng` with id
//! `FFFFFFFF`, 2.x `ST`) are controller states from the PCAN status code in the last four
//! bytes (`BUSOFF` 0x10, `BUSPASSIVE` 0x40000, `BUSHEAVY` 0x08 and `BUSLIGHT` 0x04 warning
//! level, 0 error active); error lines (1.0 `ERROR` in place of the data, 1.1 to 1.3 `Error`,
//! 2.x `ER`) are bus errors; error counter lines (2.x `EC`: the RX error counter, then the TX
//! one) are the counters with the state they imply (error passive from 128, warning from 96).
//! Other events (`EV` user text, ...) are skipped.

mod fast;

use super::lex::{self, Channels, Tokens, dec_u32, err, hex, hex_u32, trim_end};
use super::status::{self, State};
use super::{Line, ParseError, SkipReason};
use crate::frame::{Flags, Frame, Interfaces};

/// The most `$COLUMNS` entries read.
const MAX_COLUMNS: usize = 16;

/// A TRC file version.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Version {
    /// 1.0 (also when no `$FILEVERSION` line is given).
    #[default]
    V1_0,
    /// 1.1.
    V1_1,
    /// 1.2.
    V1_2,
    /// 1.3.
    V1_3,
    /// 2.0.
    V2_0,
    /// 2.1.
    V2_1,
}

/// The version a `$FILEVERSION` line in `sample` (the start of the input) names.
pub(crate) fn detect_version(sample: &[u8]) -> Version {
    let mut p = Parser::new();
    for line in sample.split(|&b| b == b'\n').take(64) {
        let s = trim_end(line);
        if let Some(rest) = s.strip_prefix(b";") {
            p.header_line(rest);
        }
    }
    p.version
}

/// Parser state for TRC lines (version, start time, columns, bus names). Use one parser
/// with one [`Interfaces`] table: it caches indexes into it.
#[derive(Debug)]
pub struct Parser {
    version: Version,
    start_ns: u64,
    columns: [u8; MAX_COLUMNS],
    n_columns: usize,
    channels: Channels,
}

impl Default for Parser {
    fn default() -> Self {
        let mut p = Parser {
            version: Version::V1_0,
            start_ns: 0,
            columns: [0; MAX_COLUMNS],
            n_columns: 0,
            channels: Channels::default(),
        };
        p.set_columns(b"N,O,T,I,d,l,D");
        p
    }
}

/// What the type of a line makes of it.
pub(super) enum Kind {
    Frame {
        fd: bool,
        brs: bool,
        esi: bool,
        rtr: bool,
        tx: bool,
    },
    Status,
    Error,
    Counters,
    Other,
}

impl Parser {
    /// A parser for version 1.0 until a `$FILEVERSION` line says otherwise.
    pub fn new() -> Self {
        Parser::default()
    }

    /// Parses one TRC line.
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        let s = trim_end(line);
        let at = lex::skip_ws(s, 0);
        if at == s.len() {
            return Ok(Line::Skip(SkipReason::Blank));
        }
        if s[at] == b';' {
            return Ok(Line::Skip(self.header_line(&s[at + 1..])));
        }
        let (f, bus) = match self.version {
            Version::V2_0 | Version::V2_1 => self.line_v2(s)?,
            _ => self.line_v1(s)?,
        };
        let Some((mut f, offset_ns)) = f else {
            return Ok(Line::Skip(SkipReason::Event));
        };
        let (bus, bus_at) = bus.unwrap_or((1, 0));
        f.iface = self.channels.get(ifaces, bus, bus_at)?;
        f.ts_ns = self.start_ns.saturating_add(offset_ns);
        Ok(Line::Frame(f))
    }

    /// A `;` line: `$FILEVERSION`, `$STARTTIME` and `$COLUMNS` are read, others are comments.
    fn header_line(&mut self, text: &[u8]) -> SkipReason {
        let Some((key, value)) = header_entry(text) else {
            return SkipReason::Comment;
        };
        match key {
            b"$FILEVERSION" => {
                self.version = match value {
                    b"1.1" => Version::V1_1,
                    b"1.2" => Version::V1_2,
                    b"1.3" => Version::V1_3,
                    b"2.0" => Version::V2_0,
                    b"2.1" => Version::V2_1,
                    _ => Version::V1_0,
                };
                if self.version == Version::V2_1 {
                    self.set_columns(b"N,O,T,B,I,d,R,L,D");
                }
            }
            b"$STARTTIME" => self.start_ns = ole_days_to_ns(value).unwrap_or(0),
            b"$COLUMNS" => self.set_columns(value),
            _ => return SkipReason::Comment,
        }
        SkipReason::Header
    }

    fn set_columns(&mut self, value: &[u8]) {
        self.n_columns = 0;
        for c in value.split(|&b| b == b',').map(trim_end) {
            if let ([c], true) = (c, self.n_columns < MAX_COLUMNS) {
                self.columns[self.n_columns] = *c;
                self.n_columns += 1;
            }
        }
    }

    /// A 1.x message line: the frame with its time offset, and the bus when the layout has one.
    #[allow(clippy::type_complexity)]
    fn line_v1(&self, s: &[u8]) -> Result<(Option<(Frame, u64)>, Option<(u32, usize)>), ParseError> {
        let mut toks = Tokens::new(s, 0);
        let (n_at, n) = toks.next().ok_or_else(|| err(0, "expected a message number"))?;
        if !n.ends_with(b")") {
            return Err(err(n_at, "expected a message number like 1)"));
        }
        let offset = offset_ns(toks.next(), s.len())?;
        let mut bus = None;
        if matches!(self.version, Version::V1_2 | Version::V1_3) {
            let (b_at, b) = toks.next().ok_or_else(|| err(s.len(), "expected a bus number"))?;
            bus = Some((dec_u32(b).ok_or_else(|| err(b_at, "expected a bus number"))?, b_at));
        }
        let kind = if self.version == Version::V1_0 {
            frame_kind(b"Rx")
        } else {
            let (_, t) = toks.next().ok_or_else(|| err(s.len(), "expected a message type"))?;
            v1_kind(t)
        };
        let (id_at, id) = toks.next().ok_or_else(|| err(s.len(), "expected a CAN id"))?;
        if self.version == Version::V1_3 {
            toks.next(); // reserved
        }
        let (dlc_at, dlc) = toks.next().ok_or_else(|| err(s.len(), "expected a data length"))?;
        let dlc = dec_u32(dlc)
            .filter(|&d| d <= 15)
            .ok_or_else(|| err(dlc_at, "expected a data length 0..15"))? as u8;
        let kind = if self.version == Version::V1_0 && id == b"FFFFFFFF" {
            Kind::Status
        } else {
            kind
        };
        // 1.0 error frames: `2)  1842  0008  4  ERROR  00 19 08 08` (the id is the error type).
        let kind = match kind {
            Kind::Frame { .. } if toks.peek().is_some_and(|(_, t)| t == b"ERROR") => Kind::Error,
            k => k,
        };
        let f = match kind {
            Kind::Frame { tx, .. } => {
                let rtr = toks.peek().is_some_and(|(_, t)| t == b"RTR");
                let mut f = Frame::default();
                parse_id(&mut f, id_at, id)?;
                f.flags.set(Flags::TX, tx);
                classic(&mut f, dlc, rtr);
                if !rtr {
                    data(&mut f, &mut toks, s.len())?;
                }
                f
            }
            Kind::Status => status_frame(hex_pairs(&mut toks).0),
            Kind::Error => status::protocol_error(),
            Kind::Counters | Kind::Other => return Ok((None, bus)),
        };
        Ok((Some((f, offset)), bus))
    }

    /// A 2.x message line, read column by column in `$COLUMNS` order.
    #[allow(clippy::type_complexity)]
    fn line_v2(&self, s: &[u8]) -> Result<(Option<(Frame, u64)>, Option<(u32, usize)>), ParseError> {
        let mut toks = Tokens::new(s, 0);
        let mut f = Frame::default();
        let (mut offset, mut bus, mut kind) = (0, None, None);
        let (mut id, mut dlc, mut len) = (None, None, None);
        for &c in &self.columns[..self.n_columns] {
            let end = s.len();
            match c {
                b'O' => offset = offset_ns(toks.next(), end)?,
                b'T' => {
                    let (_, t) = toks.next().ok_or_else(|| err(end, "expected a message type"))?;
                    let k = v2_kind(t);
                    if let Kind::Frame { .. } = k {
                        kind = Some(k);
                        continue;
                    }
                    // Status and error lines leave the id and length columns blank: a
                    // bus column right after the type is read, their bytes are the last tokens.
                    if let Some(b'B') = self.columns[..self.n_columns].iter().skip_while(|&&x| x != b'T').nth(1) {
                        bus = toks.next().and_then(|(b_at, b)| dec_u32(b).map(|n| (n, b_at))).or(bus);
                    }
                    let f = match k {
                        Kind::Status => status_frame(hex_pairs(&mut toks).0),
                        Kind::Error => status::protocol_error(),
                        Kind::Counters => counters_frame(hex_pairs(&mut toks)).ok_or_else(|| err(end, COUNTERS))?,
                        _ => return Ok((None, bus)),
                    };
                    return Ok((Some((f, offset)), bus));
                }
                b'B' => {
                    let (b_at, b) = toks.next().ok_or_else(|| err(end, "expected a bus number"))?;
                    bus = Some((dec_u32(b).ok_or_else(|| err(b_at, "expected a bus number"))?, b_at));
                }
                b'I' => id = Some(toks.next().ok_or_else(|| err(end, "expected a CAN id"))?),
                b'd' => {
                    let (d_at, d) = toks.next().ok_or_else(|| err(end, "expected Rx or Tx"))?;
                    match d {
                        b"Rx" => {}
                        b"Tx" => f.flags.set(Flags::TX, true),
                        _ => return Err(err(d_at, "expected Rx or Tx")),
                    }
                }
                b'L' | b'l' => {
                    let (n_at, n) = toks.next().ok_or_else(|| err(end, "expected a data length"))?;
                    let v = dec_u32(n).ok_or_else(|| err(n_at, "expected a data length"))?;
                    if c == b'L' {
                        dlc = Some((v, n_at));
                    } else {
                        len = Some((v, n_at));
                    }
                }
                b'D' => break,
                _ => {
                    toks.next();
                }
            }
        }
        let Some(Kind::Frame { fd, brs, esi, rtr, .. }) = kind else {
            return Err(err(s.len(), "expected a message type (T column)"));
        };
        let (id_at, id) = id.ok_or_else(|| err(s.len(), "expected a CAN id (I column)"))?;
        parse_id(&mut f, id_at, id)?;
        set_length(&mut f, [fd, brs, esi, rtr], dlc, len, s.len())?;
        if !rtr {
            data(&mut f, &mut toks, s.len())?;
        }
        Ok((Some((f, offset)), bus))
    }
}

/// The key and value of a `;` header line's text (`$STARTTIME=45244.5`), both trimmed;
/// `None` without a `=`.
pub(super) fn header_entry(text: &[u8]) -> Option<(&[u8], &[u8])> {
    let i = text.iter().position(|&b| b == b'=')?;
    let value = &text[i + 1..];
    Some((trim_end(&text[..i]), trim_end(&value[lex::skip_ws(value, 0)..])))
}

/// Sets the length (and the FD flags) of a 2.x frame of type flags `[fd, brs, esi, rtr]`
/// from its `L` column (a DLC) or else its `l` column (a length), each with its index;
/// `end` is the line's length.
pub(super) fn set_length(
    f: &mut Frame,
    [fd, brs, esi, rtr]: [bool; 4],
    dlc: Option<(u32, usize)>,
    len: Option<(u32, usize)>,
    end: usize,
) -> Result<(), ParseError> {
    let (n, n_at) = dlc
        .map(|(d, at)| (d, at, true))
        .or(len.map(|(l, at)| (l, at, false)))
        .map(|(v, at, is_dlc)| {
            let n = if is_dlc && fd { fd_len(v) } else { Some(v) };
            (n, at)
        })
        .ok_or_else(|| err(end, "expected a data length (L or l column)"))?;
    let bad = || err(n_at, "data length out of range");
    if fd {
        let n = n
            .filter(|&n| n <= 8 || matches!(n, 12 | 16 | 20 | 24 | 32 | 48 | 64))
            .ok_or_else(bad)?;
        f.flags.set(Flags::FD | Flags::FDF, true);
        f.flags.set(Flags::BRS, brs);
        f.flags.set(Flags::ESI, esi);
        f.len = n as u8;
    } else {
        let n = n.filter(|&n| n <= 15).ok_or_else(bad)?;
        classic(f, n as u8, rtr);
    }
    Ok(())
}

/// The length of FD DLC `dlc`.
fn fd_len(dlc: u32) -> Option<u32> {
    crate::frame::FD_LENS.get(dlc as usize).map(|&n| u32::from(n))
}

fn frame_kind(dir: &[u8]) -> Kind {
    Kind::Frame {
        fd: false,
        brs: false,
        esi: false,
        rtr: false,
        tx: dir == b"Tx",
    }
}

fn v1_kind(t: &[u8]) -> Kind {
    match t {
        b"Rx" | b"Tx" => frame_kind(t),
        b"Warng" => Kind::Status,
        b"Error" => Kind::Error,
        _ => Kind::Other,
    }
}

/// What a 2.x message type (`DT`, `FB`, `ST`, ...) makes of a line.
pub(super) fn v2_kind(t: &[u8]) -> Kind {
    let frame = |fd, brs, esi, rtr| Kind::Frame {
        fd,
        brs,
        esi,
        rtr,
        tx: false,
    };
    match t {
        b"DT" => frame(false, false, false, false),
        b"RR" => frame(false, false, false, true),
        b"FD" => frame(true, false, false, false),
        b"FB" => frame(true, true, false, false),
        b"FE" => frame(true, false, true, false),
        b"BI" => frame(true, true, true, false),
        b"ST" => Kind::Status,
        b"ER" => Kind::Error,
        b"EC" => Kind::Counters,
        _ => Kind::Other,
    }
}

/// A time offset in milliseconds (`1059.900`) as nanoseconds.
pub(super) fn offset_ns(tok: Option<(usize, &[u8])>, end: usize) -> Result<u64, ParseError> {
    let (at, t) = tok.ok_or_else(|| err(end, "expected a time offset (ms)"))?;
    let (v, stop) = lex::timestamp(t, 0).map_err(|e| err(at + e.column - 1, e.message))?;
    if stop != t.len() {
        return Err(err(at + stop, "expected a time offset like 1059.900 (ms)"));
    }
    Ok(v / 1000)
}

/// An id: more than 4 hex digits is a 29-bit id.
pub(super) fn parse_id(f: &mut Frame, at: usize, tok: &[u8]) -> Result<(), ParseError> {
    let id = hex_u32(tok).ok_or_else(|| err(at, "expected a CAN id in hex"))?;
    set_id(f, id, tok.len()).ok_or_else(|| err(at, "CAN id out of range"))
}

/// Sets the id `id` written with `digits` hex digits; `None` when out of range.
pub(super) fn set_id(f: &mut Frame, id: u32, digits: usize) -> Option<()> {
    let ext = digits > 4;
    if id > if ext { 0x1FFF_FFFF } else { 0x7FF } {
        return None;
    }
    f.id = id;
    f.flags.set(Flags::EXT, ext);
    Some(())
}

/// A classic frame's length from DLC `dlc` (a DLC above 8 is kept as the raw DLC).
fn classic(f: &mut Frame, dlc: u8, rtr: bool) {
    f.flags.set(Flags::RTR, rtr);
    f.len = dlc.min(8);
    if dlc > 8 {
        f.raw_dlc = dlc;
    }
}

/// `f.len` data bytes of 2 hex digits; text after them (1.x annotations) is left.
fn data(f: &mut Frame, toks: &mut Tokens<'_>, end: usize) -> Result<(), ParseError> {
    for k in 0..f.len as usize {
        let (b_at, b) = toks
            .next()
            .ok_or_else(|| err(end, "fewer data bytes than the length says"))?;
        f.data[k] = match b {
            [h, l] => match (hex(*h), hex(*l)) {
                (Some(h), Some(l)) => h << 4 | l,
                _ => return Err(err(b_at, "expected a data byte of 2 hex digits")),
            },
            _ => return Err(err(b_at, "expected a data byte of 2 hex digits")),
        };
    }
    Ok(())
}

/// The bytes of a status or counter line: its two-digit hex tokens (`00 00 00 08 BUSHEAVY`:
/// a trailing name, a `-` or `Rx` column, a one-digit length are read past) as a big-endian
/// number of their last four, and how many there were.
pub(super) fn hex_pairs<'a>(toks: impl IntoIterator<Item = (usize, &'a [u8])>) -> (u32, usize) {
    let (mut code, mut n) = (0u32, 0);
    for (_, t) in toks {
        if let (2, Some(b)) = (t.len(), hex_u32(t)) {
            code = code << 8 | b;
            n += 1;
        }
    }
    (code, n)
}

/// What an `EC` line lacks when it has fewer than two bytes.
pub(super) const COUNTERS: &str = "expected 2 error counter bytes (RX, TX)";

/// The error frame of an error counter line's bytes `(code, count)` (as [`hex_pairs`] gives
/// them): the RX counter, then the TX counter; `None` with fewer than two bytes.
pub(super) fn counters_frame((code, n): (u32, usize)) -> Option<Frame> {
    (n >= 2).then(|| status::counters_frame(code & 0xFF, code >> 8 & 0xFF))
}

/// The controller state of a status line's PCAN status code (the line's last four bytes).
pub(super) fn status_frame(code: u32) -> Frame {
    let state = if code & 0x10 != 0 {
        State::BusOff
    } else if code & 0x4_0000 != 0 {
        State::Passive
    } else if code & 0x0C != 0 {
        State::Warning
    } else {
        State::Active
    };
    status::state_frame(state, None)
}

/// `$STARTTIME`: days (with fraction) since 1899-12-30 as nanoseconds since the Unix
/// epoch; `None` when malformed or before 1970.
pub(super) fn ole_days_to_ns(value: &[u8]) -> Option<u64> {
    const UNIX_DAY: u128 = 25_569;
    const NS_PER_DAY: u128 = 86_400_000_000_000;
    let (int, frac) = match value.iter().position(|&b| b == b'.') {
        Some(i) => (&value[..i], &value[i + 1..]),
        None => (value, &value[..0]),
    };
    let days = u128::from(dec_u32(int)?);
    let (mut num, mut den) = (0u128, 1u128);
    for &b in frac.iter().take(18) {
        if !b.is_ascii_digit() {
            return None;
        }
        num = num * 10 + u128::from(b - b'0');
        den *= 10;
    }
    let ns = days.checked_sub(UNIX_DAY)? * NS_PER_DAY + num * NS_PER_DAY / den;
    u64::try_from(ns).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(text: &str) -> (Vec<Frame>, Interfaces) {
        let mut p = Parser::new();
        let mut ifaces = Interfaces::default();
        let fs = text
            .lines()
            .filter_map(|l| match p.parse_line(l.as_bytes(), &mut ifaces) {
                Ok(Line::Frame(f)) => Some(f),
                Ok(Line::Skip(_)) => None,
                Err(e) => panic!("{l:?}: {e}"),
            })
            .collect();
        (fs, ifaces)
    }

    #[test]
    fn version_1_0_and_1_1() {
        let (fs, _) = frames(
            ";##########\n;   Start time: 12.11.2007 17:28:14.109\n     1)      1841  0001    8  00 01 02 03 04 05 06 07\n     2)      1842  00000100  2  RTR\n     3)      1843  FFFFFFFF  4  00 00 00 10\n     4)      1844  0008    4  ERROR 00 19 08 08\n",
        );
        assert_eq!(
            (fs[0].ts_ns, fs[0].id, fs[0].len, fs[0].data[7]),
            (1_841_000_000, 1, 8, 7)
        );
        assert_eq!(
            (fs[1].id, fs[1].flags.0, fs[1].len),
            (0x100, Flags::EXT | Flags::RTR, 2)
        );
        assert_eq!((fs[2].flags.0, fs[2].id), (Flags::ERR, 0x40));
        assert_eq!(
            (fs[3].flags.0, fs[3].id, fs[3].ts_ns),
            (Flags::ERR, 0x88, 1_844_000_000)
        );
        let (fs, _) = frames(
            ";$FILEVERSION=1.1\n;$STARTTIME=25569.5\n     1)      1059.9  Rx         0300  8  00 00 00 00 00 00 00 01\n     2)      1298.9  Tx     00000100  8  RTR\n     3)      1346.0  Warng  FFFFFFFF  4  00 00 00 08  BUSHEAVY\n     4)      1349.8  Error      0100  3  00 19 08\n     5)      1350.0  Bogus      0100  0\n",
        );
        assert_eq!(fs.len(), 4);
        assert_eq!(fs[0].ts_ns, 43_200_000_000_000 + 1_059_900_000);
        assert_eq!((fs[1].flags.0, fs[1].len), (Flags::EXT | Flags::RTR | Flags::TX, 8));
        assert_eq!((fs[2].id, fs[2].data[1]), (0x004, 0x08));
        assert_eq!((fs[3].flags.0, fs[3].id), (Flags::ERR, 0x88));
    }

    #[test]
    fn versions_1_2_and_1_3_have_a_bus() {
        let (fs, ifaces) = frames(";$FILEVERSION=1.2\n     1)      1.000 2  Rx         0300  1  AA\n");
        assert_eq!(
            (ifaces.name(fs[0].iface), fs[0].id, fs[0].data[0]),
            ("can1", 0x300, 0xAA)
        );
        let (fs, ifaces) = frames(";$FILEVERSION=1.3\n     1)      1.500 3  Tx         0300 -  1  BB\n");
        assert_eq!(
            (ifaces.name(fs[0].iface), fs[0].ts_ns, fs[0].flags.0),
            ("can2", 1_500_000, Flags::TX)
        );
    }

    #[test]
    fn version_2_columns_fd_remote_status_and_errors() {
        let (fs, ifaces) = frames(
            ";$FILEVERSION=2.1\n;$STARTTIME=25570\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n      1         0.100 DT  1      0181 Rx -  2    11 22\n      2         0.200 FB  2  18FF0102 Tx -  9    00 01 02 03 04 05 06 07 08 09 0A 0B\n      3         0.300 RR  1      0701 Rx -  1\n      4         0.400 ST  1           Rx    00 04 00 00\n      5         0.500 ER  1           Rx    04 00 02 00 00\n      6         0.600 EV  1  some event\n      7         0.700 EC  1         - Rx -  2    02 81\n      8         0.800 EC  2         - Rx -  2    61 05\n      9         0.900 EC  1         - Rx -  2    00 00\n",
        );
        assert_eq!(fs.len(), 8, "EV skipped, EC read");
        assert_eq!(
            (fs[0].ts_ns, fs[0].id, fs[0].payload()),
            (86_400_000_100_000, 0x181, &[0x11, 0x22][..])
        );
        assert_eq!(
            (ifaces.name(fs[1].iface), fs[1].flags.0, fs[1].len, fs[1].data[11]),
            (
                "can1",
                Flags::EXT | Flags::TX | Flags::FD | Flags::FDF | Flags::BRS,
                12,
                0x0B
            )
        );
        assert_eq!((fs[2].flags.0, fs[2].len), (Flags::RTR, 1));
        assert_eq!((fs[3].id, fs[3].data[1]), (0x004, 0x20), "BUSPASSIVE");
        assert_eq!(fs[4].id, 0x88);
        // EC: RX counter 2, TX 0x81 = 129: error passive on the TX side, with the counters
        // (CAN_ERR_CRTL | CAN_ERR_CNT, data[6] TX, data[7] RX).
        assert_eq!(
            (fs[5].id, fs[5].data[1], fs[5].data[6], fs[5].data[7], fs[5].ts_ns),
            (0x204, 0x20, 0x81, 0x02, 86_400_000_700_000)
        );
        assert_eq!(
            (ifaces.name(fs[6].iface), fs[6].data[1], fs[6].data[6], fs[6].data[7]),
            ("can1", 0x04, 5, 97),
            "RX 97: RX warning"
        );
        assert_eq!((fs[7].id, fs[7].data[1]), (0x204, 0x40), "both 0: error active");
        // 2.0 with a length column.
        let (fs, _) = frames(
            ";$FILEVERSION=2.0\n;$COLUMNS=N,O,T,I,d,l,D\n      1      1054.310 FE     0300 Rx 12 11 22 33 44 55 66 77 88 99 AA BB CC\n",
        );
        assert_eq!((fs[0].len, fs[0].flags.0), (12, Flags::FD | Flags::FDF | Flags::ESI));
    }

    #[test]
    fn malformed_lines_are_located_errors() {
        let mut p = Parser::new();
        let mut ifaces = Interfaces::default();
        let mut e = |l: &str| p.parse_line(l.as_bytes(), &mut ifaces).unwrap_err();
        assert_eq!(
            e("     1)      1841  0001    8  00 01").message,
            "fewer data bytes than the length says"
        );
        assert_eq!(e("     1)      18x1  0001    0").column, 16);
        assert_eq!(e("     1)      1841  0801    0").message, "CAN id out of range");
        assert_eq!(e("     1      1841  0001    0").column, 6);
        let mut p2 = Parser::new();
        p2.parse_line(b";$FILEVERSION=2.1", &mut ifaces).unwrap();
        let ec = p2.parse_line(b"      1         0.700 EC  1         - Rx -  1    02", &mut ifaces);
        assert_eq!(ec, Err(err(51, COUNTERS)));
        assert_eq!(ole_days_to_ns(b"45244.5"), Some(1_699_963_200_000_000_000));
        assert_eq!(ole_days_to_ns(b"100"), None);
    }
}
