//! Vector ASC logs, as Vector tools and can-utils' `log2asc` write them.
//!
//! ```text
//! date Tue Nov 14 22:13:20 2023
//! base hex  timestamps absolute
//! no internal events logged
//! Begin Triggerblock Tue Nov 14 22:13:20 2023
//!    0.000000 Start of measurement
//!    0.001000 1  123             Rx   d 3 11 22 33
//!    0.002000 2  1ABCDEFx        Tx   d 8 01 02 03 04 05 06 07 08  Length = 0 BitCount = 0
//!    0.003000 1  7FF             Rx   r 8
//!    0.004000 1  ErrorFrame
//!    0.005000 CANFD   1 Rx        123  msgName  1 0 9 12 11 22 ... 130000  130  3000 0 0 0 0 0
//! End TriggerBlock
//! ```
//! Lines are split on any run of blanks. Choices, all as can-utils' `asc2log` makes them:
//! - channel N is interface `can{N-1}` (channel 1 is `can0`); channel 0 is `canX`;
//! - times are seconds since the start of the measurement, which the `date` line names,
//!   or the date of the `Begin Triggerblock` line that follows it (as python-can's
//!   `ASCReader` takes them; dates as UTC, see `asc_date.rs`): with a readable date frames
//!   carry absolute times (ns since 1970), without one the times as written; with
//!   `timestamps relative` each timed line's time (events too) is added to the last;
//! - `base dec` reads ids and data bytes as decimal (the DLC stays hex);
//! - `ErrorFrame` has no detail in ASC, so it becomes a generic bus error: an error frame
//!   with class `CAN_ERR_BUSERROR` (0x80) and 8 zero bytes;
//! - a status line (`CAN 1 Status:chip status error passive - TxErr: 132 RxErr: 0`) becomes
//!   the error frame a SocketCAN controller sends for the same state: bus off as
//!   `CAN_ERR_BUSOFF`, error passive / warning level / error active as `CAN_ERR_CRTL` with
//!   the TX or RX bit of the larger counter, and the counters (`CAN_ERR_CNT`) when given;
//! - a `CANFD` line is an FD frame (with [`Flags::FDF`]) when its flags column has bit
//!   0x1000 or is missing, else a classic frame (remote when bit 0x10 is set);
//! - `Rx`/`Tx` set the direction; `TxRq`, `Start of measurement` and other events are
//!   skipped as [`SkipReason::Event`], `CANXL` lines as [`SkipReason::CanXl`], lines not
//!   starting with a timestamp as [`SkipReason::Header`] or [`SkipReason::Comment`] (`//`).

mod fast;

use super::lex::{self, Channels, Tokens, dec_u32, err, hex_u32, trim_end};
use super::status::{self, State};
use super::{Line, ParseError, SkipReason};
use crate::frame::{Flags, Frame, Interfaces};

/// `CAN_ERR_BUSERROR`: the class given to ASC error frames.
pub const CAN_ERR_BUSERROR: u32 = status::CAN_ERR_BUSERROR;

const ASC_F_RTR: u32 = 0x10;
const ASC_F_FDF: u32 = 0x1000;

/// Parser state for ASC lines (number base, timestamp mode, channel names). Use one parser
/// with one [`Interfaces`] table: it caches indexes into it.
#[derive(Debug, Default)]
pub struct Parser {
    decimal: bool,
    relative: bool,
    last_ns: u64,
    start_ns: u64,
    channels: Channels,
}

impl Parser {
    /// A parser in the defaults of an ASC file: hex, absolute timestamps.
    pub fn new() -> Self {
        Parser::default()
    }

