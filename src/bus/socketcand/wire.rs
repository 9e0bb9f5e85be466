//! The socketcand ASCII protocol as text, pure (no IO, no clock): splitting a byte stream
//! into `< ... >` elements, parsing what a client asks ([`Request`]) and what a server
//! answers ([`Reply`]), and formatting both sides' elements.
//!
//! The protocol (linux-can/socketcand, `doc/protocol.md`): the server greets with `< hi >`;
//! `< open BUS >` is answered `< ok >` (BCM mode), `< rawmode >` `< ok >`; in raw mode every
//! frame on the bus comes as `< frame ID SECS.USECS DATA >` (ID 3 hex digits, or 8 for a
//! 29-bit identifier; DATA uppercase hex, no spaces) and an error frame as
//! `< error CLASS SECS.USECS >`; a client sends with `< send ID LEN B0 B1 ... >` (bytes in
//! unpadded hex); `< echo >` comes back as it is. Elements are not lines: they may follow
//! each other without a separator, and bytes between them are ignored.

use crate::frame::{Flags, Frame};
use std::fmt;

/// The longest element accepted, in bytes between `<` and `>` (a `< frame >` of 8 bytes is
/// under 50; socketcand's own buffer is 4096).
pub const MAX_ELEMENT: usize = 4096;

/// What is wrong with an element or with the bytes around it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WireError {
    /// An element longer than [`MAX_ELEMENT`] bytes: skipped up to its `>`.
    TooLong,
    /// Bytes that are not ASCII text inside an element.
    NotText,
    /// Text outside `< >` (ignored, reported once per run).
    Stray,
    /// An element that does not parse; the text says why.
    Syntax(String),
}

impl fmt::Display for WireError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WireError::TooLong => write!(f, "command longer than {MAX_ELEMENT} bytes, skipped"),
            WireError::NotText => write!(f, "command is not ASCII text, skipped"),
            WireError::Stray => write!(f, "text outside < >, ignored"),
            WireError::Syntax(why) => write!(f, "{why}"),
        }
    }
}

fn syntax(why: impl Into<String>) -> WireError {
    WireError::Syntax(why.into())
}

/// Splits a byte stream into the texts of its elements (between `<` and `>`, trimmed).
/// Memory is bounded by [`MAX_ELEMENT`] whatever the input.
#[derive(Debug, Default)]
pub struct Splitter {
    /// The bytes of the element being read, after its `<`.
    buf: Vec<u8>,
    /// Inside an element (after `<`).
    inside: bool,
    /// Skipping the rest of an element that was too long.
    skipping: bool,
    /// In a run of stray bytes already reported.
    stray: bool,
}

impl Splitter {
    /// A splitter at the start of a stream.
    pub fn new() -> Splitter {
        Splitter::default()
    }

    /// Feeds `bytes`; every element completed by them (or the error in its place) is pushed to `out`.
    pub fn push(&mut self, bytes: &[u8], out: &mut Vec<Result<String, WireError>>) {
        for &b in bytes {
            if !self.inside {
                if b == b'<' {
                    self.inside = true;
                    self.stray = false;
                    self.buf.clear();
                } else if !b.is_ascii_whitespace() && !self.stray {
                    self.stray = true;
                    out.push(Err(WireError::Stray));
                }
                continue;
            }
            match b {
                b'>' => {
                    self.inside = false;
                    if std::mem::take(&mut self.skipping) {
                        continue;
                    }
                    let text = std::mem::take(&mut self.buf);
                    out.push(match String::from_utf8(text) {
                        Ok(s) if s.is_ascii() => Ok(s.trim().to_string()),
                        _ => Err(WireError::NotText),
                    });
                }
                // A new element starts: what came before had no end (socketcand drops it too).
                b'<' if !self.skipping => {
                    self.buf.clear();
                    out.push(Err(syntax("command without its closing >, skipped")));
                }
                _ if self.skipping => {}
                _ if self.buf.len() >= MAX_ELEMENT => {
                    self.skipping = true;
                    self.buf = Vec::new();
                    out.push(Err(WireError::TooLong));
                }
                _ => self.buf.push(b),
            }
        }
    }
}

