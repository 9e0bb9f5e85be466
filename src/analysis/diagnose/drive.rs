//! CiA 402 drive detector: faults (`drive_fault`, with their cause from EMCY or 0x603F
//! and the fault resets that followed; faults on several axes at once are one incident)
//! and drives that do not reach the state their controlword asked for (`drive_stuck`).
//! Reads the controlword, statusword and error code of each axis from PDOs and SDO
//! transfers.

use super::detector::Detector;
use super::timeline::{At, MS, PerNode, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::decode::cia402::DriveState;
use crate::decode::stall::{self, Observation, Step};
use crate::frame::NodeKey;
use crate::od::PdoMapping;
use std::collections::{BTreeMap, HashMap};

/// Faults on several axes of one node this close together are one incident.
const AXES_TOGETHER_NS: u64 = 50 * MS;
/// A fault reset this soon after the fault cleared belongs to it (one SYNC cycle).
const SAME_CYCLE_NS: u64 = 20 * MS;
/// A drive has this long to show the state its controlword asked for.
const STALL_NS: u64 = 1_000 * MS;
/// Axes of a multi-axis drive (objects 0x6000 + 0x800 * (axis - 1)).
const AXES: u16 = 8;

/// The axis (1-based) whose object `index` is, for the object of axis 1 at `base`.
fn axis_of(index: u16, base: u16) -> Option<u8> {
    let off = index.checked_sub(base)?;
    (off % 0x800 == 0 && off / 0x800 < AXES).then(|| (off / 0x800 + 1) as u8)
}

/// True when a PDO with `mapping` carries a CiA 402 controlword, statusword or error code.
pub(super) fn maps_drive_words(mapping: &PdoMapping) -> bool {
    mapping
        .entries
        .iter()
        .any(|e| [0x6040, 0x6041, 0x603F].iter().any(|b| axis_of(e.index, *b).is_some()))
}

/// A CiA 402 axis.
#[derive(Clone, Debug, Default)]
struct Axis {
    cw: Option<u16>,
    /// The open fault incident.
    fault: Option<usize>,
    /// A cleared fault waiting for "operation enabled".
    cleared: Option<usize>,
    /// The last statusword.
    sw: Option<u16>,
    /// A state change the controlword asked for and the statusword has not shown yet:
    /// when, what, and the statusword then.
    asked: Option<(At, Step, Option<u16>)>,
    /// The open "stuck" incident, until the drive reaches the state asked for.
    stuck: Option<usize>,
}

/// The CiA 402 axes of one node.
#[derive(Clone, Debug, Default)]
struct NodeDrive {
    axes: BTreeMap<u8, Axis>,
}

impl NodeDrive {
    /// The open fault incidents of the node's axes.
    fn faults(&self) -> impl Iterator<Item = usize> + '_ {
        self.axes.values().filter_map(|a| a.fault)
    }
}

/// Finds drive faults and stuck drives.
#[derive(Clone, Default)]
pub(super) struct Drives {
    /// The fault resets sent for each drive-fault incident.
    resets: HashMap<usize, u32>,
    nodes: PerNode<NodeDrive>,
}

impl Drives {
    /// The fault resets sent for drive-fault incident `i`.
    pub(super) fn resets(&self, i: usize) -> u32 {
        self.resets.get(&i).copied().unwrap_or(0)
    }

