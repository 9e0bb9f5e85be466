//! The transmit list file of `send --list FILE` (PCAN-View's transmit window as a file):
//! parsing its text and turning each entry into the exact frame it sends. Pure: the text
//! comes in, entries or located errors come out (the caller reads the file).
//!
//! The file is JSON, one object with an `entries` array:
//!
//! ```json
//! {
//!   "entries": [
//!     { "frame": "601#4041600000000000", "every_ms": 100, "comment": "poll the statusword" },
//!     { "rpdo": "rpdo1", "node": 2, "signals": { "Controlword": "0x0F", "Target velocity": 500 },
//!       "every_ms": "10ms", "count": 50 },
//!     { "frame": "000#0100", "enabled": false, "comment": "NMT start all, by hand" }
//!   ]
//! }
//! ```
//!
//! Each entry is either a raw `frame` (candump's compact form, as `send FRAME` takes it) or
//! an RPDO by name: `rpdo` (`rpdo1`..), `node` and `signals` (name, alias or index:sub to a
//! value, encoded through the node's mapping as `pdo NODE send` does; mapped signals not
//! given are sent as 0). `every_ms`: the period (a number of ms, or a duration text as the
//! `--every` flag takes it); absent: sent once (or `count` times back to back). `enabled`
//! (default true): a disabled entry is listed and not sent. `count`: stop that entry after
//! so many frames. `comment`: free text. A bad entry (a bad frame, an unknown signal, a
//! period of 0, an unknown field) is named by its index (from 1) and its line in the file.

use super::cyclic::{Schedule, rpdo};
use super::error::CommandError;
use super::words::{frame_arg, ms_arg, pdo_arg};
use crate::frame::Frame;
use crate::od::bind::Bindings;
use serde::Deserialize;
use serde_json::value::RawValue;
use std::collections::BTreeMap;
use std::fmt;

/// A transmit list as read from its file, not yet bound to node dictionaries.
#[derive(Clone, Debug, PartialEq)]
pub struct TransmitList {
    pub entries: Vec<Entry>,
}

/// One entry of a transmit list.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// Its index in the list, from 1.
    pub index: usize,
    /// Its line in the file (from 1): where its object starts.
    pub line: usize,
    pub what: What,
    pub schedule: Schedule,
    pub enabled: bool,
    pub comment: Option<String>,
}

/// What an entry sends.
#[derive(Clone, Debug, PartialEq)]
pub enum What {
    /// A raw frame.
    Frame(Frame),
    /// RPDO `num` of `node`, encoded from `signals` (NAME, VALUE) through the node's mapping.
    Rpdo {
        node: u8,
        num: u16,
        signals: Vec<(String, String)>,
    },
}

/// An entry bound to the dictionaries: the exact frame it sends.
#[derive(Clone, Debug, PartialEq)]
pub struct Resolved {
    /// Its index in the list, from 1.
    pub index: usize,
    pub line: usize,
    pub frame: Frame,
    /// What it is, for reports: `601#40...` or `RPDO1 node 2 202#0F00...`.
    pub what: String,
    pub schedule: Schedule,
    pub enabled: bool,
    pub comment: Option<String>,
    /// Mapped signals not given, sent as 0 (RPDO entries).
    pub defaulted: Vec<String>,
}

/// Why a list (or some of its entries) cannot be used: one line per problem, each naming
/// the entry and its line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ListError {
    pub problems: Vec<Problem>,
}

/// One problem of a list: in entry `entry` (from 1; `None`: the file as a whole) at `line`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    pub entry: Option<usize>,
    pub line: usize,
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.entry {
            Some(k) => write!(f, "entry {k} (line {}): {}", self.line, self.message),
            None => write!(f, "line {}: {}", self.line, self.message),
        }
    }
}

impl fmt::Display for ListError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lines: Vec<String> = self.problems.iter().map(Problem::to_string).collect();
        f.write_str(&lines.join("\n"))
    }
}

/// The file's outer object.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileJson<'a> {
    #[serde(borrow)]
    entries: Vec<&'a RawValue>,
}

