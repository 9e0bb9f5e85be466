//! Object values as SDO labels and JSON show them, typed through the dictionary.

use crate::decode::value_text::ValuePart;
use crate::frame::hex;
use crate::od::{Dictionary, Value};

/// A value ready for a label and for JSON.
#[derive(Clone, Debug, PartialEq)]
pub struct ValueView {
    /// Label text, e.g. `6 (Shutdown)`, `1500 rpm`, `"DEXMART "` or `B8 0B (3000)`.
    pub text: String,
    /// JSON value: typed when the dictionary knows the object, else the
    /// little-endian integer of 1-4 bytes, else the hex string.
    pub json: serde_json::Value,
    /// The typed value when the dictionary knows the object.
    pub typed: Option<Value>,
    /// Byte count the object's type expects, when it has a fixed size that
    /// differs from the bytes seen.
    pub type_len_mismatch: Option<usize>,
    /// The fields of a structured value (0x1016, 0x1003, ...), empty for others.
    pub parts: Vec<ValuePart>,
}

/// Little-endian unsigned integer of 1-4 bytes.
pub(crate) fn le_uint(bytes: &[u8]) -> Option<u32> {
    if bytes.is_empty() || bytes.len() > 4 {
        return None;
    }
    Some(bytes.iter().rev().fold(0u32, |acc, b| (acc << 8) | *b as u32))
}

/// Types `bytes` through the dictionary entry of (index, sub).
pub fn view(dict: &Dictionary, index: u16, sub: u8, bytes: &[u8]) -> ValueView {
    view_in_mode(dict, index, sub, bytes, None)
}

/// [`view`] with the node's mode of operation, which names controlword/statusword bits.
pub(crate) fn view_in_mode(dict: &Dictionary, index: u16, sub: u8, bytes: &[u8], mode: Option<i8>) -> ValueView {
    if let Some(info) = dict.object(index, sub) {
        let size = info.data_type.size();
        let take = size.map_or(bytes.len(), |n| n.min(bytes.len()));
        let typed = info.data_type.decode(&bytes[..take]);
        return ValueView {
            text: crate::decode::value_text::object_text_of(dict, Some(info), index, sub, &typed, mode),
            json: typed.to_json(),
            parts: typed
                .as_i64()
                .map_or_else(Vec::new, |raw| crate::decode::value_text::parts(dict, index, sub, raw)),
            typed: Some(typed),
            type_len_mismatch: size.filter(|n| *n != bytes.len()),
        };
    }
    match le_uint(bytes) {
        Some(n) => ValueView {
            text: crate::decode::cia402::value_text(index, sub, n as i64, mode, None)
                .or_else(|| crate::decode::comm_params::describe(index, sub, n as u64, dict))
                .unwrap_or_else(|| format!("{} ({n})", hex::spaced(bytes))),
            json: n.into(),
            typed: None,
            type_len_mismatch: None,
            parts: Vec::new(),
        },
        None => ValueView {
            text: hex::spaced(bytes),
            json: hex::upper(bytes).into(),
            typed: None,
            type_len_mismatch: None,
            parts: Vec::new(),
        },
    }
}

/// Segment bytes for a label: quoted text when all printable ASCII, else spaced hex.
pub(crate) fn segment_text(bytes: &[u8]) -> String {
    if !bytes.is_empty() && bytes.iter().all(|b| (0x20..0x7F).contains(b)) {
        format!("\"{}\"", bytes.iter().map(|b| *b as char).collect::<String>())
    } else {
        hex::spaced(bytes)
    }
}
