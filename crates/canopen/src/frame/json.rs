//! JSON forms of frame fields that every record type shares: exact seconds, upper-case
//! hex and the contract's string escaping. Each is a `Serialize` wrapper, so the record
//! types derive `Serialize` and write straight into the output buffer.

use serde::ser::{Error, Serialize, Serializer};
use serde_json::value::RawValue;

/// Writes already formatted JSON text (checked by serde_json, which is cheap for the
/// short texts here) into the record.
fn raw<S: Serializer>(text: &str, s: S) -> Result<S::Ok, S::Error> {
    let raw: &RawValue = serde_json::from_str(text).map_err(S::Error::custom)?;
    raw.serialize(s)
}

/// A time in ns as a JSON number of seconds with all nine decimals, exact to the ns
/// (`1700000000.450000000`): a float would round it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Seconds(pub u64);

impl Serialize for Seconds {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // u64::MAX ns is 18446744073.709551615 s: 21 characters.
        let mut buf = [b'0'; 32];
        let (mut secs, mut frac) = (self.0 / 1_000_000_000, self.0 % 1_000_000_000);
        let mut i = buf.len();
        for _ in 0..9 {
            i -= 1;
            buf[i] = b'0' + (frac % 10) as u8;
            frac /= 10;
        }
        i -= 1;
        buf[i] = b'.';
        loop {
            i -= 1;
            buf[i] = b'0' + (secs % 10) as u8;
            secs /= 10;
            if secs == 0 {
                break;
            }
        }
        raw(std::str::from_utf8(&buf[i..]).map_err(S::Error::custom)?, s)
    }
}

/// Bytes as upper-case hex without separators: `[0x1A, 0x2B]` -> `"1A2B"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hex<'a>(pub &'a [u8]);

impl Serialize for Hex<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
        // Frame payloads (up to 64 bytes) are written from the stack; transfers allocate.
        if self.0.len() > 64 {
            return s.serialize_str(&super::hex::upper(self.0));
        }
        let mut buf = [0u8; 128];
        for (i, b) in self.0.iter().enumerate() {
            buf[2 * i] = DIGITS[(b >> 4) as usize];
            buf[2 * i + 1] = DIGITS[(b & 15) as usize];
        }
        s.serialize_str(std::str::from_utf8(&buf[..2 * self.0.len()]).map_err(S::Error::custom)?)
    }
}

/// A string with the escaping of the frame record's own fields (`iface`, `label`,
/// `malformed`): as serde_json escapes, except that backspace and form feed are written
/// `\u0008` and `\u000c`, as the JSONL contract always has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Text<'a>(pub &'a str);

impl Serialize for Text<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if memchr::memchr2(0x08, 0x0C, self.0.as_bytes()).is_none() {
            return s.serialize_str(self.0);
        }
        let mut lit = String::with_capacity(self.0.len() + 16);
        lit.push('"');
        for c in self.0.chars() {
            match c {
                '"' => lit.push_str("\\\""),
                '\\' => lit.push_str("\\\\"),
                '\n' => lit.push_str("\\n"),
                '\r' => lit.push_str("\\r"),
                '\t' => lit.push_str("\\t"),
                '\0'..='\x1f' => lit.push_str(&format!("\\u{:04x}", c as u32)),
                c => lit.push(c),
            }
        }
        lit.push('"');
        raw(&lit, s)
    }
}

/// The decimal digits of 0..100, two by two.
const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// Appends `v` in decimal.
#[inline]
pub fn push_u64(out: &mut Vec<u8>, v: u64) {
    // Node-IDs, lengths, flags, PDO numbers: one or two digits.
    if v < 10 {
        out.push(b'0' + v as u8);
    } else if v < 100 {
        let d = v as usize * 2;
        out.extend_from_slice(&PAIRS[d..d + 2]);
    } else {
        push_u64_long(out, v);
    }
}

/// [`push_u64`] for any value.
fn push_u64_long(out: &mut Vec<u8>, mut v: u64) {
    let mut buf = [0u8; 20];
    let mut i = buf.len();
    while v >= 100 {
        let d = (v % 100) as usize * 2;
        v /= 100;
        i -= 2;
        buf[i..i + 2].copy_from_slice(&PAIRS[d..d + 2]);
    }
    if v >= 10 {
        let d = v as usize * 2;
        i -= 2;
        buf[i..i + 2].copy_from_slice(&PAIRS[d..d + 2]);
    } else {
        i -= 1;
        buf[i] = b'0' + v as u8;
    }
    out.extend_from_slice(&buf[i..]);
}

/// A record's start composed on the stack and appended to the output at once (one copy
/// instead of one per field: the hot path of `cotui decode --format jsonl`).
pub struct Stacked {
    buf: [u8; 512],
    len: usize,
}

