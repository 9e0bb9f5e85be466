//! `--summary`: per-node and per-kind totals.

use crate::decode::Kind;
use serde::Serialize;
use std::collections::BTreeMap;

/// Running totals of frames by kind and by node.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Frames per kind.
    pub by_kind: BTreeMap<Kind, u64>,
    /// Frames per node, split by kind.
    pub by_node: BTreeMap<u8, BTreeMap<Kind, u64>>,
    /// Frames in all.
    pub frames: u64,
    kind_counts: [u64; Kind::ALL.len()],
    node_counts: Vec<[u64; Kind::ALL.len()]>,
}

impl Summary {
    /// Counts one frame (a fixed-size array increment: this is the hot path).
    pub fn add(&mut self, kind: Kind, node: Option<u8>) {
        self.frames += 1;
        let k = kind.index();
        self.kind_counts[k] += 1;
        if let Some(n) = node {
            if self.node_counts.is_empty() {
                self.node_counts = vec![[0; Kind::ALL.len()]; 128];
            }
            self.node_counts[(n & 0x7F) as usize][k] += 1;
        }
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
        for (n, counts) in self.node_counts.iter().enumerate() {
            for (i, k) in Kind::ALL.iter().enumerate() {
                if counts[i] > 0 {
                    self.by_node.entry(n as u8).or_default().insert(*k, counts[i]);
                }
            }
        }
    }

    /// Text report.
    pub fn to_text(&self) -> String {
        let mut s = format!("frames: {}\n", self.frames);
        s.push_str("by kind:\n");
        for (k, n) in &self.by_kind {
            s.push_str(&format!("  {:<12} {n}\n", k.as_str()));
        }
        s.push_str("by node:\n");
        for (node, kinds) in &self.by_node {
            let total: u64 = kinds.values().sum();
            let parts: Vec<String> = kinds.iter().map(|(k, n)| format!("{}={n}", k.as_str())).collect();
            s.push_str(&format!("  node {node:<3} {total:>10}  {}\n", parts.join(" ")));
        }
        s
    }

    /// The JSON report of `--summary --format jsonl`.
    pub fn to_json(&self) -> SummaryJson {
        let named = |kinds: &BTreeMap<Kind, u64>| kinds.iter().map(|(k, n)| (k.as_str(), *n)).collect();
        SummaryJson {
            by_kind: named(&self.by_kind),
            by_node: self
                .by_node
                .iter()
                .map(|(node, kinds)| (node.to_string(), named(kinds)))
                .collect(),
            frames: self.frames,
        }
    }
}

/// The summary as a JSON record (fields in key order). Maps are ordered by their JSON
/// keys, so nodes are in text order (`"10"` before `"2"`).
#[derive(Clone, Debug, Serialize)]
pub struct SummaryJson {
    /// Frames per kind name.
    pub by_kind: BTreeMap<&'static str, u64>,
    /// Frames per node (its number as text), per kind name.
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
        assert_eq!(s.by_node[&5][&Kind::Heartbeat], 2);
        let t = s.to_text();
        assert!(t.contains("  heartbeat    2"), "{t}");
        assert!(t.contains("node 5            2  heartbeat=2"), "{t}");
        assert_eq!(serde_json::to_value(s.to_json()).unwrap()["by_node"]["2"]["tpdo"], 1);
    }
}
