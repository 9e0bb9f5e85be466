//! candump `-l` / `-L` log lines: `(1436509052.249713) vcan0 044#2A366C2BBA`.
//!
//! The tolerance follows can-utils' `canplayer` and `parse_canframe` (lib.c):
//! - any line not starting with `(` is not a frame (comments, `DROPCOUNT: ...`);
//! - blanks between the fields may be any run of spaces or tabs (padded interface names);
//! - the fraction of the timestamp may have any number of digits (6 and 9 are what candump
//!   writes; python-can writes `(0.0)`), digits past the ninth are dropped;
//! - ids have 3 hex digits (11-bit) or 8 (29-bit, or an error frame when `CAN_ERR_FLAG`
//!   0x20000000 is set; then [`Frame::id`] holds the class bits without the flag);
//! - `R`/`r` with an optional length and `_<raw dlc>` when that length is 8;
//! - `.` between data bytes; `_<raw dlc>` after exactly 8 data bytes;
//! - `##<flags>` CAN FD frames, where flag bits 1/2/4 become BRS/ESI/FDF (bit 8 is ignored);
//! - 5-digit CAN XL ids are skipped as [`SkipReason::CanXl`];
//! - an optional trailing `R` or `T` (candump `-x`); `T` sets [`Flags::TX`];
//! - any other text after a blank behind the frame (a comment, an annotation) is ignored
//!   as `canplayer` ignores it, and the line is flagged ([`Parser::ignored_tail`]) so the
//!   reader can say how many lines had text it did not read.
//!
//! Unlike `parse_canframe`, text glued to the frame (`123#1122zz`), a bad raw DLC or an
//! 11-bit id above 7FF is reported as an error, so that what parses is exactly what
//! [`super::writer`] writes back.

mod fast;

use super::lex::{self, IfaceCache, err, hex, is_ws, skip_ws, token_end, trim_end};
use super::{Line, ParseError, SkipReason};
use crate::frame::linux::CAN_ERR_FLAG;
use crate::frame::{Flags, Frame, Interfaces};

/// Parser state for candump log lines (remembers the last interface to intern nothing per
/// line). Use one parser with one [`Interfaces`] table: it caches an index into it.
#[derive(Debug, Default)]
pub struct Parser {
    iface: IfaceCache,
    tail: bool,
}

impl Parser {
    /// A fresh parser.
    pub fn new() -> Self {
        Parser::default()
    }

    /// True when the last frame line had text after the frame that was ignored.
    pub fn ignored_tail(&self) -> bool {
        self.tail
    }

    /// Reads the common `-l` line at the start of `buf` (see [`fast`]) into `frame`;
    /// returns the bytes it took, its line end included, or `None` when the general
    /// [`Parser::parse_into`] must read it.
    #[inline]
    pub fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        let n = fast::line(buf, &mut self.iface, ifaces, frame)?;
        self.tail = false;
        Some(n)
    }

    /// Parses one line (with or without its line end).
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        let mut frame = Frame::default();
        Ok(match self.parse_into(line, ifaces, &mut frame)? {
            Some(reason) => Line::Skip(reason),
            None => Line::Frame(frame),
        })
    }

    /// Like [`Parser::parse_line`], but writes a frame into `frame` (returning `None`) so
    /// that a hot loop copies no frame around; a skip returns its reason.
    pub fn parse_into(
        &mut self,
        line: &[u8],
        ifaces: &mut Interfaces,
        frame: &mut Frame,
    ) -> Result<Option<SkipReason>, ParseError> {
        let s = trim_end(line);
        self.tail = false;
        if s.first() != Some(&b'(') {
            let t = &s[skip_ws(s, 0)..];
            return Ok(Some(if t.is_empty() {
                SkipReason::Blank
            } else if t.starts_with(b"DROPCOUNT") {
                SkipReason::DropCount
            } else {
                SkipReason::Comment
            }));
        }
        let (ts, i) = lex::timestamp(s, 1)?;
        if s.get(i) != Some(&b')') {
            return Err(err(i, "expected ')' after the timestamp"));
        }
        let name_at = skip_ws(s, i + 1);
        if name_at == i + 1 {
            return Err(err(i + 1, "expected a blank after the timestamp"));
        }
        let name_end = token_end(s, name_at);
        let frame_at = skip_ws(s, name_end);
        if frame_at >= s.len() {
            return Err(err(frame_at, "expected an interface name and a frame"));
        }
        let Some(frame_end) = compact(&s[frame_at..], frame_at, frame)? else {
            return Ok(Some(SkipReason::CanXl));
        };
        let extra_at = skip_ws(s, frame_end);
        if extra_at < s.len() {
            match (s[extra_at], s.len() - extra_at) {
                (b'T', 1) => frame.flags.set(Flags::TX, true),
                (b'R', 1) => {}
                _ if extra_at == frame_end => {
                    return Err(err(extra_at, "unexpected text after the frame"));
                }
                _ => self.tail = true,
            }
        }
        frame.ts_ns = ts;
        frame.iface = self.iface.get(ifaces, &s[name_at..name_end], name_at)?;
        Ok(None)
    }
}

