//! Boot stories: for each node, each boot (a boot-up, or an NMT reset of it) up to its
//! first TPDO or heartbeat in Operational, with the configuration written to it (SDO
//! downloads) and the NMT commands, in order. A boot is compared with the node's first
//! complete boot (the reference) and with an expected configuration (a DCF's values, given
//! as plain [`Expected`] values); each difference is a [`Finding`]. Pure: built by the
//! diagnosis from frames and transfers (`diagnose/boot_config.rs`).

use crate::frame::NodeKey;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// How a write ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WriteResult {
    /// The node confirmed it.
    Ok,
    /// The node (or the client) aborted it: the abort text.
    Refused(String),
    /// No answer came.
    Unanswered,
}

impl WriteResult {
    /// JSON name: `ok`, `refused`, `unanswered`.
    pub fn as_str(&self) -> &'static str {
        match self {
            WriteResult::Ok => "ok",
            WriteResult::Refused(_) => "refused",
            WriteResult::Unanswered => "unanswered",
        }
    }
}

/// Bytes of a written value kept (a longer one, e.g. a domain, is kept as its length and
/// a digest of all its bytes, so memory stays small).
pub const DATA_KEPT: usize = 64;

/// A value written: its first [`DATA_KEPT`] bytes, its length and a digest of all of it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bytes {
    /// The first bytes (little-endian, as on the wire).
    pub head: Vec<u8>,
    /// All bytes.
    pub len: usize,
    /// FNV-1a of all bytes.
    digest: u64,
}

impl Bytes {
    /// The value of `b`.
    pub fn of(b: &[u8]) -> Bytes {
        let digest = b.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
            (h ^ u64::from(*x)).wrapping_mul(0x100_0000_01b3)
        });
        Bytes {
            head: b[..b.len().min(DATA_KEPT)].to_vec(),
            len: b.len(),
            digest,
        }
    }

    /// The same value: numbers (up to 8 bytes) compared as numbers are, the shorter one
    /// padded with zero bytes (a client may send a 16-bit value in 4 bytes); longer values
    /// byte for byte.
    pub fn same(&self, other: &Bytes) -> bool {
        if self.len <= 8 && other.len <= 8 {
            same_bytes(&self.head, &other.head)
        } else {
            self.len == other.len && self.digest == other.digest
        }
    }

    /// The value in words ([`value_text`]; a longer one cut, with its length).
    pub fn text(&self) -> String {
        let mut s = value_text(&self.head);
        if self.len > self.head.len() {
            let _ = write!(s, " … ({} bytes)", self.len);
        }
        s
    }
}

/// One SDO download to the node during a boot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Write {
    /// Frame number of its request.
    pub frame: u64,
    /// Time of its request (ns).
    pub t_ns: u64,
    pub index: u16,
    pub sub: u8,
    /// The value written.
    pub data: Bytes,
    pub result: WriteResult,
}

/// What a boot was and what happened in it, in order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BootStep {
    /// A configuration write.
    Write(Write),
    /// An NMT command to the node (`all`: addressed to all nodes).
    Nmt {
        frame: u64,
        t_ns: u64,
        command: &'static str,
        all: bool,
    },
    /// The node's boot-up message.
    BootUp { frame: u64, t_ns: u64 },
}

impl BootStep {
    /// The frame number of the step.
    pub fn frame(&self) -> u64 {
        match self {
            BootStep::Write(w) => w.frame,
            BootStep::Nmt { frame, .. } | BootStep::BootUp { frame, .. } => *frame,
        }
    }
}

/// The frame that showed a boot reached Operational.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Operational {
    pub frame: u64,
    pub t_ns: u64,
    /// What showed it: `heartbeat` or `TPDO`.
    pub by: &'static str,
}

/// One boot of one node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Boot {
    pub node: NodeKey,
    /// 1-based, per node.
    pub number: u32,
    /// Frame and time the boot began (its boot-up or the NMT reset).
    pub frame: u64,
    pub t_ns: u64,
    /// When it reached Operational; None: it did not within the capture (or before the
    /// next boot).
    pub operational: Option<Operational>,
    pub steps: Vec<BootStep>,
    /// The boot it was compared with (None: it is the reference, or there is none).
    pub reference: Option<u32>,
    /// What differs from the reference and from the expected configuration.
    pub findings: Vec<Finding>,
}

impl Boot {
    /// The writes of the boot, in order.
    pub fn writes(&self) -> impl Iterator<Item = &Write> {
        self.steps.iter().filter_map(|s| match s {
            BootStep::Write(w) => Some(w),
            _ => None,
        })
    }