impl Default for Stacked {
    fn default() -> Stacked {
        Stacked { buf: [0; 512], len: 0 }
    }
}

impl Stacked {
    /// Room left for a field of variable length.
    pub fn room(&self) -> usize {
        self.buf.len() - self.len
    }

    /// Appends a literal (a fixed-size copy).
    #[inline(always)]
    pub fn lit<const K: usize>(&mut self, s: &[u8; K]) {
        self.buf[self.len..self.len + K].copy_from_slice(s);
        self.len += K;
    }

    /// Appends `key` and `true` or `false`.
    pub fn flag<const K: usize>(&mut self, key: &[u8; K], v: bool) {
        self.lit(key);
        if v {
            self.lit(b"true");
        } else {
            self.lit(b"false");
        }
    }

    /// Appends a few bytes (at most [`Stacked::room`]).
    #[inline]
    pub fn bytes(&mut self, s: &[u8]) {
        for &b in s {
            self.buf[self.len] = b;
            self.len += 1;
        }
    }

    /// Appends `v` in decimal (as [`push_u64`]).
    pub fn u64(&mut self, v: u64) {
        if v < 10 {
            self.buf[self.len] = b'0' + v as u8;
            self.len += 1;
        } else if v < 100 {
            let d = v as usize * 2;
            self.buf[self.len..self.len + 2].copy_from_slice(&PAIRS[d..d + 2]);
            self.len += 2;
        } else {
            self.long(v);
        }
    }

    /// [`Stacked::u64`] for three digits and more: written backwards into a scratch
    /// buffer, then moved with a copy of fixed size.
    fn long(&mut self, mut v: u64) {
        let mut tmp = [0u8; 40];
        let mut i = 20;
        while v >= 100 {
            let d = (v % 100) as usize * 2;
            v /= 100;
            i -= 2;
            tmp[i..i + 2].copy_from_slice(&PAIRS[d..d + 2]);
        }
        if v >= 10 {
            let d = v as usize * 2;
            i -= 2;
            tmp[i..i + 2].copy_from_slice(&PAIRS[d..d + 2]);
        } else {
            i -= 1;
            tmp[i] = b'0' + v as u8;
        }
        self.buf[self.len..self.len + 20].copy_from_slice(&tmp[i..i + 20]);
        self.len += 20 - i;
    }

    /// Appends a time in ns as seconds with all nine decimals (as [`push_seconds`]).
    pub fn seconds(&mut self, ns: u64) {
        self.u64(ns / 1_000_000_000);
        let mut frac = (ns % 1_000_000_000) as u32;
        let buf = &mut self.buf[self.len..self.len + 10];
        buf[0] = b'.';
        buf[1] = b'0' + (frac / 100_000_000) as u8;
        frac %= 100_000_000;
        for i in [8, 6, 4, 2] {
            let d = (frac % 100) as usize * 2;
            frac /= 100;
            buf[i..i + 2].copy_from_slice(&PAIRS[d..d + 2]);
        }
        self.len += 10;
    }

    /// Appends bytes (at most 64) as a quoted upper-case hex string (as [`push_hex`]).
    pub fn hex(&mut self, bytes: &[u8]) {
        const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
        let bytes = &bytes[..bytes.len().min(64)];
        self.buf[self.len] = b'"';
        let buf = &mut self.buf[self.len + 1..self.len + 1 + 2 * bytes.len()];
        for (i, b) in bytes.iter().enumerate() {
            buf[2 * i] = DIGITS[(b >> 4) as usize];
            buf[2 * i + 1] = DIGITS[(b & 15) as usize];
        }
        self.len += 2 * bytes.len() + 1;
        self.buf[self.len] = b'"';
        self.len += 1;
    }

    /// Appends `text` quoted as [`push_text`] does when it fits and needs no escaping;
    /// false (and nothing appended) otherwise.
    pub fn plain_text(&mut self, text: &str) -> bool {
        let b = text.as_bytes();
        if b.len() + 2 > self.room() || needs_escape(b) {
            return false;
        }
        self.buf[self.len] = b'"';
        self.len += 1;
        self.bytes(b);
        self.buf[self.len] = b'"';
        self.len += 1;
        true
    }

    /// Appends what is composed to `out` and starts again.
    pub fn flush(&mut self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.buf[..self.len]);
        self.len = 0;
    }
}

/// Appends `v` in decimal, with a minus sign when negative.
pub(crate) fn push_i64(out: &mut Vec<u8>, v: i64) {
    if v < 0 {
        out.push(b'-');
    }
    push_u64(out, v.unsigned_abs());
}

