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
//!
//! CAN FD is not in socketcand's released protocol; this module speaks it as the open
//! socketcand pull request linux-can/socketcand#33 does (reviewed upstream, not merged):
//! `< fdframe ID FLAGS SECS.USECS DATA >` from the server and `< fdsend ID FLAGS LEN B0 ... >`
//! from a client, FLAGS two hex digits of `struct canfd_frame`'s flags (01 BRS, 02 ESI,
//! 04 FDF), LEN decimal and one of the CAN FD lengths (0..8, 12, 16, 20, 24, 32, 48, 64).
//! The client also reads `< fdframe ID SECS.USECS DATA >` without FLAGS, as the
//! maintainer's `rawmode-canfd` branch of socketcand writes it.

use crate::frame::linux::{CANFD_BRS, CANFD_ESI, CANFD_FDF};
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
    /// `send ID LEN DATA...` (classic) or `fdsend ID FLAGS LEN DATA...` (CAN FD): one frame.
    Send(Frame),
    /// `subscribe SECS USECS ID` (BCM mode): frames of `id`, at most one per `interval_us`.
    Subscribe { id: u32, ext: bool, interval_us: u64 },
    /// `unsubscribe ID` (BCM mode).
    Unsubscribe { id: u32, ext: bool },
    /// `add SECS USECS ID LEN DATA...` (BCM mode): send `frame` every `interval_us`.
    Add { interval_us: u64, frame: Frame },
    /// `update ID LEN DATA...` (BCM mode): new content for the send job of its identifier,
    /// its timer kept.
    Update(Frame),
    /// `delete ID` (BCM mode): the send job of `id` ends.
    Delete { id: u32, ext: bool },
    /// `filter SECS USECS ID LEN MASK...` (BCM mode): frames of `id` when the bits in `mask`
    /// (or the length) changed, at most one per `interval_us`.
    Filter {
        id: u32,
        ext: bool,
        interval_us: u64,
        mask: Vec<u8>,
    },
    /// `muxfilter SECS USECS ID N TUPLES...` (BCM mode): `tuples[0]` is the multiplexer's
    /// mask; each further tuple holds a multiplexer value (in the mask's bits) and the
    /// mask of what to watch in frames of that value.
    MuxFilter {
        id: u32,
        ext: bool,
        interval_us: u64,
        tuples: Vec<[u8; 8]>,
    },
    /// `cotui_send_policy`: cotui's question whether this server lets the client send
    /// (another socketcand answers it with an error, which the client takes as yes).
    SendPolicy,
    /// A known socketcand command that this server does not implement (its first word).
    Unsupported(String),
}

/// The commands of socketcand this server does not implement.
const UNSUPPORTED: &[&str] = &["controlmode", "isotpmode", "statistics", "isotpconf", "sendpdu"];

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
        "fdsend" => parse_fdsend(&rest).map(Request::Send),
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
        "add" => match rest.as_slice() {
            [secs, usecs, frame @ ..] => Ok(Request::Add {
                interval_us: interval("add", secs, usecs)?,
                frame: parse_send(frame).map_err(|e| renamed(e, "add"))?,
            }),
            _ => Err(syntax("add takes SECS USECS ID LEN DATA: add 1 0 123 2 11 22")),
        },
        "update" => parse_send(&rest).map(Request::Update).map_err(|e| renamed(e, "update")),
        "delete" => match rest.as_slice() {
            [id] => parse_id(id).map(|(id, ext)| Request::Delete { id, ext }),
            _ => Err(syntax("delete takes one ID")),
        },
        "filter" => match rest.as_slice() {
            [secs, usecs, frame @ ..] => {
                let f = parse_send(frame).map_err(|e| renamed(e, "filter"))?;
                Ok(Request::Filter {
                    id: f.id,
                    ext: f.is_ext(),
                    interval_us: interval("filter", secs, usecs)?,
                    mask: f.payload().to_vec(),
                })
            }
            _ => Err(syntax("filter takes SECS USECS ID LEN MASK: filter 0 0 123 1 FF")),
        },
        "muxfilter" => parse_muxfilter(&rest),
        w if UNSUPPORTED.contains(&w) => Ok(Request::Unsupported(w.to_string())),
        w => Err(syntax(format!("unknown command {}", printable(w, 32)))),
    }
}

