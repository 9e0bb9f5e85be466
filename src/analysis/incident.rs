//! Incidents: what went wrong on the bus, in plain words, with the frames that tell it.
//! Built by [`super::diagnose::Diagnoser`]; rendered as text (`cotui diagnose`) and as one
//! JSON object per incident (`--format jsonl`, field names are a public API).

use super::boot_story::{Finding, FindingJson};
use serde::Serialize;
use std::fmt::Write;

/// Timeline entries kept per incident; further ones are counted in `count`, not listed.
pub const TIMELINE_KEPT: usize = 12;

/// Whether an incident still needs attention at the end of the capture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    /// Still wrong at the end of the capture.
    Open,
    /// Went wrong, then came right again.
    Recovered,
    /// Worth knowing, did not stop anything that the bus shows.
    Warning,
    /// Only for information: nothing went wrong (e.g. entries the node does not have, read
    /// by the capturing host itself).
    Info,
}

impl Status {
    /// JSON name: `open`, `recovered`, `warning`.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Open => "open",
            Status::Recovered => "recovered",
            Status::Warning => "warning",
            Status::Info => "info",
        }
    }
}

/// The kind of problem (the JSON `kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Problem {
    /// SDO requests unanswered and nothing at all heard from the node.
    Missing,
    /// No heartbeat any more until the end of the capture.
    Silent,
    /// Heartbeat stopped for a while and came back.
    SilentBack,
    /// A boot-up nobody asked for (no NMT reset before it).
    Rebooted,
    /// An SDO transfer refused (abort), per object.
    SdoRefused,
    /// SDO frames from the node that follow no transfer, or break the protocol.
    SdoGarbled,
    /// Heartbeat off (0x1017 = 0) and no node guarding: a lost node goes unnoticed.
    Unmonitored,
    /// SDO requests with no answer from a node that is otherwise alive.
    SdoTimeout,
    /// CiA 402 drive fault (statusword bit 3).
    DriveFault,
    /// An emergency message not tied to a drive fault.
    Emcy,
    /// CAN error frames: errors, error passive, bus off.
    BusErrors,
    /// Two devices answer with one node-ID.
    DuplicateId,
    /// An NMT command the node did not follow.
    NmtIgnored,
    /// A CiA 402 drive that did not reach the state its controlword asked for.
    DriveStuck,
    /// A PDO that stopped arriving within its event time or measured period.
    PdoMissing,
    /// SYNC intervals off the SYNC period.
    SyncJitter,
    /// Requests or commands from two masters at once.
    SecondMaster,
    /// A synchronous TPDO sent after the SYNC window (0x1007) closed.
    PdoLate,
    /// A boot whose configuration writes differ from the node's first complete boot or
    /// from the expected configuration (`--expect NODE=FILE.dcf`).
    BootConfig,
    /// Entries a node does not have, asked for by reads the capturing host sent (cotui's
    /// own, or TX-marked in a log): one info row per node, not an incident per entry.
    NotPresent,
}

impl Problem {
    /// Every kind, in declaration order (the one list; a test holds it to the enum).
    pub const ALL: [Problem; 20] = [
        Problem::Missing,
        Problem::Silent,
        Problem::SilentBack,
        Problem::Rebooted,
        Problem::SdoRefused,
        Problem::SdoGarbled,
        Problem::Unmonitored,
        Problem::SdoTimeout,
        Problem::DriveFault,
        Problem::Emcy,
        Problem::BusErrors,
        Problem::DuplicateId,
        Problem::NmtIgnored,
        Problem::DriveStuck,
        Problem::PdoMissing,
        Problem::SyncJitter,
        Problem::SecondMaster,
        Problem::PdoLate,
        Problem::BootConfig,
        Problem::NotPresent,
    ];

