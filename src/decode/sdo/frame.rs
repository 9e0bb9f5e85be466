//! The meaning of one SDO frame: command specifier, bit fields, index, data.
//!
//! Block transfer sub-block segments carry a sequence number where other
//! frames carry a command byte, so [`decode`] needs to know whether the
//! channel is inside a sub-block (the tracker knows).

use super::abort::abort_text;
use super::value::{ValueView, segment_text};
use crate::frame::hex;
use crate::frame::json::Hex;
use serde::Serialize;

/// Which end of an SDO channel sent a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The SDO client (master), COB-ID 0x600 + node by default.
    Client,
    /// The SDO server (the node's dictionary), COB-ID 0x580 + node by default.
    Server,
}

impl Side {
    /// `"client"` or `"server"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Client => "client",
            Side::Server => "server",
        }
    }
    /// The other end.
    pub fn other(self) -> Side {
        match self {
            Side::Client => Side::Server,
            Side::Server => Side::Client,
        }
    }
}

/// Up to seven payload bytes carried by one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Chunk {
    buf: [u8; 7],
    len: u8,
}

impl Chunk {
    /// The first `len` (at most 7) of `bytes`, or fewer when `bytes` is shorter.
    pub fn new(bytes: &[u8], len: usize) -> Chunk {
        let n = len.min(7).min(bytes.len());
        let mut buf = [0; 7];
        buf[..n].copy_from_slice(&bytes[..n]);
        Chunk { buf, len: n as u8 }
    }
    /// The bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.buf[..self.len as usize]
    }
    /// The segment of `data` starting at `pos` (up to 7 bytes), where it ends, and
    /// whether it is the last one.
    pub fn segment(data: &[u8], pos: usize) -> (Chunk, usize, bool) {
        let end = (pos + 7).min(data.len());
        (Chunk::new(&data[pos.min(end)..end], 7), end, end == data.len())
    }
}

/// The block-transfer segments of one sub-block: up to `blksize` segments of `data`
/// from `from`, numbered from 1; returns them and the bytes they carry.
pub fn sub_block(data: &[u8], from: usize, blksize: u8) -> (Vec<SdoCommand>, usize) {
    let mut segments = Vec::new();
    let mut pos = from;
    for seqno in 1..=blksize {
        let (chunk, end, last) = Chunk::segment(data, pos);
        segments.push(SdoCommand::BlockSegment {
            seqno,
            last,
            data: chunk,
        });
        pos = end;
        if last {
            break;
        }
    }
    (segments, pos - from)
}

/// One SDO frame's command and fields (CiA 301 section 7.2.4.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdoCommand {
    /// Client: initiate download (ccs=1). `size` is the indicated size (for
    /// expedited frames 4-n); `data` the expedited bytes.
    InitiateDownload {
        index: u16,
        sub: u8,
        expedited: bool,
        size: Option<u32>,
        data: Chunk,
    },
    /// Server: initiate download response (scs=3).
    InitiateDownloadResponse { index: u16, sub: u8 },
    /// Client: download segment (ccs=0).
    DownloadSegment { toggle: bool, last: bool, data: Chunk },
    /// Server: download segment response (scs=1).
    DownloadSegmentResponse { toggle: bool },
    /// Client: initiate upload (ccs=2).
    InitiateUpload { index: u16, sub: u8 },
    /// Server: initiate upload response (scs=2), expedited data or indicated size.
    InitiateUploadResponse {
        index: u16,
        sub: u8,
        expedited: bool,
        size: Option<u32>,
        data: Chunk,
    },
    /// Client: upload segment request (ccs=3).
    UploadSegment { toggle: bool },
    /// Server: upload segment response (scs=0).
    UploadSegmentResponse { toggle: bool, last: bool, data: Chunk },
    /// Either side: abort transfer (cs=4).
    Abort { index: u16, sub: u8, code: u32 },
    /// Client: initiate block download (ccs=6, cs=0).
    BlockDownloadInitiate {
        index: u16,
        sub: u8,
        crc: bool,
        size: Option<u32>,
    },
    /// Server: initiate block download response (scs=5, ss=0).
    BlockDownloadInitiateResponse {
        index: u16,
        sub: u8,
        crc: bool,
        blksize: u8,
    },
    /// Server: block download sub-block acknowledge (scs=5, ss=2).
    BlockDownloadAck { ackseq: u8, blksize: u8 },
    /// Client: end block download (ccs=6, cs=1) with unused bytes of the last segment and CRC.
    BlockDownloadEnd { unused: u8, crc: u16 },
    /// Server: end block download response (scs=5, ss=1).
    BlockDownloadEndResponse,
    /// Client: initiate block upload (ccs=5, cs=0) with blksize and protocol switch threshold.
    BlockUploadInitiate {
        index: u16,
        sub: u8,
        crc: bool,
        blksize: u8,
        pst: u8,
    },
    /// Server: initiate block upload response (scs=6, ss=0).
    BlockUploadInitiateResponse {
        index: u16,
        sub: u8,
        crc: bool,
        size: Option<u32>,
    },
    /// Client: start block upload (ccs=5, cs=3).
    BlockUploadStart,
    /// Client: block upload sub-block acknowledge (ccs=5, cs=2).
    BlockUploadAck { ackseq: u8, blksize: u8 },
    /// Server: end block upload (scs=6, ss=1) with unused bytes of the last segment and CRC.
    BlockUploadEnd { unused: u8, crc: u16 },
    /// Client: end block upload response (ccs=5, cs=1).
    BlockUploadEndResponse,
    /// A sub-block segment (client in a download, server in an upload).
    BlockSegment { seqno: u8, last: bool, data: Chunk },
    /// A command byte CiA 301 does not define for this side.
    Unknown { command: u8 },
}

