//! python-can CSV logs (`can.CSVWriter`):
//!
//! ```text
//! timestamp,arbitration_id,extended,remote,error,dlc,data
//! 1700000000.123456,0x181,0,0,0,2,ESI=
//! 1700000000.2,0x1abcdef,1,1,0,8,
//! ```
//! The timestamp is a Python float (`repr`: `0.0`, `1e-05` too), the id is hex, the data
//! base64. The file names no interface: frames are on `can0`. More than 8 data bytes make a
//! CAN FD frame (python-can keeps no FD flag in CSV); with `error` set the id is the
//! SocketCAN error class.

mod fast;

use super::lex::{IfaceCache, dec_u32, err, hex_u32, trim_end};
use super::{Line, ParseError, SkipReason};
use crate::frame::{Flags, Frame, Interfaces};

/// The header line python-can writes.
pub(crate) const HEADER: &[u8] = b"timestamp,arbitration_id,extended,remote,error,dlc,data";

/// Parser state for CSV lines. Use one parser with one [`Interfaces`] table: it caches an
/// index into it.
#[derive(Debug, Default)]
pub struct Parser {
    iface: IfaceCache,
}

impl Parser {
    /// A parser.
    pub fn new() -> Self {
        Parser::default()
    }

    /// Parses one CSV line.
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        let s = trim_end(line);
        if s.is_empty() {
            return Ok(Line::Skip(SkipReason::Blank));
        }
        if s == HEADER {
            return Ok(Line::Skip(SkipReason::Header));
        }
        let mut fields = [(0usize, &s[..0]); 7];
        let mut n = 0;
        let mut at = 0usize;
        for field in s.split(|&b| b == b',') {
            if n == fields.len() {
                return Err(err(at.saturating_sub(1), "more than 7 fields"));
            }
            fields[n] = (at, field);
            n += 1;
            at += field.len() + 1;
        }
        if n < fields.len() {
            return Err(err(
                s.len(),
                "expected 7 fields: timestamp,arbitration_id,extended,remote,error,dlc,data",
            ));
        }
        let [ts, id, ext, rtr, error, dlc, data] = fields;
        let mut f = Frame {
            ts_ns: float_ns(ts.1).ok_or_else(|| err(ts.0, "expected a timestamp in seconds"))?,
            ..Frame::default()
        };
        let flag = |(at, t): (usize, &[u8])| match t {
            b"0" => Ok(false),
            b"1" => Ok(true),
            _ => Err(err(at, "expected 0 or 1")),
        };
        let (ext, rtr, error) = (flag(ext)?, flag(rtr)?, flag(error)?);
        let digits = id.1.strip_prefix(b"0x").unwrap_or(id.1);
        let raw = hex_u32(digits).ok_or_else(|| err(id.0, "expected a hex CAN id"))?;
        self.fill(&mut f, ifaces, (id.0, raw), [ext, rtr, error], dlc, data)?;
        Ok(Line::Frame(f))
    }

    /// Fills in the frame of a row from its fields after the timestamp: the id's value,
    /// the flags `[extended, remote, error]`, the DLC and the base64 data (fields with
    /// their indexes in the line).
    fn fill(
        &mut self,
        f: &mut Frame,
        ifaces: &mut Interfaces,
        (id_at, raw): (usize, u32),
        [ext, rtr, error]: [bool; 3],
        dlc: (usize, &[u8]),
        data: (usize, &[u8]),
    ) -> Result<(), ParseError> {
        if error {
            f.flags.set(Flags::ERR, true);
            f.id = raw & 0x1FFF_FFFF;
        } else if raw > if ext { 0x1FFF_FFFF } else { 0x7FF } {
            return Err(err(id_at, "CAN id out of range"));
        } else {
            f.id = raw;
            f.flags.set(Flags::EXT, ext);
        }
        let dlc_v = dec_u32(dlc.1)
            .filter(|&d| d <= 64)
            .ok_or_else(|| err(dlc.0, "expected a DLC"))? as u8;
        let len = base64(data.1, &mut f.data).map_err(|i| err(data.0 + i, "expected base64 data"))?;
        if rtr {
            f.flags.set(Flags::RTR, true);
            f.len = dlc_v.min(8);
            if (9..=15).contains(&dlc_v) {
                f.raw_dlc = dlc_v;
            }
        } else if len > 8 {
            if !matches!(len, 12 | 16 | 20 | 24 | 32 | 48 | 64) {
                return Err(err(data.0, "CAN FD data of a length no DLC gives"));
            }
            f.flags.set(Flags::FD | Flags::FDF, true);
            f.len = len as u8;
        } else {
            f.len = len as u8;
            if len == 8 && (9..=15).contains(&dlc_v) {
                f.raw_dlc = dlc_v;
            }
        }
        f.iface = self.iface.get(ifaces, b"can0", 0)?;
        Ok(())
    }
}