/// `SECS USECS` as microseconds.
fn interval(cmd: &str, secs: &str, usecs: &str) -> Result<u64, WireError> {
    let secs = number(secs, &format!("{cmd}: seconds"))?;
    let usecs = number(usecs, &format!("{cmd}: microseconds"))?;
    Ok(secs.saturating_mul(1_000_000).saturating_add(usecs))
}

/// A `send` parse error said for `cmd`, which takes the same `ID LEN DATA`.
fn renamed(e: WireError, cmd: &str) -> WireError {
    match e {
        WireError::Syntax(t) => WireError::Syntax(t.replacen("send", cmd, 1)),
        other => other,
    }
}

/// `SECS USECS ID N B0 ... B(8N-1)` of a `muxfilter` (2 <= N <= 257).
fn parse_muxfilter(words: &[&str]) -> Result<Request, WireError> {
    let [secs, usecs, id, n, data @ ..] = words else {
        return Err(syntax(
            "muxfilter takes SECS USECS ID N and N tuples of 8 bytes: the multiplexer mask, then a value and its mask each",
        ));
    };
    let interval_us = interval("muxfilter", secs, usecs)?;
    let (id, ext) = parse_id(id)?;
    let n = match number(n, "muxfilter: tuples") {
        Ok(n) if (2..=257).contains(&n) => n as usize,
        _ => return Err(syntax(format!("muxfilter: {} tuples: give 2..257", printable(n, 16)))),
    };
    if data.len() != n * 8 {
        return Err(syntax(format!(
            "muxfilter: {n} tuples are {} bytes, {} given",
            n * 8,
            data.len()
        )));
    }
    let mut tuples = Vec::with_capacity(n);
    for chunk in data.chunks(8) {
        let bytes = parse_bytes("muxfilter", 8, chunk)?;
        let mut t = [0u8; 8];
        t.copy_from_slice(&bytes[..8]);
        tuples.push(t);
    }
    Ok(Request::MuxFilter {
        id,
        ext,
        interval_us,
        tuples,
    })
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
        _ => {
            return Err(syntax(format!(
                "send: length {} is not 0..8 (a CAN FD frame goes as fdsend ID FLAGS LEN DATA)",
                printable(len, 16)
            )));
        }
    };
    let bytes = parse_bytes("send", len, data)?;
    let mut f = Frame::classic(id, &bytes[..len]);
    f.flags.set(Flags::EXT, ext);
    Ok(f)
}

/// `ID FLAGS LEN B0 B1 ...` of an `fdsend`.
fn parse_fdsend(words: &[&str]) -> Result<Frame, WireError> {
    let [id, flags, len, data @ ..] = words else {
        return Err(syntax(
            "fdsend takes ID FLAGS LEN and LEN data bytes: fdsend 123 01 12 11 22 33 44 55 66 77 88 99 aa bb cc",
        ));
    };
    let (id, ext) = parse_id(id)?;
    let flags = parse_fd_flags(flags, "fdsend")?;
    if flags & !(CANFD_BRS | CANFD_ESI | CANFD_FDF) != 0 {
        return Err(syntax(format!(
            "fdsend: flags {flags:02X} has bits other than 01 (BRS), 02 (ESI), 04 (FDF)"
        )));
    }
    let len = match len.parse::<usize>() {
        Ok(n) if len.len() <= 2 && is_fd_len(n) => n,
        _ => {
            return Err(syntax(format!(
                "fdsend: length {} is not a CAN FD length ({FD_LENGTHS})",
                printable(len, 16)
            )));
        }
    };
    let bytes = parse_bytes("fdsend", len, data)?;
    Ok(fd_frame(id, ext, flags, &bytes[..len]))
}