impl SdoCommand {
    /// The JSON `cs` name; requests and responses share it.
    pub fn cs_name(&self) -> &'static str {
        use SdoCommand::*;
        match self {
            InitiateDownload { .. } | InitiateDownloadResponse { .. } => "initiate_download",
            DownloadSegment { .. } | DownloadSegmentResponse { .. } => "download_segment",
            InitiateUpload { .. } | InitiateUploadResponse { .. } => "initiate_upload",
            UploadSegment { .. } | UploadSegmentResponse { .. } => "upload_segment",
            Abort { .. } => "abort",
            BlockDownloadInitiate { .. }
            | BlockDownloadInitiateResponse { .. }
            | BlockDownloadAck { .. }
            | BlockDownloadEnd { .. }
            | BlockDownloadEndResponse => "block_download",
            BlockUploadInitiate { .. }
            | BlockUploadInitiateResponse { .. }
            | BlockUploadStart
            | BlockUploadAck { .. }
            | BlockUploadEnd { .. }
            | BlockUploadEndResponse => "block_upload",
            BlockSegment { .. } => "block_segment",
            Unknown { .. } => "unknown",
        }
    }

    /// The step within a block transfer (`initiate`, `start`, `ack`, `end`), for JSON.
    pub fn block_step(&self) -> Option<&'static str> {
        use SdoCommand::*;
        Some(match self {
            BlockDownloadInitiate { .. }
            | BlockDownloadInitiateResponse { .. }
            | BlockUploadInitiate { .. }
            | BlockUploadInitiateResponse { .. } => "initiate",
            BlockUploadStart => "start",
            BlockDownloadAck { .. } | BlockUploadAck { .. } => "ack",
            BlockDownloadEnd { .. } | BlockDownloadEndResponse | BlockUploadEnd { .. } | BlockUploadEndResponse => {
                "end"
            }
            _ => return None,
        })
    }

    /// The (index, sub) the frame itself carries.
    pub fn object(&self) -> Option<(u16, u8)> {
        use SdoCommand::*;
        match *self {
            InitiateDownload { index, sub, .. }
            | InitiateDownloadResponse { index, sub }
            | InitiateUpload { index, sub }
            | InitiateUploadResponse { index, sub, .. }
            | Abort { index, sub, .. }
            | BlockDownloadInitiate { index, sub, .. }
            | BlockDownloadInitiateResponse { index, sub, .. }
            | BlockUploadInitiate { index, sub, .. }
            | BlockUploadInitiateResponse { index, sub, .. } => Some((index, sub)),
            _ => None,
        }
    }

    /// Segment data bytes, or expedited data bytes.
    pub fn data(&self) -> Option<&[u8]> {
        use SdoCommand::*;
        match self {
            InitiateDownload {
                expedited: true, data, ..
            }
            | InitiateUploadResponse {
                expedited: true, data, ..
            } => Some(data.bytes()),
            DownloadSegment { data, .. } | UploadSegmentResponse { data, .. } | BlockSegment { data, .. } => {
                Some(data.bytes())
            }
            _ => None,
        }
    }
}

/// Decodes one SDO payload sent by `side`. `block_segments` tells that this
/// side is inside a block sub-block, so the first byte is `c | seqno`.
/// A short payload is decoded as if padded with zeros (data stops at the real end).
pub fn decode(side: Side, payload: &[u8], block_segments: bool) -> SdoCommand {
    let mut p = [0u8; 8];
    let n = payload.len().min(8);
    p[..n].copy_from_slice(&payload[..n]);
    let real = |from: usize, len: usize| Chunk::new(payload.get(from..).unwrap_or(&[]), len);
    let cmd = p[0];
    let index = u16::from_le_bytes([p[1], p[2]]);
    let sub = p[3];
    let d32 = u32::from_le_bytes([p[4], p[5], p[6], p[7]]);
    let toggle = cmd & 0x10 != 0;
    let last = cmd & 0x01 != 0;
    let seg_len = 7 - ((cmd >> 1) & 7) as usize;
    use SdoCommand::*;
    // Seqno 0 is not a valid block segment, so 0x80 inside a sub-block is an abort.
    if block_segments && cmd != 0x80 {
        return BlockSegment {
            seqno: cmd & 0x7F,
            last: cmd & 0x80 != 0,
            data: real(1, 7),
        };
    }
    match (side, cmd >> 5) {
        (_, 4) => Abort { index, sub, code: d32 },
        (Side::Client, 0) => DownloadSegment {
            toggle,
            last,
            data: real(1, seg_len),
        },
        (Side::Client, 1) => {
            let (expedited, sized) = (cmd & 2 != 0, cmd & 1 != 0);
            let unused = ((cmd >> 2) & 3) as usize;
            match (expedited, sized) {
                (true, true) => InitiateDownload {
                    index,
                    sub,
                    expedited,
                    size: Some(4 - unused as u32),
                    data: real(4, 4 - unused),
                },
                (true, false) => InitiateDownload {
                    index,
                    sub,
                    expedited,
                    size: None,
                    data: real(4, 4),
                },
                (false, true) => InitiateDownload {
                    index,
                    sub,
                    expedited,
                    size: Some(d32),
                    data: Chunk::default(),
                },
                (false, false) => InitiateDownload {
                    index,
                    sub,
                    expedited,
                    size: None,
                    data: Chunk::default(),
                },
            }
        }
        (Side::Client, 2) => InitiateUpload { index, sub },
        (Side::Client, 3) => UploadSegment { toggle },
        (Side::Client, 5) => match cmd & 3 {
            0 => BlockUploadInitiate {
                index,
                sub,
                crc: cmd & 4 != 0,
                blksize: p[4],
                pst: p[5],
            },
            1 => BlockUploadEndResponse,
            2 => BlockUploadAck {
                ackseq: p[1],
                blksize: p[2],
            },
            _ => BlockUploadStart,
        },
        (Side::Client, 6) => match cmd & 1 {
            0 => BlockDownloadInitiate {
                index,
                sub,
                crc: cmd & 4 != 0,
                size: (cmd & 2 != 0).then_some(d32),
            },
            _ => BlockDownloadEnd {
                unused: (cmd >> 2) & 7,
                crc: u16::from_le_bytes([p[1], p[2]]),
            },
        },
        (Side::Server, 0) => UploadSegmentResponse {
            toggle,
            last,
            data: real(1, seg_len),
        },
        (Side::Server, 1) => DownloadSegmentResponse { toggle },
        (Side::Server, 2) => {
            let (expedited, sized) = (cmd & 2 != 0, cmd & 1 != 0);
            let unused = ((cmd >> 2) & 3) as usize;
            match (expedited, sized) {
                (true, true) => InitiateUploadResponse {
                    index,
                    sub,
                    expedited,
                    size: Some(4 - unused as u32),
                    data: real(4, 4 - unused),
                },
                (true, false) => InitiateUploadResponse {
                    index,
                    sub,
                    expedited,
                    size: None,
                    data: real(4, 4),
                },
                (false, true) => InitiateUploadResponse {
                    index,
                    sub,
                    expedited,
                    size: Some(d32),
                    data: Chunk::default(),
                },
                (false, false) => InitiateUploadResponse {
                    index,
                    sub,
                    expedited,
                    size: None,
                    data: Chunk::default(),
                },
            }
        }
        (Side::Server, 3) => InitiateDownloadResponse { index, sub },
        (Side::Server, 5) => match cmd & 3 {
            0 => BlockDownloadInitiateResponse {
                index,
                sub,
                crc: cmd & 4 != 0,
                blksize: p[4],
            },
            1 => BlockDownloadEndResponse,
            2 => BlockDownloadAck {
                ackseq: p[1],
                blksize: p[2],
            },
            _ => Unknown { command: cmd },
        },
        (Side::Server, 6) => match cmd & 1 {
            0 => BlockUploadInitiateResponse {
                index,
                sub,
                crc: cmd & 4 != 0,
                size: (cmd & 2 != 0).then_some(d32),
            },
            _ => BlockUploadEnd {
                unused: (cmd >> 2) & 7,
                crc: u16::from_le_bytes([p[1], p[2]]),
            },
        },
        _ => Unknown { command: cmd },
    }
}

