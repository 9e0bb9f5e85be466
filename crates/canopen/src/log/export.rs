//! Writers of Vector ASC and PEAK TRC 2.1 logs, so that a capture opens where users
//! already work (CANalyzer/CANoe, PCAN-View, python-can). Both read back through
//! [`super::LogReader`] to the same frames and times (ASC's from its `date` line).
//!
//! Channel numbers: interface `canN` is channel N+1 (as the readers name channels back);
//! any other name is channel (its index in the interface table + 1). The header is written
//! with the first frame, whose time is the measurement's start (ASC: to the ms, as its
//! `date` line has it; times are offsets from that date).

use std::fmt::Write as _;

use crate::frame::{Flags, Frame};

/// The channel (1-based) a frame on interface `name` (index `index`) is written on.
fn channel(index: u16, name: &str) -> u32 {
    name.strip_prefix("can")
        .and_then(|n| n.parse::<u32>().ok())
        .and_then(|n| n.checked_add(1))
        .unwrap_or(u32::from(index) + 1)
}

/// A classic frame's DLC: the raw DLC when one above 8 was kept.
fn classic_dlc(f: &Frame) -> u8 {
    if f.raw_dlc > 8 { f.raw_dlc } else { f.len }
}

fn push_bytes(out: &mut String, data: &[u8]) {
    for (k, b) in data.iter().enumerate() {
        if k > 0 {
            out.push(' ');
        }
        let _ = write!(out, "{b:02X}");
    }
}

/// Civil date and time (UTC) of `ns` since the epoch: (year, month, day, weekday 0 =
/// Sunday, hour, minute, second, millisecond).
fn civil(ns: u64) -> (i64, usize, i64, usize, u64, u64, u64, u64) {
    let secs = ns / 1_000_000_000;
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let (y, m, d) = crate::calendar::civil_from_days(days);
    let weekday = (days + 4).rem_euclid(7) as usize;
    let ms = ns / 1_000_000 % 1000;
    (
        y,
        m as usize,
        i64::from(d),
        weekday,
        rem / 3600,
        rem / 60 % 60,
        rem % 60,
        ms,
    )
}

/// Writes Vector ASC: a header (`date`, `base hex  timestamps absolute`, `Begin
/// Triggerblock`), one line per frame (classic, `CANFD`, `ErrorFrame`), and with
/// [`AscWriter::finish`] the `End TriggerBlock` line.
#[derive(Debug, Default)]
pub struct AscWriter {
    start_ns: Option<u64>,
}

impl AscWriter {
    /// A writer whose header comes with the first frame.
    pub fn new() -> Self {
        AscWriter::default()
    }

