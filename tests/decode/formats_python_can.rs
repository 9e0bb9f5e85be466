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
