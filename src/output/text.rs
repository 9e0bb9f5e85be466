//! candump-like text lines with the decoded label appended.

use crate::decode::Decoded;
use crate::frame::{Frame, Interfaces};
use std::fmt::Write;

/// Appends one line (with `\n`) for `frame`:
/// `(1700000000.123456)  can0  181   [8]  37 02 00 00 00 00 00 00  TPDO1 node 1: ...`.
/// A frame that breaks its kind's rules ends with `  !! <reason>`.
pub fn write_line(out: &mut String, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    let secs = frame.ts_ns / 1_000_000_000;
    let usecs = frame.ts_ns % 1_000_000_000 / 1000;
    let _ = write!(out, "({secs:010}.{usecs:06})  {:>4}  ", ifaces.name(frame.iface));
    if frame.is_ext() || frame.is_err() {
        let _ = write!(out, "{:08X}", frame.id);
    } else {
        let _ = write!(out, "     {:03X}", frame.id);
    }
    if frame.is_fd() {
        let _ = write!(out, "  [{:02}]  ", frame.len);
    } else {
        let _ = write!(out, "   [{}]  ", frame.len);
    }
    let width = if frame.is_fd() { 3 * frame.len as usize } else { 24 };
    let start = out.len();
    if frame.is_rtr() {
        out.push_str("remote request");
    } else {
        for b in frame.payload() {
            crate::hex::push_upper(out, std::slice::from_ref(b));
            out.push(' ');
        }
    }
    let used = out.len() - start;
    for _ in used..width {
        out.push(' ');
    }
    if frame.flags.has(crate::frame::Flags::TX) {
        out.push_str("T ");
    }
    out.push(' ');
    out.push_str(&decoded.label);
    if let Some(m) = &decoded.malformed {
        out.push_str("  !! ");
        out.push_str(m);
    }
    out.push('\n');
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
