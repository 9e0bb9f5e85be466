//! candump-like text lines with the decoded label appended.

use crate::decode::Decoded;
use crate::frame::{Frame, Interfaces};

/// Spaces for column padding.
const PADDING: &[u8; 32] = b"                                ";

/// Upper-case hex digits.
const DIGITS: &[u8; 16] = b"0123456789ABCDEF";

/// Appends one line (with `\n`) for `frame`:
/// `(1700000000.123456)  can0  181   [8]  37 02 00 00 00 00 00 00  TPDO1 node 1: ...`.
/// A frame that breaks its kind's rules ends with `  !! <reason>`. The line is UTF-8.
pub fn write_line(out: &mut Vec<u8>, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    let name = ifaces.name(frame.iface);
    // The columns before the label are composed on the stack and appended at once (one
    // copy instead of one per column): the hot path of `cotui decode --format text`.
    let mut line = [b' '; 128];
    let start = time_into(&mut line, frame.ts_ns);
    let mut n = TIME_END;
    let short_name = name.len() <= 16 && !super::has_control(name.as_bytes());
    if short_name {
        // The padding is already spaces.
        n += 4usize.saturating_sub(name.len());
        for &b in name.as_bytes() {
            line[n] = b;
            n += 1;
        }
    } else {
        out.extend_from_slice(&line[start..n]);
        out.extend_from_slice(&PADDING[..4usize.saturating_sub(name.len())]);
        super::push_escaped(out, name);
        line[..TIME_END].fill(b' ');
        n = 0;
    }
    let from = if short_name { start } else { 0 };
    n += 2;
    if frame.is_ext() || frame.is_err() {
        hex_into(&mut line[n..n + 8], frame.id);
        n += 8;
    } else {
        hex_into(&mut line[n + 5..n + 8], frame.id);
        n += 8;
    }
    if frame.is_fd() {
        // Two digits at least: `[08]`, `[64]`.
        if frame.len < 10 {
            line[n..n + 4].copy_from_slice(b"  [0");
        } else {
            line[n..n + 3].copy_from_slice(b"  [");
        }
        n += if frame.len < 10 { 4 } else { 3 };
    } else {
        line[n..n + 4].copy_from_slice(b"   [");
        n += 4;
    }
    n += len_into(&mut line[n..n + 3], frame.len);
    line[n..n + 3].copy_from_slice(b"]  ");
    n += 3;
    let payload = frame.payload();
    let classic = !frame.is_fd() && !frame.is_rtr() && payload.len() <= 8;
    if classic {
        classic_data_into(&mut line[n..n + 24], payload);
        n += 24;
        if frame.flags.has(crate::frame::Flags::TX) {
            line[n] = b'T';
            n += 2;
        }
        n += 1;
        out.reserve(n - from + decoded.label.len() + 1);
        out.extend_from_slice(&line[from..n]);
    } else {
        out.extend_from_slice(&line[from..n]);
        push_data_column(out, frame);
        if frame.flags.has(crate::frame::Flags::TX) {
            out.extend_from_slice(b"T ");
        }
        out.push(b' ');
    }
    super::push_escaped(out, &decoded.label);
    if let Some(m) = &decoded.malformed {
        out.extend_from_slice(b"  !! ");
        super::push_escaped(out, m);
    }
    out.push(b'\n');
}

/// Writes the low `out.len()` hex digits of `v`, upper case, into `out`.
fn hex_into(out: &mut [u8], v: u32) {
    for (i, d) in out.iter_mut().rev().enumerate() {
        *d = DIGITS[(v >> (4 * i) & 0xF) as usize];
    }
}

/// Writes a frame length (0..=255) in decimal at the start of `out` (three bytes);
/// returns the digits written.
fn len_into(out: &mut [u8], len: u8) -> usize {
    if len >= 100 {
        let d = len as usize % 100 * 2;
        out[0] = b'0' + len / 100;
        out[1..3].copy_from_slice(&PAIRS[d..d + 2]);
        3
    } else if len >= 10 {
        let d = len as usize * 2;
        out[..2].copy_from_slice(&PAIRS[d..d + 2]);
        2
    } else {
        out[0] = b'0' + len;
        1
    }
}

/// Writes the data column of a classic frame with up to eight bytes into `out` (24
/// bytes, spaces): spaced upper-case hex and a trailing space, padded to 24 characters.
fn classic_data_into(out: &mut [u8], payload: &[u8]) {
    for (i, b) in payload.iter().enumerate() {
        out[3 * i] = DIGITS[(b >> 4) as usize];
        out[3 * i + 1] = DIGITS[(b & 15) as usize];
    }
}

/// The decimal digits of 0..100, two by two.
const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// Where the time column ends in the line buffer of [`write_line`].
const TIME_END: usize = 23;

