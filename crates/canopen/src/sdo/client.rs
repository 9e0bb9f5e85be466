//! An SDO client as a pure state machine: one upload or download at a time,
//! expedited, segmented or block (with CRC and a configurable block size).
//! Frames from the server go in through [`SdoClient::on_frame`], time through
//! `now_ns` arguments; frames to send and the result come out.
//!
//! Every transfer ends: each answer must come within [`ClientConfig::timeout_ns`] of the
//! previous frame, the whole transfer within an overall deadline, and the data received is
//! bounded by the size the server announced (or [`ClientConfig::max_size`] when it announced
//! none). Times are receive timestamps: [`SdoClient::on_frame`] judges a frame by when it
//! arrived, not by when it is processed, so a frame that arrived in time but was read late
//! is still an answer in time.
//!
//! Abort codes the client sends when the server misbehaves (CiA 301):
//!
//! | what the server did | code |
//! | --- | --- |
//! | silent past the per-answer timeout, or the transfer past the overall deadline | `0x05040000` timed out |
//! | an answer that is not 8 bytes, a command specifier that is unknown or not expected now | `0x05040001` command specifier |
//! | toggle bit not alternated (segmented) | `0x05030000` toggle |
//! | invalid block size (block) | `0x05040002` block size |
//! | acknowledged a block segment never sent (block download) | `0x05040003` sequence number |
//! | CRC of a block upload wrong | `0x05040004` CRC |
//! | announced a size above the cap, or sent more than the cap without announcing a size | `0x05040005` out of memory |
//! | sent more data than it announced | `0x06070012` length too high |
//! | ended the transfer with less data than it announced | `0x06070013` length too low |

use super::abort::{abort_text, codes};
use super::codec::{Chunk, SdoCommand, Side, decode, encode, sub_block};
use super::crc::crc16;
use super::transaction::Protocol;
use crate::od::{Dictionary, Value};
use std::fmt;

/// Client settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClientConfig {
    /// Abort with 0x05040000 when the server is silent this long.
    pub timeout_ns: u64,
    /// Abort with 0x05040000 when the whole transfer takes longer than this, however
    /// promptly the server answers. `None`: [`ClientConfig::default_deadline_ns`].
    pub deadline_ns: Option<u64>,
    /// The most bytes an upload may bring: a larger announced size, or more data without an
    /// announced size, is aborted with 0x05040005 (out of memory).
    pub max_size: usize,
    /// Block size asked for in block uploads (1..=127).
    pub block_size: u8,
    /// Ask for a CRC in block transfers.
    pub crc: bool,
}

impl Default for ClientConfig {
    fn default() -> Self {
        ClientConfig {
            timeout_ns: 1_000_000_000,
            deadline_ns: None,
            max_size: DEFAULT_MAX_SIZE,
            block_size: 127,
            crc: true,
        }
    }
}

/// The default [`ClientConfig::max_size`]: 16 MiB.
pub(crate) const DEFAULT_MAX_SIZE: usize = 16 << 20;
/// The default overall deadline is at least this long (10 s)...
const MIN_DEADLINE_NS: u64 = 10_000_000_000;
/// ...and at least this many per-answer timeouts...
const DEADLINE_TIMEOUTS: u64 = 10;
/// ...plus this much per byte of the size known (written, or announced by the server):
/// 1 ms a byte is far slower than any bus (a 10 kbit/s bus moves about 65 bytes a second
/// in block mode, a segmented transfer to a slow device about 7 bytes a round trip).
const DEADLINE_NS_PER_BYTE: u64 = 1_000_000;

impl ClientConfig {
    /// The overall deadline when none is set: the longer of 10 s and 10 per-answer
    /// timeouts, plus 1 ms for every byte of `known_size` (the data written, or the size the
    /// server announced for an upload; 0 while unknown).
    pub fn default_deadline_ns(&self, known_size: u64) -> u64 {
        MIN_DEADLINE_NS
            .max(self.timeout_ns.saturating_mul(DEADLINE_TIMEOUTS))
            .saturating_add(known_size.saturating_mul(DEADLINE_NS_PER_BYTE))
    }
}

