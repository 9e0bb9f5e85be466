//! pcapng capture files of CAN frames, for Wireshark (`tshark -r`) and anything that reads
//! pcapng.
//!
//! Layout (pcapng, IETF draft `draft-ietf-opsawg-pcapng`), little-endian blocks:
//! - one Section Header Block;
//! - one Interface Description Block per CAN interface, written the first time a frame of
//!   that interface comes: `LINKTYPE_CAN_SOCKETCAN` (227), `if_name` = the interface name,
//!   `if_tsresol` = 9 (timestamps in nanoseconds);
//! - one Enhanced Packet Block per frame: 64-bit nanosecond timestamp, the frame in the
//!   SocketCAN layout (below), `epb_flags` inbound or outbound (cotui's own frames, candump
//!   `T`).
//!
//! The SocketCAN layout is the kernel's `struct can_frame` / `struct canfd_frame` with the
//! CAN ID in network byte order: 4 bytes CAN ID with `CAN_EFF_FLAG` (29-bit), `CAN_RTR_FLAG`
//! and `CAN_ERR_FLAG` (error frame; the ID holds the error class), 1 byte payload length,
//! 1 byte FD flags (`CANFD_BRS`, `CANFD_ESI`, `CANFD_FDF`; zero for classic frames),
//! 1 reserved byte, 1 byte `len8_dlc` (a classic DLC 9..15 with length 8), then the payload:
//! 8 bytes for classic frames (16 in all, `CAN_MTU`), 64 for CAN FD (72, `CANFD_MTU`), so
//! readers that tell FD by the record length and readers that look at `CANFD_FDF` agree.
//!
//! [`PcapngWriter`] writes incrementally (header, then frame by frame, flush), so a
//! recorder can stream into it; the block builders are pure functions of their inputs.

use crate::frame::linux::{CAN_EFF_FLAG, CAN_ERR_FLAG, CAN_RTR_FLAG, CANFD_BRS, CANFD_ESI, CANFD_FDF};
use crate::frame::{Flags, Frame};
use std::io::{self, Write};

/// `LINKTYPE_CAN_SOCKETCAN`.
pub const LINKTYPE_CAN_SOCKETCAN: u16 = 227;

const SHB: u32 = 0x0A0D_0D0A;
const IDB: u32 = 0x0000_0001;
const EPB: u32 = 0x0000_0006;
const BYTE_ORDER_MAGIC: u32 = 0x1A2B_3C4D;
const OPT_ENDOFOPT: u16 = 0;
const IF_NAME: u16 = 2;
const IF_TSRESOL: u16 = 9;
const EPB_FLAGS: u16 = 2;
const EPB_INBOUND: u32 = 1;
const EPB_OUTBOUND: u32 = 2;

/// One option (code, length, value padded to 4 bytes).
fn option(body: &mut Vec<u8>, code: u16, value: &[u8]) {
    body.extend_from_slice(&code.to_le_bytes());
    body.extend_from_slice(&(value.len() as u16).to_le_bytes());
    body.extend_from_slice(value);
    pad4(body);
}

fn pad4(v: &mut Vec<u8>) {
    while !v.len().is_multiple_of(4) {
        v.push(0);
    }
}

/// A block: type, total length, body (a multiple of 4 bytes), total length again.
fn block(kind: u32, body: &[u8]) -> Vec<u8> {
    let total = (body.len() + 12) as u32;
    let mut b = Vec::with_capacity(total as usize);
    b.extend_from_slice(&kind.to_le_bytes());
    b.extend_from_slice(&total.to_le_bytes());
    b.extend_from_slice(body);
    b.extend_from_slice(&total.to_le_bytes());
    b
}

/// The Section Header Block: version 1.0, section length unknown.
pub fn section_header() -> Vec<u8> {
    let mut body = Vec::new();
    body.extend_from_slice(&BYTE_ORDER_MAGIC.to_le_bytes());
    body.extend_from_slice(&1u16.to_le_bytes());
    body.extend_from_slice(&0u16.to_le_bytes());
    body.extend_from_slice(&(-1i64).to_le_bytes());
    block(SHB, &body)
}

/// The Interface Description Block of one CAN interface: SocketCAN link type, no snap
/// length limit, `if_name` and nanosecond `if_tsresol`.
pub fn interface_description(name: &str) -> Vec<u8> {
    let mut body = Vec::new();
    body.extend_from_slice(&LINKTYPE_CAN_SOCKETCAN.to_le_bytes());
    body.extend_from_slice(&0u16.to_le_bytes());
    body.extend_from_slice(&0u32.to_le_bytes());
    // An option value is at most 65535 bytes; interface names are far shorter.
    option(&mut body, IF_NAME, &name.as_bytes()[..name.len().min(0xFFFF)]);
    option(&mut body, IF_TSRESOL, &[9]);
    option(&mut body, OPT_ENDOFOPT, &[]);
    block(IDB, &body)
}

