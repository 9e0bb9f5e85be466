//! An SDO server as a pure state machine: frames from the client in, frames
//! to send and events out, time passed in as `now_ns`. It answers expedited,
//! segmented and block transfers from an [`ObjectStore`], one transfer at a time.

use crate::decode::sdo::abort::codes;
use crate::decode::sdo::crc::crc16;
use crate::decode::sdo::frame::{Chunk, SdoCommand, Side, decode, encode, sub_block};
use crate::decode::sdo::transaction::Protocol;
use crate::od::Access;
use std::collections::BTreeMap;

/// Where the server reads and writes object values. Errors are SDO abort codes.
pub trait ObjectStore {
    /// The value of (index, sub).
    fn read(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, u32>;
    /// Stores a new value of (index, sub).
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), u32>;
    /// Checks a segmented or block download before its data arrives
    /// (`size` when indicated); the default accepts everything.
    fn check_write(&mut self, _index: u16, _sub: u8, _size: Option<usize>) -> Result<(), u32> {
        Ok(())
    }
    /// The fixed size of (index, sub), used for expedited downloads that do not indicate one.
    fn size(&self, _index: u16, _sub: u8) -> Option<usize> {
        None
    }
}

/// One entry of a [`MemoryStore`].
#[derive(Clone, Debug, PartialEq)]
pub struct StoredObject {
    /// Access rights (`Ro`/`Const` refuse writes, `Wo` refuses reads).
    pub access: Access,
    /// Required length of written data, when the type has a fixed size.
    pub size: Option<usize>,
    /// Current value.
    pub value: Vec<u8>,
}

/// An in-memory object store with access rights and length checks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MemoryStore {
    /// Entries by (index, sub).
    pub objects: BTreeMap<(u16, u8), StoredObject>,
}

impl MemoryStore {
    /// Adds or replaces an entry.
    pub fn insert(&mut self, index: u16, sub: u8, access: Access, size: Option<usize>, value: Vec<u8>) {
        self.objects.insert((index, sub), StoredObject { access, size, value });
    }

    /// The entry, or the abort code saying whether the index or only the sub is missing.
    fn entry(&self, index: u16, sub: u8) -> Result<&StoredObject, u32> {
        self.objects.get(&(index, sub)).ok_or_else(|| {
            if self.objects.range((index, 0)..=(index, 255)).next().is_some() {
                codes::NO_SUB
            } else {
                codes::NO_OBJECT
            }
        })
    }

    /// Write access and length checks.
    fn writable(&self, index: u16, sub: u8, len: Option<usize>) -> Result<(), u32> {
        let o = self.entry(index, sub)?;
        if matches!(o.access, Access::Ro | Access::Const) {
            return Err(codes::READ_ONLY);
        }
        match (o.size, len) {
            (Some(want), Some(got)) if got > want => Err(codes::LENGTH_TOO_HIGH),
            (Some(want), Some(got)) if got < want => Err(codes::LENGTH_TOO_LOW),
            _ => Ok(()),
        }
    }
}

impl ObjectStore for MemoryStore {
    fn read(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, u32> {
        let o = self.entry(index, sub)?;
        if o.access == Access::Wo {
            return Err(codes::WRITE_ONLY);
        }
        Ok(o.value.clone())
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        self.writable(index, sub, Some(data.len()))?;
        if let Some(o) = self.objects.get_mut(&(index, sub)) {
            o.value = data.to_vec();
        }
        Ok(())
    }
    fn check_write(&mut self, index: u16, sub: u8, size: Option<usize>) -> Result<(), u32> {
        self.writable(index, sub, size)
    }
    fn size(&self, index: u16, sub: u8) -> Option<usize> {
        self.objects.get(&(index, sub)).and_then(|o| o.size)
    }
}

/// Server settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ServerConfig {
    /// Abort with 0x05040000 when the client is silent this long mid-transfer.
    pub timeout_ns: u64,
    /// Block size offered for block downloads (1..=127).
    pub block_size: u8,
    /// Offer a CRC in block transfers.
    pub crc: bool,
}

