//! The CiA 309-3 data types of the gateway (`b`, `i8`..`i64`, `u8`..`u64`, `x8`..`x64`,
//! `r32`, `r64`, `vs`, `os`, `us`, `d`, and canopend's `hex`), printed and parsed as
//! CANopenNode's `canopend` does: integers in decimal (`x..` as `0x` and fixed-width upper
//! case hex), reals as C's `%g`, visible strings between double quotes (a quote doubled),
//! octet and unicode strings and domains as one line of MIME base64, `hex` as bytes
//! separated by blanks. Data whose length does not fit the type is printed as `hex`, as
//! canopend does. Numbers are read as C's `strtol(.., 0)` reads them: `0x` hex, a leading
//! `0` octal, else decimal. Pure: no IO.

use base64::Engine;
use base64::engine::general_purpose::STANDARD;

/// A data type word of a `read` or `write` request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GwType {
    /// `b`: BOOLEAN (one byte, printed as a number, as canopend does).
    Bool,
    /// `i8`..`i64`: signed integer of that many bytes.
    Int(u8),
    /// `u8`..`u64`: unsigned integer of that many bytes.
    Uint(u8),
    /// `x8`..`x64`: unsigned integer printed as hex (non-standard, canopend's).
    Hex(u8),
    /// `r32`: REAL32.
    R32,
    /// `r64`: REAL64.
    R64,
    /// `vs`: VISIBLE_STRING.
    Vs,
    /// `os`: OCTET_STRING (base64).
    Os,
    /// `us`: UNICODE_STRING (base64).
    Us,
    /// `d`: DOMAIN (base64).
    Domain,
    /// `hex`: any data as hex bytes (non-standard, canopend's; the type of a `read` without one).
    Bytes,
}

/// The type words, for messages and `help datatype`.
pub const TYPE_WORDS: &str = "b, i8, i16, i32, i64, u8, u16, u32, u64, x8, x16, x32, x64, r32, r64, vs, os, us, d, hex";

impl GwType {
    /// The type of a (lower case) word; `None` for an unknown one.
    pub fn parse(word: &str) -> Option<GwType> {
        let bits = |s: &str| match s {
            "8" => Some(1),
            "16" => Some(2),
            "32" => Some(4),
            "64" => Some(8),
            _ => None,
        };
        Some(match word {
            "b" => GwType::Bool,
            "r32" => GwType::R32,
            "r64" => GwType::R64,
            "vs" => GwType::Vs,
            "os" => GwType::Os,
            "us" => GwType::Us,
            "d" => GwType::Domain,
            "hex" => GwType::Bytes,
            _ => {
                let (kind, n) = word.split_at_checked(1)?;
                let n = bits(n)?;
                match kind {
                    "i" => GwType::Int(n),
                    "u" => GwType::Uint(n),
                    "x" => GwType::Hex(n),
                    _ => return None,
                }
            }
        })
    }

    /// The size in bytes of a value of the type; `None` for the strings, domains and `hex`.
    pub fn size(self) -> Option<usize> {
        match self {
            GwType::Bool => Some(1),
            GwType::Int(n) | GwType::Uint(n) | GwType::Hex(n) => Some(n as usize),
            GwType::R32 => Some(4),
            GwType::R64 => Some(8),
            _ => None,
        }
    }

    /// The value of `data` as canopend prints it (data of another length than the type's: as `hex`).
    pub fn print(self, data: &[u8]) -> String {
        if self.size().is_some_and(|n| n != data.len()) {
            return hex_bytes(data);
        }
        let mut le = [0u8; 8];
        le[..data.len().min(8)].copy_from_slice(&data[..data.len().min(8)]);
        let unsigned = u64::from_le_bytes(le);
        match self {
            GwType::Bool | GwType::Uint(_) => unsigned.to_string(),
            GwType::Int(n) => {
                let shift = 64 - 8 * u32::from(n);
                (((unsigned << shift) as i64) >> shift).to_string()
            }
            GwType::Hex(n) => format!("0x{unsigned:0width$X}", width = 2 * n as usize),
            GwType::R32 => c_g(f64::from(f32::from_bits(unsigned as u32))),
            GwType::R64 => c_g(f64::from_bits(unsigned)),
            GwType::Vs => {
                let mut s = String::with_capacity(data.len() + 2);
                s.push('"');
                for c in String::from_utf8_lossy(data).chars() {
                    match c {
                        '\0' | '\r' => {}
                        '"' => s.push_str("\"\""),
                        '\n' => s.push_str("\\n"),
                        c => s.push(c),
                    }
                }
                s.push('"');
                s
            }
            GwType::Os | GwType::Us | GwType::Domain => STANDARD.encode(data),
            GwType::Bytes => hex_bytes(data),
        }
    }