/// What a client asks of the server (the text of one element).
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// `open BUS`
    Open(String),
    /// `rawmode`
    RawMode,
    /// `bcmmode`
    BcmMode,
    /// `echo`
    Echo,
    /// `send ID LEN DATA...`: one frame.
    Send(Frame),
    /// `subscribe SECS USECS ID` (BCM mode): frames of `id`, at most one per `interval_us`.
    Subscribe { id: u32, ext: bool, interval_us: u64 },
    /// `unsubscribe ID` (BCM mode).
    Unsubscribe { id: u32, ext: bool },
    /// `cotui_send_policy`: cotui's question whether this server lets the client send
    /// (another socketcand answers it with an error, which the client takes as yes).
    SendPolicy,
    /// A known socketcand command that this server does not implement (its first word).
    Unsupported(String),
}

/// The commands of socketcand this server does not implement.
const UNSUPPORTED: &[&str] = &[
    "add",
    "update",
    "delete",
    "filter",
    "muxfilter",
    "controlmode",
    "isotpmode",
    "statistics",
    "isotpconf",
    "sendpdu",
];

/// Parses the text of one element a client sent.
pub fn parse_request(text: &str) -> Result<Request, WireError> {
    let mut words = text.split_ascii_whitespace();
    let Some(word) = words.next() else {
        return Err(syntax("empty command"));
    };
    let rest: Vec<&str> = words.collect();
    let none = |r: Request| {
        if rest.is_empty() {
            Ok(r)
        } else {
            Err(syntax(format!("{word} takes no arguments")))
        }
    };
    match word {
        "open" => match rest.as_slice() {
            [bus] if bus.len() <= 64 => Ok(Request::Open(bus.to_string())),
            [_] => Err(syntax("open: bus name longer than 64 characters")),
            _ => Err(syntax("open takes one bus name: open BUS")),
        },
        "rawmode" => none(Request::RawMode),
        "bcmmode" => none(Request::BcmMode),
        "echo" => none(Request::Echo),
        "cotui_send_policy" => none(Request::SendPolicy),
        "send" => parse_send(&rest).map(Request::Send),
        "subscribe" => match rest.as_slice() {
            [secs, usecs, id] => {
                let secs = number(secs, "subscribe: seconds")?;
                let usecs = number(usecs, "subscribe: microseconds")?;
                let (id, ext) = parse_id(id)?;
                let interval_us = secs.saturating_mul(1_000_000).saturating_add(usecs);
                Ok(Request::Subscribe { id, ext, interval_us })
            }
            _ => Err(syntax("subscribe takes SECS USECS ID")),
        },
        "unsubscribe" => match rest.as_slice() {
            [id] => parse_id(id).map(|(id, ext)| Request::Unsubscribe { id, ext }),
            _ => Err(syntax("unsubscribe takes one ID")),
        },
        w if UNSUPPORTED.contains(&w) => Ok(Request::Unsupported(w.to_string())),
        w => Err(syntax(format!("unknown command {}", printable(w, 32)))),
    }
}

/// A decimal number of at most 9 digits.
fn number(s: &str, what: &str) -> Result<u64, WireError> {
    if s.is_empty() || s.len() > 9 || !s.bytes().all(|b| b.is_ascii_digit()) {
        return Err(syntax(format!("{what}: {} is not a number", printable(s, 16))));
    }
    s.parse()
        .map_err(|_| syntax(format!("{what}: {} is not a number", printable(s, 16))))
}

/// A CAN identifier in hex: 8 digits are a 29-bit identifier, fewer an 11-bit one.
pub fn parse_id(s: &str) -> Result<(u32, bool), WireError> {
    let bad = || syntax(format!("{} is not a CAN identifier in hex", printable(s, 16)));
    if s.is_empty() || s.len() > 8 || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(bad());
    }
    let id = u32::from_str_radix(s, 16).map_err(|_| bad())?;
    if s.len() == 8 {
        if id > 0x1FFF_FFFF {
            return Err(syntax(format!("identifier {s} does not fit 29 bits")));
        }
        Ok((id, true))
    } else if id > 0x7FF {
        Err(syntax(format!(
            "identifier {s} does not fit 11 bits (write 8 hex digits for a 29-bit identifier)"
        )))
    } else {
        Ok((id, false))
    }
}