impl Default for ServerConfig {
    fn default() -> Self {
        ServerConfig {
            timeout_ns: 1_000_000_000,
            block_size: 127,
            crc: true,
        }
    }
}

/// What the server reports when a transfer ends.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ServerEvent {
    /// The client read (index, sub).
    Read {
        index: u16,
        sub: u8,
        protocol: Protocol,
        len: usize,
    },
    /// The client wrote (index, sub); the value is in the store.
    Written {
        index: u16,
        sub: u8,
        protocol: Protocol,
        len: usize,
    },
    /// The transfer was aborted (by `by`).
    Aborted { index: u16, sub: u8, code: u32, by: Side },
}

/// Frames to send and at most one event.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ServerOutput {
    /// Frames to send to the client, in order.
    pub frames: Vec<[u8; 8]>,
    /// What happened, when a transfer ended.
    pub event: Option<ServerEvent>,
}

/// A transfer in progress.
#[derive(Clone, Debug)]
enum State {
    Idle,
    Download {
        index: u16,
        sub: u8,
        size: Option<u32>,
        data: Vec<u8>,
        toggle: bool,
    },
    Upload {
        index: u16,
        sub: u8,
        data: Vec<u8>,
        pos: usize,
        toggle: bool,
    },
    BlockDownload {
        index: u16,
        sub: u8,
        size: Option<u32>,
        crc: bool,
        data: Vec<u8>,
        next: u8,
        blksize: u8,
        done: bool,
    },
    BlockDownloadEnd {
        index: u16,
        sub: u8,
        size: Option<u32>,
        crc: bool,
        data: Vec<u8>,
    },
    BlockUploadStart {
        index: u16,
        sub: u8,
        crc: bool,
        data: Vec<u8>,
        blksize: u8,
    },
    BlockUpload {
        index: u16,
        sub: u8,
        crc: bool,
        data: Vec<u8>,
        acked: usize,
        sent: usize,
    },
    BlockUploadEnd {
        index: u16,
        sub: u8,
        len: usize,
    },
}

impl State {
    /// The object of the running transfer ((0, 0) when idle).
    fn object(&self) -> (u16, u8) {
        match self {
            State::Idle => (0, 0),
            State::Download { index, sub, .. }
            | State::Upload { index, sub, .. }
            | State::BlockDownload { index, sub, .. }
            | State::BlockDownloadEnd { index, sub, .. }
            | State::BlockUploadStart { index, sub, .. }
            | State::BlockUpload { index, sub, .. }
            | State::BlockUploadEnd { index, sub, .. } => (*index, *sub),
        }
    }
}

/// The SDO server of one node.
#[derive(Clone, Debug)]
pub struct SdoServer {
    cfg: ServerConfig,
    state: State,
    deadline: Option<u64>,
}

impl SdoServer {
    /// An idle server.
    pub fn new(cfg: ServerConfig) -> SdoServer {
        SdoServer {
            cfg,
            state: State::Idle,
            deadline: None,
        }
    }

    /// True while a transfer is in progress.
    pub fn is_busy(&self) -> bool {
        !matches!(self.state, State::Idle)
    }

    /// Handles one frame from the client.
    pub fn on_frame(&mut self, payload: &[u8], now_ns: u64, store: &mut dyn ObjectStore) -> ServerOutput {
        let in_segments = matches!(self.state, State::BlockDownload { done: false, .. });
        let cmd = decode(Side::Client, payload, in_segments);
        let mut out = ServerOutput::default();
        let state = std::mem::replace(&mut self.state, State::Idle);
        self.state = self.step(state, cmd, store, &mut out);
        self.deadline = self.is_busy().then_some(now_ns.saturating_add(self.cfg.timeout_ns));
        out
    }

