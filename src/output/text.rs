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
    out.reserve(160);
    push_time(out, frame.ts_ns);
    let name = ifaces.name(frame.iface);
    out.extend_from_slice(&PADDING[..4usize.saturating_sub(name.len())]);
    super::push_escaped(out, name);
    out.extend_from_slice(b"  ");
    if frame.is_ext() || frame.is_err() {
        push_hex(out, frame.id, 8);
    } else {
        out.extend_from_slice(b"     ");
        push_hex(out, frame.id, 3);
    }
    if frame.is_fd() {
        // Two digits at least: `[08]`, `[64]`.
        out.extend_from_slice(if frame.len < 10 { b"  [0" } else { b"  [" });
    } else {
        out.extend_from_slice(b"   [");
    }
    push_len(out, frame.len);
    out.extend_from_slice(b"]  ");
    let payload = frame.payload();
    if !frame.is_fd() && !frame.is_rtr() && payload.len() <= 8 {
        push_classic_data(out, payload);
    } else {
        push_data_column(out, frame);
    }
    if frame.flags.has(crate::frame::Flags::TX) {
        out.extend_from_slice(b"T ");
    }
    out.push(b' ');
    super::push_escaped(out, &decoded.label);
    if let Some(m) = &decoded.malformed {
        out.extend_from_slice(b"  !! ");
        super::push_escaped(out, m);
    }
    out.push(b'\n');
}

/// Appends the low `digits` hex digits of `v`, upper case.
fn push_hex(out: &mut Vec<u8>, v: u32, digits: usize) {
    let mut buf = [b'0'; 8];
    for (i, d) in buf[..digits].iter_mut().rev().enumerate() {
        *d = DIGITS[(v >> (4 * i) & 0xF) as usize];
    }
    out.extend_from_slice(&buf[..digits]);
}

/// Appends a frame length (0..=64) in decimal.
fn push_len(out: &mut Vec<u8>, len: u8) {
    if len >= 10 {
        let d = len as usize % 100 * 2;
        if len >= 100 {
            out.push(b'0' + len / 100);
        }
        out.extend_from_slice(&PAIRS[d..d + 2]);
    } else {
        out.push(b'0' + len);
    }
}

/// Appends the data column of a classic frame with up to eight bytes: spaced upper-case
/// hex and a trailing space, padded to 24 characters (the common case, from the stack).
fn push_classic_data(out: &mut Vec<u8>, payload: &[u8]) {
    let mut buf = [b' '; 24];
    for (i, b) in payload.iter().enumerate() {
        buf[3 * i] = DIGITS[(b >> 4) as usize];
        buf[3 * i + 1] = DIGITS[(b & 15) as usize];
    }
    out.extend_from_slice(&buf);
}

/// The decimal digits of 0..100, two by two.
const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// Appends `(SSSSSSSSSS.UUUUUU)  `: the seconds with at least ten digits and the
/// microseconds, two digits at a time.
fn push_time(out: &mut Vec<u8>, ts_ns: u64) {
    // Seconds end at 13 (u64::MAX ns is 18446744073 s: eleven digits at most), then
    // `.UUUUUU)  `. Zeros pad the seconds to ten digits.
    let mut buf = [b'0'; 23];
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
    out.extend_from_slice(&buf[start..]);
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
        let mut s = Vec::new();
        push_hex(&mut s, 0x1ABCDEF, 8);
        push_hex(&mut s, 0x7E5, 3);
        for len in [0, 8, 9, 12, 64] {
            push_len(&mut s, len);
        }
        assert_eq!(String::from_utf8(s).unwrap(), "01ABCDEF7E5089126".to_string() + "4");
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
            let mut s = Vec::new();
            push_time(&mut s, ns);
            let expected = format!("({:010}.{:06})  ", ns / 1_000_000_000, ns % 1_000_000_000 / 1000);
            assert_eq!(String::from_utf8(s).unwrap(), expected);
        }
        for secs in [1u64, 9, 10, 99, 100, 12_345_678_901] {
            let mut s = Vec::new();
            push_time(&mut s, secs * 1_000_000_000 + 7_000);
            assert_eq!(String::from_utf8(s).unwrap(), format!("({secs:010}.000007)  "));
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
