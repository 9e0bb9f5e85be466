//! Synthetic CANopen traffic for benchmarks: a deterministic mix that looks
//! like a commissioning bus (SYNC, four TPDOs and RPDOs per drive, heartbeats,
//! about 12 % SDO frames with segmented and block transfers and aborts, EMCY, NMT).
//! Pure: the same frame count always gives the same frames.

use crate::frame::Frame;

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
        for node in 1u32..=NODES {
            pdos(s, c, node);
        }
        if c.is_multiple_of(10) {
            for node in 1..=NODES {
                s.push(Frame::classic(0x700 + node, &[0x05]));
            }
        }
        // Every cycle one expedited upload, every other cycle one expedited download,
        // each on the next node in turn.
        let node = (c % u64::from(NODES)) as u32 + 1;
        let (index, sub, value) = POLLED[(c / u64::from(NODES)) as usize % POLLED.len()];
        expedited_upload(s, node, index, sub, value);
        if c.is_multiple_of(2) {
            let mode = [1u8, 3, 8][(c / 2 % 3) as usize];
            sdo_pair(
                s,
                node,
                [0x2F, 0x60, 0x60, 0, mode, 0, 0, 0],
                [0x60, 0x60, 0x60, 0, 0, 0, 0, 0],
            );
        }
        if c % 8 == 3 {
            segmented_upload(s, node);
        }
        if c % 16 == 5 {
            block_upload(s, node);
        }
        if c % 50 == 7 {
            // A read of an object the drive does not have: abort 0x06020000.
            sdo_pair(
                s,
                node,
                [0x40, 0x00, 0x30, 0, 0, 0, 0, 0],
                [0x80, 0x00, 0x30, 0, 0, 0, 2, 6],
            );
        }
        if c % 997 == 11 {
            // EMCY: overcurrent, then its reset.
            s.push(Frame::classic(0x080 + node, &[0x10, 0x23, 0x03, 0, 0, 0, 0, 0]));
            s.push(Frame::classic(0x080 + node, &[0, 0, 0, 0, 0, 0, 0, 0]));
        }
        if c % 1000 == 13 {
            // NMT: enter pre-operational, then start, all nodes.
            s.push(Frame::classic(0x000, &[0x80, 0]));
            s.push(Frame::classic(0x000, &[0x01, 0]));
        }
    }
}

/// Drives on the generated bus (node-IDs 1..=NODES).
const NODES: u32 = 4;

/// The objects the expedited uploads poll, with the answer's value.
const POLLED: [(u16, u8, u32); 5] = [
    (0x6041, 0, 0x0237),
    (0x6064, 0, 123_456),
    (0x606C, 0, 1500),
    (0x1018, 1, 0x0000_02A5),
    (0x6061, 0, 3),
];

/// The node's four TPDOs and the master's four RPDOs to it.
fn pdos(s: &mut Vec<Frame>, c: u64, node: u32) {
    let pos = (c as i32 * 100 + node as i32).to_le_bytes();
    let vel = ((c % 3000) as i32 - 1500).to_le_bytes();
    let torque = ((c % 200) as i16 - 100).to_le_bytes();
    // TPDO1 statusword + mode display; TPDO2 position + velocity; TPDO3 torque +
    // current; TPDO4 error code + digital inputs.
    s.push(Frame::classic(0x180 + node, &[0x37, 0x02, 0x03]));
    s.push(Frame::classic(
        0x280 + node,
        &[pos[0], pos[1], pos[2], pos[3], vel[0], vel[1], vel[2], vel[3]],
    ));
    s.push(Frame::classic(0x380 + node, &[torque[0], torque[1], 0x20, 0x01]));
    s.push(Frame::classic(0x480 + node, &[0, 0, 0x01, 0, 0, 0]));
    // RPDO1 controlword + target velocity; RPDO2 controlword + target position;
    // RPDO3 target torque; RPDO4 profile velocity.
    s.push(Frame::classic(
        0x200 + node,
        &[0x0F, 0x00, vel[0], vel[1], vel[2], vel[3]],
    ));
    s.push(Frame::classic(
        0x300 + node,
        &[0x1F, 0x00, pos[0], pos[1], pos[2], pos[3]],
    ));
    s.push(Frame::classic(0x400 + node, &[torque[0], torque[1]]));
    s.push(Frame::classic(0x500 + node, &[0xE8, 0x03, 0, 0]));
}

/// One SDO request from the master and the node's answer.
fn sdo_pair(s: &mut Vec<Frame>, node: u32, request: [u8; 8], answer: [u8; 8]) {
    s.push(Frame::classic(0x600 + node, &request));
    s.push(Frame::classic(0x580 + node, &answer));
}

/// An expedited 4-byte upload of (index, sub) answering `value`.
fn expedited_upload(s: &mut Vec<Frame>, node: u32, index: u16, sub: u8, value: u32) {
    let [i0, i1] = index.to_le_bytes();
    let [v0, v1, v2, v3] = value.to_le_bytes();
    sdo_pair(
        s,
        node,
        [0x40, i0, i1, sub, 0, 0, 0, 0],
        [0x43, i0, i1, sub, v0, v1, v2, v3],
    );
}

/// A segmented upload of the 16-byte device name (0x1008).
fn segmented_upload(s: &mut Vec<Frame>, node: u32) {
    sdo_pair(
        s,
        node,
        [0x40, 0x08, 0x10, 0, 0, 0, 0, 0],
        [0x41, 0x08, 0x10, 0, 16, 0, 0, 0],
    );
    sdo_pair(
        s,
        node,
        [0x60, 0, 0, 0, 0, 0, 0, 0],
        [0x00, b'C', b'O', b'T', b'U', b'I', b' ', b'D'],
    );
    sdo_pair(
        s,
        node,
        [0x70, 0, 0, 0, 0, 0, 0, 0],
        [0x10, b'R', b'I', b'V', b'E', b' ', b'0', b'1'],
    );
    sdo_pair(s, node, [0x60, 0, 0, 0, 0, 0, 0, 0], [0x0D, b'!', b'!', 0, 0, 0, 0, 0]);
}

/// A block upload (no CRC) of 20 bytes of 0x1008: three segments, one block.
fn block_upload(s: &mut Vec<Frame>, node: u32) {
    sdo_pair(
        s,
        node,
        [0xA0, 0x08, 0x10, 0, 127, 0, 0, 0],
        [0xC2, 0x08, 0x10, 0, 20, 0, 0, 0],
    );
    s.push(Frame::classic(0x600 + node, &[0xA3, 0, 0, 0, 0, 0, 0, 0]));
    s.push(Frame::classic(
        0x580 + node,
        &[0x01, b'c', b'o', b't', b'u', b'i', b' '],
    ));
    s.push(Frame::classic(
        0x580 + node,
        &[0x02, b'b', b'e', b'n', b'c', b'h', b' '],
    ));
    // Last segment: 6 data bytes, the 7th unused (n = 1 in the end frame).
    s.push(Frame::classic(
        0x580 + node,
        &[0x83, b'd', b'r', b'i', b'v', b'e', b'!', 0],
    ));
    s.push(Frame::classic(0x600 + node, &[0xA2, 3, 127, 0, 0, 0, 0, 0]));
    s.push(Frame::classic(0x580 + node, &[0xC5, 0, 0, 0, 0, 0, 0, 0]));
    s.push(Frame::classic(0x600 + node, &[0xA1, 0, 0, 0, 0, 0, 0, 0]));
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
}