    /// Parses one ASC line.
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        let s = trim_end(line);
        let mut toks = Tokens::new(s, 0);
        let Some((at, first)) = toks.next() else {
            return Ok(Line::Skip(SkipReason::Blank));
        };
        if first.starts_with(b"//") {
            return Ok(Line::Skip(SkipReason::Comment));
        }
        if !first[0].is_ascii_digit() {
            if first == b"base" {
                self.base_line(&mut toks);
            } else if first == b"date" {
                self.start_ns = super::asc_date::parse(&mut toks).unwrap_or(0);
            } else if first == b"Begin"
                && toks
                    .next()
                    .is_some_and(|(_, t)| t.eq_ignore_ascii_case(b"Triggerblock"))
                && let Some(start) = super::asc_date::parse(&mut toks)
            {
                self.start_ns = start;
            }
            return Ok(Line::Skip(SkipReason::Header));
        }
        let (mut ts, end) = lex::timestamp(s, at)?;
        if end != at + first.len() {
            return Err(err(end, "expected a timestamp like 1.000000"));
        }
        if self.relative {
            ts = self.last_ns.saturating_add(ts);
            self.last_ns = ts;
        }
        let ts = self.start_ns.saturating_add(ts);
        let (ch_at, ch_tok) = toks
            .next()
            .ok_or_else(|| err(s.len(), "expected a channel or event after the time"))?;
        let mut f = match ch_tok {
            b"CANFD" => {
                let (ch_at, ch) = toks
                    .next()
                    .ok_or_else(|| err(s.len(), "expected a channel after CANFD"))?;
                let channel = dec_u32(ch).ok_or_else(|| err(ch_at, "expected a channel number"))?;
                let Some(mut f) = self.fd_line(&mut toks, s.len())? else {
                    return Ok(Line::Skip(SkipReason::Event));
                };
                f.iface = self.channels.get(ifaces, channel, ch_at)?;
                f
            }
            b"CANXL" => return Ok(Line::Skip(SkipReason::CanXl)),
            b"CAN" => {
                let (ch_at, ch) = toks
                    .next()
                    .ok_or_else(|| err(s.len(), "expected a channel after CAN"))?;
                let channel = dec_u32(ch).ok_or_else(|| err(ch_at, "expected a channel number"))?;
                let Some(mut f) = status_line(&s[toks.pos()..]) else {
                    return Ok(Line::Skip(SkipReason::Event));
                };
                f.iface = self.channels.get(ifaces, channel, ch_at)?;
                f
            }
            _ => match dec_u32(ch_tok) {
                Some(channel) => {
                    let Some(mut f) = self.classic_line(&mut toks, s.len())? else {
                        return Ok(Line::Skip(SkipReason::Event));
                    };
                    f.iface = self.channels.get(ifaces, channel, ch_at)?;
                    f
                }
                None => return Ok(Line::Skip(SkipReason::Event)),
            },
        };
        f.ts_ns = ts;
        Ok(Line::Frame(f))
    }

    /// `base hex|dec  timestamps absolute|relative`.
    fn base_line(&mut self, toks: &mut Tokens<'_>) {
        for (_, t) in toks {
            match t {
                b"dec" => self.decimal = true,
                b"hex" => self.decimal = false,
                b"relative" => self.relative = true,
                b"absolute" => self.relative = false,
                _ => {}
            }
        }
    }
}

/// Parses an id token (`123`, `1ABx`), decimal or hex, into `f`.
fn parse_id(decimal: bool, f: &mut Frame, at: usize, tok: &[u8]) -> Result<(), ParseError> {
    let (digits, ext) = match tok.split_last() {
        Some((b'x' | b'X', rest)) => (rest, true),
        _ => (tok, false),
    };
    let id = if decimal { dec_u32(digits) } else { hex_u32(digits) }.ok_or_else(|| err(at, "expected a CAN id"))?;
    if id > if ext { 0x1FFF_FFFF } else { 0x7FF } {
        return Err(err(at, "CAN id out of range (29-bit ids end in 'x')"));
    }
    f.id = id;
    f.flags.set(Flags::EXT, ext);
    Ok(())
}