/// Builds the 8-byte payload of a command (the inverse of [`decode`]).
/// Unused bytes are zero; expedited data and segment data set `n` from their length.
pub fn encode(cmd: &SdoCommand) -> [u8; 8] {
    use SdoCommand::*;
    let mut p = [0u8; 8];
    let head = |p: &mut [u8; 8], c: u8, index: u16, sub: u8| {
        p[0] = c;
        p[1..3].copy_from_slice(&index.to_le_bytes());
        p[3] = sub;
    };
    let put32 = |p: &mut [u8; 8], v: u32| p[4..8].copy_from_slice(&v.to_le_bytes());
    let seg = |p: &mut [u8; 8], c: u8, data: &Chunk| {
        let d = data.bytes();
        p[0] = c | ((7 - d.len() as u8) << 1);
        p[1..1 + d.len()].copy_from_slice(d);
    };
    let initiate =
        |p: &mut [u8; 8], base: u8, index: u16, sub: u8, expedited: bool, size: Option<u32>, data: &Chunk| {
            if expedited {
                let d = data.bytes();
                let sized = if size.is_some() {
                    0x01 | ((4 - d.len().min(4) as u8) << 2)
                } else {
                    0
                };
                head(p, base | 0x02 | sized, index, sub);
                p[4..4 + d.len().min(4)].copy_from_slice(&d[..d.len().min(4)]);
            } else {
                head(p, base | size.is_some() as u8, index, sub);
                put32(p, size.unwrap_or(0));
            }
        };
    match cmd {
        InitiateDownload {
            index,
            sub,
            expedited,
            size,
            data,
        } => initiate(&mut p, 0x20, *index, *sub, *expedited, *size, data),
        InitiateDownloadResponse { index, sub } => head(&mut p, 0x60, *index, *sub),
        DownloadSegment { toggle, last, data } => seg(&mut p, (*toggle as u8) << 4 | *last as u8, data),
        DownloadSegmentResponse { toggle } => p[0] = 0x20 | (*toggle as u8) << 4,
        InitiateUpload { index, sub } => head(&mut p, 0x40, *index, *sub),
        InitiateUploadResponse {
            index,
            sub,
            expedited,
            size,
            data,
        } => initiate(&mut p, 0x40, *index, *sub, *expedited, *size, data),
        UploadSegment { toggle } => p[0] = 0x60 | (*toggle as u8) << 4,
        UploadSegmentResponse { toggle, last, data } => seg(&mut p, (*toggle as u8) << 4 | *last as u8, data),
        Abort { index, sub, code } => {
            head(&mut p, 0x80, *index, *sub);
            put32(&mut p, *code);
        }
        BlockDownloadInitiate { index, sub, crc, size } => {
            head(
                &mut p,
                0xC0 | (*crc as u8) << 2 | (size.is_some() as u8) << 1,
                *index,
                *sub,
            );
            put32(&mut p, size.unwrap_or(0));
        }
        BlockDownloadInitiateResponse {
            index,
            sub,
            crc,
            blksize,
        } => {
            head(&mut p, 0xA0 | (*crc as u8) << 2, *index, *sub);
            p[4] = *blksize;
        }
        BlockDownloadAck { ackseq, blksize } | BlockUploadAck { ackseq, blksize } => {
            p[0] = 0xA2;
            p[1] = *ackseq;
            p[2] = *blksize;
        }
        BlockDownloadEnd { unused, crc } | BlockUploadEnd { unused, crc } => {
            p[0] = 0xC1 | (unused & 7) << 2;
            p[1..3].copy_from_slice(&crc.to_le_bytes());
        }
        BlockDownloadEndResponse | BlockUploadEndResponse => p[0] = 0xA1,
        BlockUploadInitiate {
            index,
            sub,
            crc,
            blksize,
            pst,
        } => {
            head(&mut p, 0xA0 | (*crc as u8) << 2, *index, *sub);
            p[4] = *blksize;
            p[5] = *pst;
        }
        BlockUploadInitiateResponse { index, sub, crc, size } => {
            head(
                &mut p,
                0xC0 | (*crc as u8) << 2 | (size.is_some() as u8) << 1,
                *index,
                *sub,
            );
            put32(&mut p, size.unwrap_or(0));
        }
        BlockUploadStart => p[0] = 0xA3,
        BlockSegment { seqno, last, data } => {
            p[0] = (seqno & 0x7F) | (*last as u8) << 7;
            p[1..1 + data.bytes().len()].copy_from_slice(data.bytes());
        }
        Unknown { command } => p[0] = *command,
    }
    p
}

