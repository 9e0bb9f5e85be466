//! The JSONL contract: one JSON object per frame (field names are a public API).
//!
//! [`write_frame`] writes the common fields straight into the output buffer and
//! [`BodyJson`], the kind-specific object (each decoder's `to_json`), through serde
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
use crate::frame::json::{push_hex, push_seconds, push_text, push_u64};
use crate::frame::{Flags, Frame, Interfaces};
use serde::Serialize;

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

impl BodyJson<'_> {
    /// The record key the object goes under.
    fn key(&self) -> &'static str {
        match self {
            BodyJson::Nmt(_) => "nmt",
            BodyJson::Heartbeat(_) => "heartbeat",
            BodyJson::Sync(_) => "sync",
            BodyJson::Time(_) => "time",
            BodyJson::Emcy(_) => "emcy",
            BodyJson::Pdo(_) => "pdo",
            BodyJson::Sdo(_) => "sdo",
            BodyJson::Lss(_) => "lss",
            BodyJson::VendorSdo(_) => "vendor_sdo",
            BodyJson::Error(_) => "error",
        }
    }

    /// Appends the object itself (without its key).
    fn write_object(&self, out: &mut Vec<u8>) -> serde_json::Result<()> {
        match self {
            BodyJson::Nmt(j) => serde_json::to_writer(out, j),
            BodyJson::Heartbeat(j) => serde_json::to_writer(out, j),
            BodyJson::Sync(j) => serde_json::to_writer(out, j),
            BodyJson::Time(j) => serde_json::to_writer(out, j),
            BodyJson::Emcy(j) => serde_json::to_writer(out, j),
            BodyJson::Pdo(j) => serde_json::to_writer(out, j),
            BodyJson::Sdo(j) => serde_json::to_writer(out, j),
            BodyJson::Lss(j) => serde_json::to_writer(out, j),
            BodyJson::VendorSdo(j) => serde_json::to_writer(out, j),
            BodyJson::Error(j) => serde_json::to_writer(out, j),
        }
    }
}

/// Appends the JSON object (and a newline) for one frame read from input line `line`.
///
/// The record's fields, in contract order: `line` (input line, 1-based), `t` (seconds,
/// exact to the ns), `iface`, `id`, `ext`, `rtr`, `fd`, `err`, `len`, `data` (upper-case
/// hex), `dir` (`rx`/`tx`), `kind` (the [`crate::decode::Kind`] name), `node`, `label`,
/// the kind-specific object under its key ([`BodyJson`], absent for kinds without one),
/// and `malformed` (absent when the frame breaks no rule).
///
/// The record's own fields are written directly (this is the hot path of
/// `cotui decode --format jsonl`); the kind-specific object goes through serde.
pub fn write_frame(out: &mut Vec<u8>, line: u64, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    let start = out.len();
    out.extend_from_slice(b"{\"line\":");
    push_u64(out, line);
    out.extend_from_slice(b",\"t\":");
    push_seconds(out, frame.ts_ns);
    out.extend_from_slice(b",\"iface\":");
    push_text(out, ifaces.name(frame.iface));
    out.extend_from_slice(b",\"id\":");
    push_u64(out, frame.id.into());
    push_flag(out, b",\"ext\":", frame.is_ext());
    push_flag(out, b",\"rtr\":", frame.is_rtr());
    push_flag(out, b",\"fd\":", frame.is_fd());
    push_flag(out, b",\"err\":", frame.is_err());
    out.extend_from_slice(b",\"len\":");
    push_u64(out, frame.len.into());
    out.extend_from_slice(b",\"data\":");
    push_hex(out, frame.payload());
    out.extend_from_slice(if frame.flags.has(Flags::TX) {
        b",\"dir\":\"tx\""
    } else {
        b",\"dir\":\"rx\""
    });
    out.extend_from_slice(b",\"kind\":\"");
    out.extend_from_slice(decoded.kind.as_str().as_bytes());
    out.extend_from_slice(b"\",\"node\":");
    match decoded.node {
        Some(n) => push_u64(out, n.into()),
        None => out.extend_from_slice(b"null"),
    }
    out.extend_from_slice(b",\"label\":");
    push_text(out, &decoded.label);
    if let Some(body) = BodyJson::new(decoded, frame) {
        out.extend_from_slice(b",\"");
        out.extend_from_slice(body.key().as_bytes());
        out.extend_from_slice(b"\":");
        if body.write_object(out).is_err() {
            // The body types hold only what JSON can carry: this does not happen.
            out.truncate(start);
            return;
        }
    }
    if let Some(m) = &decoded.malformed {
        out.extend_from_slice(b",\"malformed\":");
        push_text(out, m);
    }
    out.extend_from_slice(b"}\n");
}

/// Appends `key` and `true`/`false`.
fn push_flag(out: &mut Vec<u8>, key: &[u8], v: bool) {
    out.extend_from_slice(key);
    out.extend_from_slice(if v { b"true" } else { b"false" });
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
        let lit = |s| serde_json::to_string(&crate::frame::json::Text(s)).unwrap();
        assert_eq!(lit("a\"b\\c\u{1}"), r#""a\"b\\c\u0001""#);
        assert_eq!(lit("µ\tz\n°"), r#""µ\tz\n°""#);
    }
}