    /// The last write of each object that is configuration (not a command or a
    /// set-point: [`crate::od::not_configuration`]), by (index, sub).
    fn last_writes(&self) -> BTreeMap<(u16, u8), &Write> {
        self.writes()
            .filter(|w| crate::od::not_configuration(w.index).is_none())
            .map(|w| ((w.index, w.sub), w))
            .collect()
    }
}

/// A value a DCF expects a node to have, typed at the CLI edge.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Expected {
    pub index: u16,
    pub sub: u8,
    /// The value (little-endian bytes of its type).
    pub bytes: Bytes,
    /// The value differs from the object's default: a boot must write it.
    pub must_write: bool,
}

/// The kind of a finding (the JSON `kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FindingKind {
    /// Written with another value than the reference or expected one.
    Different,
    /// Not written, although the reference wrote it or the configuration needs it.
    Missing,
    /// Written, although the reference did not or the configuration does not have it.
    Extra,
    /// The write was aborted.
    Refused,
    /// The write got no answer.
    Unanswered,
}

impl FindingKind {
    /// JSON name.
    pub fn as_str(self) -> &'static str {
        match self {
            FindingKind::Different => "different",
            FindingKind::Missing => "missing",
            FindingKind::Extra => "extra",
            FindingKind::Refused => "refused",
            FindingKind::Unanswered => "unanswered",
        }
    }
}

/// What a boot is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Against {
    /// The node's first complete boot (its number).
    Reference(u32),
    /// The expected configuration (`--expect NODE=FILE.dcf`).
    Expected,
}

/// One difference of one object in one boot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Finding {
    pub kind: FindingKind,
    pub against: Against,
    pub index: u16,
    pub sub: u8,
    /// The value this boot wrote (None: not written).
    pub value: Option<Bytes>,
    /// The reference's or expected value (None: none there).
    pub wanted: Option<Bytes>,
    /// The abort text of a refused write.
    pub abort: Option<String>,
    /// Frame and time of this boot's write (None: not written).
    pub at: Option<(u64, u64)>,
}

/// Whether two values hold the same number: the shorter one padded with zero bytes.
fn same_bytes(a: &[u8], b: &[u8]) -> bool {
    let at = |v: &[u8], i: usize| v.get(i).copied().unwrap_or(0);
    (0..a.len().max(b.len())).all(|i| at(a, i) == at(b, i))
}

/// The finding of a write that did not go through, if it did not.
fn failed(w: &Write, against: Against, wanted: Option<&Bytes>) -> Option<Finding> {
    let (kind, abort) = match &w.result {
        WriteResult::Ok => return None,
        WriteResult::Refused(text) => (FindingKind::Refused, Some(text.clone())),
        WriteResult::Unanswered => (FindingKind::Unanswered, None),
    };
    Some(Finding {
        kind,
        against,
        index: w.index,
        sub: w.sub,
        value: Some(w.data.clone()),
        wanted: wanted.cloned(),
        abort,
        at: Some((w.frame, w.t_ns)),
    })
}

/// A finding of write `w` (or of none) against `against`.
fn finding(kind: FindingKind, against: Against, key: (u16, u8), w: Option<&Write>, wanted: Option<&Bytes>) -> Finding {
    Finding {
        kind,
        against,
        index: key.0,
        sub: key.1,
        value: w.map(|w| w.data.clone()),
        wanted: wanted.cloned(),
        abort: None,
        at: w.map(|w| (w.frame, w.t_ns)),
    }
}

/// What `boot` does otherwise than `reference` (the node's first complete boot), per
/// object (its last write): nothing when they agree. Missing writes count only for a boot
/// that reached Operational (one cut short did not finish its configuration).
pub fn against_reference(boot: &Boot, reference: &Boot) -> Vec<Finding> {
    let against = Against::Reference(reference.number);
    let mine = boot.last_writes();
    let theirs = reference.last_writes();
    let mut out = Vec::new();
    for (key, w) in &mine {
        let r = theirs.get(key);
        let wanted = r.map(|r| &r.data);
        if let Some(f) = failed(w, against, wanted) {
            // A write refused the same way in the reference is how the node is.
            if r.is_none_or(|r| r.result != w.result) {
                out.push(f);
            }
            continue;
        }
        match r {
            None => out.push(finding(FindingKind::Extra, against, *key, Some(w), None)),
            Some(r) if r.result == WriteResult::Ok && !w.data.same(&r.data) => {
                out.push(finding(FindingKind::Different, against, *key, Some(w), wanted))
            }
            Some(_) => {}
        }
    }
    if boot.operational.is_some() {
        for (key, r) in &theirs {
            if r.result == WriteResult::Ok && !mine.contains_key(key) {
                out.push(finding(FindingKind::Missing, against, *key, None, Some(&r.data)));
            }
        }
    }
    sort(&mut out);
    out
}

