//! The JSONL contract: one JSON object per frame (field names are a public API).
//!
//! [`write_frame`] writes the common fields and the most frequent kind-specific objects
//! (`pdo`, `sdo`) straight into the output buffer, byte for byte as serde writes them;
//! [`BodyJson`], the other kinds' objects (each decoder's `to_json`), go through serde
//! (this is the hot path of `cotui decode --format jsonl`).

use crate::decode::emcy::EmcyJson;
use crate::decode::error_frame::{self, ErrorFrameJson};
use crate::decode::heartbeat::HeartbeatJson;
use crate::decode::lss::LssJson;
use crate::decode::nmt::NmtJson;
use crate::decode::pdo::{Pdo, PdoJson, source_text};
use crate::decode::sdo::frame::SdoJson;
use crate::decode::sync::SyncJson;
use crate::decode::time::TimeJson;
use crate::decode::vendor_sdo::VendorSdoJson;
use crate::decode::{Body, Decoded};
use crate::frame::json::{Stacked, push_hex, push_prefixed_str, push_str, push_text, push_u64};
use crate::frame::{Flags, Frame, Interfaces};
use crate::od::MappingSource;
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
/// The record's own fields and the `pdo` and `sdo` objects are written directly (this is
/// the hot path of `cotui decode --format jsonl`); the other kinds' objects go through serde.
pub fn write_frame(out: &mut Vec<u8>, line: u64, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    let start = out.len();
    let mut st = Stacked::default();
    st.lit(b"{\"line\":");
    st.u64(line);
    st.lit(b",\"t\":");
    st.seconds(frame.ts_ns);
    st.lit(b",\"iface\":");
    let name = ifaces.name(frame.iface);
    if !(name.len() <= 32 && st.plain_text(name)) {
        st.flush(out);
        push_text(out, name);
    }
    st.lit(b",\"id\":");
    st.u64(frame.id.into());
    st.flag(b",\"ext\":", frame.is_ext());
    st.flag(b",\"rtr\":", frame.is_rtr());
    st.flag(b",\"fd\":", frame.is_fd());
    st.flag(b",\"err\":", frame.is_err());
    st.lit(b",\"len\":");
    st.u64(frame.len.into());
    st.lit(b",\"data\":");
    st.hex(frame.payload());
    st.lit(if frame.flags.has(Flags::TX) {
        b",\"dir\":\"tx\""
    } else {
        b",\"dir\":\"rx\""
    });
    st.lit(b",\"kind\":\"");
    st.bytes(decoded.kind.as_str().as_bytes());
    st.lit(b"\",\"node\":");
    match decoded.node {
        Some(n) => st.u64(n.into()),
        None => st.lit(b"null"),
    }
    st.lit(b",\"label\":");
    st.flush(out);
    push_text(out, &decoded.label);
    if let Body::Pdo(p) = &decoded.body {
        // The most frequent kinds are written directly (as serde would write them).
        out.extend_from_slice(b",\"pdo\":");
        write_pdo(out, p);
    } else if let Body::Sdo(s) = &decoded.body {
        out.extend_from_slice(b",\"sdo\":");
        write_sdo(out, &s.to_json());
    } else if let Some(body) = BodyJson::new(decoded, frame) {
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

/// Appends the `pdo` object, byte for byte as serde writes [`PdoJson`].
fn write_pdo(out: &mut Vec<u8>, p: &Pdo) {
    out.extend_from_slice(b"{\"mapping_source\":");
    match &p.source {
        None => out.extend_from_slice(b"null"),
        Some(MappingSource::Profile(name)) => push_prefixed_str(out, "profile ", name),
        Some(MappingSource::Eds(file)) => push_prefixed_str(out, "eds ", file),
        Some(source) => push_str(out, &source_text(source)),
    }
    out.extend_from_slice(b",\"num\":");
    push_u64(out, p.num.into());
    out.extend_from_slice(b",\"signals\":[");
    for (i, s) in p.signals.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        out.extend_from_slice(b"{\"index\":");
        push_u64(out, s.index.into());
        out.extend_from_slice(b",\"name\":");
        push_str(out, &s.name);
        out.extend_from_slice(b",\"sub\":");
        push_u64(out, s.sub.into());
        out.extend_from_slice(b",\"text\":");
        push_str(out, &s.text);
        out.extend_from_slice(b",\"value\":");
        s.value.push_json(out);
        out.push(b'}');
    }
    out.extend_from_slice(b"]}");
}

/// Appends the `sdo` object, byte for byte as serde writes [`SdoJson`] (fields in its order,
/// the optional ones only when set).
fn write_sdo(out: &mut Vec<u8>, j: &SdoJson) {
    out.extend_from_slice(b"{\"abort_code\":");
    match j.abort_code {
        Some(c) => push_u64(out, c.into()),
        None => out.extend_from_slice(b"null"),
    }
    out.extend_from_slice(b",\"abort_text\":");
    match j.abort_text {
        Some(t) => push_str(out, t),
        None => out.extend_from_slice(b"null"),
    }
    push_opt_u64(out, b",\"ackseq\":", j.ackseq.map(u64::from));
    push_opt_u64(out, b",\"blksize\":", j.blksize.map(u64::from));
    if let Some(step) = j.block_step {
        out.extend_from_slice(b",\"block_step\":");
        push_str(out, step);
    }
    push_opt_u64(out, b",\"command\":", j.command.map(u64::from));
    push_opt_u64(out, b",\"crc\":", j.crc.map(u64::from));
    if let Some(v) = j.crc_supported {
        push_flag(out, b",\"crc_supported\":", v);
    }
    out.extend_from_slice(b",\"cs\":");
    push_str(out, j.cs);
    if let Some(data) = j.data {
        out.extend_from_slice(b",\"data\":");
        push_hex(out, data.0);
    }
    if let Some(v) = j.expedited {
        push_flag(out, b",\"expedited\":", v);
    }
    out.extend_from_slice(b",\"index\":");
    match j.index {
        Some(i) => push_u64(out, i.into()),
        None => out.extend_from_slice(b"null"),
    }
    if let Some(v) = j.last {
        push_flag(out, b",\"last\":", v);
    }
    push_flag(out, b",\"malformed\":", j.malformed);
    if let Some(r) = j.malformed_reason {
        out.extend_from_slice(b",\"malformed_reason\":");
        push_str(out, r);
    }
    if let Some(n) = j.name {
        out.extend_from_slice(b",\"name\":");
        push_str(out, n);
    }
    if let Some(problems) = j.problems {
        out.extend_from_slice(b",\"problems\":[");
        for (i, p) in problems.iter().enumerate() {
            if i > 0 {
                out.push(b',');
            }
            push_str(out, p);
        }
        out.push(b']');
    }
    push_opt_u64(out, b",\"pst\":", j.pst.map(u64::from));
    push_opt_u64(out, b",\"seqno\":", j.seqno.map(u64::from));
    out.extend_from_slice(b",\"side\":");
    push_str(out, j.side);
    if let Some(size) = j.size {
        out.extend_from_slice(b",\"size\":");
        match size {
            Some(n) => push_u64(out, n.into()),
            None => out.extend_from_slice(b"null"),
        }
    }
    out.extend_from_slice(b",\"sub\":");
    match j.sub {
        Some(s) => push_u64(out, s.into()),
        None => out.extend_from_slice(b"null"),
    }
    push_opt_u64(out, b",\"toggle\":", j.toggle.map(u64::from));
    push_opt_u64(out, b",\"unused\":", j.unused.map(u64::from));
    // Typed values and structured parts are rarer: serde writes them.
    if let Some(v) = j.value {
        out.extend_from_slice(b",\"value\":");
        let _ = serde_json::to_writer(&mut *out, v);
    }
    if let Some(parts) = j.value_parts {
        out.extend_from_slice(b",\"value_parts\":");
        let _ = serde_json::to_writer(&mut *out, parts);
    }
    if let Some(t) = j.value_text {
        out.extend_from_slice(b",\"value_text\":");
        push_str(out, t);
    }
    out.push(b'}');
}

/// Appends `key` and `v` when `v` is set.
fn push_opt_u64(out: &mut Vec<u8>, key: &[u8], v: Option<u64>) {
    if let Some(v) = v {
        out.extend_from_slice(key);
        push_u64(out, v);
    }
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

    /// The directly written `pdo` object is what serde writes for [`PdoJson`].
    #[test]
    fn pdo_object_as_serde_writes_it() {
        use crate::decode::pdo::Signal;
        use crate::od::Value;
        let sig = |name: &str, text: &str, value: Value| Signal {
            index: 0x6041,
            sub: 0,
            bit: 0,
            bits: 16,
            name: name.into(),
            value,
            text: text.into(),
        };
        let sources = [
            None,
            Some(MappingSource::Profile("syntron-ds".into())),
            Some(MappingSource::Eds("a\"b.eds".into())),
            Some(MappingSource::Sniffed { ts_ns: 12_345_678_901 }),
        ];
        for source in sources {
            let p = Pdo {
                num: 3,
                transmit: true,
                signals: vec![
                    sig("Statusword", "0x0237 (Operation enabled)", Value::Unsigned(567)),
                    sig("Velo\tcity", "-1.5 rpm", Value::Float(-1.5)),
                    sig("Name", "\"x\"", Value::Text("x\u{8}".into())),
                ],
                source,
            };
            let mut direct = Vec::new();
            write_pdo(&mut direct, &p);
            assert_eq!(
                String::from_utf8(direct).unwrap(),
                serde_json::to_string(&p.to_json()).unwrap()
            );
        }
    }

    /// The directly written `sdo` object is what serde writes for [`SdoJson`], for frames
    /// of every command with and without tracker and dictionary additions.
    #[test]
    fn sdo_object_as_serde_writes_it() {
        use crate::decode::sdo::SdoFrame;
        use crate::decode::sdo::value::view;
        use crate::sdo::codec::Side;
        let dict = crate::od::Dictionary::default();
        let frames: [(Side, &[u8]); 14] = [
            (Side::Client, &[0x2B, 0x40, 0x60, 0x00, 0x06, 0x00, 0, 0]),
            (Side::Client, &[0x21, 0x08, 0x10, 0x00, 0x07, 0, 0, 0]),
            (Side::Server, &[0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0]),
            (Side::Client, &[0x00, b'D', b'E', b'X', b'"', 0, 0, 0]),
            (Side::Server, &[0x43, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]),
            (Side::Server, &[0x80, 0x00, 0x20, 0x01, 0x11, 0x00, 0x09, 0x06]),
            (Side::Client, &[0xC6, 0x00, 0x20, 0x00, 0x10, 0, 0, 0]),
            (Side::Server, &[0xA4, 0x00, 0x20, 0x00, 0x7F, 0, 0, 0]),
            (Side::Server, &[0xA2, 0x05, 0x7F, 0, 0, 0, 0, 0]),
            (Side::Client, &[0xC9, 0x34, 0x12, 0, 0, 0, 0, 0]),
            (Side::Client, &[0xA4, 0x00, 0x20, 0x00, 0x20, 0x00, 0, 0]),
            (Side::Client, &[0xE0, 0, 0, 0, 0, 0, 0, 0]),
            (Side::Client, &[0x2B, 0x40, 0x60]),
            (Side::Server, &[0x10, 0x08, 0x10, 0x00, 0, 0, 0, 0]),
        ];
        for (side, payload) in frames {
            let mut f = SdoFrame::new(side, payload, false);
            let mut variants = vec![f.clone()];
            f.name = Some("Controlword \"x\"".into());
            f.problems = vec!["toggle error".into(), "b\\c".into()];
            if let (Some((index, sub)), Some(data)) = (f.object, f.command.data()) {
                f.value = Some(view(&dict, index, sub, data));
            }
            variants.push(f);
            for f in variants {
                let mut direct = Vec::new();
                write_sdo(&mut direct, &f.to_json());
                assert_eq!(
                    String::from_utf8(direct).unwrap(),
                    serde_json::to_string(&f.to_json()).unwrap(),
                    "{f:?}"
                );
            }
        }
        let structured = view(&dict, 0x1018, 1, &[0x11, 0x22, 0, 0]);
        let mut f = SdoFrame::new(Side::Server, &[0x43, 0x18, 0x10, 0x01, 0x11, 0x22, 0, 0], false);
        f.value = Some(structured);
        let mut direct = Vec::new();
        write_sdo(&mut direct, &f.to_json());
        assert_eq!(
            String::from_utf8(direct).unwrap(),
            serde_json::to_string(&f.to_json()).unwrap()
        );
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
