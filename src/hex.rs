//! Hex and decimal formatting helpers used by logs, labels and JSON (hot paths: no `format!`).

const DIGITS: &[u8; 16] = b"0123456789ABCDEF";

/// Upper-case hex without separators: `[0x1A, 0x2B]` -> `"1A2B"`.
pub fn upper(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 2);
    push_upper(&mut s, bytes);
    s
}

/// Appends upper-case hex without separators.
pub fn push_upper(out: &mut String, bytes: &[u8]) {
    for b in bytes {
        out.push(DIGITS[(b >> 4) as usize] as char);
        out.push(DIGITS[(b & 15) as usize] as char);
    }
}

/// Upper-case hex with spaces: `[0x1A, 0x2B]` -> `"1A 2B"`.
pub fn spaced(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 3);
    for (i, b) in bytes.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        s.push(DIGITS[(b >> 4) as usize] as char);
        s.push(DIGITS[(b & 15) as usize] as char);
    }
    s
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

/// Appends `v` in decimal, zero-padded to at least `width` digits.
pub fn push_decimal(out: &mut String, mut v: u64, width: usize) {
    let mut buf = [b'0'; 20];
    let mut i = buf.len();
    while v > 0 || buf.len() - i < width.max(1) {
        i -= 1;
        buf[i] = b'0' + (v % 10) as u8;
        v /= 10;
    }
    buf[i..].iter().for_each(|b| out.push(*b as char));
}

/// Appends the low `digits` hex digits of `v`, upper case.
pub fn push_hex(out: &mut String, v: u32, digits: u32) {
    for i in (0..digits).rev() {
        out.push(char::from(b"0123456789ABCDEF"[(v >> (4 * i) & 0xF) as usize]));
    }
}

/// Appends upper-case hex bytes separated by spaces.
pub fn push_spaced(out: &mut String, bytes: &[u8]) {
    for (i, b) in bytes.iter().enumerate() {
        if i > 0 {
            out.push(' ');
        }
        out.push(DIGITS[(b >> 4) as usize] as char);
        out.push(DIGITS[(b & 15) as usize] as char);
    }
}
