//! Passive SDO transfer tracking: frames in, reassembled [`Transaction`]s out.
//!
//! One state per channel (node + COB-ID pair), so transfers on different
//! nodes may interleave freely. The tracker copes with a capture that starts
//! mid-transfer (frames outside any transfer are labelled, not counted),
//! checks toggle bits, block sequence numbers and block CRCs, and never
//! lets an unrecognised command byte disturb a running transfer.

use super::crc::crc16;
use super::frame::{Chunk, SdoCommand, SdoFrame, Side};
use super::transaction::{Channel, Outcome, Problem, Protocol, Transaction, TransferDirection};
use super::value::view;
use crate::od::Dictionary;
use std::collections::BTreeMap;

/// Where a transfer stands: what the next frame should be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    InitDownload,
    DownloadSegment { toggle: bool },
    DownloadSegmentResponse { toggle: bool, last: bool },
    InitUpload,
    UploadSegment { toggle: bool },
    UploadSegmentResponse { toggle: bool },
    BlockDownloadInit,
    BlockDownloadSegments { next: u8, blksize: u8 },
    BlockDownloadAck,
    BlockDownloadEnd,
    BlockDownloadEndResponse,
    BlockUploadInit { blksize: u8 },
    BlockUploadStart { blksize: u8 },
    BlockUploadSegments { next: u8, blksize: u8 },
    BlockUploadAck,
    BlockUploadEnd,
    BlockUploadEndResponse,
}

impl Phase {
    /// The side whose frames are block segments in this phase.
    fn segment_sender(self) -> Option<Side> {
        match self {
            Phase::BlockDownloadSegments { .. } => Some(Side::Client),
            Phase::BlockUploadSegments { .. } => Some(Side::Server),
            _ => None,
        }
    }
}

/// A transfer in progress.
#[derive(Clone, Debug)]
struct Pending {
    txn: Transaction,
    phase: Phase,
    /// Both sides agreed on a block CRC.
    crc: bool,
    /// Segments of the current sub-block not yet acknowledged.
    sub_block: Vec<(u8, bool, Chunk)>,
    /// The segment with the c bit was acknowledged.
    last_committed: bool,
}

/// Per-channel state.
#[derive(Clone, Debug, Default)]
struct ChannelState {
    pending: Option<Pending>,
    /// The client sent a command byte we do not know (e.g. a vendor command)
    /// and its reply has not been seen yet.
    unknown_request: bool,
}

/// What happened to one frame, as the tracker's result for it.
enum Step {
    /// The frame belongs to the pending transfer, which goes on.
    Continue,
    /// The frame completes the pending transfer with this outcome.
    Complete(Outcome),
    /// The frame does not fit the pending transfer.
    Unexpected,
}

/// Tracks SDO transfers on every channel and collects completed transactions.
#[derive(Clone, Debug, Default)]
pub struct SdoTracker {
    channels: BTreeMap<Channel, ChannelState>,
    completed: Vec<Transaction>,
}

impl SdoTracker {
    /// An empty tracker.
    pub fn new() -> SdoTracker {
        SdoTracker::default()
    }

    /// Feeds one frame on the node's default channel (0x600 + node / 0x580 + node).
    pub fn on_frame(
        &mut self,
        seq: u64,
        ts_ns: u64,
        node: u8,
        client_to_server: bool,
        payload: &[u8],
        dict: &Dictionary,
    ) -> SdoFrame {
        let side = if client_to_server { Side::Client } else { Side::Server };
        self.on_channel_frame(seq, ts_ns, Channel::default_for(node), side, payload, dict)
    }

