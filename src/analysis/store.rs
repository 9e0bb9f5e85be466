//! The trace store: every captured frame, packed into 32 bytes.
//!
//! A [`Packed`] frame keeps the timestamp, identifier, flags, length, interface and the
//! first 8 payload bytes inline, plus the frame's kind and node from the indexing pass
//! (one byte each, so filters on kind and node never decode). CAN FD payloads longer than
//! 8 bytes go to a side arena; their inline bytes then hold the arena offset.
//!
//! Frames live in fixed-size chunks so that growing the store never copies what is
//! already stored and never reserves more than one chunk ahead.

use crate::decode::Kind;
use crate::frame::{Flags, Frame};

/// Frames per chunk (2 MiB of packed frames).
const CHUNK: usize = 1 << 16;

/// `node` byte meaning "no node".
const NO_NODE: u8 = 0xFF;

/// The stored byte of a kind.
pub fn kind_byte(kind: Kind) -> u8 {
    kind.index() as u8
}

/// One stored frame (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Packed {
    /// Timestamp in nanoseconds.
    pub ts_ns: u64,
    /// Identifier without flags.
    pub id: u32,
    /// Interface index.
    pub iface: u16,
    /// [`Flags`] bits.
    pub flags: u8,
    /// Payload length.
    pub len: u8,
    /// Raw DLC of a classic frame with DLC > 8.
    pub raw_dlc: u8,
    kind: u8,
    node: u8,
    /// Payload bytes 0..8, or the arena offset (little endian) when `len > 8`.
    data: [u8; 8],
}

impl Packed {
    /// The kind found when the frame was indexed.
    pub fn kind(&self) -> Kind {
        Kind::ALL[(self.kind as usize).min(Kind::ALL.len() - 1)]
    }
    /// The node found when the frame was indexed.
    pub fn node(&self) -> Option<u8> {
        (self.node != NO_NODE).then_some(self.node)
    }
    /// True for an extended (29-bit) identifier.
    pub fn is_ext(&self) -> bool {
        Flags(self.flags).has(Flags::EXT)
    }
    /// Bits the frame takes on the wire at worst, for the bus load: see [`wire_bits`].
    pub fn wire_bits(&self) -> u64 {
        wire_bits(Flags(self.flags), self.len)
    }
}

/// Bits after the CRC that are never stuffed: CRC delimiter, ACK slot, ACK delimiter (3),
/// end of frame (7) and the intermission between frames (3).
const TAIL_BITS: u64 = 3 + 7 + 3;

/// The most bits a frame with `flags` and `len` payload bytes takes on the bus, the
/// intermission after it included, in nominal bit times.
///
/// Classic CAN: the stuffed part is SOF, identifier, RTR, IDE, r0, DLC and CRC: 34 bits for a
/// base frame (1 + 11 + 1 + 1 + 1 + 4 + 15), 54 for an extended one (1 + 11 + SRR 1 + IDE 1 +
/// 18 + RTR 1 + r1 1 + r0 1 + 4 + 15), plus `8 * len` data bits (none for a remote frame).
/// In the worst case a stuff bit follows the first 5 equal bits and then every 4 bits (the
/// stuff bit starts the next run), so `L` stuffed bits gain `(L - 1) / 4`. Then the 13
/// fixed tail bits. A base frame with n bytes is `34 + 8n + (33 + 8n) / 4 + 13` bits:
/// 55 for n = 0, 135 for n = 8; an extended 8-byte frame is 160.
///
/// CAN FD: the dynamically stuffed part is SOF, identifier, RRS, IDE, FDF, res, BRS, ESI,
/// DLC and data (22 + 8n base, 41 + 8n extended with SRR and the 18-bit extension); then
/// the 4-bit stuff count and the CRC (17 bits up to 16 bytes, 21 above) with a fixed stuff
/// bit before the stuff count and after every 4 bits (6 or 7), then the 13 tail bits.
/// Approximation: every bit is counted at the nominal rate, so a frame with BRS (whose
/// data phase runs faster, at a rate the trace does not know) counts as an upper bound.
///
/// SocketCAN error frames are reports of the controller, not frames on the wire: 0 bits.
pub fn wire_bits(flags: Flags, len: u8) -> u64 {
    if flags.has(Flags::ERR) {
        return 0;
    }
    let ext = flags.has(Flags::EXT);
    let n = u64::from(len);
    let worst_stuff = |stuffed: u64| (stuffed - 1) / 4;
    if flags.has(Flags::FD) {
        let stuffed = if ext { 41 } else { 22 } + 8 * n;
        let crc = if n > 16 { 21 } else { 17 };
        let checked = 4 + crc;
        let fixed_stuff = 1 + (checked - 1) / 4;
        stuffed + worst_stuff(stuffed) + checked + fixed_stuff + TAIL_BITS
    } else {
        let data = if flags.has(Flags::RTR) { 0 } else { 8 * n };
        let stuffed = if ext { 54 } else { 34 } + data;
        stuffed + worst_stuff(stuffed) + TAIL_BITS
    }
}

