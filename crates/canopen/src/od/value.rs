//! CANopen data types and decoded values.

use serde::{Serialize, Serializer};
use std::fmt;

/// CiA 301 basic data types (codes 0x0001..0x001B) we decode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DataType {
    Boolean,
    I8,
    I16,
    I24,
    I32,
    I40,
    I48,
    I56,
    I64,
    U8,
    U16,
    U24,
    U32,
    U40,
    U48,
    U56,
    U64,
    F32,
    F64,
    VisibleString,
    OctetString,
    UnicodeString,
    TimeOfDay,
    TimeDifference,
    #[default]
    Domain,
}

impl DataType {
    /// Size in bytes of fixed-size types; `None` for strings and domains.
    pub fn size(self) -> Option<usize> {
        use DataType::*;
        Some(match self {
            Boolean | I8 | U8 => 1,
            I16 | U16 => 2,
            I24 | U24 => 3,
            I32 | U32 | F32 => 4,
            I40 | U40 => 5,
            I48 | U48 | TimeOfDay | TimeDifference => 6,
            I56 | U56 => 7,
            I64 | U64 | F64 => 8,
            VisibleString | OctetString | UnicodeString | Domain => return None,
        })
    }

    /// The type for a CiA 301 DataType code (as in EDS `DataType=0x0007`).
    pub fn from_code(code: u16) -> Option<DataType> {
        use DataType::*;
        Some(match code {
            0x01 => Boolean,
            0x02 => I8,
            0x03 => I16,
            0x04 => I32,
            0x05 => U8,
            0x06 => U16,
            0x07 => U32,
            0x08 => F32,
            0x09 => VisibleString,
            0x0A => OctetString,
            0x0B => UnicodeString,
            0x0C => TimeOfDay,
            0x0D => TimeDifference,
            0x0F => Domain,
            0x10 => I24,
            0x11 => F64,
            0x12 => I40,
            0x13 => I48,
            0x14 => I56,
            0x15 => I64,
            0x16 => U24,
            0x18 => U40,
            0x19 => U48,
            0x1A => U56,
            0x1B => U64,
            _ => return None,
        })
    }

    /// The CiA 301 DataType code (inverse of [`DataType::from_code`]).
    pub fn code(self) -> u16 {
        (0x01..=0x1B)
            .find(|c| DataType::from_code(*c) == Some(self))
            .unwrap_or(0x0F)
    }

    /// Decodes little-endian bytes as this type. Short input decodes what is
    /// there (zero-extended); the caller flags the length mismatch.
    pub fn decode(self, bytes: &[u8]) -> Value {
        use DataType::*;
        let le = |n: usize| -> u64 {
            let mut v = 0u64;
            for (i, b) in bytes.iter().take(n).enumerate() {
                v |= (*b as u64) << (8 * i);
            }
            v
        };
        let signed = |n: usize| -> i64 {
            let v = le(n);
            let shift = 64 - 8 * n as u32;
            ((v << shift) as i64) >> shift
        };
        match self {
            Boolean => Value::Bool(le(1) != 0),
            U8 | U16 | U24 | U32 | U40 | U48 | U56 | U64 => Value::Unsigned(le(self.size().unwrap_or(8))),
            I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => Value::Signed(signed(self.size().unwrap_or(8))),
            // The f32's shortest decimal form, so 12.345 stays 12.345 (not 12.345000267028809).
            F32 => Value::Float(shortest_f32(f32::from_bits(le(4) as u32))),
            F64 => Value::Float(f64::from_bits(le(8))),
            VisibleString => {
                let end = bytes.iter().position(|b| *b == 0).unwrap_or(bytes.len());
                Value::Text(String::from_utf8_lossy(&bytes[..end]).into_owned())
            }
            UnicodeString => {
                let units: Vec<u16> = bytes
                    .chunks_exact(2)
                    .map(|c| u16::from_le_bytes([c[0], c[1]]))
                    .collect();
                Value::Text(String::from_utf16_lossy(&units))
            }
            TimeOfDay | TimeDifference | OctetString | Domain => Value::Bytes(bytes.to_vec()),
        }
    }
}

/// An f32 as the f64 with the same shortest decimal form (`12.345f32` -> `12.345`).
fn shortest_f32(x: f32) -> f64 {
    if x.is_finite() {
        x.to_string().parse().unwrap_or(x as f64)
    } else {
        x as f64
    }
}

