//! What every detector shares: the capture clock (frame number and time), the node table
//! (each node's facts several detectors read) and the incident book (incidents opened,
//! grouped per key, with their timelines). Each detector keeps its own state of a node in
//! a [`PerNode`] table; the timeline knows no detector.

use crate::analysis::incident::{Incident, Problem, Status};
use crate::decode::heartbeat::NmtState;
use crate::frame::NodeKey;
use std::collections::{BTreeMap, HashMap};

/// One millisecond in ns.
pub(super) const MS: u64 = 1_000_000;

/// A frame seen: its number and time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct At {
    pub(super) frame: u64,
    pub(super) t: u64,
}

/// What one node has shown so far.
#[derive(Clone, Debug, Default)]
pub(super) struct Node {
    /// Something came from the node (heartbeat, EMCY, SDO answer, TPDO).
    pub(super) heard: bool,
    /// Last frame of any kind sent by the node.
    pub(super) last_any: Option<At>,
    /// The last heartbeat state (not boot-up) and when.
    pub(super) last_state: Option<(u64, NmtState)>,
    /// A heartbeat that stopped: the last one, when it was missed, silent ms so far.
    pub(super) silence: Option<(At, u64, f64)>,
    /// 0x1000 read as a CiA 402 device.
    pub(super) cia402: bool,
    /// The last EMCY error code.
    pub(super) last_emcy: Option<u16>,
}

/// A detector's own state of each node, made on first use. Making it puts the node in the
/// timeline's table too: the end of the capture goes through that table.
#[derive(Clone, Debug, Default)]
pub(super) struct PerNode<T>(BTreeMap<NodeKey, T>);

impl<T: Default> PerNode<T> {
    /// Node `n`'s state, made on first use (and the node in `tl`'s table).
    pub(super) fn of(&mut self, tl: &mut Timeline, n: NodeKey) -> &mut T {
        tl.node(n);
        self.0.entry(n).or_default()
    }

    /// Node `n`'s state, if it was made.
    pub(super) fn get(&self, n: NodeKey) -> Option<&T> {
        self.0.get(&n)
    }

    /// The nodes with a state, in key order.
    pub(super) fn iter(&self) -> impl Iterator<Item = (&NodeKey, &T)> {
        self.0.iter()
    }
}

/// The clock, the nodes and the incidents of one capture.
#[derive(Clone, Default)]
pub(super) struct Timeline {
    /// The frame being read.
    pub(super) at: At,
    /// The capture time reached by a tick (ns), 0 before any tick.
    pub(super) now: u64,
    /// Time of the first frame.
    pub(super) first_ns: Option<u64>,
    /// The interface of the frame being read (index into the source's table).
    pub(super) iface: u16,
    /// Interface names by index, as far as known (to name nodes when there are several).
    pub(super) iface_names: Vec<String>,
    pub(super) nodes: BTreeMap<NodeKey, Node>,
    pub(super) incidents: Vec<Incident>,
    keyed: HashMap<(Option<NodeKey>, Problem, u32), usize>,
}

impl Timeline {
    /// Node `n`, made on first use.
    pub(super) fn node(&mut self, n: NodeKey) -> &mut Node {
        self.nodes.entry(n).or_default()
    }

    /// A new incident of `problem` on `node` (None: the bus) at `t`; its index.
    pub(super) fn open(&mut self, node: Option<NodeKey>, problem: Problem, t: u64) -> usize {
        self.incidents.push(Incident {
            node: node.map(|k| k.node),
            iface: node.map_or(0, |k| k.iface),
            iface_name: None,
            axes: Vec::new(),
            problem,
            status: Status::Open,
            title: String::new(),
            cause: None,
            events: Vec::new(),
            check: Vec::new(),
            why: String::new(),
            count: 0,
            first_ns: t,
            last_ns: t,
            findings: Vec::new(),
        });
        self.incidents.len() - 1
    }

    /// The incident for `(node, problem, detail)`, made on first use; counts one more
    /// occurrence at `t`.
    pub(super) fn grouped(&mut self, node: Option<NodeKey>, problem: Problem, detail: u32, t: u64) -> usize {
        let i = match self.keyed.get(&(node, problem, detail)) {
            Some(i) => *i,
            None => {
                let i = self.open(node, problem, t);
                self.keyed.insert((node, problem, detail), i);
                i
            }
        };
        let inc = &mut self.incidents[i];
        inc.count += 1;
        inc.last_ns = inc.last_ns.max(t);
        i
    }

    /// The grouped incident for `(node, problem, detail)`, if there is one.
    pub(super) fn keyed(&self, node: Option<NodeKey>, problem: Problem, detail: u32) -> Option<usize> {
        self.keyed.get(&(node, problem, detail)).copied()
    }

    /// One more line in incident `i`'s timeline.
    pub(super) fn step(&mut self, i: usize, at: At, text: impl Into<String>) {
        self.incidents[i].step(at.frame, at.t, text);
    }
}
