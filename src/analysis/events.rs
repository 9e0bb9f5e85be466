//! Bus events: what happened to a node or an interface, when. One [`Event`] renders as a
//! text line (`cotui decode --events`), a JSON line (`--format jsonl`, field names are a
//! public API) and a message for the analyzer's message log.

use crate::decode::heartbeat::NmtState;
use crate::frame::json::Seconds;
use serde::{Serialize, Serializer};
use std::fmt::Write;

/// Where the expected heartbeat period came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PeriodSource {
    /// 0x1017 seen on the bus (SDO write or read).
    Sdo,
    /// 0x1017 default of the node's dictionary (EDS/DCF or profile).
    Dictionary,
    /// Measured from the node's recent heartbeat intervals.
    Measured,
}

impl PeriodSource {
    /// Human wording, e.g. `0x1017 by SDO`.
    pub fn text(self) -> &'static str {
        match self {
            PeriodSource::Sdo => "0x1017 by SDO",
            PeriodSource::Dictionary => "0x1017 default",
            PeriodSource::Measured => "measured",
        }
    }
}

/// One event at a time, for a node (or for the bus: `node` None).
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// When it happened (ns, on the frames' time base). A loss is dated at the deadline
    /// that passed, not at the frame or tick that revealed it.
    pub t_ns: u64,
    /// The node, None for interface events.
    pub node: Option<u8>,
    /// The interface of the node (index into the source's interface table; 0 for
    /// interface events, whose [`What::BusState`] names theirs).
    pub iface: u16,
    /// What happened.
    pub what: What,
}

/// The kinds of events with their details; the JSON `event` field is the variant name in
/// snake case, the details are flat fields next to it.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum What {
    /// A boot-up message (0x700 + node, data 00).
    BootUp {
        /// The node had been seen before (heartbeat, guarding or an earlier boot-up).
        rebooted: bool,
        /// Boot-ups seen from the node so far, this one included.
        boot_ups: u64,
        /// The node was lost when it booted.
        was_lost: bool,
    },
    /// The NMT state in the node's heartbeat or guarding response changed.
    State {
        /// The state before (None: first heartbeat of the node).
        #[serde(serialize_with = "opt_state")]
        from: Option<NmtState>,
        /// The state now.
        #[serde(serialize_with = "state")]
        to: NmtState,
    },
    /// No heartbeat for 1.5 expected periods, or a guarding request left unanswered.
    HeartbeatLost {
        /// The expected period (ms).
        period_ms: f64,
        /// Where the period came from.
        period_source: PeriodSource,
        /// Time since the last heartbeat or guarding response (ms).
        silent_ms: f64,
        /// Found by node guarding (a request not answered) rather than by heartbeat timing.
        guarding: bool,
        /// Deadlines missed and guarding requests unanswered so far.
        missed: u64,
    },
    /// A heartbeat (or guarding response) from a lost node.
    HeartbeatBack {
        /// Time since the heartbeat before (ms).
        silent_ms: f64,
    },
    /// The node's heartbeat producer time 0x1017 seen on the bus changed.
    HeartbeatPeriod {
        /// The new period (ms, 0: heartbeat off).
        period_ms: u16,
    },
    /// An emergency message.
    Emcy {
        /// Error code.
        code: u16,
        /// Text of the code.
        text: String,
        /// Error register 0x1001.
        register: u8,
    },
    /// An SDO transfer aborted.
    SdoAbort {
        /// `upload` or `download`.
        direction: &'static str,
        /// Object index.
        index: u16,
        /// Object sub-index.
        sub: u8,
        /// Abort code.
        code: u32,
        /// Text of the abort code.
        text: &'static str,
        /// `client` or `server`.
        by: &'static str,
    },
    /// The CAN controller's state changed, from a SocketCAN error frame.
    BusState {
        /// Interface name.
        iface: String,
        /// The state before.
        from: &'static str,
        /// The state now: `error_active`, `error_warning`, `error_passive` or `bus_off`.
        to: &'static str,
        /// The error frame's classes and details.
        detail: String,
    },
}

fn state<S: Serializer>(s: &NmtState, ser: S) -> Result<S::Ok, S::Error> {
    ser.serialize_str(s.as_str())
}

fn opt_state<S: Serializer>(s: &Option<NmtState>, ser: S) -> Result<S::Ok, S::Error> {
    match s {
        Some(s) => ser.serialize_str(s.as_str()),
        None => ser.serialize_none(),
    }
}

/// Milliseconds as `450.0 ms` below a second, else `2.350 s`.
fn span(ms: f64) -> String {
    if ms >= 1000.0 {
        format!("{:.3} s", ms / 1000.0)
    } else {
        format!("{ms:.1} ms")
    }
}

