//! Tracker tests: every transfer path, as a user reading the trace would see it.

use super::*;
use crate::frame::NodeKey;
use crate::od::{DataType, Dictionary, ObjectInfo, Profile};
use crate::sdo::crc::crc16;
use crate::sdo::{Channel, Outcome, Problem, Protocol, Side, Transaction, TransferDirection};
use std::sync::Arc;

fn dict() -> Dictionary {
    let mut p = Profile {
        name: "test".into(),
        ..Profile::default()
    };
    let mut obj = |index: u16, sub: u8, name: &str, data_type: DataType, values: &[(i64, &str)]| {
        let info = ObjectInfo {
            name: name.into(),
            data_type,
            values: values.iter().map(|(k, v)| (*k, v.to_string())).collect(),
            ..ObjectInfo::default()
        };
        p.objects.insert((index, sub), info);
    };
    obj(
        0x6040,
        0,
        "Controlword",
        DataType::U16,
        &[(6, "Shutdown"), (7, "Switch on"), (15, "Enable operation")],
    );
    obj(0x6041, 0, "Statusword", DataType::U16, &[]);
    obj(0x1008, 0, "Manufacturer device name", DataType::VisibleString, &[]);
    obj(0x1F50, 1, "Program data", DataType::Domain, &[]);
    obj(0x6083, 0, "Profile acceleration", DataType::U32, &[]);
    Dictionary::new(vec![Arc::new(p)])
}

/// A bus feeding a tracker, one millisecond per frame.
struct Bus {
    t: SdoTracker,
    seq: u64,
    dict: Dictionary,
}

impl Bus {
    fn new() -> Bus {
        Bus {
            t: SdoTracker::new(),
            seq: 0,
            dict: dict(),
        }
    }
    fn send(&mut self, node: u8, c2s: bool, bytes: &[u8]) -> SdoFrame {
        self.seq += 1;
        self.t.on_frame(
            self.seq,
            self.seq * 1_000_000,
            NodeKey::new(0, node),
            c2s,
            bytes,
            &self.dict,
        )
    }
    fn c(&mut self, node: u8, bytes: &[u8]) -> SdoFrame {
        self.send(node, true, bytes)
    }
    fn s(&mut self, node: u8, bytes: &[u8]) -> SdoFrame {
        self.send(node, false, bytes)
    }
    fn done(&mut self) -> Vec<Transaction> {
        self.t.drain_completed().collect()
    }
    fn one(&mut self) -> Transaction {
        let mut v = self.done();
        assert_eq!(v.len(), 1, "{v:#?}");
        v.remove(0)
    }
}

/// Block segments of `data` in sub-blocks of `blksize`: (sub-block, frames).
fn block_segments(data: &[u8], blksize: usize) -> Vec<Vec<[u8; 8]>> {
    let chunks: Vec<&[u8]> = data.chunks(7).collect();
    let n = chunks.len();
    let mut out = Vec::new();
    for (b, group) in chunks.chunks(blksize).enumerate() {
        let mut frames = Vec::new();
        for (i, c) in group.iter().enumerate() {
            let mut f = [0u8; 8];
            let last = b * blksize + i + 1 == n;
            f[0] = (i as u8 + 1) | if last { 0x80 } else { 0 };
            f[1..1 + c.len()].copy_from_slice(c);
            frames.push(f);
        }
        out.push(frames);
    }
    out
}

#[test]
fn expedited_download() {
    let mut bus = Bus::new();
    let f = bus.c(1, &[0x2B, 0x40, 0x60, 0x00, 0x06, 0x00, 0x00, 0x00]);
    assert_eq!(f.label(), "Download 0x6040:00 Controlword = 0x0006 (Shutdown)");
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["cs"], "initiate_download");
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["value"], 6);
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["expedited"], true);
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["size"], 2);
    let f = bus.s(1, &[0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(f.label(), "Download response 0x6040:00 Controlword");
    let t = bus.one();
    assert_eq!((t.index, t.sub, t.node), (0x6040, 0, 1));
    assert_eq!(t.direction, TransferDirection::Download);
    assert_eq!(t.protocol, Protocol::Expedited);
    assert_eq!(t.data, vec![6, 0]);
    assert_eq!(t.outcome, Outcome::Ok);
    assert_eq!(t.frames, vec![1, 2]);
    assert_eq!((t.start_ns, t.end_ns), (1_000_000, 2_000_000));
    assert!(t.problems.is_empty());
    let d = dict();
    assert_eq!(
        t.label(&d),
        "Download 0x6040:00 Controlword = 0x0006 (Shutdown) (expedited, 2 bytes, 1.000 ms): ok"
    );
    let j = serde_json::to_value(t.to_json(&d)).unwrap();
    assert_eq!(j["value"], 6);
    assert_eq!(j["value_text"], "0x0006 (Shutdown)");
    assert_eq!(j["data"], "0600");
    assert_eq!(j["outcome"], "ok");
    assert_eq!(j["duration_ns"], 1_000_000);
    assert_eq!(j["name"], "Controlword");
}

#[test]
fn expedited_upload_without_size_uses_type_size() {
    let mut bus = Bus::new();
    bus.c(3, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]);
    let f = bus.s(3, &[0x42, 0x41, 0x60, 0x00, 0x37, 0x02, 0xAA, 0xBB]);
    assert_eq!(
        f.label(),
        "Upload response 0x6041:00 Statusword = 0x0237 (Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote])"
    );
    let t = bus.one();
    assert_eq!(t.direction, TransferDirection::Upload);
    assert_eq!(t.data, vec![0x37, 0x02]);
    assert!(t.problems.is_empty(), "{:?}", t.problems);
}

