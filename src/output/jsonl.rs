//! The JSONL contract: one JSON object per frame (field names are a public API).

use crate::decode::{Body, Decoded};
use crate::frame::{Frame, Interfaces};

/// The JSON object for one frame read from input line `line`.
pub fn frame_json(line: u64, frame: &Frame, ifaces: &Interfaces, decoded: &Decoded) -> serde_json::Value {
    let mut o = serde_json::Map::with_capacity(16);
    o.insert("line".into(), line.into());
    o.insert("t".into(), frame.seconds().into());
    o.insert("iface".into(), ifaces.name(frame.iface).into());
    o.insert("id".into(), frame.id.into());
    o.insert("ext".into(), frame.is_ext().into());
    o.insert("rtr".into(), frame.is_rtr().into());
    o.insert("fd".into(), frame.is_fd().into());
    o.insert("err".into(), frame.is_err().into());
    o.insert("len".into(), frame.len.into());
    o.insert("data".into(), crate::hex::upper(frame.payload()).into());
    o.insert(
        "dir".into(),
        if frame.flags.has(crate::frame::Flags::TX) {
            "tx"
        } else {
            "rx"
        }
        .into(),
    );
    o.insert("kind".into(), decoded.kind.as_str().into());
    o.insert(
        "node".into(),
        decoded
            .node
            .map(serde_json::Value::from)
            .unwrap_or(serde_json::Value::Null),
    );
    o.insert("label".into(), decoded.label.clone().into());
    let (key, value) = match &decoded.body {
        Body::None => ("", serde_json::Value::Null),
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
    };
    if !key.is_empty() {
        o.insert(key.into(), value);
    }
    if let Some(m) = &decoded.malformed {
        o.insert("malformed".into(), m.clone().into());
    }
    serde_json::Value::Object(o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;
    use crate::od::Dictionary;
    use serde_json::json;

    #[test]
    fn contract_fields() {
        let mut ifaces = Interfaces::default();
        ifaces.intern("can0");
        let mut f = Frame::classic(0x000, &[0x81, 0x00]);
        f.ts_ns = 1_500_000_000;
        let d = Decoder::new(Dictionary::default(), vec![]).decode(&f);
        let j = frame_json(7, &f, &ifaces, &d);
        assert_eq!(j["line"], 7);
        assert_eq!(j["t"], 1.5);
        assert_eq!(j["iface"], "can0");
        assert_eq!(j["id"], 0);
        assert_eq!(j["ext"], false);
        assert_eq!(j["len"], 2);
        assert_eq!(j["data"], "8100");
        assert_eq!(j["kind"], "nmt");
        assert_eq!(j["node"], json!(null));
        assert_eq!(j["nmt"], json!({"command": "reset_node", "target": 0}));
        assert_eq!(j["label"], "NMT Reset node -> all nodes");
        assert!(j.get("malformed").is_none());
    }
}
