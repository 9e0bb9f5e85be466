//! The fast line paths against the general parsers: on any line of its format, valid or
//! mutated, a fast path must leave the line to the general parser or read exactly the
//! frame (and the bytes) the general parser reads, in the same parser state (property
//! tests, one a format).

use super::{Line, ParseError, asc, candump, csv, peak_csv, savvycan, screen, trc};
use crate::frame::FD_LENS;
use crate::frame::{Frame, Interfaces};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// A line parser with a fast path.
trait FastAndGeneral {
    /// The fast path on `buf`.
    fn fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize>;
    /// The general parser on one line.
    fn general(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError>;
}

macro_rules! fast_and_general {
    ($($parser:ty),*) => {$(
        impl FastAndGeneral for $parser {
            fn fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
                self.parse_fast(buf, ifaces, frame)
            }
            fn general(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
                self.parse_line(line, ifaces)
            }
        }
    )*};
}

fast_and_general!(
    candump::Parser,
    screen::Parser,
    asc::Parser,
    trc::Parser,
    csv::Parser,
    peak_csv::Parser,
    savvycan::Parser
);

/// Bytes the mutations put into lines: blanks, line ends, digits, letters and signs.
const NOISE: &[u8] = b" \t\r\n09aAfFgGxX.,;#()[]-=+/rdRT\xFF";

/// Up to three mutations: (position, byte, 0 replace / 1 insert / 2 delete / 3 none).
fn mutations() -> impl Strategy<Value = Vec<(usize, u8, u8)>> {
    prop::collection::vec((any::<usize>(), prop::sample::select(NOISE), 0..4u8), 0..4)
}

/// `line` with `muts` applied.
fn mutate(line: &str, muts: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut v = line.as_bytes().to_vec();
    for &(at, b, kind) in muts {
        let at = at % (v.len() + 1);
        match kind {
            0 if at < v.len() => v[at] = b,
            1 => v.insert(at, b),
            2 if at < v.len() => {
                v.remove(at);
            }
            _ => {}
        }
    }
    v
}

/// Hex digits of `v`, `n` wide.
fn hex(v: u32, n: usize) -> String {
    format!("{v:0n$X}")
}

/// Data bytes as hex pairs, each after `gap` (one or more blanks).
fn spaced(bytes: &[u8], gap: &str) -> String {
    bytes.iter().map(|b| format!("{gap}{b:02X}")).collect()
}

/// Checks `line` (followed by `next` in the buffer) against both paths of two parsers
/// that `make` gives in the same state; `must` says the fast path must take the line.
fn agree<P: FastAndGeneral>(make: impl Fn() -> P, line: &[u8], next: &[u8], must: bool) -> Result<(), TestCaseError> {
    let (mut fast, mut general) = (make(), make());
    let (mut fast_ifaces, mut general_ifaces) = (Interfaces::default(), Interfaces::default());
    let buf = [line, next].concat();
    let mut frame = Frame::default();
    let taken = fast.fast(&buf, &mut fast_ifaces, &mut frame);
    prop_assert!(
        taken.is_some() || !must,
        "not taken: {:?}",
        String::from_utf8_lossy(line)
    );
    let Some(n) = taken else {
        return Ok(());
    };
    let claimed = &buf[..n];
    prop_assert_eq!(claimed.iter().filter(|&&b| b == b'\n').count(), 1);
    prop_assert_eq!(claimed.last(), Some(&b'\n'));
    prop_assert_eq!(
        general.general(claimed, &mut general_ifaces),
        Ok(Line::Frame(frame)),
        "{:?}",
        String::from_utf8_lossy(claimed)
    );
    prop_assert_eq!(fast_ifaces.names(), general_ifaces.names());
    // The state after the line is the same: the next line reads alike.
    prop_assert_eq!(
        fast.general(next, &mut fast_ifaces),
        general.general(next, &mut general_ifaces)
    );
    Ok(())
}

/// A `secs.frac` time with 1 to 9 fraction digits, its seconds zero-padded to up to 12
/// digits, and whether they are at most 10 digits (what the fast paths take).
fn times() -> impl Strategy<Value = (String, bool)> {
    let secs = prop_oneof![0u64..1000, 0u64..10_000_000_000, 0u64..100_000_000_000];
    (secs, 0u32..1_000_000_000, 1usize..10, 1usize..13).prop_map(|(secs, frac_ns, digits, width)| {
        let frac = frac_ns / 10u32.pow(9 - digits as u32);
        let ts = format!("{secs:0width$}.{frac:0digits$}");
        let fits = ts.len() - 1 - digits <= 10;
        (ts, fits)
    })
}

