//! Boot-up and NMT detector: restarts nobody asked for (`rebooted`: no NMT reset before
//! the boot-up), two boot-ups of one node-ID close together (`duplicate_id`), and NMT
//! commands a node did not follow (`nmt_ignored`).

use super::timeline::{At, MS, PerNode, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::decode::heartbeat::NmtState;
use crate::frame::NodeKey;
use std::collections::BTreeMap;

/// Two boot-ups of one node-ID this close together come from two devices.
const DUPLICATE_BOOT_NS: u64 = 100 * MS;
/// A boot-up this soon after an NMT reset was asked for.
const RESET_BOOT_NS: u64 = 5_000 * MS;
/// A node has this long (and two heartbeats) to follow an NMT command.
const NMT_GRACE_NS: u64 = 100 * MS;

/// An NMT command a node should follow.
#[derive(Clone, Copy, Debug)]
struct Expect {
    at: At,
    target: NmtState,
    command: &'static str,
    wrong: u8,
}

/// The boot-ups and NMT commands of one node.
#[derive(Clone, Debug, Default)]
struct NodeBoot {
    last_boot: Option<u64>,
    reset_asked: Option<u64>,
    expect: Option<Expect>,
    /// The open "did not follow" incident and the state the command asked for.
    ignored: Option<(usize, NmtState)>,
}

/// The words and the state an NMT command specifier asks for (None: not a command a
/// node's heartbeat shows).
pub(super) fn nmt_command(cs: u8) -> Option<(&'static str, NmtState)> {
    Some(match cs {
        0x01 => ("start", NmtState::Operational),
        0x02 => ("stop", NmtState::Stopped),
        0x80 => ("enter pre-operational", NmtState::PreOperational),
        0x81 => ("reset node", NmtState::BootUp),
        0x82 => ("reset communication", NmtState::BootUp),
        _ => return None,
    })
}

/// Finds boot-up and NMT incidents.
#[derive(Clone, Default)]
pub(super) struct Boots {
    /// The last NMT reset addressed to all nodes, per interface.
    reset_all: BTreeMap<u16, u64>,
    nodes: PerNode<NodeBoot>,
}

impl Boots {
    /// NMT `command` (asking for `state`) to `target` (0: all nodes) on the current
    /// interface: the nodes heard so far should follow it.
    pub(super) fn command(&mut self, tl: &mut Timeline, command: &'static str, state: NmtState, target: u8) {
        let (at, iface) = (tl.at, tl.iface);
        let known: Vec<NodeKey> = tl
            .nodes
            .iter()
            .filter(|(n, d)| n.iface == iface && (target == 0 || n.node == target) && d.last_state.is_some())
            .map(|(n, _)| *n)
            .collect();
        if state == NmtState::BootUp {
            if target == 0 {
                self.reset_all.insert(iface, at.t);
            } else {
                self.nodes.of(tl, NodeKey::new(iface, target)).reset_asked = Some(at.t);
            }
        }
        for n in known {
            self.nodes.of(tl, n).expect = Some(Expect {
                at,
                target: state,
                command,
                wrong: 0,
            });
        }
    }

    /// A heartbeat of `n` in state `s`: an NMT command followed, late or not at all.
    pub(super) fn heartbeat(&mut self, tl: &mut Timeline, n: NodeKey, s: NmtState) {
        let at = tl.at;
        let boot = self.nodes.of(tl, n);
        if let Some((i, target)) = boot.ignored
            && target == s
        {
            boot.ignored = None;
            tl.incidents[i].status = Status::Warning;
            tl.step(i, at, format!("Reached {} later", s.text()));
        }
        let Some(mut ex) = boot.expect else { return };
        if ex.target == s {
            boot.expect = None;
            return;
        }
        if s == NmtState::BootUp {
            return;
        }
        ex.wrong += 1;
        boot.expect = Some(ex);
        if ex.wrong >= 2 && at.t.saturating_sub(ex.at.t) >= NMT_GRACE_NS {
            boot.expect = None;
            let i = tl.grouped(
                Some(n),
                Problem::NmtIgnored,
                u32::from(ex.target.as_str().len() as u8),
                at.t,
            );
            tl.incidents[i].status = Status::Open;
            tl.incidents[i].cause = Some(format!("NMT {} sent, node stays {}", ex.command, s.text()));
            tl.step(i, ex.at, format!("NMT {} sent", ex.command));
            tl.step(i, at, format!("Node still says {}", s.text()));
            boot.ignored = Some((i, ex.target));
        }
    }

    /// A boot-up of `n` at `at` (`rebooted`: the node was heard before).
    pub(super) fn boot_up(&mut self, tl: &mut Timeline, n: NodeKey, at: At, rebooted: bool) {
        let reset_all = self.reset_all.get(&n.iface).copied();
        let boot = self.nodes.of(tl, n);
        // (Equal times say nothing: logs without timestamps.)
        let close = boot
            .last_boot
            .is_some_and(|t| at.t > t && at.t - t <= DUPLICATE_BOOT_NS);
        let asked = boot
            .reset_asked
            .max(reset_all)
            .is_some_and(|t| at.t.saturating_sub(t) <= RESET_BOOT_NS);
        boot.last_boot = Some(at.t);
        boot.expect = None;
        if asked {
            boot.reset_asked = None;
        }
        let node = tl.node(n);
        node.last_state = None;
        // A silence that ends in a boot-up is part of the restart (expected when a reset
        // was asked for).
        let silence = node.silence.take();
        if close {
            let i = tl.grouped(Some(n), Problem::DuplicateId, 0, at.t);
            tl.step(i, at, "A second boot-up with the same node-ID right after the first");
        } else if rebooted && !asked {
            let i = tl.grouped(Some(n), Problem::Rebooted, 0, at.t);
            tl.incidents[i].status = Status::Warning;
            if let Some((last, _, _)) = silence {
                tl.step(i, last, "Last heartbeat before the restart");
            }
            tl.step(i, at, "Boot-up: the node restarted, no NMT reset was sent before");
        }
    }
}
