//! Typed SDO values: text to bytes for writes, bytes to values for reads.

use super::grammar::parse_int;
use crate::od::{DataType, Value};

/// Why a text is not a value of its type.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ValueError {
    #[error("`{0}` is not a number (decimal or 0x hex)")]
    NotAnInteger(String),
    #[error("{0} does not fit {1:?}")]
    DoesNotFit(String, DataType),
    #[error("`{0}` is not a boolean (true/false/1/0)")]
    NotABoolean(String),
    #[error("`{0}` is not a number")]
    NotANumber(String),
    #[error("`{0}` has an odd number of hex digits")]
    OddHex(String),
    #[error("`{0}` is not hex")]
    NotHex(String),
    #[error("a domain value comes from a file (give its path as the value)")]
    Domain,
}

impl From<ValueError> for super::error::CommandError {
    fn from(e: ValueError) -> Self {
        super::error::CommandError::Usage(e.to_string())
    }
}

/// Encodes `text` as `ty` (little-endian). Octet strings are hex (`01 02`, `0102`);
/// domains are not text (the caller reads a file).
pub fn encode(text: &str, ty: DataType) -> Result<Vec<u8>, ValueError> {
    use DataType::*;
    let int = |signed: bool, size: usize| -> Result<Vec<u8>, ValueError> {
        let v = parse_int(text).ok_or_else(|| ValueError::NotAnInteger(text.to_string()))?;
        let bits = 8 * size as u32;
        let fits = if bits == 64 {
            true
        } else if signed {
            let lo = -(1i64 << (bits - 1));
            (lo..-lo).contains(&v) || (text.trim().starts_with("0x") && (v as u64) < (1u64 << bits))
        } else {
            (0..(1i64 << bits)).contains(&v)
        };
        if !fits {
            return Err(ValueError::DoesNotFit(text.to_string(), ty));
        }
        Ok(v.to_le_bytes()[..size].to_vec())
    };
    match ty {
        Boolean => match text.trim() {
            "1" | "true" | "on" => Ok(vec![1]),
            "0" | "false" | "off" => Ok(vec![0]),
            _ => Err(ValueError::NotABoolean(text.to_string())),
        },
        U8 | U16 | U24 | U32 | U40 | U48 | U56 | U64 => int(false, ty.size().unwrap_or(8)),
        I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => int(true, ty.size().unwrap_or(8)),
        F32 => text
            .trim()
            .parse::<f32>()
            .map(|f| f.to_le_bytes().to_vec())
            .map_err(|_| ValueError::NotANumber(text.to_string())),
        F64 => text
            .trim()
            .parse::<f64>()
            .map(|f| f.to_le_bytes().to_vec())
            .map_err(|_| ValueError::NotANumber(text.to_string())),
        VisibleString => Ok(text.as_bytes().to_vec()),
        UnicodeString => Ok(text.encode_utf16().flat_map(|u| u.to_le_bytes()).collect()),
        OctetString | TimeOfDay | TimeDifference => parse_hex(text),
        Domain => Err(ValueError::Domain),
    }
}

/// Parses hex bytes, with or without spaces: `01 2A ff`, `012Aff`.
pub fn parse_hex(text: &str) -> Result<Vec<u8>, ValueError> {
    let digits: Vec<u8> = text
        .bytes()
        .filter(|b| !b.is_ascii_whitespace() && *b != b':' && *b != b'.')
        .collect();
    if !digits.len().is_multiple_of(2) {
        return Err(ValueError::OddHex(text.to_string()));
    }
    digits
        .chunks(2)
        .map(
            |p| match (crate::frame::hex::nibble(p[0]), crate::frame::hex::nibble(p[1])) {
                (Some(h), Some(l)) => Ok(h << 4 | l),
                _ => Err(ValueError::NotHex(text.to_string())),
            },
        )
        .collect()
}

/// The value of uploaded bytes: typed when the type is known, else a number for 1..4
/// bytes (unsigned) and raw bytes above.
pub fn decode(bytes: &[u8], ty: Option<DataType>) -> Value {
    match ty {
        Some(t) => t.decode(bytes),
        None if (1..=4).contains(&bytes.len()) => DataType::U32.decode(bytes),
        None => Value::Bytes(bytes.to_vec()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodes_types() {
        assert_eq!(encode("0x0F", DataType::U16), Ok(vec![0x0F, 0]));
        assert_eq!(encode("-2", DataType::I16), Ok(vec![0xFE, 0xFF]));
        assert_eq!(encode("0xFF", DataType::I8), Ok(vec![0xFF]));
        assert!(
            encode("256", DataType::U8)
                .unwrap_err()
                .to_string()
                .contains("does not fit")
        );
        assert_eq!(encode("1.5", DataType::F32), Ok(1.5f32.to_le_bytes().to_vec()));
        assert_eq!(encode("abc", DataType::VisibleString), Ok(b"abc".to_vec()));
        assert_eq!(encode("01 2a", DataType::OctetString), Ok(vec![1, 0x2A]));
        assert!(
            encode("1x", DataType::U32)
                .unwrap_err()
                .to_string()
                .contains("not a number")
        );
    }
}