    /// Checks the timeout: past it, aborts the transfer with 0x05040000.
    pub fn poll(&mut self, now_ns: u64) -> ServerOutput {
        let mut out = ServerOutput::default();
        if self.deadline.is_some_and(|d| now_ns >= d) {
            let (index, sub) = self.state.object();
            self.state = State::Idle;
            self.deadline = None;
            abort(&mut out, index, sub, codes::TIMEOUT);
        }
        out
    }

    /// Moves from `state` on one client command.
    fn step(&self, state: State, cmd: SdoCommand, store: &mut dyn ObjectStore, out: &mut ServerOutput) -> State {
        use SdoCommand as C;
        if let C::Abort { code, .. } = cmd {
            if !matches!(state, State::Idle) {
                let (index, sub) = state.object();
                out.event = Some(ServerEvent::Aborted {
                    index,
                    sub,
                    code,
                    by: Side::Client,
                });
            }
            return State::Idle;
        }
        match (state, cmd) {
            (
                _,
                C::InitiateDownload {
                    index,
                    sub,
                    expedited: true,
                    size,
                    data,
                },
            ) => {
                let mut bytes = data.bytes().to_vec();
                if size.is_none()
                    && let Some(n) = store.size(index, sub).filter(|n| *n < bytes.len())
                {
                    bytes.truncate(n);
                }
                match store.write(index, sub, &bytes) {
                    Ok(()) => {
                        out.frames.push(encode(&C::InitiateDownloadResponse { index, sub }));
                        let len = bytes.len();
                        out.event = Some(ServerEvent::Written {
                            index,
                            sub,
                            protocol: Protocol::Expedited,
                            len,
                        });
                    }
                    Err(code) => abort(out, index, sub, code),
                }
                State::Idle
            }
            (_, C::InitiateDownload { index, sub, size, .. }) => {
                match store.check_write(index, sub, size.map(|s| s as usize)) {
                    Ok(()) => {
                        out.frames.push(encode(&C::InitiateDownloadResponse { index, sub }));
                        State::Download {
                            index,
                            sub,
                            size,
                            data: Vec::new(),
                            toggle: false,
                        }
                    }
                    Err(code) => {
                        abort(out, index, sub, code);
                        State::Idle
                    }
                }
            }
            (_, C::InitiateUpload { index, sub }) => match store.read(index, sub) {
                Ok(data) => self.start_upload(index, sub, data, out),
                Err(code) => {
                    abort(out, index, sub, code);
                    State::Idle
                }
            },
            (_, C::BlockDownloadInitiate { index, sub, crc, size }) => {
                match store.check_write(index, sub, size.map(|s| s as usize)) {
                    Ok(()) => {
                        let crc = crc && self.cfg.crc;
                        let blksize = self.cfg.block_size.clamp(1, 127);
                        out.frames.push(encode(&C::BlockDownloadInitiateResponse {
                            index,
                            sub,
                            crc,
                            blksize,
                        }));
                        State::BlockDownload {
                            index,
                            sub,
                            size,
                            crc,
                            data: Vec::new(),
                            next: 1,
                            blksize,
                            done: false,
                        }
                    }
                    Err(code) => {
                        abort(out, index, sub, code);
                        State::Idle
                    }
                }
            }
            (
                _,
                C::BlockUploadInitiate {
                    index,
                    sub,
                    crc,
                    blksize,
                    pst,
                },
            ) => {
                if !(1..=127).contains(&blksize) {
                    abort(out, index, sub, codes::BLOCK_SIZE);
                    return State::Idle;
                }
                match store.read(index, sub) {
                    Ok(data) if pst > 0 && data.len() <= pst as usize => self.start_upload(index, sub, data, out),
                    Ok(data) => {
                        let crc = crc && self.cfg.crc;
                        let size = Some(data.len() as u32);
                        out.frames
                            .push(encode(&C::BlockUploadInitiateResponse { index, sub, crc, size }));
                        State::BlockUploadStart {
                            index,
                            sub,
                            crc,
                            data,
                            blksize,
                        }
                    }
                    Err(code) => {
                        abort(out, index, sub, code);
                        State::Idle
                    }
                }
            }
            (
                State::Download {
                    index,
                    sub,
                    size,
                    mut data,
                    toggle: want,
                },
                C::DownloadSegment { toggle, last, data: d },
            ) => {
                if toggle != want {
                    abort(out, index, sub, codes::TOGGLE);
                    return State::Idle;
                }
                data.extend_from_slice(d.bytes());
                if !last {
                    out.frames.push(encode(&C::DownloadSegmentResponse { toggle }));
                    return State::Download {
                        index,
                        sub,
                        size,
                        data,
                        toggle: !toggle,
                    };
                }
                if size.is_some_and(|s| s as usize != data.len()) {
                    abort(out, index, sub, codes::LENGTH_MISMATCH);
                    return State::Idle;
                }
                match store.write(index, sub, &data) {
                    Ok(()) => {
                        out.frames.push(encode(&C::DownloadSegmentResponse { toggle }));
                        let len = data.len();
                        out.event = Some(ServerEvent::Written {
                            index,
                            sub,
                            protocol: Protocol::Segmented,
                            len,
                        });
                    }
                    Err(code) => abort(out, index, sub, code),
                }
                State::Idle
            }
            (
                State::Upload {
                    index,
                    sub,
                    data,
                    pos,
                    toggle: want,
                },
                C::UploadSegment { toggle },
            ) => {
                if toggle != want {
                    abort(out, index, sub, codes::TOGGLE);
                    return State::Idle;
                }
                let (chunk, end, last) = Chunk::segment(&data, pos);
                out.frames.push(encode(&C::UploadSegmentResponse {
                    toggle,
                    last,
                    data: chunk,
                }));
                if last {
                    let len = data.len();
                    out.event = Some(ServerEvent::Read {
                        index,
                        sub,
                        protocol: Protocol::Segmented,
                        len,
                    });
                    return State::Idle;
                }
                State::Upload {
                    index,
                    sub,
                    data,
                    pos: end,
                    toggle: !toggle,
                }
            }
            (
                State::BlockDownload {
                    index,
                    sub,
                    size,
                    crc,
                    mut data,
                    next,
                    blksize,
                    done: false,
                },
                C::BlockSegment { seqno, last, data: d },
            ) => {
                let mut next = next;
                let mut done = false;
                if seqno == next {
                    data.extend_from_slice(d.bytes());
                    next += 1;
                    done = last;
                }
                if last || seqno >= blksize {
                    let ackseq = next - 1;
                    out.frames.push(encode(&C::BlockDownloadAck { ackseq, blksize }));
                    if done {
                        return State::BlockDownloadEnd {
                            index,
                            sub,
                            size,
                            crc,
                            data,
                        };
                    }
                    next = 1;
                }
                State::BlockDownload {
                    index,
                    sub,
                    size,
                    crc,
                    data,
                    next,
                    blksize,
                    done: false,
                }
            }
            (
                State::BlockDownloadEnd {
                    index,
                    sub,
                    size,
                    crc,
                    mut data,
                },
                C::BlockDownloadEnd { unused, crc: sent },
            ) => {
                let keep = data.len().saturating_sub(unused as usize);
                data.truncate(keep);
                if crc && crc16(&data) != sent {
                    abort(out, index, sub, codes::CRC);
                    return State::Idle;
                }
                if size.is_some_and(|s| s as usize != data.len()) {
                    abort(out, index, sub, codes::LENGTH_MISMATCH);
                    return State::Idle;
                }
                match store.write(index, sub, &data) {
                    Ok(()) => {
                        out.frames.push(encode(&C::BlockDownloadEndResponse));
                        let len = data.len();
                        out.event = Some(ServerEvent::Written {
                            index,
                            sub,
                            protocol: Protocol::Block,
                            len,
                        });
                    }
                    Err(code) => abort(out, index, sub, code),
                }
                State::Idle
            }
            (
                State::BlockUploadStart {
                    index,
                    sub,
                    crc,
                    data,
                    blksize,
                },
                C::BlockUploadStart,
            ) => {
                let sent = send_sub_block(out, &data, 0, blksize);
                State::BlockUpload {
                    index,
                    sub,
                    crc,
                    data,
                    acked: 0,
                    sent,
                }
            }
            (
                State::BlockUpload {
                    index,
                    sub,
                    crc,
                    data,
                    acked,
                    sent,
                },
                C::BlockUploadAck { ackseq, blksize },
            ) => {
                // Segments of the last sub-block (an empty value is still sent as one).
                let in_flight = (sent - acked).div_ceil(7).max(1);
                if ackseq as usize > in_flight {
                    abort(out, index, sub, codes::SEQUENCE);
                    return State::Idle;
                }
                if !(1..=127).contains(&blksize) {
                    abort(out, index, sub, codes::BLOCK_SIZE);
                    return State::Idle;
                }
                if sent == data.len() && ackseq as usize == in_flight {
                    let unused = (data.len().div_ceil(7).max(1) * 7 - data.len()) as u8;
                    let crc = if crc { crc16(&data) } else { 0 };
                    out.frames.push(encode(&C::BlockUploadEnd { unused, crc }));
                    return State::BlockUploadEnd {
                        index,
                        sub,
                        len: data.len(),
                    };
                }
                let acked = (acked + ackseq as usize * 7).min(data.len());
                let sent = acked + send_sub_block(out, &data, acked, blksize);
                State::BlockUpload {
                    index,
                    sub,
                    crc,
                    data,
                    acked,
                    sent,
                }
            }
            (State::BlockUploadEnd { index, sub, len }, C::BlockUploadEndResponse) => {
                out.event = Some(ServerEvent::Read {
                    index,
                    sub,
                    protocol: Protocol::Block,
                    len,
                });
                State::Idle
            }
            (state, _) => {
                let (index, sub) = state.object();
                abort(out, index, sub, codes::UNKNOWN_COMMAND);
                if !matches!(state, State::Idle) {
                    out.event = Some(ServerEvent::Aborted {
                        index,
                        sub,
                        code: codes::UNKNOWN_COMMAND,
                        by: Side::Server,
                    });
                }
                State::Idle
            }
        }
    }

