//! The JSONL contract: one JSON object per frame (field names are a public API).
//!
//! The common fields are written straight into the output buffer (this is the
//! hot path of `cotui decode --format jsonl`); kind-specific objects come from
//! each decoder's `to_json`.

use crate::decode::{Body, Decoded};
use crate::frame::{Flags, Frame, Interfaces};
use std::fmt::Write;

/// Appends a JSON string literal: unescaped runs are copied whole (escapes are ASCII,
/// so every cut falls on a char boundary).
fn push_str_lit(out: &mut String, s: &str) {
    out.push('"');
    let mut from = 0;
    for (i, b) in s.bytes().enumerate() {
        let escape = match b {
            b'"' => "\\\"",
            b'\\' => "\\\\",
            b'\n' => "\\n",
            b'\r' => "\\r",
            b'\t' => "\\t",
            0..0x20 => "",
            _ => continue,
        };
        out.push_str(&s[from..i]);
        if escape.is_empty() {
            let _ = write!(out, "\\u{b:04x}");
        } else {
            out.push_str(escape);
        }
        from = i + 1;
    }
    out.push_str(&s[from..]);
    out.push('"');
}

fn push_bool(out: &mut String, key: &str, v: bool) {
    out.push_str(key);
    out.push_str(if v { "true" } else { "false" });
}

/// The kind-specific object of a decoded frame: its JSON key and value.
pub fn body_json(decoded: &Decoded, frame: &Frame) -> Option<(&'static str, serde_json::Value)> {
    Some(match &decoded.body {
        Body::None => return None,
        Body::Nmt(n) => ("nmt", n.to_json()),
        Body::Heartbeat(h) => ("heartbeat", h.to_json()),
        Body::Sync(s) => ("sync", s.to_json()),
        Body::Time(t) => ("time", t.to_json()),
        Body::Emcy(e) => ("emcy", e.to_json()),
        Body::Pdo(p) => ("pdo", p.to_json()),
        Body::Sdo(s) => ("sdo", s.to_json()),
        Body::Lss(l) => ("lss", l.to_json()),
        Body::VendorSdo(v) => ("vendor_sdo", v.to_json()),
        Body::ErrorFrame { class } => ("error", crate::decode::error_frame::to_json(*class, frame.payload())),
    })
}

/// Appends the JSON object (and a newline) for one frame read from input line `line`.
pub fn write_frame(out: &mut String, line: u64, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) {
    let secs = frame.ts_ns / 1_000_000_000;
    let frac = frame.ts_ns % 1_000_000_000;
    let _ = write!(out, "{{\"line\":{line},\"t\":{secs}.{frac:09},\"iface\":");
    push_str_lit(out, ifaces.name(frame.iface));
    let _ = write!(out, ",\"id\":{}", frame.id);
    push_bool(out, ",\"ext\":", frame.is_ext());
    push_bool(out, ",\"rtr\":", frame.is_rtr());
    push_bool(out, ",\"fd\":", frame.is_fd());
    push_bool(out, ",\"err\":", frame.is_err());
    let _ = write!(out, ",\"len\":{},\"data\":\"", frame.len);
    crate::frame::hex::push_upper(out, frame.payload());
    out.push_str("\",\"dir\":");
    out.push_str(if frame.flags.has(Flags::TX) { "\"tx\"" } else { "\"rx\"" });
    out.push_str(",\"kind\":\"");
    out.push_str(decoded.kind.as_str());
    out.push_str("\",\"node\":");
    match decoded.node {
        Some(n) => {
            let _ = write!(out, "{n}");
        }
        None => out.push_str("null"),
    }
    out.push_str(",\"label\":");
    push_str_lit(out, &decoded.label);
    if let Some((key, value)) = body_json(decoded, frame) {
        // serde_json writes to a byte buffer much faster than through `Display`.
        if let Ok(text) = serde_json::to_string(&value) {
            let _ = write!(out, ",\"{key}\":");
            out.push_str(&text);
        }
    }
    if let Some(m) = &decoded.malformed {
        out.push_str(",\"malformed\":");
        push_str_lit(out, m);
    }
    out.push_str("}\n");
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
        let mut s = String::new();
        write_frame(&mut s, line, frame, &ifaces, &d);
        assert!(s.ends_with("}\n"));
        serde_json::from_str(&s).expect("valid JSON")
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
        let mut s = String::new();
        push_str_lit(&mut s, "a\"b\\c\u{1}");
        assert_eq!(s, r#""a\"b\\c\u0001""#);
        s.clear();
        push_str_lit(&mut s, "µ\tz\n°");
        assert_eq!(s, r#""µ\tz\n°""#);
    }
}
