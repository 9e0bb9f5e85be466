//! A reassembled SDO transfer as the trace shows it: label and JSON, values typed
//! through the dictionary. The transfer itself is [`crate::sdo::transaction`].

use super::value::{ValueView, view_in_mode};
use crate::decode::value_text::ValuePart;
use crate::frame::json::Hex;
use crate::od::Dictionary;
use crate::sdo::transaction::{Outcome, Protocol, Transaction, TransferDirection};
use serde::Serialize;

impl Transaction {
    /// One-line label, e.g.
    /// `Upload 0x1008:00 Manufacturer device name = "DEXMART" (segmented, 7 bytes, 1.200 ms): ok`.
    pub fn label(&self, dict: &Dictionary) -> String {
        let mut s = String::new();
        self.write_label(&mut s, dict);
        s
    }

    /// Appends [`Transaction::label`] to `s`.
    pub fn write_label(&self, s: &mut String, dict: &Dictionary) {
        // Writing into a String cannot fail.
        let _ = self.write_label_fmt(s, dict);
    }

    fn write_label_fmt(&self, s: &mut String, dict: &Dictionary) -> std::fmt::Result {
        use std::fmt::Write;
        s.push_str(match self.direction {
            TransferDirection::Upload => "Upload",
            TransferDirection::Download => "Download",
        });
        let partial = self.is_partial();
        if partial {
            s.push_str(" (object not captured)");
        } else {
            write!(s, " 0x{:04X}:{:02X}", self.index, self.sub)?;
            if let Some(name) = dict.label_name(self.index, self.sub) {
                s.push(' ');
                s.push_str(&name);
            }
        }
        if self.outcome == Outcome::Ok && !self.data.is_empty() && !partial {
            let v = view_in_mode(dict, self.index, self.sub, &self.data, self.mode);
            s.push_str(" = ");
            match v.text.char_indices().nth(80) {
                Some(_) => {
                    let cut = v.text.char_indices().nth(77).map_or(v.text.len(), |(i, _)| i);
                    s.push_str(&v.text[..cut]);
                    s.push_str("...");
                }
                None => s.push_str(&v.text),
            }
        }
        let n = self.len();
        s.push_str(" (");
        if self.protocol != Protocol::Unknown {
            s.push_str(self.protocol.as_str());
            s.push_str(", ");
        }
        // Cut short: `7 of 64 bytes`, the count then the size the initiate announced.
        let last = match self.cut_short_of() {
            Some(size) => {
                write!(s, "{n} of {size}")?;
                size as usize
            }
            None => {
                write!(s, "{n}")?;
                n
            }
        };
        s.push_str(if last == 1 { " byte" } else { " bytes" });
        if partial {
            s.push_str(" seen");
        }
        if self.dropped > 0 {
            write!(s, ", first {} kept", self.data.len())?;
        }
        write!(s, ", {:.3} ms): ", self.duration_ns() as f64 / 1e6)?;
        match &self.outcome {
            Outcome::Ok => s.push_str("ok"),
            Outcome::Aborted { code, text, by } => write!(s, "aborted by {}: 0x{code:08X} {text}", by.as_str())?,
            Outcome::Incomplete => s.push_str("incomplete"),
            Outcome::ProtocolError(e) => write!(s, "protocol error: {e}")?,
        }
        for p in &self.problems {
            write!(s, " [{p}]")?;
        }
        Ok(())
    }

    /// The JSONL record of `--transactions --format jsonl`: the object, name, typed value,
    /// hex data, timing, outcome and problems.
    pub fn to_json<'a>(&'a self, dict: &'a Dictionary) -> TransactionJson<'a> {
        let partial = self.is_partial();
        let value = (!self.data.is_empty() && !partial)
            .then(|| view_in_mode(dict, self.index, self.sub, &self.data, self.mode));
        let (abort_code, abort_text, aborted_by, error) = match &self.outcome {
            Outcome::Aborted { code, text, by } => (Some(*code), Some(*text), Some(by.as_str()), None),
            Outcome::ProtocolError(e) => (None, None, None, Some(e.as_str())),
            _ => (None, None, None, None),
        };
        TransactionJson {
            abort_code,
            abort_text,
            aborted_by,
            data: Hex(&self.data),
            direction: self.direction.as_str(),
            duration_ns: self.duration_ns(),
            end_ns: self.end_ns,
            error,
            frames: &self.frames,
            iface: None,
            index: (!partial).then_some(self.index),
            len: self.len(),
            name: if partial { None } else { dict.name(self.index, self.sub) },
            node: self.node,
            outcome: self.outcome.as_str(),
            partial,
            problems: self
                .problems
                .iter()
                .map(|p| ProblemJson {
                    kind: p.as_str(),
                    text: p.to_string(),
                })
                .collect(),
            protocol: self.protocol.as_str(),
            request_cob: self.channel.request_cob,
            response_cob: self.channel.response_cob,
            size: self.size,
            size_announced: self.cut_short_of(),
            start_ns: self.start_ns,
            sub: (!partial).then_some(self.sub),
            value_text: value.as_ref().map(|v| v.text.clone()),
            value_parts: value.as_ref().map_or_else(Vec::new, |v| v.parts.clone()),
            value,
        }
    }
}

/// One SDO transaction as a JSONL record (fields in key order). `index`, `sub` and `name`
/// are null for a transfer seen only in part; the abort fields and `error` are null unless
/// it ended that way.
#[derive(Clone, Debug, Serialize)]
pub struct TransactionJson<'a> {
    pub abort_code: Option<u32>,
    pub abort_text: Option<&'static str>,
    /// `client` or `server`.
    pub aborted_by: Option<&'static str>,
    pub data: Hex<'a>,
    pub direction: &'static str,
    pub duration_ns: u64,
    pub end_ns: u64,
    /// What broke the protocol.
    pub error: Option<&'a str>,
    /// Sequence numbers of the frames (the first ones).
    pub frames: &'a [u64],
    /// The interface it ran on, only when the input has several interfaces.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iface: Option<&'a str>,
    pub index: Option<u16>,
    pub len: usize,
    pub name: Option<&'a str>,
    pub node: u8,
    pub outcome: &'static str,
    pub partial: bool,
    pub problems: Vec<ProblemJson>,
    pub protocol: &'static str,
    pub request_cob: u32,
    pub response_cob: u32,
    pub size: Option<u32>,
    /// The size the initiate announced, on a transfer that ended before that many bytes
    /// came (`len` of them did); left out otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size_announced: Option<u32>,
    pub start_ns: u64,
    pub sub: Option<u8>,
    /// The typed value (`null` without data or for a partial transfer).
    #[serde(serialize_with = "view_json")]
    pub value: Option<ValueView>,
    /// The fields of a structured value (`name`, `raw`, `text`), left out when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub value_parts: Vec<ValuePart>,
    pub value_text: Option<String>,
}

/// The JSON value of a [`ValueView`], `null` without one.
fn view_json<S: serde::Serializer>(v: &Option<ValueView>, s: S) -> Result<S::Ok, S::Error> {
    v.as_ref().map(|v| &v.json).serialize(s)
}

/// One problem of [`TransactionJson`].
#[derive(Clone, Debug, Serialize)]
pub struct ProblemJson {
    /// Its name, e.g. `toggle_error`.
    pub kind: &'static str,
    /// Its text.
    pub text: String,
}