/// One decoded SDO frame with what the tracker and dictionary add to it.
#[derive(Clone, Debug, PartialEq)]
pub struct SdoFrame {
    /// Who sent it.
    pub side: Side,
    /// The command and its fields.
    pub command: SdoCommand,
    /// The raw payload (up to 8 bytes; longer CAN FD payloads are cut to 8).
    pub raw: Chunk8,
    /// Why the frame is malformed (unknown command, DLC other than 8), if it is.
    pub malformed_reason: Option<String>,
    /// The object of the transfer the frame belongs to (from the frame or the tracker).
    pub object: Option<(u16, u8)>,
    /// The dictionary name of `object`.
    pub name: Option<String>,
    /// The typed value of expedited data.
    pub value: Option<ValueView>,
    /// Problems the tracker saw in this frame (toggle error, unmatched response...).
    pub problems: Vec<String>,
}

/// The first eight payload bytes of a frame and their count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Chunk8 {
    buf: [u8; 8],
    len: u8,
}

impl Chunk8 {
    /// Up to eight bytes of `bytes`.
    pub fn new(bytes: &[u8]) -> Chunk8 {
        let n = bytes.len().min(8);
        let mut buf = [0; 8];
        buf[..n].copy_from_slice(&bytes[..n]);
        Chunk8 { buf, len: n as u8 }
    }
    /// The bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.buf[..self.len as usize]
    }
}

impl SdoFrame {
    /// A frame decoded without dictionary or tracker context.
    pub fn new(side: Side, payload: &[u8], block_segments: bool) -> SdoFrame {
        let command = decode(side, payload, block_segments);
        let mut malformed = Vec::new();
        if let SdoCommand::Unknown { command } = command {
            malformed.push(format!("unknown {} command specifier 0x{command:02X}", side.as_str()));
        }
        if payload.len() != 8 {
            malformed.push(format!("DLC {}, expected 8", payload.len()));
        }
        SdoFrame {
            side,
            command,
            raw: Chunk8::new(payload),
            malformed_reason: (!malformed.is_empty()).then(|| malformed.join("; ")),
            object: command.object(),
            name: None,
            value: None,
            problems: Vec::new(),
        }
    }

    /// Why the frame is malformed (unknown command specifier, DLC other than 8), if it is.
    pub fn malformed(&self) -> Option<String> {
        self.malformed_reason.clone()
    }

    /// The object as `0x6040:00` plus its name when known.
    fn object_text(&self) -> String {
        let Some((index, sub)) = self.object else {
            return String::new();
        };
        match &self.name {
            Some(name) => format!(" 0x{index:04X}:{sub:02X} {name}"),
            None => format!(" 0x{index:04X}:{sub:02X}"),
        }
    }

    /// The value part of an expedited label: ` = 6 (Shutdown)`.
    fn value_text(&self) -> String {
        self.value
            .as_ref()
            .map(|v| format!(" = {}", v.text))
            .unwrap_or_default()
    }

    /// One-line label, e.g. `Download 0x6040:00 Controlword = 6 (Shutdown)`, with tracker
    /// problems in brackets. Malformation is reported by [`SdoFrame::malformed`], not here.
    pub fn label(&self) -> String {
        use SdoCommand::*;
        let obj = self.object_text();
        let mut s = match self.command {
            InitiateDownload { expedited: true, .. } => format!("Download{obj}{}", self.value_text()),
            InitiateDownload { size, .. } => format!("Download{obj} ({})", segmented_size(size)),
            InitiateDownloadResponse { .. } => format!("Download response{obj}"),
            DownloadSegment { toggle, last, data } => {
                format!(
                    "Download segment t={} {} c={}",
                    toggle as u8,
                    segment_text(data.bytes()),
                    last as u8
                )
            }
            DownloadSegmentResponse { toggle } => format!("Download segment response t={}", toggle as u8),
            InitiateUpload { .. } => format!("Upload{obj}"),
            InitiateUploadResponse { expedited: true, .. } => format!("Upload response{obj}{}", self.value_text()),
            InitiateUploadResponse { size, .. } => format!("Upload response{obj} ({})", segmented_size(size)),
            UploadSegment { toggle } => format!("Upload segment request t={}", toggle as u8),
            UploadSegmentResponse { toggle, last, data } => {
                format!(
                    "Upload segment t={} {} c={}",
                    toggle as u8,
                    segment_text(data.bytes()),
                    last as u8
                )
            }
            Abort { code, .. } => format!("Abort{obj}: 0x{code:08X} {}", abort_text(code)),
            BlockDownloadInitiate { crc, size, .. } => format!("Block download{obj} ({})", block_opts(crc, size)),
            BlockDownloadInitiateResponse { crc, blksize, .. } => {
                format!(
                    "Block download response{obj} blksize={blksize}{}",
                    if crc { " (crc)" } else { "" }
                )
            }
            BlockDownloadAck { ackseq, blksize } => format!("Block download ack ackseq={ackseq} blksize={blksize}"),
            BlockDownloadEnd { unused, crc } => format!("Block download end n={unused} crc=0x{crc:04X}"),
            BlockDownloadEndResponse => "Block download end response".to_string(),
            BlockUploadInitiate { crc, blksize, pst, .. } => {
                format!(
                    "Block upload{obj} blksize={blksize} pst={pst}{}",
                    if crc { " (crc)" } else { "" }
                )
            }
            BlockUploadInitiateResponse { crc, size, .. } => {
                format!("Block upload response{obj} ({})", block_opts(crc, size))
            }
            BlockUploadStart => "Block upload start".to_string(),
            BlockUploadAck { ackseq, blksize } => format!("Block upload ack ackseq={ackseq} blksize={blksize}"),
            BlockUploadEnd { unused, crc } => format!("Block upload end n={unused} crc=0x{crc:04X}"),
            BlockUploadEndResponse => "Block upload end response".to_string(),
            BlockSegment { seqno, last, .. } => {
                let dir = if self.side == Side::Client {
                    "download"
                } else {
                    "upload"
                };
                format!("Block {dir} segment seqno={seqno}{}", if last { " last" } else { "" })
            }
            Unknown { command } => format!("Unknown SDO command 0x{command:02X}: {}", hex::spaced(self.raw.bytes())),
        };
        for p in &self.problems {
            s.push_str(" [");
            s.push_str(p);
            s.push(']');
        }
        s
    }

