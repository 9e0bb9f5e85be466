//! Passive SDO transfer tracking: frames in, reassembled [`Transaction`]s out.
//!
//! One state per channel (node + COB-ID pair), so transfers on different
//! nodes may interleave freely. The tracker copes with a capture that starts
//! mid-transfer (frames outside any transfer are labelled, not counted; a block
//! transfer caught mid-way is recognised by its pattern, see [`super::resync`], and
//! becomes one partial transaction), checks toggle bits, block sequence numbers and
//! block CRCs, and never lets an unrecognised command byte disturb a running transfer.
//! What it keeps per transfer is capped ([`super::transaction::DATA_KEPT`]), so a
//! transfer that never ends does not grow memory.

use super::crc::crc16_update;
use super::frame::{Chunk, SdoCommand, SdoFrame, Side};
use super::resync::{Orphan, end_command, impossible_command};
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
    BlockDownloadAck { blksize: u8 },
    BlockDownloadEnd,
    BlockDownloadEndResponse,
    BlockUploadInit { blksize: u8 },
    BlockUploadStart { blksize: u8 },
    BlockUploadSegments { next: u8, blksize: u8 },
    BlockUploadAck { blksize: u8 },
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

    /// The side that sent the sub-block whose acknowledgement this phase awaits.
    fn acked_sender(self) -> Option<Side> {
        match self {
            Phase::BlockDownloadAck { .. } => Some(Side::Client),
            Phase::BlockUploadAck { .. } => Some(Side::Server),
            _ => None,
        }
    }
}

/// Segments of one sub-block kept until acknowledged (a sub-block has at most 127).
const SUB_BLOCK_KEPT: usize = 128;

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
    /// Block CRC of the acknowledged bytes before `held`.
    crc_acc: u16,
    /// The last acknowledged segment, whose unused tail only the end frame tells.
    held: Chunk,
    /// Picked up mid-way: no CRC check, and the first sub-block began before the capture.
    partial: bool,
    /// A partial transfer seen in one frame only (an impossible command byte): dropped
    /// without a trace if the next frame does not continue it.
    tentative: bool,
    /// The frame that began it, while it is the only one: if the same side's next frame
    /// counts on from its first byte, both were block segments, not an initiate.
    opener: Option<Orphan>,
}

impl Pending {
    fn new(txn: Transaction, phase: Phase, crc: bool) -> Pending {
        Pending {
            txn,
            phase,
            crc,
            sub_block: Vec::new(),
            last_committed: false,
            crc_acc: 0,
            held: Chunk::default(),
            partial: false,
            tentative: false,
            opener: None,
        }
    }

    /// The object of the transfer, when its initiate was seen.
    fn object(&self) -> Option<(u16, u8)> {
        (!self.partial).then_some((self.txn.index, self.txn.sub))
    }

    /// Adds an acknowledged block segment to the data and the running CRC.
    fn commit(&mut self, last: bool, data: Chunk) {
        self.crc_acc = crc16_update(self.crc_acc, self.held.bytes());
        self.held = data;
        self.txn.append(data.bytes());
        self.last_committed |= last;
    }
}