/// Appends a time in ns as seconds with all nine decimals (the JSON form of [`Seconds`]).
pub fn push_seconds(out: &mut Vec<u8>, ns: u64) {
    let mut st = Stacked::default();
    st.seconds(ns);
    st.flush(out);
}

/// Appends bytes as a quoted upper-case hex string (the JSON form of [`Hex`]).
pub fn push_hex(out: &mut Vec<u8>, bytes: &[u8]) {
    const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
    out.reserve(2 * bytes.len() + 2);
    out.push(b'"');
    // Eight bytes (a classic payload) at a time from the stack.
    for chunk in bytes.chunks(8) {
        let mut buf = [0u8; 16];
        for (i, b) in chunk.iter().enumerate() {
            buf[2 * i] = DIGITS[(b >> 4) as usize];
            buf[2 * i + 1] = DIGITS[(b & 15) as usize];
        }
        out.extend_from_slice(&buf[..2 * chunk.len()]);
    }
    out.push(b'"');
}

/// Whether any byte must be escaped in a JSON string (`"`, `\\`, control characters).
fn needs_escape(bytes: &[u8]) -> bool {
    any_below_or_equal(bytes, 0x20, [b'"', b'\\'])
}

/// Whether any byte of `bytes` is below `limit` (at most 0x80) or equal to one of `equal`,
/// eight bytes at a time (the text and JSON writers' check before escaping).
pub fn any_below_or_equal(bytes: &[u8], limit: u8, equal: [u8; 2]) -> bool {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    // Bytes of `w` below `n` (n <= 0x80) set their high bit in the result.
    let below = |w: u64, n: u8| w.wrapping_sub(ONES * u64::from(n)) & !w & HIGH;
    let [a, b] = equal.map(|e| ONES * u64::from(e));
    let mut chunks = bytes.chunks_exact(8);
    for c in &mut chunks {
        let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        if below(w, limit) | below(w ^ a, 1) | below(w ^ b, 1) != 0 {
            return true;
        }
    }
    // The tail byte by byte (a copy into a word would cost a call to memcpy).
    chunks.remainder().iter().any(|&c| c < limit || equal.contains(&c))
}

/// Appends a quoted string with the contract's escaping (the JSON form of [`Text`]).
pub fn push_text(out: &mut Vec<u8>, text: &str) {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let bytes = text.as_bytes();
    out.reserve(bytes.len() + 2);
    out.push(b'"');
    if !needs_escape(bytes) {
        out.extend_from_slice(bytes);
        out.push(b'"');
        return;
    }
    let mut clean = 0;
    for (i, &b) in bytes.iter().enumerate() {
        let escape: &[u8] = match b {
            b'"' => b"\\\"",
            b'\\' => b"\\\\",
            b'\n' => b"\\n",
            b'\r' => b"\\r",
            b'\t' => b"\\t",
            0..=0x1F => b"",
            _ => continue,
        };
        out.extend_from_slice(&bytes[clean..i]);
        if escape.is_empty() {
            out.extend_from_slice(&[b'\\', b'u', b'0', b'0', HEX[(b >> 4) as usize], HEX[(b & 15) as usize]]);
        } else {
            out.extend_from_slice(escape);
        }
        clean = i + 1;
    }
    out.extend_from_slice(&bytes[clean..]);
    out.push(b'"');
}

/// Appends a quoted string escaped as serde_json escapes it (the form of the kind-specific
/// objects' strings; the record's own fields use [`push_text`]).
pub fn push_str(out: &mut Vec<u8>, text: &str) {
    if needs_escape(text.as_bytes()) {
        // Writing into a Vec cannot fail.
        let _ = serde_json::to_writer(&mut *out, text);
        return;
    }
    out.reserve(text.len() + 2);
    out.push(b'"');
    out.extend_from_slice(text.as_bytes());
    out.push(b'"');
}

/// Appends `prefix` and `text` as one quoted string escaped as [`push_str`] does (`prefix`
/// is plain ASCII that needs no escaping).
pub fn push_prefixed_str(out: &mut Vec<u8>, prefix: &str, text: &str) {
    if needs_escape(text.as_bytes()) {
        push_str(out, &format!("{prefix}{text}"));
        return;
    }
    out.push(b'"');
    out.extend_from_slice(prefix.as_bytes());
    out.extend_from_slice(text.as_bytes());
    out.push(b'"');
}

