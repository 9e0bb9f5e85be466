//! Stop-all: the emergency stop of the TUI (`ctrl-s`) and of `cotui stop IFACE`.
//!
//! Which drives to stop comes from two places: the nodes cotui itself commanded on the bus
//! ([`Commanded`], learned from the frames it sent, whatever path sent them), and the nodes
//! seen in a powered CiA 402 state. Each target is stopped by [`super::drive::stop`]
//! (quick stop, wait for the ramp, disable voltage, statusword read back), all targets at
//! once, and the report says per node whether the stop was confirmed.

use super::drive::{NodeStop, STOP_CONTROLWORDS, controlword_frame, stop as stop_drive};
use super::error::{CommandError, ParseError};
use super::grammar::DEFAULT_TIMEOUT_MS;
use super::report::Reported;
use super::sdo::upload;
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::{ms_arg, node_arg};
use crate::bus::{Bus, BusError};
use crate::decode::cia402::DriveState;
use crate::frame::{Direction, Frame};
use crate::sdo::codec::{SdoCommand, Side, decode};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};
use std::time::Duration;
use tokio::task::JoinSet;

/// How a stop runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StopOptions {
    /// ms to wait for each SDO answer.
    pub timeout_ms: u64,
    /// ms a drive may take to finish its quick stop ramp before voltage is disabled.
    pub ramp_ms: u64,
}

impl Default for StopOptions {
    fn default() -> Self {
        StopOptions {
            timeout_ms: DEFAULT_TIMEOUT_MS,
            ramp_ms: DEFAULT_RAMP_MS,
        }
    }
}

/// Default time a drive may take to come to a standstill after a quick stop.
pub const DEFAULT_RAMP_MS: u64 = 1500;
/// Default time `cotui stop` listens for nodes before reading their statuswords.
pub const DEFAULT_LISTEN_MS: u64 = 1200;

/// `stop [NODE ...] [--node N]... [--listen MS] [--ramp MS] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct StopArgs {
    /// Stop these nodes. Without any, every CiA 402 drive found powered is stopped.
    #[arg(value_parser = node_arg)]
    pub nodes: Vec<u8>,
    /// Stop this node too (repeatable; the same as naming it).
    #[arg(long = "node", value_name = "N", value_parser = node_arg)]
    pub node_flags: Vec<u8>,
    /// How long to listen for nodes before reading their statuswords (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_LISTEN_MS)]
    pub listen: u64,
    /// How long a drive may take to finish its quick stop ramp before voltage is disabled (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_RAMP_MS)]
    pub ramp: u64,
    /// How long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

/// Quick stop and disable voltage on these nodes, or (none given) on every CiA 402 drive
/// found powered.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Stop {
    pub nodes: Vec<u8>,
    pub listen_ms: u64,
    pub options: StopOptions,
}

impl<D> CommandArgs<D> for StopArgs {
    type Spec = Stop;
    const NAME: &'static str = "stop";

    fn spec(&self) -> Result<Stop, ParseError> {
        let mut nodes = self.nodes.clone();
        nodes.extend(self.node_flags.iter().filter(|n| !self.nodes.contains(n)));
        Ok(Stop {
            nodes,
            listen_ms: self.listen,
            options: StopOptions {
                timeout_ms: self.timeout,
                ramp_ms: self.ramp,
            },
        })
    }
}

impl Spec for Stop {
    /// The controlwords of each node named (the drives found powered are known only then).
    fn preview(&self, _known: &Known<'_>) -> Result<Preview, CommandError> {
        let words = |cws: &[u16]| {
            cws.iter()
                .map(|c| format!("0x{c:04X}"))
                .collect::<Vec<_>>()
                .join(" then ")
        };
        let frames: Vec<String> = self
            .nodes
            .iter()
            .flat_map(|n| STOP_CONTROLWORDS.map(|cw| super::spec::candump(&controlword_frame(*n, cw))))
            .collect();
        Ok(Preview::sends(if self.nodes.is_empty() {
            format!(
                "cancels running commands, then controlwords {} (quick stop, disable voltage) to every \
                 drive cotui commanded or sees powered",
                words(&STOP_CONTROLWORDS)
            )
        } else {
            format!(
                "cancels running commands, then {} (quick stop, then disable voltage, per node), also to \
                 every drive cotui commanded or sees powered",
                frames.join(", ")
            )
        }))
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        stop(ctx.bus, &self.nodes, self.listen_ms, self.options)
            .await?
            .into_result()
    }
}

