//! Writes candump `-l` log lines byte for byte as candump does.
//!
//! candump (can-utils `candump.c`, `sprint_timestamp` and the log branch of the receive
//! loop) writes `"(%010llu.%06llu) "` (`%09llu` with `-N`; `(%03llu.…)` for `-t z`), then
//! `"%*s "` with the interface right-aligned to `max_devname_len`, then the compact frame
//! of `snprintf_canframe` (lib.c), then `" R"`/`" T"` with `-x`.
//!
//! `max_devname_len` starts as the longest interface name given on candump's command line
//! and grows whenever a frame arrives on a longer name (possible with `any`). So a log of
//! one interface has no padding, `candump -l can0 vcan10` pads `can0` to `  can0`, and
//! `candump -l any` pads nothing until a name longer than `any` appears; from then on the
//! shorter names are padded. [`LogWriter`] reproduces this with [`LogWriter::pad_to`] for
//! the command line names plus growth on every written name.
//!
//! The compact frame is upper-case hex without separators: 3-digit ids for 11-bit frames,
//! 8 digits for 29-bit ones and error frames (with `CAN_ERR_FLAG`), `R<len>` for remote
//! frames (length only when non-zero), `_<dlc>` for a raw DLC 9..F with length 8, and
//! `##<flags>` for CAN FD with BRS=1, ESI=2, FDF=4.

use std::io;

use crate::frame::linux::CAN_ERR_FLAG;
use crate::frame::{Flags, Frame};

const DIGITS: &[u8; 16] = b"0123456789ABCDEF";

/// Longest compact frame: 8-digit id, `##`, flags, 64 bytes.
pub(crate) const COMPACT_MAX: usize = 8 + 2 + 1 + 128 + 2;

/// Timestamp style of the log, as chosen on candump's command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timestamps {
    /// `-t a` (the default): seconds zero-padded to 10 digits.
    Absolute,
    /// `-t z`: zero-based, seconds zero-padded to 3 digits.
    ZeroBased,
}

/// Formats frames as candump log lines.
#[derive(Clone, Debug)]
pub struct LogWriter {
    timestamps: Timestamps,
    nanos: bool,
    direction: bool,
    width: usize,
}

impl Default for LogWriter {
    fn default() -> Self {
        LogWriter::new()
    }
}

impl LogWriter {
    /// Plain `candump -l`: absolute microsecond timestamps, no direction.
    pub fn new() -> Self {
        LogWriter {
            timestamps: Timestamps::Absolute,
            nanos: false,
            direction: false,
            width: 0,
        }
    }
    /// Timestamp style (`-t a` / `-t z`).
    pub fn timestamps(mut self, t: Timestamps) -> Self {
        self.timestamps = t;
        self
    }
    /// Nanosecond fractions (`-N`).
    pub fn nanos(mut self, on: bool) -> Self {
        self.nanos = on;
        self
    }
    /// Appends ` R` / ` T` (`-x`).
    pub fn direction(mut self, on: bool) -> Self {
        self.direction = on;
        self
    }
    /// Pads interface names to the longest of `names` (the interfaces given to candump).
    pub fn pad_to<S: AsRef<str>>(mut self, names: &[S]) -> Self {
        for n in names {
            self.width = self.width.max(n.as_ref().len());
        }
        self
    }

    /// Appends one line (with `\n`) to `out`.
    pub fn write_line(&mut self, out: &mut String, frame: &Frame, iface: &str) {
        let mut head = [0u8; 48];
        let mut body = [0u8; COMPACT_MAX + 3];
        let (h, b) = self.parts(frame, iface, &mut head, &mut body);
        // Both parts are ASCII.
        out.push_str(std::str::from_utf8(&head[..h]).unwrap_or_default());
        out.push_str(iface);
        out.push_str(std::str::from_utf8(&body[..b]).unwrap_or_default());
    }