/// How to transfer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Expedited when the data fits in 4 bytes (downloads), else segmented.
    #[default]
    Auto,
    /// Segmented even for 1-4 bytes (downloads; uploads follow the server).
    Segmented,
    /// Block transfer.
    Block,
}

/// Why a transfer failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SdoError {
    /// The server aborted.
    Aborted { code: u32, text: &'static str },
    /// The server was silent past the timeout; the client sent abort 0x05040000.
    Timeout,
    /// The transfer was still running at its overall deadline, `limit_ns` after it started
    /// (the server kept it going); the client sent abort 0x05040000.
    Deadline { limit_ns: u64 },
    /// The server broke the protocol; the client sent an abort with `code`.
    Protocol { code: u32, reason: String },
    /// The caller aborted the transfer with `code`.
    Cancelled { code: u32 },
}

impl fmt::Display for SdoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SdoError::Aborted { code, text } => write!(f, "aborted by the server: 0x{code:08X} {text}"),
            SdoError::Timeout => write!(f, "SDO protocol timed out (no answer from the server)"),
            SdoError::Deadline { limit_ns } => write!(
                f,
                "SDO transfer not finished within its overall deadline of {} ms (the server kept it going)",
                limit_ns / 1_000_000
            ),
            SdoError::Protocol { code, reason } => write!(f, "{reason} (sent abort 0x{code:08X})"),
            SdoError::Cancelled { code } => write!(f, "cancelled with abort 0x{code:08X} {}", abort_text(*code)),
        }
    }
}

impl std::error::Error for SdoError {}

/// The result of a finished transfer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Completion {
    /// Data read from (index, sub).
    Uploaded {
        index: u16,
        sub: u8,
        protocol: Protocol,
        data: Vec<u8>,
    },
    /// (index, sub) written.
    Downloaded {
        index: u16,
        sub: u8,
        protocol: Protocol,
        len: usize,
    },
    /// The transfer of (index, sub) failed.
    Failed { index: u16, sub: u8, error: SdoError },
}

impl Completion {
    /// The uploaded value typed through the dictionary (`None` for downloads,
    /// failures and objects the dictionary does not know).
    pub fn value(&self, dict: &Dictionary) -> Option<Value> {
        match self {
            Completion::Uploaded { index, sub, data, .. } => {
                dict.object(*index, *sub).map(|o| o.data_type.decode(data))
            }
            _ => None,
        }
    }
}

/// Frames to send now and, when the transfer ended, its result.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ClientOutput {
    /// Frames to send to the server, in order.
    pub frames: Vec<[u8; 8]>,
    /// The result, when the transfer ended.
    pub done: Option<Completion>,
}

/// The caller asked for a transfer while one is running.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Busy;

impl fmt::Display for Busy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an SDO transfer is already running on this channel")
    }
}

impl std::error::Error for Busy {}

/// What the client waits for.
#[derive(Clone, Debug)]
enum State {
    Idle,
    /// The answer to an initiate download (expedited or segmented).
    InitDownload {
        data: Vec<u8>,
        protocol: Protocol,
    },
    /// The confirmation of the download segment before `pos`.
    DownloadSegment(Sending),
    /// The answer to an initiate upload.
    InitUpload,
    /// The next upload segment.
    UploadSegment(Receiving),
    /// The answer to an initiate block download.
    BlockDownloadInit {
        data: Vec<u8>,
    },
    /// The acknowledgement of the sub-block sent.
    BlockDownloadAck(SubBlocksOut),
    /// The answer to the end of a block download.
    BlockDownloadEnd {
        len: usize,
    },
    /// The answer to an initiate block upload.
    BlockUploadInit,
    /// The segments of a sub-block.
    BlockUpload(SubBlocksIn),
    /// The end of a block upload.
    BlockUploadEnd {
        data: Vec<u8>,
        crc: bool,
        size: Option<u32>,
    },
}

/// A segmented download under way.
#[derive(Clone, Debug)]
struct Sending {
    data: Vec<u8>,
    /// Bytes sent so far.
    pos: usize,
    /// Toggle bit of the segment sent last.
    toggle: bool,
}

/// A segmented upload under way.
#[derive(Clone, Debug)]
struct Receiving {
    data: Vec<u8>,
    /// The size the server announced.
    size: Option<u32>,
    /// Toggle bit of the segment asked for.
    toggle: bool,
}

