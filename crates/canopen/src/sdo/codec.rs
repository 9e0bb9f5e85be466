//! The SDO command-byte codec (CiA 301 section 7.2.4.3): one frame's eight bytes to a
//! typed [`SdoCommand`] and back. Every part of cotui that reads or writes SDO frames (the
//! client, the server, the passive tracker, the labels) goes through [`decode`] (or the
//! strict [`parse`]) and [`encode`]; none of them builds or takes apart command bytes itself.
//!
//! Block transfer sub-block segments carry a sequence number where other frames carry a
//! command byte, so decoding needs to know whether the sender is inside a sub-block (the
//! party running the transfer knows).

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

/// Client command specifiers (`ccs`, bits 7-5 of a client's command byte).
mod ccs {
    pub const DOWNLOAD_SEGMENT: u8 = 0;
    pub const INITIATE_DOWNLOAD: u8 = 1;
    pub const INITIATE_UPLOAD: u8 = 2;
    pub const UPLOAD_SEGMENT: u8 = 3;
    pub const BLOCK_UPLOAD: u8 = 5;
    pub const BLOCK_DOWNLOAD: u8 = 6;
}

/// Server command specifiers (`scs`, bits 7-5 of a server's command byte).
mod scs {
    pub const UPLOAD_SEGMENT: u8 = 0;
    pub const DOWNLOAD_SEGMENT: u8 = 1;
    pub const INITIATE_UPLOAD: u8 = 2;
    pub const INITIATE_DOWNLOAD: u8 = 3;
    pub const BLOCK_DOWNLOAD: u8 = 5;
    pub const BLOCK_UPLOAD: u8 = 6;
}

/// The abort transfer command specifier, the same for both sides.
const CS_ABORT: u8 = 4;

/// Sub-commands of a block transfer in bits 1-0 (`cs`/`ss`): with ccs 5 (block upload)
/// all four, with scs 5 (block download) the first three; with ccs/scs 6 only bit 0
/// (initiate or end).
mod block {
    pub const INITIATE: u8 = 0;
    pub const END: u8 = 1;
    pub const ACK: u8 = 2;
    pub const START: u8 = 3;
}

/// Bit flags of command bytes.
const TOGGLE: u8 = 0x10;
const CRC: u8 = 0x04;
const BLOCK_SIZE_INDICATED: u8 = 0x02;
const EXPEDITED: u8 = 0x02;
const SIZE_INDICATED: u8 = 0x01;
const LAST: u8 = 0x01;
const LAST_SEGMENT: u8 = 0x80;
/// The command byte of a block end with `n` zero (ccs/scs 6, cs/ss 1), either side.
const BLOCK_END: u8 = ccs::BLOCK_DOWNLOAD << 5 | block::END;

/// A frame's eight bytes (a short payload padded with zeros) and its real payload, which
/// bounds the data fields.
struct Fields<'a> {
    p: [u8; 8],
    payload: &'a [u8],
}

impl Fields<'_> {
    fn new(payload: &[u8]) -> Fields<'_> {
        let mut p = [0u8; 8];
        let n = payload.len().min(8);
        p[..n].copy_from_slice(&payload[..n]);
        Fields { p, payload }
    }
    fn cmd(&self) -> u8 {
        self.p[0]
    }
    fn index(&self) -> u16 {
        u16::from_le_bytes([self.p[1], self.p[2]])
    }
    fn sub(&self) -> u8 {
        self.p[3]
    }
    fn d32(&self) -> u32 {
        u32::from_le_bytes([self.p[4], self.p[5], self.p[6], self.p[7]])
    }
    fn crc16(&self) -> u16 {
        u16::from_le_bytes([self.p[1], self.p[2]])
    }
    fn flag(&self, bit: u8) -> bool {
        self.cmd() & bit != 0
    }
    /// Up to `len` data bytes from byte `from`, as far as the payload reaches.
    fn data(&self, from: usize, len: usize) -> Chunk {
        Chunk::new(self.payload.get(from..).unwrap_or(&[]), len)
    }
    /// The data of a segment: 7 bytes less `n` (bits 3-1).
    fn segment(&self) -> Chunk {
        self.data(1, 7 - ((self.cmd() >> 1) & 7) as usize)
    }
    /// The `unused` count of a block end (bits 4-2).
    fn unused(&self) -> u8 {
        (self.cmd() >> 2) & 7
    }
    /// Expedited flag, indicated size and expedited data of an initiate (download request
    /// or upload response): `e`, `s` and `n` (bits 3-2, unused bytes when e and s are set).
    fn initiate(&self) -> (bool, Option<u32>, Chunk) {
        let n = ((self.cmd() >> 2) & 3) as usize;
        match (self.flag(EXPEDITED), self.flag(SIZE_INDICATED)) {
            (true, true) => (true, Some(4 - n as u32), self.data(4, 4 - n)),
            (true, false) => (true, None, self.data(4, 4)),
            (false, true) => (false, Some(self.d32()), Chunk::default()),
            (false, false) => (false, None, Chunk::default()),
        }
    }
    /// The size of a block initiate, when indicated.
    fn block_size(&self) -> Option<u32> {
        self.flag(BLOCK_SIZE_INDICATED).then_some(self.d32())
    }
}