    /// The open fault incidents of `n`'s axes.
    pub(super) fn faults(&self, n: NodeKey) -> impl Iterator<Item = usize> + '_ {
        self.nodes.get(n).into_iter().flat_map(NodeDrive::faults)
    }

    /// A CiA 402 object value `w` of `n` at `index` (from a PDO or an SDO transfer).
    /// Returns the fault incident it opened, if it did: its cause, a recent EMCY of the
    /// node, is the EMCY detector's to give (the facade asks it).
    pub(super) fn word(&mut self, tl: &mut Timeline, n: NodeKey, index: u16, w: u16) -> Option<usize> {
        if let Some(axis) = axis_of(index, 0x6041) {
            return self.statusword(tl, n, axis, w);
        }
        if let Some(axis) = axis_of(index, 0x6040) {
            self.controlword(tl, n, axis, w);
        } else if let Some(axis) = axis_of(index, 0x603F) {
            let fault = self.nodes.of(tl, n).axes.get(&axis).and_then(|a| a.fault);
            if let Some(i) = fault
                && w != 0
            {
                let text = format!("drive error code 0x{w:04X} (0x{index:04X})");
                let inc = &mut tl.incidents[i];
                if !inc.cause.as_deref().is_some_and(|c| c.contains(&text)) {
                    inc.cause = Some(match inc.cause.take() {
                        Some(c) => format!("{c}; {text}"),
                        None => text.clone(),
                    });
                    let at = tl.at;
                    tl.step(i, at, format!("Drive reports {text}"));
                }
            }
        }
        None
    }

    /// A statusword `sw` of `n`'s `axis`; the fault incident it opened, if it did.
    fn statusword(&mut self, tl: &mut Timeline, n: NodeKey, axis: u8, sw: u16) -> Option<usize> {
        let at = tl.at;
        let state = DriveState::from_statusword(sw);
        let node = self.nodes.of(tl, n);
        stall_check(tl, node, n, axis, sw, state);
        let faulted = matches!(state, DriveState::Fault | DriveState::FaultReactionActive);
        let a = node.axes.entry(axis).or_default().clone();
        let mut opened = None;
        match (a.fault, faulted) {
            (None, true) => {
                // Another axis of the node faulted just now: one incident.
                let together = node.faults().find(|i| {
                    at.t.saturating_sub(tl.incidents[*i].first_ns) <= AXES_TOGETHER_NS
                        && tl.incidents[*i].status == Status::Open
                });
                let i = match together {
                    Some(i) => {
                        tl.incidents[i].axes.push(axis);
                        tl.step(i, at, format!("Axis {axis} faulted too (statusword 0x{sw:04X})"));
                        i
                    }
                    None => {
                        let i = tl.open(Some(n), Problem::DriveFault, at.t);
                        tl.incidents[i].count = 1;
                        tl.incidents[i].axes.push(axis);
                        self.resets.insert(i, 0);
                        tl.step(
                            i,
                            at,
                            format!("Fault: the drive switched the motor torque off (statusword 0x{sw:04X})"),
                        );
                        opened = Some(i);
                        i
                    }
                };
                let ax = node.axes.entry(axis).or_default();
                ax.fault = Some(i);
                ax.cleared = None;
            }
            (Some(i), false) => {
                let ax = node.axes.entry(axis).or_default();
                ax.fault = None;
                ax.cleared = Some(i);
                // The incident is recovered once every faulted axis is clear.
                let still = node.faults().any(|f| f == i);
                if !still {
                    tl.incidents[i].status = Status::Recovered;
                    tl.incidents[i].last_ns = at.t;
                    tl.step(
                        i,
                        at,
                        format!("Fault cleared (statusword 0x{sw:04X}, {})", state.text()),
                    );
                }
            }
            _ => {}
        }
        if state == DriveState::OperationEnabled
            && let Some(i) = node.axes.get_mut(&axis).and_then(|a| a.cleared.take())
        {
            let others_running = node.axes.values().any(|x| x.cleared == Some(i));
            if !others_running {
                tl.step(i, at, "Running again (operation enabled)");
            }
        }
        opened
    }

    fn controlword(&mut self, tl: &mut Timeline, n: NodeKey, axis: u8, cw: u16) {
        let at = tl.at;
        let node = self.nodes.of(tl, n);
        let ax = node.axes.entry(axis).or_default().clone();
        if ax.cw != Some(cw)
            && let Some(step) = stall::requested(cw)
        {
            let a = node.axes.entry(axis).or_default();
            let done =
                a.sw.is_some_and(|sw| stall::reached(&step, DriveState::from_statusword(sw)));
            a.asked = (!done).then_some((at, step, a.sw));
        }
        let rising = cw & 0x80 != 0 && ax.cw.is_none_or(|p| p & 0x80 == 0);
        node.axes.entry(axis).or_default().cw = Some(cw);
        // A reset in the same cycle as the clear (the statusword went out first) counts too.
        let just_cleared = ax
            .cleared
            .filter(|i| at.t.saturating_sub(tl.incidents[*i].last_ns) <= SAME_CYCLE_NS);
        let Some(i) = ax.fault.or(just_cleared).filter(|_| rising) else {
            return;
        };
        let resets = self.resets.entry(i).or_default();
        *resets += 1;
        let r = *resets;
        let text = if ax.fault.is_none() {
            format!("Fault reset #{r} sent, in the same cycle as the clear")
        } else if r > 1 {
            format!(
                "Fault reset #{r} sent; reset #{} did not work, the fault was still there",
                r - 1
            )
        } else {
            "Fault reset #1 sent (controlword bit 7)".to_string()
        };
        tl.step(i, at, text);
    }
}

