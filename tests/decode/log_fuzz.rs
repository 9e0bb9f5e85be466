//! Property tests of the log parsers: no input makes them panic, and every valid frame
//! survives writer -> parser unchanged.

use cotui::frame::{Flags, Frame, Interfaces};
use cotui::log::writer::{LogWriter, Timestamps};
use cotui::log::{Format, Line, LogReader, asc, candump, csv, peak_csv, savvycan, screen, trc};
use proptest::prelude::*;

const SAMPLES: &[&str] = &[
    "(1436509052.249713) vcan0 044#2A366C2BBA",
    "(1700000000.000001)   can0 7FF#R8_9 T",
    "(1700000000.123456789) can0 123##5112233445566778899AABBCC",
    "(1.0) can0 20000004#000C000000000000",
    "(1.000000) can0 123#11.22.33_9",
    "  can0  20000004   [8]  00 0C 00 00 00 00 00 00   ERRORFRAME",
    " (2023-11-14 22:13:20.500000)  can0  RX B E  124  [02]  33 44",
    "  can0  321   {B}  11 22 33 44 55 66 77 88",
    "   0.176544 CANFD   1 Rx        305  fdMsg  1 0 9 12 11 22 33 44 55 66 77 88 99 AA BB CC   130000  130     3000 0 0",
    "   0.002000 2  1ABCDEFx        Tx   d F 01 02 03 04 05 06 07 08  Length = 0",
    "base dec  timestamps relative",
    "date Tue Mar 5 10:00:00.000 am 2024",
    "date Sam Sep 30 15:06:13.191 2017",
    "Begin Triggerblock Tue Nov 14 22:13:20.0 2023",
    "   0.015991 CAN 1 Status:chip status error passive - TxErr: 132 RxErr: 0",
    "     1)      1841  0001    8  00 01 02 03 04 05 06 07",
    "     3)      1346.0  Warng  FFFFFFFF  4  00 00 00 08  BUSHEAVY",
    "     1)      1.500 3  Tx         0300 -  1  BB",
    "      2         0.200 FB  2  18FF0102 Tx -  9    00 01 02 03 04 05 06 07 08 09 0A 0B",
    "      4         0.400 ST  1           Rx    00 04 00 00",
    "      5         0.500 ER  1           Rx    04 00 02 00 00",
    "      6       500.000 EC  1           Rx    00 80",
    "     4)      1349.8  Error      0100  3  00 19 08",
    "     2)      1842  0008    4  ERROR 00 19 08 08",
    ";$STARTTIME=45244.9258101852",
    ";$COLUMNS=N,O,T,B,I,d,R,L,D",
    "1700000000.123456,0x181,0,0,0,2,ESI=",
    "2.5,0x7ff,0,0,0,12,AAECAwQFBgcICQoL",
    "1,1841.300,1,Rx,DT,0181,-,2,11,22,,",
    "2;0,200;2;Tx;FB;18FF0102;-;12;00;01;02;03;04;05;06;07;08;09;0A;0B",
    "3\t0.300\t1\tRx\tRR\t0701\t-\t1",
    "4,100.000,1,Rx,ST,-,-,4,00,04,00,00",
    "6,0.600,1,Rx,EC,-,-,2,02,81",
    "\"Number\",\"Time\",\"Bus\",\"Direction\",\"Type\",\"ID\",\"Reserved\",\"Length\",\"D0\"",
    "      7       0.700 EC  1         - Rx -  2    02 81",
];

/// PEAK CSV lines that set a parser's delimiter and columns before the line under test.
const PEAK_CSV_HEADERS: &[&str] = &[
    "Number;Time;Bus;Direction;Type;ID;Reserved;Length;D0",
    "type,id,time,len,d0",
    "1\t0.1\t1\tRx\tDT\t0701\t-\t0",
];

/// TRC header lines that put a parser in each version's layout.
const TRC_VERSIONS: &[&str] = &[
    ";$FILEVERSION=1.1",
    ";$FILEVERSION=1.2",
    ";$FILEVERSION=1.3",
    ";$FILEVERSION=2.0",
    ";$FILEVERSION=2.1",
];

/// ASC header lines that give a parser a date (times become absolute) or relative times.
const ASC_HEADERS: &[&str] = &["date Fri Dec 31 11:59:59.999 pm 9999", "base hex  timestamps relative"];

