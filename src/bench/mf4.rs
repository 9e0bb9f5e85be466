//! The bench log as ASAM MDF4, for the MF4 input row: one sorted data group of
//! `CAN_DataFrame` records (float seconds after the header's start time, bus channel, ID,
//! IDE, DLC, data length, 8 data bytes, direction) in one `##DT` block, the shape
//! python-can's `MF4Writer` writes (classic frames only: the synthetic traffic has no FD).

use crate::frame::Frame;
use crate::sim::synth::Traffic;
use std::io::Write;
use std::path::Path;

/// Bytes of one record: time f64, bus u8, ID u32, IDE, DLC, data length, 8 bytes, Dir.
const RECORD: u32 = 25;

/// The blocks before the data, built at known offsets.
struct Blocks(Vec<u8>);

impl Blocks {
    /// Appends a block and returns its file offset (blocks start on 8-byte boundaries).
    fn add(&mut self, id: &[u8; 4], links: &[u64], data: &[u8]) -> u64 {
        let at = self.0.len() as u64;
        let len = 24 + 8 * links.len() + data.len();
        self.0.extend_from_slice(id);
        self.0.extend_from_slice(&[0; 4]);
        self.0.extend_from_slice(&(len as u64).to_le_bytes());
        self.0.extend_from_slice(&(links.len() as u64).to_le_bytes());
        for l in links {
            self.0.extend_from_slice(&l.to_le_bytes());
        }
        self.0.extend_from_slice(data);
        self.0.resize(self.0.len().next_multiple_of(8), 0);
        at
    }
    fn text(&mut self, s: &str) -> u64 {
        let mut d = s.as_bytes().to_vec();
        d.push(0);
        self.add(b"##TX", &[], &d)
    }
    fn set_link(&mut self, block: u64, i: usize, to: u64) {
        let at = block as usize + 24 + 8 * i;
        self.0[at..at + 8].copy_from_slice(&to.to_le_bytes());
    }
    /// A `##CN` block: type (0 value, 2 master), sync (1 time), data type, byte, bits.
    fn channel(&mut self, name: &str, cn_type: u8, data_type: u8, byte: u32, bits: u32) -> u64 {
        let name = self.text(name);
        let mut d = vec![cn_type, u8::from(cn_type == 2), data_type, 0];
        d.extend_from_slice(&byte.to_le_bytes());
        d.extend_from_slice(&bits.to_le_bytes());
        d.resize(72, 0);
        self.add(b"##CN", &[0, 0, name, 0, 0, 0, 0, 0], &d)
    }
}

/// Writes `frames` synthetic frames (the bench log's, on bus channel 0) as MF4 to `path`.
pub fn write_mf4_log(path: &Path, frames: u64) -> std::io::Result<()> {
    const START_NS: u64 = 1_700_000_000_000_000_000;
    let mut b = Blocks(b"MDF     4.10    cotui   ".to_vec());
    b.0.extend_from_slice(&[0; 4]);
    b.0.extend_from_slice(&410u16.to_le_bytes());
    b.0.resize(64, 0);
    let mut hd_data = START_NS.to_le_bytes().to_vec();
    hd_data.resize(32, 0);
    let hd = b.add(b"##HD", &[0; 6], &hd_data);
    let dg = b.add(b"##DG", &[0; 4], &[0; 8]);
    let mut cg_data = vec![0u8; 32];
    cg_data[8..16].copy_from_slice(&frames.to_le_bytes());
    cg_data[24..28].copy_from_slice(&RECORD.to_le_bytes());
    let cg = b.add(b"##CG", &[0; 6], &cg_data);
    let members = [
        ("BusChannel", 0, 8, 8),
        ("ID", 0, 9, 32),
        ("IDE", 0, 13, 8),
        ("DLC", 0, 14, 8),
        ("DataLength", 0, 15, 8),
        ("DataBytes", 10, 16, 64),
        ("Dir", 0, 24, 8),
    ];
    let time = b.channel("t", 2, 4, 0, 64);
    let frame = b.channel("CAN_DataFrame", 0, 10, 8, (RECORD - 8) * 8);
    let mut prev = None;
    for (name, data_type, byte, bits) in members {
        let cn = b.channel(&format!("CAN_DataFrame.{name}"), 0, data_type, byte, bits);
        match prev {
            None => b.set_link(frame, 1, cn),
            Some(p) => b.set_link(p, 0, cn),
        }
        prev = Some(cn);
    }
    b.set_link(time, 0, frame);
    b.set_link(cg, 1, time);
    b.set_link(dg, 1, cg);
    b.set_link(hd, 0, dg);
    let dt = b.0.len() as u64;
    b.set_link(dg, 2, dt);
    let mut out = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    out.write_all(&b.0)?;
    out.write_all(b"##DT\0\0\0\0")?;
    out.write_all(&(24 + frames * u64::from(RECORD)).to_le_bytes())?;
    out.write_all(&0u64.to_le_bytes())?;
    for f in Traffic::new(frames, START_NS) {
        out.write_all(&record(&f, START_NS))?;
    }
    out.flush()
}

fn record(f: &Frame, start_ns: u64) -> [u8; RECORD as usize] {
    let mut r = [0u8; RECORD as usize];
    let secs = (f.ts_ns as i128 - start_ns as i128) as f64 / 1e9;
    r[..8].copy_from_slice(&secs.to_le_bytes());
    r[9..13].copy_from_slice(&f.id.to_le_bytes());
    r[13] = u8::from(f.is_ext());
    r[14] = f.len;
    r[15] = f.len;
    r[16..16 + f.len.min(8) as usize].copy_from_slice(&f.data[..f.len.min(8) as usize]);
    r[24] = u8::from(f.flags.has(crate::frame::Flags::TX));
    r
}
