//! Byte-level lexing helpers shared by the log parsers (no allocation).

use super::ParseError;
use crate::frame::Interfaces;

/// Value of each byte as a hex digit, `0xFF` when it is not one.
pub(crate) const HEX: [u8; 256] = {
    let mut t = [0xFFu8; 256];
    let mut i = 0;
    while i < 10 {
        t[b'0' as usize + i] = i as u8;
        i += 1;
    }
    let mut i = 0;
    while i < 6 {
        t[b'a' as usize + i] = 10 + i as u8;
        t[b'A' as usize + i] = 10 + i as u8;
        i += 1;
    }
    t
};

/// Hex value of `b`, or `None`.
#[inline]
pub(crate) fn hex(b: u8) -> Option<u8> {
    let v = HEX[b as usize];
    (v != 0xFF).then_some(v)
}

/// Space or tab.
#[inline]
pub(crate) fn is_ws(b: u8) -> bool {
    b == b' ' || b == b'\t'
}

/// The line without its trailing `\n`, `\r`, spaces and tabs.
#[inline]
pub(crate) fn trim_end(line: &[u8]) -> &[u8] {
    let mut n = line.len();
    while n > 0 && matches!(line[n - 1], b'\n' | b'\r' | b' ' | b'\t') {
        n -= 1;
    }
    &line[..n]
}

/// Index of the first non-blank byte at or after `i`.
#[inline]
pub(crate) fn skip_ws(s: &[u8], mut i: usize) -> usize {
    while i < s.len() && is_ws(s[i]) {
        i += 1;
    }
    i
}

/// Index of the first blank byte (or the end) at or after `i`.
#[inline]
pub(crate) fn token_end(s: &[u8], mut i: usize) -> usize {
    while i < s.len() && !is_ws(s[i]) {
        i += 1;
    }
    i
}

/// Whitespace tokenizer yielding `(start_index, token)`.
pub(crate) struct Tokens<'a> {
    s: &'a [u8],
    i: usize,
}