    /// Answers an upload request expedited (up to 4 bytes) or starts a segmented one.
    fn start_upload(&self, index: u16, sub: u8, data: Vec<u8>, out: &mut ServerOutput) -> State {
        use SdoCommand as C;
        let len = data.len();
        if (1..=4).contains(&len) {
            let chunk = Chunk::new(&data, 4);
            let size = Some(len as u32);
            out.frames.push(encode(&C::InitiateUploadResponse {
                index,
                sub,
                expedited: true,
                size,
                data: chunk,
            }));
            out.event = Some(ServerEvent::Read {
                index,
                sub,
                protocol: Protocol::Expedited,
                len,
            });
            return State::Idle;
        }
        let size = Some(len as u32);
        out.frames.push(encode(&C::InitiateUploadResponse {
            index,
            sub,
            expedited: false,
            size,
            data: Chunk::default(),
        }));
        State::Upload {
            index,
            sub,
            data,
            pos: 0,
            toggle: false,
        }
    }
}

/// Sends up to `blksize` segments of `data` from `from`; returns the bytes sent.
fn send_sub_block(out: &mut ServerOutput, data: &[u8], from: usize, blksize: u8) -> usize {
    let (segments, sent) = sub_block(data, from, blksize);
    out.frames.extend(segments.iter().map(encode));
    sent
}

/// Adds an abort frame.
fn abort(out: &mut ServerOutput, index: u16, sub: u8, code: u32) {
    out.frames.push(encode(&SdoCommand::Abort { index, sub, code }));
}
