//! The parser: tokens to an expression tree. `or` binds loosest, then `and` (or two
//! conditions side by side), then `not`/`!`; parentheses group.

use super::error::FilterError;
use super::lex::{Cmp, Tok, Token};
use super::names::Names;
use crate::decode::Kind;
use std::collections::HashMap;

/// A parsed expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// Every part matches.
    And(Vec<Expr>),
    /// Some part matches.
    Or(Vec<Expr>),
    /// The part does not match.
    Not(Box<Expr>),
    /// One condition.
    Term(Term),
}

/// How a COB-ID condition matches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IdMatch {
    /// `lo..=hi` (one ID: `lo == hi`).
    Range(u32, u32),
    /// `id & mask == value`.
    Mask {
        /// The bits wanted.
        value: u32,
        /// The bits compared.
        mask: u32,
    },
}

/// A test on an object's value: `& MASK` (non-zero, or compared), `OP NUMBER`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Test {
    /// The value is and-ed with this first.
    pub mask: Option<u64>,
    /// The comparison; with a mask and none, the masked value must be non-zero.
    pub cmp: Option<(Cmp, f64)>,
}

/// The leading hex digits of an SDO abort code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CodePrefix {
    /// The digits' value.
    pub value: u32,
    /// How many hex digits were given (1..=8).
    pub digits: u8,
}

impl CodePrefix {
    /// True when `code` starts with these digits (written as 8 hex digits).
    pub fn matches(self, code: u32) -> bool {
        let shift = 32 - 4 * u32::from(self.digits);
        code.checked_shr(shift).unwrap_or(0) == self.value
    }
}

/// One condition.
#[derive(Clone, Debug, PartialEq)]
pub enum Term {
    /// Frames of nodes `lo..=hi`.
    Node(u8, u8),
    /// Frames of the interface so named (`iface can1`).
    Iface(String),
    /// Frames of any of these kinds.
    Kinds(Vec<Kind>),
    /// Frames whose COB-ID matches.
    Id(IdMatch),
    /// Frames sent by cotui (`true`, candump's `T`) or received (`false`).
    Tx(bool),
    /// Frames whose time, in seconds from the first frame, compares so.
    Time(Cmp, f64),
    /// Frames carrying the object (SDO transfers of it, PDOs mapping it), optionally
    /// whose value passes the test.
    Object {
        /// Index.
        index: u16,
        /// Sub-index (any when `None`).
        sub: Option<u8>,
        /// The value test.
        test: Option<Test>,
    },
    /// SDO frames of aborted transfers (and abort frames), optionally with this code.
    Abort(Option<CodePrefix>),
    /// The decoded label contains this (lower case) text.
    Text(String),
}

/// The kinds a kind word names.
pub fn kinds(word: &str) -> Option<Vec<Kind>> {
    Some(match word.to_ascii_lowercase().as_str() {
        "nmt" => vec![Kind::Nmt],
        "sync" => vec![Kind::Sync],
        "emcy" => vec![Kind::Emcy],
        "time" => vec![Kind::Time],
        "tpdo" => vec![Kind::Tpdo],
        "rpdo" => vec![Kind::Rpdo],
        "pdo" => vec![Kind::Tpdo, Kind::Rpdo],
        "sdo" => vec![Kind::SdoTx, Kind::SdoRx],
        "sdo_tx" => vec![Kind::SdoTx],
        "sdo_rx" => vec![Kind::SdoRx],
        "heartbeat" | "hb" => vec![Kind::Heartbeat],
        "lss" => vec![Kind::Lss],
        "error" | "error_frame" => vec![Kind::ErrorFrame],
        "other" => vec![Kind::Other],
        _ => return None,
    })
}

/// Nesting allowed for parentheses and `not` (deeper is an error, not a stack overflow).
const MAX_DEPTH: usize = 64;

/// Words that start a condition of their own, never an object name.
const KEYWORDS: [&str; 12] = [
    "node", "iface", "kind", "id", "tx", "rx", "time", "abort", "aborts", "and", "or", "not",
];

/// Words a multi-word object name may have.
const MAX_NAME_WORDS: usize = 8;