#[test]
fn unknown_object_shows_hex_and_integer() {
    let mut bus = Bus::new();
    let f = bus.c(1, &[0x2B, 0x03, 0x30, 0x01, 0xB8, 0x0B, 0x00, 0x00]);
    assert_eq!(f.label(), "Download 0x3003:01 = B8 0B (3000)");
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["value"], 3000);
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["data"], "B80B");
}

/// Dexmart manual: segmented upload of 0x3082:00, a 16-byte ASCII string in three segments.
#[test]
fn dexmart_segmented_upload() {
    let mut bus = Bus::new();
    let f = bus.c(1, &[0x40, 0x82, 0x30, 0x00, 0, 0, 0, 0]);
    assert_eq!(f.label(), "Upload 0x3082:00");
    let f = bus.s(1, &[0x41, 0x82, 0x30, 0x00, 0x10, 0x00, 0x00, 0x00]);
    assert_eq!(f.label(), "Upload response 0x3082:00 (segmented, 16 bytes)");
    assert_eq!(
        bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]).label(),
        "Upload segment request t=0"
    );
    let f = bus.s(1, &[0x00, 0x32, 0x30, 0x33, 0x36, 0x49, 0x30, 0x34]);
    assert_eq!(f.label(), "Upload segment t=0 \"2036I04\" c=0");
    assert_eq!(f.object, Some((0x3082, 0)));
    assert_eq!(serde_json::to_value(f.to_json()).unwrap()["index"], 0x3082);
    bus.c(1, &[0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        bus.s(1, &[0x10, 0x41, 0x30, 0x30, 0x32, 0x30, 0x20, 0x20]).label(),
        "Upload segment t=1 \"A0020  \" c=0"
    );
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        bus.s(1, &[0x0B, 0x20, 0x20, 0, 0, 0, 0, 0]).label(),
        "Upload segment t=0 \"  \" c=1"
    );
    let t = bus.one();
    assert_eq!(t.protocol, Protocol::Segmented);
    assert_eq!(t.data, b"2036I04A0020    ".to_vec());
    assert_eq!(t.size, Some(16));
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty());
    assert_eq!(t.frames, (1..=8).collect::<Vec<u64>>());
}

