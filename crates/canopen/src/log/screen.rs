//! candump's default screen output, so that a user can paste a terminal capture.
//!
//! Layout (can-utils `snprintf_long_canframe` in lib.c and the print branch of candump.c):
//! `" " [timestamp " "] " " iface ["  RX|TX B|- E|-"] "  " id "  " len "  " data`, e.g.
//! ```text
//!   can0  123   [3]  11 22 33
//!   can0  12345678   [0]  remote request
//!   can0  20000004   [8]  00 0C 00 00 00 00 00 00   ERRORFRAME
//!   can0  123  [12]  11 22 33 44 55 66 77 88 99 AA BB CC     (CAN FD: two-digit length)
//!   can0  321   {B}  11 22 33 44 55 66 77 88                 (-8: raw DLC)
//!  (1700000000.123456)  can0  123   [1]  11                   (-t a; -t d/z: (000.001000))
//!   can0  TX B -  123  [02]  11 22                            (-x)
//! ```
//! Blanks are any run of spaces or tabs (SFF indentation, padded names). The ASCII column
//! of `-a` (`'..'`) and the `ERRORFRAME` marker are read past; bytes are taken by count,
//! so the `E` of `ERRORFRAME` is never read as data. Date timestamps (`-t A`) are read as
//! UTC. CAN FD frames get [`Flags::FDF`] (current candump sets it on every FD frame) and
//! BRS/ESI from the `-x` columns when present. CAN XL lines (`[0003]`) are skipped; the
//! byte-swapped (`-S`) and binary (`-B`) views are reported as malformed.

mod fast;

use super::lex::{self, IfaceCache, Tokens, err, hex, hex_u32, skip_ws, trim_end};
use super::{Line, ParseError, SkipReason};
use crate::frame::{Flags, Frame, Interfaces};

/// The timestamp column of screen output, by candump's `-t` option.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Times {
    /// No timestamps.
    #[default]
    None,
    /// `-ta`: seconds since the Unix epoch.
    Absolute,
    /// `-tz`: seconds since the first frame.
    Zero,
    /// `-td`: seconds since the previous frame (summed up when read).
    Delta,
    /// `-tA`: date and time (read as UTC).
    Date,
}

impl Times {
    /// What the user is told was detected, e.g. `candump screen output, delta times (-td)`.
    pub fn label(self) -> &'static str {
        match self {
            Times::None => "candump screen output, no timestamps",
            Times::Absolute => "candump screen output, absolute times (-ta)",
            Times::Zero => "candump screen output, times since the start (-tz)",
            Times::Delta => "candump screen output, delta times (-td)",
            Times::Date => "candump screen output, date and time (-tA)",
        }
    }
}

/// Seconds from which a timestamp is taken for epoch time (`-ta`) rather than time since
/// the start (about three years).
const EPOCH_FROM_NS: u64 = 100_000_000 * 1_000_000_000;

/// The timestamp mode of the screen lines in `sample` (the start of the input): a date
/// means `-tA`; epoch-sized seconds `-ta`; small times that go back at least once `-td`
/// (deltas), else `-tz`.
pub(crate) fn detect_times(sample: &[u8]) -> Times {
    let mut last = None;
    let mut times = Times::None;
    for line in sample.split(|&b| b == b'\n').take(256) {
        let s = trim_end(line);
        let at = skip_ws(s, 0);
        if s.get(at) != Some(&b'(') {
            continue;
        }
        let Ok((ns, _)) = timestamp(s, at + 1) else {
            continue;
        };
        if s.get(at + 5) == Some(&b'-') {
            return Times::Date;
        }
        if ns >= EPOCH_FROM_NS {
            return Times::Absolute;
        }
        if last.is_some_and(|l| ns < l) {
            return Times::Delta;
        }
        last = Some(ns);
        times = Times::Zero;
    }
    times
}

