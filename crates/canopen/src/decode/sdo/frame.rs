//! One SDO frame as the trace shows it: its command (from [`crate::sdo::codec`]) with the
//! object, dictionary name, typed value and problems the tracker and dictionary add, as a
//! label and as JSON.

use super::value::{ValueView, segment_text};
use crate::decode::value_text::ValuePart;
use crate::frame::hex;
use crate::frame::json::Hex;
use crate::sdo::abort::abort_text;
use crate::sdo::codec::{SdoCommand, Side, decode};
use serde::Serialize;

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
        SdoFrame::of(side, payload, decode(side, payload, block_segments))
    }

    /// The frame `payload` sent by `side`, whose meaning is `command`.
    pub fn of(side: Side, payload: &[u8], command: SdoCommand) -> SdoFrame {
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

    /// Appends the object as ` 0x6040:00` plus its name when known.
    fn push_object(&self, s: &mut String) {
        let Some((index, sub)) = self.object else {
            return;
        };
        s.push_str(" 0x");
        hex::push_hex(s, index.into(), 4);
        s.push(':');
        hex::push_hex(s, sub.into(), 2);
        if let Some(name) = &self.name {
            s.push(' ');
            s.push_str(name);
        }
    }

    /// Appends the value part of an expedited label: ` = 6 (Shutdown)`.
    fn push_value(&self, s: &mut String) {
        if let Some(v) = &self.value {
            s.push_str(" = ");
            s.push_str(&v.text);
        }
    }

    /// One-line label, e.g. `Download 0x6040:00 Controlword = 6 (Shutdown)`, with tracker
    /// problems in brackets. Malformation is reported by [`SdoFrame::malformed`], not here.
    pub fn label(&self) -> String {
        let mut s = String::with_capacity(64);
        self.write_label(&mut s);
        s
    }

    /// Appends [`SdoFrame::label`] to `s`.
    pub fn write_label(&self, s: &mut String) {
        // Writing into a String cannot fail.
        let _ = self.write_label_fmt(s);
    }

    fn write_label_fmt(&self, s: &mut String) -> std::fmt::Result {
        use SdoCommand::*;
        use std::fmt::Write;
        match self.command {
            InitiateDownload { expedited: true, .. } => {
                s.push_str("Download");
                self.push_object(s);
                self.push_value(s);
            }
            InitiateDownload { size, .. } => {
                s.push_str("Download");
                self.push_object(s);
                push_segmented_size(s, size)?;
            }
            InitiateDownloadResponse { .. } => {
                s.push_str("Download response");
                self.push_object(s);
            }
            DownloadSegment { toggle, last, data } => write!(
                s,
                "Download segment t={} {} c={}",
                toggle as u8,
                segment_text(data.bytes()),
                last as u8
            )?,
            DownloadSegmentResponse { toggle } => s.push_str(if toggle {
                "Download segment response t=1"
            } else {
                "Download segment response t=0"
            }),
            InitiateUpload { .. } => {
                s.push_str("Upload");
                self.push_object(s);
            }
            InitiateUploadResponse { expedited: true, .. } => {
                s.push_str("Upload response");
                self.push_object(s);
                self.push_value(s);
            }
            InitiateUploadResponse { size, .. } => {
                s.push_str("Upload response");
                self.push_object(s);
                push_segmented_size(s, size)?;
            }
            UploadSegment { toggle } => s.push_str(if toggle {
                "Upload segment request t=1"
            } else {
                "Upload segment request t=0"
            }),
            UploadSegmentResponse { toggle, last, data } => write!(
                s,
                "Upload segment t={} {} c={}",
                toggle as u8,
                segment_text(data.bytes()),
                last as u8
            )?,
            Abort { code, .. } => {
                s.push_str("Abort");
                self.push_object(s);
                write!(s, ": 0x{code:08X} {}", abort_text(code))?;
            }
            BlockDownloadInitiate { crc, size, .. } => {
                s.push_str("Block download");
                self.push_object(s);
                write!(s, " ({})", block_opts(crc, size))?;
            }
            BlockDownloadInitiateResponse { crc, blksize, .. } => {
                s.push_str("Block download response");
                self.push_object(s);
                write!(s, " blksize={blksize}{}", if crc { " (crc)" } else { "" })?;
            }
            BlockDownloadAck { ackseq, blksize } => write!(s, "Block download ack ackseq={ackseq} blksize={blksize}")?,
            BlockDownloadEnd { unused, crc } => write!(s, "Block download end n={unused} crc=0x{crc:04X}")?,
            BlockDownloadEndResponse => s.push_str("Block download end response"),
            BlockUploadInitiate { crc, blksize, pst, .. } => {
                s.push_str("Block upload");
                self.push_object(s);
                write!(s, " blksize={blksize} pst={pst}{}", if crc { " (crc)" } else { "" })?;
            }
            BlockUploadInitiateResponse { crc, size, .. } => {
                s.push_str("Block upload response");
                self.push_object(s);
                write!(s, " ({})", block_opts(crc, size))?;
            }
            BlockUploadStart => s.push_str("Block upload start"),
            BlockUploadAck { ackseq, blksize } => write!(s, "Block upload ack ackseq={ackseq} blksize={blksize}")?,
            BlockUploadEnd { unused, crc } => write!(s, "Block upload end n={unused} crc=0x{crc:04X}")?,
            BlockUploadEndResponse => s.push_str("Block upload end response"),
            BlockSegment { seqno, last, .. } => {
                let dir = if self.side == Side::Client {
                    "download"
                } else {
                    "upload"
                };
                write!(
                    s,
                    "Block {dir} segment seqno={seqno}{}",
                    if last { " last" } else { "" }
                )?;
            }
            Unknown { command } => write!(
                s,
                "Unknown SDO command 0x{command:02X}: {}",
                hex::spaced(self.raw.bytes())
            )?,
        }
        for p in &self.problems {
            s.push_str(" [");
            s.push_str(p);
            s.push(']');
        }
        Ok(())
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
            value_parts: self
                .value
                .as_ref()
                .map(|v| v.parts.as_slice())
                .filter(|p| !p.is_empty()),
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
    /// The fields of a structured value (`name`, `raw`, `text`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value_parts: Option<&'a [ValuePart]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value_text: Option<&'a str>,
}

/// Appends ` (segmented, 16 bytes)` or ` (segmented, size not indicated)`.
fn push_segmented_size(s: &mut String, size: Option<u32>) -> std::fmt::Result {
    use std::fmt::Write;
    match size {
        Some(n) => write!(s, " (segmented, {n} bytes)"),
        None => {
            s.push_str(" (segmented, size not indicated)");
            Ok(())
        }
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
    use crate::sdo::codec::Chunk;
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
}