#[test]
fn segmented_download() {
    let mut bus = Bus::new();
    let f = bus.c(5, &[0x21, 0x08, 0x10, 0x00, 15, 0, 0, 0]);
    assert_eq!(
        f.label(),
        "Download 0x1008:00 Manufacturer device name (segmented, 15 bytes)"
    );
    bus.s(5, &[0x60, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    let f = bus.c(5, &[0x00, b'D', b'E', b'X', b'M', b'A', b'R', b'T']);
    assert_eq!(f.label(), "Download segment t=0 \"DEXMART\" c=0");
    assert_eq!(
        bus.s(5, &[0x20, 0, 0, 0, 0, 0, 0, 0]).label(),
        "Download segment response t=0"
    );
    bus.c(5, &[0x10, b' ', b'D', b'E', b'V', b' ', b'1', b'.']);
    bus.s(5, &[0x30, 0, 0, 0, 0, 0, 0, 0]);
    bus.c(5, &[0x0D, b'0', 0, 0, 0, 0, 0, 0]);
    bus.s(5, &[0x20, 0, 0, 0, 0, 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.data, b"DEXMART DEV 1.0".to_vec());
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty());
    assert_eq!(
        t.label(&bus.dict),
        "Download 0x1008:00 Manufacturer device name = \"DEXMART DEV 1.0\" (segmented, 15 bytes, 7.000 ms): ok"
    );
}

/// Transfers on thousands of channels (idle ones are dropped past a thousand): each
/// completes as on one channel, and a segmented download running meanwhile, and an
/// unanswered request on another channel, go on through the drops.
#[test]
fn many_channels_keep_their_running_transfers() {
    let d = dict();
    let mut t = SdoTracker::new();
    let seq = &mut 0u64;
    let mut send = |t: &mut SdoTracker, iface: u16, node: u8, c2s: bool, bytes: &[u8]| {
        *seq += 1;
        t.on_frame(*seq, *seq * 1000, NodeKey::new(iface, node), c2s, bytes, &d)
    };
    send(&mut t, 0, 5, true, &[0x21, 0x08, 0x10, 0x00, 8, 0, 0, 0]);
    send(&mut t, 0, 5, false, &[0x60, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    send(&mut t, 0, 6, true, &[0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
    for i in 0..5000u32 {
        let (iface, node) = (1 + (i / 100) as u16, 1 + (i % 100) as u8);
        send(&mut t, iface, node, true, &[0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
        send(
            &mut t,
            iface,
            node,
            false,
            &[0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00],
        );
    }
    let done: Vec<_> = t.drain_completed().collect();
    assert_eq!(done.len(), 5000);
    assert!(
        done.iter()
            .all(|x| x.outcome == Outcome::Ok && x.data == [0x92, 0x01, 0x02, 0x00])
    );
    let f = send(&mut t, 0, 5, true, &[0x00, b'D', b'E', b'X', b'M', b'A', b'R', b'T']);
    assert_eq!(f.label(), "Download segment t=0 \"DEXMART\" c=0");
    send(&mut t, 0, 5, false, &[0x20, 0, 0, 0, 0, 0, 0, 0]);
    send(&mut t, 0, 5, true, &[0x1D, b'!', 0, 0, 0, 0, 0, 0]);
    send(&mut t, 0, 5, false, &[0x30, 0, 0, 0, 0, 0, 0, 0]);
    let f = send(&mut t, 0, 6, false, &[0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]);
    assert!(f.problems.is_empty(), "{:?}", f.problems);
    let done: Vec<_> = t.drain_completed().collect();
    assert_eq!(done.len(), 2);
    assert_eq!(
        (done[0].node, done[0].data.as_slice(), &done[0].outcome),
        (5, &b"DEXMART!"[..], &Outcome::Ok)
    );
    assert!(done[0].problems.is_empty(), "{:?}", done[0].problems);
    assert_eq!((done[1].node, &done[1].outcome), (6, &Outcome::Ok));
    assert!(done[1].problems.is_empty(), "{:?}", done[1].problems);
}

#[test]
fn toggle_error_is_flagged() {
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 14, 0, 0, 0]);
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g']);
    let f = bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]); // should have been 0x70
    assert!(f.label().ends_with("[toggle error]"), "{}", f.label());
    bus.s(1, &[0x01, b'h', b'i', b'j', b'k', b'l', b'm', b'n']);
    let t = bus.one();
    assert_eq!(t.problems, vec![Problem::ToggleError]);
    assert_eq!(t.data.len(), 14);
    assert!(t.label(&bus.dict).ends_with("ok [toggle error]"));
    assert_eq!(
        serde_json::to_value(t.to_json(&bus.dict)).unwrap()["problems"][0]["kind"],
        "toggle_error"
    );
}

#[test]
fn abort_mid_transfer() {
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0]);
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g']);
    let f = bus.c(1, &[0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05]);
    assert_eq!(
        f.label(),
        "Abort 0x1008:00 Manufacturer device name: 0x05040000 SDO protocol timed out"
    );
    let t = bus.one();
    assert_eq!(
        t.outcome,
        Outcome::Aborted {
            code: 0x0504_0000,
            text: "SDO protocol timed out",
            by: Side::Client
        }
    );
    assert_eq!(t.data, b"abcdefg".to_vec());
    let j = serde_json::to_value(t.to_json(&bus.dict)).unwrap();
    assert_eq!(j["outcome"], "aborted");
    assert_eq!(j["aborted_by"], "client");
    assert_eq!(j["abort_code"], 0x0504_0000);
    assert!(
        t.label(&bus.dict)
            .contains("aborted by client: 0x05040000 SDO protocol timed out")
    );
}

#[test]
fn abort_answering_a_request() {
    // Dexmart manual: upload of 0x3000:21 answered with 0x06020000.
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x00, 0x30, 0x21, 0, 0, 0, 0]);
    bus.s(1, &[0x80, 0x00, 0x30, 0x21, 0x00, 0x00, 0x02, 0x06]);
    let t = bus.one();
    assert_eq!((t.index, t.sub), (0x3000, 0x21));
    assert_eq!(t.protocol, Protocol::Unknown);
    assert_eq!(
        t.label(&bus.dict),
        "Upload 0x3000:21 (0 bytes, 1.000 ms): aborted by server: 0x06020000 Object does not exist in the object dictionary"
    );
    assert_eq!(
        t.outcome,
        Outcome::Aborted {
            code: 0x0602_0000,
            text: "Object does not exist in the object dictionary",
            by: Side::Server
        }
    );
}

fn run_block_download(data: &[u8], blksize: u8, crc_sent: Option<u16>) -> (Bus, Transaction) {
    let mut bus = Bus::new();
    let size = (data.len() as u32).to_le_bytes();
    let f = bus.c(2, &[0xC6, 0x50, 0x1F, 0x01, size[0], size[1], size[2], size[3]]);
    assert_eq!(
        f.label(),
        format!("Block download 0x1F50:01 Program data (crc, {} bytes)", data.len())
    );
    let f = bus.s(2, &[0xA4, 0x50, 0x1F, 0x01, blksize, 0, 0, 0]);
    assert_eq!(
        f.label(),
        format!("Block download response 0x1F50:01 Program data blksize={blksize} (crc)")
    );
    for sub_block in block_segments(data, blksize as usize) {
        let n = sub_block.len() as u8;
        for (i, seg) in sub_block.iter().enumerate() {
            let f = bus.c(2, seg);
            assert_eq!(f.command.cs_name(), "block_segment");
            assert!(
                f.label()
                    .starts_with(&format!("Block download segment seqno={}", i + 1)),
                "{}",
                f.label()
            );
        }
        let f = bus.s(2, &[0xA2, n, blksize, 0, 0, 0, 0, 0]);
        assert_eq!(f.label(), format!("Block download ack ackseq={n} blksize={blksize}"));
    }
    let unused = (7 - data.len() % 7) % 7;
    let crc = crc_sent.unwrap_or(crc16(data)).to_le_bytes();
    let f = bus.c(2, &[0xC1 | (unused as u8) << 2, crc[0], crc[1], 0, 0, 0, 0, 0]);
    assert!(f.label().starts_with(&format!("Block download end n={unused} crc=0x")));
    bus.s(2, &[0xA1, 0, 0, 0, 0, 0, 0, 0]);
    let t = bus.one();
    (bus, t)
}

