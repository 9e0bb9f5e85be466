//! One request line of the CiA 309-3 ASCII gateway, parsed as canopend parses it:
//! `[seq] [[net] node] command ...`, the command word case-insensitive, numbers as C's
//! `strtoul(.., 0)` reads them, `#` starting a comment. Pure: no IO, no bus.

use super::answer::Code;
use super::types::{GwType, TYPE_WORDS, c_number};
use crate::command::NmtAction;

/// The longest request line the gateway reads, in bytes (a `d` domain write of about
/// 190 kB in base64); a longer line is refused with `ERROR:101` and skipped to its end.
pub const MAX_LINE: usize = 256 * 1024;

/// A parsed line.
#[derive(Clone, Debug, PartialEq)]
pub enum Line {
    /// Empty, or a comment only: answered with an empty line.
    Empty,
    /// A request.
    Request(Request),
}

/// A request: its sequence number, the network and node given before the command, the command.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub seq: u32,
    pub net: Option<u32>,
    /// The node given on the line (0..127; `None`: the default node, `set node`).
    pub node: Option<u8>,
    pub command: Command,
}

/// What a request asks for.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `r[ead] INDEX SUB [TYPE]` (no type: `hex`).
    Read { index: u16, sub: u8, ty: GwType },
    /// `w[rite] INDEX SUB TYPE VALUE`, the value already encoded.
    Write {
        index: u16,
        sub: u8,
        ty: GwType,
        data: Vec<u8>,
    },
    /// `start`, `stop`, `preop[erational]`, `reset node`, `reset comm[unication]`.
    Nmt(NmtAction),
    /// `set network N`.
    SetNetwork(u16),
    /// `set node N`.
    SetNode(u8),
    /// `set sdo_timeout MS` (1..65535).
    SetSdoTimeout(u16),
    /// `set sdo_block 0|1`.
    SetSdoBlock(bool),
    /// `lss_...`.
    Lss(Lss),
    /// `help [datatype|lss]`.
    Help(Help),
    /// `log`: the notifications kept since the last `log`.
    Log,
}

/// The topic of `help`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Help {
    Commands,
    Datatype,
    Lss,
}

/// The LSS commands of canopend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lss {
    /// `lss_switch_glob 0|1`: 1 configuration, 0 waiting.
    SwitchGlobal(bool),
    /// `lss_switch_sel VENDOR PRODUCT REVISION SERIAL`.
    SwitchSelective([u32; 4]),
    /// `lss_set_node N` (0..127, 255 unconfigured).
    SetNode(u8),
    /// `lss_conf_bitrate 0 INDEX`.
    ConfBitrate(u8),
    /// `lss_activate_bitrate DELAY_MS`.
    ActivateBitrate(u16),
    /// `lss_store`.
    Store,
    /// `lss_inquire_addr [0..3]`: one part (vendor, product, revision, serial) or all four.
    InquireAddress(Option<u8>),
    /// `lss_get_node`.
    GetNode,
    /// `_lss_fastscan [TIMEOUT_MS]`.
    Fastscan(Option<u16>),
    /// `lss_allnodes [TIMEOUT_MS [FIRST STORE [SCAN0 VENDOR SCAN1 PRODUCT SCAN2 REVISION
    /// SCAN3 SERIAL]]]`: every non-configured slave a fastscan finds gets the next node-ID.
    AllNodes(AllNodes),
}

/// What `lss_allnodes` does, as canopend takes its words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AllNodes {
    /// The fastscan's wait for each answer (0 or absent: 100 ms).
    pub timeout_ms: u16,
    /// The node-ID of the first slave found (absent: 2); each next one gets one more.
    pub first: u8,
    /// Each slave stores its node-ID (absent: yes).
    pub store: bool,
    /// Vendor-ID, product code, revision, serial: `Some` to match (scan type 2), `None` to
    /// scan (scan type 0; scan type 1, ignore, is scanned too: the same slaves are found).
    pub known: [Option<u32>; 4],
}