/// Parses one candump line with a throw-away [`Parser`] (convenient in tests and one-offs).
pub fn parse_line(line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
    Parser::new().parse_line(line, ifaces)
}

/// Parses a compact frame as `cansend` takes it (`123#1122`, `12345678#R`, `123##1AABB`).
///
/// Returns `Ok(None)` for a CAN XL frame, which cotui does not model. Columns in errors
/// count from the start of `text`. Timestamp and interface of the frame are left at 0.
pub fn parse_compact(text: &[u8]) -> Result<Option<Frame>, ParseError> {
    let mut f = Frame::default();
    match compact(text, 0, &mut f)? {
        None => Ok(None),
        Some(end) if end == text.len() => Ok(Some(f)),
        Some(end) => Err(err(end, "unexpected text after the frame")),
    }
}

/// [`parse_compact`] for the text `t` that starts at line index `at`, into `f`: the frame
/// ends at the first blank or the end of `t`. Returns the line index just past it (`None`
/// for CAN XL).
fn compact(t: &[u8], at: usize, f: &mut Frame) -> Result<Option<usize>, ParseError> {
    *f = Frame::default();
    let mut i = if t.len() > 3 && t[3] == b'#' {
        let id = id_digits(&t[..3], at)?;
        if id > 0x7FF {
            return Err(err(at, "11-bit CAN id above 7FF"));
        }
        f.id = id;
        4
    } else if t.len() > 5 && t[5] == b'#' {
        return Ok(None);
    } else if t.len() > 8 && t[8] == b'#' {
        let raw = id_digits(&t[..8], at)?;
        if raw & 0xC000_0000 != 0 {
            return Err(err(at, "29-bit CAN id with bit 30 or 31 set"));
        }
        if raw & CAN_ERR_FLAG != 0 {
            f.flags.set(Flags::ERR, true);
            f.id = raw & !CAN_ERR_FLAG;
        } else {
            f.flags.set(Flags::EXT, true);
            f.id = raw;
        }
        9
    } else {
        return Err(err(at, "expected a CAN id of 3 or 8 hex digits followed by '#'"));
    };
    let more = |i: usize| i < t.len() && !is_ws(t[i]);
    let mut max = 8;
    match t.get(i) {
        Some(b'R' | b'r') => {
            f.flags.set(Flags::RTR, true);
            i += 1;
            if more(i) {
                match hex(t[i]) {
                    Some(n) if n <= 8 => f.len = n,
                    _ => return Err(err(at + i, "remote frame length must be a digit 0..8")),
                }
                i += 1;
            }
            i = raw_dlc(t, i, f, at)?;
            if more(i) {
                return Err(err(at + i, "unexpected text after the remote frame"));
            }
            return Ok(Some(at + i));
        }
        Some(b'#') => {
            let flags = t
                .get(i + 1)
                .and_then(|&b| hex(b))
                .ok_or_else(|| err(at + i + 1, "expected a CAN FD flags digit after '##'"))?;
            f.flags.set(Flags::FD, true);
            f.flags.set(Flags::BRS, flags & 1 != 0);
            f.flags.set(Flags::ESI, flags & 2 != 0);
            f.flags.set(Flags::FDF, flags & 4 != 0);
            max = 64;
            i += 2;
        }
        _ => {}
    }
    let mut n = 0usize;
    while i < t.len() {
        let c = t[i];
        if let Some(hi) = hex(c) {
            if n == max {
                return Err(err(
                    at + i,
                    if max == 8 {
                        "more than 8 data bytes (CAN FD frames use '##')"
                    } else {
                        "more than 64 data bytes"
                    },
                ));
            }
            let lo = match t.get(i + 1) {
                Some(&b) if !is_ws(b) => hex(b).ok_or_else(|| err(at + i + 1, "expected a hex digit in the data"))?,
                _ => return Err(err(at + i + 1, "odd number of hex digits in the data")),
            };
            f.data[n] = hi << 4 | lo;
            n += 1;
            i += 2;
        } else if c == b'.' {
            i += 1;
        } else if c == b'_' || is_ws(c) {
            break;
        } else {
            return Err(err(at + i, "expected a hex digit in the data"));
        }
    }
    f.len = n as u8;
    if max == 8 {
        i = raw_dlc(t, i, f, at)?;
    }
    if more(i) {
        return Err(err(at + i, "unexpected text after the data"));
    }
    Ok(Some(at + i))
}