impl<'a> Tokens<'a> {
    /// Tokens of `s` starting at index `i`.
    pub(crate) fn new(s: &'a [u8], i: usize) -> Self {
        Tokens { s, i }
    }
    /// Index just past the last token returned (the end of the line when exhausted).
    pub(crate) fn pos(&self) -> usize {
        self.i
    }
    /// The next token, without consuming it.
    pub(crate) fn peek(&self) -> Option<(usize, &'a [u8])> {
        let start = skip_ws(self.s, self.i);
        if start >= self.s.len() {
            return None;
        }
        Some((start, &self.s[start..token_end(self.s, start)]))
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = (usize, &'a [u8]);
    fn next(&mut self) -> Option<Self::Item> {
        let (start, tok) = self.peek()?;
        self.i = start + tok.len();
        Some((start, tok))
    }
}

/// Error at byte index `i` (reported 1-based).
#[inline]
pub(crate) fn err(i: usize, message: &'static str) -> ParseError {
    ParseError { column: i + 1, message }
}

/// `10^(9 - k)`: the nanoseconds of one unit of a `k`-digit fraction of a second.
pub(crate) const FRACTION_NS: [u64; 10] = [
    1_000_000_000,
    100_000_000,
    10_000_000,
    1_000_000,
    100_000,
    10_000,
    1000,
    100,
    10,
    1,
];

/// Parses `digits[.digits]` at `i` into nanoseconds; returns the value and the index after it.
///
/// Any number of fraction digits is accepted (python-can writes `(0.0)`); digits past the
/// ninth are truncated.
pub(crate) fn timestamp(s: &[u8], mut i: usize) -> Result<(u64, usize), ParseError> {
    let start = i;
    let mut secs: u64 = 0;
    while i < s.len() && s[i].is_ascii_digit() {
        secs = secs.wrapping_mul(10).wrapping_add((s[i] - b'0') as u64);
        i += 1;
    }
    if i == start {
        return Err(err(start, "expected a timestamp (seconds)"));
    }
    // 19 digits always fit a u64; the product below catches the rest.
    let too_large = || err(start, "timestamp is too large");
    if i - start > 19 {
        return Err(too_large());
    }
    let mut frac: u64 = 0;
    if i < s.len() && s[i] == b'.' {
        i += 1;
        let from = i;
        while i < s.len() && s[i].is_ascii_digit() {
            if i - from < 9 {
                frac = frac * 10 + (s[i] - b'0') as u64;
            }
            i += 1;
        }
        frac *= FRACTION_NS[(i - from).min(9)];
    }
    let ns = secs
        .checked_mul(1_000_000_000)
        .and_then(|v| v.checked_add(frac))
        .ok_or_else(too_large)?;
    Ok((ns, i))
}

/// Parses an unsigned hex number of up to 8 digits occupying all of `tok`.
pub(crate) fn hex_u32(tok: &[u8]) -> Option<u32> {
    if tok.is_empty() || tok.len() > 8 {
        return None;
    }
    let mut v = 0u32;
    for &b in tok {
        v = (v << 4) | hex(b)? as u32;
    }
    Some(v)
}

/// Parses an unsigned decimal number occupying all of `tok`.
pub(crate) fn dec_u32(tok: &[u8]) -> Option<u32> {
    if tok.is_empty() || tok.len() > 10 {
        return None;
    }
    let mut v = 0u32;
    for &b in tok {
        if !b.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add((b - b'0') as u32)?;
    }
    Some(v)
}

/// Remembers the last interface seen so that the common single-interface log interns
/// nothing per line (and compares the name without a library call).
#[derive(Debug, Default)]
pub(crate) struct IfaceCache {
    last: Option<u16>,
    name: [u8; 16],
    len: usize,
    /// The name as a little-endian word, and the mask of its bytes in a 16-byte load.
    word: u128,
    mask: u128,
}

impl IfaceCache {
    /// Index of interface `name` (bytes at line index `at`), interning it on first sight.
    #[inline]
    pub(crate) fn get(&mut self, ifaces: &mut Interfaces, name: &[u8], at: usize) -> Result<u16, ParseError> {
        if let Some(idx) = self.last
            && name.len() == self.len
            && name.iter().zip(&self.name).all(|(a, b)| a == b)
        {
            return Ok(idx);
        }
        self.intern(ifaces, name, at)
    }

    /// The cached interface when `buf[at..]` starts with its name and a space: its index
    /// and the index of that space (one 16-byte compare, no search for the name's end).
    #[inline]
    pub(crate) fn at_space(&self, buf: &[u8], at: usize) -> Option<(u16, usize)> {
        let idx = self.last?;
        let end = at + self.len;
        let chunk: &[u8; 16] = buf.get(at..at + 16)?.try_into().ok()?;
        (u128::from_le_bytes(*chunk) & self.mask == self.word && buf.get(end) == Some(&b' ')).then_some((idx, end))
    }

    /// The slow path of [`IfaceCache::get`].
    fn intern(&mut self, ifaces: &mut Interfaces, name: &[u8], at: usize) -> Result<u16, ParseError> {
        let text = std::str::from_utf8(name).map_err(|_| err(at, "interface name is not valid UTF-8"))?;
        let idx = match ifaces.find(text) {
            Some(i) => i,
            None if ifaces.names().len() >= u16::MAX as usize => {
                return Err(err(at, "too many distinct interface names"));
            }
            None => ifaces.add(text),
        };
        // Only names that fit are cached; longer ones take the slow path every time.
        self.last = None;
        if name.len() <= self.name.len() {
            self.name = [0; 16];
            self.name[..name.len()].copy_from_slice(name);
            self.len = name.len();
            self.last = Some(idx);
            self.word = u128::from_le_bytes(self.name);
            self.mask = u128::MAX.checked_shr(8 * (16 - name.len() as u32)).unwrap_or(0);
        }
        Ok(idx)
    }
}

/// Channels whose interface index is cached; higher ones are interned per line.
const CACHED_CHANNELS: usize = 64;

/// Interface names of numbered channels, as ASC and TRC logs number them: channel N is
/// `can{N-1}` (channel 1 is `can0`), channel 0 is `canX` (as can-utils' `asc2log` names them).
#[derive(Debug)]
pub(crate) struct Channels {
    slots: [Option<u16>; CACHED_CHANNELS],
    iface: IfaceCache,
}

impl Default for Channels {
    fn default() -> Self {
        Channels {
            slots: [None; CACHED_CHANNELS],
            iface: IfaceCache::default(),
        }
    }
}

impl Channels {
    /// Interface index of channel `n` (written at line index `at`), interning it on first sight.
    pub(crate) fn get(&mut self, ifaces: &mut Interfaces, n: u32, at: usize) -> Result<u16, ParseError> {
        if let Some(Some(idx)) = self.slots.get(n as usize) {
            return Ok(*idx);
        }
        let mut buf = [0u8; 16];
        buf[..3].copy_from_slice(b"can");
        let len = if n == 0 {
            buf[3] = b'X';
            4
        } else {
            let mut digits = [0u8; 10];
            let (mut k, mut v) = (digits.len(), n - 1);
            loop {
                k -= 1;
                digits[k] = b'0' + (v % 10) as u8;
                v /= 10;
                if v == 0 {
                    break;
                }
            }
            let d = &digits[k..];
            buf[3..3 + d.len()].copy_from_slice(d);
            3 + d.len()
        };
        let idx = self.iface.get(ifaces, &buf[..len], at)?;
        if let Some(slot) = self.slots.get_mut(n as usize) {
            *slot = Some(idx);
        }
        Ok(idx)
    }
}
