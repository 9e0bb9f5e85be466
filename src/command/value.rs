//! Typed SDO values: text to bytes for writes, bytes to values for reads.

use super::grammar::parse_int;
use crate::od::{DataType, Value};

/// Encodes `text` as `ty` (little-endian). Octet strings are hex (`01 02`, `0102`);
/// domains are not text (the caller reads a file).
pub fn encode(text: &str, ty: DataType) -> Result<Vec<u8>, String> {
    use DataType::*;
    let int = |signed: bool, size: usize| -> Result<Vec<u8>, String> {
        let v = parse_int(text).ok_or(format!("`{text}` is not a number (decimal or 0x hex)"))?;
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
            return Err(format!("{text} does not fit {ty:?}", ty = ty));
        }
        Ok(v.to_le_bytes()[..size].to_vec())
    };
    match ty {
        Boolean => match text.trim() {
            "1" | "true" | "on" => Ok(vec![1]),
            "0" | "false" | "off" => Ok(vec![0]),
            _ => Err(format!("`{text}` is not a boolean (true/false/1/0)")),
        },
        U8 | U16 | U24 | U32 | U40 | U48 | U56 | U64 => int(false, ty.size().unwrap_or(8)),
        I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => int(true, ty.size().unwrap_or(8)),
        F32 => text
            .trim()
            .parse::<f32>()
            .map(|f| f.to_le_bytes().to_vec())
            .map_err(|_| format!("`{text}` is not a number")),
        F64 => text
            .trim()
            .parse::<f64>()
            .map(|f| f.to_le_bytes().to_vec())
            .map_err(|_| format!("`{text}` is not a number")),
        VisibleString => Ok(text.as_bytes().to_vec()),
        UnicodeString => Ok(text.encode_utf16().flat_map(|u| u.to_le_bytes()).collect()),
        OctetString | TimeOfDay | TimeDifference => parse_hex(text),
        Domain => Err("a domain value comes from a file (give its path as the value)".into()),
    }
}

/// Parses hex bytes, with or without spaces: `01 2A ff`, `012Aff`.
pub fn parse_hex(text: &str) -> Result<Vec<u8>, String> {
    let digits: Vec<u8> = text
        .bytes()
        .filter(|b| !b.is_ascii_whitespace() && *b != b':' && *b != b'.')
        .collect();
    if !digits.len().is_multiple_of(2) {
        return Err(format!("`{text}` has an odd number of hex digits"));
    }
    digits
        .chunks(2)
        .map(
            |p| match (crate::frame::hex::nibble(p[0]), crate::frame::hex::nibble(p[1])) {
                (Some(h), Some(l)) => Ok(h << 4 | l),
                _ => Err(format!("`{text}` is not hex")),
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
        assert!(encode("256", DataType::U8).unwrap_err().contains("does not fit"));
        assert_eq!(encode("1.5", DataType::F32), Ok(1.5f32.to_le_bytes().to_vec()));
        assert_eq!(encode("abc", DataType::VisibleString), Ok(b"abc".to_vec()));
        assert_eq!(encode("01 2a", DataType::OctetString), Ok(vec![1, 0x2A]));
        assert!(encode("1x", DataType::U32).unwrap_err().contains("not a number"));
    }
}
