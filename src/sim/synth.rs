//! Synthetic CANopen traffic for benchmarks: a deterministic mix that looks
//! like a commissioning bus (SYNC, four TPDOs and RPDOs per drive, heartbeats,
//! about 12 % SDO frames with segmented and block transfers and aborts, EMCY, NMT).
//! Pure: the same frame count always gives the same frames.

use crate::cob;
use crate::frame::Frame;
use crate::sdo::codec::{Chunk, SdoCommand, encode, sub_block};

/// Generates `count` frames, 100 µs apart, starting at `start_ns`.
pub struct Traffic {
    remaining: u64,
    ts_ns: u64,
    step: u64,
    script: Vec<Frame>,
    pos: usize,
    cycle: u64,
}

impl Traffic {
    /// A generator of `count` frames starting at `start_ns`.
    pub fn new(count: u64, start_ns: u64) -> Traffic {
        Traffic {
            remaining: count,
            ts_ns: start_ns,
            step: 100_000,
            script: Vec::new(),
            pos: 0,
            cycle: 0,
        }
    }

    /// Fills `script` with one SYNC cycle of frames.
    fn refill(&mut self) {
        self.script.clear();
        self.pos = 0;
        let c = self.cycle;
        self.cycle += 1;
        let s = &mut self.script;
        s.push(Frame::classic(0x080, &[(c % 240 + 1) as u8]));
        for node in 1u8..=NODES {
            pdos(s, c, node);
        }
        if c.is_multiple_of(10) {
            for node in 1..=NODES {
                s.push(Frame::classic(cob::heartbeat(node), &[0x05]));
            }
        }
        // Every cycle one expedited upload, every other cycle one expedited download,
        // each on the next node in turn.
        let node = (c % u64::from(NODES)) as u8 + 1;
        let (index, sub, value) = POLLED[(c / u64::from(NODES)) as usize % POLLED.len()];
        expedited_upload(s, node, index, sub, value);
        if c.is_multiple_of(2) {
            let mode = [1u8, 3, 8][(c / 2 % 3) as usize];
            expedited_download(s, node, 0x6060, 0, &[mode]);
        }
        if c % 8 == 3 {
            segmented_upload(s, node);
        }
        if c % 16 == 5 {
            block_upload(s, node);
        }
        if c % 50 == 7 {
            // A read of an object the drive does not have: abort 0x06020000.
            let (index, sub) = (0x3000, 0);
            let abort = SdoCommand::Abort {
                index,
                sub,
                code: 0x0602_0000,
            };
            sdo_pair(s, node, SdoCommand::InitiateUpload { index, sub }, abort);
        }
        if c % 997 == 11 {
            // EMCY: overcurrent, then its reset.
            s.push(Frame::classic(cob::emcy(node), &[0x10, 0x23, 0x03, 0, 0, 0, 0, 0]));
            s.push(Frame::classic(cob::emcy(node), &[0, 0, 0, 0, 0, 0, 0, 0]));
        }
        if c % 1000 == 13 {
            // NMT: enter pre-operational, then start, all nodes.
            s.push(Frame::classic(0x000, &[0x80, 0]));
            s.push(Frame::classic(0x000, &[0x01, 0]));
        }
    }
}

/// Drives on the generated bus (node-IDs 1..=NODES).
const NODES: u8 = 4;

/// The objects the expedited uploads poll, with the answer's value.
const POLLED: [(u16, u8, u32); 5] = [
    (0x6041, 0, 0x0237),
    (0x6064, 0, 123_456),
    (0x606C, 0, 1500),
    (0x1018, 1, 0x0000_02A5),
    (0x6061, 0, 3),
];