#[test]
fn block_download_good_crc() {
    let data: Vec<u8> = (0..40u8).collect();
    let (bus, t) = run_block_download(&data, 2, None);
    assert_eq!(t.protocol, Protocol::Block);
    assert_eq!(t.direction, TransferDirection::Download);
    assert_eq!(t.data, data);
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty(), "{:?}", t.problems);
    assert_eq!(t.frames.len() as u64, bus.seq);
}

#[test]
fn block_download_bad_crc() {
    let data = b"hello block world".to_vec();
    let good = crc16(&data);
    let (_, t) = run_block_download(&data, 127, Some(good ^ 0xFFFF));
    assert_eq!(t.data, data);
    assert_eq!(
        t.problems,
        vec![Problem::BadCrc {
            sent: good ^ 0xFFFF,
            computed: good
        }]
    );
}

fn run_block_upload(data: &[u8], blksize: u8, crc_sent: Option<u16>) -> Transaction {
    let mut bus = Bus::new();
    let f = bus.c(4, &[0xA4, 0x08, 0x10, 0x00, blksize, 0, 0, 0]);
    assert_eq!(
        f.label(),
        format!("Block upload 0x1008:00 Manufacturer device name blksize={blksize} pst=0 (crc)")
    );
    let size = (data.len() as u32).to_le_bytes();
    let f = bus.s(4, &[0xC6, 0x08, 0x10, 0x00, size[0], size[1], size[2], size[3]]);
    assert_eq!(
        f.label(),
        format!(
            "Block upload response 0x1008:00 Manufacturer device name (crc, {} bytes)",
            data.len()
        )
    );
    assert_eq!(bus.c(4, &[0xA3, 0, 0, 0, 0, 0, 0, 0]).label(), "Block upload start");
    for sub_block in block_segments(data, blksize as usize) {
        let n = sub_block.len() as u8;
        for seg in &sub_block {
            assert!(bus.s(4, seg).label().starts_with("Block upload segment seqno="));
        }
        assert_eq!(
            bus.c(4, &[0xA2, n, blksize, 0, 0, 0, 0, 0]).label(),
            format!("Block upload ack ackseq={n} blksize={blksize}")
        );
    }
    let unused = (7 - data.len() % 7) % 7;
    let crc = crc_sent.unwrap_or(crc16(data)).to_le_bytes();
    bus.s(4, &[0xC1 | (unused as u8) << 2, crc[0], crc[1], 0, 0, 0, 0, 0]);
    assert_eq!(
        bus.c(4, &[0xA1, 0, 0, 0, 0, 0, 0, 0]).label(),
        "Block upload end response"
    );
    bus.one()
}

#[test]
fn block_upload_good_crc() {
    let data = b"CANopen block upload, three sub-blocks".to_vec();
    let t = run_block_upload(&data, 2, None);
    assert_eq!(t.direction, TransferDirection::Upload);
    assert_eq!(t.protocol, Protocol::Block);
    assert_eq!(t.data, data);
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty(), "{:?}", t.problems);
}

#[test]
fn block_upload_bad_crc() {
    let data = b"0123456789ABCD".to_vec();
    let t = run_block_upload(&data, 127, Some(0x1234));
    assert_eq!(
        t.problems,
        vec![Problem::BadCrc {
            sent: 0x1234,
            computed: crc16(&data)
        }]
    );
    assert!(t.label(&dict()).contains("[bad block CRC: sent 0x1234"));
}