/// `ID LEN B0 B1 ...` of a `send`.
fn parse_send(words: &[&str]) -> Result<Frame, WireError> {
    let [id, len, data @ ..] = words else {
        return Err(syntax("send takes ID LEN and LEN data bytes: send 601 2 40 17"));
    };
    let (id, ext) = parse_id(id)?;
    let len = match len.parse::<usize>() {
        Ok(n) if len.len() <= 2 && n <= 8 => n,
        _ => return Err(syntax(format!("send: length {} is not 0..8", printable(len, 16)))),
    };
    if data.len() != len {
        return Err(syntax(format!("send: length {len} but {} data bytes", data.len())));
    }
    let mut bytes = [0u8; 8];
    for (b, w) in bytes.iter_mut().zip(data) {
        *b = match u8::from_str_radix(w, 16) {
            Ok(v) if w.len() <= 2 => v,
            _ => return Err(syntax(format!("send: {} is not a byte in hex", printable(w, 16)))),
        };
    }
    let mut f = Frame::classic(id, &bytes[..len]);
    f.flags.set(Flags::EXT, ext);
    Ok(f)
}

/// What a server sends (the text of one element).
#[derive(Clone, Debug, PartialEq)]
pub enum Reply {
    /// `hi`
    Hi,
    /// `ok`
    Ok,
    /// `echo`
    Echo,
    /// `frame ID SECS.USECS DATA`, or `error CLASS SECS.USECS` as an error frame; stamped
    /// with the server's time.
    Frame(Frame),
    /// `error TEXT`
    Error(String),
    /// `cotui_send_policy allowed|refused TEXT`: `None` when allowed, else why not.
    SendPolicy(Option<String>),
    /// Anything else (its text).
    Other(String),
}

/// Parses the text of one element a server sent.
pub fn parse_reply(text: &str) -> Result<Reply, WireError> {
    let mut words = text.split_ascii_whitespace();
    let word = words.next().unwrap_or("");
    let rest: Vec<&str> = words.collect();
    match (word, rest.as_slice()) {
        ("hi", []) => Ok(Reply::Hi),
        ("ok", []) => Ok(Reply::Ok),
        ("echo", []) => Ok(Reply::Echo),
        ("frame", [id, ts, data @ ..]) => {
            let (id, ext) = parse_id(id)?;
            let ts_ns = parse_time(ts)?;
            let hex: String = data.concat();
            let bytes = parse_hex(&hex)?;
            let mut f = Frame::classic(id, &bytes);
            f.flags.set(Flags::EXT, ext);
            f.ts_ns = ts_ns;
            Ok(Reply::Frame(f))
        }
        ("error", [class, ts]) if parse_time(ts).is_ok() => {
            let class = u32::from_str_radix(class, 16)
                .ok()
                .filter(|c| *c <= 0x1FFF_FFFF && class.len() <= 8)
                .ok_or_else(|| syntax(format!("error frame class {} is not hex", printable(class, 16))))?;
            let mut f = Frame {
                id: class,
                ts_ns: parse_time(ts)?,
                ..Frame::default()
            };
            f.flags.set(Flags::ERR, true);
            Ok(Reply::Frame(f))
        }
        ("error", _) => Ok(Reply::Error(rest.join(" "))),
        ("cotui_send_policy", ["allowed"]) => Ok(Reply::SendPolicy(None)),
        ("cotui_send_policy", ["refused", why @ ..]) => Ok(Reply::SendPolicy(Some(why.join(" ")))),
        _ => Ok(Reply::Other(text.to_string())),
    }
}

/// `SECS.FRACTION` (1 to 9 fractional digits) as ns.
fn parse_time(s: &str) -> Result<u64, WireError> {
    let bad = || syntax(format!("{} is not a time SECS.USECS", printable(s, 24)));
    let (secs, frac) = s.split_once('.').ok_or_else(bad)?;
    let digits = |t: &str, max: usize| !t.is_empty() && t.len() <= max && t.bytes().all(|b| b.is_ascii_digit());
    if !digits(secs, 11) || !digits(frac, 9) {
        return Err(bad());
    }
    let secs: u64 = secs.parse().map_err(|_| bad())?;
    let frac: u64 = frac.parse().map_err(|_| bad())?;
    let scale = 10u64.pow(9 - frac_len(s));
    Ok(secs.saturating_mul(1_000_000_000).saturating_add(frac * scale))
}

/// The number of digits after the `.` (at most 9, checked by the caller).
fn frac_len(s: &str) -> u32 {
    s.split_once('.').map_or(0, |(_, f)| f.len()) as u32
}