/// A data byte, decimal or hex.
fn byte(decimal: bool, at: usize, tok: &[u8]) -> Result<u8, ParseError> {
    let v = if decimal { dec_u32(tok) } else { hex_u32(tok) };
    match v {
        Some(v) if v <= 0xFF && tok.len() <= 3 => Ok(v as u8),
        _ => Err(err(at, "expected a data byte")),
    }
}

impl Parser {
    /// `<id> <Rx|Tx> <d|r> <dlc> <bytes…>` or `ErrorFrame`; `None` for events.
    fn classic_line(&self, toks: &mut Tokens<'_>, end: usize) -> Result<Option<Frame>, ParseError> {
        let mut f = Frame::default();
        let (id_at, id) = toks.next().ok_or_else(|| err(end, "expected a CAN id"))?;
        if id == b"ErrorFrame" {
            return Ok(Some(status::bus_error()));
        }
        if !id[0].is_ascii_hexdigit() {
            return Ok(None);
        }
        parse_id(self.decimal, &mut f, id_at, id)?;
        if !direction(&mut f, toks, end)? {
            return Ok(None);
        }
        let (kind_at, kind) = toks.next().ok_or_else(|| err(end, "expected 'd' or 'r'"))?;
        let remote = match kind {
            b"d" => false,
            b"r" => true,
            _ => return Err(err(kind_at, "expected 'd' (data) or 'r' (remote)")),
        };
        let dlc = match toks.peek() {
            Some((dlc_at, t)) if t.len() == 1 || !remote => {
                toks.next();
                match hex_u32(t) {
                    Some(v) if v <= 15 => v as u8,
                    _ if remote => return Ok(Some(remote_frame(f, 0))),
                    _ => return Err(err(dlc_at, "expected a DLC 0..F")),
                }
            }
            _ => 0,
        };
        if remote {
            return Ok(Some(remote_frame(f, dlc)));
        }
        f.len = dlc.min(8);
        if dlc > 8 {
            f.raw_dlc = dlc;
        }
        for k in 0..f.len as usize {
            let (b_at, b) = toks
                .next()
                .ok_or_else(|| err(end, "fewer data bytes than the DLC says"))?;
            f.data[k] = byte(self.decimal, b_at, b)?;
        }
        Ok(Some(f))
    }

    /// `<dir> <id> [name] <brs> <esi> <dlc> <len> <bytes…> <dur> <bits> <flags> …`.
    fn fd_line(&self, toks: &mut Tokens<'_>, end: usize) -> Result<Option<Frame>, ParseError> {
        let mut f = Frame::default();
        if !direction(&mut f, toks, end)? {
            return Ok(None);
        }
        let (id_at, id) = toks.next().ok_or_else(|| err(end, "expected a CAN id"))?;
        // CANFD lines are hex whatever the base line says (as asc2log reads them).
        parse_id(false, &mut f, id_at, id)?;
        let bit = |t: &[u8]| matches!(t, b"0" | b"1");
        if toks.peek().is_some_and(|(_, t)| !bit(t)) {
            toks.next(); // symbolic name
        }
        let mut next = |what: &'static str| toks.next().ok_or_else(|| err(end, what));
        let (brs_at, brs) = next("expected the BRS column")?;
        let (esi_at, esi) = next("expected the ESI column")?;
        if !bit(brs) {
            return Err(err(brs_at, "BRS must be 0 or 1"));
        }
        if !bit(esi) {
            return Err(err(esi_at, "ESI must be 0 or 1"));
        }
        let (dlc_at, dlc) = next("expected a DLC")?;
        let dlc = hex_u32(dlc)
            .filter(|&d| d <= 15)
            .ok_or_else(|| err(dlc_at, "expected a DLC 0..f"))? as u8;
        let (len_at, len) = next("expected a data length")?;
        let len = dec_u32(len)
            .filter(|&l| l <= 8 || matches!(l, 12 | 16 | 20 | 24 | 32 | 48 | 64))
            .ok_or_else(|| err(len_at, "expected a data length 0..8, 12, 16, 20, 24, 32, 48 or 64"))?
            as usize;
        for k in 0..len {
            let (b_at, b) = toks
                .next()
                .ok_or_else(|| err(end, "fewer data bytes than the length says"))?;
            f.data[k] = byte(false, b_at, b)?;
        }
        let flags = match (toks.next(), toks.next(), toks.next()) {
            (Some(_), Some(_), Some((fl_at, fl))) => {
                hex_u32(fl).ok_or_else(|| err(fl_at, "expected the flags in hex"))?
            }
            _ => ASC_F_FDF,
        };
        if flags & ASC_F_FDF != 0 {
            f.flags.set(Flags::FD | Flags::FDF, true);
            f.flags.set(Flags::BRS, brs == b"1");
            f.flags.set(Flags::ESI, esi == b"1");
            f.len = len as u8;
        } else if flags & ASC_F_RTR != 0 {
            f = remote_frame(f, dlc);
        } else {
            if len > 8 {
                return Err(err(len_at, "classic frame with more than 8 data bytes"));
            }
            f.len = len as u8;
            if len == 8 && dlc > 8 {
                f.raw_dlc = dlc;
            }
        }
        Ok(Some(f))
    }
}