/// Why a line is refused: the sequence number when it was read, the code and what was wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    pub seq: Option<u32>,
    pub code: Code,
    pub why: String,
}

/// The words of a line, up to its comment.
struct Words<'a> {
    rest: &'a str,
}

impl<'a> Words<'a> {
    fn new(line: &'a str) -> Words<'a> {
        Words { rest: line }
    }
    /// The next word; `None` at the end of the line or at a comment.
    fn next(&mut self) -> Option<&'a str> {
        let s = self.rest.trim_start();
        if s.is_empty() || s.starts_with('#') {
            self.rest = "";
            return None;
        }
        let end = s.find(|c: char| c.is_whitespace() || c == '#').unwrap_or(s.len());
        self.rest = &s[end..];
        Some(&s[..end])
    }
    /// What is left, up to a comment outside double quotes.
    fn value(&mut self) -> &'a str {
        let s = self.rest.trim_start();
        let mut quoted = false;
        let mut end = s.len();
        for (i, c) in s.char_indices() {
            match c {
                '"' => quoted = !quoted,
                '#' if !quoted => {
                    end = i;
                    break;
                }
                _ => {}
            }
        }
        self.rest = "";
        s[..end].trim_end()
    }
    /// True when no word is left.
    fn done(&mut self) -> bool {
        let mut probe = Words { rest: self.rest };
        probe.next().is_none()
    }
}

/// Parses one line (without its line end).
pub fn parse(line: &str) -> Result<Line, Refusal> {
    let mut words = Words::new(line);
    let Some(first) = words.next() else {
        return Ok(Line::Empty);
    };
    let refuse = |seq, code, why: String| Refusal { seq, code, why };
    let seq = first
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .and_then(c_number)
        .and_then(|n| u32::try_from(n).ok())
        .ok_or_else(|| {
            refuse(
                None,
                Code::Syntax,
                format!(
                    "a request starts with [SEQUENCE] (e.g. `[1] 4 read 0x1017 0 u16`), not `{}`",
                    cut(first)
                ),
            )
        })?;
    let syntax = |why: String| refuse(Some(seq), Code::Syntax, why);
    // Up to two numbers (net, node) before the command word.
    let mut numbers = Vec::new();
    let word = loop {
        let Some(w) = words.next() else {
            return Err(syntax("the command is missing (`help` lists them)".into()));
        };
        if !w.starts_with(|c: char| c.is_ascii_digit()) {
            break w;
        }
        if numbers.len() == 2 {
            return Err(syntax(format!(
                "`{w}`: at most a network and a node come before the command"
            )));
        }
        numbers.push(c_number(w).ok_or_else(|| syntax(format!("`{}` is not a number", cut(w))))?);
    };
    let (net, node) = match numbers[..] {
        [] => (None, None),
        [node] => (None, Some(node)),
        [net, node] => (Some(net), Some(node)),
        _ => (None, None),
    };
    if net.is_some_and(|n| n > 0xFFFF) {
        return Err(refuse(Some(seq), Code::UnsupportedNet, "networks are 0..65535".into()));
    }
    if node.is_some_and(|n| n > 127) {
        return Err(refuse(Some(seq), Code::UnsupportedNode, "node-IDs are 0..127".into()));
    }
    let command =
        command(&word.to_ascii_lowercase(), &mut words).map_err(|(code, why)| refuse(Some(seq), code, why))?;
    Ok(Line::Request(Request {
        seq,
        net: net.map(|n| n as u32),
        node: node.map(|n| n as u8),
        command,
    }))
}

/// At most 40 characters of `text`, for messages.
fn cut(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((at, _)) => format!("{}...", &text[..at]),
        None => text.to_string(),
    }
}

type Fail = (Code, String);

fn syntax(why: impl Into<String>) -> Fail {
    (Code::Syntax, why.into())
}

/// A number word within `min..=max`.
fn number(words: &mut Words<'_>, what: &str, min: u64, max: u64) -> Result<u64, Fail> {
    let w = words.next().ok_or_else(|| syntax(format!("{what} is missing")))?;
    match c_number(w) {
        Some(v) if (min..=max).contains(&v) => Ok(v),
        _ => Err(syntax(format!("{what} `{}` must be a number {min}..{max}", cut(w)))),
    }
}