/// The frame in the SocketCAN layout: 16 bytes for classic CAN, 72 for CAN FD.
pub fn socketcan_record(f: &Frame) -> Vec<u8> {
    let mut id = f.id;
    if f.is_err() {
        id |= CAN_ERR_FLAG;
    } else if f.is_ext() {
        id |= CAN_EFF_FLAG;
    }
    if f.is_rtr() && !f.is_fd() {
        id |= CAN_RTR_FLAG;
    }
    let (fd_flags, data_len) = if f.is_fd() {
        let mut fl = CANFD_FDF;
        if f.flags.has(Flags::BRS) {
            fl |= CANFD_BRS;
        }
        if f.flags.has(Flags::ESI) {
            fl |= CANFD_ESI;
        }
        (fl, 64)
    } else {
        (0, 8)
    };
    let mut r = Vec::with_capacity(8 + data_len);
    r.extend_from_slice(&id.to_be_bytes());
    r.push(f.len);
    r.push(fd_flags);
    r.push(0);
    r.push(if f.is_fd() { 0 } else { f.raw_dlc });
    let payload = f.payload();
    r.extend_from_slice(&payload[..payload.len().min(data_len)]);
    r.resize(8 + data_len, 0);
    r
}

/// The Enhanced Packet Block of one frame on interface `interface_id`.
pub fn enhanced_packet(interface_id: u32, f: &Frame) -> Vec<u8> {
    let rec = socketcan_record(f);
    let mut body = Vec::with_capacity(rec.len() + 32);
    body.extend_from_slice(&interface_id.to_le_bytes());
    body.extend_from_slice(&((f.ts_ns >> 32) as u32).to_le_bytes());
    body.extend_from_slice(&(f.ts_ns as u32).to_le_bytes());
    body.extend_from_slice(&(rec.len() as u32).to_le_bytes());
    body.extend_from_slice(&(rec.len() as u32).to_le_bytes());
    body.extend_from_slice(&rec);
    pad4(&mut body);
    let dir = if f.flags.has(Flags::TX) {
        EPB_OUTBOUND
    } else {
        EPB_INBOUND
    };
    option(&mut body, EPB_FLAGS, &dir.to_le_bytes());
    option(&mut body, OPT_ENDOFOPT, &[]);
    block(EPB, &body)
}

/// Streams frames into a pcapng file: [`PcapngWriter::new`] writes the section header,
/// [`PcapngWriter::write_frame`] one frame (and the interface's description block the
/// first time it sees that interface name), [`PcapngWriter::flush`] pushes what is
/// buffered. Memory stays flat: only the interface names seen are kept.
pub struct PcapngWriter<W: Write> {
    out: W,
    interfaces: Vec<String>,
}

impl<W: Write> PcapngWriter<W> {
    /// Starts a pcapng section on `out`.
    pub fn new(mut out: W) -> io::Result<PcapngWriter<W>> {
        out.write_all(&section_header())?;
        Ok(PcapngWriter {
            out,
            interfaces: Vec::new(),
        })
    }

    /// Writes one frame seen on the interface called `iface`.
    pub fn write_frame(&mut self, iface: &str, f: &Frame) -> io::Result<()> {
        let id = match self.interfaces.iter().position(|n| n == iface) {
            Some(i) => i,
            None => {
                self.out.write_all(&interface_description(iface))?;
                self.interfaces.push(iface.to_string());
                self.interfaces.len() - 1
            }
        };
        self.out.write_all(&enhanced_packet(id as u32, f))
    }

