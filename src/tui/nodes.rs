//! Per-node state gathered while frames come in: NMT state, heartbeat timing, boot-ups,
//! the last EMCY, CiA 402 state and mode, frame rate and profile.

use crate::decode::cia402::DriveState;
use crate::decode::emcy::Emcy;
use crate::decode::heartbeat::{Heartbeat, NmtState};
use crate::decode::pdo::Pdo;
use crate::decode::sdo::Transaction;
use std::collections::BTreeMap;

/// What is known about one node.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeInfo {
    /// Last NMT state from a heartbeat or guarding response.
    pub nmt: Option<NmtState>,
    /// Time of the last heartbeat (ns).
    pub last_heartbeat_ns: Option<u64>,
    /// Last measured heartbeat period (ns).
    pub period_ns: Option<u64>,
    /// Producer heartbeat time 0x1017 seen in SDO traffic (ms).
    pub configured_ms: Option<u16>,
    /// Heartbeats that came later than 1.5 periods (configured, else measured) after the one before.
    pub missed: u64,
    /// Boot-up messages seen.
    pub boot_ups: u64,
    /// Last EMCY: time, code and text.
    pub last_emcy: Option<(u64, u16, String)>,
    /// CiA 402 state from the last statusword seen.
    pub drive: Option<DriveState>,
    /// Mode of operation in force.
    pub mode: Option<i8>,
    /// Frames from or to the node.
    pub frames: u64,
    /// First and last frame time (ns).
    pub first_ns: u64,
    /// Time of the last frame (ns).
    pub last_ns: u64,
    /// Profile (dictionary) name.
    pub profile: String,
}

impl NodeInfo {
    /// Frames per second over the node's active span.
    pub fn rate(&self) -> f64 {
        let span = self.last_ns.saturating_sub(self.first_ns) as f64 / 1e9;
        if span > 0.0 { self.frames as f64 / span } else { 0.0 }
    }
}

/// All nodes seen, by node-ID.
#[derive(Default)]
pub struct Nodes {
    map: BTreeMap<u8, NodeInfo>,
}

impl Nodes {
    /// The nodes in node-ID order.
    pub fn iter(&self) -> impl Iterator<Item = (&u8, &NodeInfo)> {
        self.map.iter()
    }
    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.map.len()
    }
    /// True when no node was seen.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }
    /// One node.
    pub fn get(&self, node: u8) -> Option<&NodeInfo> {
        self.map.get(&node)
    }

    fn entry(&mut self, node: u8) -> &mut NodeInfo {
        self.map.entry(node).or_default()
    }

    /// Counts a frame of `node`.
    pub fn frame(&mut self, node: u8, ts_ns: u64) {
        if node == 0 {
            return;
        }
        let n = self.entry(node);
        if n.frames == 0 {
            n.first_ns = ts_ns;
        }
        n.frames += 1;
        n.last_ns = ts_ns;
    }

    /// A heartbeat, boot-up or guarding frame of `node`.
    pub fn heartbeat(&mut self, node: u8, ts_ns: u64, h: &Heartbeat) {
        let Some(state) = h.state else { return };
        let n = self.entry(node);
        if state == NmtState::BootUp {
            n.boot_ups += 1;
            n.nmt = Some(NmtState::PreOperational);
            n.last_heartbeat_ns = None;
            return;
        }
        n.nmt = Some(state);
        if let Some(prev) = n.last_heartbeat_ns {
            let gap = ts_ns.saturating_sub(prev);
            let expected = n
                .configured_ms
                .filter(|m| *m > 0)
                .map(|m| m as u64 * 1_000_000)
                .or(n.period_ns);
            if expected.is_some_and(|e| gap * 2 > e * 3) {
                n.missed += 1;
            }
            n.period_ns = Some(gap);
        }
        n.last_heartbeat_ns = Some(ts_ns);
    }

    /// An EMCY of `node`.
    pub fn emcy(&mut self, node: u8, ts_ns: u64, e: &Emcy) {
        self.entry(node).last_emcy = Some((ts_ns, e.code, e.text.clone()));
    }

    /// A PDO of `node`: picks up the statusword.
    pub fn pdo(&mut self, node: u8, p: &Pdo, mode: Option<i8>) {
        let n = self.entry(node);
        for s in &p.signals {
            if (s.index, s.sub) == (0x6041, 0)
                && let Some(sw) = s.value.as_i64()
            {
                n.drive = Some(DriveState::from_statusword(sw as u16));
            }
        }
        n.mode = mode.or(n.mode);
    }

    /// Records the profile and mode in force for `node`.
    pub fn profile(&mut self, node: u8, name: &str, mode: Option<i8>) {
        if node == 0 {
            return;
        }
        let n = self.entry(node);
        if n.profile != name {
            n.profile = name.to_string();
        }
        n.mode = mode.or(n.mode);
    }

    /// A completed SDO transfer: picks up 0x1017, the statusword and the mode.
    pub fn transaction(&mut self, t: &Transaction) {
        if !t.is_ok() || t.data.is_empty() {
            return;
        }
        let mut b = [0u8; 4];
        let k = t.data.len().min(4);
        b[..k].copy_from_slice(&t.data[..k]);
        let v = u32::from_le_bytes(b);
        let n = self.entry(t.node);
        match (t.index, t.sub) {
            (0x1017, 0) => n.configured_ms = Some(v as u16),
            (0x6041, 0) => n.drive = Some(DriveState::from_statusword(v as u16)),
            (0x6060 | 0x6061, 0) => n.mode = Some(v as u8 as i8),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hb(b: u8) -> Heartbeat {
        crate::decode::heartbeat::decode(&[b], false).0
    }

    #[test]
    fn heartbeats_give_state_period_misses_and_boot_ups() {
        let mut n = Nodes::default();
        n.heartbeat(3, 0, &hb(0x00));
        for (i, t) in [0u64, 100, 200, 400, 500].iter().enumerate() {
            n.heartbeat(3, 1_000_000_000 + t * 1_000_000, &hb(if i < 4 { 0x7F } else { 0x05 }));
        }
        let info = n.get(3).unwrap();
        assert_eq!(info.boot_ups, 1);
        assert_eq!(info.nmt, Some(NmtState::Operational));
        assert_eq!(info.period_ns, Some(100_000_000));
        assert_eq!(info.missed, 1);
    }
}
