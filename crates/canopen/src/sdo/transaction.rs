//! A reassembled SDO transfer: what was read or written, how, and how it ended.

use super::codec::Side;
use crate::cob;
use std::fmt;

/// An SDO channel: a node on one interface and the COB-ID pair its client and server
/// use. Frames of different interfaces never share a channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Channel {
    /// The interface (index into the source's interface table, as `Frame::iface`).
    pub iface: u16,
    /// The server's node-ID.
    pub node: u8,
    /// Client to server COB-ID (0x600 + node by default).
    pub request_cob: u32,
    /// Server to client COB-ID (0x580 + node by default).
    pub response_cob: u32,
}

impl Channel {
    /// The default SDO channel of a node on the first interface (0x600 + node / 0x580 + node).
    pub fn default_for(node: u8) -> Channel {
        Channel::default_on(crate::frame::NodeKey::new(0, node))
    }

    /// The default SDO channel of a node on its interface (0x600 + node / 0x580 + node).
    pub fn default_on(key: crate::frame::NodeKey) -> Channel {
        let node = key.node;
        Channel {
            iface: key.iface,
            node,
            request_cob: cob::sdo_request(node),
            response_cob: cob::sdo_response(node),
        }
    }
}

/// Upload (read from the server) or download (write to the server).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransferDirection {
    /// Read from the server.
    Upload,
    /// Written to the server.
    Download,
}

impl TransferDirection {
    /// `"upload"` or `"download"`.
    pub fn as_str(self) -> &'static str {
        match self {
            TransferDirection::Upload => "upload",
            TransferDirection::Download => "download",
        }
    }
}

/// The SDO protocol a transfer used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Protocol {
    /// Up to 4 bytes in the initiate frames.
    Expedited,
    /// 7-byte segments with a toggle bit, each confirmed.
    Segmented,
    /// Sub-blocks of numbered segments with a CRC.
    Block,
    /// Not seen yet: an upload the server has not answered, or a transfer whose
    /// request was not captured.
    Unknown,
}

impl Protocol {
    /// `"expedited"`, `"segmented"`, `"block"` or `"unknown"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Protocol::Expedited => "expedited",
            Protocol::Segmented => "segmented",
            Protocol::Block => "block",
            Protocol::Unknown => "unknown",
        }
    }
}

/// How a transfer ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Completed (problems may still be listed).
    Ok,
    /// Aborted with a code by one side.
    Aborted { code: u32, text: &'static str, by: Side },
    /// Still running at the end of the input (or only its end was seen).
    Incomplete,
    /// The frames did not follow the protocol.
    ProtocolError(String),
}

impl Outcome {
    /// `"ok"`, `"aborted"`, `"incomplete"` or `"protocol_error"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Outcome::Ok => "ok",
            Outcome::Aborted { .. } => "aborted",
            Outcome::Incomplete => "incomplete",
            Outcome::ProtocolError(_) => "protocol_error",
        }
    }
}

/// Something wrong seen in a transfer that did not necessarily end it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Problem {
    /// A response without the request it answers (e.g. capture started after the request).
    UnmatchedResponse,
    /// A segment's toggle bit did not alternate.
    ToggleError,
    /// The block CRC sent does not match the data.
    BadCrc { sent: u16, computed: u16 },
    /// A frame of the transfer had a DLC other than 8.
    WrongDlc { dlc: u8 },
    /// Block segments out of sequence or not all acknowledged.
    SequenceError,
    /// Indicated size and transferred bytes differ.
    SizeMismatch { indicated: u32, actual: usize },
    /// The bytes do not fit the size of the object's type in the dictionary.
    TypeLengthMismatch { expected: usize, actual: usize },
    /// The capture started in the middle of this (block) transfer: its initiate, object
    /// and first bytes were not seen, so the data is only the part seen.
    StartedBeforeCapture,
}

impl Problem {
    /// Machine name for JSON, e.g. `"toggle_error"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Problem::UnmatchedResponse => "unmatched_response",
            Problem::ToggleError => "toggle_error",
            Problem::BadCrc { .. } => "bad_crc",
            Problem::WrongDlc { .. } => "wrong_dlc",
            Problem::SequenceError => "sequence_error",
            Problem::SizeMismatch { .. } => "size_mismatch",
            Problem::TypeLengthMismatch { .. } => "type_length_mismatch",
            Problem::StartedBeforeCapture => "partial",
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Problem::UnmatchedResponse => write!(f, "unmatched response"),
            Problem::ToggleError => write!(f, "toggle error"),
            Problem::BadCrc { sent, computed } => {
                write!(f, "bad block CRC: sent 0x{sent:04X}, data gives 0x{computed:04X}")
            }
            Problem::WrongDlc { dlc } => write!(f, "wrong DLC {dlc}"),
            Problem::SequenceError => write!(f, "sequence error"),
            Problem::SizeMismatch { indicated, actual } => {
                write!(f, "size mismatch: indicated {indicated}, transferred {actual}")
            }
            Problem::TypeLengthMismatch { expected, actual } => {
                write!(f, "length {actual} does not fit the object's type ({expected} bytes)")
            }
            Problem::StartedBeforeCapture => write!(f, "partial: started before the capture"),
        }
    }
}