/// What `boot` does otherwise than the expected configuration: a write of another value,
/// refused or unanswered, of an object the configuration does not have (extra), and
/// (for a boot that reached Operational) a value that differs from its default and was not
/// written (missing).
pub fn against_expected(boot: &Boot, expected: &[Expected]) -> Vec<Finding> {
    let against = Against::Expected;
    let mine = boot.last_writes();
    let want: BTreeMap<(u16, u8), &Expected> = expected.iter().map(|e| ((e.index, e.sub), e)).collect();
    let mut out = Vec::new();
    for (key, w) in &mine {
        let e = want.get(key).map(|e| &e.bytes);
        if let Some(f) = failed(w, against, e) {
            out.push(f);
            continue;
        }
        match e {
            None => out.push(finding(FindingKind::Extra, against, *key, Some(w), None)),
            Some(e) if !w.data.same(e) => out.push(finding(FindingKind::Different, against, *key, Some(w), Some(e))),
            Some(_) => {}
        }
    }
    if boot.operational.is_some() {
        for (key, e) in &want {
            if e.must_write && !mine.contains_key(key) {
                out.push(finding(FindingKind::Missing, against, *key, None, Some(&e.bytes)));
            }
        }
    }
    sort(&mut out);
    out
}

/// Findings in object order.
fn sort(out: &mut [Finding]) {
    out.sort_by_key(|f| (f.index, f.sub));
}

/// Bytes as the value they hold: `0x03E8` (little-endian, up to 8 bytes, two hex digits a
/// byte), longer ones as hex bytes in order (`48 65 6C ...`).
pub fn value_text(b: &[u8]) -> String {
    if b.is_empty() {
        return "(empty)".to_string();
    }
    if b.len() <= 8 {
        let mut s = String::from("0x");
        for byte in b.iter().rev() {
            let _ = write!(s, "{byte:02X}");
        }
        return s;
    }
    let parts: Vec<String> = b.iter().map(|x| format!("{x:02X}")).collect();
    parts.join(" ")
}

/// `0x1017:00`.
pub fn object_text(index: u16, sub: u8) -> String {
    format!("0x{index:04X}:{sub:02X}")
}

impl Finding {
    /// What it is, in words: `0x1017:00 written 0x03E8, boot 1 wrote 0x01F4`.
    pub fn text(&self) -> String {
        let obj = object_text(self.index, self.sub);
        let value = self.value.as_ref().map(Bytes::text).unwrap_or_default();
        let wanted = self.wanted.as_ref().map(Bytes::text).unwrap_or_default();
        let (had, lacks) = match self.against {
            Against::Reference(n) => (format!("boot {n} wrote"), format!("boot {n} did not write it")),
            Against::Expected => ("the DCF says".to_string(), "the DCF does not have it".to_string()),
        };
        match self.kind {
            FindingKind::Different => format!("{obj} written {value}, {had} {wanted}"),
            FindingKind::Missing => format!("{obj} not written, {had} {wanted}"),
            FindingKind::Extra => format!("{obj} written {value}, {lacks}"),
            FindingKind::Refused => format!(
                "{obj} write of {value} refused: {}",
                self.abort.as_deref().unwrap_or("aborted")
            ),
            FindingKind::Unanswered => format!("{obj} write of {value} not answered"),
        }
    }

    /// The JSON object of a finding (times since `origin`).
    pub fn to_json(&self, origin: u64) -> FindingJson<'_> {
        let wanted = self.wanted.as_ref().map(Bytes::text);
        let (reference, expected) = match self.against {
            Against::Reference(_) => (wanted, None),
            Against::Expected => (None, wanted),
        };
        FindingJson {
            abort: self.abort.as_deref(),
            against: match self.against {
                Against::Reference(_) => "reference",
                Against::Expected => "expected",
            },
            expected,
            frame: self.at.map(|a| a.0),
            index: format!("0x{:04X}", self.index),
            kind: self.kind.as_str(),
            reference,
            reference_boot: match self.against {
                Against::Reference(n) => Some(n),
                Against::Expected => None,
            },
            subindex: self.sub,
            t: self.at.map(|a| secs(a.1, origin)),
            value: self.value.as_ref().map(Bytes::text),
        }
    }
}

/// Seconds since `origin` with µs precision, for JSON.
fn secs(t_ns: u64, origin: u64) -> f64 {
    (t_ns.saturating_sub(origin) / 1000) as f64 / 1e6
}