    /// Feeds one frame of `channel` sent by `side`; returns its decoded meaning.
    pub fn on_channel_frame(
        &mut self,
        seq: u64,
        ts_ns: u64,
        channel: Channel,
        side: Side,
        payload: &[u8],
        dict: &Dictionary,
    ) -> SdoFrame {
        let state = self.channels.entry(channel).or_default();
        let in_block = state.pending.as_ref().and_then(|p| p.phase.segment_sender()) == Some(side);
        let mut frame = SdoFrame::new(side, payload, in_block);
        let dlc_problem = (payload.len() != 8).then_some(Problem::WrongDlc {
            dlc: payload.len().min(255) as u8,
        });

        if let SdoCommand::Unknown { .. } = frame.command {
            // Shown as malformed, never allowed to disturb a running transfer.
            // A client's unknown command awaits a reply; a server's unknown command is that reply.
            state.unknown_request = side == Side::Client;
            return frame;
        }
        let ctx = FrameCtx {
            seq,
            ts_ns,
            side,
            command: frame.command,
            dlc_problem,
        };
        if side == Side::Client {
            state.unknown_request = false;
        }
        let mut notes = Vec::new();
        if let Some(mut p) = state.pending.take() {
            match step(&mut p, &ctx, &mut notes) {
                Step::Continue => {
                    attach(&mut p.txn, &ctx);
                    frame.object = frame.object.or(Some((p.txn.index, p.txn.sub)));
                    state.pending = Some(p);
                }
                Step::Complete(outcome) => {
                    attach(&mut p.txn, &ctx);
                    frame.object = frame.object.or(Some((p.txn.index, p.txn.sub)));
                    self.completed.push(finalize(p, outcome, dict));
                }
                Step::Unexpected => {
                    let outcome = if p.phase == (Phase::DownloadSegment { toggle: false })
                        && p.txn.protocol == Protocol::Unknown
                    {
                        // Only an initiate download response was seen: it was expedited.
                        Outcome::Incomplete
                    } else if frame.command.object().is_some() && side == Side::Client {
                        Outcome::ProtocolError("interrupted by a new request".to_string())
                    } else {
                        let what = frame.command.cs_name();
                        Outcome::ProtocolError(format!("unexpected {what} frame from the {}", side.as_str()))
                    };
                    self.completed.push(finalize(p, outcome, dict));
                    let state = self.channels.entry(channel).or_default();
                    start(state, channel, &ctx, &mut notes, &mut self.completed, dict);
                }
            }
        } else {
            start(state, channel, &ctx, &mut notes, &mut self.completed, dict);
        }
        let state = self.channels.entry(channel).or_default();
        if frame.object.is_none() {
            frame.object = state.pending.as_ref().map(|p| (p.txn.index, p.txn.sub));
        }
        if let Some((index, sub)) = frame.object {
            frame.name = dict.label_name(index, sub);
            if let Some(data) = match frame.command {
                SdoCommand::InitiateDownload { expedited: true, .. }
                | SdoCommand::InitiateUploadResponse { expedited: true, .. } => frame.command.data(),
                _ => None,
            } {
                frame.value = Some(view(dict, index, sub, data));
            }
        }
        frame.problems = notes;
        frame
    }

    /// Transactions completed since the last call, oldest first.
    pub fn take_completed(&mut self) -> Vec<Transaction> {
        std::mem::take(&mut self.completed)
    }

    /// Ends the input: every transfer still running becomes [`Outcome::Incomplete`];
    /// returns them after any completed ones not yet taken.
    pub fn finish(&mut self) -> Vec<Transaction> {
        let mut out = self.take_completed();
        for (_, state) in std::mem::take(&mut self.channels) {
            if let Some(p) = state.pending {
                let mut t = p.txn;
                t.outcome = Outcome::Incomplete;
                out.push(t);
            }
        }
        out
    }
}

/// The facts about one frame the state machine needs.
struct FrameCtx {
    seq: u64,
    ts_ns: u64,
    side: Side,
    command: SdoCommand,
    dlc_problem: Option<Problem>,
}

/// Records that a frame belongs to a transaction.
fn attach(t: &mut Transaction, ctx: &FrameCtx) {
    t.frames.push(ctx.seq);
    t.end_ns = ctx.ts_ns;
    if let Some(p) = ctx.dlc_problem {
        t.flag(p);
    }
}

/// Final checks of a transfer that ended.
fn finalize(p: Pending, outcome: Outcome, dict: &Dictionary) -> Transaction {
    let mut t = p.txn;
    if outcome == Outcome::Ok {
        let fixed = dict.object(t.index, t.sub).and_then(|o| o.data_type.size());
        if t.protocol == Protocol::Expedited && t.size.is_none() {
            // e=1, s=0: four bytes, of which the object's type says how many count.
            if let Some(n) = fixed.filter(|n| *n < t.data.len()) {
                t.data.truncate(n);
            }
        }
        if let Some(indicated) = t.size.filter(|s| *s as usize != t.data.len()) {
            t.flag(Problem::SizeMismatch {
                indicated,
                actual: t.data.len(),
            });
        }
        if let Some(expected) = fixed.filter(|n| *n != t.data.len()) {
            t.flag(Problem::TypeLengthMismatch {
                expected,
                actual: t.data.len(),
            });
        }
    }
    t.outcome = outcome;
    t
}

