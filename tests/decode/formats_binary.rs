//! Binary log formats against their real peers: python-can's `BLFWriter` writes BLF files
//! (zlib and plain containers, 29-bit, RTR, FD, error frames, two channels) and cotui
//! decodes exactly the frames written; damaged files decode around the damage with a
//! located warning; random and mutated bytes never make the reader panic.

use cotui::frame::Flags;
use cotui::log::Outcome;
use cotui::logio::reader::Reader;
use proptest::prelude::*;
use serde_json::Value;
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

/// Runs a python script with `args`; a missing python-can fails with how to fix it.
fn python(script: &str, args: &[&str]) -> String {
    let out = Command::new("python3")
        .args(["-c", script])
        .args(args)
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "python: {} (python-can missing? run scripts/install-test-deps.sh)",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Writes FRAMES to `path` with python-can's BLFWriter (`level` 0: plain containers).
fn write_blf(path: &Path, level: u32, container: usize) {
    let script = r#"
import can, json, sys
w = can.BLFWriter(sys.argv[1], compression_level=int(sys.argv[2]), max_container_size=int(sys.argv[3]))
for t, ch, i, ext, rtr, err, fd, brs, tx, dlc, data in json.loads(sys.argv[4]):
    w.on_message_received(can.Message(timestamp=t, channel=ch, arbitration_id=i, is_extended_id=ext,
        is_remote_frame=rtr, is_error_frame=err, is_fd=fd, bitrate_switch=brs, is_rx=not tx,
        dlc=dlc, data=bytes.fromhex(data)))
w.stop()
"#;
    python(
        script,
        &[
            &path.display().to_string(),
            &level.to_string(),
            &container.to_string(),
            FRAMES,
        ],
    );
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("formats_binary");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn decode_jsonl(path: &Path) -> (Vec<Value>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--format", "jsonl"])
        .arg(path)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (lines, String::from_utf8(out.stderr).unwrap())
}

/// Every frame of FRAMES, as cotui reads it from `path`: the interface, id, flags, data
/// and time (1 ns ticks after the header's millisecond start time) match what was written.
fn assert_frames(path: &Path) {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut r = Reader::open(file, None).unwrap();
    let frames: Vec<_> = r
        .by_ref()
        .map(|x| match x.unwrap() {
            (_, Outcome::Frame(f)) => f,
            other => panic!("not a frame: {other:?}"),
        })
        .collect();
    let want: Vec<Value> = serde_json::from_str(FRAMES).unwrap();
    assert_eq!(frames.len(), want.len());
    for (f, w) in frames.iter().zip(&want) {
        let w = w.as_array().unwrap();
        let name = r.interfaces().name(f.iface);
        assert_eq!(name, format!("can{}", w[1]), "{w:?}");
        let ts = w[0].as_f64().unwrap();
        assert!((f.seconds() - ts).abs() < 2e-6, "time {} for {ts}", f.seconds());
        let err = w[5].as_bool().unwrap();
        assert_eq!(f.is_err(), err, "{w:?}");
        if err {
            assert_eq!(f.id, 0x80, "an error frame is a generic bus error");
            continue;
        }
        assert_eq!(u64::from(f.id), w[2].as_u64().unwrap(), "{w:?}");
        assert_eq!(f.is_ext(), w[3].as_bool().unwrap());
        assert_eq!(f.is_rtr(), w[4].as_bool().unwrap());
        assert_eq!(f.is_fd(), w[6].as_bool().unwrap());
        assert_eq!(f.flags.has(Flags::BRS), w[7].as_bool().unwrap());
        assert_eq!(f.flags.has(Flags::TX), w[8].as_bool().unwrap());
        assert_eq!(u64::from(f.len), w[9].as_u64().unwrap());
        let hex: String = f.payload().iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(hex, w[10].as_str().unwrap());
    }
    assert_eq!((r.counts().frames, r.counts().warnings), (want.len() as u64, 0));
}

#[test]
fn python_can_blf_files_decode_to_the_frames_written() {
    for (name, level, container) in [
        ("zlib.blf", 6, 128 * 1024),
        ("plain.blf", 0, 128 * 1024),
        ("small.blf", 6, 100),
    ] {
        let path = tmp(name);
        write_blf(&path, level, container);
        assert_frames(&path);
    }
    // The command line reads it too: by content, whatever the file is called.
    let path = tmp("zlib.blf");
    let renamed = tmp("capture.log");
    std::fs::copy(&path, &renamed).unwrap();
    let (lines, stderr) = decode_jsonl(&renamed);
    assert_eq!(lines.len(), 7, "{stderr}");
    assert_eq!(lines[5]["label"], "Heartbeat node 1: Operational");
    assert_eq!(lines[1]["iface"], "can1");
}

#[test]
fn a_damaged_blf_object_is_a_located_warning_and_the_rest_decodes() {
    // One plain container: the objects lie as written in the file.
    let path = tmp("damaged.blf");
    write_blf(&path, 0, 128 * 1024);
    let mut bytes = std::fs::read(&path).unwrap();
    // The signature of the third frame object (after the container's and two frames').
    let lobjs: Vec<usize> = bytes
        .windows(4)
        .enumerate()
        .filter(|(_, w)| *w == b"LOBJ")
        .map(|(i, _)| i)
        .collect();
    assert_eq!(lobjs.len(), 8);
    let victim = lobjs[3];
    bytes[victim..victim + 4].copy_from_slice(b"XXXX");
    let damaged = tmp("damaged2.blf");
    std::fs::write(&damaged, &bytes).unwrap();
    let (lines, stderr) = decode_jsonl(&damaged);
    assert!(
        stderr.contains(&format!(
            "warning: byte {} of the unpacked objects (container at byte 144): no object signature",
            victim - 144 - 32
        )),
        "{stderr}"
    );
    assert_eq!(lines.len(), 6, "{stderr}");
    assert_eq!(
        lines[2]["id"], 1110,
        "the remote frame is lost, the FD frame after it decodes"
    );
    assert_eq!(lines.last().unwrap()["id"], 1537);
    // Cut short: the frames before the cut decode, and the cut is reported.
    let whole = std::fs::read(&path).unwrap();
    std::fs::write(&damaged, &whole[..whole.len() - 30]).unwrap();
    let (lines, stderr) = decode_jsonl(&damaged);
    assert_eq!(lines.len(), 6, "{stderr}");
    assert!(stderr.contains("cut short"), "{stderr}");
}

fn read_all(bytes: &[u8]) -> u64 {
    let mut r = Reader::open(bytes, None).unwrap();
    let n = r.by_ref().filter(|x| x.is_ok()).count();
    n as u64 + r.counts().frames
}

/// A seed file for mutations: plain containers (mutations reach the objects) or zlib ones.
fn sample_blf(zlib: bool) -> Vec<u8> {
    let path = tmp(if zlib {
        "fuzz_seed_zlib.blf"
    } else {
        "fuzz_seed_plain.blf"
    });
    if !path.exists() {
        write_blf(&path, if zlib { 6 } else { 0 }, 200);
    }
    std::fs::read(&path).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_after_the_blf_signature_never_panic(tail in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let mut bytes = b"LOGG".to_vec();
        bytes.extend_from_slice(&tail);
        read_all(&bytes);
    }

    #[test]
    fn mutated_blf_files_never_panic(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..12),
        cut in any::<usize>(),
        zlib in any::<bool>(),
    ) {
        let mut bytes = sample_blf(zlib);
        for (at, b) in edits {
            let i = at % bytes.len();
            bytes[i] = b;
        }
        bytes.truncate(4.max(cut % (bytes.len() + 1)));
        read_all(&bytes);
    }
}

#[test]
fn python_can_reads_cotuis_blf_back_to_the_same_frames() {
    let src = tmp("for_writer.blf");
    write_blf(&src, 6, 128 * 1024);
    let out = tmp("written_by_cotui.blf");
    let status = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--format", "blf", "-o"])
        .arg(&out)
        .arg(&src)
        .status()
        .unwrap();
    assert!(status.success());
    let script = r#"
import can, json, sys
r = can.BLFReader(sys.argv[1])
rows = [[m.timestamp, m.channel, m.arbitration_id, m.is_extended_id, m.is_remote_frame, m.is_error_frame,
         m.is_fd, m.bitrate_switch, not m.is_rx, m.dlc, m.data.hex()] for m in r]
print(json.dumps({"rows": rows, "objects": r.object_count, "start": r.start_timestamp}))
"#;
    let back: Value = serde_json::from_str(&python(script, &[&out.display().to_string()])).unwrap();
    let want: Vec<Value> = serde_json::from_str(FRAMES).unwrap();
    assert_eq!(back["objects"], want.len());
    assert_eq!(back["start"], 1700000000.001);
    let rows = back["rows"].as_array().unwrap();
    assert_eq!(rows.len(), want.len());
    for (got, w) in rows.iter().zip(&want) {
        let (got, w) = (got.as_array().unwrap(), w.as_array().unwrap());
        assert!(
            (got[0].as_f64().unwrap() - w[0].as_f64().unwrap()).abs() < 2e-6,
            "{got:?} {w:?}"
        );
        // Everything else as python-can wrote it; an RTR frame has no data bytes either way.
        assert_eq!(got[1..], w[1..], "{got:?}");
    }
}

/// `record --format blf` and a candump recording of the same bus at the same time:
/// python-can reads the BLF back frame for frame as the candump log has them, and the
/// header's totals are filled in.
#[tokio::test(start_paused = true)]
async fn a_blf_recording_holds_what_a_candump_recording_of_the_same_bus_holds() {
    use cotui::command::record::{Limits, LogFormat, WriteMode, open_output, record};
    let (log, blf) = (tmp("demo.log"), tmp("demo.blf"));
    for p in [&log, &blf] {
        let _ = std::fs::remove_file(p);
    }
    let demo = cotui::sim::demo::Demo::spawn(cotui::sim::Simulation::demo(), false);
    let limits = Limits {
        count: Some(80),
        duration_ms: None,
    };
    let mut a = open_output(log.to_str().unwrap(), WriteMode::New, LogFormat::Candump).unwrap();
    let mut b = open_output(blf.to_str().unwrap(), WriteMode::New, LogFormat::Blf).unwrap();
    let never = || std::future::pending::<()>();
    let bus = [("demo".to_string(), demo.bus.clone())];
    let (ra, rb) = tokio::join!(
        record(&bus, &mut a, limits, LogFormat::Candump, never(), |_| {}),
        record(&bus, &mut b, limits, LogFormat::Blf, never(), |_| {}),
    );
    assert_eq!((ra.unwrap().frames, rb.unwrap().frames), (80, 80));
    drop((a, b));
    let script = r#"
import can, sys
r = can.BLFReader(sys.argv[1])
for m in r:
    print("(%.6f) can%d %03X#%s" % (m.timestamp, m.channel, m.arbitration_id, m.data.hex().upper()))
print(r.object_count, r.file_size)
"#;
    let back = python(script, &[&blf.display().to_string()]);
    let mut back: Vec<&str> = back.lines().collect();
    let totals = back.pop().unwrap();
    let size = std::fs::metadata(&blf).unwrap().len();
    assert_eq!(totals, format!("80 {size}"));
    let ours = std::fs::read_to_string(&log).unwrap();
    let ours: Vec<&str> = ours.lines().collect();
    assert_eq!(back.len(), 80);
    for (got, want) in back.iter().zip(&ours) {
        // python-can's float seconds may be 1 µs off the candump log's; compare the rest.
        let (got_t, got_rest) = got.split_once(' ').unwrap();
        let (want_t, want_rest) = want.split_once(' ').unwrap();
        // The bus `demo` is the file's first channel (python-can counts it as channel 0).
        assert_eq!(got_rest, want_rest.replacen("demo ", "can0 ", 1));
        let t = |s: &str| s.trim_matches(['(', ')']).parse::<f64>().unwrap();
        assert!((t(got_t) - t(want_t)).abs() < 2e-6, "{got} vs {want}");
    }
}