/// One reassembled SDO transfer.
#[derive(Clone, Debug, PartialEq)]
pub struct Transaction {
    /// The interface it ran on (index into the source's interface table).
    pub iface: u16,
    /// The server's node-ID.
    pub node: u8,
    /// The channel it ran on.
    pub channel: Channel,
    /// Object index.
    pub index: u16,
    /// Object sub-index.
    pub sub: u8,
    /// Upload (read) or download (write).
    pub direction: TransferDirection,
    /// Expedited, segmented or block.
    pub protocol: Protocol,
    /// The bytes transferred (so far, when not complete); at most the first
    /// [`DATA_KEPT`] bytes, the rest is only counted in `dropped`.
    pub data: Vec<u8>,
    /// Bytes transferred beyond [`DATA_KEPT`], counted but not kept.
    pub dropped: usize,
    /// The size the initiating frames indicated.
    pub size: Option<u32>,
    /// Timestamp of the first frame (ns).
    pub start_ns: u64,
    /// Timestamp of the last frame (ns).
    pub end_ns: u64,
    /// How it ended.
    pub outcome: Outcome,
    /// What went wrong along the way, each kind once.
    pub problems: Vec<Problem>,
    /// Sequence numbers of the frames that belong to it (the first [`FRAMES_KEPT`]).
    pub frames: Vec<u64>,
    /// Frames that belong to it beyond [`FRAMES_KEPT`], counted but not listed.
    pub frames_dropped: u64,
    /// The node's mode of operation when the transfer ended (known to the decoder from
    /// 6060h/6061h), so that controlword/statusword bits are named for that mode.
    pub mode: Option<i8>,
}

/// Bytes of one transfer kept in [`Transaction::data`]; a longer transfer (a firmware
/// download, or a transfer that never ends) is counted, not kept, so memory stays flat.
pub(crate) const DATA_KEPT: usize = 1 << 20;

/// Frame numbers of one transfer kept in [`Transaction::frames`].
pub(crate) const FRAMES_KEPT: usize = 1 << 14;

impl Transaction {
    /// The server as a node of its interface.
    pub fn key(&self) -> crate::frame::NodeKey {
        crate::frame::NodeKey::new(self.iface, self.node)
    }

    /// Duration from first to last frame, in ns.
    pub fn duration_ns(&self) -> u64 {
        self.end_ns.saturating_sub(self.start_ns)
    }

    /// Completed, and its data can be trusted (no bad CRC, toggle error or size mismatch,
    /// not partial): what the decoder may learn COB-IDs and PDO mappings from.
    pub fn is_ok(&self) -> bool {
        self.outcome == Outcome::Ok
            && !self.problems.iter().any(|p| {
                matches!(
                    p,
                    Problem::BadCrc { .. }
                        | Problem::ToggleError
                        | Problem::SizeMismatch { .. }
                        | Problem::StartedBeforeCapture
                )
            })
    }

    /// The capture started in the middle of it: object unknown, only the bytes seen.
    pub fn is_partial(&self) -> bool {
        self.problems.contains(&Problem::StartedBeforeCapture)
    }

    /// The size the initiate announced, when the transfer ended (aborted, broke, or was
    /// still running when the input ended) before that many bytes came: a download that
    /// announced 64 bytes and sent 7 gives `Some(64)`.
    pub fn cut_short_of(&self) -> Option<u32> {
        let size = self.size?;
        (self.outcome != Outcome::Ok && (self.len() as u64) < u64::from(size)).then_some(size)
    }

    /// Bytes transferred, kept or not.
    pub fn len(&self) -> usize {
        self.data.len() + self.dropped
    }

    /// No bytes transferred.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends transferred bytes, keeping at most [`DATA_KEPT`] of them.
    pub(crate) fn append(&mut self, bytes: &[u8]) {
        let room = DATA_KEPT.saturating_sub(self.data.len()).min(bytes.len());
        self.data.extend_from_slice(&bytes[..room]);
        self.dropped += bytes.len() - room;
    }

    /// Removes the last `n` bytes (the unused bytes of a last block segment).
    pub(crate) fn cut(&mut self, n: usize) {
        let n = n.min(self.len());
        let from_dropped = n.min(self.dropped);
        self.dropped -= from_dropped;
        self.data.truncate(self.data.len() - (n - from_dropped));
    }

    /// Records a frame number, keeping at most [`FRAMES_KEPT`] of them.
    pub(crate) fn add_frame(&mut self, seq: u64) {
        if self.frames.len() < FRAMES_KEPT {
            self.frames.push(seq);
        } else {
            self.frames_dropped += 1;
        }
    }

    /// Adds a problem once.
    pub(crate) fn flag(&mut self, p: Problem) {
        if !self.problems.contains(&p) {
            self.problems.push(p);
        }
    }
}