/// The error frame of a status line's text after the channel (`Status:chip status error
/// passive - TxErr: 132 RxErr: 0`); `None` when it is no controller state.
fn status_line(rest: &[u8]) -> Option<Frame> {
    let text = lex::skip_ws(rest, 0);
    let rest = rest[text..].strip_prefix(b"Status:")?;
    let has = |word: &[u8]| rest.windows(word.len()).any(|w| w.eq_ignore_ascii_case(word));
    let counter = |name: &[u8]| {
        let at = rest.windows(name.len()).position(|w| w == name)? + name.len();
        let at = lex::skip_ws(rest, at);
        dec_u32(&rest[at..lex::token_end(rest, at)])
    };
    let state = if has(b"bus off") || has(b"busoff") {
        State::BusOff
    } else if has(b"passive") {
        State::Passive
    } else if has(b"warning") {
        State::Warning
    } else if has(b"active") {
        State::Active
    } else {
        return None;
    };
    let counters = counter(b"TxErr:").zip(counter(b"RxErr:"));
    Some(status::state_frame(state, counters))
}

/// Reads `Rx`/`Tx` into the TX flag; `false` for other directions (`TxRq`).
fn direction(f: &mut Frame, toks: &mut Tokens<'_>, end: usize) -> Result<bool, ParseError> {
    let (_, dir) = toks.next().ok_or_else(|| err(end, "expected Rx or Tx"))?;
    match dir {
        b"Rx" => Ok(true),
        b"Tx" => {
            f.flags.set(Flags::TX, true);
            Ok(true)
        }
        _ => Ok(false),
    }
}