/// Per-channel state.
#[derive(Clone, Debug, Default)]
struct ChannelState {
    pending: Option<Pending>,
    /// The client sent a command byte we do not know (e.g. a vendor command)
    /// and its reply has not been seen yet.
    unknown_request: bool,
    /// The previous frame fitted no transfer (it may begin a run of block segments).
    orphan: Option<Orphan>,
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
        // An "initiate" followed by the next sequence number, or answered by an
        // acknowledgement of its sequence number, was a block segment.
        let opener = state
            .pending
            .as_ref()
            .filter(|p| p.txn.frames.len() == 1)
            .and_then(|p| p.opener);
        let run = opener.filter(|o| o.continued_by(side, payload));
        let acked = opener.filter(|o| {
            o.side == side.other() && payload.len() == 8 && payload[0] == 0xA2 && o.seqno() == Some(payload[1])
        });
        let in_block = run.is_some() || (acked.is_none() && block_segment_expected(state, side, payload));
        let opener = run.or(acked);
        let orphan = state.orphan.take().or(opener);
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
            orphan,
            this: Orphan::of(side, payload, seq, ts_ns),
        };
        if side == Side::Client {
            state.unknown_request = false;
        }
        let mut notes = Vec::new();
        if let Some(mut p) = state.pending.take() {
            match step(&mut p, &ctx, &mut notes) {
                Step::Continue => {
                    if std::mem::take(&mut p.tentative) {
                        let dir = p.txn.direction.as_str();
                        notes.push(format!("resynchronised: block {dir} started before the capture"));
                    }
                    attach(&mut p.txn, &ctx);
                    frame.object = frame.object.or(p.object());
                    state.pending = Some(p);
                }
                Step::Complete(outcome) => {
                    attach(&mut p.txn, &ctx);
                    frame.object = frame.object.or(p.object());
                    self.completed.push(finalize(p, outcome, dict));
                }
                Step::Unexpected if p.tentative || opener.is_some() => {
                    // One impossible byte was not the start of a run after all, or one
                    // seemingly valid command was its start: either way no transaction.
                    start(state, channel, &ctx, &mut notes, &mut self.completed, dict);
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
            frame.object = state.pending.as_ref().and_then(Pending::object);
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
            if let Some(p) = state.pending.filter(|p| !p.tentative) {
                let mut t = p.txn;
                t.outcome = Outcome::Incomplete;
                out.push(t);
            }
        }
        out
    }
}

/// Whether the frame `side` sends next is a block segment (`c | seqno` first), from
/// the transfer running on the channel or, with none, from the frame's pattern.
fn block_segment_expected(state: &ChannelState, side: Side, payload: &[u8]) -> bool {
    let seqno_one = payload.len() == 8 && payload[0] & 0x7F == 1;
    match state.pending.as_ref() {
        Some(p) if p.tentative => {
            // A guess from one byte holds only if the run goes on.
            matches!(p.phase, Phase::BlockDownloadSegments { next, .. } | Phase::BlockUploadSegments { next, .. }
                if p.phase.segment_sender() == Some(side) && payload.first().map(|b| b & 0x7F) == Some(next))
        }
        // A sub-block starts at seqno 1; an end command there means the last segment
        // (or its acknowledgement) was not captured.
        Some(p) if p.phase.segment_sender() == Some(side) => {
            let fresh = matches!(
                p.phase,
                Phase::BlockDownloadSegments { next: 1, .. } | Phase::BlockUploadSegments { next: 1, .. }
            );
            !(fresh && !seqno_one && payload.first().is_some_and(|b| end_command(*b)))
        }
        // The next sub-block began although its acknowledgement was not captured.
        Some(p) if p.phase.acked_sender() == Some(side) => seqno_one,
        // A transfer awaits an answer: a strange byte is a bad answer, not a segment.
        Some(_) => false,
        None => impossible_command(side, payload) || state.orphan.is_some_and(|o| o.continued_by(side, payload)),
    }
}

/// The facts about one frame the state machine needs.
struct FrameCtx {
    seq: u64,
    ts_ns: u64,
    side: Side,
    command: SdoCommand,
    dlc_problem: Option<Problem>,
    /// The channel's previous frame, when it fitted no transfer.
    orphan: Option<Orphan>,
    /// This frame, to keep as the channel's orphan if it fits no transfer.
    this: Option<Orphan>,
}