/// The trace store.
#[derive(Default)]
pub struct Store {
    chunks: Vec<Vec<Packed>>,
    arena: Vec<u8>,
    len: usize,
}

impl Store {
    /// An empty store.
    pub fn new() -> Store {
        Store::default()
    }

    /// Number of stored frames.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Stores `frame` with its kind and node; returns its position.
    pub fn push(&mut self, frame: &Frame, kind: Kind, node: Option<u8>) -> usize {
        let mut data = [0u8; 8];
        if frame.len as usize > 8 {
            let off = self.arena.len() as u64;
            self.arena.extend_from_slice(&frame.data[..frame.len as usize]);
            data = off.to_le_bytes();
        } else {
            data.copy_from_slice(&frame.data[..8]);
        }
        let p = Packed {
            ts_ns: frame.ts_ns,
            id: frame.id,
            iface: frame.iface,
            flags: frame.flags.0,
            len: frame.len,
            raw_dlc: frame.raw_dlc,
            kind: kind_byte(kind),
            node: node.unwrap_or(NO_NODE),
            data,
        };
        if self.len.is_multiple_of(CHUNK) {
            self.chunks.push(Vec::with_capacity(CHUNK));
        }
        let last = self.chunks.len() - 1;
        self.chunks[last].push(p);
        self.len += 1;
        self.len - 1
    }

    /// The packed frame at `i` (panics past the end, like a slice).
    pub fn packed(&self, i: usize) -> &Packed {
        &self.chunks[i / CHUNK][i % CHUNK]
    }

    /// Gives back the unused room of the last chunk (when no more frames will come).
    pub fn shrink(&mut self) {
        if let Some(last) = self.chunks.last_mut() {
            last.shrink_to_fit();
        }
        self.arena.shrink_to_fit();
    }

    /// The frame at `i`, unpacked.
    pub fn frame(&self, i: usize) -> Frame {
        let p = self.packed(i);
        let mut f = Frame {
            ts_ns: p.ts_ns,
            id: p.id,
            flags: Flags(p.flags),
            len: p.len,
            raw_dlc: p.raw_dlc,
            iface: p.iface,
            ..Frame::default()
        };
        if p.len as usize > 8 {
            let off = u64::from_le_bytes(p.data) as usize;
            f.data[..p.len as usize].copy_from_slice(&self.arena[off..off + p.len as usize]);
        } else {
            f.data[..8].copy_from_slice(&p.data);
        }
        f
    }

