//! An SDO server as a pure state machine: frames from the client in, frames
//! to send and events out, time passed in as `now_ns`. It answers expedited,
//! segmented and block transfers from an [`ObjectStore`], one transfer at a time.

use super::abort::codes;
use super::codec::{Chunk, SdoCommand, Side, decode, encode, sub_block};
use super::crc::crc16;
use super::transaction::Protocol;
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

/// A transfer in progress: what the server waits for.
#[derive(Clone, Debug)]
enum State {
    Idle,
    /// The next download segment.
    Download(Incoming),
    /// The next upload segment request.
    Upload(Outgoing),
    /// The segments of a block download sub-block.
    BlockDownload(BlockIn),
    /// The end of a block download.
    BlockDownloadEnd(BlockIn),
    /// The client's start of a block upload.
    BlockUploadStart {
        at: Object,
        crc: bool,
        data: Vec<u8>,
        blksize: u8,
    },
    /// The acknowledgement of the sub-block sent.
    BlockUpload(BlockOut),
    /// The client's answer to the end of a block upload.
    BlockUploadEnd {
        at: Object,
        len: usize,
    },
}

/// An object's (index, sub).
type Object = (u16, u8);

/// A segmented download under way.
#[derive(Clone, Debug)]
struct Incoming {
    at: Object,
    /// The size the client indicated.
    size: Option<u32>,
    data: Vec<u8>,
    /// Toggle bit of the segment expected.
    toggle: bool,
}

/// A segmented upload under way.
#[derive(Clone, Debug)]
struct Outgoing {
    at: Object,
    data: Vec<u8>,
    /// Bytes sent so far.
    pos: usize,
    /// Toggle bit of the request expected.
    toggle: bool,
}

/// A block download under way.
#[derive(Clone, Debug)]
struct BlockIn {
    at: Object,
    /// The size the client indicated.
    size: Option<u32>,
    crc: bool,
    data: Vec<u8>,
    /// The sequence number expected next.
    next: u8,
    blksize: u8,
}

/// A block upload under way.
#[derive(Clone, Debug)]
struct BlockOut {
    at: Object,
    crc: bool,
    data: Vec<u8>,
    /// Bytes acknowledged.
    acked: usize,
    /// Bytes sent.
    sent: usize,
}

impl State {
    /// The object of the running transfer ((0, 0) when idle).
    fn object(&self) -> Object {
        match self {
            State::Idle => (0, 0),
            State::Download(Incoming { at, .. })
            | State::Upload(Outgoing { at, .. })
            | State::BlockDownload(BlockIn { at, .. })
            | State::BlockDownloadEnd(BlockIn { at, .. })
            | State::BlockUploadStart { at, .. }
            | State::BlockUpload(BlockOut { at, .. })
            | State::BlockUploadEnd { at, .. } => *at,
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
        let in_segments = matches!(self.state, State::BlockDownload(_));
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
            let at = self.state.object();
            self.state = State::Idle;
            self.deadline = None;
            abort(&mut out, at, codes::TIMEOUT);
        }
        out
    }

    /// Moves from `state` on one client command: an abort ends the transfer, a request
    /// starts one whatever ran, anything else goes on with the transfer running.
    fn step(&self, state: State, cmd: SdoCommand, store: &mut dyn ObjectStore, out: &mut ServerOutput) -> State {
        if let SdoCommand::Abort { code, .. } = cmd {
            if !matches!(state, State::Idle) {
                let ((index, sub), by) = (state.object(), Side::Client);
                out.event = Some(ServerEvent::Aborted { index, sub, code, by });
            }
            return State::Idle;
        }
        match self.request(cmd, store, out) {
            Some(next) => next,
            None => continued(state, cmd, store, out),
        }
    }

