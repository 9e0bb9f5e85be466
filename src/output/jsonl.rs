//! The JSONL contract: one JSON object per frame (field names are a public API).
//!
//! [`FrameRecord`] holds the common fields and [`BodyJson`] the kind-specific object,
//! each decoder's `to_json`; serde writes the record straight into the output buffer
//! (this is the hot path of `cotui decode --format jsonl`).

use crate::decode::emcy::EmcyJson;
use crate::decode::error_frame::{self, ErrorFrameJson};
use crate::decode::heartbeat::HeartbeatJson;
use crate::decode::lss::LssJson;
use crate::decode::nmt::NmtJson;
use crate::decode::pdo::PdoJson;
use crate::decode::sdo::frame::SdoJson;
use crate::decode::sync::SyncJson;
use crate::decode::time::TimeJson;
use crate::decode::vendor_sdo::VendorSdoJson;
use crate::decode::{Body, Decoded};
use crate::frame::json::{Hex, Seconds, Text, write_line};
use crate::frame::{Flags, Frame, Interfaces};
use serde::Serialize;

/// One frame as a JSONL record (fields in contract order).
#[derive(Clone, Debug, Serialize)]
pub struct FrameRecord<'a> {
    /// Input line number (1-based).
    pub line: u64,
    /// Seconds, exact to the ns.
    pub t: Seconds,
    pub iface: Text<'a>,
    pub id: u32,
    pub ext: bool,
    pub rtr: bool,
    pub fd: bool,
    pub err: bool,
    pub len: u8,
    /// The payload, upper-case hex.
    pub data: Hex<'a>,
    /// `rx` or `tx`.
    pub dir: &'static str,
    /// The [`crate::decode::Kind`] name.
    pub kind: &'static str,
    pub node: Option<u8>,
    pub label: Text<'a>,
    /// The kind-specific object under its key (absent for kinds without one).
    #[serde(flatten)]
    pub body: Option<BodyJson<'a>>,
    /// Why the frame breaks a rule (absent when it does not).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub malformed: Option<Text<'a>>,
}

/// The kind-specific object of a frame record, under its key (`nmt`, `heartbeat`, ...).
#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyJson<'a> {
    Nmt(NmtJson),
    Heartbeat(HeartbeatJson),
    Sync(SyncJson),
    Time(TimeJson),
    Emcy(EmcyJson<'a>),
    Pdo(PdoJson<'a>),
    Sdo(SdoJson<'a>),
    Lss(LssJson),
    VendorSdo(VendorSdoJson<'a>),
    /// Error frames (kind `error_frame`) carry theirs under `error`.
    Error(ErrorFrameJson),
}

impl<'a> BodyJson<'a> {
    /// The kind-specific object of a decoded frame, `None` for kinds without one.
    pub fn new(decoded: &'a Decoded, frame: &Frame) -> Option<BodyJson<'a>> {
        Some(match &decoded.body {
            Body::None => return None,
            Body::Nmt(n) => BodyJson::Nmt(n.to_json()),
            Body::Heartbeat(h) => BodyJson::Heartbeat(h.to_json()),
            Body::Sync(s) => BodyJson::Sync(s.to_json()),
            Body::Time(t) => BodyJson::Time(t.to_json()),
            Body::Emcy(e) => BodyJson::Emcy(e.to_json()),
            Body::Pdo(p) => BodyJson::Pdo(p.to_json()),
            Body::Sdo(s) => BodyJson::Sdo(s.to_json()),
            Body::Lss(l) => BodyJson::Lss(l.to_json()),
            Body::VendorSdo(v) => BodyJson::VendorSdo(v.to_json()),
            Body::ErrorFrame { class } => BodyJson::Error(error_frame::to_json(*class, frame.payload())),
        })
    }
}

impl<'a> FrameRecord<'a> {
    /// The record of one frame read from input line `line`.
    pub fn new(line: u64, frame: &'a Frame, ifaces: &'a Interfaces, decoded: &'a Decoded) -> FrameRecord<'a> {
        FrameRecord {
            line,
            t: Seconds(frame.ts_ns),
            iface: Text(ifaces.name(frame.iface)),
            id: frame.id,
            ext: frame.is_ext(),
            rtr: frame.is_rtr(),
            fd: frame.is_fd(),
            err: frame.is_err(),
            len: frame.len,
            data: Hex(frame.payload()),
            dir: if frame.flags.has(Flags::TX) { "tx" } else { "rx" },
            kind: decoded.kind.as_str(),
            node: decoded.node,
            label: Text(&decoded.label),
            body: BodyJson::new(decoded, frame),
            malformed: decoded.malformed.as_deref().map(Text),
        }
    }
}

/// Appends the JSON object (and a newline) for one frame read from input line `line`.
pub fn write_frame(out: &mut Vec<u8>, line: u64, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    write_line(out, &FrameRecord::new(line, frame, ifaces, decoded));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;
    use crate::od::Dictionary;
    use serde_json::json;

    fn json_of(frame: &Frame, line: u64) -> serde_json::Value {
        let mut ifaces = Interfaces::default();
        ifaces.intern("can0");
        let d = Decoder::new(Dictionary::default(), vec![]).decode(frame);
        let mut s = Vec::new();
        write_frame(&mut s, line, frame, &ifaces, &d);
        assert!(s.ends_with(b"}\n"));
        serde_json::from_slice(&s).expect("valid JSON")
    }

    #[test]
    fn contract_fields() {
        let mut f = Frame::classic(0x000, &[0x81, 0x00]);
        f.ts_ns = 1_500_000_000;
        let j = json_of(&f, 7);
        assert_eq!(j["line"], 7);
        assert_eq!(j["t"], 1.5);
        assert_eq!(j["iface"], "can0");
        assert_eq!(j["id"], 0);
        assert_eq!(j["ext"], false);
        assert_eq!(j["rtr"], false);
        assert_eq!(j["fd"], false);
        assert_eq!(j["err"], false);
        assert_eq!(j["len"], 2);
        assert_eq!(j["data"], "8100");
        assert_eq!(j["kind"], "nmt");
        assert_eq!(j["node"], json!(null));
        assert_eq!(j["nmt"], json!({"command": "reset_node", "target": 0}));
        assert_eq!(j["label"], "NMT Reset node -> all nodes");
        assert!(j.get("malformed").is_none());
    }

    #[test]
    fn malformed_and_escaping() {
        let j = json_of(&Frame::classic(0x705, &[0x05, 0x00]), 1);
        assert_eq!(j["node"], 5);
        assert_eq!(j["heartbeat"]["state"], "operational");
        assert_eq!(j["malformed"], "heartbeat frame has 2 data bytes, expected 1");
        let lit = |s| serde_json::to_string(&Text(s)).unwrap();
        assert_eq!(lit("a\"b\\c\u{1}"), r#""a\"b\\c\u0001""#);
        assert_eq!(lit("µ\tz\n°"), r#""µ\tz\n°""#);
    }
}