/// Decodes one SDO payload sent by `side`. `block_segments` tells that this side is inside
/// a block sub-block, so the first byte is `c | seqno`. Lenient, as an analyzer must be:
/// reserved bits are ignored, a short payload is decoded as if padded with zeros (data stops
/// at the real end), and a command specifier CiA 301 does not define for this side is
/// [`SdoCommand::Unknown`].
pub fn decode(side: Side, payload: &[u8], block_segments: bool) -> SdoCommand {
    let f = Fields::new(payload);
    let cs = f.cmd() >> 5;
    // Seqno 0 is not a valid block segment, so 0x80 inside a sub-block is an abort.
    if block_segments && f.cmd() != CS_ABORT << 5 {
        return SdoCommand::BlockSegment {
            seqno: f.cmd() & 0x7F,
            last: f.flag(LAST_SEGMENT),
            data: f.data(1, 7),
        };
    }
    if cs == CS_ABORT {
        return SdoCommand::Abort {
            index: f.index(),
            sub: f.sub(),
            code: f.d32(),
        };
    }
    match side {
        Side::Client => client_command(cs, &f),
        Side::Server => server_command(cs, &f),
    }
}

/// A client's command (not an abort).
fn client_command(cs: u8, f: &Fields) -> SdoCommand {
    use SdoCommand::*;
    let (index, sub) = (f.index(), f.sub());
    match cs {
        ccs::DOWNLOAD_SEGMENT => DownloadSegment {
            toggle: f.flag(TOGGLE),
            last: f.flag(LAST),
            data: f.segment(),
        },
        ccs::INITIATE_DOWNLOAD => {
            let (expedited, size, data) = f.initiate();
            InitiateDownload {
                index,
                sub,
                expedited,
                size,
                data,
            }
        }
        ccs::INITIATE_UPLOAD => InitiateUpload { index, sub },
        ccs::UPLOAD_SEGMENT => UploadSegment { toggle: f.flag(TOGGLE) },
        ccs::BLOCK_UPLOAD => match f.cmd() & 3 {
            block::INITIATE => BlockUploadInitiate {
                index,
                sub,
                crc: f.flag(CRC),
                blksize: f.p[4],
                pst: f.p[5],
            },
            block::END => BlockUploadEndResponse,
            block::ACK => BlockUploadAck {
                ackseq: f.p[1],
                blksize: f.p[2],
            },
            _ => BlockUploadStart,
        },
        ccs::BLOCK_DOWNLOAD if f.cmd() & 1 == block::INITIATE => BlockDownloadInitiate {
            index,
            sub,
            crc: f.flag(CRC),
            size: f.block_size(),
        },
        ccs::BLOCK_DOWNLOAD => BlockDownloadEnd {
            unused: f.unused(),
            crc: f.crc16(),
        },
        _ => Unknown { command: f.cmd() },
    }
}