/// `s` in double quotes as a user reads it: UTF-8 as is, `"` and `\` escaped, control
/// characters as `\n`, `\t`, `\r`, `\xNN` (C0, DEL) or `\u{NNNN}` (C1), so no value can
/// drive a terminal.
pub fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if (c as u32) < 0x20 || c as u32 == 0x7F => out.push_str(&format!("\\x{:02X}", c as u32)),
            c if c.is_control() => out.push_str(&format!("\\u{{{:04X}}}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A decoded object value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Unsigned(u64),
    Signed(i64),
    Float(f64),
    Text(String),
    Bytes(Vec<u8>),
}

impl Value {
    /// The value as a number, when it is one.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Bool(b) => Some(*b as u8 as f64),
            Value::Unsigned(u) => Some(*u as f64),
            Value::Signed(i) => Some(*i as f64),
            Value::Float(f) => Some(*f),
            _ => None,
        }
    }
    /// The value as an integer, when it is one.
    pub fn as_i64(&self) -> Option<i64> {
        match self {
            Value::Bool(b) => Some(*b as i64),
            Value::Unsigned(u) => Some(*u as i64),
            Value::Signed(i) => Some(*i),
            _ => None,
        }
    }
    /// JSON form: numbers stay numbers, text stays text, bytes become upper-case hex
    /// (the [`Serialize`] form as a value).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}

/// Numbers stay numbers (a float that is not finite is `null`), text stays text, bytes
/// become upper-case hex.
impl Value {
    /// Appends the value as JSON, as serde_json writes it (the JSONL writer's hot path).
    pub fn push_json(&self, out: &mut Vec<u8>) {
        use crate::frame::json::{push_hex, push_i64, push_str, push_u64};
        match self {
            Value::Bool(b) => out.extend_from_slice(if *b { b"true" } else { b"false" }),
            Value::Unsigned(u) => push_u64(out, *u),
            Value::Signed(i) => push_i64(out, *i),
            Value::Text(t) => push_str(out, t),
            Value::Bytes(b) => push_hex(out, b),
            // Floats (ryu through serde_json) and non-finite ones (null) are rare.
            Value::Float(_) => {
                let _ = serde_json::to_writer(&mut *out, self);
            }
        }
    }
}

impl Serialize for Value {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Value::Bool(b) => s.serialize_bool(*b),
            Value::Unsigned(u) => s.serialize_u64(*u),
            Value::Signed(i) => s.serialize_i64(*i),
            Value::Float(f) if f.is_finite() => s.serialize_f64(*f),
            Value::Float(_) => s.serialize_unit(),
            Value::Text(t) => s.serialize_str(t),
            Value::Bytes(b) => crate::frame::json::Hex(b).serialize(s),
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{b}"),
            Value::Unsigned(u) => write!(f, "{u}"),
            Value::Signed(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x}"),
            Value::Text(s) => write!(f, "{}", quoted(s)),
            Value::Bytes(b) => write!(f, "{}", crate::frame::hex::spaced(b)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_json_writes_what_serde_json_writes() {
        for v in [
            Value::Bool(true),
            Value::Bool(false),
            Value::Unsigned(u64::MAX),
            Value::Signed(-15000),
            Value::Signed(i64::MIN),
            Value::Float(1.5),
            Value::Float(-0.1),
            Value::Float(f64::NAN),
            Value::Text("DEXMART \"x\"\u{8}\u{c}\u{1f}µ".into()),
            Value::Bytes(vec![0xAB; 70]),
            Value::Bytes(vec![1, 2]),
        ] {
            let mut out = Vec::new();
            v.push_json(&mut out);
            assert_eq!(
                String::from_utf8(out).unwrap(),
                serde_json::to_string(&v).unwrap(),
                "{v:?}"
            );
        }
    }

    #[test]
    fn strings_are_utf8_and_shown_as_written_with_controls_escaped() {
        let v = DataType::VisibleString.decode("€ 5 °C\0junk".as_bytes());
        assert_eq!(v, Value::Text("€ 5 °C".into()));
        assert_eq!(v.to_string(), "\"€ 5 °C\"");
        assert_eq!(v.to_json(), serde_json::json!("€ 5 °C"));
        // Bytes that are not UTF-8 become U+FFFD, never a panic or Latin-1 mojibake.
        assert_eq!(
            DataType::VisibleString.decode(b"ok\xFF"),
            Value::Text("ok\u{FFFD}".into())
        );
        let hostile = Value::Text("a\"b\\\x1b]0;x\x07\u{85}\n".into());
        assert_eq!(hostile.to_string(), r#""a\"b\\\x1B]0;x\x07\u{0085}\n""#);
    }

    #[test]
    fn real32_values_keep_their_shortest_decimal_form() {
        let v = DataType::F32.decode(&12.345f32.to_le_bytes());
        assert_eq!(v.to_string(), "12.345");
        assert_eq!(v.to_json().to_string(), "12.345");
        assert_eq!(
            DataType::F32.decode(&f32::NAN.to_le_bytes()).to_json(),
            serde_json::Value::Null
        );
        assert_eq!(DataType::F64.decode(&0.1f64.to_le_bytes()).to_string(), "0.1");
    }
}
