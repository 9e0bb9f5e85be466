//! An SDO client as a pure state machine: one upload or download at a time,
//! expedited, segmented or block (with CRC and a configurable block size).
//! Frames from the server go in through [`SdoClient::on_frame`], time through
//! `now_ns` arguments; frames to send and the result come out.

use crate::decode::sdo::abort::{abort_text, codes};
use crate::decode::sdo::crc::crc16;
use crate::decode::sdo::frame::{Chunk, SdoCommand, Side, decode, encode, sub_block};
use crate::decode::sdo::transaction::Protocol;
use crate::od::{Dictionary, Value};
use std::fmt;

/// Client settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClientConfig {
    /// Abort with 0x05040000 when the server is silent this long.
    pub timeout_ns: u64,
    /// Block size asked for in block uploads (1..=127).
    pub block_size: u8,
    /// Ask for a CRC in block transfers.
    pub crc: bool,
}

impl Default for ClientConfig {
    fn default() -> Self {
        ClientConfig {
            timeout_ns: 1_000_000_000,
            block_size: 127,
            crc: true,
        }
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
    InitDownload {
        data: Vec<u8>,
        protocol: Protocol,
    },
    DownloadSegment {
        data: Vec<u8>,
        pos: usize,
        toggle: bool,
    },
    InitUpload,
    UploadSegment {
        data: Vec<u8>,
        size: Option<u32>,
        toggle: bool,
    },
    BlockDownloadInit {
        data: Vec<u8>,
    },
    BlockDownloadAck {
        data: Vec<u8>,
        crc: bool,
        acked: usize,
        sent: usize,
    },
    BlockDownloadEnd {
        len: usize,
    },
    BlockUploadInit,
    BlockUpload {
        data: Vec<u8>,
        crc: bool,
        size: Option<u32>,
        next: u8,
        sub_block: Vec<u8>,
        last: bool,
    },
    BlockUploadEnd {
        data: Vec<u8>,
        crc: bool,
        size: Option<u32>,
    },
}

/// An SDO client for one channel.
#[derive(Clone, Debug)]
pub struct SdoClient {
    cfg: ClientConfig,
    state: State,
    index: u16,
    sub: u8,
    deadline: u64,
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
        let size = Some(data.len() as u32);
        let (frame, state) = match mode {
            Mode::Auto if (1..=4).contains(&data.len()) => {
                let chunk = Chunk::new(&data, 4);
                let cmd = SdoCommand::InitiateDownload {
                    index,
                    sub,
                    expedited: true,
                    size,
                    data: chunk,
                };
                (
                    encode(&cmd),
                    State::InitDownload {
                        data,
                        protocol: Protocol::Expedited,
                    },
                )
            }
            Mode::Auto | Mode::Segmented => {
                let cmd = SdoCommand::InitiateDownload {
                    index,
                    sub,
                    expedited: false,
                    size,
                    data: Chunk::default(),
                };
                (
                    encode(&cmd),
                    State::InitDownload {
                        data,
                        protocol: Protocol::Segmented,
                    },
                )
            }
            Mode::Block => {
                let cmd = SdoCommand::BlockDownloadInitiate {
                    index,
                    sub,
                    crc: self.cfg.crc,
                    size,
                };
                (encode(&cmd), State::BlockDownloadInit { data })
            }
        };
        self.state = state;
        Ok(frame)
    }

    /// Aborts the running transfer with `code`; returns the abort frame and the failure.
    pub fn abort(&mut self, code: u32) -> ClientOutput {
        let mut out = ClientOutput::default();
        if self.is_busy() {
            self.fail(&mut out, code, SdoError::Cancelled { code });
        }
        out
    }

    /// Checks the timeout: past it, sends abort 0x05040000 and fails the transfer.
    pub fn poll(&mut self, now_ns: u64) -> ClientOutput {
        let mut out = ClientOutput::default();
        if self.is_busy() && now_ns >= self.deadline {
            self.fail(&mut out, codes::TIMEOUT, SdoError::Timeout);
        }
        out
    }

    /// Handles one frame from the server.
    pub fn on_frame(&mut self, payload: &[u8], now_ns: u64) -> ClientOutput {
        let mut out = ClientOutput::default();
        if !self.is_busy() {
            return out;
        }
        let in_segments = matches!(self.state, State::BlockUpload { .. });
        let cmd = decode(Side::Server, payload, in_segments);
        let state = std::mem::replace(&mut self.state, State::Idle);
        self.state = self.step(state, cmd, &mut out);
        self.deadline = now_ns.saturating_add(self.cfg.timeout_ns);
        out
    }