/// A block download under way.
#[derive(Clone, Debug)]
struct SubBlocksOut {
    data: Vec<u8>,
    crc: bool,
    /// Bytes acknowledged.
    acked: usize,
    /// Bytes sent.
    sent: usize,
}

/// A block upload under way.
#[derive(Clone, Debug)]
struct SubBlocksIn {
    /// Bytes of acknowledged sub-blocks.
    data: Vec<u8>,
    crc: bool,
    /// The size the server announced.
    size: Option<u32>,
    /// The sequence number expected next.
    next: u8,
    /// Bytes of the current sub-block.
    sub_block: Vec<u8>,
    /// The segment with the c bit arrived.
    last: bool,
}

/// An SDO client for one channel.
#[derive(Clone, Debug)]
pub struct SdoClient {
    cfg: ClientConfig,
    state: State,
    index: u16,
    sub: u8,
    /// When the current answer is due (receive time of the last frame plus the timeout).
    deadline: u64,
    /// When the transfer started.
    start: u64,
    /// When the whole transfer must be done.
    overall: u64,
}

impl SdoClient {
    /// An idle client.
    pub fn new(cfg: ClientConfig) -> SdoClient {
        SdoClient {
            cfg,
            state: State::Idle,
            index: 0,
            sub: 0,
            deadline: 0,
            start: 0,
            overall: 0,
        }
    }

    /// True while a transfer is running.
    pub fn is_busy(&self) -> bool {
        !matches!(self.state, State::Idle)
    }

    /// Starts reading (index, sub); returns the first frame to send.
    pub fn upload(&mut self, index: u16, sub: u8, mode: Mode, now_ns: u64) -> Result<[u8; 8], Busy> {
        self.begin(index, sub, now_ns)?;
        Ok(if mode == Mode::Block {
            self.state = State::BlockUploadInit;
            let blksize = self.cfg.block_size.clamp(1, 127);
            encode(&SdoCommand::BlockUploadInitiate {
                index,
                sub,
                crc: self.cfg.crc,
                blksize,
                pst: 0,
            })
        } else {
            self.state = State::InitUpload;
            encode(&SdoCommand::InitiateUpload { index, sub })
        })
    }

    /// Starts writing `data` to (index, sub); returns the first frame to send.
    pub fn download(&mut self, index: u16, sub: u8, data: Vec<u8>, mode: Mode, now_ns: u64) -> Result<[u8; 8], Busy> {
        self.begin(index, sub, now_ns)?;
        self.size_known(data.len() as u64);
        let size = Some(data.len() as u32);
        let expedited = mode == Mode::Auto && (1..=4).contains(&data.len());
        let (cmd, state) = match mode {
            Mode::Block => {
                let crc = self.cfg.crc;
                let cmd = SdoCommand::BlockDownloadInitiate { index, sub, crc, size };
                (cmd, State::BlockDownloadInit { data })
            }
            Mode::Auto | Mode::Segmented => {
                let (protocol, chunk) = if expedited {
                    (Protocol::Expedited, Chunk::new(&data, 4))
                } else {
                    (Protocol::Segmented, Chunk::default())
                };
                let cmd = SdoCommand::InitiateDownload {
                    index,
                    sub,
                    expedited,
                    size,
                    data: chunk,
                };
                (cmd, State::InitDownload { data, protocol })
            }
        };
        self.state = state;
        Ok(encode(&cmd))
    }

    /// Aborts the running transfer with `code`; returns the abort frame and the failure.
    pub fn abort(&mut self, code: u32) -> ClientOutput {
        let mut out = ClientOutput::default();
        if self.is_busy() {
            self.fail(&mut out, code, SdoError::Cancelled { code });
        }
        out
    }

    /// Checks the timeouts at `now_ns`: past the answer's deadline or the overall one, sends
    /// abort 0x05040000 and fails the transfer. Call it only after every frame received
    /// before `now_ns` went through [`SdoClient::on_frame`].
    pub fn poll(&mut self, now_ns: u64) -> ClientOutput {
        let mut out = ClientOutput::default();
        self.expire(&mut out, now_ns);
        out
    }

