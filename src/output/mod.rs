//! Headless renderings of decoded frames: text lines, JSON lines, SDO
//! transactions and summaries, pcapng capture files and Parquet tables. Pure formatting; the caller writes.

pub mod jsonl;
pub mod parquet;
pub mod pcapng;
pub mod summary;
pub mod text;

/// Appends `s` with control characters escaped (`\xNN`, `\u{NNNN}` for C1), so that no
/// input field (an interface name in a log, a name in an EDS) can drive the terminal.
pub fn push_escaped(out: &mut String, s: &str) {
    // Fast path: no C0 control, DEL, or UTF-8 lead byte of a C1 control (0xC2 0x80..0x9F).
    if !s.bytes().any(|b| b < 0x20 || b == 0x7F || b == 0xC2) {
        out.push_str(s);
        return;
    }
    for c in s.chars() {
        let u = c as u32;
        if u < 0x20 || u == 0x7F {
            out.push_str(&format!("\\x{u:02X}"));
        } else if c.is_control() {
            out.push_str(&format!("\\u{{{u:04X}}}"));
        } else {
            out.push(c);
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn control_characters_are_escaped_and_text_is_kept() {
        let mut s = String::new();
        super::push_escaped(&mut s, "can0\x1b]0;pwned\x07\u{85}€ ok");
        assert_eq!(s, "can0\\x1B]0;pwned\\x07\\u{0085}€ ok");
    }
}
