//! Differential tests against can-utils' `log2asc` and `asc2log` (Debian package
//! `can-utils`). They run without a CAN bus. When the tools are missing these tests fail
//! and say how to install them.

use std::io::Write;
use std::process::{Command, Stdio};

use cotui::frame::{Flags, Frame};
use cotui::log::asc::CAN_ERR_BUSERROR;
use cotui::log::{Format, LogReader, Outcome};

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Runs a can-utils tool with `input` on stdin and returns its stdout.
fn run(tool: &str, args: &[&str], input: &[u8]) -> Vec<u8> {
    let mut child = match Command::new(tool)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
    {
        Ok(c) => c,
        Err(e) => panic!(
            "cannot run `{tool}` ({e}): these differential tests need can-utils; install it with `apt-get install can-utils`"
        ),
    };
    child.stdin.take().unwrap().write_all(input).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{tool} {args:?} failed: {:?}", out.status);
    out.stdout
}

/// A frame as both formats can carry it: time since the first frame in µs, interface name
/// and the frame fields, with FDF cleared (old can-utils drop it, new ones add it).
#[derive(Debug, PartialEq, Eq)]
struct Seen {
    rel_us: u64,
    iface: String,
    id: u32,
    flags: u8,
    len: u8,
    raw_dlc: u8,
    data: Vec<u8>,
}

/// Every frame of `input` read as `format`, and the number of malformed lines.
fn frames(input: &[u8], format: Format) -> (Vec<Seen>, u64) {
    let mut reader = LogReader::with_format(input, format);
    let mut raw: Vec<(Frame, String)> = Vec::new();
    while let Some((_, outcome)) = reader.next_line().unwrap() {
        match outcome {
            Outcome::Frame(f) => raw.push((f, reader.interfaces().name(f.iface).to_string())),
            Outcome::Skip(_) | Outcome::Warning(_) => {}
        }
    }
    let t0 = raw.first().map_or(0, |(f, _)| f.ts_ns);
    let seen = raw
        .into_iter()
        .map(|(f, iface)| Seen {
            rel_us: (f.ts_ns - t0) / 1000,
            iface,
            id: f.id,
            flags: f.flags.0 & !Flags::FDF,
            len: f.len,
            raw_dlc: f.raw_dlc,
            data: f.payload().to_vec(),
        })
        .collect();
    (seen, reader.counts().warnings)
}

/// What ASC keeps of an error frame: a generic bus error without direction.
fn as_asc_error(mut s: Seen) -> Seen {
    if s.flags & Flags::ERR != 0 {
        s.id = CAN_ERR_BUSERROR;
        s.flags = Flags::ERR;
        s.len = 8;
        s.data = vec![0; 8];
    }
    s
}

#[test]
fn log2asc_output_reads_as_the_same_frames() {
    let log = std::fs::read(fixture("candump_diff.log")).unwrap();
    let asc = run("log2asc", &["can0", "can1"], &log);
    let (from_log, log_warnings) = frames(&log, Format::Candump);
    let from_log: Vec<Seen> = from_log.into_iter().map(as_asc_error).collect();
    let (from_asc, asc_warnings) = frames(&asc, Format::Asc);
    assert_eq!((from_log.len(), log_warnings, asc_warnings), (13, 0, 0));
    assert_eq!(from_asc, from_log, "log2asc output:\n{}", String::from_utf8_lossy(&asc));
}

#[test]
fn asc2log_agrees_with_our_asc_reader() {
    let vector = std::fs::read(fixture("vector.asc")).unwrap();
    let converted = run(
        "log2asc",
        &["can0", "can1"],
        &std::fs::read(fixture("candump_diff.log")).unwrap(),
    );
    // vector.asc has one malformed line (`ZZ` as a data byte) that asc2log drops too.
    for (name, asc, malformed) in [("vector.asc", vector, 1), ("log2asc output", converted, 0)] {
        let log = run("asc2log", &[], &asc);
        let (ours, warnings) = frames(&asc, Format::Asc);
        assert_eq!(warnings, malformed, "{name}");
        let (theirs, log_warnings) = frames(&log, Format::Candump);
        assert_eq!(log_warnings, 0, "{name}: our reader rejected asc2log output");
        assert!(ours.len() >= 8, "{name}: too few frames");
        assert_eq!(
            ours,
            theirs,
            "{name}: asc2log wrote:\n{}",
            String::from_utf8_lossy(&log)
        );
    }
}