/// The CAN FD payload lengths, as error texts name them.
const FD_LENGTHS: &str = "0..8, 12, 16, 20, 24, 32, 48, 64";

/// True for a payload length a CAN FD DLC gives.
fn is_fd_len(n: usize) -> bool {
    matches!(n, 0..=8 | 12 | 16 | 20 | 24 | 32 | 48 | 64)
}

/// Exactly `len` words of one or two hex digits each, the data of `cmd`.
fn parse_bytes(cmd: &str, len: usize, words: &[&str]) -> Result<[u8; 64], WireError> {
    if words.len() != len {
        return Err(syntax(format!("{cmd}: length {len} but {} data bytes", words.len())));
    }
    let mut bytes = [0u8; 64];
    for (b, w) in bytes.iter_mut().zip(words) {
        *b = match u8::from_str_radix(w, 16) {
            Ok(v) if w.len() <= 2 => v,
            _ => return Err(syntax(format!("{cmd}: {} is not a byte in hex", printable(w, 16)))),
        };
    }
    Ok(bytes)
}

/// FLAGS of an `fdsend` or `fdframe`: one or two hex digits.
fn parse_fd_flags(s: &str, cmd: &str) -> Result<u8, WireError> {
    match u8::from_str_radix(s, 16) {
        Ok(v) if s.len() <= 2 => Ok(v),
        _ => Err(syntax(format!(
            "{cmd}: flags {} is not one byte in hex (01 BRS, 02 ESI)",
            printable(s, 16)
        ))),
    }
}

/// A CAN FD frame with `struct canfd_frame`'s `flags` (bits other than BRS, ESI, FDF ignored).
fn fd_frame(id: u32, ext: bool, flags: u8, data: &[u8]) -> Frame {
    let mut f = Frame { id, ..Frame::default() };
    f.len = data.len() as u8;
    f.data[..data.len()].copy_from_slice(data);
    f.flags.set(Flags::EXT, ext);
    f.flags.set(Flags::FD, true);
    f.flags.set(Flags::BRS, flags & CANFD_BRS != 0);
    f.flags.set(Flags::ESI, flags & CANFD_ESI != 0);
    f.flags.set(Flags::FDF, flags & CANFD_FDF != 0);
    f
}

/// `struct canfd_frame`'s `flags` of an FD frame.
fn fd_flags(f: &Frame) -> u8 {
    let bit = |flag, raw| if f.flags.has(flag) { raw } else { 0 };
    bit(Flags::BRS, CANFD_BRS) | bit(Flags::ESI, CANFD_ESI) | bit(Flags::FDF, CANFD_FDF)
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
    /// `frame ID SECS.USECS DATA`, `fdframe ID [FLAGS] SECS.USECS DATA` (CAN FD), or
    /// `error CLASS SECS.USECS` as an error frame; stamped with the server's time.
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
            let bytes = parse_hex(&hex, 8, "frame")?;
            let mut f = Frame::classic(id, &bytes);
            f.flags.set(Flags::EXT, ext);
            f.ts_ns = ts_ns;
            Ok(Reply::Frame(f))
        }
        ("fdframe", _) => parse_fdframe(&rest).map(Reply::Frame),
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

