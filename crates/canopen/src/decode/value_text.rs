//! How an object value is shown wherever it appears (SDO or PDO): CiA 402
//! meaning, communication parameter meaning, else enum text / scaled value.

use crate::od::{Dictionary, Meaning, ObjectInfo, Value, format_value};
use serde::Serialize;

/// The text of `value` of object (index, sub) on a node with dictionary `dict`
/// and mode of operation `mode`.
pub fn object_text(dict: &Dictionary, index: u16, sub: u8, value: &Value, mode: Option<i8>) -> String {
    object_text_of(dict, dict.object(index, sub), index, sub, value, mode)
}

/// [`object_text`] for a caller that has looked up the object's entry, `info`
/// (`dict.object(index, sub)`), already: one dictionary lookup instead of three.
pub(crate) fn object_text_of(
    dict: &Dictionary,
    info: Option<&ObjectInfo>,
    index: u16,
    sub: u8,
    value: &Value,
    mode: Option<i8>,
) -> String {
    if let Some(raw) = value.as_i64() {
        if let Some(t) = super::cia402::value_text(index, sub, raw, mode, info) {
            return t;
        }
        if let Some(t) = super::comm_params::describe(index, sub, raw as u64, dict) {
            return t;
        }
        if let Some(info) = info {
            if let Some(m) = info.meaning {
                return meaning_text(dict, m, raw);
            }
            if !info.fields.is_empty() {
                return split(dict, info, raw);
            }
        }
    }
    format_value(info, value)
}

/// A vendor object's raw value read as the CiA 301 parameter it configures.
fn meaning_text(dict: &Dictionary, meaning: Meaning, raw: i64) -> String {
    use super::comm_params::{cob_id, transmission_type};
    match meaning {
        Meaning::CobId => cob_id(raw as u32, ""),
        Meaning::TransmissionType => transmission_type(raw as u32),
        Meaning::ObjectIndex => {
            let index = raw as u16;
            match dict.object_name(index) {
                Some(name) => format!("{raw} (0x{index:04X} {name})"),
                None => format!("{raw} (0x{index:04X})"),
            }
        }
    }
}

/// One field of a structured value: 0x1016's node-ID and time, 0x1003's error code and
/// manufacturer bytes (JSON `value_parts`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ValuePart {
    /// The field's name, e.g. `node`, `time`, `error code`.
    pub name: String,
    /// Its raw value.
    pub raw: i64,
    /// Its value as shown: `100 ms`, `0x2310 Continuous over-current`.
    pub text: String,
}

/// The fields of object (index, sub) holding `raw`, empty when the dictionary does not
/// describe the object as structured.
pub fn parts(dict: &Dictionary, index: u16, sub: u8, raw: i64) -> Vec<ValuePart> {
    dict.object(index, sub)
        .map_or_else(Vec::new, |info| fields_of(dict, info, raw))
}

fn fields_of(dict: &Dictionary, info: &ObjectInfo, raw: i64) -> Vec<ValuePart> {
    let bytes = raw.to_le_bytes();
    info.fields
        .iter()
        .filter_map(|f| {
            let v = f.raw(&bytes)?;
            let text = if f.emcy {
                let code = v as u16;
                let text = dict.emcy_text(code).unwrap_or_else(|| super::emcy::code_text(code));
                format!("0x{code:04X} {text}")
            } else {
                f.format(v)
            };
            Some(ValuePart {
                name: f.name.clone(),
                raw: v,
                text,
            })
        })
        .collect()
}

/// A structured value split into its fields: `0x00020064 (node 2, time 100 ms)`,
/// `0x00052310 (error code 0x2310 Continuous over-current, M1 alarm 0x05, M2 alarm 0x00)`.
fn split(dict: &Dictionary, info: &ObjectInfo, raw: i64) -> String {
    let parts: Vec<String> = fields_of(dict, info, raw)
        .into_iter()
        .map(|p| format!("{} {}", p.name, p.text))
        .collect();
    let width = 2 * info.data_type.size().unwrap_or(4);
    let masked = if width >= 16 {
        raw as u64
    } else {
        raw as u64 & ((1u64 << (4 * width)) - 1)
    };
    format!("0x{masked:0width$X} ({})", parts.join(", "))
}