/// `f` as a remote frame with DLC `dlc` (length capped at 8, raw DLC kept).
fn remote_frame(mut f: Frame, dlc: u8) -> Frame {
    f.flags.set(Flags::RTR, true);
    f.len = dlc.min(8);
    if dlc > 8 {
        f.raw_dlc = dlc;
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_all(text: &str) -> (Vec<Result<Line, ParseError>>, Interfaces) {
        let mut p = Parser::new();
        let mut ifaces = Interfaces::default();
        let out = text.lines().map(|l| p.parse_line(l.as_bytes(), &mut ifaces)).collect();
        (out, ifaces)
    }

    fn frames(text: &str) -> (Vec<Frame>, Interfaces) {
        let (lines, ifaces) = parse_all(text);
        let fs = lines
            .into_iter()
            .filter_map(|l| match l {
                Ok(Line::Frame(f)) => Some(f),
                Ok(Line::Skip(_)) => None,
                Err(e) => panic!("{e}"),
            })
            .collect();
        (fs, ifaces)
    }

    #[test]
    fn header_lines_are_skipped_and_base_is_read() {
        let (lines, _) = parse_all(
            "date Tue Nov 14 22:13:20 2023\nbase hex  timestamps absolute\nno internal events logged\n// version 18.2.0\nBegin Triggerblock Tue Nov 14 22:13:20 2023\n   0.000000 Start of measurement\nEnd TriggerBlock\n",
        );
        let reasons: Vec<_> = lines.into_iter().map(Result::unwrap).collect();
        use SkipReason::*;
        let want = [Header, Header, Header, Comment, Header, Event, Header];
        assert_eq!(reasons, want.map(Line::Skip));
    }

    #[test]
    fn classic_lines() {
        let (fs, ifaces) = frames(
            "   0.001000 1  123             Rx   d 3 11 22 33\n   0.002500 2  1ABCDEFx        Tx   d 8 01 02 03 04 05 06 07 08  Length = 0 BitCount = 0 ID = 1\n   0.003000 1  7FF             Rx   r 8\n   0.004000 1  12              Rx   r\n   0.005000 1  ErrorFrame\n   0.006000 1  100             Rx   d F 01 02 03 04 05 06 07 08\n",
        );
        assert_eq!(fs.len(), 6);
        assert_eq!(
            (fs[0].ts_ns, fs[0].id, fs[0].payload()),
            (1_000_000, 0x123, &[0x11, 0x22, 0x33][..])
        );
        assert_eq!(ifaces.name(fs[0].iface), "can0");
        assert_eq!(
            (fs[1].id, fs[1].flags.0, fs[1].data[7]),
            (0x1AB_CDEF, Flags::EXT | Flags::TX, 8)
        );
        assert_eq!(ifaces.name(fs[1].iface), "can1");
        assert_eq!((fs[2].flags.0, fs[2].len), (Flags::RTR, 8));
        assert_eq!((fs[3].id, fs[3].flags.0, fs[3].len), (0x12, Flags::RTR, 0));
        assert_eq!(
            (fs[4].flags.0, fs[4].id, fs[4].len, fs[4].payload()),
            (Flags::ERR, 0x80, 8, &[0u8; 8][..])
        );
        assert_eq!((fs[5].len, fs[5].raw_dlc), (8, 15));
    }

    #[test]
    fn fd_lines_with_and_without_symbolic_name() {
        let (fs, _) = frames(
            "   0.176544 CANFD   1 Rx        123                                   1 0 9 12 11 22 33 44 55 66 77 88 99 AA BB CC   130000  130     3000 0 0 0 0 0\n  21.671796 CANFD   1 Tx         11  msgCanFdFr1                      0 1 a 16 00 00 00 00 00 00 00 00 00 00 00 00 00 00 59 c0 100000  214   223040 80000000 46500250\n   1.000000 CANFD   2 Rx   1234x  0 0 8 8 01 02 03 04 05 06 07 08 130000 130 0 0\n   2.000000 CANFD   2 Rx   1234x  0 0 d 0 130000 130 10 0\n",
        );
        assert_eq!(
            (fs[0].flags.0, fs[0].len, fs[0].data[11]),
            (Flags::FD | Flags::FDF | Flags::BRS, 12, 0xCC)
        );
        assert_eq!(
            (fs[1].id, fs[1].flags.0, fs[1].len, fs[1].data[15]),
            (0x11, Flags::FD | Flags::FDF | Flags::ESI | Flags::TX, 16, 0xC0)
        );
        assert_eq!((fs[2].flags.0, fs[2].len), (Flags::EXT, 8));
        assert_eq!(
            (fs[3].flags.0, fs[3].len, fs[3].raw_dlc),
            (Flags::EXT | Flags::RTR, 8, 0xD)
        );
    }

    #[test]
    fn decimal_base_and_relative_timestamps() {
        let (fs, _) = frames(
            "base dec  timestamps relative\n   0.500000 1  291             Rx   d 2 17 255\n   0.250000 1  2047            Rx   d 0\n",
        );
        assert_eq!((fs[0].id, fs[0].payload()), (0x123, &[17, 255][..]));
        assert_eq!((fs[1].id, fs[1].ts_ns), (0x7FF, 750_000_000));
    }

    #[test]
    fn the_date_line_makes_times_absolute_and_relative_times_sum_over_events() {
        let (fs, _) = frames(
            "date Tue Nov 14 10:13:20.000 pm 2023\nbase hex  timestamps relative\n   0.500000 1  123  Rx   d 0\n   0.100000 Start of measurement\n   0.250000 1  124  Rx   d 0\n",
        );
        let t0 = 1_700_000_000_000_000_000;
        assert_eq!((fs[0].ts_ns - t0, fs[1].ts_ns - t0), (500_000_000, 850_000_000));
        // A trigger block's date is the base of the times after it.
        let (fs, _) = frames(
            "date Wed Dec 02 15:21:53.870 2026\nBegin Triggerblock Tue Nov 14 22:13:20.0 2023\n   0.000100 1  123  Rx   d 0\n",
        );
        assert_eq!(fs[0].ts_ns, t0 + 100_000);
        // An unreadable date leaves the times as written.
        let (fs, _) = frames("date someday\n   1.500000 1  123  Rx   d 0\n");
        assert_eq!(fs[0].ts_ns, 1_500_000_000);
    }

    #[test]
    fn status_lines_are_controller_error_frames() {
        let (fs, ifaces) = frames(
            "   0.015991 CAN 1 Status:chip status error passive - TxErr: 132 RxErr: 0\n   0.015991 CAN 2 Status:chip status error active\n   1.0 CAN 1 Status:chip status warning level - TxErr: 3 RxErr: 97\n   2.0 CAN 1 Status:chip status bus off - TxErr: 300 RxErr: 0\n",
        );
        let got: Vec<_> = fs
            .iter()
            .map(|f| (ifaces.name(f.iface), f.flags.0, f.id, f.payload()))
            .collect();
        assert_eq!(
            got,
            [
                ("can0", Flags::ERR, 0x204, &[0, 0x20, 0, 0, 0, 0, 132, 0][..]),
                ("can1", Flags::ERR, 0x004, &[0, 0x40, 0, 0, 0, 0, 0, 0][..]),
                ("can0", Flags::ERR, 0x204, &[0, 0x04, 0, 0, 0, 0, 3, 97][..]),
                ("can0", Flags::ERR, 0x240, &[0, 0, 0, 0, 0, 0, 255, 0][..]),
            ]
        );
        let (lines, _) = parse_all("   1.0 CAN 1 Status:chip status something else\n   1.0 CAN x Status:\n");
        assert_eq!(lines[0], Ok(Line::Skip(SkipReason::Event)));
        assert_eq!(lines[1].unwrap_err().message, "expected a channel number");
    }

    #[test]
    fn events_and_errors() {
        let (lines, _) = parse_all(
            "   0.1 1  123  TxRq d 1 11\n   0.1 CANXL   2 Rx   XLFF   984438\n   0.1 1  123  Rx   d 2 11\n   0.1 1  123  Rx   q 2 11\n   0.1 1  800  Rx   d 0\n   0.1 1  123  Rx   d 1 1FF\n   0.1 CANFD 1 Rx 123 0 0 9  9 00 01 02 03 04 05 06 07 08\n",
        );
        assert_eq!(lines[0], Ok(Line::Skip(SkipReason::Event)));
        assert_eq!(lines[1], Ok(Line::Skip(SkipReason::CanXl)));
        assert_eq!(
            lines[2],
            Err(ParseError {
                column: 27,
                message: "fewer data bytes than the DLC says"
            })
        );
        assert_eq!(
            lines[3],
            Err(ParseError {
                column: 21,
                message: "expected 'd' (data) or 'r' (remote)"
            })
        );
        assert_eq!(lines[4].unwrap_err().column, 11);
        assert_eq!(lines[5].unwrap_err().message, "expected a data byte");
        assert_eq!(lines[6].unwrap_err().column, 30);
    }
}