/// A non-negative Python float (`12.5`, `1e-05`, `1.5E+3`) as nanoseconds; `None` when
/// malformed, negative or too large.
fn float_ns(t: &[u8]) -> Option<u64> {
    let (mant, exp) = match t.iter().position(|&b| b == b'e' || b == b'E') {
        Some(i) => {
            let e = &t[i + 1..];
            let (neg, digits) = match e.split_first() {
                Some((b'-', d)) => (true, d),
                Some((b'+', d)) => (false, d),
                _ => (false, e),
            };
            let v = i32::try_from(dec_u32(digits)?).ok()?;
            (&t[..i], if neg { -v } else { v })
        }
        None => (t, 0),
    };
    let (int, frac) = match mant.iter().position(|&b| b == b'.') {
        Some(i) => (&mant[..i], &mant[i + 1..]),
        None => (mant, &mant[..0]),
    };
    if int.is_empty() && frac.is_empty() {
        return None;
    }
    // value = digits * 10^(exp - frac digits); in ns: * 10^9.
    let mut digits: u128 = 0;
    let mut kept_frac = 0i32;
    for (k, &b) in int.iter().chain(frac).enumerate() {
        if !b.is_ascii_digit() {
            return None;
        }
        if digits < 10u128.pow(30) {
            digits = digits * 10 + u128::from(b - b'0');
            if k >= int.len() {
                kept_frac += 1;
            }
        } else if k < int.len() {
            return None;
        }
    }
    let scale = exp.checked_add(9)?.checked_sub(kept_frac)?;
    let ns = if scale >= 0 {
        digits.checked_mul(10u128.checked_pow(scale as u32)?)?
    } else {
        digits / 10u128.checked_pow(scale.unsigned_abs()).unwrap_or(u128::MAX)
    };
    u64::try_from(ns).ok()
}

/// The value of each byte as a base64 digit (`A`-`Z`, `a`-`z`, `0`-`9`, `+`, `/`); 255 for
/// a byte that is none.
const BASE64: [u8; 256] = {
    let mut t = [255u8; 256];
    let mut i = 0;
    while i < 26 {
        t[b'A' as usize + i] = i as u8;
        t[b'a' as usize + i] = 26 + i as u8;
        if i < 10 {
            t[b'0' as usize + i] = 52 + i as u8;
        }
        i += 1;
    }
    t[b'+' as usize] = 62;
    t[b'/' as usize] = 63;
    t
};

/// Whether `b` may be in base64 data: a digit or the `=` padding.
fn is_base64(b: u8) -> bool {
    BASE64[b as usize] < 64 || b == b'='
}

