//! The log formats against python-can, the peer that writes them: files written by its
//! `ASCWriter`, `TRCWriter` (1.0 and 2.1) and `CSVWriter` from one set of frames (11- and
//! 29-bit, remote, CAN FD, an error frame, both directions, two channels) decode to exactly
//! the frames each format holds: count, order, id, flags, data, interface, and the time
//! within the format's resolution.

use std::process::Command;

use cotui::frame::{Flags, Frame};
use cotui::log::{Format, LogReader, Outcome};

/// The frames, as python-can `Message` arguments (the time is added to 1700000000).
const MESSAGES: &str = r#"[
    dict(timestamp=0.000100, arbitration_id=0x181, is_extended_id=False, data=[0x11, 0x22], channel=0),
    dict(timestamp=0.001200, arbitration_id=0x1ABCDEF, is_extended_id=True, data=[1, 2, 3, 4, 5, 6, 7, 8], channel=1),
    dict(timestamp=0.002300, arbitration_id=0x701, is_extended_id=False, is_remote_frame=True, dlc=1, channel=0),
    dict(timestamp=0.003400, arbitration_id=0x123, is_extended_id=False, is_fd=True, bitrate_switch=True, data=list(range(12)), channel=0),
    dict(timestamp=0.004500, arbitration_id=0x4, is_extended_id=False, is_error_frame=True, data=[0, 0x20, 0, 0, 0, 0, 0x84, 0], channel=0),
    dict(timestamp=0.005600, arbitration_id=0x605, is_extended_id=False, data=[0x40, 0x17, 0x10, 0, 0, 0, 0, 0], is_rx=False, channel=0),
]"#;

/// One frame as the test compares it: µs since the first frame, interface, id, flags,
/// length (a remote frame's DLC), data.
#[derive(Debug, PartialEq)]
struct Seen {
    us: i64,
    iface: String,
    id: u32,
    flags: u8,
    len: u8,
    data: Vec<u8>,
}

/// The frames as written, in the `Seen` shape (times since the first frame).
fn written() -> Vec<Seen> {
    let s = |us, iface: &str, id, flags, data: &[u8]| Seen {
        us,
        iface: iface.to_string(),
        id,
        flags,
        len: data.len() as u8,
        data: data.to_vec(),
    };
    let fd: Vec<u8> = (0..12).collect();
    vec![
        s(0, "can0", 0x181, 0, &[0x11, 0x22]),
        s(1100, "can1", 0x1AB_CDEF, Flags::EXT, &[1, 2, 3, 4, 5, 6, 7, 8]),
        Seen {
            len: 1,
            ..s(2200, "can0", 0x701, Flags::RTR, &[])
        },
        s(3300, "can0", 0x123, Flags::FD | Flags::FDF | Flags::BRS, &fd),
        s(4400, "can0", 0x4, Flags::ERR, &[0, 0x20, 0, 0, 0, 0, 0x84, 0]),
        s(5500, "can0", 0x605, Flags::TX, &[0x40, 0x17, 0x10, 0, 0, 0, 0, 0]),
    ]
}

