//! Heartbeat detector: heartbeats that stop for good (`silent`) or for a while
//! (`silent_back`), heartbeat states that flip between two values (`duplicate_id`: two
//! devices with one node-ID), and a node nobody watches (`unmonitored`: 0x1017 = 0 and no
//! node guarding).

use super::detector::Detector;
use super::timeline::{At, PerNode, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::decode::heartbeat::NmtState;
use crate::frame::NodeKey;
use crate::sdo::transaction::{Outcome, Transaction};
use std::collections::BTreeMap;

/// The heartbeat state of one node.
#[derive(Clone, Debug, Default)]
struct NodeBeat {
    /// A heartbeat (not a boot-up) came since the last boot-up.
    beating: bool,
    last_hb: Option<At>,
    /// The heartbeat state before the last change.
    state_before: Option<NmtState>,
    conflicts: u32,
    /// A node guarding request (RTR) was seen.
    guarded: bool,
    /// 0x1017 = 0 seen on the bus, and when.
    heartbeat_off: Option<At>,
}

/// Finds heartbeat incidents.
#[derive(Clone, Default)]
pub(super) struct Heartbeats {
    /// Longest silence per node that came back (ms).
    silent_max: BTreeMap<NodeKey, f64>,
    nodes: PerNode<NodeBeat>,
}

impl Heartbeats {
    /// A heartbeat of `n` in state `s`.
    pub(super) fn heartbeat(&mut self, tl: &mut Timeline, n: NodeKey, s: NmtState) {
        let at = tl.at;
        let beat = self.nodes.of(tl, n);
        beat.last_hb = Some(at);
        beat.beating = s != NmtState::BootUp;
        if s == NmtState::BootUp {
            return;
        }
        // Two devices with one node-ID: heartbeat states that flip back and forth
        // (A, B, A, B...), which one node changing state never does.
        if let (Some((_, s1)), Some(s2)) = (tl.node(n).last_state, beat.state_before)
            && s != s1
            && s == s2
        {
            beat.conflicts += 1;
            if beat.conflicts == 3 {
                let i = tl.grouped(Some(n), Problem::DuplicateId, 0, at.t);
                tl.step(
                    i,
                    at,
                    format!("Heartbeats keep flipping between {} and {}", s1.text(), s.text()),
                );
            }
        }
        let node = tl.node(n);
        if node.last_state.is_some_and(|(_, s1)| s1 != s) {
            beat.state_before = node.last_state.map(|(_, s1)| s1);
        }
        node.last_state = Some((at.t, s));
    }

    /// A boot-up of `n`: the states before it say nothing of the states after.
    pub(super) fn boot_up(&mut self, tl: &mut Timeline, n: NodeKey) {
        self.nodes.of(tl, n).state_before = None;
    }

    /// A node guarding request (RTR) to `n`: the node is watched.
    pub(super) fn guarded(&mut self, tl: &mut Timeline, n: NodeKey) {
        self.nodes.of(tl, n).guarded = true;
    }

    /// The tracker lost `n`'s heartbeat at `at` after `silent_ms`; a heartbeat that has
    /// not started since the boot-up did not stop.
    pub(super) fn lost(&mut self, tl: &mut Timeline, n: NodeKey, at: At, silent_ms: f64) {
        let beat = self.nodes.of(tl, n);
        if !beat.beating {
            return;
        }
        let last = beat.last_hb.unwrap_or(at);
        tl.node(n).silence = Some((last, at.t, silent_ms));
    }

    /// `n`'s heartbeat came back at `at` after `silent_ms`.
    pub(super) fn back(&mut self, tl: &mut Timeline, n: NodeKey, at: At, silent_ms: f64) {
        let Some((last, lost, _)) = tl.node(n).silence.take() else {
            return;
        };
        let i = tl.grouped(Some(n), Problem::SilentBack, 0, lost);
        let longest = self.silent_max.entry(n).or_insert(0.0);
        *longest = longest.max(silent_ms);
        let inc = &mut tl.incidents[i];
        inc.status = Status::Warning;
        inc.cause = Some(format!("no heartbeat for up to {:.2} s", *longest / 1000.0));
        tl.step(
            i,
            at,
            format!(
                "No heartbeat for {:.2} s (last #{}), then it came back",
                silent_ms / 1000.0,
                last.frame
            ),
        );
    }
}

impl Detector for Heartbeats {
    fn transaction(&mut self, tl: &mut Timeline, t: &Transaction) {
        if t.outcome != Outcome::Ok || t.data.is_empty() || (t.index, t.sub) != (0x1017, 0) {
            return;
        }
        let at = tl.at;
        let off = super::detector::value(t) & 0xFFFF == 0;
        self.nodes.of(tl, t.key()).heartbeat_off = off.then_some(at);
    }

    fn end_node(&mut self, tl: &mut Timeline, n: NodeKey, end: At) {
        if let Some((last, lost, _)) = tl.node(n).silence.take() {
            let i = tl.grouped(Some(n), Problem::Silent, 0, lost);
            tl.step(i, last, "Last heartbeat");
            if let Some(other) = tl.nodes[&n].last_any.filter(|a| a.t > lost) {
                tl.incidents[i].cause = Some("the heartbeat stopped, other messages of the node go on".into());
                tl.step(i, other, "The node still sends other messages (PDO, SDO or EMCY)");
            }
            tl.step(i, end, "Nothing after that, until the end of the capture");
            tl.incidents[i].last_ns = end.t;
        }
        let Some(beat) = self.nodes.get(n) else { return };
        if let Some(at) = beat.heartbeat_off.filter(|_| !beat.guarded) {
            let i = tl.grouped(Some(n), Problem::Unmonitored, 0, at.t);
            tl.incidents[i].status = Status::Warning;
            tl.step(i, at, "Heartbeat producer time 0x1017 = 0: heartbeat off");
        }
    }
}