    /// The time at which [`SdoClient::poll`] fails the running transfer (`None` when idle).
    pub fn next_deadline(&self) -> Option<u64> {
        self.is_busy().then(|| self.deadline.min(self.overall))
    }

    /// Notes that a frame of ours reached the bus at `ts_ns` (its own receive timestamp):
    /// the answer is due a timeout after that, not after the moment the client made the
    /// frame, in case sending was delayed.
    pub fn on_sent(&mut self, ts_ns: u64) {
        if self.is_busy() {
            self.deadline = self.deadline.max(ts_ns.saturating_add(self.cfg.timeout_ns));
        }
    }

    /// Handles one frame from the server, received at `ts_ns`. A frame received after the
    /// answer was due (or after the overall deadline) ends the transfer as a timeout.
    pub fn on_frame(&mut self, payload: &[u8], ts_ns: u64) -> ClientOutput {
        let mut out = ClientOutput::default();
        if !self.is_busy() || self.expire(&mut out, ts_ns) {
            return out;
        }
        let state = std::mem::replace(&mut self.state, State::Idle);
        self.state = if payload.len() != 8 {
            let reason = format!(
                "the server sent a {}-byte answer ({}); SDO frames have 8 bytes",
                payload.len(),
                crate::frame::hex::spaced(payload)
            );
            self.protocol_error(&mut out, codes::UNKNOWN_COMMAND, reason)
        } else {
            let in_segments = matches!(state, State::BlockUpload { .. });
            let cmd = decode(Side::Server, payload, in_segments);
            self.step(state, cmd, &mut out)
        };
        self.deadline = ts_ns.saturating_add(self.cfg.timeout_ns);
        out
    }

    /// Fails the transfer when `at_ns` is past the overall deadline or the answer's; true if it did.
    fn expire(&mut self, out: &mut ClientOutput, at_ns: u64) -> bool {
        if !self.is_busy() {
            return false;
        }
        if at_ns >= self.overall {
            let limit_ns = self.overall - self.start;
            self.fail(out, codes::TIMEOUT, SdoError::Deadline { limit_ns });
        } else if at_ns >= self.deadline {
            self.fail(out, codes::TIMEOUT, SdoError::Timeout);
        } else {
            return false;
        }
        true
    }

    /// Sets the overall deadline once the size of the transfer is known (default deadline only).
    fn size_known(&mut self, size: u64) {
        if self.cfg.deadline_ns.is_none() {
            self.overall = self.start.saturating_add(self.cfg.default_deadline_ns(size));
        }
    }

    fn begin(&mut self, index: u16, sub: u8, now_ns: u64) -> Result<(), Busy> {
        if self.is_busy() {
            return Err(Busy);
        }
        self.index = index;
        self.sub = sub;
        self.deadline = now_ns.saturating_add(self.cfg.timeout_ns);
        self.start = now_ns;
        let overall = self.cfg.deadline_ns.unwrap_or_else(|| self.cfg.default_deadline_ns(0));
        self.overall = now_ns.saturating_add(overall);
        Ok(())
    }

    /// Sends an abort and ends the transfer with `error`.
    fn fail(&mut self, out: &mut ClientOutput, code: u32, error: SdoError) {
        let (index, sub) = (self.index, self.sub);
        out.frames.push(encode(&SdoCommand::Abort { index, sub, code }));
        out.done = Some(Completion::Failed { index, sub, error });
        self.state = State::Idle;
    }

    /// Ends with a protocol error: abort `code` for `reason`.
    fn protocol_error(&self, out: &mut ClientOutput, code: u32, reason: String) -> State {
        let (index, sub) = (self.index, self.sub);
        out.frames.push(encode(&SdoCommand::Abort { index, sub, code }));
        out.done = Some(Completion::Failed {
            index,
            sub,
            error: SdoError::Protocol { code, reason },
        });
        State::Idle
    }