/// Up to 8 bytes in hex, two digits each.
fn parse_hex(s: &str) -> Result<Vec<u8>, WireError> {
    if !s.len().is_multiple_of(2) || s.len() > 16 || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(syntax(format!(
            "frame data {} is not up to 8 bytes in hex",
            printable(s, 24)
        )));
    }
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).map_err(|_| syntax("frame data is not hex")))
        .collect()
}

/// At most `max` characters of `s`, printable and without `<` or `>` (safe inside an element).
pub fn printable(s: &str, max: usize) -> String {
    let mut out: String = s
        .chars()
        .take(max)
        .map(|c| {
            if c.is_ascii_graphic() && c != '<' && c != '>' {
                c
            } else {
                '?'
            }
        })
        .collect();
    if s.chars().count() > max {
        out.push_str("...");
    }
    out
}

/// The identifier as socketcand writes it: 3 hex digits, or 8 for a 29-bit one.
fn id_text(f: &Frame) -> String {
    if f.is_ext() {
        format!("{:08X}", f.id & 0x1FFF_FFFF)
    } else {
        format!("{:03X}", f.id & 0x7FF)
    }
}

/// `SECS.USECS` of a timestamp in ns.
fn time_text(ts_ns: u64) -> String {
    format!("{}.{:06}", ts_ns / 1_000_000_000, ts_ns % 1_000_000_000 / 1000)
}

/// The element a server sends for a bus frame: `< frame ... >`, `< error ... >` for an
/// error frame; none for what socketcand cannot carry (remote request and CAN FD frames).
pub fn frame_element(f: &Frame) -> Option<String> {
    if f.is_err() {
        return Some(format!("< error {:03X} {} >", f.id & 0x1FFF_FFFF, time_text(f.ts_ns)));
    }
    if f.is_rtr() || f.is_fd() {
        return None;
    }
    let data: String = f.payload().iter().map(|b| format!("{b:02X}")).collect();
    Some(format!("< frame {} {} {data} >", id_text(f), time_text(f.ts_ns)))
}

/// The element a client sends to put `f` on the bus: `< send ID LEN B0 ... >`; none for what
/// the protocol cannot carry (remote request, CAN FD and error frames).
pub fn send_element(f: &Frame) -> Option<String> {
    if f.is_rtr() || f.is_fd() || f.is_err() {
        return None;
    }
    let mut s = format!("< send {} {}", id_text(f), f.len);
    for b in f.payload() {
        s.push_str(&format!(" {b:x}"));
    }
    s.push_str(" >");
    Some(s)
}

/// The element of an error the server answers with (text made safe).
pub fn error_element(text: &str) -> String {
    format!("< error {} >", printable_words(text))
}

/// `text` with every character that could end or open an element replaced.
fn printable_words(text: &str) -> String {
    text.chars()
        .take(200)
        .map(|c| {
            if (c.is_ascii_graphic() || c == ' ') && c != '<' && c != '>' {
                c
            } else {
                '?'
            }
        })
        .collect()
}