/// Runs every parser on `line`; the result does not matter, only that it returns.
fn parse_all(line: &[u8]) {
    let mut ifaces = Interfaces::default();
    let _ = candump::Parser::new().parse_line(line, &mut ifaces);
    let mut s = screen::Parser::new();
    s.set_delta(true);
    let _ = s.parse_line(line, &mut ifaces);
    let _ = screen::Parser::new().parse_line(line, &mut ifaces);
    let _ = asc::Parser::new().parse_line(line, &mut ifaces);
    let _ = candump::parse_compact(line);
    let _ = csv::Parser::new().parse_line(line, &mut ifaces);
    let _ = trc::Parser::new().parse_line(line, &mut ifaces);
    for header in [
        "Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2",
        "Time Stamp,ID,Extended,Bus,LEN,D1",
    ] {
        let mut p = savvycan::Parser::new();
        let _ = p.parse_line(header.as_bytes(), &mut ifaces);
        let _ = p.parse_line(line, &mut ifaces);
    }
    let _ = peak_csv::Parser::new().parse_line(line, &mut ifaces);
    for header in PEAK_CSV_HEADERS {
        let mut p = peak_csv::Parser::new();
        let _ = p.parse_line(header.as_bytes(), &mut ifaces);
        let _ = p.parse_line(line, &mut ifaces);
    }
    for header in ASC_HEADERS {
        let mut a = asc::Parser::new();
        let _ = a.parse_line(header.as_bytes(), &mut ifaces);
        let _ = a.parse_line(line, &mut ifaces);
    }
    for header in TRC_VERSIONS {
        let mut t = trc::Parser::new();
        let _ = t.parse_line(header.as_bytes(), &mut ifaces);
        let _ = t.parse_line(line, &mut ifaces);
    }
}