#[test]
fn block_retransmission_is_a_sequence_error_but_data_is_right() {
    let mut bus = Bus::new();
    let data: Vec<u8> = (0..21u8).collect(); // three segments
    bus.c(2, &[0xC2, 0x50, 0x1F, 0x01, 21, 0, 0, 0]); // no CRC
    bus.s(2, &[0xA0, 0x50, 0x1F, 0x01, 3, 0, 0, 0]);
    let segs = &block_segments(&data, 3)[0];
    bus.c(2, &segs[0]);
    let f = bus.c(2, &{
        let mut s = segs[2];
        s[0] = 3 | 0x80;
        s
    }); // seqno 2 lost on the bus
    assert!(f.label().contains("[sequence error]"), "{}", f.label());
    bus.s(2, &[0xA2, 1, 3, 0, 0, 0, 0, 0]); // server acknowledges only 1
    // The client resends segments 2 and 3 as a new sub-block numbered from 1.
    let mut a = segs[1];
    a[0] = 1;
    let mut b = segs[2];
    b[0] = 2 | 0x80;
    bus.c(2, &a);
    bus.c(2, &b);
    bus.s(2, &[0xA2, 2, 3, 0, 0, 0, 0, 0]);
    bus.c(2, &[0xC1, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(2, &[0xA1, 0, 0, 0, 0, 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.data, data);
    assert_eq!(t.problems, vec![Problem::SequenceError]);
    assert_eq!(t.outcome, Outcome::Ok);
}

#[test]
fn block_upload_switching_to_segmented() {
    let mut bus = Bus::new();
    bus.c(1, &[0xA4, 0x08, 0x10, 0x00, 0x7F, 0x20, 0, 0]);
    bus.s(1, &[0x43, 0x08, 0x10, 0x00, b'a', b'b', b'c', b'd']);
    let t = bus.one();
    assert_eq!(t.protocol, Protocol::Expedited);
    assert_eq!(t.data, b"abcd".to_vec());
    assert_eq!(t.outcome, Outcome::Ok);
}

#[test]
fn unmatched_responses() {
    let mut bus = Bus::new();
    // An expedited upload response whose request came before the capture: the value is still known.
    let f = bus.s(1, &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]);
    assert!(f.label().ends_with("[unmatched response]"), "{}", f.label());
    assert!(f.label().starts_with("Upload response 0x6041:00 Statusword = 0x0237 (Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote])"));
    let t = bus.one();
    assert_eq!(t.problems, vec![Problem::UnmatchedResponse]);
    assert_eq!(t.outcome, Outcome::Ok);
    assert_eq!(t.data, vec![0x37, 0x02]);
    // A download response without request, then a normal transfer.
    bus.s(1, &[0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]);
    bus.c(1, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x06, 0, 0]);
    let v = bus.done();
    assert_eq!(v.len(), 2);
    assert_eq!(v[0].outcome, Outcome::Incomplete);
    assert_eq!(v[0].problems, vec![Problem::UnmatchedResponse]);
    assert_eq!(v[1].outcome, Outcome::Ok);
    assert!(v[1].problems.is_empty());
    // A response to another object than the one requested.
    bus.c(1, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x4B, 0x40, 0x60, 0x00, 0x37, 0x06, 0, 0]);
    assert_eq!(bus.one().problems, vec![Problem::UnmatchedResponse]);
}

#[test]
fn interleaved_nodes() {
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.c(2, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.s(2, &[0x41, 0x08, 0x10, 0x00, 9, 0, 0, 0]);
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 8, 0, 0, 0]);
    bus.c(2, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x00, b'n', b'o', b'd', b'e', b' ', b'o', b'n']);
    bus.s(2, &[0x00, b'n', b'o', b'd', b'e', b' ', b't', b'w']);
    bus.c(1, &[0x70, 0, 0, 0, 0, 0, 0, 0]);
    bus.c(2, &[0x70, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(2, &[0x1B, b'o', b'!', 0, 0, 0, 0, 0]);
    bus.s(1, &[0x1D, b'e', 0, 0, 0, 0, 0, 0]);
    let v = bus.done();
    assert_eq!(v.len(), 2);
    assert_eq!((v[0].node, v[0].data.as_slice()), (2, &b"node two!"[..]));
    assert_eq!((v[1].node, v[1].data.as_slice()), (1, &b"node one"[..]));
    assert!(v.iter().all(|t| t.problems.is_empty() && t.outcome == Outcome::Ok));
    assert_eq!(v[1].frames, vec![1, 4, 6, 7, 9, 12]);
}

#[test]
fn capture_starting_mid_transfer() {
    let mut bus = Bus::new();
    // The tail of a segmented upload whose start was not captured.
    let f = bus.s(1, &[0x10, b'x', b'y', b'z', 0, 0, 0, 0]);
    assert_eq!(f.object, None);
    assert!(f.malformed().is_none());
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x0B, b'x', b'y', 0, 0, 0, 0, 0]);
    assert!(bus.done().is_empty());
    // The next transfer is tracked normally.
    bus.c(1, &[0x2B, 0x40, 0x60, 0x00, 0x07, 0x00, 0, 0]);
    bus.s(1, &[0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty());
    assert_eq!(
        t.label(&bus.dict),
        "Download 0x6040:00 Controlword = 0x0007 (Switch on) (expedited, 2 bytes, 1.000 ms): ok"
    );
}

#[test]
fn capture_starting_after_an_initiate_response() {
    let mut bus = Bus::new();
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 3, 0, 0, 0]);
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x09, b'a', b'b', b'c', 0, 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.data, b"abc".to_vec());
    assert_eq!(t.outcome, Outcome::Ok);
    assert_eq!(t.problems, vec![Problem::UnmatchedResponse]);
}