/// Writes the messages with `writer` (a python expression of a writer on `path`) and
/// returns the file's bytes.
fn python_can_file(name: &str, writer: &str) -> Vec<u8> {
    let dir = std::env::temp_dir().join(format!("cotui-pycan-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let script = format!(
        "import can, logging\nlogging.disable(logging.WARNING)\nfrom can.io.trc import TRCFileVersion\n\
         path = {path:?}\nw = {writer}\n\
         for m in {MESSAGES}:\n    m['timestamp'] += 1700000000\n    w.on_message_received(can.Message(**m))\nw.stop()\n",
        path = path.to_str().unwrap()
    );
    let out = Command::new("python3")
        .args(["-c", &script])
        .output()
        .expect("python3 runs (scripts/install-test-deps.sh installs python-can)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    bytes
}

/// What cotui reads from `bytes`: the detected format, the frames, and the first frame's
/// absolute time in ns.
fn read(bytes: &[u8]) -> (Format, Vec<Seen>, u64) {
    let mut r = LogReader::new(bytes).unwrap();
    let mut frames: Vec<(Frame, String)> = Vec::new();
    while let Some((line, outcome)) = r.next_line().unwrap() {
        match outcome {
            Outcome::Frame(f) => frames.push((f, r.interfaces().name(f.iface).to_string())),
            Outcome::Skip(_) => {}
            Outcome::Warning(w) => panic!("line {line}: {w}"),
        }
    }
    let t0 = frames.first().map_or(0, |(f, _)| f.ts_ns);
    let seen = frames
        .into_iter()
        .map(|(f, iface)| Seen {
            us: (f.ts_ns as i64 - t0 as i64) / 1000,
            iface,
            id: f.id,
            flags: f.flags.0,
            len: f.len,
            data: f.payload().to_vec(),
        })
        .collect();
    (r.format(), seen, t0)
}

/// `got` is `want` with times within `tolerance_us`.
fn assert_frames(what: &str, got: &[Seen], want: &[Seen], tolerance_us: i64) {
    assert_eq!(got.len(), want.len(), "{what}: {got:#?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g.us - w.us).abs() <= tolerance_us, "{what}: {g:?} vs {w:?}");
        let (g, w) = (
            (&g.iface, g.id, g.flags, g.len, &g.data),
            (&w.iface, w.id, w.flags, w.len, &w.data),
        );
        assert_eq!(g, w, "{what}");
    }
}

#[test]
fn asc_from_python_can() {
    let (format, got, _) = read(&python_can_file("x.asc", "can.ASCWriter(path)"));
    assert_eq!(format, Format::Asc);
    let mut want = written();
    // ASC's ErrorFrame has no detail: a bus error.
    want[4].id = 0x80;
    want[4].data = vec![0; 8];
    assert_frames("ASC", &got, &want, 1);
}

#[test]
fn trc_2_1_and_1_0_from_python_can() {
    // python-can's TRCWriter leaves out remote, FD and error frames.
    let mut want = written();
    want.retain(|s| s.flags & (Flags::RTR | Flags::FD | Flags::ERR) == 0);
    let (format, got, t0) = read(&python_can_file("x.trc", "can.TRCWriter(path)"));
    assert_eq!(format, Format::Trc);
    assert_frames("TRC 2.1", &got, &want, 1);
    // $STARTTIME (days since 1899) puts the first frame at its time, within 1 µs.
    assert!(t0.abs_diff(1_700_000_000_000_100_000) <= 1000, "{t0}");

    let (format, got, _) = read(&python_can_file(
        "x1.trc",
        "can.TRCWriter(path)\nw.file_version = TRCFileVersion.V1_0",
    ));
    assert_eq!(format, Format::Trc);
    // 1.0 has no bus column (all on can0), no direction, and whole milliseconds.
    for s in &mut want {
        s.iface = "can0".into();
        s.flags &= !Flags::TX;
    }
    assert_frames("TRC 1.0", &got, &want, 1000);
}

/// python-can's TRC 2.1 (`N,O,T,B,I,d,R,L,D` lines), turned row by row into the PEAK CSV
/// that PEAK-Converter makes of a trace (its header copied, then `Number, Time, Bus,
/// Direction, Type, ID, Reserved, Length, D0..`, with `,` or with `;` and decimal commas),
/// reads as exactly the same frames as the TRC, at the same times.
#[test]
fn peak_csv_of_python_cans_trc_reads_as_the_trc() {
    let trc = python_can_file("p.trc", "can.TRCWriter(path)");
    let (format, from_trc, t0) = read(&trc);
    assert_eq!(format, Format::Trc);
    assert_eq!(
        from_trc.len(),
        3,
        "python-can's TRCWriter leaves out remote, FD and error frames"
    );
    for delim in [",", ";"] {
        let mut csv = String::new();
        for line in String::from_utf8_lossy(&trc).lines() {
            if line.starts_with(';') {
                csv += line;
            } else {
                let t: Vec<&str> = line.split_whitespace().collect();
                let time = if delim == ";" {
                    t[1].replace('.', ",")
                } else {
                    t[1].to_string()
                };
                let mut row = vec![t[0], &time, t[3], t[5], t[2], t[4], t[6], t[7]];
                row.extend(&t[8..]);
                csv += &row.join(delim);
            }
            csv += "\r\n";
        }
        let (format, got, csv_t0) = read(csv.as_bytes());
        assert_eq!(format, Format::PeakCsv, "{csv}");
        assert_eq!(got, from_trc, "{delim}: {csv}");
        assert_eq!(csv_t0, t0, "{delim}");
    }
}

#[test]
fn csv_from_python_can() {
    let (format, got, t0) = read(&python_can_file("x.csv", "can.CSVWriter(path)"));
    assert_eq!(format, Format::Csv);
    // CSV keeps no channel, direction or BRS.
    let mut want = written();
    for s in &mut want {
        s.iface = "can0".into();
        s.flags &= !(Flags::TX | Flags::BRS);
    }
    assert_frames("CSV", &got, &want, 1);
    assert!(t0.abs_diff(1_700_000_000_000_100_000) <= 1000, "{t0}");
}

/// The frames of [`MESSAGES`] as a candump log, for cotui to convert.
const CANDUMP: &str = "(1700000000.000100) can0 181#1122
(1700000000.001200) can1 01ABCDEF#0102030405060708 T
(1700000000.002300) can0 701#R1
(1700000000.003400) can0 123##1000102030405060708090A0B
(1700000000.004500) can0 20000004#0020000000008400
(1700000000.005600) can0 605#4017100000000000 T
";

/// python-can's reader of `kind` (asc or trc) on what `cotui decode --format KIND` made of
/// [`CANDUMP`]: one line per message, `time id ext rtr fd brs err rx channel dlc data`.
fn python_can_reads_cotui(kind: &str) -> Vec<(f64, String)> {
    let dir = std::env::temp_dir().join(format!("cotui-pycan-out-{}-{kind}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (log, out) = (dir.join("in.log"), dir.join(format!("out.{kind}")));
    std::fs::write(&log, CANDUMP).unwrap();
    let run = crate::run::cotui(
        &[
            "decode",
            "--format",
            kind,
            log.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let reader = if kind == "asc" { "ASCReader" } else { "TRCReader" };
    let script = format!(
        "import can, logging\nlogging.disable(logging.WARNING)\nfor m in can.{reader}({:?}):\n    \
         print(f'{{m.timestamp:.6f}} {{m.arbitration_id:x}} {{int(m.is_extended_id)}} {{int(m.is_remote_frame)}} \
         {{int(m.is_fd)}} {{int(m.bitrate_switch)}} {{int(m.is_error_frame)}} {{int(m.is_rx)}} {{m.channel}} {{m.dlc}} {{m.data.hex()}}')\n",
        out.to_str().unwrap()
    );
    let py = Command::new("python3").args(["-c", &script]).output().expect("python3");
    assert!(py.status.success(), "{}", String::from_utf8_lossy(&py.stderr));
    std::fs::remove_dir_all(&dir).ok();
    String::from_utf8_lossy(&py.stdout)
        .lines()
        .map(|l| {
            let (t, rest) = l.split_once(' ').unwrap();
            (t.parse().unwrap(), rest.trim_end().to_string())
        })
        .collect()
}

fn assert_messages(kind: &str, got: &[(f64, String)], want: &[(f64, &str)]) {
    assert_eq!(got.len(), want.len(), "{kind}: {got:#?}");
    for ((gt, g), (wt, w)) in got.iter().zip(want) {
        assert!((gt - wt).abs() < 2e-6, "{kind}: time {gt} vs {wt}");
        assert_eq!(g, w, "{kind}");
    }
}

#[test]
fn python_can_reads_cotuis_asc_and_trc() {
    // ASC times are since the `date` line (the first frame's time to the ms); channel 1 is python-can's channel 0; the error
    // frame is ASC's ErrorFrame (no detail).
    assert_messages(
        "asc",
        &python_can_reads_cotui("asc"),
        &[
            (0.0001, "181 0 0 0 0 0 1 0 2 1122"),
            (0.0012, "1abcdef 1 0 0 0 0 0 1 8 0102030405060708"),
            (0.0023, "701 0 1 0 0 0 1 0 1"),
            (0.0034, "123 0 0 1 1 0 1 0 12 000102030405060708090a0b"),
            (0.0045, "0 1 0 0 0 1 1 0 0"),
            (0.0056, "605 0 0 0 0 0 0 0 8 4017100000000000"),
        ],
    );
    // TRC 2.1 times are absolute ($STARTTIME); python-can keeps the bus number (1-based),
    // the FD DLC (9 for 12 bytes), and skips ER lines.
    let t = 1_700_000_000.0;
    assert_messages(
        "trc",
        &python_can_reads_cotui("trc"),
        &[
            (t + 0.0001, "181 0 0 0 0 0 1 1 2 1122"),
            (t + 0.0012, "1abcdef 1 0 0 0 0 0 2 8 0102030405060708"),
            (t + 0.0023, "701 0 1 0 0 0 1 1 1"),
            (t + 0.0034, "123 0 0 1 1 0 1 1 9 000102030405060708090a0b"),
            (t + 0.0056, "605 0 0 0 0 0 0 1 8 4017100000000000"),
        ],
    );
}

/// The times python-can's `ASCReader` gives the messages of `asc` (read in UTC), in ns.
fn python_can_asc_times(asc: &[u8]) -> Vec<u64> {
    let path = std::env::temp_dir().join(format!("cotui-pycan-times-{}.asc", std::process::id()));
    std::fs::write(&path, asc).unwrap();
    let script = format!(
        "import can, logging\nlogging.disable(logging.WARNING)\nfor m in can.ASCReader({:?}, relative_timestamp=False):\n    print(f'{{m.timestamp:.6f}}')\n",
        path.to_str().unwrap()
    );
    let py = Command::new("python3")
        .args(["-c", &script])
        .env("TZ", "UTC")
        .output()
        .expect("python3");
    std::fs::remove_file(&path).ok();
    assert!(py.status.success(), "{}", String::from_utf8_lossy(&py.stderr));
    String::from_utf8_lossy(&py.stdout)
        .lines()
        .map(|l| {
            let (s, us) = l.split_once('.').unwrap();
            s.parse::<u64>().unwrap() * 1_000_000_000 + us.parse::<u64>().unwrap() * 1000
        })
        .collect()
}

#[test]
fn asc_date_line_gives_the_absolute_times_python_can_reads() {
    // python-can's ASCWriter writes a `date` line (the time of writing), a `Begin
    // Triggerblock` line with the first message's date and times since it; its ASCReader
    // (`relative_timestamp=False`) adds them, as cotui does (in UTC).
    let asc = python_can_file("dated.asc", "can.ASCWriter(path)");
    assert!(asc.starts_with(b"date "), "{}", String::from_utf8_lossy(&asc));
    let theirs = python_can_asc_times(&asc);
    let mut r = LogReader::new(&asc[..]).unwrap();
    let mut ours = Vec::new();
    while let Some((_, outcome)) = r.next_line().unwrap() {
        if let Outcome::Frame(f) = outcome {
            ours.push(f.ts_ns);
        }
    }
    assert_eq!(ours.len(), theirs.len());
    // The first message's own time (python-can writes the trigger block's date to 0.1 s).
    assert!(ours[0].abs_diff(1_700_000_000_000_100_000) < 100_000_000, "{}", ours[0]);
    for (o, t) in ours.iter().zip(&theirs) {
        assert!(o.abs_diff(*t) <= 1000, "{o} vs python-can {t}");
    }
}

#[test]
fn decode_jsonl_times_of_an_asc_are_its_date_plus_the_offsets() {
    let dir = std::env::temp_dir().join(format!("cotui-asc-date-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rel.asc");
    // Relative timestamps: each time is added to the last (the event line's too).
    std::fs::write(
        &path,
        "date Tue Mar 5 10:00:00.000 am 2024\nbase hex  timestamps relative\ninternal events logged\nBegin Triggerblock Tue Mar 5 10:00:00.000 am 2024\n   0.001000 1  701             Rx   d 1 00\n   0.500000 Start of measurement\n   0.000250 1  181             Rx   d 2 11 22\nEnd TriggerBlock\n",
    )
    .unwrap();
    let run = crate::run::cotui(&["decode", "--format", "jsonl", path.to_str().unwrap()], None);
    std::fs::remove_dir_all(&dir).ok();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let times: Vec<String> = String::from_utf8_lossy(&run.stdout)
        .lines()
        .map(|l| {
            let t = &l[l.find("\"t\":").unwrap() + 4..];
            t[..t.find(',').unwrap()].to_string()
        })
        .collect();
    // 2024-03-05 10:00:00 UTC is 1709632800.
    assert_eq!(times, ["1709632800.001000000", "1709632800.501250000"]);
}