    fn begin(&mut self, index: u16, sub: u8, now_ns: u64) -> Result<(), Busy> {
        if self.is_busy() {
            return Err(Busy);
        }
        self.index = index;
        self.sub = sub;
        self.deadline = now_ns.saturating_add(self.cfg.timeout_ns);
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

    /// Moves from `state` on one server command.
    fn step(&self, state: State, cmd: SdoCommand, out: &mut ClientOutput) -> State {
        use SdoCommand as C;
        let (index, sub) = (self.index, self.sub);
        if let C::Abort { code, .. } = cmd {
            let error = SdoError::Aborted {
                code,
                text: abort_text(code),
            };
            out.done = Some(Completion::Failed { index, sub, error });
            return State::Idle;
        }
        let same = |i: u16, s: u8| (i, s) == (index, sub);
        match (state, cmd) {
            (State::InitDownload { data, protocol }, C::InitiateDownloadResponse { index: i, sub: s })
                if same(i, s) =>
            {
                if protocol == Protocol::Expedited {
                    out.done = Some(Completion::Downloaded {
                        index,
                        sub,
                        protocol,
                        len: data.len(),
                    });
                    return State::Idle;
                }
                self.send_download_segment(out, data, 0, false)
            }
            (
                State::DownloadSegment {
                    data,
                    pos,
                    toggle: want,
                },
                C::DownloadSegmentResponse { toggle },
            ) => {
                if toggle != want {
                    return self.protocol_error(out, codes::TOGGLE, "toggle bit not alternated".into());
                }
                if pos >= data.len() {
                    out.done = Some(Completion::Downloaded {
                        index,
                        sub,
                        protocol: Protocol::Segmented,
                        len: data.len(),
                    });
                    return State::Idle;
                }
                self.send_download_segment(out, data, pos, !toggle)
            }
            (
                State::InitUpload | State::BlockUploadInit,
                C::InitiateUploadResponse {
                    index: i,
                    sub: s,
                    expedited,
                    size,
                    data,
                },
            ) if same(i, s) => {
                if expedited {
                    let mut bytes = data.bytes().to_vec();
                    if let Some(n) = size {
                        bytes.truncate(n as usize);
                    }
                    out.done = Some(Completion::Uploaded {
                        index,
                        sub,
                        protocol: Protocol::Expedited,
                        data: bytes,
                    });
                    return State::Idle;
                }
                out.frames.push(encode(&C::UploadSegment { toggle: false }));
                State::UploadSegment {
                    data: Vec::new(),
                    size,
                    toggle: false,
                }
            }
            (
                State::UploadSegment {
                    mut data,
                    size,
                    toggle: want,
                },
                C::UploadSegmentResponse { toggle, last, data: d },
            ) => {
                if toggle != want {
                    return self.protocol_error(out, codes::TOGGLE, "toggle bit not alternated".into());
                }
                data.extend_from_slice(d.bytes());
                if !last {
                    out.frames.push(encode(&C::UploadSegment { toggle: !toggle }));
                    return State::UploadSegment {
                        data,
                        size,
                        toggle: !toggle,
                    };
                }
                if let Some(n) = size.filter(|n| *n as usize != data.len()) {
                    let reason = format!("server indicated {n} bytes but sent {}", data.len());
                    return self.protocol_error(out, codes::LENGTH_MISMATCH, reason);
                }
                out.done = Some(Completion::Uploaded {
                    index,
                    sub,
                    protocol: Protocol::Segmented,
                    data,
                });
                State::Idle
            }
            (
                State::BlockDownloadInit { data },
                C::BlockDownloadInitiateResponse {
                    index: i,
                    sub: s,
                    crc,
                    blksize,
                },
            ) if same(i, s) => {
                if !(1..=127).contains(&blksize) {
                    return self.protocol_error(out, codes::BLOCK_SIZE, format!("invalid block size {blksize}"));
                }
                let crc = crc && self.cfg.crc;
                let sent = send_sub_block(out, &data, 0, blksize);
                State::BlockDownloadAck {
                    data,
                    crc,
                    acked: 0,
                    sent,
                }
            }
            (State::BlockDownloadAck { data, crc, acked, sent }, C::BlockDownloadAck { ackseq, blksize }) => {
                // Segments of the last sub-block (an empty transfer still sends one).
                let in_flight = (sent - acked).div_ceil(7).max(1);
                if ackseq as usize > in_flight {
                    return self.protocol_error(
                        out,
                        codes::SEQUENCE,
                        format!("acknowledged segment {ackseq} not sent"),
                    );
                }
                if !(1..=127).contains(&blksize) {
                    return self.protocol_error(out, codes::BLOCK_SIZE, format!("invalid block size {blksize}"));
                }
                if sent == data.len() && ackseq as usize == in_flight {
                    let unused = (data.len().div_ceil(7).max(1) * 7 - data.len()) as u8;
                    let crc = if crc { crc16(&data) } else { 0 };
                    out.frames.push(encode(&C::BlockDownloadEnd { unused, crc }));
                    return State::BlockDownloadEnd { len: data.len() };
                }
                let acked = (acked + ackseq as usize * 7).min(data.len());
                let sent = acked + send_sub_block(out, &data, acked, blksize);
                State::BlockDownloadAck { data, crc, acked, sent }
            }
            (State::BlockDownloadEnd { len }, C::BlockDownloadEndResponse) => {
                out.done = Some(Completion::Downloaded {
                    index,
                    sub,
                    protocol: Protocol::Block,
                    len,
                });
                State::Idle
            }
            (
                State::BlockUploadInit,
                C::BlockUploadInitiateResponse {
                    index: i,
                    sub: s,
                    crc,
                    size,
                },
            ) if same(i, s) => {
                out.frames.push(encode(&C::BlockUploadStart));
                let crc = crc && self.cfg.crc;
                State::BlockUpload {
                    data: Vec::new(),
                    crc,
                    size,
                    next: 1,
                    sub_block: Vec::new(),
                    last: false,
                }
            }
            (
                State::BlockUpload {
                    mut data,
                    crc,
                    size,
                    next,
                    mut sub_block,
                    last,
                },
                C::BlockSegment {
                    seqno,
                    last: c,
                    data: d,
                },
            ) => {
                let mut next = next;
                let mut last = last;
                if seqno == next && !last {
                    sub_block.extend_from_slice(d.bytes());
                    next += 1;
                    last = c;
                }
                let blksize = self.cfg.block_size.clamp(1, 127);
                if c || seqno >= blksize {
                    out.frames.push(encode(&C::BlockUploadAck {
                        ackseq: next - 1,
                        blksize,
                    }));
                    data.append(&mut sub_block);
                    if last {
                        return State::BlockUploadEnd { data, crc, size };
                    }
                    next = 1;
                }
                State::BlockUpload {
                    data,
                    crc,
                    size,
                    next,
                    sub_block,
                    last,
                }
            }
            (State::BlockUploadEnd { mut data, crc, size }, C::BlockUploadEnd { unused, crc: sent }) => {
                let keep = data.len().saturating_sub(unused as usize);
                data.truncate(keep);
                if crc && crc16(&data) != sent {
                    return self.protocol_error(out, codes::CRC, "block CRC does not match the data".into());
                }
                if let Some(n) = size.filter(|n| *n as usize != data.len()) {
                    let reason = format!("server indicated {n} bytes but sent {}", data.len());
                    return self.protocol_error(out, codes::LENGTH_MISMATCH, reason);
                }
                out.frames.push(encode(&C::BlockUploadEndResponse));
                out.done = Some(Completion::Uploaded {
                    index,
                    sub,
                    protocol: Protocol::Block,
                    data,
                });
                State::Idle
            }
            (_, cmd) => {
                let reason = format!("unexpected {} frame from the server", cmd.cs_name());
                self.protocol_error(out, codes::UNKNOWN_COMMAND, reason)
            }
        }
    }

    /// Sends the download segment starting at `pos`.
    fn send_download_segment(&self, out: &mut ClientOutput, data: Vec<u8>, pos: usize, toggle: bool) -> State {
        let (chunk, end, last) = Chunk::segment(&data, pos);
        out.frames.push(encode(&SdoCommand::DownloadSegment {
            toggle,
            last,
            data: chunk,
        }));
        State::DownloadSegment { data, pos: end, toggle }
    }
}

/// Sends up to `blksize` block segments of `data` from `from`; returns the bytes sent.
fn send_sub_block(out: &mut ClientOutput, data: &[u8], from: usize, blksize: u8) -> usize {
    let (segments, sent) = sub_block(data, from, blksize);
    out.frames.extend(segments.iter().map(encode));
    sent
}