    /// Moves from `state` on one server command: (state, command) to the step of the
    /// transfer type running; a command that fits no step is a protocol error.
    fn step(&mut self, state: State, cmd: SdoCommand, out: &mut ClientOutput) -> State {
        use SdoCommand as C;
        let same = |i: u16, s: u8| (i, s) == (self.index, self.sub);
        match (state, cmd) {
            (_, C::Abort { code, .. }) => self.aborted(code, out),
            (State::InitDownload { data, protocol }, C::InitiateDownloadResponse { index, sub })
                if same(index, sub) =>
            {
                self.download_initiated(data, protocol, out)
            }
            (State::DownloadSegment(s), C::DownloadSegmentResponse { toggle }) => {
                self.download_segment_confirmed(s, toggle, out)
            }
            (
                State::InitUpload | State::BlockUploadInit,
                C::InitiateUploadResponse {
                    index,
                    sub,
                    expedited,
                    size,
                    data,
                },
            ) if same(index, sub) => self.upload_initiated(expedited, size, data, out),
            (State::UploadSegment(r), C::UploadSegmentResponse { toggle, last, data }) => {
                self.upload_segment(r, (toggle, last, data), out)
            }
            (
                State::BlockDownloadInit { data },
                C::BlockDownloadInitiateResponse {
                    index,
                    sub,
                    crc,
                    blksize,
                },
            ) if same(index, sub) => self.block_download_initiated(data, crc, blksize, out),
            (State::BlockDownloadAck(b), C::BlockDownloadAck { ackseq, blksize }) => {
                self.block_download_acked(b, ackseq, blksize, out)
            }
            (State::BlockDownloadEnd { len }, C::BlockDownloadEndResponse) => {
                self.downloaded(out, Protocol::Block, len)
            }
            (State::BlockUploadInit, C::BlockUploadInitiateResponse { index, sub, crc, size }) if same(index, sub) => {
                self.block_upload_initiated(crc, size, out)
            }
            (State::BlockUpload(b), C::BlockSegment { seqno, last, data }) => {
                self.block_upload_segment(b, (seqno, last, data), out)
            }
            (State::BlockUploadEnd { data, crc, size }, C::BlockUploadEnd { unused, crc: sent }) => {
                self.block_upload_ended(data, (crc, size), (unused, sent), out)
            }
            (_, cmd) => {
                let reason = format!("unexpected {} frame from the server", cmd.cs_name());
                self.protocol_error(out, codes::UNKNOWN_COMMAND, reason)
            }
        }
    }

    /// The server aborted.
    fn aborted(&self, code: u32, out: &mut ClientOutput) -> State {
        let error = SdoError::Aborted {
            code,
            text: abort_text(code),
        };
        out.done = Some(Completion::Failed {
            index: self.index,
            sub: self.sub,
            error,
        });
        State::Idle
    }

    /// Ends the transfer: `len` bytes written.
    fn downloaded(&self, out: &mut ClientOutput, protocol: Protocol, len: usize) -> State {
        let (index, sub) = (self.index, self.sub);
        out.done = Some(Completion::Downloaded {
            index,
            sub,
            protocol,
            len,
        });
        State::Idle
    }

    /// Ends the transfer: `data` read.
    fn uploaded(&self, out: &mut ClientOutput, protocol: Protocol, data: Vec<u8>) -> State {
        let (index, sub) = (self.index, self.sub);
        out.done = Some(Completion::Uploaded {
            index,
            sub,
            protocol,
            data,
        });
        State::Idle
    }

    // Expedited and segmented download.

    /// The server accepted the download: done if expedited, else the first segment.
    fn download_initiated(&self, data: Vec<u8>, protocol: Protocol, out: &mut ClientOutput) -> State {
        if protocol == Protocol::Expedited {
            return self.downloaded(out, protocol, data.len());
        }
        self.send_download_segment(out, data, 0, false)
    }

    /// The server confirmed a segment: the next one, or done.
    fn download_segment_confirmed(&self, s: Sending, toggle: bool, out: &mut ClientOutput) -> State {
        if toggle != s.toggle {
            return self.protocol_error(out, codes::TOGGLE, "toggle bit not alternated".into());
        }
        if s.pos >= s.data.len() {
            return self.downloaded(out, Protocol::Segmented, s.data.len());
        }
        self.send_download_segment(out, s.data, s.pos, !toggle)
    }

    /// Sends the download segment starting at `pos`.
    fn send_download_segment(&self, out: &mut ClientOutput, data: Vec<u8>, pos: usize, toggle: bool) -> State {
        let (chunk, end, last) = Chunk::segment(&data, pos);
        out.frames.push(encode(&SdoCommand::DownloadSegment {
            toggle,
            last,
            data: chunk,
        }));
        State::DownloadSegment(Sending { data, pos: end, toggle })
    }

