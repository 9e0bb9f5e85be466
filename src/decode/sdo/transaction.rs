//! A reassembled SDO transfer as the trace shows it: label and JSON, values typed
//! through the dictionary.

use super::value::view_in_mode;
use crate::frame::hex;
use crate::od::Dictionary;
use crate::sdo::transaction::{Outcome, Protocol, Transaction, TransferDirection};
use serde_json::{Value as Json, json};

impl Transaction {
    /// One-line label, e.g.
    /// `Upload 0x1008:00 Manufacturer device name = "DEXMART" (segmented, 7 bytes, 1.200 ms): ok`.
    pub fn label(&self, dict: &Dictionary) -> String {
        let dir = match self.direction {
            TransferDirection::Upload => "Upload",
            TransferDirection::Download => "Download",
        };
        let partial = self.is_partial();
        let mut s = if partial {
            format!("{dir} (object not captured)")
        } else {
            format!("{dir} 0x{:04X}:{:02X}", self.index, self.sub)
        };
        if let Some(name) = dict.label_name(self.index, self.sub).filter(|_| !partial) {
            s.push(' ');
            s.push_str(&name);
        }
        if self.outcome == Outcome::Ok && !self.data.is_empty() && !partial {
            let v = view_in_mode(dict, self.index, self.sub, &self.data, self.mode);
            let text: String = if v.text.chars().count() > 80 {
                v.text.chars().take(77).chain("...".chars()).collect()
            } else {
                v.text
            };
            s.push_str(" = ");
            s.push_str(&text);
        }
        let n = self.len();
        s.push_str(" (");
        if self.protocol != Protocol::Unknown {
            s.push_str(self.protocol.as_str());
            s.push_str(", ");
        }
        let plural = if n == 1 { "" } else { "s" };
        let seen = if partial { " seen" } else { "" };
        let kept = if self.dropped > 0 {
            format!(", first {} kept", self.data.len())
        } else {
            String::new()
        };
        s.push_str(&format!(
            "{n} byte{plural}{seen}{kept}, {:.3} ms): ",
            self.duration_ns() as f64 / 1e6
        ));
        match &self.outcome {
            Outcome::Ok => s.push_str("ok"),
            Outcome::Aborted { code, text, by } => {
                s.push_str(&format!("aborted by {}: 0x{code:08X} {text}", by.as_str()))
            }
            Outcome::Incomplete => s.push_str("incomplete"),
            Outcome::ProtocolError(e) => s.push_str(&format!("protocol error: {e}")),
        }
        for p in &self.problems {
            s.push_str(&format!(" [{p}]"));
        }
        s
    }

    /// JSON object with the object, name, typed value, hex data, timing, outcome and problems.
    pub fn to_json(&self, dict: &Dictionary) -> Json {
        let partial = self.is_partial();
        let v = (!self.data.is_empty() && !partial)
            .then(|| view_in_mode(dict, self.index, self.sub, &self.data, self.mode));
        let (index, sub) = if partial {
            (Json::Null, Json::Null)
        } else {
            (Json::from(self.index), Json::from(self.sub))
        };
        let (code, text, by, error) = match &self.outcome {
            Outcome::Aborted { code, text, by } => (
                Json::from(*code),
                Json::from(*text),
                Json::from(by.as_str()),
                Json::Null,
            ),
            Outcome::ProtocolError(e) => (Json::Null, Json::Null, Json::Null, Json::from(e.clone())),
            _ => (Json::Null, Json::Null, Json::Null, Json::Null),
        };
        json!({
            "node": self.node,
            "request_cob": self.channel.request_cob,
            "response_cob": self.channel.response_cob,
            "index": index,
            "sub": sub,
            "name": if partial { None } else { dict.name(self.index, self.sub) },
            "partial": partial,
            "direction": self.direction.as_str(),
            "protocol": self.protocol.as_str(),
            "size": self.size,
            "data": hex::upper(&self.data),
            "len": self.len(),
            "value": v.as_ref().map_or(Json::Null, |v| v.json.clone()),
            "value_text": v.as_ref().map(|v| v.text.clone()),
            "start_ns": self.start_ns,
            "end_ns": self.end_ns,
            "duration_ns": self.duration_ns(),
            "outcome": self.outcome.as_str(),
            "abort_code": code,
            "abort_text": text,
            "aborted_by": by,
            "error": error,
            "problems": self.problems.iter().map(|p| json!({"kind": p.as_str(), "text": p.to_string()})).collect::<Vec<_>>(),
            "frames": self.frames,
        })
    }
}