/// A server's command (not an abort).
fn server_command(cs: u8, f: &Fields) -> SdoCommand {
    use SdoCommand::*;
    let (index, sub) = (f.index(), f.sub());
    match cs {
        scs::UPLOAD_SEGMENT => UploadSegmentResponse {
            toggle: f.flag(TOGGLE),
            last: f.flag(LAST),
            data: f.segment(),
        },
        scs::DOWNLOAD_SEGMENT => DownloadSegmentResponse { toggle: f.flag(TOGGLE) },
        scs::INITIATE_UPLOAD => {
            let (expedited, size, data) = f.initiate();
            InitiateUploadResponse {
                index,
                sub,
                expedited,
                size,
                data,
            }
        }
        scs::INITIATE_DOWNLOAD => InitiateDownloadResponse { index, sub },
        scs::BLOCK_DOWNLOAD => match f.cmd() & 3 {
            block::INITIATE => BlockDownloadInitiateResponse {
                index,
                sub,
                crc: f.flag(CRC),
                blksize: f.p[4],
            },
            block::END => BlockDownloadEndResponse,
            block::ACK => BlockDownloadAck {
                ackseq: f.p[1],
                blksize: f.p[2],
            },
            _ => Unknown { command: f.cmd() },
        },
        scs::BLOCK_UPLOAD if f.cmd() & 1 == block::INITIATE => BlockUploadInitiateResponse {
            index,
            sub,
            crc: f.flag(CRC),
            size: f.block_size(),
        },
        scs::BLOCK_UPLOAD => BlockUploadEnd {
            unused: f.unused(),
            crc: f.crc16(),
        },
        _ => Unknown { command: f.cmd() },
    }
}

/// Why [`parse`] refused a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseError {
    /// The command byte has a bit set that CiA 301 reserves (must be zero) for this side,
    /// or a block segment carries sequence number 0.
    #[error("SDO command byte 0x{0:02X} has reserved bits set")]
    Reserved(u8),
    /// The command specifier is not one CiA 301 defines for this side.
    #[error("SDO command byte 0x{0:02X} is not a command of this side")]
    Undefined(u8),
}

/// Decodes a whole frame strictly: like [`decode`], but a command byte with reserved bits
/// set (see [`command_allowed`]) or an undefined command specifier is an error. Every frame
/// it accepts is given back by [`encode`] with the same command byte.
pub fn parse(side: Side, frame: &[u8; 8], block_segments: bool) -> Result<SdoCommand, ParseError> {
    let byte = frame[0];
    let allowed = if block_segments {
        byte & 0x7F != 0 || byte == CS_ABORT << 5
    } else {
        command_allowed(side, byte)
    };
    match decode(side, frame, block_segments) {
        _ if !allowed => Err(ParseError::Reserved(byte)),
        SdoCommand::Unknown { command } => Err(ParseError::Undefined(command)),
        cmd => Ok(cmd),
    }
}

/// Whether `byte` is a command byte CiA 301 allows `side` to send, with every reserved
/// bit zero (in an initiate, `n` is zero unless both `e` and `s` are set);
/// `0xE0..=0xFF` (no command specifier 7) is left to the unknown-command handling.
pub(crate) fn command_allowed(side: Side, byte: u8) -> bool {
    let initiate = |b: u8| b & 0x03 == 0x03 || b & 0x0C == 0;
    match (side, byte) {
        (_, 0x00..=0x1F) | (_, 0x80) | (_, 0xE0..=0xFF) => true,
        (Side::Client, 0x20..=0x2F) | (Side::Server, 0x40..=0x4F) => initiate(byte),
        (Side::Client, 0x40 | 0x60 | 0x70 | 0xA0..=0xA4) => true,
        (Side::Server, 0x20 | 0x30 | 0x60 | 0xA0 | 0xA1 | 0xA2 | 0xA4) => true,
        // Block initiates (cs 0, x bits zero) and ends (n, cs 1, bit 1 zero).
        (_, 0xC0..=0xDF) => {
            let initiate = byte & 1 == 0;
            if initiate { byte & 0x19 == 0 } else { byte & 0x02 == 0 }
        }
        _ => false,
    }
}

/// An end-of-block command byte (`110 n n n x 1`, either side).
pub(crate) fn end_command(byte: u8) -> bool {
    byte & 0xE3 == BLOCK_END
}