    /// The `sdo` object of the frame's JSONL record: `cs`, `side`, `index`, `sub`,
    /// `abort_code`, `abort_text`, `malformed` and the decoded fields (`expedited`, `size`,
    /// `toggle`, `last`, `data`, `seqno`, `ackseq`, `blksize`, `pst`, `crc_supported`,
    /// `unused`, `crc`, `block_step`, `name`, `value`, `value_text`, `problems`).
    /// `index`/`sub` are the frame's own or, for segments and block steps, those of the
    /// transfer the tracker puts the frame in (null when unknown).
    pub fn to_json(&self) -> SdoJson<'_> {
        use SdoCommand::*;
        let mut j = SdoJson {
            abort_code: None,
            abort_text: None,
            ackseq: None,
            blksize: None,
            block_step: self.command.block_step(),
            command: None,
            crc: None,
            crc_supported: None,
            cs: self.command.cs_name(),
            data: None,
            expedited: None,
            index: self.object.map(|o| o.0),
            last: None,
            malformed: self.malformed_reason.is_some(),
            malformed_reason: self.malformed_reason.as_deref(),
            name: self.name.as_deref(),
            problems: (!self.problems.is_empty()).then_some(&self.problems),
            pst: None,
            seqno: None,
            side: self.side.as_str(),
            size: None,
            sub: self.object.map(|o| o.1),
            toggle: None,
            unused: None,
            value: self.value.as_ref().map(|v| &v.json),
            value_text: self.value.as_ref().map(|v| v.text.as_str()),
        };
        match &self.command {
            Abort { code, .. } => {
                j.abort_code = Some(*code);
                j.abort_text = Some(abort_text(*code));
            }
            InitiateDownload { expedited, size, .. } | InitiateUploadResponse { expedited, size, .. } => {
                j.expedited = Some(*expedited);
                j.size = Some(*size);
            }
            DownloadSegment { toggle, last, data } | UploadSegmentResponse { toggle, last, data } => {
                j.toggle = Some(*toggle as u8);
                j.last = Some(*last);
                j.data = Some(Hex(data.bytes()));
            }
            DownloadSegmentResponse { toggle } | UploadSegment { toggle } => j.toggle = Some(*toggle as u8),
            BlockDownloadInitiate { crc, size, .. } | BlockUploadInitiateResponse { crc, size, .. } => {
                j.crc_supported = Some(*crc);
                j.size = Some(*size);
            }
            BlockDownloadInitiateResponse { crc, blksize, .. } => {
                j.crc_supported = Some(*crc);
                j.blksize = Some(*blksize);
            }
            BlockUploadInitiate { crc, blksize, pst, .. } => {
                j.crc_supported = Some(*crc);
                j.blksize = Some(*blksize);
                j.pst = Some(*pst);
            }
            BlockDownloadAck { ackseq, blksize } | BlockUploadAck { ackseq, blksize } => {
                j.ackseq = Some(*ackseq);
                j.blksize = Some(*blksize);
            }
            BlockDownloadEnd { unused, crc } | BlockUploadEnd { unused, crc } => {
                j.unused = Some(*unused);
                j.crc = Some(*crc);
            }
            BlockSegment { seqno, last, data } => {
                j.seqno = Some(*seqno);
                j.last = Some(*last);
                j.data = Some(Hex(data.bytes()));
            }
            Unknown { command } => j.command = Some(*command),
            _ => {}
        }
        if let Some(data) = self.command.data().filter(|_| self.value.is_some()) {
            j.data = Some(Hex(data));
        }
        j
    }
}

/// The `sdo` object of a JSONL frame record, fields in key order. `abort_code`,
/// `abort_text`, `cs`, `index`, `malformed`, `side` and `sub` are always there (null when
/// they do not apply); the others only when the command carries them.
#[derive(Clone, Debug, Serialize)]
pub struct SdoJson<'a> {
    pub abort_code: Option<u32>,
    pub abort_text: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ackseq: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blksize: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block_step: Option<&'static str>,
    /// The command byte of an unknown command.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crc: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crc_supported: Option<bool>,
    pub cs: &'static str,
    /// Segment data, or the expedited data when it has a value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub data: Option<Hex<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expedited: Option<bool>,
    pub index: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub last: Option<bool>,
    pub malformed: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub malformed_reason: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problems: Option<&'a Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pst: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seqno: Option<u8>,
    pub side: &'static str,
    /// Present (null when not indicated) for the commands that can indicate a size.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size: Option<Option<u32>>,
    pub sub: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub toggle: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unused: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<&'a serde_json::Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value_text: Option<&'a str>,
}

/// `segmented, 16 bytes` or `segmented, size not indicated`.
fn segmented_size(size: Option<u32>) -> String {
    match size {
        Some(n) => format!("segmented, {n} bytes"),
        None => "segmented, size not indicated".to_string(),
    }
}