/// `ID FLAGS SECS.USECS DATA` of an `fdframe` (socketcand#33), or `ID SECS.USECS DATA`
/// (socketcand's `rawmode-canfd` branch): told apart by where the time is.
fn parse_fdframe(words: &[&str]) -> Result<Frame, WireError> {
    let (id, flags, ts, data) = match words {
        [id, ts, data @ ..] if ts.contains('.') => (id, 0, ts, data),
        [id, flags, ts, data @ ..] => (id, parse_fd_flags(flags, "fdframe")?, ts, data),
        _ => return Err(syntax("fdframe takes ID FLAGS SECS.USECS DATA")),
    };
    let (id, ext) = parse_id(id)?;
    let ts_ns = parse_time(ts)?;
    let bytes = parse_hex(&data.concat(), 64, "fdframe")?;
    if !is_fd_len(bytes.len()) {
        return Err(syntax(format!(
            "fdframe: {} data bytes is not a CAN FD length ({FD_LENGTHS})",
            bytes.len()
        )));
    }
    let mut f = fd_frame(id, ext, flags, &bytes);
    f.ts_ns = ts_ns;
    Ok(f)
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

/// Up to `max` bytes in hex, two digits each, the data of a `cmd` element.
fn parse_hex(s: &str, max: usize, cmd: &str) -> Result<Vec<u8>, WireError> {
    if !s.len().is_multiple_of(2) || s.len() > 2 * max || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(syntax(format!(
            "{cmd} data {} is not up to {max} bytes in hex",
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

/// The element a server sends for a bus frame: `< frame ... >`, `< fdframe ... >` for a
/// CAN FD frame, `< error ... >` for an error frame; none for what socketcand cannot carry
/// (remote request frames).
pub fn frame_element(f: &Frame) -> Option<String> {
    if f.is_err() {
        return Some(format!("< error {:03X} {} >", f.id & 0x1FFF_FFFF, time_text(f.ts_ns)));
    }
    if f.is_rtr() || (f.is_fd() && !is_fd_len(f.len as usize)) {
        return None;
    }
    let data: String = f.payload().iter().map(|b| format!("{b:02X}")).collect();
    if f.is_fd() {
        let (id, flags, ts) = (id_text(f), fd_flags(f), time_text(f.ts_ns));
        return Some(format!("< fdframe {id} {flags:02X} {ts} {data} >"));
    }
    Some(format!("< frame {} {} {data} >", id_text(f), time_text(f.ts_ns)))
}

/// The element a client sends to put `f` on the bus: `< send ID LEN B0 ... >`, or
/// `< fdsend ID FLAGS LEN B0 ... >` for a CAN FD frame; else why the protocol cannot carry
/// it (a remote request or error frame, a CAN FD length with no DLC).
pub fn send_element(f: &Frame) -> Result<String, String> {
    if f.is_rtr() || f.is_err() {
        return Err(
            "socketcand carries data frames only, classic and CAN FD (no remote request or error frames)".into(),
        );
    }
    if f.is_fd() && !is_fd_len(f.len as usize) {
        return Err(format!(
            "a CAN FD frame of {} bytes has no DLC (FD lengths: 0-8, 12, 16, 20, 24, 32, 48, 64)",
            f.len
        ));
    }
    let mut s = if f.is_fd() {
        format!("< fdsend {} {:02X} {}", id_text(f), fd_flags(f), f.len)
    } else {
        format!("< send {} {}", id_text(f), f.len)
    };
    for b in f.payload() {
        s.push_str(&format!(" {b:x}"));
    }
    s.push_str(" >");
    Ok(s)
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
        assert_eq!(
            parse_request("add 1 0 123 2 11 22"),
            Ok(Request::Add {
                interval_us: 1_000_000,
                frame: Frame::classic(0x123, &[0x11, 0x22])
            })
        );
        assert_eq!(
            parse_request("filter 1 500000 123 2 FF 00"),
            Ok(Request::Filter {
                id: 0x123,
                ext: false,
                interval_us: 1_500_000,
                mask: vec![0xFF, 0]
            })
        );
        assert_eq!(
            parse_request("muxfilter 0 0 123 2 FF 00 00 00 00 00 00 00 33 FF FF FF FF FF FF FF"),
            Ok(Request::MuxFilter {
                id: 0x123,
                ext: false,
                interval_us: 0,
                tuples: vec![
                    [0xFF, 0, 0, 0, 0, 0, 0, 0],
                    [0x33, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF]
                ]
            })
        );
        assert_eq!(
            parse_request("delete 1AAAAAAA"),
            Ok(Request::Delete {
                id: 0x1AAA_AAAA,
                ext: true
            })
        );
        assert!(
            matches!(parse_request("update 123 9"), Err(WireError::Syntax(t)) if t.starts_with("update: length 9"))
        );
        assert!(
            matches!(parse_request("muxfilter 0 0 123 2 FF"), Err(WireError::Syntax(t)) if t.contains("16 bytes, 1 given"))
        );
        assert!(matches!(parse_request("muxfilter 0 0 123 1"), Err(WireError::Syntax(t)) if t.contains("give 2..257")));
    }

    #[test]
    fn bad_requests_say_what_is_wrong() {
        let e = |t| parse_request(t).unwrap_err().to_string();
        assert_eq!(e("send 601 2 40"), "send: length 2 but 1 data bytes");
        assert_eq!(
            e("send 601 9 1 2 3 4 5 6 7 8 9"),
            "send: length 9 is not 0..8 (a CAN FD frame goes as fdsend ID FLAGS LEN DATA)"
        );
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

    /// An FD frame as the parsers build it.
    fn fd(id: u32, ext: bool, flags: u8, data: &[u8], ts_ns: u64) -> Frame {
        let mut f = fd_frame(id, ext, flags, data);
        f.ts_ns = ts_ns;
        f
    }

    #[test]
    fn fd_frames_are_fdframe_and_fdsend_with_their_flags() {
        let data: Vec<u8> = (0x11..=0x1C).collect();
        let mut f = fd(0x123, false, CANFD_BRS, &data, 23_424_242_000);
        assert!(f.is_fd() && f.flags.has(Flags::BRS) && !f.flags.has(Flags::ESI));
        let text = frame_element(&f).unwrap();
        assert_eq!(text, "< fdframe 123 01 23.424242 1112131415161718191A1B1C >");
        let inner = text.trim_start_matches('<').trim_end_matches('>').trim();
        assert_eq!(parse_reply(inner), Ok(Reply::Frame(f)));
        f.ts_ns = 0;
        assert_eq!(
            send_element(&f).unwrap(),
            "< fdsend 123 01 12 11 12 13 14 15 16 17 18 19 1a 1b 1c >"
        );
        assert_eq!(
            parse_request("fdsend 123 01 12 11 12 13 14 15 16 17 18 19 1a 1b 1c"),
            Ok(Request::Send(f))
        );
        // 29-bit, ESI, 64 bytes, and an empty FD frame.
        let big = fd(0x1ABC_DEF0, true, CANFD_ESI | CANFD_BRS, &[0xAB; 64], 1_000_000);
        let text = frame_element(&big).unwrap();
        assert!(text.starts_with("< fdframe 1ABCDEF0 03 0.001000 ABAB"), "{text}");
        let inner = text.trim_start_matches('<').trim_end_matches('>').trim();
        assert_eq!(parse_reply(inner), Ok(Reply::Frame(big)));
        let empty = fd(0x7FF, false, 0, &[], 0);
        assert_eq!(send_element(&empty).unwrap(), "< fdsend 7FF 00 0 >");
        // Ten bytes: no FD DLC says ten, so nothing is sent, and the reason says why.
        assert_eq!(
            send_element(&fd(0x457, false, CANFD_BRS, &[0xAA; 10], 0)),
            Err("a CAN FD frame of 10 bytes has no DLC (FD lengths: 0-8, 12, 16, 20, 24, 32, 48, 64)".into())
        );
        assert_eq!(parse_request("fdsend 7FF 0 0"), Ok(Request::Send(empty)));
        // The kernel's FDF bit is carried as it came.
        let fdf = fd(0x10, false, CANFD_FDF, &[1], 0);
        assert_eq!(frame_element(&fdf).unwrap(), "< fdframe 010 04 0.000000 01 >");
        // The maintainer's branch writes no FLAGS; unknown flag bits from a server are ignored.
        assert_eq!(
            parse_reply("fdframe 03B 1589476062.377071 7D1FDF312DD0DE1CAABBCCDD"),
            Ok(Reply::Frame(fd(
                0x3B,
                false,
                0,
                &[0x7D, 0x1F, 0xDF, 0x31, 0x2D, 0xD0, 0xDE, 0x1C, 0xAA, 0xBB, 0xCC, 0xDD],
                1_589_476_062_377_071_000
            )))
        );
        assert_eq!(
            parse_reply("fdframe 123 F1 1.000000 01"),
            Ok(Reply::Frame(fd(0x123, false, CANFD_BRS, &[1], 1_000_000_000)))
        );
    }

    #[test]
    fn malformed_fd_elements_say_what_is_wrong() {
        let reply = |t: &str| parse_reply(t).unwrap_err().to_string();
        assert_eq!(reply("fdframe"), "fdframe takes ID FLAGS SECS.USECS DATA");
        assert_eq!(reply("fdframe 123"), "fdframe takes ID FLAGS SECS.USECS DATA");
        assert_eq!(reply("fdframe 123 01"), "fdframe takes ID FLAGS SECS.USECS DATA");
        assert_eq!(reply("fdframe 123 01 later 00"), "later is not a time SECS.USECS");
        assert_eq!(
            reply("fdframe 123 1FF 1.5 00"),
            "fdframe: flags 1FF is not one byte in hex (01 BRS, 02 ESI)"
        );
        assert_eq!(
            reply("fdframe 12345 01 1.5 00"),
            "identifier 12345 does not fit 11 bits (write 8 hex digits for a 29-bit identifier)"
        );
        assert_eq!(
            reply("fdframe 123 01 1.5 ABC"),
            "fdframe data ABC is not up to 64 bytes in hex"
        );
        assert_eq!(
            reply("fdframe 123 01 1.5 XY"),
            "fdframe data XY is not up to 64 bytes in hex"
        );
        let long = "00".repeat(65);
        assert!(reply(&format!("fdframe 123 01 1.5 {long}")).ends_with("is not up to 64 bytes in hex"));
        assert_eq!(
            reply("fdframe 123 01 1.5 00112233445566778899"),
            "fdframe: 10 data bytes is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48, 64)"
        );
        let req = |t: &str| parse_request(t).unwrap_err().to_string();
        assert!(req("fdsend").starts_with("fdsend takes ID FLAGS LEN and LEN data bytes"));
        assert!(req("fdsend 123 01").starts_with("fdsend takes ID FLAGS LEN and LEN data bytes"));
        assert_eq!(
            req("fdsend 123 x 1 00"),
            "fdsend: flags x is not one byte in hex (01 BRS, 02 ESI)"
        );
        assert_eq!(
            req("fdsend 123 10 1 00"),
            "fdsend: flags 10 has bits other than 01 (BRS), 02 (ESI), 04 (FDF)"
        );
        assert_eq!(
            req("fdsend 123 01 13 0 1 2 3 4 5 6 7 8 9 a b c"),
            "fdsend: length 13 is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48, 64)"
        );
        assert_eq!(
            req("fdsend 123 01 C 0 1 2 3 4 5 6 7 8 9 a b"),
            "fdsend: length C is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48, 64)"
        );
        assert_eq!(req("fdsend 123 01 12 0 1 2"), "fdsend: length 12 but 3 data bytes");
        assert_eq!(req("fdsend 123 01 1 100"), "fdsend: 100 is not a byte in hex");
        assert_eq!(
            req("fdsend 1234 01 0"),
            "identifier 1234 does not fit 11 bits (write 8 hex digits for a 29-bit identifier)"
        );
        // python-can writes an FD message as a `send` with its length in hex: refused,
        // naming fdsend.
        assert_eq!(
            req("send 123 C 0 1 2 3 4 5 6 7 8 9 a b"),
            "send: length C is not 0..8 (a CAN FD frame goes as fdsend ID FLAGS LEN DATA)"
        );
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
