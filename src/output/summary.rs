//! `--summary`: per-node and per-kind totals.

use super::busload::{BusJson, BusLoad, IfaceJson, push_num};
use crate::decode::Kind;
use crate::frame::{Frame, Interfaces, NodeKey};
use crate::wire::WireFigures;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::fmt::Write;

/// Counters of one node, by kind index.
pub type Counts = [u64; Kind::ALL.len()];

/// Running totals of frames by kind and by node.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Frames per kind.
    pub by_kind: BTreeMap<Kind, u64>,
    /// Frames per node (of its interface) by kind index ([`Kind::index`]), in node order:
    /// only nodes seen, after [`Summary::finish`].
    pub by_node: Vec<(NodeKey, Counts)>,
    /// Frames in all.
    pub frames: u64,
    /// The bits on the wire (set the bit rate with [`BusLoad::new`] before counting).
    pub bus: BusLoad,
    kind_counts: Counts,
    /// The first interface's 128 nodes' counters (made on its first node frame): the
    /// common case of one bus stays an array increment.
    first_counts: Vec<Counts>,
    /// Counters of the nodes of every other interface, only of nodes seen: a log of
    /// 40,000 interface names costs its nodes, not 40,000 x 128 counters. A fast seeded
    /// hash: this map is looked up per frame.
    other_counts: HashMap<NodeKey, Counts, foldhash::fast::RandomState>,
    /// Interface names by index, as far as known: with nodes on several, a node is shown
    /// with its interface (`can1 node 5`, JSON key `"can1/5"`).
    ifaces: Vec<String>,
}

impl Summary {
    /// Empty totals whose bits on the wire are counted by `bus` (its bit rate set).
    pub fn with_bus(bus: BusLoad) -> Summary {
        Summary {
            bus,
            ..Summary::default()
        }
    }

    /// Counts one frame of the first interface.
    pub fn add(&mut self, kind: Kind, node: Option<u8>) {
        self.add_on(0, kind, node);
    }

    /// Counts one frame of interface `iface` (on the first interface a fixed-size array
    /// increment: this is the hot path).
    #[inline(always)]
    pub fn add_on(&mut self, iface: u16, kind: Kind, node: Option<u8>) {
        self.frames += 1;
        let k = kind.index();
        self.kind_counts[k] += 1;
        let Some(n) = node else { return };
        if iface == 0 {
            if self.first_counts.is_empty() {
                self.first_counts = vec![[0; Kind::ALL.len()]; 128];
            }
            self.first_counts[usize::from(n & 0x7F)][k] += 1;
        } else {
            self.other_counts
                .entry(NodeKey::new(iface, n & 0x7F))
                .or_insert([0; Kind::ALL.len()])[k] += 1;
        }
    }

    /// Counts one frame: its kind and node, and its bits on the wire (`figures`: worked
    /// out already, else here).
    #[inline]
    pub fn add_frame(&mut self, frame: &Frame, kind: Kind, node: Option<u8>, figures: Option<WireFigures>) {
        self.add_on(frame.iface, kind, node);
        self.bus.add(frame, node, figures);
    }

    /// Takes note of the interface names of the frames counted (a source's table grows as
    /// names appear; call it with the newest).
    pub fn name_interfaces(&mut self, ifaces: &Interfaces) {
        let names = ifaces.names();
        if names.len() > self.ifaces.len() {
            self.ifaces.extend(names[self.ifaces.len()..].iter().cloned());
        }
    }

    /// Whether nodes were counted on several interfaces (then node 5 of can0 and node 5 of
    /// can1 are told apart). `by_node` is ordered by interface: the first and last differ.
    fn several_ifaces(&self) -> bool {
        let first = self.by_node.first().map(|k| k.0.iface);
        let last = self.by_node.last().map(|k| k.0.iface);
        first != last
    }