/// One finding as JSON (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct FindingJson<'a> {
    /// The abort text of a refused write.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub abort: Option<&'a str>,
    /// `reference` or `expected`.
    pub against: &'static str,
    /// The DCF's value (against `expected`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expected: Option<String>,
    /// The frame that ended the write (null: not written).
    pub frame: Option<u64>,
    /// `0x1017`.
    pub index: String,
    /// `different`, `missing`, `extra`, `refused`, `unanswered`.
    pub kind: &'static str,
    /// The reference boot's value (against `reference`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference: Option<String>,
    /// The reference boot's number (against `reference`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_boot: Option<u32>,
    pub subindex: u8,
    /// Seconds since the capture's first frame (null: not written).
    pub t: Option<f64>,
    /// The value written (null: not written).
    pub value: Option<String>,
}

/// One boot as a JSON line of `diagnose --boots --format jsonl` (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct BootJson<'a> {
    pub boot: u32,
    pub findings: Vec<FindingJson<'a>>,
    pub frame: u64,
    pub node: u8,
    /// Seconds since the first frame it reached Operational (null: it did not).
    pub operational: Option<f64>,
    /// What showed Operational: `heartbeat` or `TPDO`.
    pub operational_by: Option<&'static str>,
    /// The reference boot's number (null: this is the reference, or there is none).
    pub reference: Option<u32>,
    pub steps: Vec<StepJson>,
    pub t: f64,
}

/// One step of a boot as JSON (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct StepJson {
    /// Abort text of a refused write.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub abort: Option<String>,
    /// The NMT command (kind `nmt`), `(all nodes)` added when addressed to all.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<String>,
    pub frame: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub index: Option<String>,
    /// `write`, `nmt`, `boot_up`.
    pub kind: &'static str,
    /// `ok`, `refused`, `unanswered` (writes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub result: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subindex: Option<u8>,
    pub t: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<String>,
}

impl Boot {
    /// The JSON line of `diagnose --boots` (times since `origin`).
    pub fn to_json(&self, origin: u64) -> BootJson<'_> {
        let steps = self
            .steps
            .iter()
            .map(|s| {
                let mut j = StepJson {
                    abort: None,
                    command: None,
                    frame: 0,
                    index: None,
                    kind: "",
                    result: None,
                    subindex: None,
                    t: 0.0,
                    value: None,
                };
                match s {
                    BootStep::Write(w) => {
                        j.kind = "write";
                        (j.frame, j.t) = (w.frame, secs(w.t_ns, origin));
                        j.index = Some(format!("0x{:04X}", w.index));
                        j.subindex = Some(w.sub);
                        j.value = Some(w.data.text());
                        j.result = Some(w.result.as_str());
                        if let WriteResult::Refused(text) = &w.result {
                            j.abort = Some(text.clone());
                        }
                    }
                    BootStep::Nmt {
                        frame,
                        t_ns,
                        command,
                        all,
                    } => {
                        j.kind = "nmt";
                        (j.frame, j.t) = (*frame, secs(*t_ns, origin));
                        j.command = Some(nmt_text(command, *all));
                    }
                    BootStep::BootUp { frame, t_ns } => {
                        j.kind = "boot_up";
                        (j.frame, j.t) = (*frame, secs(*t_ns, origin));
                    }
                }
                j
            })
            .collect();
        BootJson {
            boot: self.number,
            findings: self.findings.iter().map(|f| f.to_json(origin)).collect(),
            frame: self.frame,
            node: self.node.node,
            operational: self.operational.map(|o| secs(o.t_ns, origin)),
            operational_by: self.operational.map(|o| o.by),
            reference: self.reference,
            steps,
            t: secs(self.t_ns, origin),
        }
    }

    /// The text block of `diagnose --boots` (times since `origin`).
    pub fn write_text(&self, origin: u64, out: &mut String) {
        let t = |ns: u64| secs(ns, origin);
        let _ = write!(
            out,
            "Node {}, boot {} at {:.3} s",
            self.node.node,
            self.number,
            t(self.t_ns)
        );
        match self.operational {
            Some(op) => {
                let _ = writeln!(out, ", operational at {:.3} s ({})", t(op.t_ns), op.by);
            }
            None => out.push_str(", did not reach operational\n"),
        }
        for s in &self.steps {
            match s {
                BootStep::Write(w) => {
                    let _ = write!(
                        out,
                        "  {:>9.3} s  #{:<7} write {} = {}",
                        t(w.t_ns),
                        w.frame,
                        object_text(w.index, w.sub),
                        w.data.text()
                    );
                    match &w.result {
                        WriteResult::Ok => out.push('\n'),
                        WriteResult::Refused(text) => {
                            let _ = writeln!(out, "  refused: {text}");
                        }
                        WriteResult::Unanswered => out.push_str("  not answered\n"),
                    }
                }
                BootStep::Nmt {
                    frame,
                    t_ns,
                    command,
                    all,
                } => {
                    let _ = writeln!(
                        out,
                        "  {:>9.3} s  #{frame:<7} NMT {}",
                        t(*t_ns),
                        nmt_text(command, *all)
                    );
                }
                BootStep::BootUp { frame, t_ns } => {
                    let _ = writeln!(out, "  {:>9.3} s  #{frame:<7} boot-up", t(*t_ns));
                }
            }
        }
        match (self.reference, self.findings.is_empty()) {
            (None, true) => {}
            (Some(r), true) => {
                let _ = writeln!(out, "  Agrees with boot {r}.");
            }
            (_, false) => {
                for f in &self.findings {
                    let _ = writeln!(out, "  {}: {}", f.kind.as_str(), f.text());
                }
            }
        }
    }
}