/// A period: ms as a number, or a duration text (`"500ms"`).
#[derive(Deserialize)]
#[serde(untagged)]
enum PeriodJson {
    Ms(u64),
    Text(String),
}

/// A signal value: a number or a text (`"0x0F"`).
#[derive(Deserialize)]
#[serde(untagged)]
enum ValueJson {
    Int(i64),
    Float(f64),
    Text(String),
}

/// One entry as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EntryJson {
    frame: Option<String>,
    rpdo: Option<String>,
    node: Option<u8>,
    signals: Option<BTreeMap<String, ValueJson>>,
    every_ms: Option<PeriodJson>,
    enabled: Option<bool>,
    count: Option<u64>,
    comment: Option<String>,
}

/// The line (from 1) of byte `offset` of `text`.
fn line_of(text: &str, offset: usize) -> usize {
    1 + text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|b| **b == b'\n')
        .count()
}

impl TransmitList {
    /// Parses the text of a list file; every bad entry is reported (with its line), not
    /// only the first.
    pub fn parse(text: &str) -> Result<TransmitList, ListError> {
        let (entries, problems): (Vec<_>, Vec<_>) = parse_entries(text)?.into_iter().partition(Result::is_ok);
        if problems.is_empty() {
            Ok(TransmitList {
                entries: entries.into_iter().flatten().collect(),
            })
        } else {
            Err(ListError {
                problems: problems.into_iter().filter_map(Result::err).collect(),
            })
        }
    }
}

/// Parses and resolves the text of a list file at once: every bad entry is reported, those
/// the parser refuses (a bad frame, a period of 0) and those the dictionaries refuse (an
/// unknown signal) alike, in the order of the file.
pub fn load(text: &str, bindings: &Bindings) -> Result<Vec<Resolved>, ListError> {
    gather(
        parse_entries(text)?
            .into_iter()
            .map(|e| e.and_then(|e| resolve(&e, bindings)))
            .collect(),
    )
}

/// One entry of [`load_each`]: its JSON text and what it resolves to, or its problem.
pub type EachEntry = (String, Result<Resolved, Problem>);

/// Each entry of a list file (its JSON text and what it resolves to, or its located
/// problem), so that a bad entry does not keep the others from being used (the TUI's
/// Transmit pane); the file itself not a list: an error.
pub fn load_each(text: &str, bindings: &Bindings) -> Result<Vec<EachEntry>, ListError> {
    let raws = raw_entries(text)?;
    Ok(parse_entries(text)?
        .into_iter()
        .zip(raws)
        .map(|(e, raw)| (raw, e.and_then(|e| resolve(&e, bindings))))
        .collect())
}

/// One entry from its JSON text alone (`{"frame": "123#01", "every_ms": 100}`, as typed in
/// the TUI), entry `index` of its list, resolved through `bindings`.
pub fn load_entry(text: &str, index: usize, bindings: &Bindings) -> Result<Resolved, Problem> {
    entry(text, index, 1)
        .map_err(|(line, message)| Problem {
            entry: Some(index),
            line,
            message,
        })
        .and_then(|e| resolve(&e, bindings))
}

/// The JSON text of each entry of a list file.
fn raw_entries(text: &str) -> Result<Vec<String>, ListError> {
    let file: FileJson = serde_json::from_str(text).map_err(|e| ListError {
        problems: vec![Problem {
            entry: None,
            line: e.line().max(1),
            message: format!("not a transmit list ({e})"),
        }],
    })?;
    Ok(file.entries.iter().map(|r| r.get().to_string()).collect())
}

/// The entries, or every problem among them.
fn gather(all: Vec<Result<Resolved, Problem>>) -> Result<Vec<Resolved>, ListError> {
    let (ok, problems): (Vec<_>, Vec<_>) = all.into_iter().partition(Result::is_ok);
    if problems.is_empty() {
        Ok(ok.into_iter().flatten().collect())
    } else {
        Err(ListError {
            problems: problems.into_iter().filter_map(Result::err).collect(),
        })
    }
}