/// The nodes cotui commanded on the bus, learned from the frames it sent (marked TX): SDO
/// writes to application objects (0x2000 and up: vendor and CiA 402 objects), vendor SDO
/// commands, and RPDOs of the predefined connection set. Pure: fed frame by frame.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Commanded {
    nodes: BTreeSet<u8>,
}

impl Commanded {
    /// Notes the node `f` commands, when `f` is a frame cotui sent that may set a drive moving.
    pub fn observe(&mut self, f: &Frame) {
        if let Some(n) = commanded_node(f) {
            self.nodes.insert(n);
        }
    }
    /// The nodes commanded, in order.
    pub fn nodes(&self) -> impl Iterator<Item = u8> + '_ {
        self.nodes.iter().copied()
    }
    /// True when `node` was commanded and not confirmed stopped since.
    pub fn contains(&self, node: u8) -> bool {
        self.nodes.contains(&node)
    }
    /// Forgets `node` (its stop was confirmed).
    pub fn forget(&mut self, node: u8) {
        self.nodes.remove(&node);
    }
}

/// The node a frame we sent commands, if it is one that may set a drive moving.
fn commanded_node(f: &Frame) -> Option<u8> {
    if f.direction() != Direction::Tx || f.is_ext() || f.is_rtr() || f.is_err() {
        return None;
    }
    let (base, node) = (f.id & 0x780, (f.id & 0x7F) as u8);
    if node == 0 {
        return None;
    }
    let p = f.payload();
    match base {
        // RPDO1..4 of the predefined connection set.
        0x200 | 0x300 | 0x400 | 0x500 => Some(node),
        0x600 if p.len() >= 3 => match decode(Side::Client, p, false) {
            // Download initiate (expedited or segmented) and block download initiate.
            SdoCommand::InitiateDownload { index, .. } | SdoCommand::BlockDownloadInitiate { index, .. }
                if index >= 0x2000 =>
            {
                Some(node)
            }
            // Not an SDO client command specifier: a vendor command (e.g. 0xE8 moves).
            SdoCommand::Unknown { .. } => Some(node),
            _ => None,
        },
        _ => None,
    }
}

/// True for the CiA 402 states in which the power stage is (or may be) on.
pub fn is_powered(s: DriveState) -> bool {
    matches!(
        s,
        DriveState::SwitchedOn | DriveState::OperationEnabled | DriveState::QuickStopActive
    )
}

/// What a stop did: one entry per node targeted, plus the nodes found not powered.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct StopReport {
    /// Per targeted node, in node order.
    pub nodes: Vec<NodeStop>,
    /// CiA 402 nodes found in a state without power, left alone: (node, state).
    pub idle: Vec<(u8, DriveState)>,
    /// What was running and was cancelled first (TUI commands).
    pub cancelled: Vec<String>,
}

impl StopReport {
    /// True when every targeted node is confirmed stopped.
    pub fn all_stopped(&self) -> bool {
        self.nodes.iter().all(|n| n.stopped)
    }
    /// The text: a summary line, then one line per node.
    pub fn text(&self) -> String {
        let failed = self.nodes.iter().filter(|n| !n.stopped).count();
        let mut lines = vec![match (self.nodes.len(), failed) {
            (0, _) => "no drive to stop (none commanded by cotui or seen powered)".to_string(),
            (n, 0) => format!("{n} drive(s) stopped and confirmed"),
            (n, f) => format!("{f} of {n} drive(s) NOT confirmed stopped"),
        }];
        if !self.cancelled.is_empty() {
            lines.push(format!("cancelled: {}", self.cancelled.join("; ")));
        }
        lines.extend(self.nodes.iter().map(NodeStop::text));
        lines.extend(
            self.idle
                .iter()
                .map(|(n, s)| format!("node {n}: {} (not powered, nothing sent)", s.text())),
        );
        lines.join("\n")
    }
    /// The report as a command result: `Ok` when all targets are confirmed stopped, else
    /// [`CommandError::NotStopped`] (exit status 5) carrying the same report.
    pub fn into_result(self) -> Result<Outcome, CommandError> {
        let text = self.text();
        if self.all_stopped() {
            Ok(Outcome::new(self, text))
        } else {
            Err(CommandError::NotStopped {
                report: Reported::new(self),
                text,
            })
        }
    }
}

/// `stop --json`.
impl Serialize for StopReport {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        StopJson {
            ok: self.all_stopped(),
            nodes: &self.nodes,
            idle: self
                .idle
                .iter()
                .map(|(n, s)| IdleJson {
                    node: *n,
                    state: s.as_str(),
                })
                .collect(),
            cancelled: &self.cancelled,
        }
        .serialize(s)
    }
}