    /// Writes one line (with `\n`) to `out` without allocating.
    pub fn write_io<W: io::Write>(&mut self, out: &mut W, frame: &Frame, iface: &str) -> io::Result<()> {
        let mut head = [0u8; 48];
        let mut body = [0u8; COMPACT_MAX + 3];
        let (h, b) = self.parts(frame, iface, &mut head, &mut body);
        out.write_all(&head[..h])?;
        out.write_all(iface.as_bytes())?;
        out.write_all(&body[..b])
    }

    /// Timestamp and padding into `head`, frame, direction and newline into `body`.
    fn parts(
        &mut self,
        frame: &Frame,
        iface: &str,
        head: &mut [u8; 48],
        body: &mut [u8; COMPACT_MAX + 3],
    ) -> (usize, usize) {
        self.width = self.width.max(iface.len());
        let mut h = 0;
        head[h] = b'(';
        h += 1;
        let secs = frame.ts_ns / 1_000_000_000;
        let ns = frame.ts_ns % 1_000_000_000;
        h += put_dec(
            &mut head[h..],
            secs,
            if self.timestamps == Timestamps::Absolute { 10 } else { 3 },
        );
        head[h] = b'.';
        h += 1;
        h += if self.nanos {
            put_dec(&mut head[h..], ns, 9)
        } else {
            put_dec(&mut head[h..], ns / 1000, 6)
        };
        head[h] = b')';
        head[h + 1] = b' ';
        h += 2;
        // Pad with spaces; names up to IFNAMSIZ fit, longer padding is cut (never happens with real names).
        let pad = (self.width - iface.len()).min(head.len() - h);
        head[h..h + pad].fill(b' ');
        h += pad;
        body[0] = b' ';
        let mut b = 1 + body[1..]
            .first_chunk_mut::<COMPACT_MAX>()
            .map_or(0, |c| compact(frame, c));
        if self.direction {
            body[b] = b' ';
            body[b + 1] = if frame.flags.has(Flags::TX) { b'T' } else { b'R' };
            b += 2;
        }
        body[b] = b'\n';
        (h, b + 1)
    }
}

/// Appends the compact form of `frame` (`123#1122`) to `out`, as `snprintf_canframe` does.
pub fn push_compact(out: &mut String, frame: &Frame) {
    let mut buf = [0u8; COMPACT_MAX];
    let n = compact(frame, &mut buf);
    out.push_str(std::str::from_utf8(&buf[..n]).unwrap_or_default());
}

/// Writes the compact form into `buf`, returning its length.
pub fn compact(frame: &Frame, buf: &mut [u8; COMPACT_MAX]) -> usize {
    let fd = frame.flags.has(Flags::FD);
    let mut o = if frame.flags.has(Flags::ERR) {
        put_hex(buf, (frame.id & 0x1FFF_FFFF) | CAN_ERR_FLAG, 8)
    } else if frame.flags.has(Flags::EXT) {
        put_hex(buf, frame.id & 0x1FFF_FFFF, 8)
    } else {
        put_hex(buf, frame.id & 0x7FF, 3)
    };
    buf[o] = b'#';
    o += 1;
    let len = (frame.len as usize).min(if fd { 64 } else { 8 });
    let raw_dlc = len == 8 && (9..=15).contains(&frame.raw_dlc);
    if !fd && frame.flags.has(Flags::RTR) {
        buf[o] = b'R';
        o += 1;
        if len > 0 {
            buf[o] = DIGITS[len];
            o += 1;
            if raw_dlc {
                buf[o] = b'_';
                buf[o + 1] = DIGITS[frame.raw_dlc as usize];
                o += 2;
            }
        }
        return o;
    }
    if fd {
        let f = frame.flags;
        let nibble = f.has(Flags::BRS) as usize | (f.has(Flags::ESI) as usize) << 1 | (f.has(Flags::FDF) as usize) << 2;
        buf[o] = b'#';
        buf[o + 1] = DIGITS[nibble];
        o += 2;
    }
    for &byte in &frame.data[..len] {
        buf[o] = DIGITS[(byte >> 4) as usize];
        buf[o + 1] = DIGITS[(byte & 15) as usize];
        o += 2;
    }
    if !fd && raw_dlc {
        buf[o] = b'_';
        buf[o + 1] = DIGITS[frame.raw_dlc as usize];
        o += 2;
    }
    o
}