/// The node's four TPDOs and the master's four RPDOs to it.
fn pdos(s: &mut Vec<Frame>, c: u64, node: u8) {
    let pos = (c as i32 * 100 + node as i32).to_le_bytes();
    let vel = ((c % 3000) as i32 - 1500).to_le_bytes();
    let torque = ((c % 200) as i16 - 100).to_le_bytes();
    // TPDO1 statusword + mode display; TPDO2 position + velocity; TPDO3 torque +
    // current; TPDO4 error code + digital inputs.
    s.push(Frame::classic(cob::tpdo(1, node), &[0x37, 0x02, 0x03]));
    s.push(Frame::classic(
        cob::tpdo(2, node),
        &[pos[0], pos[1], pos[2], pos[3], vel[0], vel[1], vel[2], vel[3]],
    ));
    s.push(Frame::classic(cob::tpdo(3, node), &[torque[0], torque[1], 0x20, 0x01]));
    s.push(Frame::classic(cob::tpdo(4, node), &[0, 0, 0x01, 0, 0, 0]));
    // RPDO1 controlword + target velocity; RPDO2 controlword + target position;
    // RPDO3 target torque; RPDO4 profile velocity.
    s.push(Frame::classic(
        cob::rpdo(1, node),
        &[0x0F, 0x00, vel[0], vel[1], vel[2], vel[3]],
    ));
    s.push(Frame::classic(
        cob::rpdo(2, node),
        &[0x1F, 0x00, pos[0], pos[1], pos[2], pos[3]],
    ));
    s.push(Frame::classic(cob::rpdo(3, node), &[torque[0], torque[1]]));
    s.push(Frame::classic(cob::rpdo(4, node), &[0xE8, 0x03, 0, 0]));
}

/// One SDO request from the master and the node's answer.
fn sdo_pair(s: &mut Vec<Frame>, node: u8, request: SdoCommand, answer: SdoCommand) {
    s.push(Frame::classic(cob::sdo_request(node), &encode(&request)));
    s.push(Frame::classic(cob::sdo_response(node), &encode(&answer)));
}

/// An expedited download of `value` (1-4 bytes) to (index, sub), confirmed.
fn expedited_download(s: &mut Vec<Frame>, node: u8, index: u16, sub: u8, value: &[u8]) {
    let request = SdoCommand::InitiateDownload {
        index,
        sub,
        expedited: true,
        size: Some(value.len() as u32),
        data: Chunk::new(value, 4),
    };
    sdo_pair(s, node, request, SdoCommand::InitiateDownloadResponse { index, sub });
}

/// An expedited 4-byte upload of (index, sub) answering `value`.
fn expedited_upload(s: &mut Vec<Frame>, node: u8, index: u16, sub: u8, value: u32) {
    let answer = SdoCommand::InitiateUploadResponse {
        index,
        sub,
        expedited: true,
        size: Some(4),
        data: Chunk::new(&value.to_le_bytes(), 4),
    };
    sdo_pair(s, node, SdoCommand::InitiateUpload { index, sub }, answer);
}

/// A segmented upload of the 16-byte device name (0x1008).
fn segmented_upload(s: &mut Vec<Frame>, node: u8) {
    let name = b"COTUI DRIVE 01!!";
    let (index, sub) = (0x1008, 0);
    let answer = SdoCommand::InitiateUploadResponse {
        index,
        sub,
        expedited: false,
        size: Some(name.len() as u32),
        data: Chunk::default(),
    };
    sdo_pair(s, node, SdoCommand::InitiateUpload { index, sub }, answer);
    let (mut pos, mut toggle) = (0, false);
    loop {
        let (data, end, last) = Chunk::segment(name, pos);
        let segment = SdoCommand::UploadSegmentResponse { toggle, last, data };
        sdo_pair(s, node, SdoCommand::UploadSegment { toggle }, segment);
        if last {
            break;
        }
        (pos, toggle) = (end, !toggle);
    }
}

/// A block upload (no CRC) of 20 bytes of 0x1008: three segments, one block.
fn block_upload(s: &mut Vec<Frame>, node: u8) {
    let data = b"cotui bench drive 01";
    let (index, sub) = (0x1008, 0);
    let request = SdoCommand::BlockUploadInitiate {
        index,
        sub,
        crc: false,
        blksize: 127,
        pst: 0,
    };
    let size = Some(data.len() as u32);
    let answer = SdoCommand::BlockUploadInitiateResponse {
        index,
        sub,
        crc: false,
        size,
    };
    sdo_pair(s, node, request, answer);
    let client = |cmd: SdoCommand| Frame::classic(cob::sdo_request(node), &encode(&cmd));
    s.push(client(SdoCommand::BlockUploadStart));
    let (segments, _) = sub_block(data, 0, 127);
    s.extend(
        segments
            .iter()
            .map(|seg| Frame::classic(cob::sdo_response(node), &encode(seg))),
    );
    s.push(client(SdoCommand::BlockUploadAck {
        ackseq: segments.len() as u8,
        blksize: 127,
    }));
    // The last segment carries 6 data bytes, the 7th unused (n = 1 in the end frame).
    let unused = (segments.len() * 7 - data.len()) as u8;
    let end = SdoCommand::BlockUploadEnd { unused, crc: 0 };
    s.push(Frame::classic(cob::sdo_response(node), &encode(&end)));
    s.push(client(SdoCommand::BlockUploadEndResponse));
}