    /// Starts the transfer a request asks for (`None`: not a request).
    fn request(&self, cmd: SdoCommand, store: &mut dyn ObjectStore, out: &mut ServerOutput) -> Option<State> {
        use SdoCommand as C;
        Some(match cmd {
            C::InitiateDownload {
                index,
                sub,
                expedited: true,
                size,
                data,
            } => expedited_download((index, sub), size, data, store, out),
            C::InitiateDownload { index, sub, size, .. } => segmented_download((index, sub), size, store, out),
            C::InitiateUpload { index, sub } => match store.read(index, sub) {
                Ok(data) => start_upload((index, sub), data, out),
                Err(code) => abort(out, (index, sub), code),
            },
            C::BlockDownloadInitiate { index, sub, crc, size } => {
                self.block_download((index, sub), crc, size, store, out)
            }
            C::BlockUploadInitiate {
                index,
                sub,
                crc,
                blksize,
                pst,
            } => self.block_upload((index, sub), (crc, blksize, pst), store, out),
            _ => return None,
        })
    }

    /// An initiate block download: accepted with our block size, or aborted.
    fn block_download(
        &self,
        at: Object,
        crc: bool,
        size: Option<u32>,
        store: &mut dyn ObjectStore,
        out: &mut ServerOutput,
    ) -> State {
        let (index, sub) = at;
        if let Err(code) = store.check_write(index, sub, size.map(|s| s as usize)) {
            return abort(out, at, code);
        }
        let crc = crc && self.cfg.crc;
        let blksize = self.cfg.block_size.clamp(1, 127);
        out.frames.push(encode(&SdoCommand::BlockDownloadInitiateResponse {
            index,
            sub,
            crc,
            blksize,
        }));
        State::BlockDownload(BlockIn {
            at,
            size,
            crc,
            data: Vec::new(),
            next: 1,
            blksize,
        })
    }

    /// An initiate block upload: answered by block, or (small values under the protocol
    /// switch threshold) expedited or segmented.
    fn block_upload(
        &self,
        at: Object,
        (crc, blksize, pst): (bool, u8, u8),
        store: &mut dyn ObjectStore,
        out: &mut ServerOutput,
    ) -> State {
        let (index, sub) = at;
        if !(1..=127).contains(&blksize) {
            return abort(out, at, codes::BLOCK_SIZE);
        }
        match store.read(index, sub) {
            Ok(data) if pst > 0 && data.len() <= pst as usize => start_upload(at, data, out),
            Ok(data) => {
                let crc = crc && self.cfg.crc;
                let size = Some(data.len() as u32);
                out.frames.push(encode(&SdoCommand::BlockUploadInitiateResponse {
                    index,
                    sub,
                    crc,
                    size,
                }));
                State::BlockUploadStart { at, crc, data, blksize }
            }
            Err(code) => abort(out, at, code),
        }
    }
}

/// (state, command) to the step of the transfer type running; a command that fits no step
/// is aborted.
fn continued(state: State, cmd: SdoCommand, store: &mut dyn ObjectStore, out: &mut ServerOutput) -> State {
    use SdoCommand as C;
    match (state, cmd) {
        (State::Download(d), C::DownloadSegment { toggle, last, data }) => {
            download_segment(d, (toggle, last, data), store, out)
        }
        (State::Upload(u), C::UploadSegment { toggle }) => upload_segment(u, toggle, out),
        (State::BlockDownload(b), C::BlockSegment { seqno, last, data }) => {
            block_download_segment(b, (seqno, last, data), out)
        }
        (State::BlockDownloadEnd(b), C::BlockDownloadEnd { unused, crc }) => {
            block_download_end(b, unused, crc, store, out)
        }
        (State::BlockUploadStart { at, crc, data, blksize }, C::BlockUploadStart) => {
            let sent = send_sub_block(out, &data, 0, blksize);
            State::BlockUpload(BlockOut {
                at,
                crc,
                data,
                acked: 0,
                sent,
            })
        }
        (State::BlockUpload(b), C::BlockUploadAck { ackseq, blksize }) => block_upload_acked(b, ackseq, blksize, out),
        (State::BlockUploadEnd { at: (index, sub), len }, C::BlockUploadEndResponse) => {
            let protocol = Protocol::Block;
            out.event = Some(ServerEvent::Read {
                index,
                sub,
                protocol,
                len,
            });
            State::Idle
        }
        (state, _) => {
            let (index, sub) = state.object();
            abort(out, (index, sub), codes::UNKNOWN_COMMAND);
            if !matches!(state, State::Idle) {
                let (code, by) = (codes::UNKNOWN_COMMAND, Side::Server);
                out.event = Some(ServerEvent::Aborted { index, sub, code, by });
            }
            State::Idle
        }
    }
}

