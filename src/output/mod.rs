//! Headless renderings of decoded frames: text lines, JSON lines, SDO
//! transactions and summaries, pcapng capture files, BLF logs and Parquet tables. Pure formatting; the caller writes.

pub mod blf;
pub mod busload;
pub mod explain;
pub mod jsonl;
pub mod parquet;
pub mod pcapng;
pub mod summary;
pub mod text;

/// Appends `s` with control characters escaped (`\xNN`, `\u{NNNN}` for C1), so that no
/// input field (an interface name in a log, a name in an EDS) can drive the terminal.
pub fn push_escaped(out: &mut Vec<u8>, s: &str) {
    if !has_control(s.as_bytes()) {
        out.extend_from_slice(s.as_bytes());
        return;
    }
    for c in s.chars() {
        let u = c as u32;
        if u < 0x20 || u == 0x7F {
            out.extend_from_slice(format!("\\x{u:02X}").as_bytes());
        } else if c.is_control() {
            out.extend_from_slice(format!("\\u{{{u:04X}}}").as_bytes());
        } else {
            out.extend_from_slice(c.encode_utf8(&mut [0; 4]).as_bytes());
        }
    }
}

/// Whether `bytes` hold a byte below 0x20, 0x7F or 0xC2 (the lead byte of the C1
/// controls, U+0080..U+009F).
fn has_control(bytes: &[u8]) -> bool {
    crate::frame::json::any_below_or_equal(bytes, 0x20, [0x7F, 0xC2])
}

#[cfg(test)]
mod tests {
    #[test]
    fn control_characters_are_escaped_and_text_is_kept() {
        let mut s = Vec::new();
        super::push_escaped(&mut s, "can0\x1b]0;pwned\x07\u{85}€ ok");
        assert_eq!(String::from_utf8(s).unwrap(), "can0\\x1B]0;pwned\\x07\\u{0085}€ ok");
    }

    /// The word-at-a-time check finds every byte the per-byte rule finds, at every place
    /// of a text of two words and a tail.
    #[test]
    fn control_check_matches_the_byte_rule() {
        for b in 0u8..=0xFF {
            for at in 0..19 {
                let mut t = vec![b'x'; 19];
                t[at] = b;
                let expected = b < 0x20 || b == 0x7F || b == 0xC2;
                assert_eq!(super::has_control(&t), expected, "byte {b:#x} at {at}");
            }
        }
    }
}