/// Appends `record` as one JSON line; nothing when it cannot be written (the record
/// types hold only what JSON can carry, so this does not happen).
pub fn write_line(out: &mut Vec<u8>, record: &impl Serialize) {
    let start = out.len();
    match serde_json::to_writer(&mut *out, record) {
        Ok(()) => out.push(b'\n'),
        Err(_) => out.truncate(start),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn json(v: impl Serialize) -> String {
        serde_json::to_string(&v).unwrap()
    }

    #[test]
    fn seconds_keep_every_nanosecond() {
        assert_eq!(json(Seconds(1_700_000_000_450_000_001)), "1700000000.450000001");
        assert_eq!(json(Seconds(0)), "0.000000000");
        assert_eq!(json(Seconds(u64::MAX)), "18446744073.709551615");
    }

    #[test]
    fn hex_is_upper_case_at_any_length() {
        assert_eq!(json(Hex(&[0x1A, 0x2B])), r#""1A2B""#);
        assert_eq!(json(Hex(&[])), r#""""#);
        let long = [0xABu8; 100];
        assert_eq!(json(Hex(&long)), format!("\"{}\"", "AB".repeat(100)));
    }

    /// The direct writers give what the `Serialize` forms give.
    #[test]
    fn direct_writers_match_the_serialize_forms() {
        let pushed = |f: &dyn Fn(&mut Vec<u8>)| {
            let mut v = Vec::new();
            f(&mut v);
            String::from_utf8(v).unwrap()
        };
        for ns in [0, 1, 999_999_999, 1_700_000_000_450_000_001, u64::MAX] {
            assert_eq!(pushed(&|o| push_seconds(o, ns)), json(Seconds(ns)));
        }
        let stacked = |f: &dyn Fn(&mut Stacked)| {
            let mut st = Stacked::default();
            f(&mut st);
            let mut v = Vec::new();
            st.flush(&mut v);
            String::from_utf8(v).unwrap()
        };
        for v in [0, 7, 9, 10, 99, 100, 101, 999, 1000, 12345, 4_294_967_295, u64::MAX] {
            assert_eq!(pushed(&|o| push_u64(o, v)), v.to_string());
            assert_eq!(stacked(&|st| st.u64(v)), v.to_string());
        }
        for v in [0, -1, 9, -10, 100, i64::MIN, i64::MAX] {
            assert_eq!(pushed(&|o| push_i64(o, v)), v.to_string());
        }
        for ns in [5, 10_000_001, 123_456_789, 1_000_000_000] {
            assert_eq!(pushed(&|o| push_seconds(o, ns)), json(Seconds(ns)));
        }
        for b in [&[][..], &[0x1A, 0x2B], &[0xAB; 64], &[0x12; 9]] {
            assert_eq!(pushed(&|o| push_hex(o, b)), json(Hex(b)));
            assert_eq!(stacked(&|st| st.hex(b)), json(Hex(b)));
        }
        let long = "a label long enough for whole words, then a quote \" at byte 52";
        for t in [
            "",
            "plain",
            "a\"b\\c\u{1}",
            "µ\tz\n°\r",
            "\u{8}x\u{c}\u{1b}\u{7f}",
            "end\\",
            long,
            "ÿÿÿÿÿÿÿÿ\u{1f}",
        ] {
            assert_eq!(pushed(&|o| push_text(o, t)), json(Text(t)), "{t:?}");
            let mut st = Stacked::default();
            if st.plain_text(t) {
                let mut v = Vec::new();
                st.flush(&mut v);
                assert_eq!(String::from_utf8(v).unwrap(), json(Text(t)), "{t:?}");
            }
            assert_eq!(pushed(&|o| push_str(o, t)), json(t), "{t:?}");
            assert_eq!(
                pushed(&|o| push_prefixed_str(o, "eds ", t)),
                json(format!("eds {t}")),
                "{t:?}"
            );
        }
    }

    /// Every ASCII byte at every place of a 17-byte text (two words and a tail) is
    /// escaped as serde_json would.
    #[test]
    fn direct_text_escaping_finds_every_byte_in_words_and_tail() {
        for b in 0u8..0x80 {
            for at in 0..17 {
                let mut t = vec![b'x'; 17];
                t[at] = b;
                let t = String::from_utf8(t).unwrap();
                let mut v = Vec::new();
                push_text(&mut v, &t);
                assert_eq!(String::from_utf8(v).unwrap(), json(Text(&t)), "byte {b:#x} at {at}");
            }
        }
    }

    #[test]
    fn text_escapes_as_the_contract_does() {
        assert_eq!(json(Text("a\"b\\c\u{1}")), r#""a\"b\\c\u0001""#);
        assert_eq!(json(Text("µ\tz\n°")), r#""µ\tz\n°""#);
        assert_eq!(json(Text("\u{8}x\u{c}\u{1b}\r")), r#""\u0008x\u000c\u001b\r""#);
        // The same text as serde_json would write it, apart from \b and \f.
        assert_eq!(json("\u{8}\u{c}"), r#""\b\f""#);
    }
}