/// Parses an optional `_<dlc>` (9..F) at `i`, allowed only when the length is 8.
fn raw_dlc(t: &[u8], i: usize, f: &mut Frame, at: usize) -> Result<usize, ParseError> {
    if t.get(i) != Some(&b'_') {
        return Ok(i);
    }
    if f.len != 8 {
        return Err(err(at + i, "a raw DLC '_<9..F>' is only allowed with length 8"));
    }
    match t.get(i + 1).and_then(|&b| hex(b)) {
        Some(d) if d > 8 => f.raw_dlc = d,
        _ => return Err(err(at + i + 1, "raw DLC after '_' must be a hex digit 9..F")),
    }
    Ok(i + 2)
}

/// Hex value of an id field; errors point at the bad digit.
fn id_digits(t: &[u8], at: usize) -> Result<u32, ParseError> {
    let mut v = 0u32;
    for (k, &b) in t.iter().enumerate() {
        v = v << 4 | hex(b).ok_or_else(|| err(at + k, "expected a hex digit in the CAN id"))? as u32;
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(line: &str) -> (Frame, Interfaces) {
        let mut ifaces = Interfaces::default();
        match parse_line(line.as_bytes(), &mut ifaces) {
            Ok(Line::Frame(f)) => (f, ifaces),
            other => panic!("{line:?} gave {other:?}"),
        }
    }

    fn error(line: &str) -> ParseError {
        match parse_line(line.as_bytes(), &mut Interfaces::default()) {
            Err(e) => e,
            other => panic!("{line:?} gave {other:?}"),
        }
    }

    fn skip(line: &str) -> SkipReason {
        match parse_line(line.as_bytes(), &mut Interfaces::default()) {
            Ok(Line::Skip(r)) => r,
            other => panic!("{line:?} gave {other:?}"),
        }
    }

    #[test]
    fn classic_frame_with_six_digit_fraction() {
        let (f, ifaces) = frame("(1436509052.249713) vcan0 044#2A366C2BBA\n");
        assert_eq!(f.ts_ns, 1_436_509_052_249_713_000);
        assert_eq!(ifaces.name(f.iface), "vcan0");
        assert_eq!((f.id, f.len, f.flags), (0x044, 5, Flags::default()));
        assert_eq!(f.payload(), &[0x2A, 0x36, 0x6C, 0x2B, 0xBA]);
    }

    #[test]
    fn nine_digit_and_short_fractions() {
        assert_eq!(
            frame("(1436509052.249713123) can0 123#").0.ts_ns,
            1_436_509_052_249_713_123
        );
        assert_eq!(frame("(0.0) vcan0 001#8d00100100820100").0.ts_ns, 0);
        assert_eq!(frame("(12.5) can0 001#").0.ts_ns, 12_500_000_000);
        assert_eq!(frame("(000.001000) can0 001#").0.ts_ns, 1_000_000);
        assert_eq!(frame("(7) can0 001#").0.ts_ns, 7_000_000_000);
    }

    #[test]
    fn padded_interface_names_and_crlf() {
        let (f, ifaces) = frame("(1700000000.000001)   can0 123#11\r\n");
        assert_eq!(ifaces.name(f.iface), "can0");
        let (f, _) = frame("(1700000000.000001)\tcan0\t\t123#11  ");
        assert_eq!(f.payload(), &[0x11]);
    }

    #[test]
    fn remote_frames() {
        let (f, _) = frame("(1.000000) can0 123#R");
        assert!(f.is_rtr());
        assert_eq!((f.len, f.payload()), (0, &[][..]));
        assert_eq!(frame("(1.000000) can0 7A1#r").0.flags.0, Flags::RTR);
        assert_eq!(frame("(1.000000) can0 123#R7").0.len, 7);
        let (f, _) = frame("(1.000000) can0 123#R8_9");
        assert_eq!((f.len, f.raw_dlc), (8, 9));
        let (f, _) = frame("(1.000000) can0 12345678#R3");
        assert_eq!((f.id, f.len, f.flags.0), (0x1234_5678, 3, Flags::EXT | Flags::RTR));
    }

    #[test]
    fn raw_dlc_dots_and_extended_ids() {
        let (f, _) = frame("(1.000000) can0 123#1122334455667788_E");
        assert_eq!((f.len, f.raw_dlc), (8, 0xE));
        let (f, _) = frame("(1.000000) can0 123#11.2233.44");
        assert_eq!(f.payload(), &[0x11, 0x22, 0x33, 0x44]);
        let (f, _) = frame("(1.000000) can0 00000123#aa");
        assert_eq!((f.id, f.is_ext(), f.payload()), (0x123, true, &[0xAA][..]));
    }

    #[test]
    fn fd_frames_keep_flag_bits() {
        let (f, _) = frame("(1.000000) can0 123##5112233445566778899AABBCC");
        assert_eq!(f.flags.0, Flags::FD | Flags::BRS | Flags::FDF);
        assert_eq!(f.len, 12);
        assert_eq!(f.data[11], 0xCC);
        assert_eq!(frame("(1.000000) can0 123##0").0.flags.0, Flags::FD);
        assert_eq!(
            frame("(1.000000) can0 12345678##3AA").0.flags.0,
            Flags::FD | Flags::BRS | Flags::ESI | Flags::EXT
        );
        let long = format!("(1.000000) can0 123##4{}", "AB".repeat(64));
        assert_eq!(frame(&long).0.len, 64);
    }

    #[test]
    fn error_frames_and_direction() {
        let (f, _) = frame("(1.000000) can0 20000004#000C000000000000");
        assert_eq!((f.flags.0, f.id, f.len), (Flags::ERR, 4, 8));
        assert_eq!(f.data[1], 0x0C);
        let (f, _) = frame("(1.000000) can0 123#11 T");
        assert_eq!(f.flags.0, Flags::TX);
        let (f, _) = frame("(1.000000) can0 123#11 R");
        assert_eq!(f.flags.0, 0);
    }

    #[test]
    fn non_frame_lines_are_skipped_by_reason() {
        assert_eq!(skip(""), SkipReason::Blank);
        assert_eq!(skip("   \r\n"), SkipReason::Blank);
        assert_eq!(
            skip("DROPCOUNT: dropped 3 CAN frames on 'can0' socket (total drops 7)"),
            SkipReason::DropCount
        );
        assert_eq!(skip("# recorded on the test bench"), SkipReason::Comment);
        assert_eq!(skip("(1.000000) can0 45123#81:00:12345678#11223344"), SkipReason::CanXl);
    }

    #[test]
    fn malformed_lines_say_where_and_what() {
        let e = error("(1.000000 can0 123#11");
        assert_eq!((e.column, e.message), (10, "expected ')' after the timestamp"));
        assert_eq!(error("(1.000000) can0 1234#11").column, 17);
        assert_eq!(error("(1.000000) can0 12G#11").column, 19);
        let e = error("(1.000000) can0 123#112");
        assert_eq!((e.column, e.message), (24, "odd number of hex digits in the data"));
        assert_eq!(
            error("(1.000000) can0 123#112233445566778899").message,
            "more than 8 data bytes (CAN FD frames use '##')"
        );
        assert_eq!(
            error("(1.000000) can0 123#11_9").message,
            "a raw DLC '_<9..F>' is only allowed with length 8"
        );
        assert_eq!(error("(1.000000) can0 123#1122334455667788_5").column, 38);
        // Text after a blank is ignored as canplayer ignores it, and flagged; glued text is an error.
        let mut p = Parser::new();
        let mut ifaces = Interfaces::default();
        assert!(matches!(p.parse_line(b"(1.000000) can0 123#11 X", &mut ifaces), Ok(Line::Frame(f)) if f.len == 1));
        assert!(p.ignored_tail());
        assert!(
            matches!(p.parse_line(b"(1.000000) can0 123#11 T", &mut ifaces), Ok(Line::Frame(f)) if f.flags.has(Flags::TX))
        );
        assert!(!p.ignored_tail());
        assert_eq!(error("(1.000000) can0 123#11X").column, 23);
        assert_eq!(error("(1.000000) can0 800#11").message, "11-bit CAN id above 7FF");
        assert_eq!(
            error("(1.000000) can0").message,
            "expected an interface name and a frame"
        );
        assert_eq!(
            error("(1.000000) can0 123#R9").message,
            "remote frame length must be a digit 0..8"
        );
        assert_eq!(
            error("(99999999999999999999.0) can0 123#").message,
            "timestamp is too large"
        );
    }

    #[test]
    fn non_utf8_interface_is_an_error_not_a_panic() {
        let e = parse_line(b"(1.000000) c\xFFn0 123#11", &mut Interfaces::default()).unwrap_err();
        assert_eq!((e.column, e.message), (12, "interface name is not valid UTF-8"));
    }

    #[test]
    fn compact_frames_parse_alone() {
        let f = parse_compact(b"1ABCDEF0#R").unwrap().unwrap();
        assert_eq!((f.id, f.flags.0), (0x1ABC_DEF0, Flags::EXT | Flags::RTR));
        assert_eq!(parse_compact(b"45123#81:00:12345678#11").unwrap(), None);
    }
}