    /// Appends `frame` (on interface `iface`) to `out`, after the header for the first one.
    pub fn write_line(&mut self, out: &mut String, frame: &Frame, iface: &str) {
        let start = *self.start_ns.get_or_insert_with(|| {
            let (y, mo, d, wd, h, mi, s, ms) = civil(frame.ts_ns);
            const DAYS: [&str; 7] = ["Sun", "Mon", "Tue", "Wed", "Thu", "Fri", "Sat"];
            const MONTHS: [&str; 12] = [
                "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
            ];
            let date = format!(
                "{} {} {d:02} {h:02}:{mi:02}:{s:02}.{ms:03} {y}",
                DAYS[wd],
                MONTHS[(mo + 11) % 12]
            );
            let _ = write!(
                out,
                "date {date}\nbase hex  timestamps absolute\nno internal events logged\n// cotui\nBegin Triggerblock {date}\n   0.000000 Start of measurement\n"
            );
            frame.ts_ns - frame.ts_ns % 1_000_000
        });
        let t = frame.ts_ns.saturating_sub(start);
        let _ = write!(out, "{:>4}.{:06} ", t / 1_000_000_000, t / 1000 % 1_000_000);
        let ch = channel(frame.iface, iface);
        let dir = if frame.flags.has(Flags::TX) { "Tx" } else { "Rx" };
        let ext = if frame.flags.has(Flags::EXT) { "x" } else { "" };
        if frame.flags.has(Flags::ERR) {
            let _ = writeln!(out, "{ch}  ErrorFrame");
        } else if frame.flags.has(Flags::FD) {
            let mut flags = 0x1000;
            if frame.flags.has(Flags::BRS) {
                flags |= 0x2000;
            }
            if frame.flags.has(Flags::ESI) {
                flags |= 0x4000;
            }
            let id = format!("{:X}{ext}", frame.id);
            let _ = write!(
                out,
                "CANFD {ch:>3} {dir:<4} {id:>8}  {:>32} {} {} {:x} {:>2} ",
                "",
                u8::from(frame.flags.has(Flags::BRS)),
                u8::from(frame.flags.has(Flags::ESI)),
                crate::frame::fd_dlc_at_least(frame.len),
                frame.len
            );
            push_bytes(out, frame.payload());
            let _ = writeln!(
                out,
                " {:>8} {:>4} {flags:>8X} {:>8} {:>8} {:>8} {:>8} {:>8}",
                0, 0, 0, 0, 0, 0, 0
            );
        } else {
            let id = format!("{:X}{ext}", frame.id);
            let kind = if frame.flags.has(Flags::RTR) { "r" } else { "d" };
            let _ = write!(out, "{ch}  {id:<15} {dir:<4} {kind} {:x}", classic_dlc(frame));
            if !frame.flags.has(Flags::RTR) && frame.len > 0 {
                out.push(' ');
                push_bytes(out, frame.payload());
            }
            out.push('\n');
        }
    }

    /// Appends the closing line (when a header was written).
    pub fn finish(&mut self, out: &mut String) {
        if self.start_ns.is_some() {
            out.push_str("End TriggerBlock\n");
        }
    }
}

/// Writes PEAK TRC 2.1 (`$COLUMNS=N,O,T,B,I,d,R,L,D`): `$STARTTIME` is the first frame's
/// time, offsets are in ms with µs resolution; remote frames are `RR`, FD frames `FD`,
/// `FB`, `FE` or `BI` with their DLC, error frames `ER` lines without detail.
#[derive(Debug, Default)]
pub struct TrcWriter {
    start_ns: Option<u64>,
    number: u64,
}

impl TrcWriter {
    /// A writer whose header comes with the first frame.
    pub fn new() -> Self {
        TrcWriter::default()
    }