/// Standard base64 of `bytes`, with `=` padding.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let (mut out, mut acc, mut bits) = (String::new(), 0u32, 0);
    for &b in bytes {
        (acc, bits) = (acc << 8 | u32::from(b), bits + 8);
        while bits >= 6 {
            bits -= 6;
            out.push(ALPHABET[(acc >> bits & 63) as usize] as char);
        }
    }
    if bits > 0 {
        out.push(ALPHABET[(acc << (6 - bits) & 63) as usize] as char);
    }
    while out.len() % 4 != 0 {
        out.push('=');
    }
    out
}

/// A parser of `P` that has read `headers` (its state lines) with the general parser.
fn after<P: FastAndGeneral>(mut p: P, headers: &[&str]) -> P {
    let mut ifaces = Interfaces::default();
    for h in headers {
        let _ = p.general(h.as_bytes(), &mut ifaces);
    }
    p
}

proptest! {
        #[test]
        fn candump_lines_read_as_the_general_parser_reads_them(
            (ts, fits) in times(),
            iface in prop::sample::select(vec!["can0", "vcan1", "a-sixteen-bytes0", "seventeen-bytes-0", "\u{e9}th0"]),
            id in any::<u32>(),
            wide in any::<bool>(),
            data in prop::collection::vec(any::<u8>(), 0..10),
            crlf in any::<bool>(),
            muts in mutations(),
        ) {
            let id = if wide { hex(id & 0x3FFF_FFFF, 8) } else { hex(id % 0x900, 3) };
            let bytes: String = data.iter().map(|b| format!("{b:02X}")).collect();
            let line = format!("({ts}) {iface} {id}#{bytes}{}\n", if crlf { "\r" } else { "" });
            let must = muts.is_empty() && fits && data.len() <= 8 && (wide || id.as_str() <= "7FF");
            agree(candump::Parser::new, &mutate(&line, &muts), b"(1700000000.000002) can0 124#22\n", must)?;
        }

        #[test]
        fn screen_lines_read_as_the_general_parser_reads_them(
            (ts, fits) in times(),
            lead in prop::sample::select(vec!["", " ", "  "]),
            gap in prop::sample::select(vec![" ", "  ", "   "]),
            iface in prop::sample::select(vec!["can0", "vcan1", "a-sixteen-bytes0", "seventeen-bytes-0"]),
            id in any::<u32>(),
            wide in any::<bool>(),
            data in prop::collection::vec(any::<u8>(), 0..10),
            shown in 0usize..10,
            delta in any::<bool>(),
            muts in mutations(),
        ) {
            let id = if wide { hex(id & 0x3FFF_FFFF, 8) } else { hex(id % 0x900, 3) };
            let n = if shown < 3 { shown } else { data.len() };
            let line = format!("{lead}({ts}){gap}{iface}{gap}{id}{gap}[{n}]{}\n", spaced(&data, gap));
            let must = muts.is_empty() && !delta && fits && n == data.len() && n <= 8
                && (wide || id.as_str() <= "7FF");
            let make = || {
                let mut p = screen::Parser::new();
                p.set_delta(delta);
                p
            };
            agree(make, &mutate(&line, &muts), b" (1700000000.000002)  can0  124   [1]  22\n", must)?;
        }

        #[test]
        fn asc_lines_read_as_the_general_parser_reads_them(
            base in prop::sample::select(vec!["base hex  timestamps absolute", "base dec  timestamps absolute", "base hex  timestamps relative"]),
            date in prop::sample::select(vec!["", "date Tue Nov 14 22:13:20.000 2023"]),
            (ts, fits) in times(),
            lead in prop::sample::select(vec!["", " ", "   "]),
            channel in 0u32..70,
            id in any::<u32>(),
            ext in any::<bool>(),
            dir in prop::sample::select(vec!["Rx", "Tx", "TxRq"]),
            kind in prop::sample::select(vec!["d", "r"]),
            dlc in 0u32..16,
            data in prop::collection::vec(any::<u8>(), 8),
            short in any::<bool>(),
            tail in prop::sample::select(vec!["", " ", "  Length = 239910 BitCount = 124 ID = 1784"]),
            muts in mutations(),
        ) {
            let v = if ext { id & 0x3FFF_FFFF } else { id % 0x900 };
            let id = format!("{v:X}{}", if ext { "x" } else { "" });
            let n = (dlc as usize).min(8) - usize::from(short && dlc > 0);
            let line = format!("{lead}{ts} {channel}  {id:<15} {dir}   {kind} {dlc:x}{}{tail}\n", spaced(&data[..n], " "));
            let must = muts.is_empty() && base == "base hex  timestamps absolute" && fits
                && dir != "TxRq" && kind == "d" && !(short && dlc > 0)
                && v <= if ext { 0x1FFF_FFFF } else { 0x7FF };
            let make = || after(asc::Parser::new(), &[date, base]);
            agree(make, &mutate(&line, &muts), b"   1.000000 1  124             Rx   d 1 22\n", must)?;
        }

        #[test]
        fn trc_lines_read_as_the_general_parser_reads_them(
            version in prop::sample::select(vec!["2.1", "2.0", "1.1"]),
            columns in prop::sample::select(vec!["", "N,O,T,B,I,d,R,L,D", "N,O,T,I,d,l,D", "N,O,B,T,I,d,L,D"]),
            start in prop::sample::select(vec!["", ";$STARTTIME=45244.925925925925"]),
            number in 0u32..10_000_000,
            (ts, fits) in times(),
            kind in prop::sample::select(vec!["DT", "FD", "FB", "FE", "BI", "RR", "ST", "ER"]),
            bus in 0u32..70,
            id in any::<u32>(),
            wide in any::<bool>(),
            dir in prop::sample::select(vec!["Rx", "Tx"]),
            dlc in 0usize..16,
            data in prop::collection::vec(any::<u8>(), 64),
            short in any::<bool>(),
            gap in prop::sample::select(vec![" ", "  ", "    "]),
            muts in mutations(),
        ) {
            let fd = matches!(kind, "FD" | "FB" | "FE" | "BI");
            let n = if fd { usize::from(FD_LENS[dlc]) } else { dlc.min(8) } - usize::from(short && dlc > 0);
            let v = if wide { id & 0x3FFF_FFFF } else { id % 0x900 };
            let header = format!(";$FILEVERSION={version}");
            let cols = if columns.is_empty() { "N,O,T,B,I,d,R,L,D" } else { columns };
            let listed = format!(";$COLUMNS={columns}");
            let mut tokens = Vec::new();
            for c in cols.split(',') {
                tokens.push(match c {
                    "N" => number.to_string(),
                    "O" => ts.clone(),
                    "T" => kind.to_string(),
                    "B" => bus.to_string(),
                    "I" => hex(v, if wide { 8 } else { 4 }),
                    "d" => dir.to_string(),
                    "L" => dlc.to_string(),
                    "l" => n.to_string(),
                    "D" => spaced(&data[..n], gap)[gap.len().min(n * 3)..].to_string(),
                    _ => "-".to_string(),
                });
            }
            let line = format!("  {}\n", tokens.join(gap).trim_end());
            let must = muts.is_empty() && version != "1.1" && (version == "2.1" || !columns.is_empty())
                && fd | (kind == "DT") && !(short && dlc > 0) && fits
                && (cols != "N,O,T,I,d,l,D" || !fd || dlc <= 8)
                && v <= if wide { 0x1FFF_FFFF } else { 0x7FF };
            let make = || {
                let headers = [header.as_str(), start, if columns.is_empty() { "" } else { listed.as_str() }];
                after(trc::Parser::new(), &headers)
            };
            agree(make, &mutate(&line, &muts), b"      9         1.000 DT  1      0124 Rx -  1    22\n", must)?;
        }

        #[test]
        fn csv_lines_read_as_the_general_parser_reads_them(
            (ts, fits) in times(),
            prefix in any::<bool>(),
            id in any::<u32>(),
            flags in prop::collection::vec(prop::sample::select(vec!["0", "1"]), 3),
            data in prop::collection::vec(any::<u8>(), 0..13),
            dlc_off in 0u32..3,
            crlf in any::<bool>(),
            muts in mutations(),
        ) {
            let v = (id % 0x2100_0000) >> (id % 3 * 9);
            let dlc = data.len() as u32 + dlc_off;
            let line = format!(
                "{ts},{}{v:x},{},{dlc},{}{}\n",
                if prefix { "0x" } else { "" },
                flags.join(","),
                base64(&data),
                if crlf { "\r" } else { "" }
            );
            let must = muts.is_empty() && fits && flags.join(",") == "0,0,0"
                && v <= 0x7FF && data.len() <= 8 && dlc_off == 0;
            agree(csv::Parser::new, &mutate(&line, &muts), b"1700000000.000002,0x124,0,0,0,1,Ig==\n", must)?;
        }
        #[test]
        fn peak_csv_rows_read_as_the_general_parser_reads_them(
            first in prop::sample::select(vec!["names", "row", "none", "other names"]),
            delim in prop::sample::select(vec![",", ";", "\t"]),
            number in 0u32..10_000_000,
            (ts, fits) in times(),
            bus in 0u32..70,
            dir in prop::sample::select(vec!["Rx", "Tx"]),
            kind in prop::sample::select(vec!["DT", "DT", "FD", "RR", "ST"]),
            id in any::<u32>(),
            wide in any::<bool>(),
            len in 0usize..16,
            data in prop::collection::vec(any::<u8>(), 8),
            short in any::<bool>(),
            trailing in 0usize..4,
            crlf in any::<bool>(),
            muts in mutations(),
        ) {
            let d = delim;
            let v = if wide { id & 0x3FFF_FFFF } else { id % 0x900 };
            let n = len.min(8) - usize::from(short && len > 0);
            let mut cells = vec![
                number.to_string(), ts.clone(), bus.to_string(), dir.to_string(), kind.to_string(),
                hex(v, if wide { 8 } else { 4 }), "-".to_string(), len.to_string(),
            ];
            cells.extend(data[..n].iter().map(|b| format!("{b:02X}")));
            cells.extend(std::iter::repeat_n(String::new(), trailing));
            let line = format!("{}{}\n", cells.join(d), if crlf { "\r" } else { "" });
            let header = match first {
                "names" => ["Number", "Time", "Bus", "Direction", "Type", "ID", "Reserved", "Length", "D0"].join(d),
                "row" => ["1", "0.1", "1", "Rx", "DT", "0701", "-", "0"].join(d),
                "other names" => ["Time", "Type", "ID", "Length", "D0"].join(d),
                _ => String::new(),
            };
            let must = muts.is_empty() && matches!(first, "names" | "row") && kind == "DT" && fits
                && !(short && len > 0) && v <= if wide { 0x1FFF_FFFF } else { 0x7FF };
            let next = format!("{}\n", ["9", "1.000", "1", "Rx", "DT", "0124", "-", "1", "22"].join(d));
            let make = || after(peak_csv::Parser::new(), &[header.as_str()]);
            agree(make, &mutate(&line, &muts), next.as_bytes(), must)?;
        }
        #[test]
        fn savvycan_rows_read_as_the_general_parser_reads_them(
            header in prop::sample::select(vec![
                "Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8",
                "Time Stamp,ID,Extended,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8",
                "",
            ]),
            us in prop_oneof![0u64..1_000_000, 0u64..u64::MAX],
            id in any::<u32>(),
            wide in any::<bool>(),
            ext in prop::sample::select(vec!["true", "false", "1", "0", "yes"]),
            dir in prop::sample::select(vec!["Rx", "Tx", "rx"]),
            bus in prop_oneof![0u32..20, 0u32..2000],
            len in 0usize..13,
            data in prop::collection::vec(any::<u8>(), 12),
            padding in 0usize..12,
            crlf in any::<bool>(),
            muts in mutations(),
        ) {
            let v = if wide { id & 0x3FFF_FFFF } else { id % 0x900 };
            let mut cells = vec![
                us.to_string(), hex(v, if wide { 8 } else { 4 }), ext.to_string(), dir.to_string(),
                bus.to_string(), len.to_string(),
            ];
            if header.contains("Dir,Bus") {
            } else {
                cells.remove(3);
            }
            cells.extend(data[..len].iter().map(|b| format!("{b:02X}")));
            cells.extend(std::iter::repeat_n(String::new(), padding));
            let line = format!("{}{}\n", cells.join(","), if crlf { "\r" } else { "" });
            let ext_ok = ["true", "false", "1", "0"].contains(&ext);
            let is_ext = ext == "true" || ext == "1";
            let must = muts.is_empty() && header.contains("Dir,Bus") && ext_ok && dir != "rx"
                && us < u64::MAX / 1000 && bus < 1000 && len <= 8 && padding <= 8
                && v <= if is_ext { 0x1FFF_FFFF } else { 0x7FF };
            let make = || after(savvycan::Parser::new(), &[header]);
            agree(make, &mutate(&line, &muts), b"5,00000124,false,Rx,1,1,22,\n", must)?;
        }
}
