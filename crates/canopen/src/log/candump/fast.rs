//! The fast path for the line candump `-l` writes almost always:
//! `(1700000000.000100) can0 181#370203` followed by `\n` (or `\r\n`).
//!
//! [`line`] reads exactly that shape — a timestamp of up to 10.9 digits (10.6 read in digit
//! groups), one space, an interface name, one space, a 3- or 8-digit hex id, `#`, up to 8
//! hex byte pairs and the line end (within 18 bytes of the `#`) — straight from the reader's buffer with the shared
//! [`Cursor`] steps, finding the line end as it goes (no separate search for `\n`).
//! Any other shape (blanks elsewhere, wider timestamps, `R`, `##`, `.`, `_`, a `T`
//! after the frame, a bad digit, a line with no line end yet) returns `None` and the
//! general parser ([`super`]) reads the line, with its located messages. So what
//! this path accepts it reads exactly as the general parser does (tested below against it).

use super::super::cursor::Cursor;
use super::super::lex::IfaceCache;
use crate::frame::{Flags, Frame, Interfaces};

/// Parses the common line at the start of `buf` into `frame`; returns the bytes it took,
/// its line end included, or `None` when the line has another shape.
#[inline]
pub(super) fn line(buf: &[u8], iface: &mut IfaceCache, ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
    let mut c = Cursor::new(buf);
    c.byte(b'(')?;
    let ts_ns = c.seconds_ns()?;
    c.byte(b')')?;
    c.byte(b' ')?;
    let name = c.iface_name(iface)?;
    c.byte(b' ')?;
    let (id, flags) = c.can_id()?;
    c.byte(b'#')?;
    // `frame` is scratch until `Some`: it is written as the line is read.
    *frame = Frame {
        ts_ns,
        id,
        flags: Flags(flags),
        ..Frame::default()
    };
    let (n, end) = c.packed_bytes_line(frame.data.first_chunk_mut()?)?;
    frame.len = n as u8;
    frame.iface = name.index(iface, ifaces)?;
    Some(end)
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
            b"(1700000000.0000011) can0 123#11\n",
            b"(1700000000.00001) can0 123#11\n",
            b"(170000000.000001) can0 123#11\n",
            b"(0.5) can0 123#11\n",
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
}