    // Expedited and segmented upload.

    /// The server answered an upload (also a block upload it answered this way): the data
    /// if expedited, else the first segment request.
    fn upload_initiated(&mut self, expedited: bool, size: Option<u32>, data: Chunk, out: &mut ClientOutput) -> State {
        if expedited {
            let mut bytes = data.bytes().to_vec();
            if let Some(n) = size {
                bytes.truncate(n as usize);
            }
            return self.uploaded(out, Protocol::Expedited, bytes);
        }
        if let Err((code, reason)) = self.announced(size) {
            return self.protocol_error(out, code, reason);
        }
        out.frames.push(encode(&SdoCommand::UploadSegment { toggle: false }));
        State::UploadSegment(Receiving {
            data: Vec::new(),
            size,
            toggle: false,
        })
    }

    /// One upload segment: ask for the next, or done.
    fn upload_segment(
        &self,
        mut r: Receiving,
        (toggle, last, d): (bool, bool, Chunk),
        out: &mut ClientOutput,
    ) -> State {
        if toggle != r.toggle {
            return self.protocol_error(out, codes::TOGGLE, "toggle bit not alternated".into());
        }
        r.data.extend_from_slice(d.bytes());
        if let Err((code, reason)) = self.bounded(r.data.len(), r.size, 1) {
            return self.protocol_error(out, code, reason);
        }
        if !last {
            out.frames.push(encode(&SdoCommand::UploadSegment { toggle: !toggle }));
            r.toggle = !toggle;
            return State::UploadSegment(r);
        }
        if let Some(n) = r.size.filter(|n| (*n as usize) > r.data.len()) {
            let reason = format!("the server announced {n} bytes but ended after {}", r.data.len());
            return self.protocol_error(out, codes::LENGTH_TOO_LOW, reason);
        }
        self.uploaded(out, Protocol::Segmented, r.data)
    }

    // Block download.

    /// The server accepted the block download: the first sub-block.
    fn block_download_initiated(&self, data: Vec<u8>, crc: bool, blksize: u8, out: &mut ClientOutput) -> State {
        if !(1..=127).contains(&blksize) {
            return self.protocol_error(out, codes::BLOCK_SIZE, format!("invalid block size {blksize}"));
        }
        let crc = crc && self.cfg.crc;
        let sent = send_sub_block(out, &data, 0, blksize);
        State::BlockDownloadAck(SubBlocksOut {
            data,
            crc,
            acked: 0,
            sent,
        })
    }

    /// The server acknowledged a sub-block: the next one, or the end.
    fn block_download_acked(&self, b: SubBlocksOut, ackseq: u8, blksize: u8, out: &mut ClientOutput) -> State {
        let SubBlocksOut { data, crc, acked, sent } = b;
        // Segments of the last sub-block (an empty transfer still sends one).
        let in_flight = (sent - acked).div_ceil(7).max(1);
        if ackseq as usize > in_flight {
            return self.protocol_error(out, codes::SEQUENCE, format!("acknowledged segment {ackseq} not sent"));
        }
        if !(1..=127).contains(&blksize) {
            return self.protocol_error(out, codes::BLOCK_SIZE, format!("invalid block size {blksize}"));
        }
        if sent == data.len() && ackseq as usize == in_flight {
            let unused = (data.len().div_ceil(7).max(1) * 7 - data.len()) as u8;
            let crc = if crc { crc16(&data) } else { 0 };
            out.frames.push(encode(&SdoCommand::BlockDownloadEnd { unused, crc }));
            return State::BlockDownloadEnd { len: data.len() };
        }
        let acked = (acked + ackseq as usize * 7).min(data.len());
        let sent = acked + send_sub_block(out, &data, acked, blksize);
        State::BlockDownloadAck(SubBlocksOut { data, crc, acked, sent })
    }

    // Block upload.

