//! candump-like text lines with the decoded label appended.

use crate::decode::Decoded;
use crate::frame::{Frame, Interfaces};

use crate::frame::hex::{push_decimal, push_hex};

/// Spaces for column padding.
const PADDING: &str = "                                ";

/// Appends one line (with `\n`) for `frame`:
/// `(1700000000.123456)  can0  181   [8]  37 02 00 00 00 00 00 00  TPDO1 node 1: ...`.
/// A frame that breaks its kind's rules ends with `  !! <reason>`.
pub fn write_line(out: &mut String, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    out.reserve(160);
    out.push('(');
    push_decimal(out, frame.ts_ns / 1_000_000_000, 10);
    out.push('.');
    push_decimal(out, frame.ts_ns % 1_000_000_000 / 1000, 6);
    out.push_str(")  ");
    let name = ifaces.name(frame.iface);
    for _ in name.len()..4 {
        out.push(' ');
    }
    super::push_escaped(out, name);
    out.push_str("  ");
    if frame.is_ext() || frame.is_err() {
        push_hex(out, frame.id, 8);
    } else {
        out.push_str("     ");
        push_hex(out, frame.id, 3);
    }
    if frame.is_fd() {
        out.push_str("  [");
        push_decimal(out, frame.len as u64, 2);
    } else {
        out.push_str("   [");
        push_decimal(out, frame.len as u64, 1);
    }
    out.push_str("]  ");
    let payload = frame.payload();
    if !frame.is_fd() && !frame.is_rtr() && payload.len() <= 8 {
        push_classic_data(out, payload);
    } else {
        push_data_column(out, frame);
    }
    if frame.flags.has(crate::frame::Flags::TX) {
        out.push_str("T ");
    }
    out.push(' ');
    super::push_escaped(out, &decoded.label);
    if let Some(m) = &decoded.malformed {
        out.push_str("  !! ");
        super::push_escaped(out, m);
    }
    out.push('\n');
}

/// Appends the data column of a classic frame with up to eight bytes: spaced upper-case
/// hex and a trailing space, padded to 24 characters (the common case, from the stack).
fn push_classic_data(out: &mut String, payload: &[u8]) {
    const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
    let mut buf = [b' '; 24];
    for (i, b) in payload.iter().enumerate() {
        buf[3 * i] = DIGITS[(b >> 4) as usize];
        buf[3 * i + 1] = DIGITS[(b & 15) as usize];
    }
    // Hex digits and spaces only: always valid UTF-8.
    out.push_str(std::str::from_utf8(&buf).unwrap_or_default());
}

/// Appends the data column of any other frame (remote request, CAN FD, longer payloads):
/// spaced hex or `remote request`, padded to 24 characters (3 per byte for CAN FD).
fn push_data_column(out: &mut String, frame: &Frame) {
    let width = if frame.is_fd() { 3 * frame.len as usize } else { 24 };
    let start = out.len();
    if frame.is_rtr() {
        out.push_str("remote request");
    } else {
        crate::frame::hex::push_spaced(out, frame.payload());
        if frame.len > 0 {
            out.push(' ');
        }
    }
    let used = out.len() - start;
    out.push_str(&PADDING[..width.saturating_sub(used).min(PADDING.len())]);
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
        let mut s = String::new();
        write_line(&mut s, &frame, &ifaces, &d);
        s
    }

    #[test]
    fn number_formatting() {
        let mut s = String::new();
        push_decimal(&mut s, 42, 6);
        push_decimal(&mut s, 0, 1);
        push_decimal(&mut s, 1234567, 2);
        push_hex(&mut s, 0x1ABCDEF, 8);
        push_hex(&mut s, 0x7E5, 3);
        assert_eq!(s, "00004201234567".to_string() + "01ABCDEF7E5");
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