/// `stop --json`, as written.
#[derive(Serialize)]
struct StopJson<'a> {
    ok: bool,
    nodes: &'a [NodeStop],
    idle: Vec<IdleJson>,
    cancelled: &'a [String],
}

/// A CiA 402 node a stop left alone (not powered).
#[derive(Serialize)]
struct IdleJson {
    node: u8,
    state: &'static str,
}

/// `stop --json` on a listen-only handle.
#[derive(Serialize)]
struct ListenOnlyJson {
    ok: bool,
    listen_only: bool,
    nodes: [u8; 0],
    message: String,
}

/// Stops `nodes`, all at once; the report lists them in node order.
pub async fn stop_nodes(bus: &Bus, nodes: &BTreeSet<u8>, opts: StopOptions) -> Result<StopReport, CommandError> {
    if bus.is_listen_only() {
        return Err(listen_only(nodes));
    }
    let mut set = JoinSet::new();
    for &n in nodes {
        // A stop never waits behind another client's SDO transfer to the node.
        let bus = bus.ahead_of_turns();
        set.spawn(async move { stop_drive(&bus, n, opts.timeout_ms, opts.ramp_ms).await });
    }
    let mut done = BTreeMap::new();
    while let Some(r) = set.join_next().await {
        let s = r.map_err(|e| CommandError::Usage(format!("a stop task failed: {e}")))?;
        done.insert(s.node, s);
    }
    Ok(StopReport {
        nodes: done.into_values().collect(),
        ..StopReport::default()
    })
}

/// The failure of a stop on a listen-only handle: nothing can be sent.
fn listen_only(nodes: &BTreeSet<u8>) -> CommandError {
    let text = format!(
        "listen-only — NOTHING was sent, no drive was stopped{}; stop them another way \
         (their own stop input, or cotui without --listen-only)",
        if nodes.is_empty() {
            String::new()
        } else {
            format!(" (nodes {})", join(nodes.iter()))
        }
    );
    CommandError::NotStopped {
        report: Reported::new(ListenOnlyJson {
            ok: false,
            listen_only: true,
            nodes: [],
            message: text.clone(),
        }),
        text,
    }
}

fn join<'a>(it: impl Iterator<Item = &'a u8>) -> String {
    it.map(u8::to_string).collect::<Vec<_>>().join(", ")
}

/// `cotui stop IFACE [--node N]...`: with `nodes`, stops exactly those; without, listens
/// `listen_ms` for the nodes on the bus, reads 0x1000 and the statusword of each (all at
/// once), and stops every CiA 402 node in a powered state.
pub async fn stop(bus: &Bus, nodes: &[u8], listen_ms: u64, opts: StopOptions) -> Result<StopReport, CommandError> {
    if bus.is_listen_only() {
        return Err(listen_only(&nodes.iter().copied().collect()));
    }
    if !nodes.is_empty() {
        return stop_nodes(bus, &nodes.iter().copied().collect(), opts).await;
    }
    let heard = listen(bus, listen_ms).await?;
    let mut set = JoinSet::new();
    for n in heard {
        let bus = bus.clone();
        set.spawn(async move { (n, powered_state(&bus, n, opts.timeout_ms).await) });
    }
    let (mut targets, mut idle) = (BTreeSet::new(), Vec::new());
    while let Some(r) = set.join_next().await {
        match r {
            Ok((n, Some(s))) if !is_powered(s) => idle.push((n, s)),
            Ok((n, Some(_))) => {
                targets.insert(n);
            }
            // Not a CiA 402 drive, or silent: nothing to stop.
            Ok((_, None)) => {}
            Err(e) => return Err(CommandError::Usage(format!("a probe task failed: {e}"))),
        }
    }
    idle.sort_unstable_by_key(|(n, _)| *n);
    let mut report = stop_nodes(bus, &targets, opts).await?;
    report.idle = idle;
    Ok(report)
}

/// The nodes heard within `ms`: heartbeats, boot-ups, EMCYs, TPDOs and SDO answers.
async fn listen(bus: &Bus, ms: u64) -> Result<BTreeSet<u8>, CommandError> {
    let mut rx = bus.subscribe();
    let mut heard = BTreeSet::new();
    let deadline = tokio::time::Instant::now() + Duration::from_millis(ms);
    loop {
        match tokio::time::timeout_at(deadline, rx.recv()).await {
            Err(_) => return Ok(heard),
            Ok(Err(BusError::Closed)) => return Err(BusError::Closed.into()),
            Ok(Err(_)) => {}
            Ok(Ok(f)) => {
                if f.direction() == Direction::Rx
                    && !f.is_ext()
                    && !f.is_err()
                    && matches!(f.id & 0x780, 0x080 | 0x180 | 0x280 | 0x380 | 0x480 | 0x580 | 0x700)
                    && f.id & 0x7F != 0
                {
                    heard.insert((f.id & 0x7F) as u8);
                }
            }
        }
    }
}

