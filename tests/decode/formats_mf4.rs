//! ASAM MDF4 bus logging against its real peers: python-can's `MF4Writer` (through asammdf)
//! writes sorted files, plain (`##DT`), deflated and transposed-deflated (`##DZ`), of the
//! same frames as the BLF tests (29-bit, RTR, FD, error frames, two channels), and cotui
//! decodes exactly the frames written; an unsorted CANedge-shaped file (VLSD payloads) that
//! asammdf reads decodes to the frames asammdf reads; damaged blocks give a located
//! warning and the rest decodes; random and mutated bytes never make the reader panic.

use cotui::frame::{Flags, Frame};
use cotui::log::Outcome;
use cotui::logio::reader::Reader;
use proptest::prelude::*;
use serde_json::Value;
use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The frames python-can writes: (time, channel, id, extended, remote, error, fd, brs, tx,
/// dlc, data hex).
const FRAMES: &str = r#"[
 [1700000000.001, 0, 291, false, false, false, false, false, false, 3, "010203"],
 [1700000000.002, 1, 448585456, true, false, false, false, false, true, 8, "0909090909090909"],
 [1700000000.003, 0, 2047, false, true, false, false, false, false, 4, ""],
 [1700000000.004, 0, 1110, false, false, false, true, true, false, 12, "000102030405060708090a0b"],
 [1700000000.005, 0, 0, false, false, true, false, false, false, 0, ""],
 [1700000000.0061234, 0, 1793, false, false, false, false, false, false, 1, "05"],
 [1700000000.007, 1, 1537, false, false, false, true, false, false, 64, "a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5a5"]
]"#;

/// Runs a python script with `args`; a missing asammdf fails with how to fix it.
fn python(script: &str, args: &[&str]) -> String {
    let out = Command::new("python3")
        .args(["-c", script])
        .args(args)
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "python: {} (asammdf missing? run scripts/install-test-deps.sh)",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("formats_mf4");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Writes FRAMES with python-can's MF4Writer at compression levels 0 (`##DT`), 1 (`##DZ`
/// deflate) and 2 (`##DZ` transposed and deflated), to `l0.mf4` ... `l2.mf4`; once.
fn written() -> [PathBuf; 3] {
    let paths = [tmp("l0.mf4"), tmp("l1.mf4"), tmp("l2.mf4")];
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let script = r#"
import can, json, sys
for level in range(3):
    w = can.MF4Writer(sys.argv[1 + level], compression_level=level)
    for t, ch, i, ext, rtr, err, fd, brs, tx, dlc, data in json.loads(sys.argv[4]):
        w.on_message_received(can.Message(timestamp=t, channel=ch, arbitration_id=i, is_extended_id=ext,
            is_remote_frame=rtr, is_error_frame=err, is_fd=fd, bitrate_switch=brs, is_rx=not tx,
            dlc=dlc, data=bytes.fromhex(data)))
    w.stop()
"#;
        let p: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        python(script, &[&p[0], &p[1], &p[2], FRAMES]);
    });
    paths
}

fn read(bytes: Vec<u8>) -> (Vec<(String, Frame)>, Vec<String>) {
    let mut r = Reader::open_file(Cursor::new(bytes), None, BufReader::new).unwrap();
    let (mut frames, mut warnings) = (Vec::new(), Vec::new());
    while let Some((_, o)) = r.next_line().unwrap() {
        match o {
            Outcome::Frame(f) => frames.push((r.interfaces().name(f.iface).to_string(), f)),
            Outcome::Warning(w) => warnings.push(w),
            Outcome::Skip(_) => {}
        }
    }
    (frames, warnings)
}

