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

    /// The bits frame `i` takes on the bus, its intermission included (exact: rebuilt as
    /// sent, see [`crate::wire`]; 0 for an error frame).
    pub fn bus_bits(&self, i: usize) -> u64 {
        crate::output::busload::bus_bits(&self.frame(i))
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
}