// Expedited and segmented download.

/// An expedited download: written at once.
fn expedited_download(
    at: Object,
    size: Option<u32>,
    data: Chunk,
    store: &mut dyn ObjectStore,
    out: &mut ServerOutput,
) -> State {
    let (index, sub) = at;
    let mut bytes = data.bytes().to_vec();
    if size.is_none()
        && let Some(n) = store.size(index, sub).filter(|n| *n < bytes.len())
    {
        bytes.truncate(n);
    }
    let confirmation = SdoCommand::InitiateDownloadResponse { index, sub };
    write(at, &bytes, (Protocol::Expedited, confirmation), store, out)
}

/// An initiate segmented download: accepted, or aborted.
fn segmented_download(at: Object, size: Option<u32>, store: &mut dyn ObjectStore, out: &mut ServerOutput) -> State {
    let (index, sub) = at;
    if let Err(code) = store.check_write(index, sub, size.map(|s| s as usize)) {
        return abort(out, at, code);
    }
    out.frames
        .push(encode(&SdoCommand::InitiateDownloadResponse { index, sub }));
    State::Download(Incoming {
        at,
        size,
        data: Vec::new(),
        toggle: false,
    })
}

/// One download segment: confirmed, and at the last one the value written.
fn download_segment(
    mut d: Incoming,
    (toggle, last, data): (bool, bool, Chunk),
    store: &mut dyn ObjectStore,
    out: &mut ServerOutput,
) -> State {
    if toggle != d.toggle {
        return abort(out, d.at, codes::TOGGLE);
    }
    d.data.extend_from_slice(data.bytes());
    if !last {
        out.frames.push(encode(&SdoCommand::DownloadSegmentResponse { toggle }));
        d.toggle = !toggle;
        return State::Download(d);
    }
    if d.size.is_some_and(|s| s as usize != d.data.len()) {
        return abort(out, d.at, codes::LENGTH_MISMATCH);
    }
    let confirmation = SdoCommand::DownloadSegmentResponse { toggle };
    write(d.at, &d.data, (Protocol::Segmented, confirmation), store, out)
}

/// Writes a downloaded value: confirms it with `confirmation` and reports it, or aborts
/// with the store's code.
fn write(
    at: Object,
    data: &[u8],
    (protocol, confirmation): (Protocol, SdoCommand),
    store: &mut dyn ObjectStore,
    out: &mut ServerOutput,
) -> State {
    let (index, sub) = at;
    match store.write(index, sub, data) {
        Ok(()) => {
            out.frames.push(encode(&confirmation));
            let len = data.len();
            out.event = Some(ServerEvent::Written {
                index,
                sub,
                protocol,
                len,
            });
            State::Idle
        }
        Err(code) => abort(out, at, code),
    }
}

// Expedited and segmented upload.

/// Answers an upload request expedited (up to 4 bytes) or starts a segmented one.
fn start_upload(at: Object, data: Vec<u8>, out: &mut ServerOutput) -> State {
    let (index, sub) = at;
    let len = data.len();
    let size = Some(len as u32);
    if (1..=4).contains(&len) {
        out.frames.push(encode(&SdoCommand::InitiateUploadResponse {
            index,
            sub,
            expedited: true,
            size,
            data: Chunk::new(&data, 4),
        }));
        let protocol = Protocol::Expedited;
        out.event = Some(ServerEvent::Read {
            index,
            sub,
            protocol,
            len,
        });
        return State::Idle;
    }
    out.frames.push(encode(&SdoCommand::InitiateUploadResponse {
        index,
        sub,
        expedited: false,
        size,
        data: Chunk::default(),
    }));
    State::Upload(Outgoing {
        at,
        data,
        pos: 0,
        toggle: false,
    })
}