/// The frames of FRAMES at `rows` as cotui read them: interface, id, flags, data, time
/// (python-can stores float seconds after the header's start: within 1 µs).
fn assert_frames(frames: &[(String, Frame)], rows: &[usize]) {
    let want: Vec<Value> = serde_json::from_str(FRAMES).unwrap();
    assert_eq!(frames.len(), rows.len(), "{frames:?}");
    for ((name, f), &row) in frames.iter().zip(rows) {
        let w = want[row].as_array().unwrap();
        assert_eq!(*name, format!("can{}", w[1]), "{w:?}");
        let ts = w[0].as_f64().unwrap();
        assert!((f.seconds() - ts).abs() < 1e-6, "time {} for {ts}", f.seconds());
        assert_eq!(f.is_err(), w[5].as_bool().unwrap(), "{w:?}");
        assert_eq!(f.flags.has(Flags::TX), w[8].as_bool().unwrap());
        if f.is_err() {
            assert_eq!(f.id, 0x80, "an error frame is a generic bus error");
            continue;
        }
        assert_eq!(u64::from(f.id), w[2].as_u64().unwrap(), "{w:?}");
        assert_eq!(f.is_ext(), w[3].as_bool().unwrap());
        assert_eq!(f.is_rtr(), w[4].as_bool().unwrap());
        assert_eq!(f.is_fd(), w[6].as_bool().unwrap());
        assert_eq!(f.flags.has(Flags::BRS), w[7].as_bool().unwrap());
        assert_eq!(u64::from(f.len), w[9].as_u64().unwrap());
        let hex: String = f.payload().iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(hex, w[10].as_str().unwrap());
    }
}

#[test]
fn python_can_mf4_files_decode_to_the_frames_written() {
    for path in written() {
        let (frames, warnings) = read(std::fs::read(&path).unwrap());
        assert_eq!(warnings, Vec::<String>::new(), "{}", path.display());
        // Three sorted data groups (data, error, remote frames) merged back in time order.
        assert_frames(&frames, &[0, 1, 2, 3, 4, 5, 6]);
    }
    // The command line reads it by content, whatever the file is called, and by name.
    let renamed = tmp("capture.log");
    std::fs::copy(&written()[2], &renamed).unwrap();
    for args in [
        &["decode", "--format", "jsonl"][..],
        &["decode", "--format", "jsonl", "--input-format", "mf4"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(args)
            .arg(&renamed)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let lines: Vec<Value> = String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 7);
        assert_eq!(lines[5]["label"], "Heartbeat node 1: Operational");
        assert_eq!(lines[1]["iface"], "can1");
    }
}

#[test]
fn an_mf4_file_on_standard_input_is_refused_with_the_reason() {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "-"])
        .stdin(std::fs::File::open(&written()[0]).unwrap())
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "cotui decode: -: an MF4 file is read by random access: give its path, not standard input or a pipe\n"
    );
}

/// An unsorted file as CAN loggers write it: records of a `CAN_DataFrame` group (time in
/// µs through a linear conversion, bit 31 of the ID for 29-bit ids) after the VLSD records
/// holding their payloads, in one data group. asammdf reads the same frames from it.
#[test]
fn an_unsorted_mf4_file_with_vlsd_payloads_decodes_as_asammdf_reads_it() {
    let path = tmp("unsorted.mf4");
    let frames = r#"[[1000, 1, 1793, false, false, false, false, "05"],
        [2500, 2, 448585456, true, true, true, true, "000102030405060708090a0b"],
        [3000, 1, 1409, false, false, false, false, "4000100000000000"]]"#;
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/decode/mf4/unsorted.py");
    let out = Command::new("python3")
        .arg(script)
        .arg(&path)
        .arg(frames)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let peer = r#"
import asammdf, json, sys
m = asammdf.MDF(sys.argv[1])
get = lambda n: m.get("CAN_DataFrame." + n, group=0)
d = get("DataBytes")
# asammdf pads the payloads to the longest: cut each to its DataLength.
print(json.dumps([[t, int(c), int(i) & 0x1FFFFFFF, bytes(b[:n]).hex()] for t, c, i, n, b in
    zip(d.timestamps, get("BusChannel").samples, get("ID").samples, get("DataLength").samples, d.samples)]))