/// Each entry of the file parsed, or its problem; the file itself not a list: an error.
fn parse_entries(text: &str) -> Result<Vec<Result<Entry, Problem>>, ListError> {
    let file: FileJson = serde_json::from_str(text).map_err(|e| ListError {
        problems: vec![Problem {
            entry: None,
            line: e.line().max(1),
            message: format!(
                "not a transmit list ({e}); write {{\"entries\": [{{\"frame\": \"601#40...\", \"every_ms\": 100}}, ...]}}"
            ),
        }],
    })?;
    Ok(file
        .entries
        .iter()
        .enumerate()
        .map(|(k, raw)| {
            let offset = raw.get().as_ptr() as usize - text.as_ptr() as usize;
            let line = line_of(text, offset);
            entry(raw.get(), k + 1, line).map_err(|(at, message)| Problem {
                entry: Some(k + 1),
                line: at,
                message,
            })
        })
        .collect())
}

/// An entry's exact frame through the node dictionaries of `bindings`.
fn resolve(e: &Entry, bindings: &Bindings) -> Result<Resolved, Problem> {
    let (frame, what, defaulted) = match &e.what {
        What::Frame(f) => (*f, super::spec::candump(f), Vec::new()),
        What::Rpdo { node, num, signals } => {
            let r = rpdo(bindings, *node, *num, signals).map_err(|err| Problem {
                entry: Some(e.index),
                line: e.line,
                message: err.to_string(),
            })?;
            let what = format!("RPDO{num} node {node} {}", super::spec::candump(&r.frame));
            (r.frame, what, r.defaulted)
        }
    };
    Ok(Resolved {
        index: e.index,
        line: e.line,
        frame,
        what,
        schedule: e.schedule,
        enabled: e.enabled,
        comment: e.comment.clone(),
        defaulted,
    })
}

impl From<ListError> for CommandError {
    fn from(e: ListError) -> Self {
        CommandError::Usage(e.to_string())
    }
}