/// Decodes standard base64 (with `=` padding) into `out`; the number of bytes, or the index
/// of the first bad character (or of the end when there are more bytes than `out` holds).
fn base64(text: &[u8], out: &mut [u8]) -> Result<usize, usize> {
    let value = |c: u8| Some(BASE64[c as usize]).filter(|&v| v < 64);
    let body_len = text.len() - text.iter().rev().take(2).take_while(|&&c| c == b'=').count();
    if !text.len().is_multiple_of(4) {
        return Err(text.len());
    }
    let body = &text[..body_len];
    // Whole groups of four digits as three bytes; a bad digit, a short group or a full
    // `out` are left to the digit-by-digit loop, which says where.
    let (mut at, mut n) = (0, 0);
    while let (Some(&[a, b, c, d]), Some(dst)) = (body.get(at..at + 4), out.get_mut(n..n + 3)) {
        let [a, b, c, d] = [a, b, c, d].map(|x| BASE64[x as usize]);
        if (a | b | c | d) > 63 {
            break;
        }
        let w = u32::from(a) << 18 | u32::from(b) << 12 | u32::from(c) << 6 | u32::from(d);
        dst.copy_from_slice(&w.to_be_bytes()[1..]);
        at += 4;
        n += 3;
    }
    let (mut acc, mut bits) = (0u32, 0);
    for (i, &c) in body.iter().enumerate().skip(at) {
        acc = acc << 6 | u32::from(value(c).ok_or(i)?);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            *out.get_mut(n).ok_or(i)? = (acc >> bits) as u8;
            n += 1;
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(line: &str) -> Result<Line, ParseError> {
        Parser::new().parse_line(line.as_bytes(), &mut Interfaces::default())
    }

    fn frame(line: &str) -> Frame {
        match parse(line) {
            Ok(Line::Frame(f)) => f,
            other => panic!("{line:?} gave {other:?}"),
        }
    }

    #[test]
    fn python_can_rows() {
        assert_eq!(
            parse(std::str::from_utf8(HEADER).unwrap()),
            Ok(Line::Skip(SkipReason::Header))
        );
        let f = frame("1700000000.123456,0x181,0,0,0,2,ESI=");
        assert_eq!(
            (f.ts_ns, f.id, f.payload()),
            (1_700_000_000_123_456_000, 0x181, &[0x11, 0x22][..])
        );
        let f = frame("1e-05,0x1abcdef,1,1,0,8,");
        assert_eq!(
            (f.ts_ns, f.id, f.flags.0, f.len),
            (10_000, 0x1AB_CDEF, Flags::EXT | Flags::RTR, 8)
        );
        let f = frame("0.0,0x4,0,0,1,8,ACAAAAAAAAA=");
        assert_eq!((f.flags.0, f.id, f.len, f.data[1]), (Flags::ERR, 4, 8, 0x20));
        let f = frame("2.5,0x7ff,0,0,0,12,AAECAwQFBgcICQoL");
        assert_eq!(
            (f.ts_ns, f.len, f.flags.0, f.data[11]),
            (2_500_000_000, 12, Flags::FD | Flags::FDF, 11)
        );
    }

    #[test]
    fn malformed_rows_are_located() {
        let e = |l: &str| parse(l).unwrap_err();
        assert_eq!(
            e("1.0,0x181,0,0,0,2").message,
            "expected 7 fields: timestamp,arbitration_id,extended,remote,error,dlc,data"
        );
        assert_eq!(e("1.0,0x800,0,0,0,0,").column, 5);
        assert_eq!(e("1.0,0x181,2,0,0,0,").column, 11);
        assert_eq!(e("1.0,0x181,0,0,0,2,ES!=").column, 21);
        assert_eq!(e("x,0x181,0,0,0,0,").column, 1);
        assert_eq!(e("1.0,0x181,0,0,0,2,ESI=,").message, "more than 7 fields");
        assert_eq!(float_ns(b"1.5E+3"), Some(1_500_000_000_000));
        assert_eq!(float_ns(b"-1.0"), None);
        assert_eq!(float_ns(b"1e400"), None);
        assert_eq!(float_ns(b"."), None);
    }

    /// The digit-by-digit decoder [`base64`] must agree with (bytes, count and error index).
    fn base64_by_digit(text: &[u8], out: &mut [u8]) -> Result<usize, usize> {
        let body_len = text.len() - text.iter().rev().take(2).take_while(|&&c| c == b'=').count();
        if !text.len().is_multiple_of(4) {
            return Err(text.len());
        }
        let (mut acc, mut bits, mut n) = (0u32, 0, 0);
        for (i, &c) in text[..body_len].iter().enumerate() {
            let v = match c {
                b'A'..=b'Z' => c - b'A',
                b'a'..=b'z' => c - b'a' + 26,
                b'0'..=b'9' => c - b'0' + 52,
                b'+' => 62,
                b'/' => 63,
                _ => return Err(i),
            };
            acc = acc << 6 | u32::from(v);
            bits += 6;
            if bits >= 8 {
                bits -= 8;
                *out.get_mut(n).ok_or(i)? = (acc >> bits) as u8;
                n += 1;
            }
        }
        Ok(n)
    }

    proptest::proptest! {
        #[test]
        fn base64_agrees_with_decoding_digit_by_digit(
            text in proptest::collection::vec(proptest::sample::select(b"AZaz09+/=!QgE".to_vec()), 0..28),
            room in 0usize..20,
        ) {
            let (mut a, mut b) = ([0u8; 20], [0u8; 20]);
            proptest::prop_assert_eq!(base64(&text, &mut a[..room]), base64_by_digit(&text, &mut b[..room]));
            proptest::prop_assert_eq!(a, b);
        }
    }
}