/// Parser state for screen lines. Use one parser with one [`Interfaces`] table: it caches
/// an index into it.
#[derive(Debug, Default)]
pub struct Parser {
    iface: IfaceCache,
    delta: bool,
    sum_ns: u64,
    tail: bool,
}

impl Parser {
    /// A parser for absolute or zero-based timestamps.
    pub fn new() -> Self {
        Parser::default()
    }

    /// True when the last frame line had an annotation after the frame that was ignored.
    pub fn ignored_tail(&self) -> bool {
        self.tail
    }

    /// Treats timestamps as deltas to the previous frame (`-t d`) and sums them.
    pub fn set_delta(&mut self, on: bool) {
        self.delta = on;
    }

    /// Parses one line of screen output.
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        self.tail = false;
        if line.first() == Some(&b'\t') {
            return Ok(Line::Skip(SkipReason::ErrorDetail));
        }
        let s = trim_end(line);
        let mut toks = Tokens::new(s, 0);
        let Some((at, first)) = toks.peek() else {
            return Ok(Line::Skip(SkipReason::Blank));
        };
        if first.starts_with(b"DROPCOUNT") {
            return Ok(Line::Skip(SkipReason::DropCount));
        }
        // Comments, and the `...` / `…` that elide frames in pasted captures.
        let elision = s[at..].iter().all(|&b| b == b'.' || lex::is_ws(b)) || &s[at..] == "…".as_bytes();
        if first.starts_with(b"#") || first.starts_with(b"//") || elision {
            return Ok(Line::Skip(SkipReason::Comment));
        }
        let mut ts = 0;
        if first[0] == b'(' {
            let (t, end) = timestamp(s, at + 1)?;
            ts = t;
            toks = Tokens::new(s, end);
            if self.delta {
                self.sum_ns = self.sum_ns.saturating_add(ts);
                ts = self.sum_ns;
            }
        }
        let (name_at, name) = toks.next().ok_or_else(|| err(s.len(), "expected an interface name"))?;
        let mut f = Frame {
            ts_ns: ts,
            ..Frame::default()
        };
        let (mut id_at, mut id_tok) = toks.next().ok_or_else(|| err(s.len(), "expected a CAN id"))?;
        let mut extra = None;
        if id_tok == b"RX" || id_tok == b"TX" {
            if id_tok == b"TX" {
                f.flags.set(Flags::TX, true);
            }
            let (b_at, b) = toks
                .next()
                .ok_or_else(|| err(s.len(), "expected 'B' or '-' after RX/TX"))?;
            let (e_at, e) = toks
                .next()
                .ok_or_else(|| err(s.len(), "expected 'E' or '-' after RX/TX"))?;
            let brs = match b {
                b"B" | b"S" => true,
                b"-" => false,
                _ => return Err(err(b_at, "expected 'B' or '-' after RX/TX")),
            };
            let esi = match e {
                b"E" | b"R" => true,
                b"-" => false,
                _ => return Err(err(e_at, "expected 'E' or '-' after the B column")),
            };
            extra = Some((brs, esi));
            (id_at, id_tok) = toks.next().ok_or_else(|| err(s.len(), "expected a CAN id"))?;
        }
        let raw = match id_tok.len() {
            3 | 8 => hex_u32(id_tok).ok_or_else(|| err(id_at, "expected a CAN id of 3 or 8 hex digits"))?,
            _ => return Err(err(id_at, "expected a CAN id of 3 or 8 hex digits")),
        };
        if id_tok.len() == 3 {
            if raw > 0x7FF {
                return Err(err(id_at, "11-bit CAN id above 7FF"));
            }
            f.id = raw;
        } else if raw & 0xC000_0000 != 0 {
            return Err(err(id_at, "29-bit CAN id with bit 30 or 31 set"));
        } else if raw & crate::frame::linux::CAN_ERR_FLAG != 0 {
            f.flags.set(Flags::ERR, true);
            f.id = raw & 0x1FFF_FFFF;
        } else {
            f.flags.set(Flags::EXT, true);
            f.id = raw;
        }
        let (len_at, len_tok) = toks.next().ok_or_else(|| err(s.len(), "expected a length like [8]"))?;
        let max = match len_tok {
            [b'[', d, b']'] if d.is_ascii_digit() && *d <= b'8' => {
                f.len = d - b'0';
                8
            }
            [b'{', d, b'}'] => match hex(*d) {
                Some(v) if v > 8 => {
                    f.len = 8;
                    f.raw_dlc = v;
                    8
                }
                Some(v) => {
                    f.len = v;
                    8
                }
                None => return Err(err(len_at + 1, "expected a hex DLC in {}")),
            },
            [b'[', a, b, b']'] if a.is_ascii_digit() && b.is_ascii_digit() && (a - b'0') * 10 + (b - b'0') <= 64 => {
                f.len = (a - b'0') * 10 + (b - b'0');
                f.flags.set(Flags::FD, true);
                f.flags.set(Flags::FDF, true);
                64
            }
            [b'[', _, _, _, _, b']'] => return Ok(Line::Skip(SkipReason::CanXl)),
            _ => return Err(err(len_at, "expected a length like [8], [12] or {F}")),
        };
        if let Some((brs, esi)) = extra
            && max == 64
        {
            f.flags.set(Flags::BRS, brs);
            f.flags.set(Flags::ESI, esi);
        }
        if max == 8 && toks.peek().is_some_and(|(_, t)| t == b"remote") {
            toks.next();
            match toks.next() {
                Some((_, b"request")) => {}
                _ => return Err(err(toks.pos(), "expected 'remote request'")),
            }
            f.flags.set(Flags::RTR, true);
        } else {
            for k in 0..f.len as usize {
                let Some((b_at, b)) = toks.next() else {
                    return Err(err(s.len(), "fewer data bytes than the length says"));
                };
                f.data[k] = match b {
                    [h, l] => match (hex(*h), hex(*l)) {
                        (Some(h), Some(l)) => h << 4 | l,
                        _ => return Err(err(b_at, "expected a data byte of 2 hex digits")),
                    },
                    _ => return Err(err(b_at, "expected a data byte of 2 hex digits")),
                };
            }
        }
        if let Some((rest_at, rest)) = toks.peek() {
            // What may follow the bytes: candump -a's ASCII column (`'..'`, one character per
            // byte) or ERRORFRAME, then an annotation, ignored and flagged.
            let after = if rest == b"ERRORFRAME" && f.flags.has(Flags::ERR) {
                rest_at + rest.len()
            } else if rest[0] == b'\'' && s.get(rest_at + f.len as usize + 1) == Some(&b'\'') {
                rest_at + f.len as usize + 2
            } else {
                rest_at
            };
            let note_at = skip_ws(s, after);
            if note_at < s.len() {
                let note = &s[note_at..];
                // After the ASCII column (which proves the byte count) any text is an annotation
                // (`'........' < response`); right after the bytes only a marked comment is.
                let marked = note.starts_with(b"#") || note.starts_with(b"//");
                if (after == rest_at && !marked) || (note_at == after && after != rest_at) {
                    return Err(err(note_at, "unexpected text after the data bytes"));
                }
                self.tail = true;
            }
        }
        f.iface = self.iface.get(ifaces, name, name_at)?;
        Ok(Line::Frame(f))
    }
}

