//! The trace store: every captured frame, packed into 20 bytes.
//!
//! A stored frame keeps a 32-bit timestamp offset, the identifier, flags, length,
//! interface and the first 8 payload bytes inline, plus the frame's kind and node from the
//! indexing pass (so filters on kind and node never decode). The length shares a byte
//! with a classic frame's raw DLC, the interface (up to the 15th) a byte with the kind; a
//! frame on a later interface, or of another shape, keeps those in its chunk's side table.
//! CAN FD
//! payloads longer than 8 bytes go to a side arena; their inline bytes then hold the arena
//! offset. The offset counts nanoseconds from its segment's base: a chunk starts a new
//! segment (its base 2^31 ns before the frame) whenever a timestamp falls outside the
//! current one, so a rising capture needs one segment per ~4.3 s and a step back of up to
//! ~2.1 s (frames of two interfaces a little out of order) needs none.
//!
//! Frames live in fixed-size chunks so that growing the store never copies what is
//! already stored and never reserves more than one chunk ahead.

use crate::decode::Kind;
use crate::frame::{Flags, Frame};

/// Frames per chunk (1.5 MiB of packed frames).
const CHUNK: usize = 1 << 16;

/// `node` byte meaning "no node".
const NO_NODE: u8 = 0xFF;

/// How far before its first frame a segment's base lies (ns): steps back up to this
/// much stay in the segment.
const BACK_NS: u64 = 1 << 31;

/// The stored byte of a kind.
pub fn kind_byte(kind: Kind) -> u8 {
    kind.index() as u8
}

/// One stored frame as the store gives it back, its timestamp whole.
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

/// A frame as kept (20 bytes): [`Packed`] with the timestamp as an offset in its segment.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
struct Kept {
    ts_off: u32,
    id: u32,
    data: [u8; 8],
    flags: u8,
    /// An FD frame's length; a classic frame's length (low nibble) and raw DLC (high).
    len_dlc: u8,
    /// The kind (low nibble) and the interface (high nibble; [`ODD`]: see the side table).
    kind_iface: u8,
    node: u8,
}

/// Interface nibble of a frame whose interface, length and raw DLC are in
/// [`Chunk::odd`].
const ODD: u8 = 15;

/// The interface, length and raw DLC of a frame that does not fit [`Kept`]'s bytes.
#[derive(Clone, Copy, Debug)]
struct Odd {
    at: u32,
    iface: u16,
    len: u8,
    raw_dlc: u8,
}

impl Kept {
    /// The length-and-DLC byte of a frame, when its shape fits one.
    fn len_dlc(frame: &Frame) -> Option<u8> {
        if frame.flags.has(Flags::FD) {
            (frame.raw_dlc == 0).then_some(frame.len)
        } else {
            (frame.len < 16 && frame.raw_dlc < 16).then_some(frame.len | frame.raw_dlc << 4)
        }
    }

    /// (length, raw DLC) from the byte.
    fn len_and_dlc(&self) -> (u8, u8) {
        if Flags(self.flags).has(Flags::FD) {
            (self.len_dlc, 0)
        } else {
            (self.len_dlc & 15, self.len_dlc >> 4)
        }
    }
}

/// Up to [`CHUNK`] frames and the timestamp bases of their segments.
#[derive(Default)]
struct Chunk {
    frames: Vec<Kept>,
    /// (index of the segment's first frame in the chunk, its base in ns), rising.
    segments: Vec<(u32, u64)>,
    /// The frames marked [`ODD`], by rising index.
    odd: Vec<Odd>,
}

impl Chunk {
    fn new() -> Chunk {
        Chunk {
            frames: Vec::with_capacity(CHUNK),
            segments: Vec::new(),
            odd: Vec::new(),
        }
    }

    /// The offset of `ts_ns` in the current segment, a new segment started when it does
    /// not fit (`at`: the index the frame will take).
    fn offset(&mut self, ts_ns: u64, at: usize) -> u32 {
        if let Some(&(_, base)) = self.segments.last()
            && let Some(off) = ts_ns.checked_sub(base).and_then(|o| u32::try_from(o).ok())
        {
            return off;
        }
        let base = ts_ns.saturating_sub(BACK_NS);
        self.segments.push((at as u32, base));
        (ts_ns - base) as u32
    }

    /// The base of the segment of frame `k`.
    fn base(&self, k: usize) -> u64 {
        let n = self.segments.partition_point(|&(first, _)| first as usize <= k);
        self.segments[n.saturating_sub(1)].1
    }

    /// Frame `k`, its timestamp whole.
    fn get(&self, k: usize) -> Packed {
        let f = &self.frames[k];
        let (iface, (len, raw_dlc)) = match f.kind_iface >> 4 {
            ODD => {
                let i = self.odd.partition_point(|o| (o.at as usize) < k);
                self.odd.get(i).map_or((0, (0, 0)), |o| (o.iface, (o.len, o.raw_dlc)))
            }
            iface => (u16::from(iface), f.len_and_dlc()),
        };
        Packed {
            ts_ns: self.base(k) + u64::from(f.ts_off),
            id: f.id,
            iface,
            flags: f.flags,
            len,
            raw_dlc,
            kind: f.kind_iface & 15,
            node: f.node,
            data: f.data,
        }
    }
}