/// `reset communication` or `reset communication (all nodes)`.
fn nmt_text(command: &str, all: bool) -> String {
    if all {
        format!("{command} (all nodes)")
    } else {
        command.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(index: u16, data: &[u8], result: WriteResult) -> BootStep {
        BootStep::Write(Write {
            frame: 1,
            t_ns: 0,
            index,
            sub: 0,
            data: Bytes::of(data),
            result,
        })
    }

    fn boot(number: u32, steps: Vec<BootStep>) -> Boot {
        Boot {
            node: NodeKey::new(0, 5),
            number,
            frame: 0,
            t_ns: 0,
            operational: Some(Operational {
                frame: 2,
                t_ns: 1,
                by: "heartbeat",
            }),
            steps,
            reference: None,
            findings: Vec::new(),
        }
    }

    #[test]
    fn each_kind_of_difference_is_one_finding_and_agreeing_boots_none() {
        let ok = WriteResult::Ok;
        let r = boot(
            1,
            vec![
                write(0x1017, &[0xE8, 0x03], ok.clone()),
                write(0x1400, &[1], ok.clone()),
                write(0x1800, &[1], ok.clone()),
                write(0x1801, &[1], ok.clone()),
            ],
        );
        assert!(against_reference(&r, &r).is_empty());
        let b = boot(
            2,
            vec![
                // Same value in 4 bytes: agrees.
                write(0x1017, &[0xE8, 0x03, 0, 0], ok.clone()),
                write(0x1400, &[2], ok.clone()),
                write(0x1800, &[1], WriteResult::Refused("no".into())),
                write(0x1801, &[1], WriteResult::Unanswered),
                write(0x2000, &[7], ok.clone()),
                // A command (store all) is in the story, not compared.
                write(0x1010, &[0x73, 0x61, 0x76, 0x65], ok.clone()),
            ],
        );
        assert_eq!(b.writes().count(), 6);
        let got: Vec<String> = against_reference(&b, &r).iter().map(Finding::text).collect();
        assert_eq!(
            got,
            [
                "0x1400:00 written 0x02, boot 1 wrote 0x01",
                "0x1800:00 write of 0x01 refused: no",
                "0x1801:00 write of 0x01 not answered",
                "0x2000:00 written 0x07, boot 1 did not write it",
            ]
        );
        let short = boot(3, vec![]);
        let got: Vec<String> = against_reference(&short, &r).iter().map(Finding::text).collect();
        assert_eq!(got.len(), 4, "{got:?}");
        assert!(got[0].starts_with("0x1017:00 not written"), "{got:?}");
        let cut = Boot {
            operational: None,
            ..short
        };
        assert!(against_reference(&cut, &r).is_empty());
    }

    #[test]
    fn a_long_value_is_kept_short_and_compared_whole() {
        let mut long = vec![0x41u8; 100];
        let a = Bytes::of(&long);
        long[90] = 0x42;
        let b = Bytes::of(&long);
        assert_eq!(a.head.len(), DATA_KEPT);
        assert!(!a.same(&b) && a.same(&Bytes::of(&[0x41; 100])));
        assert!(a.text().ends_with("41 41 … (100 bytes)"), "{}", a.text());
        // Numbers: one sent in 4 bytes is the same as in 2.
        assert!(Bytes::of(&[0xE8, 0x03]).same(&Bytes::of(&[0xE8, 0x03, 0, 0])));
        assert_eq!(Bytes::of(&[0xE8, 0x03]).text(), "0x03E8");
    }
}