/// A new transaction from its first frame.
fn new_txn(
    channel: Channel,
    ctx: &FrameCtx,
    index: u16,
    sub: u8,
    dir: TransferDirection,
    proto: Protocol,
) -> Transaction {
    Transaction {
        node: channel.node,
        channel,
        index,
        sub,
        direction: dir,
        protocol: proto,
        data: Vec::new(),
        size: None,
        start_ns: ctx.ts_ns,
        end_ns: ctx.ts_ns,
        outcome: Outcome::Incomplete,
        problems: Vec::new(),
        frames: Vec::new(),
        mode: None,
    }
}

/// Handles a frame on a channel with no transfer running.
fn start(
    state: &mut ChannelState,
    channel: Channel,
    ctx: &FrameCtx,
    notes: &mut Vec<String>,
    completed: &mut Vec<Transaction>,
    dict: &Dictionary,
) {
    use SdoCommand::*;
    use TransferDirection::*;
    let pending = |txn: Transaction, phase: Phase, crc: bool| Pending {
        txn,
        phase,
        crc,
        sub_block: Vec::new(),
        last_committed: false,
    };
    let mut begin = |mut p: Pending, unmatched: bool| {
        if unmatched {
            p.txn.flag(Problem::UnmatchedResponse);
            notes.push(Problem::UnmatchedResponse.to_string());
        }
        attach(&mut p.txn, ctx);
        state.pending = Some(p);
    };
    match (ctx.side, ctx.command) {
        (
            Side::Client,
            InitiateDownload {
                index,
                sub,
                expedited,
                size,
                data,
            },
        ) => {
            let proto = if expedited {
                Protocol::Expedited
            } else {
                Protocol::Segmented
            };
            let mut t = new_txn(channel, ctx, index, sub, Download, proto);
            t.size = size;
            t.data.extend_from_slice(data.bytes());
            begin(pending(t, Phase::InitDownload, false), false);
        }
        (Side::Client, InitiateUpload { index, sub }) => {
            let t = new_txn(channel, ctx, index, sub, Upload, Protocol::Unknown);
            begin(pending(t, Phase::InitUpload, false), false);
        }
        (Side::Client, BlockDownloadInitiate { index, sub, crc, size }) => {
            let mut t = new_txn(channel, ctx, index, sub, Download, Protocol::Block);
            t.size = size;
            begin(pending(t, Phase::BlockDownloadInit, crc), false);
        }
        (
            Side::Client,
            BlockUploadInitiate {
                index,
                sub,
                crc,
                blksize,
                ..
            },
        ) => {
            let t = new_txn(channel, ctx, index, sub, Upload, Protocol::Block);
            begin(pending(t, Phase::BlockUploadInit { blksize }, crc), false);
        }
        (Side::Server, cmd) if state.unknown_request && cmd.object().is_some() => {
            // The reply to a command byte we did not recognise: not ours to judge.
            state.unknown_request = false;
            notes.push("reply to an unrecognised request".to_string());
        }
        (
            Side::Server,
            InitiateUploadResponse {
                index,
                sub,
                expedited: true,
                size,
                data,
            },
        ) => {
            let mut t = new_txn(channel, ctx, index, sub, Upload, Protocol::Expedited);
            t.size = size;
            t.data.extend_from_slice(data.bytes());
            t.flag(Problem::UnmatchedResponse);
            notes.push(Problem::UnmatchedResponse.to_string());
            attach(&mut t, ctx);
            completed.push(finalize(pending(t, Phase::InitUpload, false), Outcome::Ok, dict));
        }
        (Side::Server, InitiateUploadResponse { index, sub, size, .. }) => {
            let mut t = new_txn(channel, ctx, index, sub, Upload, Protocol::Segmented);
            t.size = size;
            begin(pending(t, Phase::UploadSegment { toggle: false }, false), true);
        }
        (Side::Server, BlockUploadInitiateResponse { index, sub, crc, size }) => {
            let mut t = new_txn(channel, ctx, index, sub, Upload, Protocol::Block);
            t.size = size;
            begin(pending(t, Phase::BlockUploadStart { blksize: 127 }, crc), true);
        }
        (
            Side::Server,
            BlockDownloadInitiateResponse {
                index,
                sub,
                crc,
                blksize,
            },
        ) => {
            let t = new_txn(channel, ctx, index, sub, Download, Protocol::Block);
            begin(pending(t, Phase::BlockDownloadSegments { next: 1, blksize }, crc), true);
        }
        (Side::Server, InitiateDownloadResponse { index, sub }) => {
            // Expedited or the start of a segmented download: only the next frame tells.
            let t = new_txn(channel, ctx, index, sub, Download, Protocol::Unknown);
            begin(pending(t, Phase::DownloadSegment { toggle: false }, false), true);
        }
        (side, Abort { .. }) => {
            if side == Side::Server {
                state.unknown_request = false;
            }
            notes.push("abort outside any transfer seen".to_string());
        }
        _ => notes.push("outside any transfer seen".to_string()),
    }
}

