//! `cotui decode --format pcapng`: Wireshark (`tshark -r`) reads the file back frame for
//! frame — time to the nanosecond, interface, id, flags, length and data — for classic,
//! 29-bit, remote, error and CAN FD frames on several interfaces, as cotui's own log
//! reader parsed them.

use cotui::frame::{Flags, Frame};
use cotui::log::{LogReader, Outcome};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Frames of a log with their interface names, as cotui's reader parses them.
fn frames(path: &Path) -> Vec<(String, Frame)> {
    let file = std::io::BufReader::new(std::fs::File::open(path).expect("fixture"));
    let mut reader = LogReader::new(file).expect("reader");
    let mut out = Vec::new();
    while let Some((_, outcome)) = reader.next_line().expect("read") {
        if let Outcome::Frame(f) = outcome {
            out.push((reader.interfaces().name(f.iface).to_string(), f));
        }
    }
    out
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

fn export(log: &Path, name: &str) -> PathBuf {
    let out = std::env::temp_dir().join(format!("cotui-pcapng-{}-{name}.pcapng", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--format", "pcapng", "-o"])
        .arg(&out)
        .arg(log)
        .output()
        .expect("run cotui");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    out
}

const FIELDS: [&str; 12] = [
    "frame.time_epoch",
    "frame.interface_name",
    "can.id",
    "can.flags.xtd",
    "can.flags.rtr",
    "can.flags.err",
    "can.len",
    "canfd.flags.brs",
    "canfd.flags.esi",
    "data.data",
    "frame.packet_flags_direction",
    "can.err.ctrl",
];

/// tshark's fields per frame (empty string = absent).
fn tshark(pcapng: &Path) -> Vec<Vec<String>> {
    let mut cmd = Command::new("tshark");
    // No heuristic sub-dissector may take the payload away from `data`.
    cmd.args(["--disable-protocol", "autosar-nm", "-r"])
        .arg(pcapng)
        .args(["-T", "fields", "-E", "occurrence=f"]);
    for f in FIELDS {
        cmd.args(["-e", f]);
    }
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("tshark is required for this test (scripts/install-test-deps.sh installs it): {e}"));
    assert!(
        out.status.success(),
        "tshark failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split('\t').map(str::to_string).collect())
        .collect()
}

/// What tshark should print for a frame, field by field.
fn expected(iface: &str, f: &Frame) -> Vec<String> {
    let b = |on: bool| if on { "1" } else { "0" }.to_string();
    let time = format!("{}.{:09}", f.ts_ns / 1_000_000_000, f.ts_ns % 1_000_000_000);
    let hex: String = f.payload().iter().map(|b| format!("{b:02x}")).collect();
    let dir = if f.flags.has(Flags::TX) {
        "0x00000002"
    } else {
        "0x00000001"
    };
    if f.is_err() {
        // Error frames: the id is the error class (here CAN_ERR_CTRL), the data its details.
        assert_eq!(f.id, 0x004, "fixture error frames are controller problems");
        let e = String::new;
        return vec![
            time,
            iface.into(),
            e(),
            e(),
            e(),
            b(true),
            f.len.to_string(),
            e(),
            e(),
            e(),
            dir.into(),
            b(true),
        ];
    }
    // tshark dissects an FD frame as `canfd` (BRS, ESI; no RTR or error flag fields).
    let (rtr, err, brs, esi) = if f.is_fd() {
        (
            String::new(),
            String::new(),
            b(f.flags.has(Flags::BRS)),
            b(f.flags.has(Flags::ESI)),
        )
    } else {
        (b(f.is_rtr()), b(false), String::new(), String::new())
    };
    // tshark shows the zero bytes of a remote request's record as data; cotui sends none.
    let data = if f.is_rtr() && f.len > 0 {
        "00".repeat(f.len as usize)
    } else {
        hex
    };
    vec![
        time,
        iface.into(),
        f.id.to_string(),
        b(f.is_ext()),
        rtr,
        err,
        f.len.to_string(),
        brs,
        esi,
        data,
        dir.into(),
        String::new(),
    ]
}

fn round_trip(name: &str) -> usize {
    let log = fixture(name);
    let ours = frames(&log);
    let path = export(&log, name);
    let theirs = tshark(&path);
    std::fs::remove_file(&path).ok();
    assert_eq!(
        theirs.len(),
        ours.len(),
        "{name}: tshark saw a different number of frames"
    );
    for (i, ((iface, f), got)) in ours.iter().zip(&theirs).enumerate() {
        assert_eq!(got, &expected(iface, f), "{name} frame {}: {f:?}", i + 1);
    }
    ours.len()
}

#[test]
fn classic_extended_remote_error_and_fd_frames() {
    // 11/29-bit, RTR with and without length, raw DLC, an error frame, FD with BRS, 64 bytes.
    assert_eq!(round_trip("candump_single.log"), 17);
}

#[test]
fn two_interfaces_and_direction() {
    // can0 and vcan10 interleaved, received and sent (candump -x R/T), an FD frame.
    let n = round_trip("candump_multi_x.log");
    assert_eq!(n, 6);
}

#[test]
fn nanosecond_timestamps_survive() {
    assert!(round_trip("candump_ns.log") >= 3);
}

#[test]
fn a_whole_decoded_log() {
    assert!(round_trip("cia301_mix.log") > 10);
}

#[test]
fn refuses_to_write_binary_to_a_terminal() {
    // `script` gives cotui a terminal for stdout.
    let log = fixture("candump_single.log");
    let cmd = format!(
        "{} decode --format pcapng {}; echo \"exit=$?\"",
        env!("CARGO_BIN_EXE_cotui"),
        log.display()
    );
    let out = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .expect("script (util-linux)");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("not writing it to a terminal"), "{text}");
    assert!(text.contains("exit=1"), "{text}");
    assert!(
        !text.contains('\u{FFFD}'),
        "no binary bytes reached the terminal: {text}"
    );
}

mod fuzz {
    use cotui::frame::{Flags, Frame};
    use cotui::output::pcapng::PcapngWriter;
    use proptest::prelude::*;

    fn frame() -> impl Strategy<Value = (u8, Frame)> {
        (
            0u8..3,
            any::<u64>(),
            any::<u32>(),
            any::<u8>(),
            0u8..=64,
            0u8..16,
            prop::collection::vec(any::<u8>(), 64),
        )
            .prop_map(|(iface, ts_ns, id, flags, len, raw_dlc, data)| {
                let mut f = Frame {
                    ts_ns,
                    id: id & 0x1FFF_FFFF,
                    flags: Flags(flags),
                    len,
                    raw_dlc,
                    ..Frame::default()
                };
                f.data.copy_from_slice(&data);
                (iface, f)
            })
    }

    fn u32le(b: &[u8], at: usize) -> u32 {
        u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
    }

    proptest! {
        /// Any frame, even one no bus produces, gives well-formed blocks: lengths agree at
        /// both ends, everything is 4-byte aligned, one packet per frame, one interface
        /// description per name, and packets name an interface described before them.
        #[test]
        fn any_frames_give_well_formed_blocks(frames in prop::collection::vec(frame(), 0..40)) {
            let names = ["can0", "vcan10", "x"];
            let mut w = PcapngWriter::new(Vec::new()).unwrap();
            for (i, f) in &frames {
                w.write_frame(names[*i as usize], f).unwrap();
            }
            let b = w.into_inner();
            let (mut at, mut idbs, mut epbs) = (0usize, 0u32, 0usize);
            while at < b.len() {
                let (kind, len) = (u32le(&b, at), u32le(&b, at + 4) as usize);
                prop_assert!(len >= 12 && len % 4 == 0 && at + len <= b.len());
                prop_assert_eq!(u32le(&b, at + len - 4) as usize, len);
                match kind {
                    0x0A0D_0D0A => prop_assert_eq!(at, 0),
                    1 => idbs += 1,
                    6 => {
                        prop_assert!(u32le(&b, at + 8) < idbs);
                        let caplen = u32le(&b, at + 20);
                        prop_assert!(caplen == 16 || caplen == 72);
                        epbs += 1;
                    }
                    other => prop_assert!(false, "block type {other:#x}"),
                }
                at += len;
            }
            prop_assert_eq!(epbs, frames.len());
            let distinct: std::collections::HashSet<u8> = frames.iter().map(|(i, _)| *i).collect();
            prop_assert_eq!(idbs as usize, distinct.len());
        }
    }
}

/// `record --format pcapng` and a candump recording of the same bus at the same time: tshark
/// reads the pcapng back frame for frame as the candump log has them.
#[tokio::test(start_paused = true)]
async fn a_pcapng_recording_holds_what_a_candump_recording_of_the_same_bus_holds() {
    use cotui::command::record::{Limits, LogFormat, WriteMode, open_output, record};
    let dir = std::env::temp_dir().join(format!("cotui-rec-pcapng-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (log, cap) = (dir.join("demo.log"), dir.join("demo.pcapng"));
    let demo = cotui::sim::demo::Demo::spawn(cotui::sim::Simulation::demo(), false);
    let limits = Limits {
        count: Some(80),
        duration_ms: None,
    };
    let mut a = open_output(log.to_str().unwrap(), WriteMode::New, LogFormat::Candump).unwrap();
    let mut b = open_output(cap.to_str().unwrap(), WriteMode::New, LogFormat::Pcapng).unwrap();
    let never = || std::future::pending::<()>();
    let bus = [("demo".to_string(), demo.bus.clone())];
    let (ra, rb) = tokio::join!(
        record(&bus, &mut a, limits, LogFormat::Candump, never(), |_| {}),
        record(&bus, &mut b, limits, LogFormat::Pcapng, never(), |_| {}),
    );
    assert_eq!((ra.unwrap().frames, rb.unwrap().frames), (80, 80));
    drop((a, b));
    let ours = frames(&log);
    let theirs = tshark(&cap);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!((ours.len(), theirs.len()), (80, 80));
    for (i, ((iface, f), got)) in ours.iter().zip(&theirs).enumerate() {
        // The candump log has microseconds, the pcapng the bus's nanoseconds.
        let mut got = got.clone();
        let keep = got[0].len() - 3;
        got[0].replace_range(keep.., "000");
        assert_eq!(got, expected(iface, f), "frame {}: {f:?}", i + 1);
    }
}
