//! The SDO transfers the TUI keeps, packed: a trace of a commissioning bus completes a
//! transfer every ~15 frames, so a 50 M-frame trace lists millions of them.
//!
//! A transfer of the common shape (the default SDO channel of its node, at most 8 bytes,
//! at most [`FRAMES_INLINE`] frames less than 2^32 positions apart, under ~4.3 s, no
//! problems, ended ok, incomplete or by an abort with no data) packs into 56 bytes with
//! nothing on the heap; any other transfer is kept whole beside them. [`TransferList::get`]
//! gives back exactly the [`Transaction`] pushed.

use crate::sdo::{Channel, Outcome, Protocol, Side, Transaction, TransferDirection, abort_text};

/// Frames a packed transfer holds (an expedited transfer has 2, a one-segment upload 4).
const FRAMES_INLINE: usize = 4;

/// One transfer of the common shape, or the place of a whole one in `whole`.
#[derive(Clone, Copy, Debug)]
struct Packed {
    start_ns: u64,
    /// The first frame's number (or, when [`WHOLE`] is set, the index into `whole`).
    first_frame: u64,
    /// How far the later frames lie behind the first.
    later_frames: [u32; FRAMES_INLINE - 1],
    end_after_ns: u32,
    /// The indicated size (when [`HAS_SIZE`] is set).
    size: u32,
    /// The data, or the abort code (little endian) of an aborted transfer.
    data: [u8; 8],
    index: u16,
    iface: u16,
    node: u8,
    sub: u8,
    mode: i8,
    /// [`WHOLE`], [`HAS_SIZE`], [`HAS_MODE`], [`DOWNLOAD`], [`BY_SERVER`], the protocol
    /// (bits 5-6) and the outcome (bits 7-8).
    bits: u16,
    /// Data length (low nibble) and frame count (high nibble).
    counts: u8,
}

const WHOLE: u16 = 1;
const HAS_SIZE: u16 = 1 << 1;
const HAS_MODE: u16 = 1 << 2;
const DOWNLOAD: u16 = 1 << 3;
const BY_SERVER: u16 = 1 << 4;
const PROTOCOL_SHIFT: u16 = 5;
const OUTCOME_SHIFT: u16 = 7;

const PROTOCOLS: [Protocol; 4] = [
    Protocol::Expedited,
    Protocol::Segmented,
    Protocol::Block,
    Protocol::Unknown,
];

/// The SDO transfers of a trace in the order they were listed.
#[derive(Clone, Debug, Default)]
pub struct TransferList {
    packed: Vec<Packed>,
    whole: Vec<Transaction>,
}

impl TransferList {
    /// Appends one transfer.
    pub fn push(&mut self, t: Transaction) {
        let p = pack(&t).unwrap_or_else(|| {
            let p = Packed::whole(self.whole.len());
            let mut t = t;
            t.data.shrink_to_fit();
            t.frames.shrink_to_fit();
            self.whole.push(t);
            p
        });
        self.packed.push(p);
    }

    /// Number of transfers.
    pub fn len(&self) -> usize {
        self.packed.len()
    }

    /// True when no transfer is listed.
    pub fn is_empty(&self) -> bool {
        self.packed.is_empty()
    }

    /// Transfer `i`, as it was pushed.
    pub fn get(&self, i: usize) -> Option<Transaction> {
        let p = self.packed.get(i)?;
        if p.bits & WHOLE != 0 {
            return self.whole.get(p.first_frame as usize).cloned();
        }
        Some(unpack(p))
    }

    /// How transfer `i` ended (without building the whole transfer).
    pub fn outcome(&self, i: usize) -> Option<Outcome> {
        let p = self.packed.get(i)?;
        if p.bits & WHOLE != 0 {
            return self.whole.get(p.first_frame as usize).map(|t| t.outcome.clone());
        }
        Some(outcome_of(p))
    }

    /// Every transfer, in order.
    pub fn iter(&self) -> impl Iterator<Item = Transaction> + '_ {
        self.iter_from(0)
    }

    /// Every transfer from `from` on, in order.
    pub fn iter_from(&self, from: usize) -> impl Iterator<Item = Transaction> + '_ {
        (from..self.len()).filter_map(|i| self.get(i))
    }

    /// Bytes the list holds (the packed records and the whole transfers with their data).
    pub fn bytes(&self) -> usize {
        let whole: usize = self
            .whole
            .iter()
            .map(|t| {
                t.data.capacity() + t.frames.capacity() * 8 + t.problems.capacity() * size_of::<crate::sdo::Problem>()
            })
            .sum();
        self.packed.capacity() * size_of::<Packed>() + self.whole.capacity() * size_of::<Transaction>() + whole
    }
}

