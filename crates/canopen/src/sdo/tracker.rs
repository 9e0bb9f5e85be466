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
//!
//! How to read it: [`TransferTracker::on_channel_frame`] decides how to read the frame
//! (command or block segment), then either `start`s a transfer on an idle channel or
//! `advance`s the pending one. `step` matches (phase, command) and hands the frame to
//! the step of the transfer type running: `download` and `upload` (expedited and
//! segmented) or `block` (both directions, which mirror each other). Each returns
//! whether the transfer goes on, completes, or did not expect the frame.

use super::abort::abort_text;
use super::codec::{Chunk, SdoCommand, Side, decode, end_command, parse};
use super::crc::crc16_update;
use super::resync::{Orphan, impossible_command};
use super::transaction::{Channel, Outcome, Problem, Protocol, Transaction, TransferDirection};
use crate::frame::NodeKey;
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

/// Per-channel state; an idle one is the same as the default. Idle states stay in the
/// map (a channel's next transfer finds its place) until there are more than
/// [`IDLE_KEPT`] channels, so a capture of many interfaces or channels costs only the
/// transfers running and a few idle channels.
#[derive(Clone, Debug, Default)]
struct ChannelState {
    pending: Option<Pending>,
    /// The client sent a command byte we do not know (e.g. a vendor command)
    /// and its reply has not been seen yet.
    unknown_request: bool,
    /// The previous frame fitted no transfer (it may begin a run of block segments).
    orphan: Option<Orphan>,
}

impl ChannelState {
    /// Nothing running, nothing remembered: the same as no state.
    fn is_idle(&self) -> bool {
        self.pending.is_none() && !self.unknown_request && self.orphan.is_none()
    }
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

/// What the tracker made of one frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tracked {
    /// Who sent it.
    pub side: Side,
    /// Its command, decoded as a block segment when its sender is inside a sub-block.
    pub command: SdoCommand,
    /// The object of the transfer it belongs to: its own, or the running transfer's.
    pub object: Option<(u16, u8)>,
    /// Problems seen in this frame (toggle error, unmatched response...).
    pub problems: Vec<String>,
}

/// Channels kept before idle ones are dropped: a bus's every node's default channel and
/// then some, while memory stays a few hundred kilobytes.
const IDLE_KEPT: usize = 1024;

/// Tracks SDO transfers on every channel and collects completed transactions.
#[derive(Debug, Default)]
pub struct TransferTracker {
    channels: BTreeMap<Channel, ChannelState>,
    /// The number of channels past which idle ones are dropped (0: [`IDLE_KEPT`]).
    sweep_at: usize,
    completed: Vec<Transaction>,
}

/// A clone carries the running channels only (an idle state is the same as none): the
/// TUI keeps a decoder clone every few thousand frames, and idle states would add up.
impl Clone for TransferTracker {
    fn clone(&self) -> TransferTracker {
        let running = self.channels.iter().filter(|(_, state)| !state.is_idle());
        TransferTracker {
            channels: running.map(|(channel, state)| (*channel, state.clone())).collect(),
            sweep_at: 0,
            completed: self.completed.clone(),
        }
    }
}

impl TransferTracker {
    /// An empty tracker.
    pub fn new() -> TransferTracker {
        TransferTracker::default()
    }

    /// Feeds one frame on the node's default channel (0x600 + node / 0x580 + node) of its
    /// interface.
    pub fn on_frame(
        &mut self,
        seq: u64,
        ts_ns: u64,
        node: NodeKey,
        client_to_server: bool,
        payload: &[u8],
        dict: &Dictionary,
    ) -> Tracked {
        let side = if client_to_server { Side::Client } else { Side::Server };
        self.on_channel_frame(seq, ts_ns, Channel::default_on(node), side, payload, dict)
    }

