//! The lexing steps the fast line paths share (see [`super::fast`]): blanks, decimal
//! seconds, decimal and hex numbers, hex byte pairs and the line end, read straight from a
//! reader's buffer. Each step takes its bytes and moves on, or returns `None` (the bytes
//! have another shape, or the buffer ends first) and the fast path leaves the line to the
//! general parser.

use super::lex::{Channels, FRACTION_NS, HEX, IfaceCache};
use crate::frame::linux::CAN_ERR_FLAG;
use crate::frame::{Flags, Frame, Interfaces};

/// A read position in a buffer that holds a line (and maybe more after it).
#[derive(Clone, Copy, Debug)]
pub(super) struct Cursor<'a> {
    buf: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `buf`.
    #[inline(always)]
    pub(super) fn new(buf: &'a [u8]) -> Self {
        Cursor { buf, at: 0 }
    }

    /// The index of the next byte.
    #[inline(always)]
    pub(super) fn pos(&self) -> usize {
        self.at
    }

    /// The next byte.
    #[inline(always)]
    pub(super) fn peek(&self) -> Option<u8> {
        self.buf.get(self.at).copied()
    }

    /// The bytes from the cursor on.
    #[inline(always)]
    pub(super) fn rest(&self) -> &'a [u8] {
        &self.buf[self.at..]
    }

    /// Moves on `n` bytes (at most to the end).
    #[inline(always)]
    pub(super) fn advance(&mut self, n: usize) {
        self.at = (self.at + n).min(self.buf.len());
    }

    /// Takes byte `b`.
    #[inline(always)]
    pub(super) fn byte(&mut self, b: u8) -> Option<()> {
        (self.peek()? == b).then(|| self.at += 1)
    }

    /// Takes one or more spaces (a tab is another shape).
    #[inline(always)]
    pub(super) fn spaces(&mut self) -> Option<()> {
        self.byte(b' ')?;
        self.skip_spaces();
        Some(())
    }

    /// Takes any spaces.
    #[inline(always)]
    pub(super) fn skip_spaces(&mut self) {
        while self.buf.get(self.at) == Some(&b' ') {
            self.at += 1;
        }
    }

    /// Takes a word: one or more bytes above the space (no blank, no control byte).
    #[inline(always)]
    pub(super) fn word(&mut self) -> Option<&'a [u8]> {
        let w = self.take_while(|b| b > b' ');
        (!w.is_empty()).then_some(w)
    }

    /// Takes the bytes that `keep` holds to, up to the first it does not (or the end).
    #[inline(always)]
    pub(super) fn take_while(&mut self, keep: impl Fn(u8) -> bool) -> &'a [u8] {
        let from = self.at;
        while self.buf.get(self.at).is_some_and(|&b| keep(b)) {
            self.at += 1;
        }
        &self.buf[from..self.at]
    }

    /// Takes 1 to `max` decimal digits (`max` at most 19) not followed by another.
    #[inline(always)]
    pub(super) fn decimal(&mut self, max: usize) -> Option<u64> {
        let from = self.at;
        let mut v = 0u64;
        while let Some(d) = self.peek().filter(u8::is_ascii_digit) {
            if self.at - from == max {
                return None;
            }
            v = v * 10 + u64::from(d - b'0');
            self.at += 1;
        }
        (self.at > from).then_some(v)
    }

    /// Takes 1 to 19 decimal digits not followed by another (as [`Cursor::decimal`] with
    /// `max` 19), up to 16 of them eight at a time: a long integer time stamp.
    #[inline(always)]
    pub(super) fn long_decimal(&mut self) -> Option<u64> {
        let from = self.at;
        let mut v = 0u64;
        while self.at - from <= 8 {
            let Some(group) = self
                .buf
                .get(self.at..self.at + 8)
                .and_then(|t| digits8(t.try_into().ok()?))
            else {
                break;
            };
            v = v * 100_000_000 + group;
            self.at += 8;
        }
        while let Some(d) = self.peek().filter(u8::is_ascii_digit) {
            if self.at - from == 19 {
                return None;
            }
            // At most 19 digits: below 10^19 < u64::MAX.
            v = v * 10 + u64::from(d - b'0');
            self.at += 1;
        }
        (self.at > from).then_some(v)
    }

    /// Takes `secs.frac` as nanoseconds: 1 to 10 digits of seconds, 1 to 9 of fraction,
    /// and no digit after them. The 10.6-digit shape of epoch microseconds is read in
    /// digit groups.
    #[inline(always)]
    pub(super) fn seconds_ns(&mut self) -> Option<u64> {
        if let Some(ns) = self.epoch_micros() {
            return Some(ns);
        }
        let secs = self.decimal(10)?;
        self.byte(b'.')?;
        let from = self.at;
        let frac = self.decimal(9)?;
        // secs < 10^10: secs * 10^9 + frac < 10^19 < u64::MAX.
        Some(secs * 1_000_000_000 + frac * FRACTION_NS[self.at - from])
    }

    /// `secs.micros` with exactly 10 and 6 digits and no digit after them, as nanoseconds.
    #[inline(always)]
    fn epoch_micros(&mut self) -> Option<u64> {
        let t: &[u8; 18] = self.buf.get(self.at..self.at + 18)?.try_into().ok()?;
        if t[10] != b'.' || t[17].is_ascii_digit() {
            return None;
        }
        let secs = digits8(t[..8].try_into().ok()?)? * 100 + digit(t[8])? * 10 + digit(t[9])?;
        // Six fraction digits behind two `0`s make an 8-digit group.
        let mut frac = [b'0'; 8];
        frac[2..].copy_from_slice(&t[11..17]);
        let micros = digits8(&frac)?;
        self.at += 17;
        Some(secs * 1_000_000_000 + micros * 1000)
    }

    /// Takes 1 to `max` hex digits (`max` at most 8) not followed by another: the value
    /// and the number of digits.
    #[inline(always)]
    pub(super) fn hex(&mut self, max: usize) -> Option<(u32, usize)> {
        let from = self.at;
        let mut v = 0u32;
        while let Some(&b) = self.buf.get(self.at) {
            let h = HEX[b as usize];
            if h > 15 {
                break;
            }
            if self.at - from == max {
                return None;
            }
            v = v << 4 | u32::from(h);
            self.at += 1;
        }
        (self.at > from).then_some((v, self.at - from))
    }

    /// Takes a SocketCAN id as candump writes it: 3 hex digits (11-bit, at most 7FF) or 8
    /// (29-bit, or with `CAN_ERR_FLAG` an error frame's class), not followed by another;
    /// the id and its flags.
    #[inline(always)]
    pub(super) fn can_id(&mut self) -> Option<(u32, u8)> {
        let is_hex = |k: usize| self.buf.get(self.at + k).is_some_and(|&b| HEX[b as usize] <= 15);
        if !is_hex(3) {
            let raw = self.hex_digits::<3>()?;
            return (raw <= 0x7FF).then_some((raw, 0));
        }
        if is_hex(8) {
            return None;
        }
        let raw = self.hex_digits::<8>()?;
        match raw {
            _ if raw & 0xC000_0000 != 0 => None,
            _ if raw & CAN_ERR_FLAG != 0 => Some((raw & !CAN_ERR_FLAG, Flags::ERR)),
            _ => Some((raw, Flags::EXT)),
        }
    }

    /// Takes exactly `N` hex digits (whatever follows).
    #[inline(always)]
    fn hex_digits<const N: usize>(&mut self) -> Option<u32> {
        let t: &[u8; N] = self.buf.get(self.at..self.at + N)?.try_into().ok()?;
        let (mut v, mut bad) = (0u32, 0u8);
        for &b in t {
            let h = HEX[b as usize];
            bad |= h;
            v = v << 4 | u32::from(h & 15);
        }
        self.at += N;
        (bad <= 15).then_some(v)
    }

    /// Takes an interface name (a word), found by one 16-byte compare when it is `cache`'s
    /// last name (then it must be followed by a space).
    #[inline(always)]
    pub(super) fn iface_name(&mut self, cache: &IfaceCache) -> Option<Name<'a>> {
        let at = self.at;
        let cached = match cache.at_space(self.buf, at) {
            Some((idx, end)) => {
                self.at = end;
                Some(idx)
            }
            None => {
                self.word()?;
                None
            }
        };
        Some(Name {
            cached,
            text: &self.buf[at..self.at],
            at,
        })
    }

    /// Takes two hex digits as a byte.
    #[inline(always)]
    pub(super) fn hex_pair(&mut self) -> Option<u8> {
        let (hi, lo) = (*self.buf.get(self.at)?, *self.buf.get(self.at + 1)?);
        let (hi, lo) = (HEX[hi as usize], HEX[lo as usize]);
        if (hi | lo) > 15 {
            return None;
        }
        self.at += 2;
        Some(hi << 4 | lo)
    }

    /// Takes up to 8 hex byte pairs with nothing between them into `out`, and the line end
    /// right after them: how many, and the bytes taken so far (as [`Cursor::line_end`]).
    /// The pairs and the line end are looked for in the next 18 bytes at once: a line that
    /// ends closer to the end of the buffer gives `None`.
    #[inline(always)]
    pub(super) fn packed_bytes_line(&mut self, out: &mut [u8; 8]) -> Option<(usize, usize)> {
        let t: &[u8; 18] = self.buf.get(self.at..self.at + 18)?.try_into().ok()?;
        let mut n = 0;
        loop {
            let (c, d) = (t[2 * n], t[2 * n + 1]);
            if c == b'\n' {
                self.at += 2 * n + 1;
                return Some((n, self.at));
            }
            if c == b'\r' && d == b'\n' {
                self.at += 2 * n + 2;
                return Some((n, self.at));
            }
            let (hi, lo) = (HEX[c as usize], HEX[d as usize]);
            if n == 8 || (hi | lo) > 15 {
                return None;
            }
            out[n] = hi << 4 | lo;
            n += 1;
        }
    }

    /// Takes `out.len()` hex byte pairs, each after one or more spaces.
    #[inline(always)]
    pub(super) fn spaced_bytes(&mut self, out: &mut [u8]) -> Option<()> {
        for b in out {
            self.spaces()?;
            *b = self.hex_pair()?;
        }
        Some(())
    }

    /// The last step of a frame line whose data bytes are spaced hex pairs (ASC, TRC): takes
    /// `f.len` bytes into `f` and the line end or tail (as [`Cursor::line_end_or_tail`]), puts
    /// `f` on the interface of numbered channel `channel` at `ts_ns` and copies it to
    /// `frame`; returns the bytes taken, the line end included.
    #[inline(always)]
    pub(super) fn spaced_frame_end(
        &mut self,
        f: &mut Frame,
        (channels, channel): (&mut Channels, u32),
        ts_ns: u64,
        ifaces: &mut Interfaces,
        frame: &mut Frame,
    ) -> Option<usize> {
        let n = f.len as usize;
        self.spaced_bytes(&mut f.data[..n])?;
        let end = self.line_end_or_tail()?;
        f.iface = channels.get(ifaces, channel, 0).ok()?;
        f.ts_ns = ts_ns;
        *frame = *f;
        Some(end)
    }

    /// Takes the line end (`\n` or `\r\n`); returns the bytes taken so far, the line end
    /// included.
    #[inline(always)]
    pub(super) fn line_end(&mut self) -> Option<usize> {
        match self.peek()? {
            b'\n' => self.at += 1,
            b'\r' if self.buf.get(self.at + 1) == Some(&b'\n') => self.at += 2,
            _ => return None,
        }
        Some(self.at)
    }

    /// Takes the line end, or a blank and the rest of the line (text the general parser
    /// reads past); returns the bytes taken, as [`Cursor::line_end`].
    #[inline(always)]
    pub(super) fn line_end_or_tail(&mut self) -> Option<usize> {
        if let Some(n) = self.line_end() {
            return Some(n);
        }
        if !matches!(self.peek()?, b' ' | b'\t') {
            return None;
        }
        self.rest_of_line()
    }

    /// Takes the rest of the line, its `\n` included; returns the bytes taken, as
    /// [`Cursor::line_end`] (`None` when the buffer holds no line end).
    #[inline(always)]
    pub(super) fn rest_of_line(&mut self) -> Option<usize> {
        self.at += memchr::memchr(b'\n', self.rest())? + 1;
        Some(self.at)
    }
}