/// Advances a pending transfer by one frame.
fn step(p: &mut Pending, ctx: &FrameCtx, notes: &mut Vec<String>) -> Step {
    use SdoCommand::*;
    let mut flag = |t: &mut Transaction, pr: Problem| {
        notes.push(pr.to_string());
        t.flag(pr);
    };
    let t = &mut p.txn;
    if let Abort { code, .. } = ctx.command {
        return Step::Complete(Outcome::Aborted {
            code,
            text: super::abort::abort_text(code),
            by: ctx.side,
        });
    }
    match (p.phase, ctx.side, ctx.command) {
        (_, Side::Client, InitiateDownload { .. } | InitiateUpload { .. })
        | (_, Side::Client, BlockDownloadInitiate { .. } | BlockUploadInitiate { .. }) => Step::Unexpected,
        (Phase::InitDownload, Side::Server, InitiateDownloadResponse { index, sub }) => {
            if (index, sub) != (t.index, t.sub) {
                flag(t, Problem::UnmatchedResponse);
            }
            if t.protocol == Protocol::Expedited {
                Step::Complete(Outcome::Ok)
            } else {
                p.phase = Phase::DownloadSegment { toggle: false };
                Step::Continue
            }
        }
        (Phase::DownloadSegment { toggle: want }, Side::Client, DownloadSegment { toggle, last, data }) => {
            if toggle != want {
                flag(t, Problem::ToggleError);
            }
            if t.protocol == Protocol::Unknown {
                // Picked up at an unmatched initiate response: it was segmented after all.
                t.protocol = Protocol::Segmented;
            }
            t.data.extend_from_slice(data.bytes());
            p.phase = Phase::DownloadSegmentResponse { toggle, last };
            Step::Continue
        }
        (Phase::DownloadSegmentResponse { toggle: want, last }, Side::Server, DownloadSegmentResponse { toggle }) => {
            if toggle != want {
                flag(t, Problem::ToggleError);
            }
            if last {
                Step::Complete(Outcome::Ok)
            } else {
                p.phase = Phase::DownloadSegment { toggle: !want };
                Step::Continue
            }
        }
        (
            Phase::InitUpload | Phase::BlockUploadInit { .. },
            Side::Server,
            InitiateUploadResponse {
                index,
                sub,
                expedited,
                size,
                data,
            },
        ) => {
            if (index, sub) != (t.index, t.sub) {
                flag(t, Problem::UnmatchedResponse);
            }
            t.size = size;
            if expedited {
                t.protocol = Protocol::Expedited;
                t.data.extend_from_slice(data.bytes());
                Step::Complete(Outcome::Ok)
            } else {
                t.protocol = Protocol::Segmented;
                p.phase = Phase::UploadSegment { toggle: false };
                Step::Continue
            }
        }
        (Phase::UploadSegment { toggle: want }, Side::Client, UploadSegment { toggle }) => {
            if toggle != want {
                flag(t, Problem::ToggleError);
            }
            p.phase = Phase::UploadSegmentResponse { toggle };
            Step::Continue
        }
        (Phase::UploadSegmentResponse { toggle: want }, Side::Server, UploadSegmentResponse { toggle, last, data }) => {
            if toggle != want {
                flag(t, Problem::ToggleError);
            }
            t.data.extend_from_slice(data.bytes());
            if last {
                Step::Complete(Outcome::Ok)
            } else {
                p.phase = Phase::UploadSegment { toggle: !want };
                Step::Continue
            }
        }
        (
            Phase::BlockDownloadInit,
            Side::Server,
            BlockDownloadInitiateResponse {
                index,
                sub,
                crc,
                blksize,
            },
        ) => {
            if (index, sub) != (t.index, t.sub) {
                flag(t, Problem::UnmatchedResponse);
            }
            p.crc &= crc;
            p.phase = Phase::BlockDownloadSegments { next: 1, blksize };
            Step::Continue
        }
        (Phase::BlockDownloadSegments { next, blksize }, Side::Client, BlockSegment { seqno, last, data })
        | (Phase::BlockUploadSegments { next, blksize }, Side::Server, BlockSegment { seqno, last, data }) => {
            let upload = matches!(p.phase, Phase::BlockUploadSegments { .. });
            let mut next = next;
            if seqno == next {
                p.sub_block.push((seqno, last, data));
                next = next.wrapping_add(1);
            } else {
                flag(t, Problem::SequenceError);
            }
            p.phase = match (last || seqno >= blksize, upload) {
                (true, false) => Phase::BlockDownloadAck,
                (true, true) => Phase::BlockUploadAck,
                (false, false) => Phase::BlockDownloadSegments { next, blksize },
                (false, true) => Phase::BlockUploadSegments { next, blksize },
            };
            Step::Continue
        }
        (
            Phase::BlockDownloadSegments { .. } | Phase::BlockDownloadAck,
            Side::Server,
            BlockDownloadAck { ackseq, blksize },
        )
        | (
            Phase::BlockUploadSegments { .. } | Phase::BlockUploadAck,
            Side::Client,
            BlockUploadAck { ackseq, blksize },
        ) => {
            let upload = matches!(ctx.command, BlockUploadAck { .. });
            let received = p.sub_block.len();
            for (_, last, data) in p.sub_block.drain(..).filter(|(s, _, _)| *s <= ackseq) {
                t.data.extend_from_slice(data.bytes());
                p.last_committed |= last;
            }
            if (ackseq as usize) < received {
                flag(t, Problem::SequenceError);
            }
            p.phase = match (p.last_committed, upload) {
                (true, false) => Phase::BlockDownloadEnd,
                (true, true) => Phase::BlockUploadEnd,
                (false, false) => Phase::BlockDownloadSegments { next: 1, blksize },
                (false, true) => Phase::BlockUploadSegments { next: 1, blksize },
            };
            Step::Continue
        }
        (Phase::BlockDownloadEnd, Side::Client, BlockDownloadEnd { unused, crc })
        | (Phase::BlockUploadEnd, Side::Server, BlockUploadEnd { unused, crc }) => {
            let keep = t.data.len().saturating_sub(unused as usize);
            t.data.truncate(keep);
            if p.crc {
                let computed = crc16(&t.data);
                if computed != crc {
                    flag(t, Problem::BadCrc { sent: crc, computed });
                }
            }
            p.phase = if matches!(p.phase, Phase::BlockUploadEnd) {
                Phase::BlockUploadEndResponse
            } else {
                Phase::BlockDownloadEndResponse
            };
            Step::Continue
        }
        (Phase::BlockDownloadEndResponse, Side::Server, BlockDownloadEndResponse)
        | (Phase::BlockUploadEndResponse, Side::Client, BlockUploadEndResponse) => Step::Complete(Outcome::Ok),
        (Phase::BlockUploadInit { blksize }, Side::Server, BlockUploadInitiateResponse { index, sub, crc, size }) => {
            if (index, sub) != (t.index, t.sub) {
                flag(t, Problem::UnmatchedResponse);
            }
            p.crc &= crc;
            t.size = size;
            p.phase = Phase::BlockUploadStart { blksize };
            Step::Continue
        }
        (Phase::BlockUploadStart { blksize }, Side::Client, BlockUploadStart) => {
            p.phase = Phase::BlockUploadSegments { next: 1, blksize };
            Step::Continue
        }
        _ => Step::Unexpected,
    }
}
