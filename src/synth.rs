//! Synthetic CANopen traffic for benchmarks: a deterministic mix that looks
//! like a busy drive bench (SYNC, PDOs, heartbeats, SDO transfers, EMCY).
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
        self.script.push(Frame::classic(0x080, &[(c % 240 + 1) as u8]));
        for node in 1u8..=4 {
            let pos = (c as i32 * 100 + node as i32).to_le_bytes();
            let vel = ((c % 3000) as i32 - 1500).to_le_bytes();
            // TPDO1: statusword + mode display; TPDO2: position + velocity.
            self.script
                .push(Frame::classic(0x180 + node as u32, &[0x37, 0x02, 0x03]));
            self.script.push(Frame::classic(
                0x280 + node as u32,
                &[pos[0], pos[1], pos[2], pos[3], vel[0], vel[1], vel[2], vel[3]],
            ));
            // RPDO1 from the master: controlword + target velocity.
            self.script.push(Frame::classic(
                0x200 + node as u32,
                &[0x0F, 0x00, vel[0], vel[1], vel[2], vel[3]],
            ));
        }
        if c.is_multiple_of(10) {
            for node in 1u8..=4 {
                self.script.push(Frame::classic(0x700 + node as u32, &[0x05]));
            }
        }
        if c.is_multiple_of(7) {
            let node = (c % 4) as u32 + 1;
            // Expedited upload of the statusword.
            self.script
                .push(Frame::classic(0x600 + node, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]));
            self.script
                .push(Frame::classic(0x580 + node, &[0x4B, 0x41, 0x60, 0, 0x37, 0x02, 0, 0]));
        }
        if c.is_multiple_of(50) {
            // Segmented upload of the device name (0x1008), 16 bytes.
            let node = (c % 4) as u32 + 1;
            self.script
                .push(Frame::classic(0x600 + node, &[0x40, 0x08, 0x10, 0, 0, 0, 0, 0]));
            self.script
                .push(Frame::classic(0x580 + node, &[0x41, 0x08, 0x10, 0, 16, 0, 0, 0]));
            self.script
                .push(Frame::classic(0x600 + node, &[0x60, 0, 0, 0, 0, 0, 0, 0]));
            self.script.push(Frame::classic(
                0x580 + node,
                &[0x00, b'C', b'O', b'T', b'U', b'I', b' ', b'D'],
            ));
            self.script
                .push(Frame::classic(0x600 + node, &[0x70, 0, 0, 0, 0, 0, 0, 0]));
            self.script.push(Frame::classic(
                0x580 + node,
                &[0x10, b'R', b'I', b'V', b'E', b' ', b'0', b'1'],
            ));
            self.script
                .push(Frame::classic(0x600 + node, &[0x60, 0, 0, 0, 0, 0, 0, 0]));
            self.script
                .push(Frame::classic(0x580 + node, &[0x0D, b'!', b'!', 0, 0, 0, 0, 0]));
        }
        if c.is_multiple_of(997) {
            self.script.push(Frame::classic(
                0x081 + (c % 4) as u32,
                &[0x10, 0x23, 0x03, 0, 0, 0, 0, 0],
            ));
        }
    }
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
}