#[test]
fn vendor_commands_do_not_disturb_the_tracker() {
    let mut bus = Bus::new();
    // A segmented upload on node 1 with Syn-tron 0xE8/0xE9 frames in between.
    bus.c(1, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 8, 0, 0, 0]);
    let f = bus.c(1, &[0xE8, 0x04, 0x50, 0x00, 0, 0, 0, 0]);
    assert!(f.malformed().is_some());
    let f = bus.s(1, &[0xE8, 0x04, 0x50, 0x00, 0xB7, 0x13, 0xAB, 0x12]);
    assert!(f.malformed().is_some());
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x00, b'1', b'2', b'3', b'4', b'5', b'6', b'7']);
    bus.c(1, &[0x70, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x1D, b'8', 0, 0, 0, 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.data, b"12345678".to_vec());
    assert!(t.problems.is_empty());
    assert_eq!(t.frames, vec![1, 2, 5, 6, 7, 8]);
    // 0xE9 write answered by a standard 0x60: a reply to the vendor request, not an unmatched response.
    assert!(
        bus.c(1, &[0xE9, 0x18, 0x23, 0x00, 0x36, 0x00, 0xCA, 0xFF])
            .malformed()
            .is_some()
    );
    let f = bus.s(1, &[0x60, 0x18, 0x23, 0x00, 0x64, 0x00, 0xCA, 0xFF]);
    assert!(f.malformed().is_none());
    assert!(bus.done().is_empty());
    assert!(bus.t.finish().is_empty());
}

#[test]
fn wrong_dlc_and_size_mismatch() {
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x08, 0x10, 0x00]);
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0]);
    bus.c(1, &[0x60, 0, 0, 0, 0, 0, 0, 0]);
    bus.s(1, &[0x07, b'a', b'b', b'c', b'd', 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.data, b"abcd".to_vec());
    assert_eq!(
        t.problems,
        vec![
            Problem::WrongDlc { dlc: 4 },
            Problem::SizeMismatch {
                indicated: 10,
                actual: 4
            }
        ]
    );
}

#[test]
fn type_length_mismatch_is_reported() {
    // Syn-tron writes 0x6083 (U32) with a four-byte frame: fine; a two-byte write is flagged.
    let mut bus = Bus::new();
    bus.c(2, &[0x2B, 0x83, 0x60, 0x00, 0xE8, 0x03, 0, 0]);
    bus.s(2, &[0x60, 0x83, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        bus.one().problems,
        vec![Problem::TypeLengthMismatch { expected: 4, actual: 2 }]
    );
}

#[test]
fn new_request_interrupts_a_running_transfer() {
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0]);
    bus.c(1, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]);
    let v = bus.done();
    assert_eq!(v.len(), 2);
    assert_eq!(
        v[0].outcome,
        Outcome::ProtocolError("interrupted by a new request".into())
    );
    assert_eq!(v[1].outcome, Outcome::Ok);
}

#[test]
fn finish_reports_incomplete_transfers() {
    let mut bus = Bus::new();
    bus.c(1, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    bus.c(9, &[0x2B, 0x40, 0x60, 0x00, 0x06, 0x00, 0, 0]);
    bus.s(9, &[0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]);
    let v = bus.t.finish();
    assert_eq!(v.len(), 2);
    assert_eq!((v[0].node, &v[0].outcome), (9, &Outcome::Ok));
    assert_eq!((v[1].node, &v[1].outcome), (1, &Outcome::Incomplete));
    assert!(v[1].label(&bus.dict).ends_with(": incomplete"));
}

#[test]
fn non_default_channel() {
    let mut t = SdoTracker::new();
    let d = dict();
    let ch = Channel {
        iface: 0,
        node: 7,
        request_cob: 0x640,
        response_cob: 0x5C0,
    };
    t.on_channel_frame(1, 10, ch, Side::Client, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0], &d);
    t.on_frame(2, 11, NodeKey::new(0, 7), false, &[0x4B, 0x41, 0x60, 0, 1, 0, 0, 0], &d);
    t.on_channel_frame(3, 12, ch, Side::Server, &[0x4B, 0x41, 0x60, 0, 2, 0, 0, 0], &d);
    let v: Vec<_> = t.drain_completed().collect();
    assert_eq!(v.len(), 2);
    assert_eq!(v[0].problems, vec![Problem::UnmatchedResponse]);
    assert_eq!((v[1].channel, v[1].data.as_slice()), (ch, &[2u8, 0][..]));
    assert_eq!(serde_json::to_value(v[1].to_json(&d)).unwrap()["request_cob"], 0x640);
}

/// A block segment frame: `c | seqno` and up to seven bytes.
fn segment(seqno: u8, last: bool, bytes: &[u8]) -> [u8; 8] {
    let mut f = [0u8; 8];
    f[0] = seqno | if last { 0x80 } else { 0 };
    f[1..1 + bytes.len()].copy_from_slice(bytes);
    f
}