impl Iterator for Traffic {
    type Item = Frame;

    fn next(&mut self) -> Option<Frame> {
        if self.remaining == 0 {
            return None;
        }
        if self.pos >= self.script.len() {
            self.refill();
        }
        let mut f = self.script[self.pos];
        self.pos += 1;
        self.remaining -= 1;
        f.ts_ns = self.ts_ns;
        self.ts_ns += self.step;
        Some(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deterministic_count_and_timing() {
        let a: Vec<Frame> = Traffic::new(1000, 5).collect();
        let b: Vec<Frame> = Traffic::new(1000, 5).collect();
        assert_eq!(a.len(), 1000);
        assert_eq!(a, b);
        assert_eq!(a[1].ts_ns - a[0].ts_ns, 100_000);
        assert_eq!(a[0].id, 0x080);
        assert!(a.iter().any(|f| f.id == 0x581));
    }

    #[test]
    fn the_mix_is_like_a_commissioning_bus() {
        let frames: Vec<Frame> = Traffic::new(200_000, 0).collect();
        let count = |p: &dyn Fn(&Frame) -> bool| frames.iter().filter(|f| p(f)).count();
        let sdo = count(&|f| (0x581..=0x67F).contains(&f.id));
        assert!(sdo * 10 >= frames.len(), "{sdo} SDO frames of {}", frames.len());
        let first = |f: &Frame| f.payload()[0];
        // Segmented (upload segment request), block (start upload) and abort frames.
        assert!(count(&|f| (0x601..=0x604).contains(&f.id) && first(f) == 0x60) > 0);
        assert!(count(&|f| (0x601..=0x604).contains(&f.id) && first(f) == 0xA3) > 0);
        assert!(count(&|f| (0x581..=0x584).contains(&f.id) && first(f) == 0x80) > 0);
        for base in [0x180, 0x280, 0x380, 0x480, 0x200, 0x300, 0x400, 0x500] {
            assert!(count(&|f| f.id == base + 4) > 1000, "PDO 0x{base:X} of node 4");
        }
        assert!(count(&|f| f.id == 0x000) > 0, "NMT");
        assert!(
            count(&|f| f.id == 0x084 || f.id == 0x081 || f.id == 0x082 || f.id == 0x083) > 0,
            "EMCY"
        );
        assert!(count(&|f| (0x701..=0x704).contains(&f.id)) > 0, "heartbeats");
    }

    #[test]
    fn its_sdo_transfers_are_well_formed() {
        use crate::sdo::tracker::TransferTracker;
        use crate::sdo::{Outcome, Protocol};
        let dict = crate::od::Dictionary::default();
        let mut tracker = TransferTracker::new();
        for (seq, f) in Traffic::new(20_000, 0).enumerate() {
            let (base, node) = (f.id & 0x780, (f.id & 0x7F) as u8);
            if base == 0x580 || base == 0x600 {
                let t = tracker.on_frame(
                    seq as u64,
                    f.ts_ns,
                    crate::frame::NodeKey::of(&f, node),
                    base == 0x600,
                    f.payload(),
                    &dict,
                );
                assert!(t.problems.is_empty(), "frame {seq}: {t:?}");
            }
        }
        let done = tracker.finish();
        let protocols = |p| done.iter().filter(|t| t.protocol == p).count();
        assert!(protocols(Protocol::Segmented) > 0 && protocols(Protocol::Block) > 0);
        for t in &done {
            assert!(t.problems.is_empty(), "{t:?}");
            let aborted = matches!(t.outcome, Outcome::Aborted { code: 0x0602_0000, .. });
            assert!(t.outcome == Outcome::Ok || aborted, "{t:?}");
        }
    }
}