/// No word may follow.
fn end(words: &mut Words<'_>, usage: &str) -> Result<(), Fail> {
    if words.done() {
        Ok(())
    } else {
        Err(syntax(format!("too many words: `{usage}`")))
    }
}

fn data_type(words: &mut Words<'_>) -> Result<GwType, Fail> {
    let w = words
        .next()
        .ok_or_else(|| syntax(format!("the data type is missing ({TYPE_WORDS})")))?;
    GwType::parse(&w.to_ascii_lowercase())
        .ok_or_else(|| syntax(format!("unknown data type `{}`: use {TYPE_WORDS}", cut(w))))
}

fn command(word: &str, words: &mut Words<'_>) -> Result<Command, Fail> {
    let nmt = |words: &mut Words<'_>, a: NmtAction, usage: &str| end(words, usage).map(|_| Command::Nmt(a));
    Ok(match word {
        "r" | "read" => {
            let index = number(words, "INDEX", 0, 0xFFFF)? as u16;
            let sub = number(words, "SUBINDEX", 0, 0xFF)? as u8;
            let ty = if words.done() { GwType::Bytes } else { data_type(words)? };
            end(words, "read INDEX SUBINDEX [TYPE]")?;
            Command::Read { index, sub, ty }
        }
        "w" | "write" => {
            let index = number(words, "INDEX", 0, 0xFFFF)? as u16;
            let sub = number(words, "SUBINDEX", 0, 0xFF)? as u8;
            let ty = data_type(words)?;
            let data = ty.encode(words.value()).map_err(syntax)?;
            if data.is_empty() {
                return Err(syntax("the value is empty: nothing to write"));
            }
            Command::Write { index, sub, ty, data }
        }
        "start" => nmt(words, NmtAction::Start, "start")?,
        "stop" => nmt(words, NmtAction::Stop, "stop")?,
        "preop" | "preoperational" => nmt(words, NmtAction::PreOp, "preop")?,
        "reset" => {
            let what = words.next().map(str::to_ascii_lowercase);
            let action = match what.as_deref() {
                Some("node") => NmtAction::ResetNode,
                Some("comm" | "communication") => NmtAction::ResetComm,
                _ => return Err(syntax("`reset` takes node or comm[unication]")),
            };
            nmt(words, action, "reset node|comm")?
        }
        "set" => {
            let what = words.next().map(str::to_ascii_lowercase);
            let c = match what.as_deref() {
                Some("network") => Command::SetNetwork(number(words, "the network", 0, 0xFFFF)? as u16),
                Some("node") => Command::SetNode(number(words, "the node", 1, 127)? as u8),
                Some("sdo_timeout") => Command::SetSdoTimeout(number(words, "the SDO timeout (ms)", 1, 0xFFFF)? as u16),
                Some("sdo_block") => Command::SetSdoBlock(number(words, "sdo_block", 0, 1)? == 1),
                _ => {
                    return Err((
                        Code::NotSupported,
                        "`set` takes network, node, sdo_timeout or sdo_block".into(),
                    ));
                }
            };
            end(words, "set WHAT VALUE")?;
            c
        }
        "help" => {
            let topic = match words.next().map(str::to_ascii_lowercase).as_deref() {
                None => Help::Commands,
                Some("datatype") => Help::Datatype,
                Some("lss") => Help::Lss,
                Some(_) => return Err(syntax("`help` takes nothing, datatype or lss")),
            };
            end(words, "help [datatype|lss]")?;
            Command::Help(topic)
        }
        "log" => {
            end(words, "log")?;
            Command::Log
        }
        w if w.starts_with("lss_") || w == "_lss_fastscan" => Command::Lss(lss(w, words)?),
        _ => {
            return Err((
                Code::NotSupported,
                format!("unknown command `{}` (`help` lists them)", cut(word)),
            ));
        }
    })
}