#[derive(Debug, Clone, Copy)]
enum Edit {
    Set(usize, u8),
    Insert(usize, u8),
    Remove(usize),
    Truncate(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    let byte = prop_oneof![
        Just(b'#'),
        Just(b'.'),
        Just(b'_'),
        Just(b' '),
        Just(b')'),
        Just(b'R'),
        Just(b'F'),
        Just(b'9'),
        Just(b'['),
        any::<u8>()
    ];
    prop_oneof![
        (any::<usize>(), byte.clone()).prop_map(|(i, b)| Edit::Set(i, b)),
        (any::<usize>(), byte).prop_map(|(i, b)| Edit::Insert(i, b)),
        any::<usize>().prop_map(Edit::Remove),
        any::<usize>().prop_map(Edit::Truncate),
    ]
}

fn apply(line: &mut Vec<u8>, e: Edit) {
    let n = line.len();
    match e {
        Edit::Set(i, b) if n > 0 => line[i % n] = b,
        Edit::Insert(i, b) => line.insert(i % (n + 1), b),
        Edit::Remove(i) if n > 0 => {
            line.remove(i % n);
        }
        Edit::Truncate(i) => line.truncate(i % (n + 1)),
        _ => {}
    }
}

/// Valid frames as candump can log them.
fn frame() -> impl Strategy<Value = Frame> {
    let data = proptest::collection::vec(any::<u8>(), 64);
    (
        0u8..4,
        any::<bool>(),
        any::<u32>(),
        0u8..=64,
        0u8..16,
        any::<u8>(),
        data,
    )
        .prop_map(|(kind, ext, id, len, dlc, bits, data)| {
            let mut f = Frame::default();
            let classic_len = len % 9;
            match kind {
                0 | 1 => {
                    f.flags.set(Flags::EXT, ext);
                    f.id = if ext { id & 0x1FFF_FFFF } else { id & 0x7FF };
                    f.len = classic_len;
                    if classic_len == 8 && dlc > 8 {
                        f.raw_dlc = dlc;
                    }
                    f.flags.set(Flags::RTR, kind == 1);
                }
                2 => {
                    f.flags.set(Flags::EXT, ext);
                    f.id = if ext { id & 0x1FFF_FFFF } else { id & 0x7FF };
                    f.flags.set(Flags::FD, true);
                    f.flags.set(Flags::BRS, bits & 1 != 0);
                    f.flags.set(Flags::ESI, bits & 2 != 0);
                    f.flags.set(Flags::FDF, bits & 4 != 0);
                    f.len = len;
                }
                _ => {
                    f.flags.set(Flags::ERR, true);
                    f.id = id & 0x1FFF_FFFF;
                    f.len = classic_len;
                }
            }
            if !f.is_rtr() {
                let n = f.len as usize;
                f.data[..n].copy_from_slice(&data[..n]);
            }
            f
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        parse_all(&bytes);
        for format in [Format::Candump, Format::Screen, Format::Asc, Format::Trc, Format::Csv, Format::Savvycan, Format::PeakCsv] {
            let reader = LogReader::with_format(&bytes[..], format);
            for item in reader {
                item.unwrap();
            }
        }
    }

    #[test]
    fn mutated_valid_lines_never_panic(pick in 0..SAMPLES.len(), edits in proptest::collection::vec(edit(), 1..6)) {
        let mut line = SAMPLES[pick].as_bytes().to_vec();
        for e in edits {
            apply(&mut line, e);
        }
        parse_all(&line);
        // Whatever the candump parser accepts, it reads back the same after writing.
        let mut ifaces = Interfaces::default();
        if let Ok(Line::Frame(f)) = candump::parse_line(&line, &mut ifaces) {
            let mut out = String::new();
            LogWriter::new().nanos(true).direction(true).write_line(&mut out, &f, ifaces.name(f.iface));
            let mut again = Interfaces::default();
            let back = candump::parse_line(out.as_bytes(), &mut again);
            prop_assert_eq!(back, Ok(Line::Frame(Frame { iface: 0, ..f })), "{}", out);
        }
    }

    #[test]
    fn peak_csv_rows_read_back_their_frames(
        f in frame(),
        ms in 0u64..10_000_000_000,
        micros in 0u64..1000,
        delim in prop::sample::select(vec![",", ";", "\t"]),
        comma in any::<bool>(),
        bus in 1u32..20,
        tx: bool,
    ) {
        // What a PEAK CSV row holds: no error frames (read as data frames here), FD lengths
        // a DLC gives, FDF always set with FD.
        let mut f = f;
        f.flags.set(Flags::ERR, false);
        let fd = f.flags.0 & Flags::FD != 0;
        if fd {
            let len = [0u8, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64].into_iter().rfind(|&l| l <= f.len).unwrap_or(0);
            f.len = len;
            f.data[len as usize..].fill(0);
        } else if !f.is_ext() {
            f.id &= 0x7FF;
        }
        let mut want = f;
        want.flags.set(Flags::FDF, fd);
        want.flags.set(Flags::TX, tx);
        want.ts_ns = ms * 1_000_000 + micros * 1000;
        let kind = match (fd, want.flags.0 & Flags::BRS != 0, want.flags.0 & Flags::ESI != 0) {
            (false, ..) if f.is_rtr() => "RR",
            (false, ..) => "DT",
            (true, false, false) => "FD",
            (true, true, false) => "FB",
            (true, false, true) => "FE",
            (true, true, true) => "BI",
        };
        let id = if f.is_ext() { format!("{:08X}", f.id) } else { format!("{:04X}", f.id) };
        let length = if f.raw_dlc > 8 { f.raw_dlc } else { f.len };
        let mut time = format!("{ms}.{micros:03}");
        if comma && delim != "," {
            time = time.replace('.', ",");
        }
        let mut cells = vec![
            "7".to_string(), time, bus.to_string(), if tx { "Tx" } else { "Rx" }.to_string(),
            kind.to_string(), id, "-".to_string(), length.to_string(),
        ];
        if !f.is_rtr() {
            cells.extend(f.payload().iter().map(|b| format!("{b:02X}")));
        }
        let row = cells.join(delim);
        let mut ifaces = Interfaces::default();
        let got = peak_csv::Parser::new().parse_line(row.as_bytes(), &mut ifaces);
        prop_assert_eq!(got, Ok(Line::Frame(want)), "{}", row);
        prop_assert_eq!(ifaces.name(0), format!("can{}", bus - 1));
    }

    #[test]
    fn valid_frames_round_trip_through_writer_and_parser(
        f in frame(),
        secs in 0u64..18_000_000_000,
        ns in 0u64..1_000_000_000,
        nanos: bool,
        zero: bool,
        direction: bool,
        tx: bool,
        iface in "[a-z][a-z0-9]{0,14}",
        other in "[a-z][a-z0-9]{0,14}",
    ) {
        let mut f = f;
        f.ts_ns = secs * 1_000_000_000 + if nanos { ns } else { ns / 1000 * 1000 };
        f.flags.set(Flags::TX, direction && tx);
        let ts = if zero { Timestamps::ZeroBased } else { Timestamps::Absolute };
        let mut w = LogWriter::new().nanos(nanos).timestamps(ts).direction(direction).pad_to(&[&iface, &other]);
        let mut out = String::new();
        w.write_line(&mut out, &f, &iface);
        let mut ifaces = Interfaces::default();
        let parsed = candump::parse_line(out.as_bytes(), &mut ifaces);
        prop_assert_eq!(parsed, Ok(Line::Frame(f)), "{}", out);
        prop_assert_eq!(ifaces.name(0), iface.as_str());
    }
}