#[test]
fn block_download_caught_mid_sub_block_resynchronises() {
    // 60 bytes in sub-blocks of 4 segments: 1-4, 1-4, 1 (last, 4 bytes used).
    let data: Vec<u8> = (100..160u8).collect();
    let segs: Vec<&[u8]> = data.chunks(7).collect();
    let mut bus = Bus::new();
    // The capture starts at segment 3 of the first sub-block. Its first byte 0x03
    // reads as a valid download segment; the run 3, 4 shows what it is.
    let f = bus.c(2, &segment(3, false, segs[2]));
    assert!(f.label().starts_with("Download segment t=0 "), "{}", f.label());
    assert!(f.label().ends_with(" c=1 [outside any transfer seen]"), "{}", f.label());
    let f = bus.c(2, &segment(4, false, segs[3]));
    assert_eq!(
        f.label(),
        "Block download segment seqno=4 [resynchronised: block download started before the capture]"
    );
    assert_eq!(f.object, None);
    assert_eq!(
        bus.s(2, &[0xA2, 4, 4, 0, 0, 0, 0, 0]).label(),
        "Block download ack ackseq=4 blksize=4"
    );
    for (i, s) in segs[4..8].iter().enumerate() {
        let f = bus.c(2, &segment(i as u8 + 1, false, s));
        assert_eq!(f.label(), format!("Block download segment seqno={}", i + 1));
    }
    bus.s(2, &[0xA2, 4, 4, 0, 0, 0, 0, 0]);
    assert_eq!(
        bus.c(2, &segment(1, true, segs[8])).label(),
        "Block download segment seqno=1 last"
    );
    bus.s(2, &[0xA2, 1, 4, 0, 0, 0, 0, 0]);
    // The CRC covers bytes the capture missed: it cannot be checked, and is not.
    let f = bus.c(2, &[0xC1 | 3 << 2, 0xEE, 0xEE, 0, 0, 0, 0, 0]);
    assert_eq!(f.label(), "Block download end n=3 crc=0xEEEE");
    bus.s(2, &[0xA1, 0, 0, 0, 0, 0, 0, 0]);
    // The next transfer is tracked from its initiate, as usual.
    bus.c(2, &[0x2B, 0x40, 0x60, 0x00, 0x0F, 0x00, 0, 0]);
    bus.s(2, &[0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]);
    let v = bus.done();
    assert_eq!(v.len(), 2, "{v:#?}");
    let t = &v[0];
    assert_eq!(t.direction, TransferDirection::Download);
    assert_eq!(t.protocol, Protocol::Block);
    assert_eq!(t.data, data[14..].to_vec(), "the bytes seen, from segment 3 on");
    assert_eq!(t.outcome, Outcome::Ok);
    assert_eq!(t.problems, vec![Problem::StartedBeforeCapture]);
    assert!(t.is_partial() && !t.is_ok());
    assert_eq!(t.frames, (1..=12).collect::<Vec<u64>>());
    assert_eq!(
        t.label(&bus.dict),
        "Download (object not captured) (block, 46 bytes seen, 11.000 ms): ok [partial: started before the capture]"
    );
    let j = serde_json::to_value(t.to_json(&bus.dict)).unwrap();
    assert_eq!((j["partial"].as_bool(), j["index"].is_null()), (Some(true), true));
    assert_eq!(
        v[1].label(&bus.dict),
        "Download 0x6040:00 Controlword = 0x000F (Enable operation) (expedited, 2 bytes, 1.000 ms): ok"
    );
}

#[test]
fn block_upload_caught_mid_way_resynchronises() {
    let tail = b"0123456789ABCDEFGHIJKLM"; // 23 bytes after the capture starts
    let segs: Vec<&[u8]> = tail.chunks(7).collect();
    let mut bus = Bus::new();
    // 0x7F from a server can only be a sequence number (an initiate download
    // response has no bits set below 0x60); the client's ack confirms it.
    let f = bus.s(5, &segment(127, false, segs[0]));
    assert_eq!(f.label(), "Block upload segment seqno=127");
    let f = bus.c(5, &[0xA2, 127, 127, 0, 0, 0, 0, 0]);
    assert_eq!(
        f.label(),
        "Block upload ack ackseq=127 blksize=127 [resynchronised: block upload started before the capture]"
    );
    bus.s(5, &segment(1, false, segs[1]));
    bus.s(5, &segment(2, false, segs[2]));
    assert_eq!(
        bus.s(5, &segment(3, true, segs[3])).label(),
        "Block upload segment seqno=3 last"
    );
    bus.c(5, &[0xA2, 3, 127, 0, 0, 0, 0, 0]);
    assert_eq!(
        bus.s(5, &[0xC1 | 5 << 2, 0x12, 0x34, 0, 0, 0, 0, 0]).label(),
        "Block upload end n=5 crc=0x3412"
    );
    bus.c(5, &[0xA1, 0, 0, 0, 0, 0, 0, 0]);
    bus.c(5, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]);
    bus.s(5, &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]);
    let v = bus.done();
    assert_eq!(v.len(), 2, "{v:#?}");
    assert_eq!(v[0].direction, TransferDirection::Upload);
    assert_eq!(v[0].data, tail.to_vec());
    assert_eq!(v[0].outcome, Outcome::Ok);
    assert_eq!(v[0].problems, vec![Problem::StartedBeforeCapture]);
    assert_eq!(v[0].frames.len(), 8);
    assert_eq!((v[1].index, v[1].outcome.clone()), (0x6041, Outcome::Ok));
    assert!(v[1].problems.is_empty());
}

#[test]
fn a_missed_acknowledgement_does_not_derail_a_partial_transfer() {
    let mut bus = Bus::new();
    bus.s(3, &[0xA2, 127, 127, 0, 0, 0, 0, 0]); // a block download ack: node 3 is receiving
    for n in 1..=127u8 {
        let f = bus.c(3, &segment(n, false, &[n; 7]));
        assert_eq!(f.command.cs_name(), "block_segment", "{}", f.label());
    }
    // The server's ack of that sub-block is lost; the next one starts at 1.
    let f = bus.c(3, &segment(1, false, &[0xAA; 7]));
    assert_eq!(f.label(), "Block download segment seqno=1 [sequence error]");
    assert!(bus.done().is_empty());
    let v = bus.t.finish();
    assert_eq!(v.len(), 1);
    assert_eq!(v[0].len(), 127 * 7, "the unacknowledged sub-block still counts as seen");
    assert_eq!(
        v[0].problems,
        vec![Problem::StartedBeforeCapture, Problem::SequenceError]
    );
    assert_eq!(v[0].outcome, Outcome::Incomplete);
}