/// Human name of a controller state.
fn bus_state_text(s: &str) -> &str {
    match s {
        "error_active" => "error active",
        "error_warning" => "error warning",
        "error_passive" => "error passive",
        "bus_off" => "bus off",
        other => other,
    }
}

impl What {
    /// The JSON `event` name, e.g. `heartbeat_lost`.
    pub fn name(&self) -> &'static str {
        match self {
            What::BootUp { .. } => "boot_up",
            What::State { .. } => "state",
            What::HeartbeatLost { .. } => "heartbeat_lost",
            What::HeartbeatBack { .. } => "heartbeat_back",
            What::HeartbeatPeriod { .. } => "heartbeat_period",
            What::Emcy { .. } => "emcy",
            What::SdoAbort { .. } => "sdo_abort",
            What::BusState { .. } => "bus_state",
        }
    }

    /// A short human title, e.g. `heartbeat lost` or `rebooted`.
    pub fn title(&self) -> &'static str {
        match self {
            What::BootUp { rebooted: true, .. } => "rebooted",
            What::BootUp { .. } => "boot-up",
            What::State { .. } => "NMT state",
            What::HeartbeatLost { .. } => "heartbeat lost",
            What::HeartbeatBack { .. } => "heartbeat back",
            What::HeartbeatPeriod { .. } => "heartbeat period",
            What::Emcy { .. } => "EMCY",
            What::SdoAbort { .. } => "SDO abort",
            What::BusState { .. } => "bus state",
        }
    }

    /// The details in words.
    pub fn detail(&self) -> String {
        match self {
            What::BootUp {
                rebooted,
                boot_ups,
                was_lost,
            } => {
                let mut s = if *rebooted {
                    format!("boot-up #{boot_ups}, node seen before")
                } else {
                    "boot-up, first message of the node".to_string()
                };
                if *was_lost {
                    s.push_str("; it was lost");
                }
                s
            }
            What::State { from: None, to } => format!("{} (first heartbeat)", to.text()),
            What::State { from: Some(f), to } => format!("{} -> {}", f.text(), to.text()),
            What::HeartbeatLost {
                period_ms,
                period_source,
                silent_ms,
                guarding: true,
                missed,
            } => format!(
                "guarding request not answered, silent {} (guarded every {}, {}; {missed} missed)",
                span(*silent_ms),
                span(*period_ms),
                period_source.text()
            ),
            What::HeartbeatLost {
                period_ms,
                period_source,
                silent_ms,
                missed,
                ..
            } => format!(
                "no heartbeat for {}, expected every {} ({}; {missed} missed)",
                span(*silent_ms),
                span(*period_ms),
                period_source.text()
            ),
            What::HeartbeatBack { silent_ms } => format!("heartbeat again after {} silent", span(*silent_ms)),
            What::HeartbeatPeriod { period_ms: 0 } => "0x1017 = 0: heartbeat off".to_string(),
            What::HeartbeatPeriod { period_ms } => format!("0x1017 = {period_ms} ms"),
            What::Emcy { code, text, register } => format!("0x{code:04X} {text}; register 0x{register:02X}"),
            What::SdoAbort {
                direction,
                index,
                sub,
                code,
                text,
                by,
            } => format!("{direction} 0x{index:04X}:{sub:02X}: 0x{code:08X} {text} (by {by})"),
            What::BusState {
                iface,
                from,
                to,
                detail,
            } => format!("{iface}: {} -> {} ({detail})", bus_state_text(from), bus_state_text(to)),
        }
    }
}

impl Event {
    /// The node as a node of its interface (None for interface events).
    pub fn key(&self) -> Option<crate::frame::NodeKey> {
        self.node.map(|n| crate::frame::NodeKey::new(self.iface, n))
    }

    /// One line for a message log, e.g. `node 5 heartbeat lost: no heartbeat for 450.0 ms, ...`.
    pub fn text(&self) -> String {
        self.text_on(None)
    }

    /// [`Event::text`] with the node's interface named after it (`node 5 (can1) ...`) when
    /// `iface` is given (several interfaces in the capture).
    pub fn text_on(&self, iface: Option<&str>) -> String {
        let who = match (self.node, iface) {
            (Some(n), Some(i)) => format!("node {n} ({i})"),
            (Some(n), None) => format!("node {n}"),
            (None, _) => "bus".to_string(),
        };
        format!("{who} {}: {}", self.what.title(), self.what.detail())
    }

    /// Appends the `cotui decode --events` text line (with `\n`):
    /// `(1700000000.450000)  node   5  heartbeat_lost    no heartbeat for ...`.
    pub fn write_line(&self, out: &mut String) {
        self.write_line_on(out, None);
    }