/// One upload segment request: the next segment, and after the last one the read reported.
fn upload_segment(mut u: Outgoing, toggle: bool, out: &mut ServerOutput) -> State {
    if toggle != u.toggle {
        return abort(out, u.at, codes::TOGGLE);
    }
    let (chunk, end, last) = Chunk::segment(&u.data, u.pos);
    out.frames.push(encode(&SdoCommand::UploadSegmentResponse {
        toggle,
        last,
        data: chunk,
    }));
    if last {
        let ((index, sub), len) = (u.at, u.data.len());
        let protocol = Protocol::Segmented;
        out.event = Some(ServerEvent::Read {
            index,
            sub,
            protocol,
            len,
        });
        return State::Idle;
    }
    u.pos = end;
    u.toggle = !toggle;
    State::Upload(u)
}

// Block download.

/// One segment of a sub-block; acknowledges the sub-block at its end.
fn block_download_segment(mut b: BlockIn, (seqno, last, data): (u8, bool, Chunk), out: &mut ServerOutput) -> State {
    let mut done = false;
    if seqno == b.next {
        b.data.extend_from_slice(data.bytes());
        b.next += 1;
        done = last;
    }
    if last || seqno >= b.blksize {
        let (ackseq, blksize) = (b.next - 1, b.blksize);
        out.frames
            .push(encode(&SdoCommand::BlockDownloadAck { ackseq, blksize }));
        if done {
            return State::BlockDownloadEnd(b);
        }
        b.next = 1;
    }
    State::BlockDownload(b)
}

/// The end of a block download: the unused tail, CRC and size checked, the value written.
fn block_download_end(
    mut b: BlockIn,
    unused: u8,
    crc: u16,
    store: &mut dyn ObjectStore,
    out: &mut ServerOutput,
) -> State {
    let keep = b.data.len().saturating_sub(unused as usize);
    b.data.truncate(keep);
    if b.crc && crc16(&b.data) != crc {
        return abort(out, b.at, codes::CRC);
    }
    if b.size.is_some_and(|s| s as usize != b.data.len()) {
        return abort(out, b.at, codes::LENGTH_MISMATCH);
    }
    let confirmation = SdoCommand::BlockDownloadEndResponse;
    write(b.at, &b.data, (Protocol::Block, confirmation), store, out)
}

// Block upload.

/// The client acknowledged a sub-block: the next one, or the end.
fn block_upload_acked(b: BlockOut, ackseq: u8, blksize: u8, out: &mut ServerOutput) -> State {
    let BlockOut {
        at,
        crc,
        data,
        acked,
        sent,
    } = b;
    // Segments of the last sub-block (an empty value is still sent as one).
    let in_flight = (sent - acked).div_ceil(7).max(1);
    if ackseq as usize > in_flight {
        return abort(out, at, codes::SEQUENCE);
    }
    if !(1..=127).contains(&blksize) {
        return abort(out, at, codes::BLOCK_SIZE);
    }
    if sent == data.len() && ackseq as usize == in_flight {
        let unused = (data.len().div_ceil(7).max(1) * 7 - data.len()) as u8;
        let crc = if crc { crc16(&data) } else { 0 };
        out.frames.push(encode(&SdoCommand::BlockUploadEnd { unused, crc }));
        return State::BlockUploadEnd { at, len: data.len() };
    }
    let acked = (acked + ackseq as usize * 7).min(data.len());
    let sent = acked + send_sub_block(out, &data, acked, blksize);
    State::BlockUpload(BlockOut {
        at,
        crc,
        data,
        acked,
        sent,
    })
}

/// Sends up to `blksize` segments of `data` from `from`; returns the bytes sent.
fn send_sub_block(out: &mut ServerOutput, data: &[u8], from: usize, blksize: u8) -> usize {
    let (segments, sent) = sub_block(data, from, blksize);
    out.frames.extend(segments.iter().map(encode));
    sent
}

/// Adds an abort frame; the transfer ends.
fn abort(out: &mut ServerOutput, (index, sub): Object, code: u32) -> State {
    out.frames.push(encode(&SdoCommand::Abort { index, sub, code }));
    State::Idle
}
