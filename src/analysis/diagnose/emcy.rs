//! EMCY detector (`emcy`): emergency messages not tied to a drive fault, grouped per
//! error code and ended by an error reset (EMCY 0x0000). An EMCY right before a CiA 402
//! fault is that fault's cause instead (the facade tells which faults [`super::drive`]
//! has open, and which one it just opened).

use super::detector::Detector;
use super::timeline::{At, MS, PerNode, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::decode::emcy::Emcy;
use crate::frame::NodeKey;
use std::collections::HashMap;

/// An EMCY this close before a fault is taken as its cause.
pub(super) const EMCY_CAUSE_NS: u64 = 100 * MS;

/// The EMCY of one node not given to an incident yet (a fault may follow at once).
#[derive(Clone, Debug, Default)]
struct NodeEmcy {
    waiting: Vec<(At, Emcy)>,
}

/// Finds EMCY incidents and the EMCY causes of drive faults.
#[derive(Clone, Default)]
pub(super) struct Emcys {
    /// The profile's "check first" steps for the EMCY code of an incident.
    device_check: HashMap<usize, Vec<String>>,
    /// The EMCY code given as the cause of a drive-fault incident.
    fault_codes: HashMap<usize, u16>,
    nodes: PerNode<NodeEmcy>,
}

/// An EMCY in words: its text, code and manufacturer fields.
fn emcy_text(e: &Emcy) -> String {
    let mut s = format!("{} (EMCY 0x{:04X})", e.text, e.code);
    for (k, v) in &e.mfr_fields {
        s.push_str(&format!(", {k}={v}"));
    }
    s
}

impl Emcys {
    /// The EMCY code that caused drive-fault incident `i`.
    pub(super) fn fault_code(&self, i: usize) -> Option<u16> {
        self.fault_codes.get(&i).copied()
    }

    /// The device's own "check first" steps for incident `i`'s EMCY code.
    pub(super) fn device_check(&self, i: usize) -> Option<&Vec<String>> {
        self.device_check.get(&i)
    }

    /// An EMCY `e` of node `n`, whose open drive-fault incidents are `faults`.
    pub(super) fn emcy(&mut self, tl: &mut Timeline, n: NodeKey, e: &Emcy, faults: impl IntoIterator<Item = usize>) {
        let at = tl.at;
        tl.node(n).last_emcy = Some(e.code);
        self.flush(tl, n, at.t.saturating_sub(EMCY_CAUSE_NS));
        if e.code == 0 {
            // "Error reset or no error": the node's EMCY incidents are over.
            self.flush(tl, n, u64::MAX);
            let mine: Vec<usize> = (0..tl.incidents.len())
                .filter(|i| {
                    let inc = &tl.incidents[*i];
                    inc.key() == Some(n) && inc.problem == Problem::Emcy && inc.status == Status::Open
                })
                .collect();
            for i in mine {
                tl.incidents[i].status = Status::Recovered;
                tl.step(i, at, "Error reset: the node reports no error any more (EMCY 0x0000)");
            }
            return;
        }
        let fault = faults.into_iter().find(|i| tl.incidents[*i].cause.is_none());
        match fault {
            Some(i) => self.give_cause(tl, i, at, e),
            None => self.nodes.of(tl, n).waiting.push((at, e.clone())),
        }
    }

    /// EMCY `e` at `at` is the cause of drive-fault incident `i`.
    fn give_cause(&mut self, tl: &mut Timeline, i: usize, at: At, e: &Emcy) {
        if !e.check.is_empty() {
            self.device_check.insert(i, e.check.clone());
        }
        tl.incidents[i].cause = Some(emcy_text(e));
        self.fault_codes.insert(i, e.code);
        tl.step(i, at, format!("Cause reported: {}", emcy_text(e)));
    }

    /// A fault of `n` just started (incident `i`): a recent EMCY of the node is its cause.
    pub(super) fn absorb(&mut self, tl: &mut Timeline, n: NodeKey, i: usize) {
        let t = tl.at.t;
        self.flush(tl, n, t.saturating_sub(EMCY_CAUSE_NS));
        if let Some((at, e)) = self.nodes.of(tl, n).waiting.pop() {
            self.give_cause(tl, i, at, &e);
        }
        self.flush(tl, n, u64::MAX);
    }

    /// EMCY of `n` older than `before` become EMCY incidents (grouped per code).
    fn flush(&mut self, tl: &mut Timeline, n: NodeKey, before: u64) {
        let node = self.nodes.of(tl, n);
        let keep = node
            .waiting
            .iter()
            .position(|(at, _)| at.t >= before)
            .unwrap_or(node.waiting.len());
        let old: Vec<(At, Emcy)> = node.waiting.drain(..keep).collect();
        for (at, e) in old {
            let i = tl.grouped(Some(n), Problem::Emcy, u32::from(e.code), at.t);
            if !e.check.is_empty() {
                self.device_check.insert(i, e.check.clone());
            }
            let inc = &mut tl.incidents[i];
            inc.status = Status::Open;
            inc.cause = Some(emcy_text(&e));
            tl.step(i, at, format!("EMCY {}", emcy_text(&e)));
        }
    }
}

impl Detector for Emcys {
    fn end_node(&mut self, tl: &mut Timeline, n: NodeKey, _end: At) {
        self.flush(tl, n, u64::MAX);
    }
}