/// An integer: decimal, `0x` hex or `0b` binary.
fn integer(s: &str) -> Option<u64> {
    let l = s.to_ascii_lowercase();
    if let Some(h) = l.strip_prefix("0x") {
        u64::from_str_radix(h, 16).ok()
    } else if let Some(b) = l.strip_prefix("0b") {
        u64::from_str_radix(b, 2).ok()
    } else {
        l.parse().ok()
    }
}

/// A number to compare with: an integer as above, negative, or decimal with a fraction.
fn number(s: &str) -> Option<f64> {
    match s.strip_prefix('-') {
        Some(rest) => number(rest).filter(|_| !rest.starts_with('-')).map(|x| -x),
        None => integer(s)
            .map(|x| x as f64)
            .or_else(|| s.parse::<f64>().ok().filter(|x| x.is_finite())),
    }
}

/// An object index and, when given, its sub-index.
type ObjectRef = (u16, Option<u8>);

/// `IIII` or `IIII:SS` in hex (optionally `0x`); `Err` names the bad sub-index and where
/// it starts in the word.
fn hex_object(w: &str) -> Result<Option<ObjectRef>, (usize, String)> {
    let skip = if w.starts_with("0x") || w.starts_with("0X") {
        2
    } else {
        0
    };
    let (i, s) = match w[skip..].split_once(':') {
        Some((i, s)) => (i, Some(s)),
        None => (&w[skip..], None),
    };
    if i.len() != 4 || !i.chars().all(|c| c.is_ascii_hexdigit()) {
        return Ok(None);
    }
    let Ok(index) = u16::from_str_radix(i, 16) else {
        return Ok(None);
    };
    let sub = match s {
        Some(s) => {
            let t = s.strip_prefix("0x").unwrap_or(s);
            match u8::from_str_radix(t, 16) {
                Ok(v) if !t.is_empty() && t.len() <= 2 => Some(v),
                _ => {
                    return Err((
                        skip + i.len() + 1,
                        format!("`{s}` is not a sub-index (hex 00..FF) in `{w}`"),
                    ));
                }
            }
        }
        None => None,
    };
    Ok(Some((index, sub)))
}

/// The parser state.
pub struct Parser<'a> {
    toks: Vec<Token>,
    at: usize,
    end: usize,
    names: &'a dyn Names,
    /// Names looked up so far: a name lookup scans the dictionaries, and every word of
    /// an implicit `and` tries the names of up to [`MAX_NAME_WORDS`] words it starts.
    looked_up: HashMap<String, Option<(u16, u8)>>,
    depth: usize,
}

