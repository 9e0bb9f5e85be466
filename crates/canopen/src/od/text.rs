//! Text of dictionary files as vendors write them: UTF-8, with a fallback to Windows-1252
//! (CP1252, a superset of Latin-1 for printable text) for the lines that are not UTF-8.

/// The characters of CP1252 bytes 0x80..=0x9F (the rest of the upper half is Latin-1);
/// the five unassigned bytes map to U+FFFD.
const CP1252_HIGH: [char; 32] = [
    '€', '\u{FFFD}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{FFFD}', 'Ž', '\u{FFFD}', '\u{FFFD}',
    '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{FFFD}', 'ž', 'Ÿ',
];

/// One CP1252 byte as a character.
fn cp1252(b: u8) -> char {
    match b {
        0x80..=0x9F => CP1252_HIGH[(b - 0x80) as usize],
        _ => b as char,
    }
}

/// Decodes a file's bytes: each line that is valid UTF-8 as such, any other line as
/// CP1252. A UTF-8 byte order mark is dropped. Returns the text and the (1-based) numbers
/// of the lines read as CP1252.
pub fn decode(bytes: &[u8]) -> (String, Vec<usize>) {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if let Ok(s) = std::str::from_utf8(bytes) {
        return (s.to_string(), Vec::new());
    }
    let mut out = String::with_capacity(bytes.len() + bytes.len() / 8);
    let mut fallback = Vec::new();
    for (i, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        match std::str::from_utf8(line) {
            Ok(s) => out.push_str(s),
            Err(_) => {
                fallback.push(i + 1);
                out.extend(line.iter().map(|&b| cp1252(b)));
            }
        }
    }
    (out, fallback)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf8_stays_and_other_lines_are_read_as_cp1252() {
        assert_eq!(
            decode("\u{feff}[A]\nName=Motor 1 €\n".as_bytes()),
            ("[A]\nName=Motor 1 €\n".into(), vec![])
        );
        let (text, lines) = decode(b"[Comments]\nLine1=Copyright \xA9 1999 \x80 Gr\xFC\xDFe\r\nLines=1\n");
        assert_eq!(text, "[Comments]\nLine1=Copyright © 1999 € Grüße\r\nLines=1\n");
        assert_eq!(lines, [2]);
        // A CP437 box character is not UTF-8 either: it becomes its CP1252 reading, not an error.
        assert_eq!(decode(b"a\xC4\n").0, "aÄ\n");
        assert_eq!(decode(b"\x81").0, "\u{FFFD}");
    }
}