    /// JSON name, e.g. `sdo_refused`.
    pub fn as_str(self) -> &'static str {
        match self {
            Problem::Missing => "missing",
            Problem::Silent => "silent",
            Problem::SilentBack => "silent_back",
            Problem::Rebooted => "rebooted",
            Problem::SdoRefused => "sdo_refused",
            Problem::SdoTimeout => "sdo_timeout",
            Problem::SdoGarbled => "sdo_garbled",
            Problem::Unmonitored => "unmonitored",
            Problem::DriveFault => "drive_fault",
            Problem::Emcy => "emcy",
            Problem::BusErrors => "bus_errors",
            Problem::DuplicateId => "duplicate_id",
            Problem::NmtIgnored => "nmt_ignored",
            Problem::DriveStuck => "drive_stuck",
            Problem::PdoMissing => "pdo_missing",
            Problem::SyncJitter => "sync_jitter",
            Problem::SecondMaster => "second_master",
            Problem::PdoLate => "pdo_late",
            Problem::BootConfig => "boot_config",
            Problem::NotPresent => "not_present",
        }
    }
}

/// One line of an incident's timeline: the frame that tells it.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Frame number, 1-based over all inputs.
    pub frame: u64,
    /// Frame time (ns, the capture's time base).
    pub t_ns: u64,
    /// What the frame shows, in words.
    pub text: String,
}

/// One problem on one node (or on the bus), repeats grouped.
#[derive(Clone, Debug, PartialEq)]
pub struct Incident {
    /// The node, None for the bus itself.
    pub node: Option<u8>,
    /// The node's interface (index into the source's interface table).
    pub iface: u16,
    /// The node's interface by name, given only when the capture has nodes on several
    /// interfaces (then the node is shown as `Node 5 (can1)` and JSON has an `iface` field).
    pub iface_name: Option<String>,
    /// Axes of a multi-axis drive (1-based), empty when not axis-specific.
    pub axes: Vec<u8>,
    /// The kind of problem.
    pub problem: Problem,
    /// Open, recovered or warning.
    pub status: Status,
    /// One line in plain words.
    pub title: String,
    /// The cause as the bus shows it (EMCY text, abort text, error code), when it does.
    pub cause: Option<String>,
    /// The frames that tell the story (the first [`TIMELINE_KEPT`]).
    pub events: Vec<Step>,
    /// What to check first, most likely first.
    pub check: Vec<String>,
    /// Why it matters.
    pub why: String,
    /// How many times it happened.
    pub count: u64,
    /// First occurrence (ns).
    pub first_ns: u64,
    /// Last occurrence (ns).
    pub last_ns: u64,
    /// What differs, object by object (a `boot_config` incident only).
    pub findings: Vec<Finding>,
}

/// Seconds since `origin` with µs precision, for JSON.
fn secs(t_ns: u64, origin: u64) -> f64 {
    (t_ns.saturating_sub(origin) / 1000) as f64 / 1e6
}

impl Incident {
    /// Adds a timeline step (kept up to [`TIMELINE_KEPT`]).
    pub fn step(&mut self, frame: u64, t_ns: u64, text: impl Into<String>) {
        if self.events.len() < TIMELINE_KEPT {
            self.events.push(Step {
                frame,
                t_ns,
                text: text.into(),
            });
        }
    }

    /// The node as a node of its interface (None for the bus).
    pub fn key(&self) -> Option<crate::frame::NodeKey> {
        self.node.map(|n| crate::frame::NodeKey::new(self.iface, n))
    }

    /// `Node 5 · axis 2`, `Node 4`, `Node 5 (can1)` (several interfaces) or `CAN bus`.
    pub fn place(&self) -> String {
        let mut s = match (self.node, &self.iface_name) {
            (Some(n), Some(i)) => format!("Node {n} ({i})"),
            (Some(n), None) => format!("Node {n}"),
            (None, _) => "CAN bus".to_string(),
        };
        match self.axes.as_slice() {
            [] | [1] => {}
            [a] => {
                let _ = write!(s, " · axis {a}");
            }
            many => {
                let list: Vec<String> = many.iter().map(u8::to_string).collect();
                let _ = write!(s, " · axes {}", list.join("+"));
            }
        }
        s
    }