    /// Appends `frame` (on interface `iface`) to `out`, after the header for the first one.
    pub fn write_line(&mut self, out: &mut String, frame: &Frame, iface: &str) {
        let start = *self.start_ns.get_or_insert_with(|| {
            // Days since 1899-12-30 with 12 decimals (86 ns).
            const UNIX_DAY: u128 = 25_569;
            let scaled = u128::from(frame.ts_ns) * 1_000_000_000_000 / 86_400_000_000_000;
            let (days, frac) = (scaled / 1_000_000_000_000 + UNIX_DAY, scaled % 1_000_000_000_000);
            let _ = write!(
                out,
                ";$FILEVERSION=2.1\n;$STARTTIME={days}.{frac:012}\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n;\n;   Generated by cotui\n;\n;   Message   Time    Type ID     Rx/Tx\n;   Number    Offset  |    Bus    [hex]  |  Reserved\n;   |         [ms]    |    |      |      |  |  Data Length Code\n;   |         |       |    |      |      |  |  |    Data [hex] ...\n;---+-- ------+------ +- --+-- ----+--- +- -+ -+-- -+ -- -- -- -- -- -- --\n"
            );
            frame.ts_ns
        });
        self.number += 1;
        let us = frame.ts_ns.saturating_sub(start) / 1000;
        let bus = channel(frame.iface, iface);
        let dir = if frame.flags.has(Flags::TX) { "Tx" } else { "Rx" };
        let _ = write!(out, "{:>7} {:>9}.{:03} ", self.number, us / 1000, us % 1000);
        if frame.flags.has(Flags::ERR) {
            let _ = writeln!(out, "ER {bus:>2} {:>8} {dir}", "");
            return;
        }
        let kind = match (
            frame.flags.has(Flags::FD),
            frame.flags.has(Flags::BRS),
            frame.flags.has(Flags::ESI),
        ) {
            (true, false, false) => "FD",
            (true, true, false) => "FB",
            (true, false, true) => "FE",
            (true, true, true) => "BI",
            _ if frame.flags.has(Flags::RTR) => "RR",
            _ => "DT",
        };
        let id = if frame.flags.has(Flags::EXT) {
            format!("{:08X}", frame.id)
        } else {
            format!("{:04X}", frame.id)
        };
        let dlc = if frame.flags.has(Flags::FD) {
            crate::frame::fd_dlc_at_least(frame.len)
        } else {
            classic_dlc(frame)
        };
        let _ = write!(out, "{kind} {bus:>2} {id:>8} {dir} -  {dlc:<4}");
        if !frame.flags.has(Flags::RTR) && frame.len > 0 {
            out.push(' ');
            push_bytes(out, frame.payload());
        }
        out.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Interfaces;
    use crate::log::{Format, LogReader, Outcome};

    fn frames() -> Vec<Frame> {
        let mut v = Vec::new();
        let mut f = Frame {
            ts_ns: 1_700_000_000_000_100_000,
            id: 0x181,
            len: 2,
            ..Frame::default()
        };
        f.data[..2].copy_from_slice(&[0x11, 0x22]);
        v.push(f);
        let mut e = Frame {
            ts_ns: f.ts_ns + 1_100_000,
            id: 0x1AB_CDEF,
            len: 8,
            iface: 1,
            ..f
        };
        e.flags.set(Flags::EXT | Flags::TX, true);
        v.push(e);
        let mut r = Frame {
            ts_ns: f.ts_ns + 2_200_000,
            id: 0x701,
            len: 1,
            ..Frame::default()
        };
        r.flags.set(Flags::RTR, true);
        v.push(r);
        let mut d = Frame {
            ts_ns: f.ts_ns + 3_300_000,
            id: 0x123,
            len: 12,
            ..Frame::default()
        };
        d.flags.set(Flags::FD | Flags::FDF | Flags::BRS, true);
        d.data[11] = 0xCC;
        v.push(d);
        v
    }

    fn read_back(text: &str) -> (Format, Vec<Frame>, Interfaces) {
        let mut r = LogReader::new(text.as_bytes()).unwrap();
        let mut out = Vec::new();
        while let Some((line, o)) = r.next_line().unwrap() {
            match o {
                Outcome::Frame(f) => out.push(f),
                Outcome::Skip(_) => {}
                Outcome::Warning(w) => panic!("line {line}: {w}\n{text}"),
            }
        }
        (r.format(), out, r.interfaces().clone())
    }

    #[test]
    fn asc_and_trc_read_back_to_the_same_frames() {
        let names = ["can0", "can1"];
        let (mut asc, mut trc) = (String::new(), String::new());
        let (mut a, mut t) = (AscWriter::new(), TrcWriter::new());
        for f in frames() {
            a.write_line(&mut asc, &f, names[f.iface as usize]);
            t.write_line(&mut trc, &f, names[f.iface as usize]);
        }
        a.finish(&mut asc);
        assert!(asc.starts_with("date Tue Nov 14 22:13:20.000 2023\n"), "{asc}");
        for (text, format, t0) in [(&asc, Format::Asc, 0), (&trc, Format::Trc, 0)] {
            let (got_format, got, ifaces) = read_back(text);
            assert_eq!(got_format, format);
            let want = frames();
            assert_eq!(got.len(), want.len(), "{text}");
            for (g, w) in got.iter().zip(&want) {
                let shifted = g.ts_ns + t0;
                assert!(
                    shifted.abs_diff(w.ts_ns) < 1000,
                    "{format:?}: {} vs {}",
                    shifted,
                    w.ts_ns
                );
                assert_eq!(
                    (ifaces.name(g.iface), g.id, g.flags.0, g.len, g.payload()),
                    (names[w.iface as usize], w.id, w.flags.0, w.len, w.payload()),
                    "{format:?}"
                );
            }
        }
    }
}