impl Packed {
    /// A record pointing at whole transfer `k`.
    fn whole(k: usize) -> Packed {
        Packed {
            start_ns: 0,
            first_frame: k as u64,
            later_frames: [0; FRAMES_INLINE - 1],
            end_after_ns: 0,
            size: 0,
            data: [0; 8],
            index: 0,
            iface: 0,
            node: 0,
            sub: 0,
            mode: 0,
            bits: WHOLE,
            counts: 0,
        }
    }
}

/// `t` packed, or None when it has another shape than the common one.
fn pack(t: &Transaction) -> Option<Packed> {
    let default_channel = t.channel == Channel::default_on(t.key());
    if !default_channel || t.data.len() > 8 || t.dropped != 0 || !t.problems.is_empty() || t.frames_dropped != 0 {
        return None;
    }
    let (&first, later) = t.frames.split_first().unwrap_or((&0, &[]));
    if t.frames.len() > FRAMES_INLINE {
        return None;
    }
    let mut later_frames = [0; FRAMES_INLINE - 1];
    for (slot, &f) in later_frames.iter_mut().zip(later) {
        *slot = u32::try_from(f.checked_sub(first)?).ok()?;
    }
    let end_after_ns = u32::try_from(t.end_ns.checked_sub(t.start_ns)?).ok()?;
    let mut data = [0; 8];
    data[..t.data.len()].copy_from_slice(&t.data);
    let (outcome, by) = match &t.outcome {
        Outcome::Ok => (0, Side::Client),
        Outcome::Incomplete => (1, Side::Client),
        Outcome::Aborted { code, text, by } if t.data.is_empty() && *text == abort_text(*code) => {
            data[..4].copy_from_slice(&code.to_le_bytes());
            (2, *by)
        }
        Outcome::Aborted { .. } | Outcome::ProtocolError(_) => return None,
    };
    let protocol = PROTOCOLS.iter().position(|p| *p == t.protocol).unwrap_or(3) as u16;
    let mut bits = protocol << PROTOCOL_SHIFT | outcome << OUTCOME_SHIFT;
    if t.size.is_some() {
        bits |= HAS_SIZE;
    }
    if t.mode.is_some() {
        bits |= HAS_MODE;
    }
    if t.direction == TransferDirection::Download {
        bits |= DOWNLOAD;
    }
    if by == Side::Server {
        bits |= BY_SERVER;
    }
    Some(Packed {
        start_ns: t.start_ns,
        first_frame: first,
        later_frames,
        end_after_ns,
        size: t.size.unwrap_or(0),
        data,
        index: t.index,
        iface: t.iface,
        node: t.node,
        sub: t.sub,
        mode: t.mode.unwrap_or(0),
        bits,
        counts: t.data.len() as u8 | (t.frames.len() as u8) << 4,
    })
}

/// How a packed transfer ended.
fn outcome_of(p: &Packed) -> Outcome {
    match p.bits >> OUTCOME_SHIFT & 3 {
        0 => Outcome::Ok,
        1 => Outcome::Incomplete,
        _ => {
            let code = u32::from_le_bytes([p.data[0], p.data[1], p.data[2], p.data[3]]);
            let by = if p.bits & BY_SERVER != 0 {
                Side::Server
            } else {
                Side::Client
            };
            Outcome::Aborted {
                code,
                text: abort_text(code),
                by,
            }
        }
    }
}

