//! Per-node state gathered while frames come in: liveness (NMT state, heartbeat timing,
//! lost/back, boot-ups, from the [`EventTracker`]), the last EMCY, CiA 402 state and mode,
//! frame rate and profile; and the bus events for the message log.

use crate::analysis::{Event, EventTracker, NodeLiveness};
use crate::decode::Decoder;
use crate::decode::cia402::DriveState;
use crate::decode::emcy::Emcy;
use crate::decode::heartbeat::Heartbeat;
use crate::decode::pdo::Pdo;
use crate::sdo::Transaction;
use std::collections::{BTreeMap, VecDeque};

/// Events kept for [`Nodes::take_events`] when nobody takes them (oldest dropped).
const EVENT_BACKLOG: usize = 1000;

/// What is known about one node besides its liveness.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeInfo {
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
pub struct Nodes {
    map: BTreeMap<u8, NodeInfo>,
    tracker: EventTracker,
    events: VecDeque<Event>,
}

impl Nodes {
    /// No node yet; default heartbeat periods come from `decoder`'s dictionaries.
    pub fn new(decoder: &Decoder) -> Nodes {
        Nodes {
            map: BTreeMap::new(),
            tracker: EventTracker::new(|n| decoder.dictionary(n)),
            events: VecDeque::new(),
        }
    }
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
    /// The liveness of one node (None before its first error-control frame).
    pub fn liveness(&self, node: u8) -> Option<&NodeLiveness> {
        self.tracker.node(node)
    }
    /// The capture time the node table is at: the newest frame or tick (ns).
    pub fn now_ns(&self) -> u64 {
        self.tracker.now_ns()
    }

    /// The bus events since the last call, oldest first (at most the newest 1000).
    pub fn take_events(&mut self) -> Vec<Event> {
        self.events.drain(..).collect()
    }

    fn entry(&mut self, node: u8) -> &mut NodeInfo {
        self.map.entry(node).or_default()
    }

    /// Moves the tracker's new events to the backlog.
    fn collect(&mut self) {
        if self.tracker.pending() == 0 {
            return;
        }
        self.events.extend(self.tracker.take_events());
        let excess = self.events.len().saturating_sub(EVENT_BACKLOG);
        self.events.drain(..excess);
    }

    /// Capture time has reached `now_ns` (a frame's time, or the capture clock of a live
    /// source or replay when no frame comes): nodes whose deadline passed are lost.
    pub fn tick(&mut self, now_ns: u64) {
        self.tracker.tick(now_ns);
        self.collect();
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
        if node == 0 {
            return;
        }
        self.entry(node);
        self.tracker.heartbeat(node, ts_ns, h);
        self.collect();
    }

    /// An EMCY of `node`.
    pub fn emcy(&mut self, node: u8, ts_ns: u64, e: &Emcy) {
        self.entry(node).last_emcy = Some((ts_ns, e.code, e.text.clone()));
        self.tracker.emcy(node, ts_ns, e);
        self.collect();
    }

    /// A SocketCAN error frame on `iface` (controller state changes become events).
    pub fn error_frame(&mut self, ts_ns: u64, iface: &str, class: u32, data: &[u8]) {
        self.tracker.error_frame(ts_ns, iface, class, data);
        self.collect();
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

    /// A completed SDO transfer: picks up 0x1017 and aborts (events), the statusword and
    /// the mode.
    pub fn transaction(&mut self, t: &Transaction) {
        self.tracker.transaction(t);
        self.collect();
        if !t.is_ok() || t.data.is_empty() {
            return;
        }
        let mut b = [0u8; 4];
        let k = t.data.len().min(4);
        b[..k].copy_from_slice(&t.data[..k]);
        let v = u32::from_le_bytes(b);
        let n = self.entry(t.node);
        match (t.index, t.sub) {
            (0x6041, 0) => n.drive = Some(DriveState::from_statusword(v as u16)),
            (0x6060 | 0x6061, 0) => n.mode = Some(v as u8 as i8),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::heartbeat::NmtState;
    use crate::od::Dictionary;

    fn hb(b: u8) -> Heartbeat {
        crate::decode::heartbeat::decode(&[b], false).0
    }

    const MS: u64 = 1_000_000;

    #[test]
    fn heartbeats_give_state_period_boot_ups_then_a_loss_found_by_a_tick() {
        let mut n = Nodes::new(&Decoder::new(Dictionary::default(), Vec::new()));
        n.heartbeat(3, 0, &hb(0x00));
        for (i, t) in [100u64, 200, 300, 400, 500].iter().enumerate() {
            n.heartbeat(3, t * MS, &hb(if i < 4 { 0x7F } else { 0x05 }));
        }
        let l = n.liveness(3).unwrap();
        assert_eq!(l.boot_ups, 1);
        assert_eq!(l.state, Some(NmtState::Operational));
        assert_eq!(l.measured_ns(), Some(100 * MS));
        assert!(!l.is_lost());
        let texts: Vec<String> = n.take_events().iter().map(Event::text).collect();
        assert_eq!(
            texts,
            [
                "node 3 boot-up: boot-up, first message of the node",
                "node 3 NMT state: Pre-operational -> Operational"
            ]
        );
        // No frame comes: the live capture clock finds the loss.
        n.tick(650 * MS);
        assert!(n.take_events().is_empty());
        n.tick(651 * MS);
        let l = n.liveness(3).unwrap();
        assert_eq!((l.lost_at_ns, l.missed), (Some(650 * MS), 1));
        assert_eq!(n.now_ns(), 651 * MS);
        let e = n.take_events();
        assert_eq!(e.len(), 1);
        assert!(
            e[0].text()
                .starts_with("node 3 heartbeat lost: no heartbeat for 150.0 ms")
        );
    }

    #[test]
    fn the_event_backlog_is_bounded() {
        let mut n = Nodes::new(&Decoder::new(Dictionary::default(), Vec::new()));
        let e = crate::decode::emcy::decode(&[0x10, 0x23, 0x11, 0, 0, 0, 0, 0], &Dictionary::default()).0;
        for i in 0..(EVENT_BACKLOG as u64 + 5) {
            n.emcy(4, i, &e);
        }
        let kept = n.take_events();
        assert_eq!(kept.len(), EVENT_BACKLOG);
        assert_eq!(kept[0].t_ns, 5);
    }
}