    /// The first position whose timestamp is at least `ts_ns` (timestamps are assumed to rise).
    pub fn position_at(&self, ts_ns: u64) -> usize {
        let (mut lo, mut hi) = (0, self.len);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.packed(mid).ts_ns < ts_ns {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Bytes of memory held by stored frames (chunk capacity plus arena).
    pub fn bytes(&self) -> usize {
        self.chunks.iter().map(|c| c.capacity()).sum::<usize>() * size_of::<Packed>() + self.arena.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_packed_frame_is_32_bytes() {
        assert_eq!(size_of::<Packed>(), 32);
    }

    #[test]
    fn frames_round_trip_including_fd_payloads_and_chunk_borders() {
        let mut s = Store::new();
        let mut fd = Frame::classic(0x123, &[]);
        fd.flags.set(Flags::FD, true);
        fd.len = 12;
        for (i, b) in fd.data[..12].iter_mut().enumerate() {
            *b = i as u8 + 1;
        }
        for i in 0..CHUNK + 3 {
            let mut f = Frame::classic(0x181, &[i as u8, 2, 3]);
            f.ts_ns = i as u64 * 10;
            s.push(&f, Kind::Tpdo, Some(1));
        }
        let at = s.push(&fd, Kind::Other, None);
        assert_eq!(s.len(), CHUNK + 4);
        s.shrink();
        assert_eq!(s.bytes(), (CHUNK + 4) * 32 + 12);
        assert_eq!(s.frame(at), fd);
        assert_eq!(s.frame(CHUNK + 1).payload(), &[(CHUNK + 1) as u8, 2, 3]);
        assert_eq!(s.packed(5).kind(), Kind::Tpdo);
        assert_eq!(s.packed(5).node(), Some(1));
        assert_eq!(s.packed(at).node(), None);
        assert_eq!(s.position_at(25), 3);
    }

    /// Worst-case bits, hand-computed as stuffed + (stuffed - 1) / 4 + 13 tail bits.
    #[test]
    fn wire_bits_of_classic_frames() {
        let mut s = Store::new();
        // SYNC, base, no data: 34 stuffed + 33/4 = 8 stuff bits + 13 = 55.
        s.push(&Frame::classic(0x80, &[]), Kind::Sync, None);
        // TPDO, base, 8 bytes: 34 + 64 = 98 stuffed + 97/4 = 24 + 13 = 135.
        s.push(&Frame::classic(0x181, &[0; 8]), Kind::Tpdo, Some(1));
        // Extended, 8 bytes: 54 + 64 = 118 stuffed + 117/4 = 29 + 13 = 160.
        s.push(&Frame::classic(0x1234_5678, &[0; 8]), Kind::Other, None);
        // Base, 1 byte: 42 stuffed + 41/4 = 10 + 13 = 65.
        s.push(&Frame::classic(0x701, &[0x05]), Kind::Heartbeat, Some(1));
        let bits: Vec<u64> = (0..4).map(|i| s.packed(i).wire_bits()).collect();
        assert_eq!(bits, [55, 135, 160, 65]);
    }

    #[test]
    fn wire_bits_of_remote_error_and_fd_frames() {
        let rtr = Flags(Flags::RTR);
        // A remote frame carries no data whatever its DLC: base 55, extended 54 + 53/4 = 13 + 13 = 80.
        assert_eq!(wire_bits(rtr, 8), 55);
        assert_eq!(wire_bits(Flags(Flags::RTR | Flags::EXT), 4), 80);
        assert_eq!(wire_bits(Flags(Flags::ERR), 8), 0);
        let fd = Flags(Flags::FD);
        // FD base, 8 bytes: 22 + 64 = 86 stuffed + 85/4 = 21; stuff count + CRC-17 = 21 bits
        // with 1 + 20/4 = 6 fixed stuff bits; + 13 tail: 86 + 21 + 21 + 6 + 13 = 147.
        assert_eq!(wire_bits(fd, 8), 147);
        // FD base, 64 bytes: 534 stuffed + 533/4 = 133; 4 + CRC-21 = 25 bits with 1 + 24/4 = 7
        // fixed stuff bits; + 13: 534 + 133 + 25 + 7 + 13 = 712.
        assert_eq!(wire_bits(fd, 64), 712);
        // FD extended, 16 bytes (still CRC-17): 41 + 128 = 169 + 168/4 = 42; 21 + 6; 13: 251.
        assert_eq!(wire_bits(Flags(Flags::FD | Flags::EXT), 16), 251);
        // BRS changes nothing: counted at the nominal rate (an upper bound).
        assert_eq!(wire_bits(Flags(Flags::FD | Flags::BRS), 8), 147);
    }
}