/// Records that a frame belongs to a transaction.
fn attach(t: &mut Transaction, ctx: &FrameCtx) {
    t.add_frame(ctx.seq);
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
        if let Some(indicated) = t.size.filter(|s| *s as usize != t.len()) {
            t.flag(Problem::SizeMismatch {
                indicated,
                actual: t.len(),
            });
        }
        if let Some(expected) = fixed.filter(|n| *n != t.len() && !p.partial) {
            t.flag(Problem::TypeLengthMismatch {
                expected,
                actual: t.len(),
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
        frames_dropped: 0,
        dropped: 0,
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
    let pending = Pending::new;
    let mut begin = |mut p: Pending, unmatched: bool| {
        if unmatched {
            p.txn.flag(Problem::UnmatchedResponse);
            notes.push(Problem::UnmatchedResponse.to_string());
        }
        attach(&mut p.txn, ctx);
        p.opener = ctx.this;
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
            t.append(data.bytes());
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
            t.append(data.bytes());
            t.flag(Problem::UnmatchedResponse);
            notes.push(Problem::UnmatchedResponse.to_string());
            attach(&mut t, ctx);
            completed.push(finalize(pending(t, Phase::InitUpload, false), Outcome::Ok, dict));
            // It may also have been a block segment, which the next frame would tell.
            state.orphan = ctx.this.map(|o| Orphan { listed: true, ..o });
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
        (side, BlockSegment { seqno, .. }) => {
            // A sub-block whose transfer began before the capture: a run or an impossible byte.
            let run = ctx
                .orphan
                .filter(|o| o.continued_by(side, &[seqno, 0, 0, 0, 0, 0, 0, 0]));
            let mut p = partial(channel, ctx, side, run);
            p.phase = match side {
                Side::Client => Phase::BlockDownloadSegments {
                    next: seqno,
                    blksize: 127,
                },
                Side::Server => Phase::BlockUploadSegments {
                    next: seqno,
                    blksize: 127,
                },
            };
            p.tentative = run.is_none();
            if let Some((o, s)) = run.filter(|o| !o.listed).and_then(|o| Some((o, o.seqno()?))) {
                p.sub_block.push((s, false, o.data));
            }
            resume(p, ctx, notes, state);
        }
        (Side::Server, BlockDownloadAck { ackseq, blksize }) | (Side::Client, BlockUploadAck { ackseq, blksize }) => {
            // An acknowledgement answers the sub-block its sender's peer just sent.
            let sender = ctx.side.other();
            let answered = ctx.orphan.filter(|o| o.side == sender && o.seqno() == Some(ackseq));
            let mut p = partial(channel, ctx, sender, answered);
            p.phase = match sender {
                Side::Client => Phase::BlockDownloadAck { blksize },
                Side::Server => Phase::BlockUploadAck { blksize },
            };
            if let Some((o, s)) = answered.filter(|o| !o.listed).and_then(|o| Some((o, o.seqno()?))) {
                p.sub_block.push((s, o.last(), o.data));
            }
            // Confirmed by what follows: a segment, or the end of the transfer.
            p.tentative = true;
            resume(p, ctx, notes, state);
        }
        _ => {
            notes.push("outside any transfer seen".to_string());
            state.orphan = ctx.this;
        }
    }
}

/// A block transfer picked up mid-way; `sender` sends its segments, `first` is an earlier
/// frame that turned out to belong to it.
fn partial(channel: Channel, ctx: &FrameCtx, sender: Side, first: Option<Orphan>) -> Pending {
    let dir = match sender {
        Side::Client => TransferDirection::Download,
        Side::Server => TransferDirection::Upload,
    };
    let mut t = new_txn(channel, ctx, 0, 0, dir, Protocol::Block);
    t.flag(Problem::StartedBeforeCapture);
    if let Some(o) = first.filter(|o| !o.listed) {
        t.start_ns = o.ts_ns;
        t.add_frame(o.seq);
    }
    let mut p = Pending::new(t, Phase::BlockDownloadInit, false);
    p.partial = true;
    p
}

/// Runs the frame that revealed a partial transfer through the state machine.
fn resume(mut p: Pending, ctx: &FrameCtx, notes: &mut Vec<String>, state: &mut ChannelState) {
    let dir = p.txn.direction.as_str();
    if !p.tentative {
        notes.push(format!("resynchronised: block {dir} started before the capture"));
    }
    // A segment or acknowledgement is what these phases wait for: the step goes on.
    step(&mut p, ctx, notes);
    attach(&mut p.txn, ctx);
    state.pending = Some(p);
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
        (Phase::BlockDownloadAck { blksize }, Side::Client, BlockSegment { .. })
        | (Phase::BlockUploadAck { blksize }, Side::Server, BlockSegment { .. }) => {
            // A new sub-block began: its acknowledgement was not captured.
            flag(&mut p.txn, Problem::SequenceError);
            for (_, last, data) in std::mem::take(&mut p.sub_block) {
                p.commit(last, data);
            }
            p.phase = match p.phase {
                Phase::BlockDownloadAck { .. } => Phase::BlockDownloadSegments { next: 1, blksize },
                _ => Phase::BlockUploadSegments { next: 1, blksize },
            };
            step(p, ctx, notes)
        }
        (Phase::BlockDownloadSegments { next: 1, .. }, Side::Client, BlockDownloadEnd { .. })
        | (Phase::BlockUploadSegments { next: 1, .. }, Side::Server, BlockUploadEnd { .. }) => {
            // The segment with the c bit, or its acknowledgement, was not captured.
            flag(t, Problem::SequenceError);
            p.phase = match p.phase {
                Phase::BlockDownloadSegments { .. } => Phase::BlockDownloadEnd,
                _ => Phase::BlockUploadEnd,
            };
            step(p, ctx, notes)
        }
        (Phase::BlockDownloadSegments { next, blksize }, Side::Client, BlockSegment { seqno, last, data })
        | (Phase::BlockUploadSegments { next, blksize }, Side::Server, BlockSegment { seqno, last, data }) => {
            let upload = matches!(p.phase, Phase::BlockUploadSegments { .. });
            if seqno != next {
                // Lost, repeated or (in a partial transfer's first sub-block) not captured:
                // the acknowledgement tells which segments count.
                flag(t, Problem::SequenceError);
            }
            if p.sub_block.len() < SUB_BLOCK_KEPT {
                p.sub_block.push((seqno, last, data));
            }
            let next = seqno.wrapping_add(1);
            p.phase = match (last || seqno >= blksize, upload) {
                (true, false) => Phase::BlockDownloadAck { blksize },
                (true, true) => Phase::BlockUploadAck { blksize },
                (false, false) => Phase::BlockDownloadSegments { next, blksize },
                (false, true) => Phase::BlockUploadSegments { next, blksize },
            };
            Step::Continue
        }
        (
            Phase::BlockDownloadSegments { .. } | Phase::BlockDownloadAck { .. },
            Side::Server,
            BlockDownloadAck { ackseq, blksize },
        )
        | (
            Phase::BlockUploadSegments { .. } | Phase::BlockUploadAck { .. },
            Side::Client,
            BlockUploadAck { ackseq, blksize },
        ) => {
            let upload = matches!(ctx.command, BlockUploadAck { .. });
            let segments = std::mem::take(&mut p.sub_block);
            // Every segment up to ackseq should have been seen, from 1 or, in the first
            // sub-block of a partial transfer, from the first one captured.
            let first = match (p.partial && t.is_empty(), segments.first()) {
                (true, Some((s, _, _))) => *s,
                (true, None) => ackseq.saturating_add(1),
                (false, _) => 1,
            };
            let missing = (first..=ackseq).any(|n| !segments.iter().any(|(s, _, _)| *s == n));
            if missing || segments.iter().any(|(s, _, _)| *s > ackseq) {
                flag(&mut p.txn, Problem::SequenceError);
            }
            for (_, last, data) in segments.into_iter().filter(|(s, _, _)| *s <= ackseq) {
                p.commit(last, data);
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
            let held = p.held.bytes();
            let computed = crc16_update(p.crc_acc, &held[..held.len().saturating_sub(unused as usize)]);
            p.txn.cut(unused as usize);
            if p.crc && !p.partial && computed != crc {
                flag(&mut p.txn, Problem::BadCrc { sent: crc, computed });
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