/// A statusword `sw` of an axis asked to change state: reached (a stuck incident
/// recovers), a fault (the fault incident tells it), or still not there after
/// [`STALL_NS`]: the drive is stuck, with the reason the bus shows. `node` is `n`'s state.
fn stall_check(tl: &mut Timeline, node: &mut NodeDrive, n: NodeKey, axis: u8, sw: u16, state: DriveState) {
    let at = tl.at;
    let nmt = tl.nodes.get(&n).and_then(|d| d.last_state.map(|(_, s)| s));
    let emcy = tl.nodes.get(&n).and_then(|d| d.last_emcy);
    let a = node.axes.entry(axis).or_default();
    a.sw = Some(sw);
    let stuck = a.stuck;
    let cw = a.cw;
    let Some((asked, step, before)) = a.asked else {
        return;
    };
    let faulted = matches!(state, DriveState::Fault | DriveState::FaultReactionActive);
    if stall::reached(&step, state) || faulted {
        a.asked = None;
        a.stuck = None;
        if let Some(i) = stuck.filter(|_| !faulted) {
            tl.incidents[i].status = Status::Recovered;
            tl.incidents[i].last_ns = at.t;
            let waited = (at.t - asked.t) as f64 / 1e9;
            let inc = &mut tl.incidents[i];
            inc.title = format!("{}; reached {} after {waited:.2} s", inc.title, state.text());
            tl.step(i, at, format!("Reached {} after {waited:.2} s", state.text()));
        }
        return;
    }
    if stuck.is_some() || at.t.saturating_sub(asked.t) < STALL_NS {
        return;
    }
    let obs = Observation {
        nmt,
        before,
        statusword: Some(sw),
        controlword: cw,
        emcy,
        ..Observation::default()
    };
    let reason = stall::diagnose(n.node, &step, &obs);
    let detail = (u32::from(axis) << 8) | u32::from(step.controlword as u8);
    let i = tl.grouped(Some(n), Problem::DriveStuck, detail, asked.t);
    let inc = &mut tl.incidents[i];
    if !inc.axes.contains(&axis) {
        inc.axes.push(axis);
    }
    inc.status = Status::Open;
    inc.last_ns = at.t;
    inc.title = format!(
        "Stuck in {}: {} (controlword 0x{:04X}) not followed",
        state.text(),
        step.name,
        step.controlword
    );
    inc.cause = Some(reason);
    tl.step(
        i,
        asked,
        format!(
            "Controlword 0x{:04X} ({}) asks for {}",
            step.controlword,
            step.name,
            step.target.text()
        ),
    );
    let waited = (at.t - asked.t) as f64 / 1e9;
    tl.step(
        i,
        at,
        format!("Still {} (statusword 0x{sw:04X}) after {waited:.2} s", state.text()),
    );
    node.axes.entry(axis).or_default().stuck = Some(i);
}

impl Detector for Drives {
    fn end_node(&mut self, tl: &mut Timeline, n: NodeKey, end: At) {
        let stuck: Vec<(usize, u16)> = self
            .nodes
            .get(n)
            .into_iter()
            .flat_map(|d| d.axes.values())
            .filter_map(|a| Some((a.stuck?, a.sw?)))
            .collect();
        for (i, sw) in stuck {
            let state = DriveState::from_statusword(sw).text();
            tl.step(i, end, format!("Still {state} at the end of the capture"));
            tl.incidents[i].last_ns = end.t;
        }
    }
}