/// The server's answer to [`Request::SendPolicy`].
pub fn send_policy_element(refused: Option<&str>) -> String {
    match refused {
        None => "< cotui_send_policy allowed >".to_string(),
        Some(why) => format!("< cotui_send_policy refused {} >", printable_words(why)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(chunks: &[&[u8]]) -> Vec<Result<String, WireError>> {
        let mut s = Splitter::new();
        let mut out = Vec::new();
        for c in chunks {
            s.push(c, &mut out);
        }
        out
    }

    #[test]
    fn elements_are_split_across_reads_and_without_separators() {
        let out = split(&[b"< hi >< open de", b"mo >\n< rawmode>"]);
        assert_eq!(out, vec![Ok("hi".into()), Ok("open demo".into()), Ok("rawmode".into())]);
    }

    #[test]
    fn garbage_too_long_and_unclosed_elements_are_reported_and_skipped() {
        let long = vec![b'x'; MAX_ELEMENT + 10];
        let out = split(&[b"junk junk < ec", b"< echo >< ", &long, b" >< echo >"]);
        assert_eq!(
            out,
            vec![
                Err(WireError::Stray),
                Err(syntax("command without its closing >, skipped")),
                Ok("echo".into()),
                Err(WireError::TooLong),
                Ok("echo".into()),
            ]
        );
        assert_eq!(split(&[b"<\xff\xfe>"]), vec![Err(WireError::NotText)]);
    }

    #[test]
    fn requests_parse_as_socketcand_and_python_can_write_them() {
        assert_eq!(parse_request("open can0"), Ok(Request::Open("can0".into())));
        let Ok(Request::Send(f)) = parse_request("send 601 8 40 17 10 0 0 0 0 0") else {
            panic!()
        };
        assert_eq!(
            (f.id, f.is_ext(), f.payload()),
            (0x601, false, &[0x40, 0x17, 0x10, 0, 0, 0, 0, 0][..])
        );
        let Ok(Request::Send(f)) = parse_request("send 1AAAAAAA 2 1 f1") else {
            panic!()
        };
        assert_eq!((f.id, f.is_ext(), f.payload()), (0x1AAA_AAAA, true, &[1, 0xF1][..]));
        let Ok(Request::Send(f)) = parse_request("send 123 0") else {
            panic!()
        };
        assert_eq!(f.len, 0);
        assert_eq!(
            parse_request("subscribe 1 500000 123"),
            Ok(Request::Subscribe {
                id: 0x123,
                ext: false,
                interval_us: 1_500_000
            })
        );
        assert_eq!(parse_request("add 1 0 123 0"), Ok(Request::Unsupported("add".into())));
    }

    #[test]
    fn bad_requests_say_what_is_wrong() {
        let e = |t| parse_request(t).unwrap_err().to_string();
        assert_eq!(e("send 601 2 40"), "send: length 2 but 1 data bytes");
        assert_eq!(e("send 601 9 1 2 3 4 5 6 7 8 9"), "send: length 9 is not 0..8");
        assert_eq!(
            e("send 901 0"),
            "identifier 901 does not fit 11 bits (write 8 hex digits for a 29-bit identifier)"
        );
        assert_eq!(e("send 601 1 1ff"), "send: 1ff is not a byte in hex");
        assert_eq!(e("frobnicate <x>"), "unknown command frobnicate");
        assert_eq!(e(""), "empty command");
        assert_eq!(e("rawmode now"), "rawmode takes no arguments");
    }

    #[test]
    fn frames_round_trip_through_the_server_and_client_texts() {
        let mut f = Frame::classic(0x123, &[0x1A, 0x22, 0x03, 0x44]);
        f.ts_ns = 23_424_242_000;
        let text = frame_element(&f).unwrap();
        assert_eq!(text, "< frame 123 23.424242 1A220344 >");
        let inner = text.trim_start_matches('<').trim_end_matches('>').trim();
        assert_eq!(parse_reply(inner), Ok(Reply::Frame(f)));
        let mut e = Frame::classic(0x1ABC_DEF0, &[]);
        e.ts_ns = 1_000_000;
        assert_eq!(frame_element(&e).unwrap(), "< frame 1ABCDEF0 0.001000  >");
        assert_eq!(parse_reply("frame 1ABCDEF0 0.001000"), Ok(Reply::Frame(e)));
        assert_eq!(
            send_element(&Frame::classic(0x601, &[0x40, 0x17, 0x10, 0])).unwrap(),
            "< send 601 4 40 17 10 0 >"
        );
        let Ok(Reply::Frame(err)) = parse_reply("error 004 5.000001") else {
            panic!()
        };
        assert!(err.is_err());
        assert_eq!((err.id, err.ts_ns), (4, 5_000_001_000));
        assert_eq!(
            parse_reply("error could not open bus"),
            Ok(Reply::Error("could not open bus".into()))
        );
        assert_eq!(
            parse_reply("frame 123 1.5 ABC").unwrap_err().to_string(),
            "frame data ABC is not up to 8 bytes in hex"
        );
        assert_eq!(parse_reply("frame 123 1.5 AB"), {
            let mut g = Frame::classic(0x123, &[0xAB]);
            g.ts_ns = 1_500_000_000;
            Ok(Reply::Frame(g))
        });
    }

    #[test]
    fn error_texts_cannot_end_an_element_early() {
        assert_eq!(error_element("bad <x> \n"), "< error bad ?x? ? >");
        assert_eq!(send_policy_element(Some("no >")), "< cotui_send_policy refused no ? >");
        assert_eq!(
            parse_reply("cotui_send_policy refused start with --allow-send"),
            Ok(Reply::SendPolicy(Some("start with --allow-send".into())))
        );
    }
}