/// Upper-case hex of `v` in exactly `digits` digits; returns `digits`.
fn put_hex(buf: &mut [u8], mut v: u32, digits: usize) -> usize {
    for k in (0..digits).rev() {
        buf[k] = DIGITS[(v & 15) as usize];
        v >>= 4;
    }
    digits
}

/// Decimal `v` zero-padded to at least `width` digits; returns the digit count.
fn put_dec(buf: &mut [u8], v: u64, width: usize) -> usize {
    let mut tmp = [0u8; 20];
    let mut n = 0;
    let mut x = v;
    loop {
        tmp[n] = b'0' + (x % 10) as u8;
        n += 1;
        x /= 10;
        if x == 0 {
            break;
        }
    }
    let total = n.max(width);
    for k in 0..total {
        buf[k] = if k < total - n { b'0' } else { tmp[total - 1 - k] };
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Interfaces;
    use crate::log::{Line, candump};

    fn roundtrip(w: &mut LogWriter, line: &str) {
        let mut ifaces = Interfaces::default();
        let Ok(Line::Frame(f)) = candump::parse_line(line.as_bytes(), &mut ifaces) else {
            panic!("{line}")
        };
        let mut out = String::new();
        w.write_line(&mut out, &f, ifaces.name(f.iface));
        assert_eq!(out, format!("{line}\n"));
        let mut bytes = Vec::new();
        w.write_io(&mut bytes, &f, ifaces.name(f.iface)).unwrap();
        assert_eq!(bytes, out.as_bytes());
    }

    #[test]
    fn candump_lines_round_trip() {
        for line in [
            "(1436509052.249713) vcan0 044#2A366C2BBA",
            "(1700000000.000001) can0 123#",
            "(1700000000.000001) can0 123#R",
            "(1700000000.000001) can0 7FF#R8_9",
            "(1700000000.000001) can0 12345678#R3",
            "(1700000000.000001) can0 123#1122334455667788_E",
            "(1700000000.000001) can0 123##5112233445566778899AABBCC",
            "(1700000000.000001) can0 1FFFFFFF##0",
            "(1700000000.000001) can0 123##1AA",
            "(1700000000.000001) can0 20000004#000C000000000000",
            "(0000000001.000000) can0 000#00",
        ] {
            roundtrip(&mut LogWriter::new(), line);
        }
    }

    #[test]
    fn options_match_candump_flags() {
        roundtrip(&mut LogWriter::new().nanos(true), "(1700000000.123456789) can0 123#11");
        roundtrip(
            &mut LogWriter::new().timestamps(Timestamps::ZeroBased),
            "(000.001000) can0 123#11",
        );
        roundtrip(
            &mut LogWriter::new().timestamps(Timestamps::ZeroBased),
            "(1234.001000) can0 123#11",
        );
        let mut w = LogWriter::new().direction(true);
        roundtrip(&mut w, "(1700000000.000001) can0 123#11 T");
        roundtrip(&mut w, "(1700000000.000001) can0 123#11 R");
    }

    #[test]
    fn padding_follows_max_devname_len() {
        let mut w = LogWriter::new().pad_to(&["can0", "vcan10"]);
        roundtrip(&mut w, "(1700000000.000001)   can0 123#11");
        roundtrip(&mut w, "(1700000000.000001) vcan10 123#11");
        // `candump -l any`: no padding until a longer name shows up.
        let mut w = LogWriter::new().pad_to(&["any"]);
        roundtrip(&mut w, "(1700000000.000001) can0 123#11");
        roundtrip(&mut w, "(1700000000.000002) vcan10 123#11");
        roundtrip(&mut w, "(1700000000.000003)   can0 123#11");
    }

    #[test]
    fn ids_above_7ff_from_frame_classic_are_written_as_29_bit() {
        let mut s = String::new();
        push_compact(&mut s, &Frame::classic(0x80F, &[1]));
        assert_eq!(s, "0000080F#01");
    }
}