    /// Feeds one frame of `channel` sent by `side`; returns what it means in its transfer.
    pub fn on_channel_frame(
        &mut self,
        seq: u64,
        ts_ns: u64,
        channel: Channel,
        side: Side,
        payload: &[u8],
        dict: &Dictionary,
    ) -> Tracked {
        let state = self.channels.entry(channel).or_default();
        let (command, opener) = classify(state, side, payload);
        let mut tracked = Tracked {
            side,
            command,
            object: command.object(),
            problems: Vec::new(),
        };
        if let SdoCommand::Unknown { .. } = command {
            // Shown as malformed, never allowed to disturb a running transfer.
            // A client's unknown command awaits a reply; a server's unknown command is that reply.
            state.unknown_request = side == Side::Client;
            self.sweep();
            return tracked;
        }
        let ctx = FrameCtx {
            seq,
            ts_ns,
            channel,
            side,
            command,
            dlc_problem: (payload.len() != 8).then_some(Problem::WrongDlc {
                dlc: payload.len().min(255) as u8,
            }),
            orphan: state.orphan.take().or(opener),
            reveals_opener: opener.is_some(),
            this: Orphan::of(side, payload, seq, ts_ns),
        };
        if side == Side::Client {
            state.unknown_request = false;
        }
        let mut out = Out {
            notes: Vec::new(),
            completed: &mut self.completed,
            dict,
        };
        let ended = advance(state, &ctx, &mut out);
        let pending = state.pending.as_ref().and_then(Pending::object);
        tracked.object = tracked.object.or(ended).or(pending);
        tracked.problems = out.notes;
        self.sweep();
        tracked
    }

    /// Drops the idle channels once there are more channels than [`IDLE_KEPT`] (or twice
    /// as many as were running at the last sweep).
    fn sweep(&mut self) {
        if self.channels.len() <= self.sweep_at.max(IDLE_KEPT) {
            return;
        }
        self.channels.retain(|_, state| !state.is_idle());
        self.sweep_at = self.channels.len() * 2;
    }

