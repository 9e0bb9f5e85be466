//! Hex and decimal formatting helpers used by logs, labels and JSON (hot paths: no `format!`).

const DIGITS: &[u8; 16] = b"0123456789ABCDEF";

/// Appends ASCII bytes produced by the helpers below (and by other formatters that write
/// only digits, letters, spaces and punctuation from literals).
#[allow(unsafe_code)] // the one unsafe block of the core: see SAFETY below
pub(crate) fn push_ascii(out: &mut String, ascii: &[u8]) {
    debug_assert!(ascii.is_ascii());
    // SAFETY: every caller fills `ascii` only from DIGITS, b'0'..=b'9', b' ' and ASCII
    // literals, so it is ASCII and therefore valid UTF-8 (checked in debug builds and by
    // the tests).
    out.push_str(unsafe { std::str::from_utf8_unchecked(ascii) });
}

/// Upper-case hex without separators: `[0x1A, 0x2B]` -> `"1A2B"`.
pub fn upper(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 2);
    push_upper(&mut s, bytes);
    s
}

/// Appends upper-case hex without separators.
pub(crate) fn push_upper(out: &mut String, bytes: &[u8]) {
    for chunk in bytes.chunks(64) {
        let mut buf = [0u8; 128];
        for (i, b) in chunk.iter().enumerate() {
            buf[2 * i] = DIGITS[(b >> 4) as usize];
            buf[2 * i + 1] = DIGITS[(b & 15) as usize];
        }
        push_ascii(out, &buf[..2 * chunk.len()]);
    }
}

/// Upper-case hex with spaces: `[0x1A, 0x2B]` -> `"1A 2B"`.
pub fn spaced(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 3);
    push_spaced(&mut s, bytes);
    s
}

/// Appends upper-case hex bytes separated by spaces.
pub fn push_spaced(out: &mut String, bytes: &[u8]) {
    // Eight bytes at a time: a classic frame's payload from one small stack buffer.
    for (n, chunk) in bytes.chunks(8).enumerate() {
        let mut buf = [b' '; 24];
        for (i, b) in chunk.iter().enumerate() {
            buf[3 * i + 1] = DIGITS[(b >> 4) as usize];
            buf[3 * i + 2] = DIGITS[(b & 15) as usize];
        }
        // Each byte is " XY"; the very first space of the whole run is dropped.
        let from = if n == 0 { 1 } else { 0 };
        push_ascii(out, &buf[from..3 * chunk.len()]);
    }
}

/// Value of one ASCII hex digit.
pub fn nibble(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

/// Appends `v` in decimal, zero-padded to at least `width` digits (at most 20).
pub fn push_decimal(out: &mut String, mut v: u64, width: usize) {
    let mut buf = [b'0'; 20];
    let mut i = buf.len();
    while v > 0 || buf.len() - i < width.clamp(1, 20) {
        i -= 1;
        buf[i] = b'0' + (v % 10) as u8;
        v /= 10;
    }
    push_ascii(out, &buf[i..]);
}

/// Appends the low `digits` hex digits (at most 8) of `v`, upper case.
pub fn push_hex(out: &mut String, v: u32, digits: u32) {
    let digits = digits.min(8);
    let mut buf = [0u8; 8];
    for i in 0..digits {
        buf[(digits - 1 - i) as usize] = DIGITS[(v >> (4 * i) & 0xF) as usize];
    }
    push_ascii(out, &buf[..digits as usize]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        assert_eq!(upper(&[0x1A, 0x2B, 0x00]), "1A2B00");
        assert_eq!(spaced(&[0x1A, 0x2B, 0x00]), "1A 2B 00");
        assert_eq!(spaced(&[]), "");
        let long: Vec<u8> = (0..70).collect();
        assert_eq!(spaced(&long).len(), 70 * 3 - 1);
        assert_eq!(upper(&long).len(), 140);
        assert!(spaced(&long).starts_with("00 01") && spaced(&long).ends_with("44 45"));
        let mut s = String::new();
        push_decimal(&mut s, 42, 6);
        push_decimal(&mut s, u64::MAX, 1);
        push_hex(&mut s, 0x7E5, 3);
        assert_eq!(s, "00004218446744073709551615".to_string() + "7E5");
    }
}