/// The transfer a packed record holds.
fn unpack(p: &Packed) -> Transaction {
    let outcome = outcome_of(p);
    let data_len = usize::from(p.counts & 15);
    let frame_count = usize::from(p.counts >> 4);
    let mut frames = Vec::with_capacity(frame_count);
    if frame_count > 0 {
        frames.push(p.first_frame);
        frames.extend(
            p.later_frames[..frame_count - 1]
                .iter()
                .map(|&d| p.first_frame + u64::from(d)),
        );
    }
    let data = match outcome {
        Outcome::Aborted { .. } => Vec::new(),
        _ => p.data[..data_len].to_vec(),
    };
    let key = crate::frame::NodeKey::new(p.iface, p.node);
    Transaction {
        iface: p.iface,
        node: p.node,
        channel: Channel::default_on(key),
        index: p.index,
        sub: p.sub,
        direction: if p.bits & DOWNLOAD != 0 {
            TransferDirection::Download
        } else {
            TransferDirection::Upload
        },
        protocol: PROTOCOLS[usize::from(p.bits >> PROTOCOL_SHIFT & 3)],
        data,
        dropped: 0,
        size: (p.bits & HAS_SIZE != 0).then_some(p.size),
        start_ns: p.start_ns,
        end_ns: p.start_ns + u64::from(p.end_after_ns),
        outcome,
        problems: Vec::new(),
        frames,
        frames_dropped: 0,
        mode: (p.bits & HAS_MODE != 0).then_some(p.mode),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sdo::Problem;

    fn expedited(node: u8, frames: Vec<u64>) -> Transaction {
        Transaction {
            iface: 1,
            node,
            channel: Channel::default_on(crate::frame::NodeKey::new(1, node)),
            index: 0x6041,
            sub: 0,
            direction: TransferDirection::Upload,
            protocol: Protocol::Expedited,
            data: vec![0x37, 0x02],
            dropped: 0,
            size: Some(2),
            start_ns: 1_700_000_000_000_000_000,
            end_ns: 1_700_000_000_000_400_000,
            outcome: Outcome::Ok,
            problems: Vec::new(),
            frames,
            frames_dropped: 0,
            mode: Some(-1),
        }
    }

    /// Every shape, packed or whole, comes back as it was pushed, in order.
    #[test]
    fn gives_back_every_transfer_as_pushed() {
        let mut shapes = vec![expedited(5, vec![10, 12]), expedited(6, vec![])];
        let mut t = expedited(7, vec![20, 21, 30, 31]);
        t.protocol = Protocol::Segmented;
        t.direction = TransferDirection::Download;
        t.data = vec![1, 2, 3, 4, 5, 6, 7, 8];
        t.size = None;
        t.mode = None;
        shapes.push(t);
        let mut t = expedited(8, vec![40, 41]);
        t.data.clear();
        t.outcome = Outcome::Aborted {
            code: 0x0602_0000,
            text: abort_text(0x0602_0000),
            by: Side::Server,
        };
        shapes.push(t);
        let mut t = expedited(9, vec![50]);
        t.outcome = Outcome::Incomplete;
        t.protocol = Protocol::Block;
        shapes.push(t);
        // Whole: too many frames, frames far apart, long, more data, a problem, another
        // channel, aborted with data, a protocol error, a long wait.
        shapes.push(expedited(10, vec![1, 2, 3, 4, 5]));
        shapes.push(expedited(11, vec![1, 1 << 40]));
        let mut t = expedited(12, vec![1, 2]);
        t.data = (0..=200).collect();
        shapes.push(t);
        let mut t = expedited(13, vec![1, 2]);
        t.problems.push(Problem::ToggleError);
        shapes.push(t);
        let mut t = expedited(14, vec![1, 2]);
        t.channel.request_cob = 0x640;
        shapes.push(t);
        let mut t = expedited(15, vec![1, 2]);
        t.outcome = Outcome::Aborted {
            code: 0x0800_0000,
            text: abort_text(0x0800_0000),
            by: Side::Client,
        };
        shapes.push(t);
        let mut t = expedited(16, vec![1, 2]);
        t.outcome = Outcome::ProtocolError("toggle".into());
        shapes.push(t);
        let mut t = expedited(17, vec![1, 2]);
        t.end_ns = t.start_ns + 5_000_000_000;
        shapes.push(t);

        let mut list = TransferList::default();
        for t in &shapes {
            list.push(t.clone());
        }
        assert_eq!(list.len(), shapes.len());
        for (i, t) in shapes.iter().enumerate() {
            assert_eq!(list.get(i).as_ref(), Some(t), "transfer {i}");
            assert_eq!(list.outcome(i).as_ref(), Some(&t.outcome), "outcome {i}");
        }
        assert_eq!(list.iter_from(3).count(), shapes.len() - 3);
        assert_eq!(list.whole.len(), 8, "the uncommon shapes are kept whole");
        assert!(list.get(shapes.len()).is_none());
    }

    #[test]
    fn a_packed_transfer_takes_56_bytes() {
        assert_eq!(size_of::<Packed>(), 56);
    }
}