/// An interface name taken by [`Cursor::iface_name`], interned by [`Name::index`] once
/// the whole line has been read (as the general parsers intern it last).
pub(super) struct Name<'a> {
    cached: Option<u16>,
    text: &'a [u8],
    at: usize,
}

impl Name<'_> {
    /// The interface's index, interned in `ifaces` on first sight.
    #[inline(always)]
    pub(super) fn index(&self, cache: &mut IfaceCache, ifaces: &mut Interfaces) -> Option<u16> {
        match self.cached {
            Some(idx) => Some(idx),
            None => cache.get(ifaces, self.text, self.at).ok(),
        }
    }
}

/// Value of one decimal digit.
#[inline(always)]
fn digit(b: u8) -> Option<u64> {
    b.is_ascii_digit().then(|| u64::from(b - b'0'))
}

/// Value of 8 decimal digits (most significant first), combined in pairs, quads and halves.
#[inline(always)]
fn digits8(b: &[u8; 8]) -> Option<u64> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let v = u64::from_le_bytes(*b);
    // Every byte 0x30..=0x39: high nibble 3, and still 3 after adding 6.
    if v & (0xF0 * ONES) != 0x30 * ONES || v.wrapping_add(6 * ONES) & (0xF0 * ONES) != 0x30 * ONES {
        return None;
    }
    let mut x = v - 0x30 * ONES;
    x = (x.wrapping_mul(10) + (x >> 8)) & 0x00FF_00FF_00FF_00FF;
    x = (x.wrapping_mul(100) + (x >> 16)) & 0x0000_FFFF_0000_FFFF;
    x = (x.wrapping_mul(10_000) + (x >> 32)) & 0xFFFF_FFFF;
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digit_groups() {
        assert_eq!(digits8(b"12345678"), Some(12_345_678));
        assert_eq!(digits8(b"00000000"), Some(0));
        assert_eq!(digits8(b"99999999"), Some(99_999_999));
        for bad in [b"1234567:", b"/2345678", b"1234 678", b"\xF9234567A"] {
            assert_eq!(digits8(bad), None);
        }
    }

    #[test]
    fn seconds_in_either_shape_and_nothing_wider() {
        let ns = |t: &[u8]| {
            let mut c = Cursor::new(t);
            c.seconds_ns().map(|v| (v, c.pos()))
        };
        assert_eq!(ns(b"1700000000.000100) "), Some((1_700_000_000_000_100_000, 17)));
        assert_eq!(ns(b"1700000000.000100"), Some((1_700_000_000_000_100_000, 17)));
        assert_eq!(ns(b"0.5 "), Some((500_000_000, 3)));
        assert_eq!(ns(b"9999999999.999999999 "), Some((9_999_999_999_999_999_999, 20)));
        for bad in [&b"12345678901.0 "[..], b"1.0000000001 ", b"1. ", b".5 ", b"1 "] {
            assert_eq!(ns(bad), None, "{:?}", String::from_utf8_lossy(bad));
        }
    }

    #[test]
    fn long_decimals_in_groups_and_digits() {
        for (text, want) in [
            ("0,", Some(0)),
            ("12345678,", Some(12_345_678)),
            ("1700000000000100,", Some(1_700_000_000_000_100)),
            ("9999999999999999999,", Some(9_999_999_999_999_999_999)),
            ("10000000000000000000,", None),
            ("123456789012345678901234,", None),
            (",", None),
        ] {
            let mut c = Cursor::new(text.as_bytes());
            let got = c.long_decimal();
            assert_eq!(got, want, "{text}");
            let mut d = Cursor::new(text.as_bytes());
            assert_eq!(got, d.decimal(19), "{text}: as decimal(19)");
            if got.is_some() {
                assert_eq!((c.pos(), c.peek()), (text.len() - 1, Some(b',')));
            }
        }
    }

    #[test]
    fn hex_and_line_ends() {
        let mut c = Cursor::new(b"1aF#");
        assert_eq!(c.hex(8), Some((0x1AF, 3)));
        assert_eq!(Cursor::new(b"123456789").hex(8), None);
        assert_eq!(Cursor::new(b"#").hex(8), None);
        assert_eq!(Cursor::new(b"7FF#").can_id(), Some((0x7FF, 0)));
        assert_eq!(Cursor::new(b"800#").can_id(), None);
        assert_eq!(Cursor::new(b"1234#").can_id(), None);
        assert_eq!(Cursor::new(b"12345678#").can_id(), Some((0x1234_5678, Flags::EXT)));
        assert_eq!(Cursor::new(b"20000004 ").can_id(), Some((4, Flags::ERR)));
        assert_eq!(Cursor::new(b"123456789#").can_id(), None);
        let mut out = [0; 8];
        assert_eq!(
            Cursor::new(b"1122\r\n..............").packed_bytes_line(&mut out),
            Some((2, 6))
        );
        assert_eq!(Cursor::new(b"112\n...............").packed_bytes_line(&mut out), None);
        assert_eq!(Cursor::new(b"\r\n").line_end(), Some(2));
        assert_eq!(Cursor::new(b"\r").line_end(), None);
        assert_eq!(Cursor::new(b" Length = 1\nx").line_end_or_tail(), Some(12));
        assert_eq!(Cursor::new(b"x\n").line_end_or_tail(), None);
    }
}