/// The CiA 402 state of `node` (0x1000 says profile 402, then 0x6041), `None` when it is
/// not a drive or does not answer.
async fn powered_state(bus: &Bus, node: u8, timeout_ms: u64) -> Option<DriveState> {
    let dt = upload(bus, node, 0x1000, 0, false, timeout_ms).await.ok()?;
    if u16::from_le_bytes([*dt.first()?, *dt.get(1)?]) != 402 {
        return None;
    }
    let sw = upload(bus, node, 0x6041, 0, false, timeout_ms).await.ok()?;
    Some(DriveState::from_statusword(u16::from_le_bytes([
        *sw.first()?,
        *sw.get(1)?,
    ])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Flags;

    fn tx(id: u32, data: &[u8]) -> Frame {
        let mut f = Frame::classic(id, data);
        f.flags.set(Flags::TX, true);
        f
    }

    #[test]
    fn commanded_nodes_come_from_what_we_sent() {
        let mut c = Commanded::default();
        // Reads, communication objects and frames of other programs command nothing.
        c.observe(&tx(0x602, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]));
        c.observe(&tx(0x602, &[0x2B, 0x17, 0x10, 0, 0xE8, 3, 0, 0]));
        c.observe(&Frame::classic(0x603, &[0x2B, 0x40, 0x60, 0, 0x0F, 0, 0, 0]));
        c.observe(&tx(0x000, &[0x01, 0x00]));
        assert_eq!(c.nodes().count(), 0);
        // Controlword write, segmented vendor write, block download, vendor command, RPDO.
        c.observe(&tx(0x602, &[0x2B, 0x40, 0x60, 0, 0x0F, 0, 0, 0]));
        c.observe(&tx(0x604, &[0x21, 0x00, 0x20, 1, 9, 0, 0, 0]));
        c.observe(&tx(0x605, &[0xC6, 0x00, 0x30, 0, 20, 0, 0, 0]));
        c.observe(&tx(0x607, &[0xE8, 1, 2, 3, 4, 5, 6, 7]));
        c.observe(&tx(0x209, &[0x0F, 0]));
        assert_eq!(c.nodes().collect::<Vec<_>>(), [2, 4, 5, 7, 9]);
        c.forget(2);
        assert!(!c.contains(2) && c.contains(9));
    }

    #[test]
    fn report_text_and_json_say_what_was_confirmed() {
        let ok = NodeStop {
            node: 2,
            stopped: true,
            statusword: Some(0x0250),
            state: Some(DriveState::SwitchOnDisabled),
            sent: vec![0x0002, 0x0000],
            reason: None,
        };
        let bad = NodeStop {
            node: 3,
            stopped: false,
            statusword: None,
            state: None,
            sent: vec![],
            reason: Some("no answer to SDO".into()),
        };
        let r = StopReport {
            nodes: vec![ok.clone(), bad],
            idle: vec![(4, DriveState::SwitchOnDisabled)],
            cancelled: vec!["run 2 pv".into()],
        };
        assert!(!r.all_stopped());
        let text = r.text();
        assert!(
            text.starts_with("1 of 2 drive(s) NOT confirmed stopped\ncancelled: run 2 pv\n"),
            "{text}"
        );
        assert!(
            text.contains("node 3: NOT confirmed stopped: no answer to SDO"),
            "{text}"
        );
        assert!(
            text.contains("node 4: Switch on disabled (not powered, nothing sent)"),
            "{text}"
        );
        let j = super::super::to_json(&r);
        assert_eq!(j["ok"], false);
        assert_eq!(j["nodes"][0]["stopped"], true);
        assert_eq!(j["nodes"][0]["state"], "switch_on_disabled");
        assert_eq!(j["nodes"][1]["reason"], "no answer to SDO");
        let e = r.into_result().unwrap_err();
        assert_eq!(e.exit_code(), 5);
        let single = StopReport {
            nodes: vec![ok],
            ..StopReport::default()
        };
        assert_eq!(single.into_result().unwrap().json()["ok"], true);
    }
}