impl<'a> Parser<'a> {
    /// A parser of `toks` from a text of `len` characters.
    pub fn new(toks: Vec<Token>, len: usize, names: &'a dyn Names) -> Parser<'a> {
        Parser {
            toks,
            at: 0,
            end: len + 1,
            names,
            looked_up: HashMap::new(),
            depth: 0,
        }
    }

    /// Parses the whole input; `None` when it has no token.
    pub fn parse(mut self) -> Result<Option<Expr>, FilterError> {
        if self.toks.is_empty() {
            return Ok(None);
        }
        let e = self.or()?;
        match self.toks.get(self.at) {
            None => Ok(Some(e)),
            Some(t) if t.tok == Tok::Close => Err(FilterError::new(t.column, "`)` without its `(`")),
            Some(t) => Err(FilterError::new(t.column, "unexpected token")),
        }
    }

    /// The object `text` names (looked up once per text).
    fn name(&mut self, text: String) -> Option<(u16, u8)> {
        if let Some(found) = self.looked_up.get(&text) {
            return *found;
        }
        let found = self.names.object(&text);
        self.looked_up.insert(text, found);
        found
    }

    fn peek(&self) -> Option<&Token> {
        self.toks.get(self.at)
    }

    fn peek_word(&self) -> Option<String> {
        match self.peek().map(|t| &t.tok) {
            Some(Tok::Word(w)) => Some(w.to_ascii_lowercase()),
            _ => None,
        }
    }

    fn next(&mut self) -> Option<Token> {
        let t = self.toks.get(self.at).cloned();
        self.at += t.is_some() as usize;
        t
    }

    /// The column where the next token starts (or the end of the text).
    fn here(&self) -> usize {
        self.peek().map(|t| t.column).unwrap_or(self.end)
    }

    fn or(&mut self) -> Result<Expr, FilterError> {
        let mut parts = vec![self.and()?];
        while self.peek_word().as_deref() == Some("or") {
            self.next();
            parts.push(self.and()?);
        }
        Ok(if parts.len() == 1 {
            parts.remove(0)
        } else {
            Expr::Or(parts)
        })
    }

    fn and(&mut self) -> Result<Expr, FilterError> {
        let mut parts = Vec::new();
        loop {
            match self.peek() {
                None => break,
                Some(t) if t.tok == Tok::Close => break,
                _ => {}
            }
            match self.peek_word().as_deref() {
                Some("or") => break,
                Some("and") if !parts.is_empty() => {
                    let t = self.next().expect("peeked");
                    if self.peek().is_none() {
                        return Err(FilterError::new(t.end(), "`and` needs a condition after it"));
                    }
                    continue;
                }
                _ => {}
            }
            parts.push(self.unary()?);
        }
        match parts.len() {
            0 => Err(FilterError::new(
                self.here(),
                match self.peek_word().as_deref() {
                    Some(w) => format!("`{w}` needs a condition before it"),
                    None => "a condition is missing here".to_string(),
                },
            )),
            1 => Ok(parts.remove(0)),
            _ => Ok(Expr::And(parts)),
        }
    }

    fn unary(&mut self) -> Result<Expr, FilterError> {
        let Some(t) = self.peek().cloned() else {
            return Err(FilterError::new(self.end, "a condition is missing here"));
        };
        let not = t.tok == Tok::Bang || matches!(&t.tok, Tok::Word(w) if w.eq_ignore_ascii_case("not"));
        if not || t.tok == Tok::Open {
            self.depth += 1;
            if self.depth > MAX_DEPTH {
                return Err(FilterError::new(t.column, "nested too deeply"));
            }
            self.next();
            let e = if not {
                if self.peek().is_none() {
                    return Err(FilterError::new(t.end(), "`not` needs a condition after it"));
                }
                Expr::Not(Box::new(self.unary()?))
            } else {
                let e = self.or()?;
                match self.next() {
                    Some(c) if c.tok == Tok::Close => e,
                    _ => return Err(FilterError::new(t.column, "`(` is never closed")),
                }
            };
            self.depth -= 1;
            return Ok(e);
        }
        if self.peek_word().as_deref() == Some("time") {
            self.next();
            return self.time();
        }
        Ok(Expr::Term(self.term()?))
    }

    /// A value word after a keyword (an `=` between them is allowed).
    fn value(&mut self, key: &Token, what: &str) -> Result<(usize, String), FilterError> {
        if matches!(self.peek().map(|t| &t.tok), Some(Tok::Cmp(Cmp::Eq))) {
            self.next();
        }
        match self.next() {
            Some(Token {
                tok: Tok::Word(w),
                column,
                ..
            }) => Ok((column, w)),
            Some(t) => Err(FilterError::new(t.column, format!("expected {what} here"))),
            None => Err(FilterError::new(
                key.end(),
                format!("`{}` needs {what}", word_of(key).to_ascii_lowercase()),
            )),
        }
    }

    fn term(&mut self) -> Result<Term, FilterError> {
        let t = self.next().expect("unary checked a token is there");
        let w = match &t.tok {
            Tok::Quoted(s) => return Ok(Term::Text(s.to_lowercase())),
            Tok::Word(w) => w.clone(),
            Tok::Close => return Err(FilterError::new(t.column, "`)` without its `(`")),
            Tok::Amp | Tok::Cmp(_) => {
                return Err(FilterError::new(
                    t.column,
                    "a comparison needs an object before it (e.g. `Statusword & 0x8`)",
                ));
            }
            Tok::Open | Tok::Bang => unreachable!("handled by unary"),
        };
        if let Some(term) = self.long_name(&w)? {
            return Ok(term);
        }
        let key = w.to_ascii_lowercase();
        match key.as_str() {
            "node" => {
                let (c, v) = self.value(&t, "a node-ID")?;
                let bad = || FilterError::new(c, format!("`{v}` is not a node-ID (0..127) or range (2-5)"));
                let (lo, hi) = v.split_once('-').unwrap_or((&v, &v));
                match (integer(lo), integer(hi)) {
                    (Some(lo), Some(hi)) if lo <= hi && hi < 128 => Ok(Term::Node(lo as u8, hi as u8)),
                    _ if !v.contains('-') => Err(FilterError::new(c, format!("`{v}` is not a node-ID (0..127)"))),
                    _ => Err(bad()),
                }
            }
            "iface" => Ok(Term::Iface(self.value(&t, "an interface name")?.1)),
            "kind" => {
                let (c, v) = self.value(&t, "a kind")?;
                kinds(&v).map(Term::Kinds).ok_or_else(|| {
                    FilterError::new(
                        c,
                        format!("unknown kind `{v}` (nmt sync emcy time tpdo rpdo pdo sdo heartbeat lss error other)"),
                    )
                })
            }
            "id" => {
                let (c, v) = self.value(&t, "a COB-ID")?;
                id_match(&v).map(Term::Id).ok_or_else(|| {
                    FilterError::new(
                        c,
                        format!("`{v}` is not a hex COB-ID (181, a range 700-77F or a mask 180/780)"),
                    )
                })
            }
            "tx" => Ok(Term::Tx(true)),
            "rx" => Ok(Term::Tx(false)),
            "abort" | "aborts" => match self.peek_word() {
                Some(v) if v.starts_with("0x") => {
                    let c = self.next().expect("peeked").column;
                    let h = &v[2..];
                    match u32::from_str_radix(h, 16) {
                        Ok(value) if !h.is_empty() && h.len() <= 8 => Ok(Term::Abort(Some(CodePrefix {
                            value,
                            digits: h.len() as u8,
                        }))),
                        _ => Err(FilterError::new(
                            c,
                            format!("`{v}` is not an abort code (up to 8 hex digits, e.g. 0x0602)"),
                        )),
                    }
                }
                _ => Ok(Term::Abort(None)),
            },
            "and" | "or" => Err(FilterError::new(
                t.column,
                format!("`{key}` needs a condition before it"),
            )),
            _ => {
                if let Some(k) = kinds(&w) {
                    return Ok(Term::Kinds(k));
                }
                let object = match hex_object(&w) {
                    Ok(Some(o)) => Some(o),
                    Err((at, msg)) => return Err(FilterError::new(t.column + at, msg)),
                    Ok(None) => self.name(w.clone()).map(|(i, s)| (i, Some(s))),
                };
                match object {
                    Some((index, sub)) => self.object(index, sub),
                    None => Err(FilterError::new(
                        t.column,
                        format!(
                            "unknown word `{w}` (not a keyword, kind, object or alias; free text goes in quotes: \"{w}\")"
                        ),
                    )),
                }
            }
        }
    }

    /// An object name of several words starting with `first` (the longest that names one).
    fn long_name(&mut self, first: &str) -> Result<Option<Term>, FilterError> {
        // A keyword keeps its meaning (profiles name subs like `Node 3`).
        if KEYWORDS.contains(&first.to_ascii_lowercase().as_str()) {
            return Ok(None);
        }
        let mut words = vec![first.to_string()];
        for t in &self.toks[self.at..] {
            match &t.tok {
                Tok::Word(w) if !KEYWORDS[8..].contains(&w.to_ascii_lowercase().as_str()) => words.push(w.clone()),
                _ => break,
            }
            if words.len() == MAX_NAME_WORDS {
                break;
            }
        }
        for n in (2..=words.len()).rev() {
            if let Some((index, sub)) = self.name(words[..n].join(" ")) {
                self.at += n - 1;
                return self.object(index, Some(sub)).map(Some);
            }
        }
        Ok(None)
    }

    /// An object term with its optional value test.
    fn object(&mut self, index: u16, sub: Option<u8>) -> Result<Term, FilterError> {
        let mut test = Test { mask: None, cmp: None };
        if let Some(amp) = self.peek().filter(|t| t.tok == Tok::Amp).cloned() {
            self.next();
            let (c, v) = self.operand(&amp, "a mask")?;
            test.mask = Some(
                integer(&v)
                    .ok_or_else(|| FilterError::new(c, format!("`{v}` is not an integer mask (e.g. 0x0008)")))?,
            );
        }
        if let Some(op) = self.peek().filter(|t| matches!(t.tok, Tok::Cmp(_))).cloned() {
            self.next();
            let Tok::Cmp(cmp) = op.tok else { unreachable!() };
            let (c, v) = self.operand(&op, "a number")?;
            test.cmp = Some((
                cmp,
                number(&v).ok_or_else(|| FilterError::new(c, format!("`{v}` is not a number")))?,
            ));
        }
        let test = (test.mask.is_some() || test.cmp.is_some()).then_some(test);
        Ok(Term::Object { index, sub, test })
    }

    fn operand(&mut self, op: &Token, what: &str) -> Result<(usize, String), FilterError> {
        match self.next() {
            Some(Token {
                tok: Tok::Word(w),
                column,
                ..
            }) => Ok((column, w)),
            Some(t) => Err(FilterError::new(t.column, format!("expected {what} here"))),
            None => Err(FilterError::new(
                op.end(),
                format!("expected {what} after the operator"),
            )),
        }
    }

    /// `time A-B`, `time A-`, `time OP SECONDS`, or the TIME kind.
    fn time(&mut self) -> Result<Expr, FilterError> {
        match self.peek().map(|t| t.tok.clone()) {
            Some(Tok::Cmp(cmp)) => {
                let op = self.next().expect("peeked");
                let (c, v) = self.operand(&op, "seconds")?;
                let s = number(&v).ok_or_else(|| FilterError::new(c, format!("`{v}` is not seconds")))?;
                Ok(Expr::Term(Term::Time(cmp, s)))
            }
            Some(Tok::Word(v)) if v.starts_with(|c: char| c.is_ascii_digit() || c == '.') => {
                let c = self.next().expect("peeked").column;
                let bad = || {
                    FilterError::new(
                        c,
                        format!("`{v}` is not a time range in seconds from the first frame (e.g. 1.5-3.0 or 10-)"),
                    )
                };
                let (a, b) = v.split_once('-').ok_or_else(bad)?;
                let a: f64 = a.parse().map_err(|_| bad())?;
                if b.is_empty() {
                    return Ok(Expr::Term(Term::Time(Cmp::Ge, a)));
                }
                let b: f64 = b.parse().map_err(|_| bad())?;
                if b < a {
                    return Err(bad());
                }
                Ok(Expr::And(vec![
                    Expr::Term(Term::Time(Cmp::Ge, a)),
                    Expr::Term(Term::Time(Cmp::Le, b)),
                ]))
            }
            _ => {
                // A multi-word object name may start with "time".
                self.at -= 1;
                Ok(Expr::Term(self.term()?))
            }
        }
    }
}

fn word_of(t: &Token) -> &str {
    match &t.tok {
        Tok::Word(w) => w,
        _ => "",
    }
}

/// `181`, `700-77f`, `180/780` (hex, optional `0x`).
fn id_match(v: &str) -> Option<IdMatch> {
    let hex = |s: &str| {
        let s = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).unwrap_or(s);
        (!s.is_empty()).then(|| u32::from_str_radix(s, 16).ok()).flatten()
    };
    if let Some((a, b)) = v.split_once('-') {
        let (a, b) = (hex(a)?, hex(b)?);
        return (a <= b).then_some(IdMatch::Range(a, b));
    }
    if let Some((a, m)) = v.split_once('/') {
        let (value, mask) = (hex(a)?, hex(m)?);
        return Some(IdMatch::Mask { value, mask });
    }
    hex(v).map(|x| IdMatch::Range(x, x))
}