    /// Flushes the underlying writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// The underlying writer.
    pub fn into_inner(self) -> W {
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn u32le(b: &[u8], at: usize) -> u32 {
        u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
    }

    #[test]
    fn section_header_layout() {
        let b = section_header();
        assert_eq!(b.len(), 28);
        assert_eq!(&b[..4], &[0x0A, 0x0D, 0x0D, 0x0A]);
        assert_eq!((u32le(&b, 4), u32le(&b, 24)), (28, 28));
        assert_eq!(&b[8..12], &[0x4D, 0x3C, 0x2B, 0x1A]);
        assert_eq!(&b[12..16], &[1, 0, 0, 0]);
        assert_eq!(&b[16..24], &[0xFF; 8]);
    }

    #[test]
    fn interface_block_names_the_interface_and_says_nanoseconds() {
        let b = interface_description("can0");
        assert_eq!(u32le(&b, 0), 1);
        assert_eq!(b.len(), 40);
        assert_eq!((u32le(&b, 4), u32le(&b, 36)), (40, 40));
        assert_eq!(&b[8..10], &[227, 0]);
        assert_eq!(&b[12..16], &[0, 0, 0, 0], "no snap length limit");
        assert_eq!(&b[16..24], &[2, 0, 4, 0, b'c', b'a', b'n', b'0']);
        assert_eq!(&b[24..32], &[9, 0, 1, 0, 9, 0, 0, 0]);
        assert_eq!(&b[32..36], &[0, 0, 0, 0]);
        // Names that are not a multiple of 4 bytes are padded.
        let b = interface_description("vcan10");
        assert_eq!(&b[16..28], &[2, 0, 6, 0, b'v', b'c', b'a', b'n', b'1', b'0', 0, 0]);
        assert_eq!(b.len() % 4, 0);
    }

    #[test]
    fn classic_frame_record() {
        let mut f = Frame::classic(0x605, &[0x40, 0x41, 0x60]);
        assert_eq!(
            socketcan_record(&f),
            [0, 0, 6, 5, 3, 0, 0, 0, 0x40, 0x41, 0x60, 0, 0, 0, 0, 0]
        );
        f.id = 0x18FF_50E5;
        f.flags.set(Flags::EXT, true);
        assert_eq!(&socketcan_record(&f)[..4], &[0x98, 0xFF, 0x50, 0xE5]);
        // A remote request keeps its requested length and sends no data.
        let mut r = Frame::classic(0x705, &[]);
        r.flags.set(Flags::RTR, true);
        r.len = 1;
        assert_eq!(&socketcan_record(&r)[..8], &[0x40, 0, 7, 5, 1, 0, 0, 0]);
        // DLC 12 with 8 bytes: len8_dlc.
        let mut d = Frame::classic(0x123, &[1, 2, 3, 4, 5, 6, 7, 8]);
        d.raw_dlc = 0xC;
        assert_eq!(&socketcan_record(&d)[4..8], &[8, 0, 0, 0x0C]);
    }

    #[test]
    fn error_frame_record() {
        let mut e = Frame::classic(0x004, &[0, 0x0C, 0, 0, 0, 0, 0, 0]);
        e.flags.set(Flags::ERR, true);
        assert_eq!(&socketcan_record(&e)[..9], &[0x20, 0, 0, 4, 8, 0, 0, 0, 0]);
    }

    #[test]
    fn fd_frame_record() {
        let mut f = Frame {
            id: 0x1234_5678,
            len: 12,
            ..Frame::default()
        };
        f.flags.set(Flags::EXT | Flags::FD | Flags::BRS | Flags::ESI, true);
        f.data[..12].copy_from_slice(&[7; 12]);
        let r = socketcan_record(&f);
        assert_eq!(r.len(), 72);
        assert_eq!(&r[..8], &[0x92, 0x34, 0x56, 0x78, 12, 0x07, 0, 0]);
        assert_eq!(&r[8..20], &[7; 12]);
        assert!(r[20..].iter().all(|b| *b == 0));
    }

    #[test]
    fn packet_block_has_nanosecond_time_and_direction() {
        let mut f = Frame::classic(0x080, &[]);
        f.ts_ns = 1_700_000_000_123_456_789;
        let b = enhanced_packet(3, &f);
        assert_eq!(u32le(&b, 0), 6);
        let total = u32le(&b, 4) as usize;
        assert_eq!((b.len(), u32le(&b, total - 4) as usize), (total, total));
        assert_eq!(u32le(&b, 8), 3);
        let ts = (u32le(&b, 12) as u64) << 32 | u32le(&b, 16) as u64;
        assert_eq!(ts, f.ts_ns);
        assert_eq!((u32le(&b, 20), u32le(&b, 24)), (16, 16));
        assert_eq!(&b[44..52], &[2, 0, 4, 0, 1, 0, 0, 0], "inbound");
        f.flags.set(Flags::TX, true);
        assert_eq!(&enhanced_packet(0, &f)[44..52], &[2, 0, 4, 0, 2, 0, 0, 0], "outbound");
    }

    #[test]
    fn writer_describes_each_interface_once() {
        let mut w = PcapngWriter::new(Vec::new()).unwrap();
        let f = Frame::classic(0x701, &[5]);
        w.write_frame("can0", &f).unwrap();
        w.write_frame("vcan10", &f).unwrap();
        w.write_frame("can0", &f).unwrap();
        w.flush().unwrap();
        let b = w.into_inner();
        let mut kinds = Vec::new();
        let mut at = 0;
        while at < b.len() {
            let kind = u32le(&b, at);
            kinds.push((kind, if kind == 6 { u32le(&b, at + 8) } else { u32::MAX }));
            at += u32le(&b, at + 4) as usize;
        }
        assert_eq!(at, b.len());
        assert_eq!(
            kinds,
            [
                (SHB, u32::MAX),
                (IDB, u32::MAX),
                (EPB, 0),
                (IDB, u32::MAX),
                (EPB, 1),
                (EPB, 0)
            ]
        );
    }
}