    /// The bytes of `text` (what follows the type word, up to a comment) as a value of the
    /// type; why not, in words.
    pub fn encode(self, text: &str) -> Result<Vec<u8>, String> {
        let text = text.trim();
        if text.is_empty() {
            return Err("the value is missing".into());
        }
        match self {
            GwType::Vs => visible_string(text),
            GwType::Bytes => parse_hex_bytes(text),
            _ if text.split_whitespace().nth(1).is_some() => Err(format!("`{}` is more than one word", cut(text))),
            GwType::Bool => unsigned(text, 1),
            GwType::Uint(n) | GwType::Hex(n) => unsigned(text, n),
            GwType::Int(n) => signed(text, n),
            GwType::R32 => real(text).map(|v| (v as f32).to_le_bytes().to_vec()),
            GwType::R64 => real(text).map(|v| v.to_le_bytes().to_vec()),
            GwType::Os | GwType::Us | GwType::Domain => STANDARD
                .decode(text)
                .map_err(|e| format!("`{}` is not base64: {e}", cut(text))),
        }
    }
}

/// At most 40 characters of `text`, for messages.
fn cut(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((at, _)) => format!("{}...", &text[..at]),
        None => text.to_string(),
    }
}

/// Bytes as upper case hex pairs separated by one blank (`01 A2 FF`).
fn hex_bytes(data: &[u8]) -> String {
    let mut s = String::with_capacity(data.len() * 3);
    for (k, b) in data.iter().enumerate() {
        if k > 0 {
            s.push(' ');
        }
        s.push_str(&format!("{b:02X}"));
    }
    s
}

/// `01 a2ff`: hex digit pairs, blanks allowed between bytes.
fn parse_hex_bytes(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    for word in text.split_whitespace() {
        if word.len() % 2 != 0 || !word.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(format!("`{}` is not hex bytes (pairs of hex digits)", cut(word)));
        }
        for pair in word.as_bytes().chunks(2) {
            let s = std::str::from_utf8(pair).unwrap_or("00");
            out.push(u8::from_str_radix(s, 16).unwrap_or(0));
        }
    }
    Ok(out)
}

/// A number as C's `strtoull(text, .., 0)` reads it, without sign: `0x` hex, a leading
/// `0` octal, else decimal. `None` when `text` is not all digits of its base.
pub fn c_number(text: &str) -> Option<u64> {
    let (digits, radix) = if let Some(h) = text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        (h, 16)
    } else if text.len() > 1 && text.starts_with('0') {
        (&text[1..], 8)
    } else {
        (text, 10)
    };
    if digits.is_empty() || !digits.chars().all(|c| c.is_digit(radix)) {
        return None;
    }
    u64::from_str_radix(digits, radix).ok()
}

fn unsigned(text: &str, n: u8) -> Result<Vec<u8>, String> {
    let max = if n == 8 { u64::MAX } else { (1u64 << (8 * n)) - 1 };
    let v = c_number(text.strip_prefix('+').unwrap_or(text))
        .ok_or_else(|| format!("`{}` is not an unsigned number", cut(text)))?;
    if v > max {
        return Err(format!("{v} does not fit {} bits (0..{max})", 8 * n));
    }
    Ok(v.to_le_bytes()[..n as usize].to_vec())
}