/// `crc, 1000 bytes`, `no crc, size not indicated`...
fn block_opts(crc: bool, size: Option<u32>) -> String {
    let crc = if crc { "crc" } else { "no crc" };
    match size {
        Some(n) => format!("{crc}, {n} bytes"),
        None => format!("{crc}, size not indicated"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use SdoCommand::*;

    fn client(bytes: &[u8]) -> SdoCommand {
        decode(Side::Client, bytes, false)
    }
    fn server(bytes: &[u8]) -> SdoCommand {
        decode(Side::Server, bytes, false)
    }
    fn chunk(b: &[u8]) -> Chunk {
        Chunk::new(b, b.len())
    }

    #[test]
    fn initiate_download_all_forms() {
        assert_eq!(
            client(&[0x2F, 0x60, 0x60, 0x00, 0x03, 0, 0, 0]),
            InitiateDownload {
                index: 0x6060,
                sub: 0,
                expedited: true,
                size: Some(1),
                data: chunk(&[3])
            }
        );
        assert_eq!(
            client(&[0x2B, 0x03, 0x30, 0x01, 0xB8, 0x0B, 0, 0]),
            InitiateDownload {
                index: 0x3003,
                sub: 1,
                expedited: true,
                size: Some(2),
                data: chunk(&[0xB8, 0x0B])
            }
        );
        assert_eq!(
            client(&[0x27, 0x00, 0x20, 0x00, 1, 2, 3, 0]),
            InitiateDownload {
                index: 0x2000,
                sub: 0,
                expedited: true,
                size: Some(3),
                data: chunk(&[1, 2, 3])
            }
        );
        assert_eq!(
            client(&[0x23, 0x83, 0x60, 0x00, 0xE8, 0x03, 0, 0]),
            InitiateDownload {
                index: 0x6083,
                sub: 0,
                expedited: true,
                size: Some(4),
                data: chunk(&[0xE8, 0x03, 0, 0])
            }
        );
        // e=1, s=0: four bytes, size not indicated.
        assert_eq!(
            client(&[0x22, 0x40, 0x60, 0x00, 6, 0, 0, 0]),
            InitiateDownload {
                index: 0x6040,
                sub: 0,
                expedited: true,
                size: None,
                data: chunk(&[6, 0, 0, 0])
            }
        );
        // Normal transfer with size.
        assert_eq!(
            client(&[0x21, 0x08, 0x10, 0x00, 16, 0, 0, 0]),
            InitiateDownload {
                index: 0x1008,
                sub: 0,
                expedited: false,
                size: Some(16),
                data: Chunk::default()
            }
        );
        assert_eq!(
            client(&[0x20, 0x08, 0x10, 0x00, 0, 0, 0, 0]),
            InitiateDownload {
                index: 0x1008,
                sub: 0,
                expedited: false,
                size: None,
                data: Chunk::default()
            }
        );
        assert_eq!(
            server(&[0x60, 0x03, 0x30, 0x01, 0, 0, 0, 0]),
            InitiateDownloadResponse { index: 0x3003, sub: 1 }
        );
    }

    #[test]
    fn segments_with_toggle_n_and_c() {
        assert_eq!(
            client(&[0x00, 1, 2, 3, 4, 5, 6, 7]),
            DownloadSegment {
                toggle: false,
                last: false,
                data: chunk(&[1, 2, 3, 4, 5, 6, 7])
            }
        );
        assert_eq!(
            client(&[0x1B, b'a', b'b', 0, 0, 0, 0, 0]),
            DownloadSegment {
                toggle: true,
                last: true,
                data: chunk(b"ab")
            }
        );
        assert_eq!(
            server(&[0x20, 0, 0, 0, 0, 0, 0, 0]),
            DownloadSegmentResponse { toggle: false }
        );
        assert_eq!(
            server(&[0x30, 0, 0, 0, 0, 0, 0, 0]),
            DownloadSegmentResponse { toggle: true }
        );
        assert_eq!(
            client(&[0x40, 0x08, 0x10, 0, 0, 0, 0, 0]),
            InitiateUpload { index: 0x1008, sub: 0 }
        );
        assert_eq!(client(&[0x60, 0, 0, 0, 0, 0, 0, 0]), UploadSegment { toggle: false });
        assert_eq!(client(&[0x70, 0, 0, 0, 0, 0, 0, 0]), UploadSegment { toggle: true });
        assert_eq!(
            server(&[0x0B, 0x20, 0x20, 0, 0, 0, 0, 0]),
            UploadSegmentResponse {
                toggle: false,
                last: true,
                data: chunk(b"  ")
            }
        );
        assert_eq!(
            server(&[0x10, 1, 2, 3, 4, 5, 6, 7]),
            UploadSegmentResponse {
                toggle: true,
                last: false,
                data: chunk(&[1, 2, 3, 4, 5, 6, 7])
            }
        );
    }

    #[test]
    fn initiate_upload_responses() {
        assert_eq!(
            server(&[0x4B, 0x00, 0x30, 0x0A, 0x6E, 0x09, 0, 0]),
            InitiateUploadResponse {
                index: 0x3000,
                sub: 0x0A,
                expedited: true,
                size: Some(2),
                data: chunk(&[0x6E, 0x09])
            }
        );
        assert_eq!(
            server(&[0x4F, 0x61, 0x60, 0, 0xFA, 0, 0, 0]),
            InitiateUploadResponse {
                index: 0x6061,
                sub: 0,
                expedited: true,
                size: Some(1),
                data: chunk(&[0xFA])
            }
        );
        assert_eq!(
            server(&[0x47, 0x00, 0x20, 0, 1, 2, 3, 9]),
            InitiateUploadResponse {
                index: 0x2000,
                sub: 0,
                expedited: true,
                size: Some(3),
                data: chunk(&[1, 2, 3])
            }
        );
        assert_eq!(
            server(&[0x43, 0x00, 0x10, 0, 0x92, 0x01, 0x02, 0x00]),
            InitiateUploadResponse {
                index: 0x1000,
                sub: 0,
                expedited: true,
                size: Some(4),
                data: chunk(&[0x92, 1, 2, 0])
            }
        );
        assert_eq!(
            server(&[0x42, 0x00, 0x10, 0, 1, 2, 3, 4]),
            InitiateUploadResponse {
                index: 0x1000,
                sub: 0,
                expedited: true,
                size: None,
                data: chunk(&[1, 2, 3, 4])
            }
        );
        assert_eq!(
            server(&[0x41, 0x82, 0x30, 0x00, 0x10, 0, 0, 0]),
            InitiateUploadResponse {
                index: 0x3082,
                sub: 0,
                expedited: false,
                size: Some(16),
                data: Chunk::default()
            }
        );
        assert_eq!(
            server(&[0x40, 0x82, 0x30, 0x00, 0, 0, 0, 0]),
            InitiateUploadResponse {
                index: 0x3082,
                sub: 0,
                expedited: false,
                size: None,
                data: Chunk::default()
            }
        );
    }

    #[test]
    fn abort_from_both_sides() {
        let f = [0x80, 0x41, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06];
        assert_eq!(
            client(&f),
            Abort {
                index: 0x6041,
                sub: 0,
                code: 0x0602_0000
            }
        );
        assert_eq!(
            server(&f),
            Abort {
                index: 0x6041,
                sub: 0,
                code: 0x0602_0000
            }
        );
        let frame = SdoFrame::new(Side::Server, &f, false);
        assert_eq!(
            frame.label(),
            "Abort 0x6041:00: 0x06020000 Object does not exist in the object dictionary"
        );
        let j = serde_json::to_value(frame.to_json()).unwrap();
        assert_eq!(j["cs"], "abort");
        assert_eq!(j["abort_code"], 0x0602_0000);
        assert_eq!(j["abort_text"], "Object does not exist in the object dictionary");
        assert_eq!(j["index"], 0x6041);
        assert_eq!(j["sub"], 0);
    }

    #[test]
    fn block_download_commands() {
        assert_eq!(
            client(&[0xC6, 0x50, 0x1F, 0x01, 0xE8, 0x03, 0, 0]),
            BlockDownloadInitiate {
                index: 0x1F50,
                sub: 1,
                crc: true,
                size: Some(1000)
            }
        );
        assert_eq!(
            client(&[0xC0, 0x50, 0x1F, 0x01, 0, 0, 0, 0]),
            BlockDownloadInitiate {
                index: 0x1F50,
                sub: 1,
                crc: false,
                size: None
            }
        );
        assert_eq!(
            server(&[0xA4, 0x50, 0x1F, 0x01, 0x7F, 0, 0, 0]),
            BlockDownloadInitiateResponse {
                index: 0x1F50,
                sub: 1,
                crc: true,
                blksize: 127
            }
        );
        assert_eq!(
            server(&[0xA2, 0x05, 0x10, 0, 0, 0, 0, 0]),
            BlockDownloadAck { ackseq: 5, blksize: 16 }
        );
        assert_eq!(
            client(&[0xC9, 0x34, 0x12, 0, 0, 0, 0, 0]),
            BlockDownloadEnd { unused: 2, crc: 0x1234 }
        );
        assert_eq!(server(&[0xA1, 0, 0, 0, 0, 0, 0, 0]), BlockDownloadEndResponse);
        assert_eq!(
            decode(Side::Client, &[0x83, 1, 2, 3, 4, 5, 6, 7], true),
            BlockSegment {
                seqno: 3,
                last: true,
                data: chunk(&[1, 2, 3, 4, 5, 6, 7])
            }
        );
        let f = SdoFrame::new(Side::Client, &[0x03, 1, 2, 3, 4, 5, 6, 7], true);
        assert_eq!(f.label(), "Block download segment seqno=3");
        assert_eq!(serde_json::to_value(f.to_json()).unwrap()["cs"], "block_segment");
        assert_eq!(serde_json::to_value(f.to_json()).unwrap()["seqno"], 3);
        // Inside a sub-block 0x80 (seqno 0) can only be an abort.
        assert_eq!(
            decode(Side::Client, &[0x80, 0, 0, 0, 0, 0, 4, 5], true),
            Abort {
                index: 0,
                sub: 0,
                code: 0x0504_0000
            }
        );
    }

    #[test]
    fn block_upload_commands() {
        assert_eq!(
            client(&[0xA4, 0x08, 0x10, 0x00, 0x7F, 0x00, 0, 0]),
            BlockUploadInitiate {
                index: 0x1008,
                sub: 0,
                crc: true,
                blksize: 127,
                pst: 0
            }
        );
        assert_eq!(
            server(&[0xC6, 0x08, 0x10, 0x00, 0x10, 0, 0, 0]),
            BlockUploadInitiateResponse {
                index: 0x1008,
                sub: 0,
                crc: true,
                size: Some(16)
            }
        );
        assert_eq!(client(&[0xA3, 0, 0, 0, 0, 0, 0, 0]), BlockUploadStart);
        assert_eq!(
            client(&[0xA2, 0x03, 0x7F, 0, 0, 0, 0, 0]),
            BlockUploadAck {
                ackseq: 3,
                blksize: 127
            }
        );
        assert_eq!(
            server(&[0xD5, 0xCD, 0xAB, 0, 0, 0, 0, 0]),
            BlockUploadEnd { unused: 5, crc: 0xABCD }
        );
        assert_eq!(client(&[0xA1, 0, 0, 0, 0, 0, 0, 0]), BlockUploadEndResponse);
        let f = SdoFrame::new(Side::Server, &[0x01, 1, 2, 3, 4, 5, 6, 7], true);
        assert_eq!(f.label(), "Block upload segment seqno=1");
    }

    #[test]
    fn unknown_commands_are_malformed_not_dropped() {
        // Syn-tron dual-axis read/write (vendor commands 0xE8/0xE9).
        let f = SdoFrame::new(Side::Client, &[0xE8, 0x04, 0x50, 0x00, 0, 0, 0, 0], false);
        assert_eq!(f.command, Unknown { command: 0xE8 });
        assert!(f.malformed().is_some());
        assert_eq!(f.label(), "Unknown SDO command 0xE8: E8 04 50 00 00 00 00 00");
        assert_eq!(f.malformed().as_deref(), Some("unknown client command specifier 0xE8"));
        assert_eq!(serde_json::to_value(f.to_json()).unwrap()["cs"], "unknown");
        assert_eq!(serde_json::to_value(f.to_json()).unwrap()["malformed"], true);
        assert_eq!(
            server(&[0xE8, 0x04, 0x50, 0, 0xB7, 0x13, 0xAB, 0x12]),
            Unknown { command: 0xE8 }
        );
        assert_eq!(server(&[0xA3, 0, 0, 0, 0, 0, 0, 0]), Unknown { command: 0xA3 });
        assert_eq!(server(&[0xE0, 0, 0, 0, 0, 0, 0, 0]), Unknown { command: 0xE0 });
        assert_eq!(
            client(&[0xE9, 0x18, 0x23, 0, 0x36, 0, 0xCA, 0xFF]),
            Unknown { command: 0xE9 }
        );
    }

    #[test]
    fn wrong_dlc_is_flagged_but_decoded() {
        let f = SdoFrame::new(Side::Client, &[0x40, 0x41, 0x60], false);
        assert_eq!(f.command, InitiateUpload { index: 0x6041, sub: 0 });
        assert_eq!(f.malformed_reason.as_deref(), Some("DLC 3, expected 8"));
        assert_eq!(f.label(), "Upload 0x6041:00");
        // Expedited data stops where the payload does.
        assert_eq!(
            client(&[0x23, 0x83, 0x60, 0x00, 0xE8]),
            InitiateDownload {
                index: 0x6083,
                sub: 0,
                expedited: true,
                size: Some(4),
                data: chunk(&[0xE8])
            }
        );
        assert_eq!(
            client(&[]),
            DownloadSegment {
                toggle: false,
                last: false,
                data: Chunk::default()
            }
        );
    }

    #[test]
    fn segment_labels_show_text_or_hex() {
        let f = SdoFrame::new(Side::Server, &[0x10, b'D', b'E', b'X', b'M', b'A', b'R', b'T'], false);
        assert_eq!(f.label(), "Upload segment t=1 \"DEXMART\" c=0");
        let f = SdoFrame::new(Side::Client, &[0x01, 0xFF, 0x00, 0x10, 0, 0, 0, 0], false);
        assert_eq!(f.label(), "Download segment t=0 FF 00 10 00 00 00 00 c=1");
        assert_eq!(serde_json::to_value(f.to_json()).unwrap()["toggle"], 0);
        assert_eq!(serde_json::to_value(f.to_json()).unwrap()["last"], true);
    }

    #[test]
    fn encode_is_the_inverse_of_decode() {
        let d = chunk(&[1, 2, 3]);
        let cases: Vec<(Side, bool, SdoCommand)> = vec![
            (
                Side::Client,
                false,
                InitiateDownload {
                    index: 0x6040,
                    sub: 0,
                    expedited: true,
                    size: Some(3),
                    data: d,
                },
            ),
            (
                Side::Client,
                false,
                InitiateDownload {
                    index: 0x6040,
                    sub: 0,
                    expedited: true,
                    size: None,
                    data: chunk(&[1, 2, 3, 4]),
                },
            ),
            (
                Side::Client,
                false,
                InitiateDownload {
                    index: 0x1008,
                    sub: 0,
                    expedited: false,
                    size: Some(99),
                    data: Chunk::default(),
                },
            ),
            (Side::Server, false, InitiateDownloadResponse { index: 0x1008, sub: 2 }),
            (
                Side::Client,
                false,
                DownloadSegment {
                    toggle: true,
                    last: true,
                    data: d,
                },
            ),
            (Side::Server, false, DownloadSegmentResponse { toggle: true }),
            (Side::Client, false, InitiateUpload { index: 0x1018, sub: 4 }),
            (
                Side::Server,
                false,
                InitiateUploadResponse {
                    index: 0x1018,
                    sub: 4,
                    expedited: true,
                    size: Some(3),
                    data: d,
                },
            ),
            (
                Side::Server,
                false,
                InitiateUploadResponse {
                    index: 0x1018,
                    sub: 4,
                    expedited: false,
                    size: None,
                    data: Chunk::default(),
                },
            ),
            (Side::Client, false, UploadSegment { toggle: true }),
            (
                Side::Server,
                false,
                UploadSegmentResponse {
                    toggle: false,
                    last: true,
                    data: d,
                },
            ),
            (
                Side::Server,
                false,
                Abort {
                    index: 0x1000,
                    sub: 0,
                    code: 0x0504_0001,
                },
            ),
            (
                Side::Client,
                false,
                BlockDownloadInitiate {
                    index: 0x1F50,
                    sub: 1,
                    crc: true,
                    size: Some(900),
                },
            ),
            (
                Side::Server,
                false,
                BlockDownloadInitiateResponse {
                    index: 0x1F50,
                    sub: 1,
                    crc: false,
                    blksize: 9,
                },
            ),
            (Side::Server, false, BlockDownloadAck { ackseq: 4, blksize: 9 }),
            (Side::Client, false, BlockDownloadEnd { unused: 6, crc: 0xBEEF }),
            (Side::Server, false, BlockDownloadEndResponse),
            (
                Side::Client,
                false,
                BlockUploadInitiate {
                    index: 0x1008,
                    sub: 0,
                    crc: true,
                    blksize: 127,
                    pst: 4,
                },
            ),
            (
                Side::Server,
                false,
                BlockUploadInitiateResponse {
                    index: 0x1008,
                    sub: 0,
                    crc: true,
                    size: None,
                },
            ),
            (Side::Client, false, BlockUploadStart),
            (
                Side::Client,
                false,
                BlockUploadAck {
                    ackseq: 127,
                    blksize: 64,
                },
            ),
            (Side::Server, false, BlockUploadEnd { unused: 1, crc: 0x0102 }),
            (Side::Client, false, BlockUploadEndResponse),
            (
                Side::Server,
                true,
                BlockSegment {
                    seqno: 127,
                    last: true,
                    data: chunk(&[9; 7]),
                },
            ),
        ];
        for (side, seg, cmd) in cases {
            assert_eq!(decode(side, &encode(&cmd), seg), cmd);
        }
    }
}