    /// The server accepted the block upload: start it.
    fn block_upload_initiated(&mut self, crc: bool, size: Option<u32>, out: &mut ClientOutput) -> State {
        if let Err((code, reason)) = self.announced(size) {
            return self.protocol_error(out, code, reason);
        }
        out.frames.push(encode(&SdoCommand::BlockUploadStart));
        State::BlockUpload(SubBlocksIn {
            data: Vec::new(),
            crc: crc && self.cfg.crc,
            size,
            next: 1,
            sub_block: Vec::new(),
            last: false,
        })
    }

    /// One segment of a sub-block; acknowledges the sub-block at its end.
    fn block_upload_segment(
        &self,
        mut b: SubBlocksIn,
        (seqno, c, d): (u8, bool, Chunk),
        out: &mut ClientOutput,
    ) -> State {
        if seqno == b.next && !b.last {
            b.sub_block.extend_from_slice(d.bytes());
            b.next += 1;
            b.last = c;
            // Block segments carry 7 bytes each, the last one padded.
            if let Err((code, reason)) = self.bounded(b.data.len() + b.sub_block.len(), b.size, 7) {
                return self.protocol_error(out, code, reason);
            }
        }
        let blksize = self.cfg.block_size.clamp(1, 127);
        if c || seqno >= blksize {
            out.frames.push(encode(&SdoCommand::BlockUploadAck {
                ackseq: b.next - 1,
                blksize,
            }));
            b.data.append(&mut b.sub_block);
            if b.last {
                let SubBlocksIn { data, crc, size, .. } = b;
                return State::BlockUploadEnd { data, crc, size };
            }
            b.next = 1;
        }
        State::BlockUpload(b)
    }

    /// The end of a block upload: the unused tail, the CRC and the size checked.
    fn block_upload_ended(
        &self,
        mut data: Vec<u8>,
        (crc, size): (bool, Option<u32>),
        (unused, sent): (u8, u16),
        out: &mut ClientOutput,
    ) -> State {
        let keep = data.len().saturating_sub(unused as usize);
        data.truncate(keep);
        if crc && crc16(&data) != sent {
            return self.protocol_error(out, codes::CRC, "block CRC does not match the data".into());
        }
        if let Some(n) = size.filter(|n| *n as usize != data.len()) {
            let (code, what) = if (n as usize) > data.len() {
                (codes::LENGTH_TOO_LOW, "ended after")
            } else {
                (codes::LENGTH_TOO_HIGH, "sent")
            };
            let reason = format!("the server announced {n} bytes but {what} {}", data.len());
            return self.protocol_error(out, code, reason);
        }
        out.frames.push(encode(&SdoCommand::BlockUploadEndResponse));
        self.uploaded(out, Protocol::Block, data)
    }

    /// Checks the size a server announced for an upload against the cap and sets the default
    /// deadline from it; `Err` holds the abort code and the reason.
    fn announced(&mut self, size: Option<u32>) -> Result<(), (u32, String)> {
        if let Some(n) = size {
            if n as usize > self.cfg.max_size {
                let reason = format!(
                    "the server announced {n} bytes, more than the {} this client takes",
                    self.cfg.max_size
                );
                return Err((codes::OUT_OF_MEMORY, reason));
            }
            self.size_known(n.into());
        }
        Ok(())
    }

    /// Checks that `got` bytes received so far stay within the announced `size` (rounded up
    /// to whole `unit`s of padding) or, without one, within the cap.
    fn bounded(&self, got: usize, size: Option<u32>, unit: usize) -> Result<(), (u32, String)> {
        let limit = |n: u32| match unit {
            1 => n as usize,
            _ => (n as usize).div_ceil(unit).max(1) * unit,
        };
        match size {
            Some(n) if got > limit(n) => Err((
                codes::LENGTH_TOO_HIGH,
                format!("the server announced {n} bytes but sent {got} already"),
            )),
            None if got > self.cfg.max_size => Err((
                codes::OUT_OF_MEMORY,
                format!(
                    "the server sent {got} bytes without announcing a size, more than the {} this client takes",
                    self.cfg.max_size
                ),
            )),
            _ => Ok(()),
        }
    }
}

/// Sends up to `blksize` block segments of `data` from `from`; returns the bytes sent.
fn send_sub_block(out: &mut ClientOutput, data: &[u8], from: usize, blksize: u8) -> usize {
    let (segments, sent) = sub_block(data, from, blksize);
    out.frames.extend(segments.iter().map(encode));
    sent
}
