//! Differential test against Wireshark's CANopen dissector (tshark).
//!
//! A candump log is converted to pcap (LINKTYPE_CAN_SOCKETCAN) and dissected by
//! `tshark -d can.subdissector,canopen`; every frame Wireshark decodes must agree
//! with `cotui decode --format jsonl` on the fields both tools produce. Where
//! Wireshark is known to be wrong or silent, the test says so and checks that it
//! really is (so a Wireshark fix shows up here).

use cotui::frame::Frame;
use cotui::log::{LogReader, Outcome};
use serde_json::Value;
use std::io::Write;
use std::process::Command;

const LINKTYPE_CAN_SOCKETCAN: u32 = 227;

/// Frames of a log, in order, parsed by cotui's own reader.
fn frames(path: &str) -> Vec<Frame> {
    let file = std::io::BufReader::new(std::fs::File::open(path).expect("fixture"));
    let mut reader = LogReader::new(file).expect("reader");
    let mut out = Vec::new();
    while let Some((_, outcome)) = reader.next_line().expect("read") {
        if let Outcome::Frame(f) = outcome {
            out.push(f);
        }
    }
    out
}

/// A pcap file with one SocketCAN record per frame (can_id in network byte order).
fn pcap(frames: &[Frame]) -> Vec<u8> {
    let mut p = Vec::new();
    p.extend_from_slice(&0xa1b2_c3d4u32.to_le_bytes());
    p.extend_from_slice(&2u16.to_le_bytes());
    p.extend_from_slice(&4u16.to_le_bytes());
    p.extend_from_slice(&[0; 8]);
    p.extend_from_slice(&65535u32.to_le_bytes());
    p.extend_from_slice(&LINKTYPE_CAN_SOCKETCAN.to_le_bytes());
    for f in frames {
        let mut id = f.id;
        if f.is_ext() {
            id |= 0x8000_0000;
        }
        if f.is_rtr() {
            id |= 0x4000_0000;
        }
        if f.is_err() {
            id |= 0x2000_0000;
        }
        let mut rec = id.to_be_bytes().to_vec();
        rec.extend_from_slice(&[f.len, 0, 0, 0]);
        let mut data = f.payload().to_vec();
        data.resize(8, 0);
        rec.extend_from_slice(&data);
        p.extend_from_slice(&((f.ts_ns / 1_000_000_000) as u32).to_le_bytes());
        p.extend_from_slice(&((f.ts_ns / 1000 % 1_000_000) as u32).to_le_bytes());
        p.extend_from_slice(&(rec.len() as u32).to_le_bytes());
        p.extend_from_slice(&(rec.len() as u32).to_le_bytes());
        p.extend_from_slice(&rec);
    }
    p
}

const FIELDS: [&str; 16] = [
    "frame.number",
    "canopen.function_code",
    "canopen.node_id",
    "canopen.nmt_ctrl.cd",
    "canopen.nmt_ctrl.node_id",
    "canopen.nmt_guard.state",
    "canopen.nmt_guard.toggle",
    "canopen.sync.counter",
    "canopen.em.err_code",
    "canopen.em.err_reg",
    "canopen.sdo.main_idx",
    "canopen.sdo.sub_idx",
    "canopen.sdo.abort_code",
    "canopen.time_stamp_ms",
    "canopen.time_stamp_days",
    "canopen.lss.cs",
];

/// tshark's fields per frame, as integers (None = field absent).
fn tshark(pcap_path: &std::path::Path) -> Vec<Vec<Option<u64>>> {
    let mut cmd = Command::new("tshark");
    cmd.args([
        "-r",
        pcap_path.to_str().unwrap(),
        "-d",
        "can.subdissector,canopen",
        "-T",
        "fields",
    ]);
    cmd.args(["-E", "separator=|", "-E", "occurrence=f"]);
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
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            l.split('|')
                .map(|v| {
                    let v = v.trim();
                    if v.is_empty() {
                        None
                    } else if let Some(h) = v.strip_prefix("0x") {
                        u64::from_str_radix(h, 16).ok()
                    } else {
                        v.parse().ok()
                    }
                })
                .collect()
        })
        .collect()
}

fn cotui_jsonl(path: &str) -> Vec<Value> {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--format", "jsonl", path])
        .output()
        .expect("run cotui");
    assert!(out.status.success());
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("json line"))
        .collect()
}

fn kind_of_function_code(fc: u64, id: u64) -> &'static str {
    match fc {
        0x0 => "nmt",
        0x1 if id == 0x80 => "sync",
        0x1 => "emcy",
        0x2 => "time",
        0x3 | 0x5 | 0x7 | 0x9 => "tpdo",
        0x4 | 0x6 | 0x8 | 0xA => "rpdo",
        0xB => "sdo_tx",
        0xC => "sdo_rx",
        0xE => "heartbeat",
        0xF => "lss",
        _ => "other",
    }
}

fn nmt_cs(name: &str) -> u64 {
    match name {
        "start" => 0x01,
        "stop" => 0x02,
        "pre_operational" => 0x80,
        "reset_node" => 0x81,
        "reset_communication" => 0x82,
        _ => 0xFFFF,
    }
}

fn hb_state(name: &str) -> u64 {
    match name {
        "boot_up" => 0,
        "stopped" => 4,
        "operational" => 5,
        "pre_operational" => 0x7F,
        _ => 0xFFFF,
    }
}

