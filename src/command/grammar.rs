//! The number, node, mode, type and NAME=VALUE parsers of the commander's declarations, and
//! their defaults.

use super::error::ParseError;
use crate::od::DataType;

/// A mode of operation by CiA 402 abbreviation (`pp`, `pv`, `pt`, `hm`, `ip`, `csp`, `csv`, `cst`) or number.
pub fn parse_mode(text: &str) -> Result<i8, ParseError> {
    Ok(match text.to_ascii_lowercase().as_str() {
        "pp" => 1,
        "vl" => 2,
        "pv" => 3,
        "pt" | "tq" => 4,
        "hm" | "homing" => 6,
        "ip" => 7,
        "csp" => 8,
        "csv" => 9,
        "cst" => 10,
        other => parse_int(other)
            .filter(|v| (-128..=127).contains(v))
            .map(|v| v as i8)
            .ok_or_else(|| {
                ParseError::Invalid(format!(
                    "unknown mode `{text}`: use pp, pv, pt, hm, ip, csp, csv, cst or a number"
                ))
            })?,
    })
}

/// Default SDO response timeout in ms.
pub const DEFAULT_TIMEOUT_MS: u64 = 1000;

/// Default wait of `nmt --wait` in ms.
pub const NMT_WAIT_MS: u64 = 2000;
/// Default SDO timeout of `scan` in ms (short: absent nodes cost this much).
pub const SCAN_TIMEOUT_MS: u64 = 300;
/// Default listening time of `scan` in ms (longer than common heartbeat periods).
pub const SCAN_LISTEN_MS: u64 = 1500;

/// Splits `NAME=VALUE` procedure arguments.
pub fn parse_assignments(words: &[&str]) -> Result<Vec<(String, String)>, ParseError> {
    words
        .iter()
        .map(|w| match w.split_once('=') {
            Some((n, v)) if !n.is_empty() => Ok((n.to_string(), v.to_string())),
            _ => Err(ParseError::Invalid(format!(
                "`{w}` is not a parameter: write NAME=VALUE, e.g. speed=100"
            ))),
        })
        .collect()
}

/// Parses a number: decimal, `0x` hex, or negative decimal.
pub fn parse_int(text: &str) -> Option<i64> {
    let t = text.trim();
    let (neg, body) = match t.strip_prefix('-') {
        Some(b) => (true, b),
        None => (false, t.strip_prefix('+').unwrap_or(t)),
    };
    let v = match body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) {
        Some(h) if !h.is_empty() => i128::from_str_radix(&h.replace('_', ""), 16).ok()?,
        Some(_) => return None,
        None if !body.is_empty() && body.bytes().all(|b| b.is_ascii_digit() || b == b'_') => {
            body.replace('_', "").parse::<i128>().ok()?
        }
        None => return None,
    };
    let v = if neg { -v } else { v };
    (i64::MIN as i128..=u64::MAX as i128)
        .contains(&v)
        .then_some(if v > i64::MAX as i128 {
            v as u64 as i64
        } else {
            v as i64
        })
}

/// Parses a node id: 0..=127 where `allow_all`, else 1..=127.
pub fn parse_node(text: &str, allow_all: bool) -> Result<u8, ParseError> {
    let lo = if allow_all { 0 } else { 1 };
    match parse_int(text) {
        Some(n) if (lo..=127).contains(&n) => Ok(n as u8),
        _ => Err(ParseError::Invalid(format!(
            "node `{text}` must be a number {lo}..127 (decimal or 0x hex)"
        ))),
    }
}

/// Parses a `--type` name: u8..u64, i8..i64, f32, f64, bool, string, octets (hex), domain.
pub fn parse_type(name: &str) -> Result<DataType, ParseError> {
    use DataType::*;
    Ok(match name.to_ascii_lowercase().as_str() {
        "u8" => U8,
        "u16" => U16,
        "u24" => U24,
        "u32" => U32,
        "u40" => U40,
        "u48" => U48,
        "u56" => U56,
        "u64" => U64,
        "i8" => I8,
        "i16" => I16,
        "i24" => I24,
        "i32" => I32,
        "i40" => I40,
        "i48" => I48,
        "i56" => I56,
        "i64" => I64,
        "f32" | "real32" => F32,
        "f64" | "real64" => F64,
        "bool" | "boolean" => Boolean,
        "string" | "str" | "vs" | "visible_string" => VisibleString,
        "octets" | "octet_string" | "hex" | "os" => OctetString,
        "domain" => Domain,
        _ => {
            return Err(ParseError::Invalid(format!(
                "unknown type `{name}`: use u8..u64, i8..i64, f32, f64, bool, string, octets or domain"
            )));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(parse_int("0x1F"), Some(31));
        assert_eq!(parse_int("-5"), Some(-5));
        assert_eq!(parse_int("0xFFFFFFFFFFFFFFFF"), Some(-1));
        assert_eq!(parse_int("12a"), None);
        assert_eq!(parse_int("0x"), None);
        assert_eq!(parse_node("0x7F", false), Ok(127));
        assert!(parse_node("128", true).is_err());
    }
}