"#;
    let want: Vec<(f64, u64, u32, String)> =
        serde_json::from_str(&python(peer, &[&path.display().to_string()])).unwrap();
    let (got, warnings) = read(std::fs::read(&path).unwrap());
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(got.len(), want.len());
    for ((name, f), (t, ch, id, hex)) in got.iter().zip(&want) {
        let data: String = f.payload().iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!((name.clone(), f.id, data), (format!("can{ch}"), *id, hex.clone()));
        assert!((f.seconds() - 1_700_000_000.0 - t).abs() < 1e-6);
    }
    assert!(got[1].1.is_ext() && got[1].1.is_fd() && got[1].1.flags.has(Flags::BRS | Flags::TX));
}

/// The file offset of the `n`th block with id `id`.
fn nth_block(bytes: &[u8], id: &[u8], n: usize) -> usize {
    (0..bytes.len().saturating_sub(24))
        .step_by(8)
        .filter(|&i| &bytes[i..i + 4] == id)
        .nth(n)
        .unwrap()
}

#[test]
fn a_damaged_mf4_block_is_a_located_warning_and_the_rest_decodes() {
    // Deflated: the first ##DZ holds the data frames; spoil its zlib data.
    let mut bytes = std::fs::read(&written()[1]).unwrap();
    let dz = nth_block(&bytes, b"##DZ", 0);
    for b in &mut bytes[dz + 48..dz + 56] {
        *b ^= 0x5A;
    }
    let (frames, warnings) = read(bytes);
    assert_eq!(
        warnings,
        [format!(
            "byte {dz}: ##DZ zlib data damaged or cut short; its records are lost"
        )]
    );
    assert_frames(&frames, &[2, 4]);
    // A channel group's block spoiled: that group is passed over with where, the rest reads.
    let mut bytes = std::fs::read(&written()[0]).unwrap();
    let cg = nth_block(&bytes, b"##CG", 0);
    bytes[cg..cg + 4].copy_from_slice(b"XXXX");
    let (frames, warnings) = read(bytes);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with(&format!("byte {cg}: no block id")),
        "{warnings:?}"
    );
    assert_eq!(frames.len(), 2, "the error and remote frames of the other groups");
    // The data frames' ##DT block 10 bytes shorter: its last record is cut short and said;
    // the records before it and the other groups decode.
    let mut bytes = std::fs::read(&written()[0]).unwrap();
    let dt = nth_block(&bytes, b"##DT", 0);
    let len = u64::from_le_bytes(bytes[dt + 8..dt + 16].try_into().unwrap());
    bytes[dt + 8..dt + 16].copy_from_slice(&(len - 10).to_le_bytes());
    let (frames, warnings) = read(bytes);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].ends_with(": record 5 cut short at the end of its data"),
        "{warnings:?}"
    );
    assert_frames(&frames, &[0, 1, 2, 3, 4, 5]);
}

fn read_all(bytes: Vec<u8>) -> u64 {
    let mut r = Reader::open_file(Cursor::new(bytes), None, BufReader::new).unwrap();
    let n = r.by_ref().filter(|x| x.is_ok()).count();
    n as u64 + r.counts().frames
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_after_the_mdf_file_id_never_panic(tail in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let mut bytes = b"MDF     4.10    ".to_vec();
        bytes.extend_from_slice(&tail);
        read_all(bytes);
    }

    #[test]
    fn mutated_mf4_files_never_panic(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..12),
        cut in any::<usize>(),
        level in 0usize..3,
    ) {
        let mut bytes = std::fs::read(&written()[level]).unwrap();
        for (at, b) in edits {
            let i = at % bytes.len();
            bytes[i] = b;
        }
        bytes.truncate(8.max(cut % (bytes.len() + 1)));
        read_all(bytes);
    }
}

/// A damaged link that loops (a data group whose next is itself) is read once, with where.
#[test]
fn a_loop_of_links_is_read_once() {
    let mut bytes = std::fs::read(&written()[0]).unwrap();
    let dg = nth_block(&bytes, b"##DG", 0);
    bytes[dg + 24..dg + 32].copy_from_slice(&(dg as u64).to_le_bytes());
    let (frames, warnings) = read(bytes);
    assert_eq!(
        warnings,
        [format!("byte {dg}: a data group linked twice (a loop); not read again")]
    );
    assert_frames(&frames, &[0, 1, 3, 5, 6]);
}