#[test]
fn one_impossible_byte_invents_no_transaction() {
    let mut bus = Bus::new();
    // A garbage frame whose first byte no command has, then an ordinary exchange.
    let f = bus.c(1, &[0x6F, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(f.label(), "Block download segment seqno=111");
    bus.c(1, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]);
    bus.s(1, &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]);
    let v = bus.t.finish();
    assert_eq!(v.len(), 1, "{v:#?}");
    assert_eq!((v[0].index, v[0].outcome.clone()), (0x6041, Outcome::Ok));
    // Alone at the end of the input, it is dropped too.
    let mut bus = Bus::new();
    bus.s(1, &[0x55, 1, 2, 3, 4, 5, 6, 7]);
    assert!(bus.t.finish().is_empty());
}

#[test]
fn a_transfer_that_never_ends_keeps_memory_flat() {
    use crate::sdo::transaction::{DATA_KEPT, FRAMES_KEPT};
    let mut bus = Bus::new();
    bus.c(2, &[0xC4, 0x50, 0x1F, 0x01, 0, 0, 0, 0]); // crc, size not indicated
    bus.s(2, &[0xA4, 0x50, 0x1F, 0x01, 127, 0, 0, 0]);
    let sub_blocks = DATA_KEPT / (127 * 7) + 2;
    let byte = |i: usize| (i * 7 % 251) as u8;
    let mut crc = 0u16;
    for b in 0..sub_blocks {
        for n in 1..=127u8 {
            let bytes = [byte(b * 127 + n as usize); 7];
            crc = crate::sdo::crc::crc16_update(crc, &bytes);
            bus.c(2, &segment(n, b + 1 == sub_blocks && n == 127, &bytes));
        }
        bus.s(2, &[0xA2, 127, 127, 0, 0, 0, 0, 0]);
    }
    // What is kept stopped growing; what was transferred is still counted.
    let c = crc.to_le_bytes();
    bus.c(2, &[0xC1, c[0], c[1], 0, 0, 0, 0, 0]);
    bus.s(2, &[0xA1, 0, 0, 0, 0, 0, 0, 0]);
    let t = bus.one();
    assert_eq!(t.data.len(), DATA_KEPT);
    assert_eq!(t.len(), sub_blocks * 127 * 7);
    assert_eq!(t.frames.len(), FRAMES_KEPT);
    assert_eq!(t.frames.len() as u64 + t.frames_dropped, bus.seq);
    // The CRC is still checked over every byte.
    assert_eq!((t.outcome.clone(), t.problems.clone()), (Outcome::Ok, vec![]));
    assert!(
        t.label(&bus.dict)
            .contains(&format!("{} bytes, first {DATA_KEPT} kept", t.len()))
    );
    let j = serde_json::to_value(t.to_json(&bus.dict)).unwrap();
    assert_eq!(j["len"], t.len());
}

#[test]
fn a_segmented_transfer_that_never_ends_keeps_memory_flat() {
    use crate::sdo::transaction::DATA_KEPT;
    let segments = DATA_KEPT / 7 + 2;
    // An upload, then a download, each of segments of 7 bytes, the last with the c bit.
    for upload in [true, false] {
        let mut bus = Bus::new();
        if upload {
            bus.c(2, &[0x40, 0x50, 0x1F, 0x01, 0, 0, 0, 0]);
            bus.s(2, &[0x40, 0x50, 0x1F, 0x01, 0, 0, 0, 0]); // size not indicated
        } else {
            bus.c(2, &[0x20, 0x50, 0x1F, 0x01, 0, 0, 0, 0]);
            bus.s(2, &[0x60, 0x50, 0x1F, 0x01, 0, 0, 0, 0]);
        }
        for i in 0..segments {
            let toggle = (i as u8 & 1) << 4;
            let last = u8::from(i + 1 == segments);
            let data = [(i % 251) as u8; 7];
            let mut seg = [toggle | last; 8];
            seg[1..].copy_from_slice(&data);
            if upload {
                bus.c(2, &[0x60 | toggle, 0, 0, 0, 0, 0, 0, 0]);
                bus.s(2, &seg);
            } else {
                bus.c(2, &seg);
                bus.s(2, &[0x20 | toggle, 0, 0, 0, 0, 0, 0, 0]);
            }
        }
        let t = bus.one();
        assert_eq!(t.protocol, Protocol::Segmented);
        assert_eq!((t.outcome.clone(), t.problems.clone()), (Outcome::Ok, vec![]));
        assert_eq!(t.data.len(), DATA_KEPT, "upload: {upload}");
        assert_eq!(t.len(), segments * 7);
        assert!(
            t.label(&bus.dict)
                .contains(&format!("{} bytes, first {DATA_KEPT} kept", t.len()))
        );
    }
}