/// Builds the 8-byte payload of a command (the inverse of [`decode`]).
/// Unused bytes are zero; expedited data and segment data set `n` from their length.
pub fn encode(cmd: &SdoCommand) -> [u8; 8] {
    use SdoCommand::*;
    match *cmd {
        InitiateDownload {
            index,
            sub,
            expedited,
            size,
            data,
        } => initiate(ccs::INITIATE_DOWNLOAD, index, sub, expedited, size, data),
        InitiateUploadResponse {
            index,
            sub,
            expedited,
            size,
            data,
        } => initiate(scs::INITIATE_UPLOAD, index, sub, expedited, size, data),
        InitiateDownloadResponse { index, sub } => object(scs::INITIATE_DOWNLOAD << 5, index, sub, 0),
        InitiateUpload { index, sub } => object(ccs::INITIATE_UPLOAD << 5, index, sub, 0),
        DownloadSegment { toggle, last, data } => segment(ccs::DOWNLOAD_SEGMENT, toggle, last, data),
        UploadSegmentResponse { toggle, last, data } => segment(scs::UPLOAD_SEGMENT, toggle, last, data),
        DownloadSegmentResponse { toggle } => command(scs::DOWNLOAD_SEGMENT << 5 | toggle_bit(toggle)),
        UploadSegment { toggle } => command(ccs::UPLOAD_SEGMENT << 5 | toggle_bit(toggle)),
        Abort { index, sub, code } => object(CS_ABORT << 5, index, sub, code),
        BlockDownloadInitiate { index, sub, crc, size } | BlockUploadInitiateResponse { index, sub, crc, size } => {
            let c = ccs::BLOCK_DOWNLOAD << 5 | crc_bit(crc) | size.map_or(0, |_| BLOCK_SIZE_INDICATED);
            object(c, index, sub, size.unwrap_or(0))
        }
        BlockDownloadInitiateResponse {
            index,
            sub,
            crc,
            blksize,
        } => object(scs::BLOCK_DOWNLOAD << 5 | crc_bit(crc), index, sub, blksize.into()),
        BlockUploadInitiate {
            index,
            sub,
            crc,
            blksize,
            pst,
        } => {
            let d = u32::from_le_bytes([blksize, pst, 0, 0]);
            object(ccs::BLOCK_UPLOAD << 5 | crc_bit(crc), index, sub, d)
        }
        BlockDownloadAck { ackseq, blksize } | BlockUploadAck { ackseq, blksize } => {
            [ccs::BLOCK_UPLOAD << 5 | block::ACK, ackseq, blksize, 0, 0, 0, 0, 0]
        }
        BlockDownloadEnd { unused, crc } | BlockUploadEnd { unused, crc } => {
            let [c0, c1] = crc.to_le_bytes();
            [BLOCK_END | (unused & 7) << 2, c0, c1, 0, 0, 0, 0, 0]
        }
        BlockDownloadEndResponse | BlockUploadEndResponse => command(ccs::BLOCK_UPLOAD << 5 | block::END),
        BlockUploadStart => command(ccs::BLOCK_UPLOAD << 5 | block::START),
        BlockSegment { seqno, last, data } => with_data((seqno & 0x7F) | if last { LAST_SEGMENT } else { 0 }, 1, data),
        Unknown { command: c } => command(c),
    }
}

fn toggle_bit(toggle: bool) -> u8 {
    if toggle { TOGGLE } else { 0 }
}

fn crc_bit(crc: bool) -> u8 {
    if crc { CRC } else { 0 }
}

/// A frame of only a command byte.
fn command(c: u8) -> [u8; 8] {
    [c, 0, 0, 0, 0, 0, 0, 0]
}

/// A command byte with `data` from byte `from`.
fn with_data(c: u8, from: usize, data: Chunk) -> [u8; 8] {
    let mut p = command(c);
    let d = data.bytes();
    p[from..from + d.len()].copy_from_slice(d);
    p
}

/// A command byte, the object and four more bytes.
fn object(c: u8, index: u16, sub: u8, d32: u32) -> [u8; 8] {
    let [i0, i1] = index.to_le_bytes();
    let [d0, d1, d2, d3] = d32.to_le_bytes();
    [c, i0, i1, sub, d0, d1, d2, d3]
}

/// A segment: `n` counts the unused bytes of the seven.
fn segment(cs: u8, toggle: bool, last: bool, data: Chunk) -> [u8; 8] {
    let n = 7 - data.bytes().len() as u8;
    with_data(
        cs << 5 | toggle_bit(toggle) | n << 1 | if last { LAST } else { 0 },
        1,
        data,
    )
}