    /// The interface name to show with `node` when there are `several` interfaces.
    fn iface_of(&self, several: bool, node: NodeKey) -> Option<&str> {
        several.then(|| self.ifaces.get(usize::from(node.iface)).map_or("?", String::as_str))
    }

    /// Folds the counters into the `by_kind`/`by_node` maps.
    pub fn finish(&mut self) {
        self.by_kind.clear();
        self.by_node.clear();
        for (i, k) in Kind::ALL.iter().enumerate() {
            if self.kind_counts[i] > 0 {
                self.by_kind.insert(*k, self.kind_counts[i]);
            }
        }
        // The first interface's nodes come first (in node order), then the others' by key:
        // the keys sorted alone, not rows of counters (a capture of 40,000 interfaces has
        // hundreds of thousands).
        let first = self.first_counts.iter().enumerate();
        let first = first.map(|(n, counts)| (NodeKey::new(0, n as u8), *counts));
        let mut keys: Vec<NodeKey> = self.other_counts.keys().copied().collect();
        keys.sort_unstable();
        let others = keys.iter().filter_map(|key| Some((*key, *self.other_counts.get(key)?)));
        self.by_node
            .extend(first.chain(others).filter(|(_, c)| c.iter().any(|n| *n > 0)));
    }

    /// Text report.
    pub fn to_text(&self) -> String {
        let mut s = format!("frames: {}\n", self.frames);
        s.push_str("by kind:\n");
        for (k, n) in &self.by_kind {
            s.push_str(&format!("  {:<12} {n}\n", k.as_str()));
        }
        s.push_str("by node:\n");
        let several = self.several_ifaces();
        for (node, counts) in &self.by_node {
            // Pieces pushed, not `write!`: a capture of 40,000 interfaces has as many rows.
            let total: u64 = counts.iter().sum();
            s.push_str("  ");
            if let Some(iface) = self.iface_of(several, *node) {
                s.push_str(iface);
                s.push(' ');
            }
            s.push_str("node ");
            push_num(&mut s, u64::from(node.node), -3);
            s.push(' ');
            push_num(&mut s, total, 10);
            s.push(' ');
            for (k, n) in kinds(counts) {
                s.push(' ');
                s.push_str(k.as_str());
                s.push('=');
                push_num(&mut s, n, 0);
            }
            s.push('\n');
        }
        self.bus.to_text(&mut s, |out, k| {
            if let Some(iface) = self.iface_of(several, k) {
                out.push_str(iface);
                out.push(' ');
            }
            out.push_str("node ");
            push_num(out, u64::from(k.node), 0);
        });
        let buses = self.by_iface();
        if buses.len() > 1 {
            s.push_str("by bus:\n");
            for b in &buses {
                let load = b.load.map_or("-".to_string(), |l| format!("{:.2} %", l * 100.0));
                let _ = writeln!(
                    s,
                    "  {:<8} {:>10} frames {:>12} bits: load {load}, busiest 100 ms {:.2} %, longest burst {:.3} ms",
                    b.iface,
                    b.frames,
                    b.bits,
                    b.busiest_100ms * 100.0,
                    b.longest_burst_ms
                );
            }
        }
        s
    }

    /// Each interface's bus figures, in interface order.
    fn by_iface(&self) -> Vec<IfaceJson> {
        let name = |i: u16| self.ifaces.get(usize::from(i)).map_or("?", String::as_str);
        let all = self.bus.by_iface().into_iter();
        all.map(|(i, figures)| self.bus.iface_json(name(i), &figures)).collect()
    }

    /// The JSON key of a node: its number, or `can1/5` when there are `several` interfaces.
    fn node_key(&self, several: bool, node: NodeKey) -> String {
        match self.iface_of(several, node) {
            Some(iface) => format!("{iface}/{}", node.node),
            None => node.node.to_string(),
        }
    }