    /// The JSON object of `cotui diagnose --format jsonl`; times are seconds since
    /// `origin` (the capture's first frame).
    pub fn to_json(&self, origin: u64) -> IncidentJson<'_> {
        IncidentJson {
            axes: &self.axes,
            cause: self.cause.as_deref(),
            check: &self.check,
            count: self.count,
            events: self
                .events
                .iter()
                .map(|e| StepJson {
                    frame: e.frame,
                    t: secs(e.t_ns, origin),
                    text: &e.text,
                })
                .collect(),
            findings: self.findings.iter().map(|f| f.to_json(origin)).collect(),
            first: secs(self.first_ns, origin),
            iface: self.iface_name.as_deref().filter(|_| self.node.is_some()),
            kind: self.problem.as_str(),
            last: secs(self.last_ns, origin),
            node: self.node,
            status: self.status.as_str(),
            title: &self.title,
            why: &self.why,
        }
    }

    /// The text block of `cotui diagnose` (numbered `n`), times since `origin`.
    pub fn write_text(&self, n: usize, origin: u64, out: &mut String) {
        let status = match self.status {
            Status::Open => "OPEN",
            Status::Recovered => "RECOVERED",
            Status::Warning => "WARNING",
            Status::Info => "INFO",
        };
        let _ = writeln!(out, "{n:>2}. {status:<9}  {}: {}", self.place(), self.title);
        if let Some(c) = &self.cause {
            let _ = writeln!(out, "    Cause: {c}");
        }
        if self.count > 1 {
            let _ = writeln!(
                out,
                "    {} times, first {:.3} s, last {:.3} s",
                self.count,
                secs(self.first_ns, origin),
                secs(self.last_ns, origin)
            );
        }
        out.push_str("    What happened:\n");
        for e in &self.events {
            let _ = writeln!(out, "      {:>9.3} s  #{:<7} {}", secs(e.t_ns, origin), e.frame, e.text);
        }
        out.push_str("    Check first:\n");
        for (i, c) in self.check.iter().enumerate() {
            let _ = writeln!(out, "      {}. {c}", i + 1);
        }
        let _ = writeln!(out, "    Why it matters: {}", self.why);
    }
}

/// One incident as a JSONL record (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct IncidentJson<'a> {
    /// The drive axes it concerns (empty when none).
    pub axes: &'a [u8],
    pub cause: Option<&'a str>,
    /// What to check, in order.
    pub check: &'a [String],
    /// How many times it happened.
    pub count: u64,
    /// The timeline (the first steps).
    pub events: Vec<StepJson<'a>>,
    /// What differs, object by object (`boot_config` only; absent otherwise).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub findings: Vec<FindingJson<'a>>,
    /// Seconds since the capture's first frame.
    pub first: f64,
    /// The node's interface, only when the capture has several interfaces.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iface: Option<&'a str>,
    /// The [`Problem`] name.
    pub kind: &'static str,
    pub last: f64,
    /// `null` for the whole bus.
    pub node: Option<u8>,
    pub status: &'static str,
    pub title: &'a str,
    pub why: &'a str,
}

/// One timeline step of [`IncidentJson`] (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct StepJson<'a> {
    /// Frame number, 1-based over all inputs.
    pub frame: u64,
    /// Seconds since the capture's first frame.
    pub t: f64,
    pub text: &'a str,
}

#[cfg(test)]
mod tests {
    use super::Problem;

    #[test]
    fn all_lists_every_kind_once_in_declaration_order() {
        for (i, p) in Problem::ALL.iter().enumerate() {
            assert_eq!(*p as usize, i, "{p:?}");
        }
        // A kind declared after the last listed one is not in ALL: its JSON name is the
        // exhaustive match, so this names the kind that must come last.
        assert_eq!(Problem::ALL.last().map(|p| p.as_str()), Some("not_present"));
    }
}
