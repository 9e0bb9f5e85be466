//! How an object value is shown wherever it appears (SDO or PDO): CiA 402
//! meaning, communication parameter meaning, else enum text / scaled value.

use crate::od::{Dictionary, Value, format_value};

/// The text of `value` of object (index, sub) on a node with dictionary `dict`
/// and mode of operation `mode`.
pub fn object_text(dict: &Dictionary, index: u16, sub: u8, value: &Value, mode: Option<i8>) -> String {
    if let Some(raw) = value.as_i64() {
        if let Some(t) = super::cia402::value_text(index, sub, raw, mode, dict.object(index, sub)) {
            return t;
        }
        if let Some(t) = super::comm_params::describe(index, sub, raw as u64, dict) {
            return t;
        }
    }
    format_value(dict.object(index, sub), value)
}