/// The trace store.
#[derive(Default)]
pub struct Store {
    chunks: Vec<Chunk>,
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
        if self.len.is_multiple_of(CHUNK) {
            self.chunks.push(Chunk::new());
        }
        let at = self.len % CHUNK;
        let Some(chunk) = self.chunks.last_mut() else {
            unreachable!("a chunk was just pushed")
        };
        let ts_off = chunk.offset(frame.ts_ns, at);
        let fits = Kept::len_dlc(frame).filter(|_| frame.iface < u16::from(ODD));
        if fits.is_none() {
            chunk.odd.push(Odd {
                at: at as u32,
                iface: frame.iface,
                len: frame.len,
                raw_dlc: frame.raw_dlc,
            });
        }
        let iface = fits.map_or(ODD, |_| frame.iface as u8);
        chunk.frames.push(Kept {
            ts_off,
            id: frame.id,
            data,
            flags: frame.flags.0,
            len_dlc: fits.unwrap_or(0),
            kind_iface: kind_byte(kind) | iface << 4,
            node: node.unwrap_or(NO_NODE),
        });
        self.len += 1;
        self.len - 1
    }

    /// The stored frame at `i` (panics past the end, like a slice).
    pub fn packed(&self, i: usize) -> Packed {
        self.chunks[i / CHUNK].get(i % CHUNK)
    }

    /// Gives back the unused room of the last chunk (when no more frames will come).
    pub fn shrink(&mut self) {
        if let Some(last) = self.chunks.last_mut() {
            last.frames.shrink_to_fit();
            last.odd.shrink_to_fit();
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

    /// Bytes of memory held by stored frames (chunk capacity, segment bases and arena).
    pub fn bytes(&self) -> usize {
        let chunks: usize = self
            .chunks
            .iter()
            .map(|c| {
                c.frames.capacity() * size_of::<Kept>()
                    + c.segments.capacity() * size_of::<(u32, u64)>()
                    + c.odd.capacity() * size_of::<Odd>()
            })
            .sum();
        chunks + self.arena.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_frame_is_20_bytes() {
        assert_eq!(size_of::<Kept>(), 20);
        assert!(Kind::ALL.len() < 16, "a kind fits a nibble");
    }

    /// Frames on interfaces past the 15th, classic frames with a raw DLC over 8 and FD
    /// frames of every length come back whole, mixed with common ones.
    #[test]
    fn every_interface_length_and_dlc_comes_back() {
        let mut s = Store::new();
        let mut frames = Vec::new();
        for i in 0..40u16 {
            let mut f = Frame::classic(0x181 + u32::from(i), &[i as u8; 8]);
            f.iface = i * 7 % 300;
            if i % 3 == 0 {
                f.raw_dlc = 9 + (i % 7) as u8;
            }
            if i % 5 == 0 {
                f.flags.set(Flags::FD, true);
                f.len = [12, 64, 8, 0][usize::from(i / 5 % 4)];
                f.raw_dlc = 0;
            }
            f.ts_ns = u64::from(i) * 1000;
            s.push(&f, Kind::ALL[usize::from(i) % Kind::ALL.len()], Some(i as u8));
            frames.push(f);
        }
        for (i, f) in frames.iter().enumerate() {
            assert_eq!(&s.frame(i), f, "frame {i}");
            assert_eq!(s.packed(i).kind(), Kind::ALL[i % Kind::ALL.len()]);
            assert_eq!(s.packed(i).node(), Some(i as u8));
        }
    }

    #[test]
    fn timestamps_come_back_whole_across_segments_and_steps_back() {
        let mut s = Store::new();
        // Rising by 3 s (a new segment every other frame), a step back of 2 s (same
        // segment), one of an hour (a new one), the clock's extremes.
        let times = [
            5,
            3_000_000_005,
            6_000_000_005,
            4_000_000_005,
            4_000_000_006,
            1,
            u64::MAX,
            0,
            7,
        ];
        for &t in &times {
            let mut f = Frame::classic(0x181, &[1]);
            f.ts_ns = t;
            s.push(&f, Kind::Tpdo, Some(1));
        }
        let back: Vec<u64> = (0..times.len()).map(|i| s.packed(i).ts_ns).collect();
        assert_eq!(back, times);
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
        // 20 bytes a frame, the FD payload, and one segment base a chunk (the frames span
        // 0.65 ms), as a small vector's room.
        let frames = (CHUNK + 4) * 20 + 12;
        assert!(
            (frames + 2 * 16..=frames + 2 * 4 * 16).contains(&s.bytes()),
            "{}",
            s.bytes()
        );
        assert_eq!(s.frame(at), fd);
        assert_eq!(s.frame(CHUNK + 1).payload(), &[(CHUNK + 1) as u8, 2, 3]);
        assert_eq!(s.packed(5).kind(), Kind::Tpdo);
        assert_eq!(s.packed(5).node(), Some(1));
        assert_eq!(s.packed(at).node(), None);
        assert_eq!(s.position_at(25), 3);
    }
}