/// Parses the inside of `(…)` at `i`: `sec.frac` or `YYYY-MM-DD HH:MM:SS.frac` (as UTC).
/// Returns nanoseconds and the index after `)`.
fn timestamp(s: &[u8], i: usize) -> Result<(u64, usize), ParseError> {
    let (ns, end) = lex::timestamp(s, i)?;
    if s.get(end) == Some(&b')') {
        return Ok((ns, end + 1));
    }
    if s.get(end) != Some(&b'-') || end != i + 4 {
        return Err(err(end, "expected ')' after the timestamp"));
    }
    // `-t A`: 2023-11-14 22:13:20.123456
    let num = |from: usize, n: usize| -> Result<i64, ParseError> {
        let t = s
            .get(from..from + n)
            .ok_or_else(|| err(from, "incomplete date timestamp"))?;
        lex::dec_u32(t)
            .map(i64::from)
            .ok_or_else(|| err(from, "expected digits in the date timestamp"))
    };
    let sep = |at: usize, c: u8| -> Result<(), ParseError> {
        if s.get(at) == Some(&c) {
            Ok(())
        } else {
            Err(err(at, "malformed date timestamp"))
        }
    };
    let (y, mo, d) = (num(i, 4)?, num(i + 5, 2)?, num(i + 8, 2)?);
    sep(i + 4, b'-')?;
    sep(i + 7, b'-')?;
    sep(i + 10, b' ')?;
    let (h, mi) = (num(i + 11, 2)?, num(i + 14, 2)?);
    sep(i + 13, b':')?;
    sep(i + 16, b':')?;
    let (sec_frac, end) = lex::timestamp(s, i + 17)?;
    if s.get(end) != Some(&b')') {
        return Err(err(end, "expected ')' after the timestamp"));
    }
    if !(1..=12).contains(&mo) || !(1..=31).contains(&d) || h > 23 || mi > 59 || y < 1970 {
        return Err(err(i, "date timestamp out of range"));
    }
    let secs = (crate::calendar::days_from_civil(y, mo, d) * 86_400 + h * 3600 + mi * 60) as u64;
    let ns = secs
        .checked_mul(1_000_000_000)
        .and_then(|v| v.checked_add(sec_frac))
        .ok_or_else(|| err(i, "timestamp is too large"))?;
    Ok((ns, end + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(p: &mut Parser, line: &str) -> Result<Line, ParseError> {
        p.parse_line(line.as_bytes(), &mut Interfaces::default())
    }

    fn frame(line: &str) -> Frame {
        match parse(&mut Parser::new(), line) {
            Ok(Line::Frame(f)) => f,
            other => panic!("{line:?} gave {other:?}"),
        }
    }

    #[test]
    fn classic_extended_and_remote() {
        let f = frame("  can0  123   [3]  11 22 33");
        assert_eq!(
            (f.id, f.len, f.flags.0, f.payload()),
            (0x123, 3, 0, &[0x11, 0x22, 0x33][..])
        );
        let f = frame("  can0  12345678   [8]  01 02 03 04 05 06 07 08");
        assert_eq!((f.id, f.flags.0, f.data[7]), (0x1234_5678, Flags::EXT, 8));
        let f = frame("  vcan0  123   [0]  remote request");
        assert_eq!((f.flags.0, f.len), (Flags::RTR, 0));
        let f = frame("  can0       123   [4]  remote request");
        assert_eq!((f.id, f.flags.0, f.len), (0x123, Flags::RTR, 4));
    }

    #[test]
    fn error_frame_marker_is_not_data() {
        let f = frame("  can0  20000004   [8]  00 0C 00 00 00 00 00 00   ERRORFRAME");
        assert_eq!((f.id, f.flags.0, f.len, f.data[1]), (4, Flags::ERR, 8, 0x0C));
        let f = frame("  can0  20001111   [7]  C6 23 7B 32 69 98 3C      ERRORFRAME");
        assert_eq!((f.id, f.len), (0x1111, 7));
    }

    #[test]
    fn fd_raw_dlc_and_ascii_column() {
        let f = frame("  can0  123  [12]  11 22 33 44 55 66 77 88 99 AA BB CC");
        assert_eq!((f.len, f.flags.0, f.data[11]), (12, Flags::FD | Flags::FDF, 0xCC));
        let f = frame("  can0  321   {B}  11 22 33 44 55 66 77 88");
        assert_eq!((f.len, f.raw_dlc), (8, 0xB));
        let f = frame("  can0  123   [2]  41 20                  'A '");
        assert_eq!(f.payload(), b"A ");
    }

    #[test]
    fn timestamps_and_extra_info() {
        let f = frame(" (1700000000.123456)  can0  123   [1]  11");
        assert_eq!(f.ts_ns, 1_700_000_000_123_456_000);
        let f = frame(" (000.001000)  can0  123   [1]  11");
        assert_eq!(f.ts_ns, 1_000_000);
        let f = frame(" (2023-11-14 22:13:20.500000)  can0  123   [1]  11");
        assert_eq!(f.ts_ns, 1_700_000_000_500_000_000);
        let f = frame("  can0  TX - -  123   [1]  11");
        assert_eq!(f.flags.0, Flags::TX);
        let f = frame("  can0  RX B E  123  [02]  11 22");
        assert_eq!(f.flags.0, Flags::FD | Flags::FDF | Flags::BRS | Flags::ESI);
    }

    #[test]
    fn delta_timestamps_are_summed() {
        let mut p = Parser::new();
        p.set_delta(true);
        let _ = parse(&mut p, " (000.000000)  can0  123   [0]  ");
        let _ = parse(&mut p, " (000.250000)  can0  123   [0]  ");
        let Ok(Line::Frame(f)) = parse(&mut p, " (001.000000)  can0  123   [0]  ") else {
            panic!()
        };
        assert_eq!(f.ts_ns, 1_250_000_000);
    }

    #[test]
    fn timestamp_mode_is_detected_from_the_lines() {
        let t = |s: &str| detect_times(s.as_bytes());
        assert_eq!(t("  can0  123   [0]  \n"), Times::None);
        assert_eq!(t(" (1700000000.123456)  can0  123   [0]  \n"), Times::Absolute);
        assert_eq!(t(" (2023-11-14 22:13:20.500000)  can0  123   [0]  \n"), Times::Date);
        let zero =
            " (000.000000)  can0  123   [0]  \n (000.010000)  can0  123   [0]  \n (000.020000)  can0  123   [0]  \n";
        assert_eq!(t(zero), Times::Zero);
        let delta =
            " (000.000000)  can0  123   [0]  \n (000.010000)  can0  123   [0]  \n (000.000005)  can0  123   [0]  \n";
        assert_eq!(t(delta), Times::Delta);
        assert_eq!(t("# (x\n (000.5)  can0  123   [0]  \n"), Times::Zero);
    }

    #[test]
    fn skips_and_errors() {
        let mut p = Parser::new();
        assert_eq!(parse(&mut p, "   "), Ok(Line::Skip(SkipReason::Blank)));
        assert_eq!(
            parse(&mut p, "\terror-class = bus-error"),
            Ok(Line::Skip(SkipReason::ErrorDetail))
        );
        assert_eq!(
            parse(
                &mut p,
                "DROPCOUNT: dropped 1 CAN frame on 'can0' socket (total drops 1)"
            ),
            Ok(Line::Skip(SkipReason::DropCount))
        );
        assert_eq!(
            parse(&mut p, "  can0  123 [0003] (45|81:00:12345678) 11 22 33"),
            Ok(Line::Skip(SkipReason::CanXl))
        );
        let e = parse(&mut p, "  can0  123   [3]  11 22").unwrap_err();
        assert_eq!((e.column, e.message), (25, "fewer data bytes than the length says"));
        let e = parse(&mut p, "  can0  123   [2]  11 2G").unwrap_err();
        assert_eq!((e.column, e.message), (23, "expected a data byte of 2 hex digits"));
        let e = parse(&mut p, "  can0  123   [1]  11 22").unwrap_err();
        assert_eq!((e.column, e.message), (23, "unexpected text after the data bytes"));
        assert_eq!(parse(&mut p, "  can0  1234   [1]  11").unwrap_err().column, 9);
        assert_eq!(parse(&mut p, "  can0  123   [9]  11").unwrap_err().column, 15);
    }
}
