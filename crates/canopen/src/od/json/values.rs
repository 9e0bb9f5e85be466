//! Reading the small value syntaxes of profile files: numbers as numbers or
//! strings, expressions, PDO mapping entries, sub and index ranges, type and
//! access names.

use serde_json::Value as Json;

use crate::od::alias::parse_object_ref;
use crate::od::expr::{Expr, ExprError, parse_int};
use crate::od::{Access, DataType, MappedEntry, ObjectRange, Value};
use std::fmt::Display;

/// A value in a profile file that does not read as what its place needs.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ValueError {
    /// A JSON value (or a number) of the wrong kind, e.g. `true is not a number`.
    #[error("{value} is not {expected}")]
    Not { value: String, expected: &'static str },
    /// A text that does not parse, e.g. ``` `0xZZ` is not a number ```.
    #[error("`{text}` is not {expected}")]
    NotText { text: String, expected: &'static str },
    #[error("bit length {bits} of 0x{index:04X}:{sub} is not 1..64")]
    BitLength { bits: u8, index: u16, sub: u8 },
    #[error("empty sub range `{0}`")]
    EmptySubRange(String),
    #[error(transparent)]
    Expr(#[from] ExprError),
}

impl ValueError {
    fn not(value: impl Display, expected: &'static str) -> ValueError {
        ValueError::Not {
            value: value.to_string(),
            expected,
        }
    }

    fn not_text(text: impl Display, expected: &'static str) -> ValueError {
        ValueError::NotText {
            text: text.to_string(),
            expected,
        }
    }
}

/// A number given as a JSON number or a string (`0x..`, `0b..`, decimal).
pub(super) fn int(v: &Json) -> Result<i64, ValueError> {
    match v {
        Json::Number(n) => n
            .as_i64()
            .or_else(|| n.as_u64().map(|u| u as i64))
            .ok_or_else(|| ValueError::not(n, "an integer")),
        Json::String(s) => parse_int(s).ok_or_else(|| ValueError::not_text(s, "a number")),
        other => Err(ValueError::not(other, "a number")),
    }
}

pub(super) fn byte(v: i64) -> Result<u8, ValueError> {
    u8::try_from(v).map_err(|_| ValueError::not(v, "a byte (0..255)"))
}

pub(super) fn float(v: &Json) -> Result<f64, ValueError> {
    match v {
        Json::Number(n) => n.as_f64().ok_or_else(|| ValueError::not(n, "a number")),
        Json::String(s) => s.trim().parse().map_err(|_| ValueError::not_text(s, "a number")),
        other => Err(ValueError::not(other, "a number")),
    }
}

pub(super) fn expr(v: &Json) -> Result<Expr, ValueError> {
    match v {
        Json::String(s) => Ok(Expr::parse(s)?),
        Json::Number(_) => int(v).map(Expr::constant),
        other => Err(ValueError::not(other, "an expression")),
    }
}

pub(super) fn default_value(v: &Json, t: DataType) -> Result<Value, ValueError> {
    use DataType::*;
    match t {
        VisibleString | UnicodeString => match v {
            Json::String(s) => Ok(Value::Text(s.clone())),
            other => Err(ValueError::not(other, "a text")),
        },
        F32 | F64 => float(v).map(Value::Float),
        Boolean => int(v).map(|x| Value::Bool(x != 0)),
        I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => int(v).map(Value::Signed),
        OctetString | Domain | TimeOfDay | TimeDifference => match v {
            Json::String(s) => hex_bytes(s)
                .map(Value::Bytes)
                .ok_or_else(|| ValueError::not_text(s, "hex bytes")),
            other => Err(ValueError::not(other, "hex bytes")),
        },
        _ => int(v).map(|x| Value::Unsigned(x as u64)),
    }
}

/// `"01 02 0A"` or `"01020A"` as bytes.
pub(super) fn hex_bytes(s: &str) -> Option<Vec<u8>> {
    let digits: Vec<u8> = s.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
    if !digits.len().is_multiple_of(2) {
        return None;
    }
    digits
        .chunks(2)
        .map(|p| Some(crate::frame::hex::nibble(p[0])? << 4 | crate::frame::hex::nibble(p[1])?))
        .collect()
}

/// `"0x6041:0/16"`, `"0x6041/16"` or a CiA mapping value `"0x60410010"` / number.
pub(super) fn mapped_entry(v: &Json) -> Result<MappedEntry, ValueError> {
    let from_raw = |raw: i64| -> Result<MappedEntry, ValueError> {
        let raw = u32::try_from(raw).map_err(|_| ValueError::not(raw, "a 32-bit mapping value"))?;
        Ok(MappedEntry {
            index: (raw >> 16) as u16,
            sub: (raw >> 8) as u8,
            bits: raw as u8,
        })
    };
    let e = match v {
        Json::Number(_) => from_raw(int(v)?)?,
        Json::String(s) => match s.split_once('/') {
            Some((obj, bits)) => {
                let (index, sub) = parse_object_ref(obj).ok_or_else(|| ValueError::not_text(obj, "an object"))?;
                let bits = bits
                    .trim()
                    .parse::<u8>()
                    .map_err(|_| ValueError::not_text(bits, "a bit length"))?;
                MappedEntry { index, sub, bits }
            }
            None => from_raw(parse_int(s).ok_or_else(|| ValueError::not_text(s, "a mapping (use 0xINDEX:SUB/BITS)"))?)?,
        },
        other => return Err(ValueError::not(other, "a mapping entry")),
    };
    if e.bits == 0 || e.bits > 64 {
        return Err(ValueError::BitLength {
            bits: e.bits,
            index: e.index,
            sub: e.sub,
        });
    }
    Ok(e)
}

/// `"0x1400..0x15FF"` as (first, last).
pub(super) fn index_range(key: &str) -> Option<(u16, u16)> {
    let (a, b) = key.split_once("..")?;
    let idx = |t: &str| {
        parse_object_ref(t)
            .filter(|(_, s)| *s == 0 && !t.contains(':'))
            .map(|(i, _)| i)
    };
    let (first, last) = (idx(a)?, idx(b)?);
    (first <= last).then_some((first, last))
}

/// `"3"`, `"0x1A"` or `"1..127"`.
pub(super) fn sub_range(key: &str) -> Result<std::ops::RangeInclusive<u8>, ValueError> {
    let one = |t: &str| {
        parse_int(t)
            .and_then(|v| u8::try_from(v).ok())
            .ok_or_else(|| ValueError::not_text(t, "a sub 0..255"))
    };
    match key.split_once("..") {
        Some((a, b)) => {
            let (a, b) = (one(a)?, one(b)?);
            if a > b {
                return Err(ValueError::EmptySubRange(key.to_string()));
            }
            Ok(a..=b)
        }
        None => one(key).map(|s| s..=s),
    }
}

/// `"0x3046"` (all subs), `"0x303F:0x11"` (one sub) or `"0x6000..0x67FF"`.
pub(super) fn object_range(text: &str) -> Result<ObjectRange, ValueError> {
    if text.contains("..") {
        let (first, last) =
            index_range(text).ok_or_else(|| ValueError::not_text(text, "an index range (0xFIRST..0xLAST)"))?;
        return Ok(ObjectRange { first, last, sub: None });
    }
    let (index, sub) = parse_object_ref(text).ok_or_else(|| ValueError::not_text(text, "an object"))?;
    let one_sub = text.contains(':') || text.to_ascii_lowercase().contains("sub");
    Ok(ObjectRange {
        first: index,
        last: index,
        sub: one_sub.then_some(sub),
    })
}

/// A data type by profile name (`u16`) or CiA name (`UNSIGNED16`), case-insensitive.
pub fn parse_type(name: &str) -> Option<DataType> {
    use DataType::*;
    let n: String = name
        .chars()
        .filter(|c| *c != '_' && *c != ' ')
        .collect::<String>()
        .to_ascii_lowercase();
    Some(match n.as_str() {
        "boolean" | "bool" => Boolean,
        "i8" | "integer8" => I8,
        "i16" | "integer16" => I16,
        "i24" | "integer24" => I24,
        "i32" | "integer32" => I32,
        "i40" | "integer40" => I40,
        "i48" | "integer48" => I48,
        "i56" | "integer56" => I56,
        "i64" | "integer64" => I64,
        "u8" | "unsigned8" => U8,
        "u16" | "unsigned16" => U16,
        "u24" | "unsigned24" => U24,
        "u32" | "unsigned32" => U32,
        "u40" | "unsigned40" => U40,
        "u48" | "unsigned48" => U48,
        "u56" | "unsigned56" => U56,
        "u64" | "unsigned64" => U64,
        "f32" | "real32" => F32,
        "f64" | "real64" => F64,
        "visiblestring" => VisibleString,
        "octetstring" => OctetString,
        "unicodestring" => UnicodeString,
        "timeofday" => TimeOfDay,
        "timedifference" => TimeDifference,
        "domain" => Domain,
        _ => return None,
    })
}

/// An access name: `ro`, `wo`, `rw`, `rwr`, `rww`, `const` (case-insensitive).
pub fn parse_access(name: &str) -> Option<Access> {
    Some(match name.trim().to_ascii_lowercase().as_str() {
        "ro" => Access::Ro,
        "wo" => Access::Wo,
        "rw" => Access::Rw,
        "rwr" => Access::Rwr,
        "rww" => Access::Rww,
        "const" => Access::Const,
        _ => return None,
    })
}