    /// Transactions completed since the last call, oldest first (the list keeps its room
    /// for the next ones).
    pub fn drain_completed(&mut self) -> std::vec::Drain<'_, Transaction> {
        self.completed.drain(..)
    }

    /// Ends the input: every transfer still running becomes [`Outcome::Incomplete`];
    /// returns them after any completed ones not yet taken.
    pub fn finish(&mut self) -> Vec<Transaction> {
        let mut out = std::mem::take(&mut self.completed);
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

/// How to read a frame on this channel, and the pending transfer's opener when this frame
/// shows that it was a block segment, not an initiate: the same side's next frame counts
/// on from its first byte, or the other side acknowledges its sequence number.
fn classify(state: &ChannelState, side: Side, payload: &[u8]) -> (SdoCommand, Option<Orphan>) {
    let opener = state
        .pending
        .as_ref()
        .filter(|p| p.txn.frames.len() == 1)
        .and_then(|p| p.opener);
    let run = opener.filter(|o| o.continued_by(side, payload));
    let acked =
        opener.filter(|o| o.side == side.other() && acknowledged(side, payload).is_some_and(|a| o.seqno() == Some(a)));
    let in_block = run.is_some() || (acked.is_none() && block_segment_expected(state, side, payload));
    (decode(side, payload, in_block), run.or(acked))
}

/// The sequence number a block acknowledgement (from either side) acknowledges.
fn acknowledged(side: Side, payload: &[u8]) -> Option<u8> {
    match parse(side, payload.try_into().ok()?, false) {
        Ok(SdoCommand::BlockDownloadAck { ackseq, .. } | SdoCommand::BlockUploadAck { ackseq, .. }) => Some(ackseq),
        _ => None,
    }
}

/// Whether the frame `side` sends next is a block segment (`c | seqno` first), from
/// the transfer running on the channel or, with none, from the frame's pattern.
fn block_segment_expected(state: &ChannelState, side: Side, payload: &[u8]) -> bool {
    let seqno = payload.first().map(|b| b & 0x7F);
    let seqno_one = payload.len() == 8 && seqno == Some(1);
    match state.pending.as_ref() {
        Some(p) if p.tentative => {
            // A guess from one byte holds only if the run goes on.
            matches!(p.phase, Phase::BlockDownloadSegments { next, .. } | Phase::BlockUploadSegments { next, .. }
                if p.phase.segment_sender() == Some(side) && seqno == Some(next))
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
    channel: Channel,
    side: Side,
    command: SdoCommand,
    dlc_problem: Option<Problem>,
    /// The channel's previous frame, when it fitted no transfer.
    orphan: Option<Orphan>,
    /// The frame shows that the pending transfer's only frame was a block segment.
    reveals_opener: bool,
    /// This frame, to keep as the channel's orphan if it fits no transfer.
    this: Option<Orphan>,
}

/// Where the state machine puts what it finds.
struct Out<'a> {
    /// Problems seen in the frame, for its label.
    notes: Vec<String>,
    /// Transactions that ended.
    completed: &'a mut Vec<Transaction>,
    /// Types of objects, for the final checks.
    dict: &'a Dictionary,
}

impl Out<'_> {
    /// Notes a problem in the frame and in its transaction.
    fn flag(&mut self, t: &mut Transaction, problem: Problem) {
        self.notes.push(problem.to_string());
        t.flag(problem);
    }

    /// Ends a transfer.
    fn complete(&mut self, p: Pending, outcome: Outcome) {
        self.completed.push(finalize(p, outcome, self.dict));
    }
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
fn new_txn(ctx: &FrameCtx, index: u16, sub: u8, dir: TransferDirection, proto: Protocol) -> Transaction {
    Transaction {
        iface: ctx.channel.iface,
        node: ctx.channel.node,
        channel: ctx.channel,
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

/// Runs a frame through the transfer pending on the channel (it stays in place while it
/// goes on), or [`start`]s one when none is; returns the object of the transfer when the
/// frame ended it.
fn advance(state: &mut ChannelState, ctx: &FrameCtx, out: &mut Out) -> Option<(u16, u8)> {
    let Some(p) = state.pending.as_mut() else {
        start(state, ctx, out);
        return None;
    };
    match step(p, ctx, out) {
        Step::Continue => {
            if std::mem::take(&mut p.tentative) {
                let dir = p.txn.direction.as_str();
                out.notes
                    .push(format!("resynchronised: block {dir} started before the capture"));
            }
            attach(&mut p.txn, ctx);
            None
        }
        Step::Complete(outcome) => {
            attach(&mut p.txn, ctx);
            let object = p.object();
            if let Some(p) = state.pending.take() {
                out.complete(p, outcome);
            }
            object
        }
        Step::Unexpected if p.tentative || ctx.reveals_opener => {
            // One impossible byte was not the start of a run after all, or one
            // seemingly valid command was its start: either way no transaction.
            state.pending = None;
            start(state, ctx, out);
            None
        }
        Step::Unexpected => {
            if let Some(p) = state.pending.take() {
                let outcome = interrupted(&p, ctx);
                out.complete(p, outcome);
            }
            start(state, ctx, out);
            None
        }
    }
}

/// How a transfer ends when a frame does not fit it.
fn interrupted(p: &Pending, ctx: &FrameCtx) -> Outcome {
    if p.phase == (Phase::DownloadSegment { toggle: false }) && p.txn.protocol == Protocol::Unknown {
        // Only an initiate download response was seen: it was expedited.
        Outcome::Incomplete
    } else if ctx.command.object().is_some() && ctx.side == Side::Client {
        Outcome::ProtocolError("interrupted by a new request".to_string())
    } else {
        let what = ctx.command.cs_name();
        Outcome::ProtocolError(format!("unexpected {what} frame from the {}", ctx.side.as_str()))
    }
}

/// Handles a frame on a channel with no transfer running.
fn start(state: &mut ChannelState, ctx: &FrameCtx, out: &mut Out) {
    use SdoCommand::*;
    let unknown_reply = ctx.side == Side::Server && state.unknown_request && ctx.command.object().is_some();
    if !unknown_reply && let Some((mut p, unmatched)) = opened(ctx) {
        if unmatched {
            p.txn.flag(Problem::UnmatchedResponse);
            out.notes.push(Problem::UnmatchedResponse.to_string());
        }
        attach(&mut p.txn, ctx);
        p.opener = ctx.this;
        state.pending = Some(p);
        return;
    }
    match (ctx.side, ctx.command) {
        _ if unknown_reply => {
            // The reply to a command byte we did not recognise: not ours to judge.
            state.unknown_request = false;
            out.notes.push("reply to an unrecognised request".to_string());
        }
        (Side::Server, InitiateUploadResponse { .. }) => unmatched_expedited_upload(state, ctx, out),
        (side, Abort { .. }) => {
            if side == Side::Server {
                state.unknown_request = false;
            }
            out.notes.push("abort outside any transfer seen".to_string());
        }
        (side, BlockSegment { seqno, .. }) => resync_at_segment(state, ctx, side, seqno, out),
        (Side::Server, BlockDownloadAck { ackseq, blksize }) | (Side::Client, BlockUploadAck { ackseq, blksize }) => {
            resync_at_ack(state, ctx, ackseq, blksize, out)
        }
        _ => {
            out.notes.push("outside any transfer seen".to_string());
            state.orphan = ctx.this;
        }
    }
}

/// The transfer a frame opens, and whether it opens it unmatched (a response whose request
/// was not seen).
fn opened(ctx: &FrameCtx) -> Option<(Pending, bool)> {
    match ctx.side {
        Side::Client => requested(ctx).map(|p| (p, false)),
        Side::Server => answered(ctx).map(|p| (p, true)),
    }
}

/// The transfer an initiate request opens.
fn requested(ctx: &FrameCtx) -> Option<Pending> {
    use TransferDirection::*;
    let (t, phase, crc) = match ctx.command {
        SdoCommand::InitiateDownload {
            index,
            sub,
            expedited,
            size,
            data,
        } => {
            let proto = if expedited {
                Protocol::Expedited
            } else {
                Protocol::Segmented
            };
            let mut t = opening(ctx, (index, sub), Download, proto, size);
            t.append(data.bytes());
            (t, Phase::InitDownload, false)
        }
        SdoCommand::InitiateUpload { index, sub } => {
            let t = opening(ctx, (index, sub), Upload, Protocol::Unknown, None);
            (t, Phase::InitUpload, false)
        }
        SdoCommand::BlockDownloadInitiate { index, sub, crc, size } => {
            let t = opening(ctx, (index, sub), Download, Protocol::Block, size);
            (t, Phase::BlockDownloadInit, crc)
        }
        SdoCommand::BlockUploadInitiate {
            index,
            sub,
            crc,
            blksize,
            ..
        } => {
            let t = opening(ctx, (index, sub), Upload, Protocol::Block, None);
            (t, Phase::BlockUploadInit { blksize }, crc)
        }
        _ => return None,
    };
    Some(Pending::new(t, phase, crc))
}

/// The transfer an initiate response opens when its request was not seen: every one but an
/// expedited upload's, which is a whole transfer.
fn answered(ctx: &FrameCtx) -> Option<Pending> {
    use TransferDirection::*;
    let (t, phase, crc) = match ctx.command {
        SdoCommand::InitiateUploadResponse {
            index,
            sub,
            expedited: false,
            size,
            ..
        } => {
            let t = opening(ctx, (index, sub), Upload, Protocol::Segmented, size);
            (t, Phase::UploadSegment { toggle: false }, false)
        }
        SdoCommand::BlockUploadInitiateResponse { index, sub, crc, size } => {
            let t = opening(ctx, (index, sub), Upload, Protocol::Block, size);
            (t, Phase::BlockUploadStart { blksize: 127 }, crc)
        }
        SdoCommand::BlockDownloadInitiateResponse {
            index,
            sub,
            crc,
            blksize,
        } => {
            let t = opening(ctx, (index, sub), Download, Protocol::Block, None);
            (t, Phase::BlockDownloadSegments { next: 1, blksize }, crc)
        }
        SdoCommand::InitiateDownloadResponse { index, sub } => {
            // Expedited or the start of a segmented download: only the next frame tells.
            let t = opening(ctx, (index, sub), Download, Protocol::Unknown, None);
            (t, Phase::DownloadSegment { toggle: false }, false)
        }
        _ => return None,
    };
    Some(Pending::new(t, phase, crc))
}

/// The transaction an initiate opens, with the size it indicates.
fn opening(
    ctx: &FrameCtx,
    (index, sub): (u16, u8),
    dir: TransferDirection,
    proto: Protocol,
    size: Option<u32>,
) -> Transaction {
    Transaction {
        size,
        ..new_txn(ctx, index, sub, dir, proto)
    }
}

/// An expedited upload response whose request was not seen: a whole transaction.
fn unmatched_expedited_upload(state: &mut ChannelState, ctx: &FrameCtx, out: &mut Out) {
    let SdoCommand::InitiateUploadResponse {
        index, sub, size, data, ..
    } = ctx.command
    else {
        return;
    };
    let mut t = new_txn(ctx, index, sub, TransferDirection::Upload, Protocol::Expedited);
    t.size = size;
    t.append(data.bytes());
    t.flag(Problem::UnmatchedResponse);
    out.notes.push(Problem::UnmatchedResponse.to_string());
    attach(&mut t, ctx);
    out.complete(Pending::new(t, Phase::InitUpload, false), Outcome::Ok);
    // It may also have been a block segment, which the next frame would tell.
    state.orphan = ctx.this.map(|o| Orphan { listed: true, ..o });
}

/// A sub-block whose transfer began before the capture: a run or an impossible byte.
fn resync_at_segment(state: &mut ChannelState, ctx: &FrameCtx, side: Side, seqno: u8, out: &mut Out) {
    let run = ctx
        .orphan
        .filter(|o| o.continued_by(side, &[seqno, 0, 0, 0, 0, 0, 0, 0]));
    let mut p = partial(ctx, side, run);
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
    resume(p, ctx, out, state);
}

/// A block acknowledgement with no transfer running: it answers the sub-block its sender's
/// peer just sent.
fn resync_at_ack(state: &mut ChannelState, ctx: &FrameCtx, ackseq: u8, blksize: u8, out: &mut Out) {
    let sender = ctx.side.other();
    let answered = ctx.orphan.filter(|o| o.side == sender && o.seqno() == Some(ackseq));
    let mut p = partial(ctx, sender, answered);
    p.phase = match sender {
        Side::Client => Phase::BlockDownloadAck { blksize },
        Side::Server => Phase::BlockUploadAck { blksize },
    };
    if let Some((o, s)) = answered.filter(|o| !o.listed).and_then(|o| Some((o, o.seqno()?))) {
        p.sub_block.push((s, o.last(), o.data));
    }
    // Confirmed by what follows: a segment, or the end of the transfer.
    p.tentative = true;
    resume(p, ctx, out, state);
}

/// A block transfer picked up mid-way; `sender` sends its segments, `first` is an earlier
/// frame that turned out to belong to it.
fn partial(ctx: &FrameCtx, sender: Side, first: Option<Orphan>) -> Pending {
    let dir = match sender {
        Side::Client => TransferDirection::Download,
        Side::Server => TransferDirection::Upload,
    };
    let mut t = new_txn(ctx, 0, 0, dir, Protocol::Block);
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
fn resume(mut p: Pending, ctx: &FrameCtx, out: &mut Out, state: &mut ChannelState) {
    let dir = p.txn.direction.as_str();
    if !p.tentative {
        out.notes
            .push(format!("resynchronised: block {dir} started before the capture"));
    }
    // A segment or acknowledgement is what these phases wait for: the step goes on.
    step(&mut p, ctx, out);
    attach(&mut p.txn, ctx);
    state.pending = Some(p);
}

/// Advances a pending transfer by one frame: (phase, command) to the transfer type's step.
fn step(p: &mut Pending, ctx: &FrameCtx, out: &mut Out) -> Step {
    use SdoCommand::*;
    match (p.phase, ctx.side, ctx.command) {
        (_, _, Abort { code, .. }) => Step::Complete(Outcome::Aborted {
            code,
            text: abort_text(code),
            by: ctx.side,
        }),
        // A new request ends whatever ran.
        (
            _,
            Side::Client,
            InitiateDownload { .. } | InitiateUpload { .. } | BlockDownloadInitiate { .. } | BlockUploadInitiate { .. },
        ) => Step::Unexpected,
        (Phase::InitDownload | Phase::DownloadSegment { .. } | Phase::DownloadSegmentResponse { .. }, ..) => {
            download(p, ctx, out)
        }
        (Phase::InitUpload | Phase::UploadSegment { .. } | Phase::UploadSegmentResponse { .. }, ..)
        | (Phase::BlockUploadInit { .. }, Side::Server, InitiateUploadResponse { .. }) => upload(p, ctx, out),
        _ => block(p, ctx, out),
    }
}

/// Flags a response for another object than the request's.
fn check_object(t: &mut Transaction, index: u16, sub: u8, out: &mut Out) {
    if (index, sub) != (t.index, t.sub) {
        out.flag(t, Problem::UnmatchedResponse);
    }
}

/// Flags a toggle bit that did not alternate.
fn check_toggle(t: &mut Transaction, toggle: bool, want: bool, out: &mut Out) {
    if toggle != want {
        out.flag(t, Problem::ToggleError);
    }
}

/// An expedited or segmented download.
fn download(p: &mut Pending, ctx: &FrameCtx, out: &mut Out) -> Step {
    use SdoCommand::*;
    let t = &mut p.txn;
    match (p.phase, ctx.side, ctx.command) {
        (Phase::InitDownload, Side::Server, InitiateDownloadResponse { index, sub }) => {
            check_object(t, index, sub, out);
            if t.protocol == Protocol::Expedited {
                return Step::Complete(Outcome::Ok);
            }
            p.phase = Phase::DownloadSegment { toggle: false };
        }
        (Phase::DownloadSegment { toggle: want }, Side::Client, DownloadSegment { toggle, last, data }) => {
            check_toggle(t, toggle, want, out);
            if t.protocol == Protocol::Unknown {
                // Picked up at an unmatched initiate response: it was segmented after all.
                t.protocol = Protocol::Segmented;
            }
            t.append(data.bytes());
            p.phase = Phase::DownloadSegmentResponse { toggle, last };
        }
        (Phase::DownloadSegmentResponse { toggle: want, last }, Side::Server, DownloadSegmentResponse { toggle }) => {
            check_toggle(t, toggle, want, out);
            if last {
                return Step::Complete(Outcome::Ok);
            }
            p.phase = Phase::DownloadSegment { toggle: !want };
        }
        _ => return Step::Unexpected,
    }
    Step::Continue
}

/// An expedited or segmented upload (also a block upload the server answered this way).
fn upload(p: &mut Pending, ctx: &FrameCtx, out: &mut Out) -> Step {
    use SdoCommand::*;
    let t = &mut p.txn;
    match (p.phase, ctx.side, ctx.command) {
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
            check_object(t, index, sub, out);
            t.size = size;
            if expedited {
                t.protocol = Protocol::Expedited;
                t.data.extend_from_slice(data.bytes());
                return Step::Complete(Outcome::Ok);
            }
            t.protocol = Protocol::Segmented;
            p.phase = Phase::UploadSegment { toggle: false };
        }
        (Phase::UploadSegment { toggle: want }, Side::Client, UploadSegment { toggle }) => {
            check_toggle(t, toggle, want, out);
            p.phase = Phase::UploadSegmentResponse { toggle };
        }
        (Phase::UploadSegmentResponse { toggle: want }, Side::Server, UploadSegmentResponse { toggle, last, data }) => {
            check_toggle(t, toggle, want, out);
            t.append(data.bytes());
            if last {
                return Step::Complete(Outcome::Ok);
            }
            p.phase = Phase::UploadSegment { toggle: !want };
        }
        _ => return Step::Unexpected,
    }
    Step::Continue
}

/// A block download or upload, which mirror each other: initiate, sub-blocks of numbered
/// segments each acknowledged, end.
fn block(p: &mut Pending, ctx: &FrameCtx, out: &mut Out) -> Step {
    use SdoCommand::*;
    match (p.phase, ctx.side, ctx.command) {
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
            check_object(&mut p.txn, index, sub, out);
            p.crc &= crc;
            p.phase = Phase::BlockDownloadSegments { next: 1, blksize };
        }
        (Phase::BlockUploadInit { blksize }, Side::Server, BlockUploadInitiateResponse { index, sub, crc, size }) => {
            check_object(&mut p.txn, index, sub, out);
            p.crc &= crc;
            p.txn.size = size;
            p.phase = Phase::BlockUploadStart { blksize };
        }
        (Phase::BlockUploadStart { blksize }, Side::Client, BlockUploadStart) => {
            p.phase = Phase::BlockUploadSegments { next: 1, blksize };
        }
        (Phase::BlockDownloadAck { blksize }, Side::Client, BlockSegment { .. })
        | (Phase::BlockUploadAck { blksize }, Side::Server, BlockSegment { .. }) => {
            return missed_ack(p, blksize, ctx, out);
        }
        (Phase::BlockDownloadSegments { next: 1, .. }, Side::Client, BlockDownloadEnd { .. })
        | (Phase::BlockUploadSegments { next: 1, .. }, Side::Server, BlockUploadEnd { .. }) => {
            return missed_last_segment(p, ctx, out);
        }
        (Phase::BlockDownloadSegments { next, blksize }, Side::Client, BlockSegment { seqno, last, data })
        | (Phase::BlockUploadSegments { next, blksize }, Side::Server, BlockSegment { seqno, last, data }) => {
            block_segment(p, (next, blksize), (seqno, last, data), out);
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
        ) => block_ack(p, ackseq, blksize, out),
        (Phase::BlockDownloadEnd, Side::Client, BlockDownloadEnd { unused, crc })
        | (Phase::BlockUploadEnd, Side::Server, BlockUploadEnd { unused, crc }) => block_end(p, unused, crc, out),
        (Phase::BlockDownloadEndResponse, Side::Server, BlockDownloadEndResponse)
        | (Phase::BlockUploadEndResponse, Side::Client, BlockUploadEndResponse) => return Step::Complete(Outcome::Ok),
        _ => return Step::Unexpected,
    }
    Step::Continue
}

/// Awaiting segment `next` of a sub-block.
fn segments_phase(upload: bool, next: u8, blksize: u8) -> Phase {
    if upload {
        Phase::BlockUploadSegments { next, blksize }
    } else {
        Phase::BlockDownloadSegments { next, blksize }
    }
}

/// A new sub-block began: its acknowledgement was not captured.
fn missed_ack(p: &mut Pending, blksize: u8, ctx: &FrameCtx, out: &mut Out) -> Step {
    out.flag(&mut p.txn, Problem::SequenceError);
    for (_, last, data) in std::mem::take(&mut p.sub_block) {
        p.commit(last, data);
    }
    p.phase = segments_phase(matches!(p.phase, Phase::BlockUploadAck { .. }), 1, blksize);
    block(p, ctx, out)
}

/// An end at the start of a sub-block: the segment with the c bit, or its
/// acknowledgement, was not captured.
fn missed_last_segment(p: &mut Pending, ctx: &FrameCtx, out: &mut Out) -> Step {
    out.flag(&mut p.txn, Problem::SequenceError);
    p.phase = match p.phase {
        Phase::BlockDownloadSegments { .. } => Phase::BlockDownloadEnd,
        _ => Phase::BlockUploadEnd,
    };
    block(p, ctx, out)
}

/// One segment of a sub-block, kept until acknowledged.
fn block_segment(p: &mut Pending, (next, blksize): (u8, u8), (seqno, last, data): (u8, bool, Chunk), out: &mut Out) {
    let upload = matches!(p.phase, Phase::BlockUploadSegments { .. });
    if seqno != next {
        // Lost, repeated or (in a partial transfer's first sub-block) not captured:
        // the acknowledgement tells which segments count.
        out.flag(&mut p.txn, Problem::SequenceError);
    }
    if p.sub_block.len() < SUB_BLOCK_KEPT {
        p.sub_block.push((seqno, last, data));
    }
    p.phase = match (last || seqno >= blksize, upload) {
        (true, false) => Phase::BlockDownloadAck { blksize },
        (true, true) => Phase::BlockUploadAck { blksize },
        (false, _) => segments_phase(upload, seqno.wrapping_add(1), blksize),
    };
}

/// The acknowledgement of a sub-block: the segments up to `ackseq` count.
fn block_ack(p: &mut Pending, ackseq: u8, blksize: u8, out: &mut Out) {
    let upload = matches!(
        p.phase,
        Phase::BlockUploadSegments { .. } | Phase::BlockUploadAck { .. }
    );
    let segments = std::mem::take(&mut p.sub_block);
    // Every segment up to ackseq should have been seen, from 1 or, in the first
    // sub-block of a partial transfer, from the first one captured.
    let first = match (p.partial && p.txn.is_empty(), segments.first()) {
        (true, Some((s, _, _))) => *s,
        (true, None) => ackseq.saturating_add(1),
        (false, _) => 1,
    };
    let missing = (first..=ackseq).any(|n| !segments.iter().any(|(s, _, _)| *s == n));
    if missing || segments.iter().any(|(s, _, _)| *s > ackseq) {
        out.flag(&mut p.txn, Problem::SequenceError);
    }
    for (_, last, data) in segments.into_iter().filter(|(s, _, _)| *s <= ackseq) {
        p.commit(last, data);
    }
    p.phase = match (p.last_committed, upload) {
        (true, false) => Phase::BlockDownloadEnd,
        (true, true) => Phase::BlockUploadEnd,
        (false, _) => segments_phase(upload, 1, blksize),
    };
}

/// The end of a block transfer: the unused tail and the CRC.
fn block_end(p: &mut Pending, unused: u8, crc: u16, out: &mut Out) {
    let held = p.held.bytes();
    let computed = crc16_update(p.crc_acc, &held[..held.len().saturating_sub(unused as usize)]);
    p.txn.cut(unused as usize);
    if p.crc && !p.partial && computed != crc {
        out.flag(&mut p.txn, Problem::BadCrc { sent: crc, computed });
    }
    p.phase = if matches!(p.phase, Phase::BlockUploadEnd) {
        Phase::BlockUploadEndResponse
    } else {
        Phase::BlockDownloadEndResponse
    };
}