    /// [`Event::write_line`] with the node's interface after the node-ID
    /// (`node   5 (can1)  heartbeat_lost ...`) when `iface` is given.
    pub fn write_line_on(&self, out: &mut String, iface: Option<&str>) {
        let _ = write!(
            out,
            "({}.{:06})  ",
            self.t_ns / 1_000_000_000,
            self.t_ns % 1_000_000_000 / 1000
        );
        match (self.node, iface) {
            (Some(n), Some(i)) => {
                let _ = write!(out, "node {n:>3} ({i})");
            }
            (Some(n), None) => {
                let _ = write!(out, "node {n:>3}");
            }
            (None, _) => out.push_str("bus     "),
        }
        let _ = writeln!(out, "  {:<16}  {}", self.what.name(), self.what.detail());
    }

    /// Appends the JSON line (with `\n`) of [`Event::to_json`].
    pub fn write_json(&self, out: &mut Vec<u8>) {
        self.write_json_on(out, None);
    }

    /// [`Event::write_json`] with an `iface` field after `node` when `iface` is given.
    pub fn write_json_on(&self, out: &mut Vec<u8>, iface: Option<&str>) {
        let mut j = self.to_json();
        j.iface = iface.filter(|_| self.node.is_some());
        crate::frame::json::write_line(out, &j);
    }

    /// The JSONL record: `t` (seconds, exact to the ns like the frame JSONL), `node` (null
    /// for the bus), `iface` (only when the capture has several interfaces), `event`, then
    /// the details of [`What`].
    pub fn to_json(&self) -> EventJson<'_> {
        EventJson {
            t: Seconds(self.t_ns),
            node: self.node,
            iface: None,
            what: &self.what,
        }
    }
}

/// One event as a JSONL record (`cotui decode --events --format jsonl`).
#[derive(Clone, Debug, Serialize)]
pub struct EventJson<'a> {
    pub t: Seconds,
    pub node: Option<u8>,
    /// The node's interface, present only when the capture has several interfaces.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iface: Option<&'a str>,
    /// `event` (the variant name) and its details, flat.
    #[serde(flatten)]
    pub what: &'a What,
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn lost() -> Event {
        Event {
            t_ns: 1_700_000_000_450_000_000,
            node: Some(5),
            iface: 0,
            what: What::HeartbeatLost {
                period_ms: 300.0,
                period_source: PeriodSource::Sdo,
                silent_ms: 450.0,
                guarding: false,
                missed: 1,
            },
        }
    }

    #[test]
    fn json_line_has_the_contract_fields() {
        let mut s = Vec::new();
        lost().write_json(&mut s);
        let s = String::from_utf8(s).unwrap();
        assert!(s.starts_with("{\"t\":1700000000.450000000,\"node\":5,\"event\":\"heartbeat_lost\""));
        let mut j: serde_json::Value = serde_json::from_str(&s).unwrap();
        // `t` is checked exactly in the text above (a parsed f64 rounds it).
        j.as_object_mut().unwrap().remove("t");
        assert_eq!(
            j,
            json!({"node": 5, "event": "heartbeat_lost", "period_ms": 300.0,
                   "period_source": "sdo", "silent_ms": 450.0, "guarding": false, "missed": 1})
        );
        let state = Event {
            t_ns: 1,
            node: Some(2),
            iface: 0,
            what: What::State {
                from: None,
                to: NmtState::PreOperational,
            },
        };
        let mut s = Vec::new();
        state.write_json(&mut s);
        let j: serde_json::Value = serde_json::from_slice(&s).unwrap();
        assert_eq!(j["from"], json!(null));
        assert_eq!(j["to"], "pre_operational");
        assert_eq!(j["t"], 1e-9);
    }

    #[test]
    fn text_line_and_message() {
        let mut s = String::new();
        lost().write_line(&mut s);
        assert_eq!(
            s,
            "(1700000000.450000)  node   5  heartbeat_lost    no heartbeat for 450.0 ms, expected every 300.0 ms (0x1017 by SDO; 1 missed)\n"
        );
        assert_eq!(
            lost().text(),
            "node 5 heartbeat lost: no heartbeat for 450.0 ms, expected every 300.0 ms (0x1017 by SDO; 1 missed)"
        );
        let bus = Event {
            t_ns: 0,
            node: None,
            iface: 0,
            what: What::BusState {
                iface: "can0".into(),
                from: "error_active",
                to: "bus_off",
                detail: "bus off".into(),
            },
        };
        let mut s = String::new();
        bus.write_line(&mut s);
        assert_eq!(
            s,
            "(0.000000)  bus       bus_state         can0: error active -> bus off (bus off)\n"
        );
    }
}