fn lss(word: &str, words: &mut Words<'_>) -> Result<Lss, Fail> {
    let u32_word = |words: &mut Words<'_>, what: &str| number(words, what, 0, 0xFFFF_FFFF).map(|v| v as u32);
    let l = match word {
        "lss_switch_glob" => Lss::SwitchGlobal(number(words, "the mode (0 waiting, 1 configuration)", 0, 1)? == 1),
        "lss_switch_sel" => Lss::SwitchSelective([
            u32_word(words, "the vendor-ID")?,
            u32_word(words, "the product code")?,
            u32_word(words, "the revision number")?,
            u32_word(words, "the serial number")?,
        ]),
        "lss_set_node" => {
            let n = number(words, "the node-ID", 0, 0xFF)? as u8;
            if n > 127 && n != 255 {
                return Err(syntax("the node-ID is 0..127 or 255 (unconfigured)"));
            }
            Lss::SetNode(n)
        }
        "lss_conf_bitrate" => {
            number(words, "the table selector (only table 0)", 0, 0)?;
            let index = number(words, "the table index", 0, 9)? as u8;
            if index == 5 {
                return Err(syntax("table index 5 is reserved in CiA 305"));
            }
            Lss::ConfBitrate(index)
        }
        "lss_activate_bitrate" => Lss::ActivateBitrate(number(words, "the switch delay (ms)", 0, 0xFFFF)? as u16),
        "lss_store" => Lss::Store,
        "lss_inquire_addr" => {
            if words.done() {
                Lss::InquireAddress(None)
            } else {
                Lss::InquireAddress(Some(number(words, "LSSSUB", 0, 3)? as u8))
            }
        }
        "lss_get_node" => Lss::GetNode,
        "_lss_fastscan" => {
            if words.done() {
                Lss::Fastscan(None)
            } else {
                Lss::Fastscan(Some(number(words, "the timeout (ms)", 0, 0xFFFF)? as u16))
            }
        }
        "lss_allnodes" => {
            let mut a = AllNodes {
                timeout_ms: 100,
                first: 2,
                store: true,
                known: [None; 4],
            };
            if !words.done() {
                let t = number(words, "the timeout (ms)", 0, 0xFFFF)? as u16;
                if t > 0 {
                    a.timeout_ms = t;
                }
            }
            if !words.done() {
                a.first = number(words, "the first node-ID", 1, 127)? as u8;
                a.store = number(words, "store (0 or 1)", 0, 1)? == 1;
            }
            if !words.done() {
                for (k, part) in ["vendor-ID", "product code", "revision number", "serial number"]
                    .iter()
                    .enumerate()
                {
                    let scan = number(words, "the scan type (0 fastscan, 1 ignore, 2 match)", 0, 2)?;
                    let value = u32_word(words, &format!("the {part}"))?;
                    a.known[k] = (scan == 2).then_some(value);
                }
            }
            Lss::AllNodes(a)
        }
        _ => {
            return Err((
                Code::NotSupported,
                format!("unknown LSS command `{}` (`help lss` lists them)", cut(word)),
            ));
        }
    };
    end(words, word)?;
    Ok(l)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn req(line: &str) -> Request {
        match parse(line) {
            Ok(Line::Request(r)) => r,
            other => panic!("{line}: {other:?}"),
        }
    }

    fn refused(line: &str) -> (Option<u32>, u16) {
        let r = parse(line).unwrap_err();
        (r.seq, r.code.number())
    }

    #[test]
    fn lss_allnodes_takes_canopends_optional_words() {
        let all = |line: &str| match req(line).command {
            Command::Lss(Lss::AllNodes(a)) => a,
            other => panic!("{line}: {other:?}"),
        };
        let plain = AllNodes {
            timeout_ms: 100,
            first: 2,
            store: true,
            known: [None; 4],
        };
        assert_eq!(all("[1] lss_allnodes"), plain);
        assert_eq!(all("[1] lss_allnodes 0"), plain, "0: the default timeout");
        assert_eq!(
            all("[1] lss_allnodes 200 10 0"),
            AllNodes {
                timeout_ms: 200,
                first: 10,
                store: false,
                ..plain
            }
        );
        assert_eq!(
            all("[1] lss_allnodes 200 10 1 2 0x1234 0 0 1 0 2 99").known,
            [Some(0x1234), None, None, Some(99)]
        );
        assert_eq!(refused("[2] lss_allnodes 200 128 1"), (Some(2), 101));
        assert_eq!(refused("[3] lss_allnodes 200 10"), (Some(3), 101), "FIRST needs STORE");
        assert_eq!(
            refused("[4] lss_allnodes 200 10 1 3 0"),
            (Some(4), 101),
            "scan type 0..2"
        );
        assert_eq!(
            refused("[5] lss_allnodes 200 10 1 2 5"),
            (Some(5), 101),
            "four parts or none"
        );
    }

    #[test]
    fn canopend_examples_parse() {
        let r = req("[1] 4 read 0x1017 0 i16");
        assert_eq!((r.seq, r.net, r.node), (1, None, Some(4)));
        assert_eq!(
            r.command,
            Command::Read {
                index: 0x1017,
                sub: 0,
                ty: GwType::Int(2)
            }
        );
        let r = req("[2] 1 4 W 0x1017 0 u16 1000 # a comment");
        assert_eq!((r.net, r.node), (Some(1), Some(4)));
        assert_eq!(
            r.command,
            Command::Write {
                index: 0x1017,
                sub: 0,
                ty: GwType::Uint(2),
                data: vec![0xE8, 0x03]
            }
        );
        assert_eq!(
            req("[3] r 0x1008 0").command,
            Command::Read {
                index: 0x1008,
                sub: 0,
                ty: GwType::Bytes
            }
        );
        assert_eq!(req("[4] 0 reset comm").command, Command::Nmt(NmtAction::ResetComm));
        assert_eq!(req("[5] 4 preoperational").command, Command::Nmt(NmtAction::PreOp));
        assert_eq!(req("[6] set sdo_block 1").command, Command::SetSdoBlock(true));
        assert_eq!(
            req("[7] lss_inquire_addr").command,
            Command::Lss(Lss::InquireAddress(None))
        );
        assert_eq!(
            req("[8] lss_conf_bitrate 0 4").command,
            Command::Lss(Lss::ConfBitrate(4))
        );
        assert_eq!(
            req("[9] 4 w 0x2000 0 vs \"a # b\" # comment").command,
            Command::Write {
                index: 0x2000,
                sub: 0,
                ty: GwType::Vs,
                data: b"a # b".to_vec()
            }
        );
        assert_eq!(parse("   # only a comment"), Ok(Line::Empty));
        assert_eq!(parse(""), Ok(Line::Empty));
    }

    #[test]
    fn bad_lines_get_the_codes_canopend_gives() {
        assert_eq!(refused("4 read 0x1017 0"), (None, 101));
        assert_eq!(refused("[x] 4 read 0x1017 0"), (None, 101));
        assert_eq!(refused("[1] 4 frobnicate"), (Some(1), 100));
        assert_eq!(refused("[1] 4 read 0x1017 0 u7"), (Some(1), 101));
        assert_eq!(refused("[1] 4 read 0x10170 0"), (Some(1), 101));
        assert_eq!(refused("[1] 4 write 0x1017 0 u8 256"), (Some(1), 101));
        assert_eq!(refused("[1] 200 read 0x1017 0"), (Some(1), 107));
        assert_eq!(refused("[1] 70000 1 read 0x1017 0"), (Some(1), 106));
        assert_eq!(refused("[1] 1 2 3 read 0x1017 0"), (Some(1), 101));
        assert_eq!(refused("[1] 4 start now"), (Some(1), 101));
        assert_eq!(refused("[1] set colour 3"), (Some(1), 100));
        assert_eq!(refused("[1] set node 0"), (Some(1), 101));
        assert_eq!(refused("[1] lss_set_node 200"), (Some(1), 101));
        assert_eq!(refused("[1]"), (Some(1), 101));
    }
}