/// Entry `index` from its JSON text, which starts at `line`; on error, the line and why.
fn entry(text: &str, index: usize, line: usize) -> Result<Entry, (usize, String)> {
    let e: EntryJson =
        serde_json::from_str(text).map_err(|err| (line + err.line().saturating_sub(1), err.to_string()))?;
    let bad = |m: String| (line, m);
    let what = match (e.frame, e.rpdo) {
        (Some(_), Some(_)) => return Err(bad("give `frame` or `rpdo`, not both".into())),
        (None, None) => {
            return Err(bad(
                "give `frame` (\"601#4041600000000000\") or `rpdo` (\"rpdo1\") with `node` and `signals`".into(),
            ));
        }
        (Some(f), None) => {
            if let Some(field) = [("node", e.node.is_some()), ("signals", e.signals.is_some())]
                .iter()
                .find_map(|(n, on)| on.then_some(*n))
            {
                return Err(bad(format!("`{field}` goes with `rpdo`, not with `frame`")));
            }
            What::Frame(frame_arg(&f).map_err(|err| bad(err.to_string()))?)
        }
        (None, Some(p)) => {
            let pdo = pdo_arg(&p).map_err(|err| bad(err.to_string()))?;
            if pdo.transmit {
                return Err(bad(format!(
                    "`{p}` is not an RPDO: use rpdo1, rpdo2, ... (TPDOs are the node's to send)"
                )));
            }
            let node = e.node.filter(|n| (1..=127).contains(n)).ok_or_else(|| {
                bad(format!(
                    "`rpdo` needs `node` 1..127{}",
                    e.node.map(|n| format!(" (not {n})")).unwrap_or_default()
                ))
            })?;
            let signals = e
                .signals
                .unwrap_or_default()
                .into_iter()
                .map(|(name, v)| {
                    let text = match v {
                        ValueJson::Int(i) => i.to_string(),
                        ValueJson::Float(x) => x.to_string(),
                        ValueJson::Text(t) => t,
                    };
                    (name, text)
                })
                .collect();
            What::Rpdo {
                node,
                num: pdo.num,
                signals,
            }
        }
    };
    let every_ms = match e.every_ms {
        None => None,
        Some(PeriodJson::Ms(0)) => {
            return Err(bad(
                "`every_ms` is 0: give a period > 0, or leave it out to send once".into()
            ));
        }
        Some(PeriodJson::Ms(ms)) => Some(ms),
        Some(PeriodJson::Text(t)) => Some(ms_arg(&t).map_err(|err| bad(format!("`every_ms`: {err}")))?),
    };
    if e.count == Some(0) {
        return Err(bad("`count` is 0: give a count > 0, or leave it out".into()));
    }
    Ok(Entry {
        index,
        line,
        what,
        schedule: Schedule {
            every_ms,
            count: e.count,
        },
        enabled: e.enabled.unwrap_or(true),
        comment: e.comment,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIST: &str = r#"{
  "entries": [
    { "frame": "601#4041600000000000", "every_ms": 100, "comment": "statusword" },
    {
      "rpdo": "rpdo1", "node": 2,
      "signals": { "Controlword": "0x0F", "Target velocity": 500 },
      "every_ms": "10", "count": 5
    },
    { "frame": "000#0100", "enabled": false }
  ]
}"#;

    fn demo_bindings() -> Bindings {
        crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap()
    }

    #[test]
    fn entries_parse_with_their_lines_and_resolve_to_frames() {
        let list = TransmitList::parse(LIST).unwrap();
        let lines: Vec<usize> = list.entries.iter().map(|e| e.line).collect();
        assert_eq!(lines, [3, 4, 9]);
        assert_eq!(
            list.entries[1].schedule,
            Schedule {
                every_ms: Some(10),
                count: Some(5)
            }
        );
        assert!(!list.entries[2].enabled);
        let r = load(LIST, &demo_bindings()).unwrap();
        let whats: Vec<&str> = r.iter().map(|e| e.what.as_str()).collect();
        assert_eq!(
            whats,
            ["601#4041600000000000", "RPDO1 node 2 202#0F00F4010000", "000#0100"]
        );
        assert_eq!(r[0].comment.as_deref(), Some("statusword"));
    }

    #[test]
    fn bad_entries_name_their_index_and_line() {
        let text = "{\"entries\": [\n  {\"frame\": \"601#4G\"},\n  {\"frame\": \"601#40\", \"every_ms\": 0},\n  {\"frame\": \"1#\", \"evry_ms\": 5}\n]}";
        let e = TransmitList::parse(text).unwrap_err().to_string();
        let lines: Vec<&str> = e.lines().collect();
        assert_eq!(lines.len(), 3, "{e}");
        assert!(lines[0].starts_with("entry 1 (line 2): `601#4G` is not a frame"), "{e}");
        assert!(lines[1].starts_with("entry 2 (line 3): `every_ms` is 0"), "{e}");
        assert!(lines[2].starts_with("entry 3 (line 4): unknown field `evry_ms`"), "{e}");
        let text = "{\"entries\": [\n{\"frame\": \"601#40\"},\n\n{\"rpdo\": \"rpdo1\", \"node\": 2,\n \"signals\": {\"Speed\": 3}}]}";
        let e = load(text, &demo_bindings()).unwrap_err().to_string();
        assert!(e.starts_with("entry 2 (line 4): "), "{e}");
        assert!(e.contains("RPDO1 of node 2 maps: Controlword (0x6040:00)"), "{e}");
        let both = "{\"entries\": [\n{\"frame\": \"601#4G\"},\n{\"rpdo\": \"rpdo1\", \"node\": 2, \"signals\": {\"Speed\": 3}}]}";
        let e = load(both, &demo_bindings()).unwrap_err();
        let at: Vec<(Option<usize>, usize)> = e.problems.iter().map(|p| (p.entry, p.line)).collect();
        assert_eq!(at, [(Some(1), 2), (Some(2), 3)], "{e}");
        let e = TransmitList::parse("{\"entries\": 3}").unwrap_err().to_string();
        assert!(e.starts_with("line 1: not a transmit list"), "{e}");
        let e = TransmitList::parse("{\"entries\": [{\"rpdo\": \"tpdo1\", \"node\": 2}]}")
            .unwrap_err()
            .to_string();
        assert!(e.contains("is not an RPDO"), "{e}");
    }
}