/// An initiate download request or upload response: expedited data with `n` and `s` from
/// the data and size, or the indicated size.
fn initiate(cs: u8, index: u16, sub: u8, expedited: bool, size: Option<u32>, data: Chunk) -> [u8; 8] {
    if !expedited {
        let s = size.map_or(0, |_| SIZE_INDICATED);
        return object(cs << 5 | s, index, sub, size.unwrap_or(0));
    }
    let d = &data.bytes()[..data.bytes().len().min(4)];
    let sized = size.map_or(0, |_| SIZE_INDICATED | (4 - d.len() as u8) << 2);
    let mut p = object(cs << 5 | EXPEDITED | sized, index, sub, 0);
    p[4..4 + d.len()].copy_from_slice(d);
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use SdoCommand::*;
    use proptest::prelude::*;
    use std::collections::HashSet;
    use std::mem::discriminant;

    fn chunk(b: &[u8]) -> Chunk {
        Chunk::new(b, b.len())
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

    /// What [`parse`] makes of `first` followed by `rest` from `side`, as sent outside or
    /// inside a sub-block.
    fn parsed(side: Side, first: u8, rest: [u8; 7], block: bool) -> Result<SdoCommand, ParseError> {
        let mut f = [first; 8];
        f[1..].copy_from_slice(&rest);
        parse(side, &f, block)
    }

    #[test]
    fn every_command_kind_parses_from_some_byte() {
        let mut kinds = HashSet::new();
        for side in [Side::Client, Side::Server] {
            for block in [false, true] {
                for byte in 0..=255u8 {
                    if let Ok(cmd) = parsed(side, byte, [1, 2, 3, 4, 5, 6, 7], block) {
                        kinds.insert(discriminant(&cmd));
                    }
                }
            }
        }
        // Every variant but Unknown: 21 commands.
        assert_eq!(kinds.len(), 21);
        assert!(!kinds.contains(&discriminant(&Unknown { command: 0 })));
    }

    #[test]
    fn parse_rejects_reserved_and_undefined_command_bytes() {
        let rest = [0x41, 0x60, 0, 1, 2, 3, 4];
        for byte in [0x6F, 0x30, 0x24, 0x28, 0x81, 0x9F, 0xA5, 0xA7, 0xC8, 0xC3, 0xD1 | 0x02] {
            assert_eq!(parsed(Side::Client, byte, rest, false), Err(ParseError::Reserved(byte)));
        }
        for byte in [0xA3, 0x50, 0x61, 0x44, 0x21, 0xC9 | 0x10 | 0x02, 0xC8] {
            assert_eq!(parsed(Side::Server, byte, rest, false), Err(ParseError::Reserved(byte)));
        }
        for side in [Side::Client, Side::Server] {
            assert_eq!(parsed(side, 0xE8, rest, false), Err(ParseError::Undefined(0xE8)));
            // Sequence number 0 does not exist; 0x80 inside a sub-block is an abort.
            assert_eq!(parsed(side, 0x00, rest, true), Err(ParseError::Reserved(0x00)));
            assert!(matches!(parsed(side, 0x80, rest, true), Ok(Abort { .. })));
        }
        // The lenient decode still reads what the strict parse refuses.
        assert_eq!(
            decode(Side::Client, &[0x6F, 0, 0, 0, 0, 0, 0, 0], false),
            UploadSegment { toggle: false }
        );
        assert_eq!(
            parsed(Side::Server, 0x4B, rest, false),
            Ok(InitiateUploadResponse {
                index: 0x6041,
                sub: 0,
                expedited: true,
                size: Some(2),
                data: chunk(&[1, 2]),
            })
        );
    }

    #[test]
    fn allowed_command_bytes_are_exactly_those_parse_accepts() {
        for side in [Side::Client, Side::Server] {
            for byte in 0..=255u8 {
                let ok = parsed(side, byte, [0; 7], false).is_ok();
                let undefined = matches!(decode(side, &[byte], false), Unknown { .. });
                assert_eq!(ok, command_allowed(side, byte) && !undefined, "{side:?} 0x{byte:02X}");
            }
        }
    }

    proptest! {
        /// Every frame that parses encodes back to the same command byte and to a frame
        /// that parses to the same command (bytes a command leaves unused come back zero).
        #[test]
        fn encode_parse_round_trips(first in any::<u8>(), rest in any::<[u8; 7]>(), server in any::<bool>(), block in any::<bool>()) {
            let side = if server { Side::Server } else { Side::Client };
            if let Ok(cmd) = parsed(side, first, rest, block) {
                let bytes = encode(&cmd);
                prop_assert_eq!(bytes[0], first);
                prop_assert_eq!(parse(side, &bytes, block), Ok(cmd));
                prop_assert_eq!(encode(&cmd), encode(&decode(side, &bytes, block)));
            }
        }
    }
}