    /// The JSON report of `--summary --format jsonl`.
    pub fn to_json(&self) -> SummaryJson {
        let several = self.several_ifaces();
        let named = |kinds: &BTreeMap<Kind, u64>| kinds.iter().map(|(k, n)| (k.as_str(), *n)).collect();
        SummaryJson {
            bus: self.bus.to_json(|k| self.node_key(several, k)),
            by_iface: self.by_iface(),
            by_kind: named(&self.by_kind),
            by_node: self
                .by_node
                .iter()
                .map(|(node, counts)| {
                    (
                        self.node_key(several, *node),
                        kinds(counts).map(|(k, n)| (k.as_str(), n)).collect(),
                    )
                })
                .collect(),
            frames: self.frames,
        }
    }
}

/// The kinds counted in `counts` and their counts, in kind order as `by_kind` ([`Kind::ALL`]
/// is in that order).
fn kinds(counts: &Counts) -> impl Iterator<Item = (Kind, u64)> + '_ {
    Kind::ALL
        .iter()
        .map(|k| (*k, counts[k.index()]))
        .filter(|(_, n)| *n > 0)
}

/// The summary as a JSON record (fields in key order). Maps are ordered by their JSON
/// keys, so nodes are in text order (`"10"` before `"2"`).
#[derive(Clone, Debug, Serialize)]
pub struct SummaryJson {
    /// The bits on the wire and the bus load.
    pub bus: BusJson,
    /// Each interface's frames, bits, load, busiest 100 ms and longest burst, in interface
    /// order (one entry, the capture's figures, for a capture of one interface).
    pub by_iface: Vec<IfaceJson>,
    /// Frames per kind name.
    pub by_kind: BTreeMap<&'static str, u64>,
    /// Frames per node (its number as text; `"can1/5"` when the input has several
    /// interfaces), per kind name.
    pub by_node: BTreeMap<String, BTreeMap<&'static str, u64>>,
    /// Frames in all.
    pub frames: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totals() {
        let mut s = Summary::default();
        s.add(Kind::Heartbeat, Some(5));
        s.add(Kind::Heartbeat, Some(5));
        s.add(Kind::Sync, None);
        s.add(Kind::Tpdo, Some(2));
        s.finish();
        assert_eq!(s.frames, 4);
        assert_eq!(s.by_kind[&Kind::Heartbeat], 2);
        let node5 = s.by_node.iter().find(|(k, _)| *k == NodeKey::new(0, 5)).unwrap().1;
        assert_eq!(node5[Kind::Heartbeat.index()], 2);
        assert!(Kind::ALL.is_sorted(), "rows list kinds in the order of by_kind");
        let t = s.to_text();
        assert!(t.contains("  heartbeat    2"), "{t}");
        assert!(t.contains("node 5            2  heartbeat=2"), "{t}");
        assert_eq!(serde_json::to_value(s.to_json()).unwrap()["by_node"]["2"]["tpdo"], 1);
    }

    #[test]
    fn numbers_pad_as_format_pads_them() {
        for n in [0, 7, 42, 123, 9999, u64::MAX] {
            for (w, want) in [
                (3, format!("{n:>3}")),
                (-3, format!("{n:<3}")),
                (10, format!("{n:>10}")),
                (0, n.to_string()),
            ] {
                let mut s = String::new();
                push_num(&mut s, n, w);
                assert_eq!(s, want);
            }
        }
    }

    #[test]
    fn nodes_of_other_interfaces_are_counted_apart() {
        let mut s = Summary::default();
        s.add_on(0, Kind::Heartbeat, Some(5));
        s.add_on(40_000, Kind::Heartbeat, Some(5));
        s.add_on(40_000, Kind::Heartbeat, Some(5));
        s.ifaces = (0..=40_000).map(|i| format!("can{i}")).collect();
        s.finish();
        assert_eq!(s.other_counts.len(), 1, "only the nodes seen are kept");
        let t = s.to_text();
        assert!(t.contains("can0 node 5            1  heartbeat=1"), "{t}");
        assert!(t.contains("can40000 node 5            2  heartbeat=2"), "{t}");
    }
}