fn signed(text: &str, n: u8) -> Result<Vec<u8>, String> {
    let (neg, digits) = match text.strip_prefix('-') {
        Some(d) => (true, d),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    let magnitude = c_number(digits).ok_or_else(|| format!("`{}` is not a number", cut(text)))?;
    let bits = 8 * u32::from(n);
    let (min, max) = (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1);
    let v = if neg {
        -i128::from(magnitude)
    } else {
        i128::from(magnitude)
    };
    if v < min || v > max {
        return Err(format!("{v} does not fit {bits} bits ({min}..{max})"));
    }
    Ok((v as i64).to_le_bytes()[..n as usize].to_vec())
}

fn real(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .map_err(|_| format!("`{}` is not a real number", cut(text)))
}

/// A visible string: `"two words"` (a quote inside doubled: `""`) or one word without quotes.
fn visible_string(text: &str) -> Result<Vec<u8>, String> {
    let Some(quoted) = text.strip_prefix('"') else {
        if text.split_whitespace().nth(1).is_some() {
            return Err(format!(
                "`{}`: a string of several words goes between double quotes",
                cut(text)
            ));
        }
        return Ok(text.as_bytes().to_vec());
    };
    let mut out = String::new();
    let mut chars = quoted.chars().peekable();
    while let Some(c) = chars.next() {
        if c != '"' {
            out.push(c);
            continue;
        }
        if chars.peek() == Some(&'"') {
            chars.next();
            out.push('"');
            continue;
        }
        let rest: String = chars.collect();
        if !rest.trim().is_empty() {
            return Err(format!("`{}` after the closing quote", cut(rest.trim())));
        }
        return Ok(out.into_bytes());
    }
    Err("the string has no closing double quote".into())
}

/// `v` as C's `printf("%g", v)`: 6 significant digits, trailing zeros removed, exponent
/// form (`1e+06`, `1.5e-05`) below 1e-4 and from 1e6.
pub fn c_g(v: f64) -> String {
    if v.is_nan() {
        return if v.is_sign_negative() { "-nan" } else { "nan" }.into();
    }
    if v.is_infinite() {
        return if v < 0.0 { "-inf" } else { "inf" }.into();
    }
    if v == 0.0 {
        return if v.is_sign_negative() { "-0" } else { "0" }.into();
    }
    let sci = format!("{v:.5e}");
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let strip = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (-4..6).contains(&exp) {
        strip(&format!("{v:.*}", (5 - exp) as usize))
    } else {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", strip(mantissa), exp.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_as_canopend_prints_them() {
        assert_eq!(GwType::Uint(2).print(&[0xE8, 0x03]), "1000");
        assert_eq!(GwType::Int(1).print(&[0xFF]), "-1");
        assert_eq!(GwType::Int(4).print(&[0xFE, 0xFF, 0xFF, 0xFF]), "-2");
        assert_eq!(GwType::Hex(2).print(&[0x41, 0x60]), "0x6041");
        assert_eq!(GwType::Hex(4).print(&[1, 0, 0, 0]), "0x00000001");
        assert_eq!(
            GwType::Uint(2).print(&[1, 2, 3]),
            "01 02 03",
            "a length that does not fit: hex"
        );
        assert_eq!(GwType::Bool.print(&[1]), "1");
        assert_eq!(GwType::R32.print(&1.5f32.to_le_bytes()), "1.5");
        assert_eq!(GwType::Vs.print(b"say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(GwType::Domain.print(b"hello"), "aGVsbG8=");
        assert_eq!(GwType::Bytes.print(&[]), "");
    }

    #[test]
    fn g_format_matches_c() {
        for (v, want) in [
            (0.0, "0"),
            (1.0, "1"),
            (100000.0, "100000"),
            (1000000.0, "1e+06"),
            (123456789.0, "1.23457e+08"),
            (0.0001, "0.0001"),
            (0.00001, "1e-05"),
            (0.000015, "1.5e-05"),
            (-3.25, "-3.25"),
            (0.1, "0.1"),
            (999999.5, "1e+06"),
            (2.5e-300, "2.5e-300"),
        ] {
            assert_eq!(c_g(v), want, "{v}");
        }
    }

    #[test]
    fn values_parse_as_canopend_reads_them() {
        assert_eq!(GwType::Uint(2).encode("0x3E8").unwrap(), [0xE8, 0x03]);
        assert_eq!(GwType::Uint(1).encode("010").unwrap(), [8], "leading 0: octal");
        assert_eq!(GwType::Int(2).encode("-2").unwrap(), [0xFE, 0xFF]);
        assert!(GwType::Uint(1).encode("256").unwrap_err().contains("does not fit"));
        assert!(GwType::Int(1).encode("-129").is_err());
        assert!(GwType::Uint(2).encode("-1").is_err());
        assert!(GwType::Uint(2).encode("12abc").is_err());
        assert_eq!(GwType::Vs.encode("\"two \"\"words\"\"\"").unwrap(), b"two \"words\"");
        assert_eq!(GwType::Vs.encode("one").unwrap(), b"one");
        assert!(GwType::Vs.encode("two words").is_err());
        assert!(GwType::Vs.encode("\"open").is_err());
        assert_eq!(GwType::Domain.encode("aGVsbG8=").unwrap(), b"hello");
        assert!(GwType::Domain.encode("a!b").is_err());
        assert_eq!(GwType::Bytes.encode("01 a2ff").unwrap(), [1, 0xA2, 0xFF]);
        assert_eq!(GwType::R32.encode("1.5").unwrap(), 1.5f32.to_le_bytes());
        assert_eq!(GwType::parse("x16"), Some(GwType::Hex(2)));
        assert_eq!(GwType::parse("u7"), None);
        assert_eq!(GwType::parse("i"), None);
    }
}