/// Writes `(SSSSSSSSSS.UUUUUU)  ` into `buf[..TIME_END]`: the seconds with at least ten
/// digits and the microseconds, two digits at a time. Returns where the column starts
/// (1 or 2: the seconds end at 13, u64::MAX ns is 18446744073 s, eleven digits at most).
fn time_into(buf: &mut [u8; 128], ts_ns: u64) -> usize {
    // Zeros pad the seconds to ten digits.
    buf[..13].fill(b'0');
    let mut i = 13;
    let mut secs = ts_ns / 1_000_000_000;
    while secs >= 100 {
        let d = (secs % 100) as usize * 2;
        secs /= 100;
        buf[i - 2..i].copy_from_slice(&PAIRS[d..d + 2]);
        i -= 2;
    }
    if secs >= 10 {
        let d = secs as usize * 2;
        buf[i - 2..i].copy_from_slice(&PAIRS[d..d + 2]);
        i -= 2;
    } else {
        i -= 1;
        buf[i] = b'0' + secs as u8;
    }
    let start = i.min(3) - 1;
    buf[start] = b'(';
    buf[13] = b'.';
    let mut us = (ts_ns % 1_000_000_000 / 1000) as usize;
    for at in [18, 16, 14] {
        let d = us % 100 * 2;
        us /= 100;
        buf[at..at + 2].copy_from_slice(&PAIRS[d..d + 2]);
    }
    buf[20..23].copy_from_slice(b")  ");
    start
}

/// Appends the data column of any other frame (remote request, CAN FD, longer payloads):
/// spaced hex or `remote request`, padded to 24 characters (3 per byte for CAN FD).
fn push_data_column(out: &mut Vec<u8>, frame: &Frame) {
    let width = if frame.is_fd() { 3 * frame.len as usize } else { 24 };
    let start = out.len();
    if frame.is_rtr() {
        out.extend_from_slice(b"remote request");
    } else {
        let mut hex = String::with_capacity(3 * frame.payload().len());
        crate::frame::hex::push_spaced(&mut hex, frame.payload());
        out.extend_from_slice(hex.as_bytes());
        if frame.len > 0 {
            out.push(b' ');
        }
    }
    let used = out.len() - start;
    out.extend_from_slice(&PADDING[..width.saturating_sub(used).min(PADDING.len())]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;
    use crate::od::Dictionary;

    fn line(frame: Frame) -> String {
        let mut ifaces = Interfaces::default();
        ifaces.intern("can0");
        let mut dec = Decoder::new(Dictionary::default(), vec![]);
        let d = dec.decode(&frame);
        let mut s = Vec::new();
        write_line(&mut s, &frame, &ifaces, &d);
        String::from_utf8(s).unwrap()
    }

    #[test]
    fn number_formatting() {
        let mut s = [0u8; 11];
        hex_into(&mut s[..8], 0x1ABCDEF);
        hex_into(&mut s[8..], 0x7E5);
        let mut t = Vec::from(s);
        for len in [0, 8, 9, 12, 64, 200] {
            let mut b = [0u8; 3];
            let n = len_into(&mut b, len);
            t.extend_from_slice(&b[..n]);
        }
        assert_eq!(String::from_utf8(t).unwrap(), "01ABCDEF7E5089126".to_string() + "4200");
    }

    fn time(ns: u64) -> String {
        let mut buf = [b' '; 128];
        let start = time_into(&mut buf, ns);
        String::from_utf8(buf[start..TIME_END].to_vec()).unwrap()
    }

    /// Timestamps: ten digits of seconds at least, six of microseconds, at every length.
    #[test]
    fn time_column() {
        for ns in [
            0,
            999,
            1_000,
            5_000_000_123,
            1_700_000_000_123_456_789,
            9_999_999_999_999_999_999,
            u64::MAX,
        ] {
            let expected = format!("({:010}.{:06})  ", ns / 1_000_000_000, ns % 1_000_000_000 / 1000);
            assert_eq!(time(ns), expected);
        }
        for secs in [1u64, 9, 10, 99, 100, 12_345_678_901] {
            assert_eq!(time(secs * 1_000_000_000 + 7_000), format!("({secs:010}.000007)  "));
        }
    }

    #[test]
    fn heartbeat_line() {
        let mut f = Frame::classic(0x705, &[0x05]);
        f.ts_ns = 1_700_000_000_123_456_789;
        assert_eq!(
            line(f),
            "(1700000000.123456)  can0       705   [1]  05                       Heartbeat node 5: Operational\n"
        );
    }

    #[test]
    fn malformed_is_marked_not_dropped() {
        let s = line(Frame::classic(0x000, &[0x01]));
        assert!(
            s.contains("NMT Start remote node -> all nodes  !! NMT frame has 1 data bytes, expected 2"),
            "{s}"
        );
    }
}
