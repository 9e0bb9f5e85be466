//! The fast path for the line candump `-l` writes almost always:
//! `(1700000000.000100) can0 181#370203` followed by `\n` (or `\r\n`).
//!
//! [`line`] reads exactly that shape — a 10.6-digit timestamp, one space, an interface name,
//! one space, a 3- or 8-digit hex id, `#`, up to 8 hex byte pairs and the line end — straight
//! from the reader's buffer, finding the line end as it goes (no separate search for `\n`).
//! Any other shape (blanks elsewhere, other timestamp widths, `R`, `##`, `.`, `_`, a `T`
//! after the frame, a bad digit, a line with no line end yet) returns `None` and the
//! general parser ([`super::candump`]) reads the line, with its located messages. So what
//! this path accepts it reads exactly as the general parser does (tested below against it).

use super::lex::{HEX, IfaceCache};
use crate::frame::linux::CAN_ERR_FLAG;
use crate::frame::{Flags, Frame, Interfaces};

/// Parses the common line at the start of `buf` into `frame`; returns the bytes it took,
/// its line end included, or `None` when the line has another shape.
#[inline]
pub(super) fn line(buf: &[u8], iface: &mut IfaceCache, ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
    // `(` 10 digits `.` 6 digits `)` ` `: 20 bytes, then at least `x 123#\n`.
    if buf.len() < 26 || buf[0] != b'(' || buf[11] != b'.' || buf[18] != b')' || buf[19] != b' ' {
        return None;
    }
    let secs = digits8(buf[1..9].try_into().ok()?)? * 100 + digit(buf[9])? * 10 + digit(buf[10])?;
    // Six fraction digits behind two `0`s make an 8-digit group.
    let mut frac = [b'0'; 8];
    frac[2..].copy_from_slice(&buf[12..18]);
    let micros = digits8(&frac)?;
    // secs < 10^10, so secs * 10^9 + micros * 1000 < 10^19 < u64::MAX.
    let ts_ns = secs * 1_000_000_000 + micros * 1000;

    let (cached, name_end) = match iface.at_space(buf, 20) {
        Some((idx, end)) => (Some(idx), end),
        None => {
            let end = 20 + buf[20..].iter().position(|&b| b <= b' ')?;
            if end == 20 || buf[end] != b' ' {
                return None;
            }
            (None, end)
        }
    };
    let at = name_end + 1;
    let (id, flags, i) = if buf.get(at + 3) == Some(&b'#') {
        let id = hex_digits(&buf[at..at + 3])?;
        if id > 0x7FF {
            return None;
        }
        (id, 0, at + 4)
    } else if buf.get(at + 8) == Some(&b'#') {
        let raw = hex_digits(&buf[at..at + 8])?;
        if raw & 0xC000_0000 != 0 {
            return None;
        }
        if raw & CAN_ERR_FLAG != 0 {
            (raw & !CAN_ERR_FLAG, Flags::ERR, at + 9)
        } else {
            (raw, Flags::EXT, at + 9)
        }
    } else {
        return None;
    };

    // Up to 8 byte pairs and the line end lie in the next 18 bytes; a line that ends
    // closer to the end of the buffer is left to the general parser.
    let t: &[u8; 18] = buf.get(i..i + 18)?.try_into().ok()?;
    let mut data = [0u8; 8];
    let mut n = 0;
    let end = loop {
        let (c, d) = (t[2 * n], t[2 * n + 1]);
        if c == b'\n' {
            break i + 2 * n + 1;
        }
        if c == b'\r' && d == b'\n' {
            break i + 2 * n + 2;
        }
        let (hi, lo) = (HEX[c as usize], HEX[d as usize]);
        if n == 8 || (hi | lo) > 15 {
            return None;
        }
        data[n] = hi << 4 | lo;
        n += 1;
    };

    let idx = match cached {
        Some(idx) => idx,
        None => iface.get(ifaces, &buf[20..name_end], 20).ok()?,
    };
    *frame = Frame {
        ts_ns,
        id,
        flags: Flags(flags),
        len: n as u8,
        iface: idx,
        ..Frame::default()
    };
    frame.data[..8].copy_from_slice(&data);
    Some(end)
}