#[test]
fn cotui_agrees_with_wireshark_canopen_dissector() {
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/cia301_mix.log");
    let compared = agree_with_wireshark(fixture, "mix");
    assert!(compared > 40, "only {compared} frames compared");
}

/// The captures pasted in public issues and docs (`../shared/realworld/logs/`, beside the
/// checkout): every frame line parses, and Wireshark agrees frame by frame.
#[test]
fn real_world_logs_parse_whole_and_agree_with_wireshark() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/logs");
    let mut logs: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (the shared real-world files sit beside the checkout)",
                dir.display()
            )
        })
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "txt" || x == "log" || x == "asc"))
        .collect();
    logs.sort();
    assert!(logs.len() >= 8, "{logs:?}");
    let mut total = 0;
    for (i, path) in logs.iter().enumerate() {
        let path = path.to_str().unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["decode", "--summary", path])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let whole =
            !err.contains("warning:") && (!err.contains("malformed lines") || err.contains(" 0 malformed lines"));
        assert!(out.status.success() && whole, "{path}: {err}");
        total += agree_with_wireshark(path, &format!("rw{i}"));
    }
    assert!(total > 150, "only {total} frames compared");
}

/// Compares cotui's JSONL with Wireshark's dissection of the log at `path`, frame by frame;
/// returns how many frames Wireshark decoded.
fn agree_with_wireshark(path: &str, tag: &str) -> usize {
    let frames = frames(path);
    let ours = cotui_jsonl(path);
    assert_eq!(frames.len(), ours.len());
    let dir = std::env::temp_dir().join(format!("cotui-ws-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pcap_path = dir.join("mix.pcap");
    std::fs::File::create(&pcap_path)
        .unwrap()
        .write_all(&pcap(&frames))
        .unwrap();
    let theirs = tshark(&pcap_path);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(theirs.len(), ours.len(), "tshark saw a different number of frames");

    let mut compared = 0;
    for (i, (o, t)) in ours.iter().zip(&theirs).enumerate() {
        let ctx = format!("{path}: frame {} ({})", i + 1, o["label"]);
        let id = o["id"].as_u64().unwrap();
        let Some(fc) = t[1] else {
            // Wireshark skips remote and 29-bit frames entirely (packet-canopen.c returns 0 when
            // CAN_RTR_FLAG/CAN_EFF_FLAG is set): node guarding requests are invisible to it.
            // Error frames (CAN_ERR_FLAG) go to its CAN error dissector, not to CANopen.
            assert!(
                o["rtr"] == true || o["ext"] == true || o["err"] == true,
                "{ctx}: Wireshark did not decode it"
            );
            continue;
        };
        compared += 1;
        let kind = o["kind"].as_str().unwrap();
        if kind == "other" {
            // Reserved COB-IDs: Wireshark still names a function code (e.g. 0x050 -> "SYNC/EMCY").
            assert!(o["malformed"].is_string() || o["ext"] == true, "{ctx}");
            continue;
        }
        assert_eq!(kind, kind_of_function_code(fc, id), "{ctx}: kind");
        if let Some(node) = o["node"].as_u64()
            && kind != "nmt"
        {
            assert_eq!(t[2], Some(node), "{ctx}: node");
        }
        match kind {
            "nmt" => {
                assert_eq!(
                    t[3],
                    Some(nmt_cs(o["nmt"]["command"].as_str().unwrap())),
                    "{ctx}: NMT cs"
                );
                if o.get("malformed").is_none() {
                    assert_eq!(t[4], o["nmt"]["target"].as_u64(), "{ctx}: NMT target");
                }
            }
            "heartbeat" => {
                let state = o["heartbeat"]["state"].as_str().unwrap();
                assert_eq!(t[5], Some(hb_state(state)), "{ctx}: state");
                assert_eq!(
                    t[6].map(|v| v != 0),
                    Some(o["heartbeat"]["toggle"] == true),
                    "{ctx}: toggle"
                );
            }
            "sync" => assert_eq!(t[7], o["sync"]["counter"].as_u64(), "{ctx}: counter"),
            "emcy" => {
                assert_eq!(t[8], o["emcy"]["code"].as_u64(), "{ctx}: code");
                assert_eq!(t[9], o["emcy"]["register"].as_u64(), "{ctx}: register");
            }
            "time" => {
                assert_eq!(t[13], o["time"]["ms"].as_u64(), "{ctx}: ms");
                assert_eq!(t[14], o["time"]["days"].as_u64(), "{ctx}: days");
            }
            "lss" => assert_eq!(t[15], o["lss"]["cs"].as_u64(), "{ctx}: LSS cs"),
            "sdo_rx" | "sdo_tx" => {
                let sdo = &o["sdo"];
                // Wireshark decodes every SDO frame on its own: segment frames and block
                // sub-block segments are read as command bytes, so only initiate and abort
                // frames carry index/sub/abort fields comparable with ours.
                if let (Some(idx), Some(ws)) = (sdo["index"].as_u64(), t[10]) {
                    assert_eq!(ws, idx, "{ctx}: index");
                    assert_eq!(t[11], sdo["sub"].as_u64(), "{ctx}: sub");
                }
                if let Some(code) = sdo["abort_code"].as_u64() {
                    assert_eq!(t[12], Some(code), "{ctx}: abort code");
                }
            }
            _ => {}
        }
    }
    compared
}