/// Value of one decimal digit.
#[inline]
fn digit(b: u8) -> Option<u64> {
    b.is_ascii_digit().then(|| u64::from(b - b'0'))
}

/// Value of 8 decimal digits (most significant first), combined in pairs, quads and halves.
#[inline]
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

/// Value of up to 8 hex digits.
#[inline]
fn hex_digits(t: &[u8]) -> Option<u32> {
    let mut v = 0u32;
    let mut bad = 0u8;
    for &b in t {
        let h = HEX[b as usize];
        bad |= h;
        v = v << 4 | u32::from(h & 15);
    }
    (bad <= 15).then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::candump::Parser;
    use crate::log::{Line, ParseError};

    /// What the general parser makes of `text` (one line, its line end included).
    fn general(text: &[u8]) -> (Result<Line, ParseError>, Vec<String>) {
        let mut ifaces = Interfaces::default();
        let r = Parser::new().parse_line(text, &mut ifaces);
        (r, ifaces.names().to_vec())
    }

    /// What the fast path makes of `text` (`None` when it leaves the line to the general one).
    /// The text is followed by another line, as in a reader's buffer.
    fn fast(text: &[u8]) -> Option<(usize, Frame, Vec<String>)> {
        let buf = [text, b"(1700000000.000002) can0 124#2233445566778899\n"].concat();
        let mut ifaces = Interfaces::default();
        let mut frame = Frame::default();
        let mut cache = IfaceCache::default();
        let n = line(&buf, &mut cache, &mut ifaces, &mut frame)?;
        // Read again with the name cached: the same frame.
        let mut again = Frame::default();
        assert_eq!(line(&buf, &mut cache, &mut ifaces, &mut again), Some(n));
        assert_eq!(again, frame);
        Some((n, frame, ifaces.names().to_vec()))
    }

    #[test]
    fn accepted_lines_read_as_the_general_parser_reads_them() {
        let lines: &[&[u8]] = &[
            b"(1700000000.000100) can0 181#370203\n",
            b"(1436509052.249713) vcan0 044#2A366C2BBA\r\n",
            b"(0000000000.000000) c 000#\n",
            b"(9999999999.999999) can0 7FF#FFFFFFFFFFFFFFFF\n",
            b"(1700000000.000001) can0 7ff#aAbBcCdDeEfF0919\n",
            b"(1700000000.000001) can0 1FFFFFFF#0102\n",
            b"(1700000000.000001) can0 00000123#aa\n",
            b"(1700000000.000001) can0 20000004#000C000000000000\n",
            b"(1700000000.000001) my-very-long-interface-name.0 123#11\n",
            b"(1700000000.000001) \xC3\xA9th0 123#11\n",
        ];
        for &text in lines {
            let (n, f, names) = fast(text).unwrap_or_else(|| panic!("{:?} not taken", String::from_utf8_lossy(text)));
            assert_eq!(n, text.len());
            let (g, gnames) = general(text);
            assert_eq!(g, Ok(Line::Frame(f)), "{:?}", String::from_utf8_lossy(text));
            assert_eq!(names, gnames);
        }
    }

    #[test]
    fn other_shapes_are_left_to_the_general_parser() {
        let lines: &[&[u8]] = &[
            b"(1700000000.000001) can0 123#R\n",
            b"(1700000000.000001) can0 123#r\n",
            b"(1700000000.000001) can0 123#R8_9\n",
            b"(1700000000.000001) can0 123##5AABB\n",
            b"(1700000000.000001) can0 12345678##0\n",
            b"(1700000000.000001) can0 123#11.22\n",
            b"(1700000000.000001) can0 123#1122334455667788_E\n",
            b"(1700000000.000001) can0 123#11 T\n",
            b"(1700000000.000001) can0 123#11 \n",
            b"(1700000000.000001) can0 123#112\n",
            b"(1700000000.000001) can0 123#1G\n",
            b"(1700000000.000001) can0 123#112233445566778899\n",
            b"(1700000000.000001) can0 800#11\n",
            b"(1700000000.000001) can0 C0000004#00\n",
            b"(1700000000.000001) can0 45123#81:00:12345678#11\n",
            b"(1700000000.000001) can0 1234#11\n",
            b"(1700000000.000001) can0 12G#11\n",
            b"(1700000000.000001)  can0 123#11\n",
            b"(1700000000.000001)\tcan0 123#11\n",
            b"(1700000000.000001) can0\t123#11\n",
            b"(1700000000.000001) can0  123#11\n",
            b"(1700000000.000001) c\xFFn0 123#11\n",
            b"(1700000000.000001) can0\n",
            b"(1700000000.000001) can0 123#11",
            b"(1700000000.0000011) can0 123#11\n",
            b"(1700000000.00001) can0 123#11\n",
            b"(170000000.000001) can0 123#11\n",
            b"(17000x0000.000001) can0 123#11\n",
            b"(1700000000.00000x) can0 123#11\n",
            b"(1700000000:000001) can0 123#11\n",
            b"(1700000000.000001 can0 123#11\n",
            b"(1700000000.000001)can0 123#11\n",
            b"# a comment that is long enough\n",
            b"DROPCOUNT: dropped 3 CAN frames\n",
            b"\n",
            b"(1700000000.000001) can0 12",
        ];
        for &text in lines {
            assert_eq!(fast(text), None, "{:?}", String::from_utf8_lossy(text));
        }
    }

    #[test]
    fn a_line_ends_at_its_first_line_end() {
        let text = b"(1700000000.000001) can0 123#11\n(1700000000.000002) can0 124#22\n";
        let (n, f, _) = fast(text).unwrap();
        assert_eq!((n, f.id, f.payload()), (32, 0x123, &[0x11][..]));
    }

    #[test]
    fn a_run_of_lines_shares_the_name_cache_as_the_general_parser_does() {
        let text: &[u8] = b"(1700000000.000001) can0 123#11\n\
            (1700000000.000002) can01 123#11\n\
            (1700000000.000003) can0 123#11\n\
            (1700000000.000004) can 7FF#\n\
            (1700000000.000005) a-sixteen-bytes0 1FFFFFFF#0102030405060708\n\
            (1700000000.000006) a-sixteen-bytes0 1FFFFFFF#0102030405060708\n\
            (1700000000.000007) seventeen-bytes-0 001#00\n\
            (1700000000.000008) seventeen-bytes-0 001#00\n\
            (1700000000.000009) can0 123#11\n\
            (1700000000.000010) can0 123#11\n";
        let (mut fast_ifaces, mut general_ifaces) = (Interfaces::default(), Interfaces::default());
        let mut cache = IfaceCache::default();
        let mut general = Parser::new();
        let mut at = 0;
        for one in text.split_inclusive(|&b| b == b'\n') {
            let mut f = Frame::default();
            // The last lines lack the 18 bytes of look-ahead: the general parser reads them.
            if let Some(n) = line(&text[at..], &mut cache, &mut fast_ifaces, &mut f) {
                assert_eq!(n, one.len());
                assert_eq!(general.parse_line(one, &mut general_ifaces), Ok(Line::Frame(f)));
            } else {
                assert!(text.len() - at < 40, "{:?}", String::from_utf8_lossy(one));
                general.parse_line(one, &mut general_ifaces).unwrap();
            }
            at += one.len();
        }
        assert_eq!(fast_ifaces.names().len(), 5);
        assert_eq!(&general_ifaces.names()[..5], fast_ifaces.names());
    }

    #[test]
    fn digit_groups() {
        assert_eq!(digits8(b"12345678"), Some(12_345_678));
        assert_eq!(digits8(b"00000000"), Some(0));
        assert_eq!(digits8(b"99999999"), Some(99_999_999));
        for bad in [b"1234567:", b"/2345678", b"1234 678", b"\xF9234567A"] {
            assert_eq!(digits8(bad), None);
        }
        assert_eq!(hex_digits(b"1aF"), Some(0x1AF));
        assert_eq!(hex_digits(b"1g0"), None);
    }
}
