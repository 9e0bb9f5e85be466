//! Per-node state gathered while frames come in: liveness (NMT state, heartbeat timing,
//! lost/back, boot-ups, from the [`EventTracker`]), the last EMCY, CiA 402 state and mode,
//! frame rate and profile; and the bus events for the message log.
//!
//! A node is shown only once the bus gave CANopen evidence of it (see [`Evidence`]):
//! frames of a node-ID without it (random or foreign traffic) are kept aside and counted as
//! "other", their events held back until the node is confirmed.

use crate::analysis::{Event, EventTracker, NodeLiveness};
use crate::decode::Decoder;
use crate::decode::cia402::DriveState;
use crate::decode::emcy::Emcy;
use crate::decode::heartbeat::{Heartbeat, NmtState};
use crate::decode::pdo::Pdo;
use crate::frame::NodeKey;
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

/// Events held per unconfirmed node (oldest dropped).
const HELD_EVENTS: usize = 16;

/// What the bus said so far about a node-ID not shown yet.
///
/// The node is confirmed by one SDO transfer that completed without a problem (its
/// initiate request and the matching response seen), or by two well-formed error-control
/// frames (boot-up `00`, or one byte with a known NMT state `04`, `05`, `7F`, the toggle
/// bit allowed) outnumbering the malformed ones at 0x700+node. EMCY, PDOs, aborted or
/// unmatched SDO frames and guarding requests never create a node on their own: random
/// traffic looks like them too often.
#[derive(Clone, Debug, Default)]
struct Evidence {
    info: NodeInfo,
    /// Well-formed and malformed error-control frames.
    ec_ok: u32,
    ec_bad: u32,
    /// Clean SDO transfers.
    sdo_ok: u32,
    /// Events of the node, released when it is confirmed.
    held: VecDeque<Event>,
}

impl Evidence {
    fn confirmed(&self) -> bool {
        self.sdo_ok > 0 || (self.ec_ok >= 2 && self.ec_ok > self.ec_bad)
    }
}

/// True for an error-control frame a CANopen node sends: a boot-up or a known NMT state.
fn well_formed(h: &Heartbeat) -> bool {
    !h.request && matches!(h.state, Some(s) if !matches!(s, NmtState::Unknown(_)))
}

/// All nodes seen, by interface and node-ID ([`NodeKey`]).
pub struct Nodes {
    map: BTreeMap<NodeKey, NodeInfo>,
    /// Node-IDs with frames but no CANopen evidence yet.
    candidates: BTreeMap<NodeKey, Evidence>,
    tracker: EventTracker,
    events: VecDeque<Event>,
}

impl Nodes {
    /// No node yet; default heartbeat periods come from `decoder`'s dictionaries.
    pub fn new(decoder: &Decoder) -> Nodes {
        Nodes {
            map: BTreeMap::new(),
            candidates: BTreeMap::new(),
            tracker: EventTracker::new(|n| decoder.dictionary(n)),
            events: VecDeque::new(),
        }
    }
    /// The nodes in interface, then node-ID order.
    pub fn iter(&self) -> impl Iterator<Item = (&NodeKey, &NodeInfo)> {
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
    /// One node, also one without CANopen evidence yet (its drive state still counts for
    /// the stop-all and quit checks).
    pub fn get(&self, node: NodeKey) -> Option<&NodeInfo> {
        self.map
            .get(&node)
            .or_else(|| self.candidates.get(&node).map(|c| &c.info))
    }
    /// A node by node-ID alone, on the first interface that has it: for what addresses the
    /// bus of a live session (one interface), e.g. the drive state stop-all and quit check.
    pub fn by_id(&self, node: u8) -> Option<&NodeInfo> {
        let first = self
            .map
            .keys()
            .chain(self.candidates.keys())
            .filter(|k| k.node == node)
            .min()?;
        self.get(*first)
    }
    /// Frames of node-IDs without CANopen evidence: "other" traffic, not nodes.
    pub fn other_frames(&self) -> u64 {
        self.candidates.values().map(|c| c.info.frames).sum()
    }
    /// The liveness of one node (None before its first error-control frame).
    pub fn liveness(&self, node: NodeKey) -> Option<&NodeLiveness> {
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

    fn entry(&mut self, node: NodeKey) -> &mut NodeInfo {
        match self.map.get_mut(&node) {
            Some(n) => n,
            None => &mut self.candidates.entry(node).or_default().info,
        }
    }

    /// Adds evidence about an unconfirmed `node`; shows it once it is enough.
    fn evidence(&mut self, node: NodeKey, add: impl FnOnce(&mut Evidence)) {
        if self.map.contains_key(&node) {
            return;
        }
        let c = self.candidates.entry(node).or_default();
        add(c);
        if c.confirmed()
            && let Some(c) = self.candidates.remove(&node)
        {
            self.map.insert(node, c.info);
            // Held events go where their time puts them among those not taken yet.
            self.backlog(c.held);
            self.events.make_contiguous().sort_by_key(|e| e.t_ns);
        }
    }

    fn backlog(&mut self, events: impl IntoIterator<Item = Event>) {
        self.events.extend(events);
        let excess = self.events.len().saturating_sub(EVENT_BACKLOG);
        self.events.drain(..excess);
    }

    /// Moves the tracker's new events to the backlog, or holds them for their node when
    /// it is not confirmed yet.
    fn collect(&mut self) {
        if self.tracker.pending() == 0 {
            return;
        }
        for e in self.tracker.take_events() {
            match e.key().and_then(|n| self.candidates.get_mut(&n)) {
                Some(c) => {
                    if c.held.len() == HELD_EVENTS {
                        c.held.pop_front();
                    }
                    c.held.push_back(e);
                }
                None => self.backlog([e]),
            }
        }
    }

    /// Capture time has reached `now_ns` (a frame's time, or the capture clock of a live
    /// source or replay when no frame comes): nodes whose deadline passed are lost.
    pub fn tick(&mut self, now_ns: u64) {
        self.tracker.tick(now_ns);
        self.collect();
    }

    /// Counts a frame of `node`.
    pub fn frame(&mut self, node: NodeKey, ts_ns: u64) {
        if node.node == 0 {
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
    pub fn heartbeat(&mut self, node: NodeKey, ts_ns: u64, h: &Heartbeat) {
        if node.node == 0 {
            return;
        }
        self.entry(node);
        let ok = well_formed(h);
        if !h.request {
            self.evidence(node, |c| if ok { c.ec_ok += 1 } else { c.ec_bad += 1 });
        }
        // A malformed frame of a node not shown says nothing about its liveness.
        if ok || h.request || self.map.contains_key(&node) {
            self.tracker.heartbeat(node, ts_ns, h);
        }
        self.collect();
    }

    /// An EMCY of `node`.
    pub fn emcy(&mut self, node: NodeKey, ts_ns: u64, e: &Emcy) {
        self.entry(node).last_emcy = Some((ts_ns, e.code, e.text.clone()));
        self.tracker.emcy(node, ts_ns, e);
        self.collect();
    }

    /// A SocketCAN error frame on `iface` (controller state changes become events).
    pub fn error_frame(&mut self, ts_ns: u64, iface: &str, class: u32, data: &[u8]) {
        self.tracker.error_frame(ts_ns, iface, class, data);
        self.collect();
    }

    /// A PDO of `node`: picks up the statusword, and records the profile and mode in force
    /// as [`Nodes::profile`] does (one node lookup for both).
    pub fn pdo(&mut self, node: NodeKey, p: &Pdo, profile: &str, mode: Option<i8>) {
        let n = self.entry(node);
        for s in &p.signals {
            if (s.index, s.sub) == (0x6041, 0)
                && let Some(sw) = s.value.as_i64()
            {
                n.drive = Some(DriveState::from_statusword(sw as u16));
            }
        }
        if node.node != 0 && n.profile != profile {
            n.profile = profile.to_string();
        }
        n.mode = mode.or(n.mode);
    }

    /// Records the profile and mode in force for `node`.
    pub fn profile(&mut self, node: NodeKey, name: &str, mode: Option<i8>) {
        if node.node == 0 {
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
        if t.is_ok() && t.problems.is_empty() {
            self.evidence(t.key(), |c| c.sdo_ok += 1);
        }
        self.tracker.transaction(t);
        self.collect();
        if !t.is_ok() || t.data.is_empty() {
            return;
        }
        let mut b = [0u8; 4];
        let k = t.data.len().min(4);
        b[..k].copy_from_slice(&t.data[..k]);
        let v = u32::from_le_bytes(b);
        let n = self.entry(t.key());
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
    use crate::od::Dictionary;

    fn hb(b: u8) -> Heartbeat {
        crate::decode::heartbeat::decode(&[b], false).0
    }

    const MS: u64 = 1_000_000;

    fn k(node: u8) -> NodeKey {
        NodeKey::new(0, node)
    }

    #[test]
    fn heartbeats_give_state_period_boot_ups_then_a_loss_found_by_a_tick() {
        let mut n = Nodes::new(&Decoder::new(Dictionary::default(), Vec::new()));
        n.heartbeat(k(3), 0, &hb(0x00));
        for (i, t) in [100u64, 200, 300, 400, 500].iter().enumerate() {
            n.heartbeat(k(3), t * MS, &hb(if i < 4 { 0x7F } else { 0x05 }));
        }
        let l = n.liveness(k(3)).unwrap();
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
        let l = n.liveness(k(3)).unwrap();
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
        n.heartbeat(k(4), 0, &hb(0x00));
        n.heartbeat(k(4), 0, &hb(0x7F));
        n.take_events();
        for i in 0..(EVENT_BACKLOG as u64 + 5) {
            n.emcy(k(4), i, &e);
        }
        let kept = n.take_events();
        assert_eq!(kept.len(), EVENT_BACKLOG);
        assert_eq!(kept[0].t_ns, 5);
    }

    /// A deterministic xorshift: the crate has no rand dependency.
    struct XorShift(u64);

    impl XorShift {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
    }

    fn trace_of(frames: impl IntoIterator<Item = crate::frame::Frame>) -> crate::analysis::trace::Trace {
        let mut t = crate::analysis::trace::Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        for f in frames {
            t.push(&f);
        }
        t
    }

    /// `cangen`-like traffic: random 11-bit IDs, lengths 0..=8, random bytes, 1 ms apart.
    fn random_frames(seed: u64, count: u64) -> Vec<crate::frame::Frame> {
        let mut r = XorShift(seed);
        (0..count)
            .map(|i| {
                let id = (r.next() % 0x800) as u32;
                let len = (r.next() % 9) as usize;
                let data: Vec<u8> = (0..len).map(|_| r.next() as u8).collect();
                let mut f = crate::frame::Frame::classic(id, &data);
                f.ts_ns = i * MS;
                f
            })
            .collect()
    }

    #[test]
    fn random_traffic_creates_no_node_and_is_counted_as_other() {
        let frames = random_frames(0x9E37_79B9_7F4A_7C15, 200_000);
        let t = trace_of(frames.clone());
        let phantoms: Vec<u8> = t.nodes.iter().map(|(n, _)| n.node).collect();
        assert_eq!(phantoms, Vec::<u8>::new());
        // Every frame of a node-ID range (all but NMT, SYNC/EMCY 0x080, TIME, LSS and the
        // IDs outside the predefined set) is counted as other.
        assert!(t.nodes.other_frames() > 140_000, "{}", t.nodes.other_frames());
        let mut n = t.nodes;
        assert!(n.take_events().iter().all(|e| e.node.is_none()));
    }

    #[test]
    fn real_heartbeats_in_random_traffic_still_make_nodes() {
        let mut frames = random_frames(42, 20_000);
        for (i, f) in frames.iter_mut().enumerate().filter(|(i, _)| i % 100 == 0) {
            // Node 5 boots, then beats every 100 ms; node 7 only beats.
            *f = match i {
                0 => crate::frame::Frame::classic(0x705, &[0x00]),
                _ if i % 200 == 0 => crate::frame::Frame::classic(0x705, &[0x05]),
                _ => crate::frame::Frame::classic(0x707, &[0x7F]),
            };
            f.ts_ns = i as u64 * MS;
        }
        let t = trace_of(frames);
        let nodes: Vec<u8> = t.nodes.iter().map(|(n, _)| n.node).collect();
        assert_eq!(nodes, [5, 7]);
        assert_eq!(t.nodes.liveness(k(5)).unwrap().state, Some(NmtState::Operational));
        assert_eq!(t.nodes.liveness(k(7)).unwrap().state, Some(NmtState::PreOperational));
        let mut n = t.nodes;
        let texts: Vec<String> = n.take_events().iter().map(Event::text).collect();
        assert_eq!(texts[0], "node 5 boot-up: boot-up, first message of the node");
    }

    #[test]
    fn one_clean_sdo_transfer_shows_a_node_a_lone_response_does_not() {
        let sdo = |ms: u64, id: u32, data: [u8; 8]| {
            let mut f = crate::frame::Frame::classic(id, &data);
            f.ts_ns = ms * MS;
            f
        };
        let t = trace_of([
            // node 3: read 0x1000 answered.
            sdo(1, 0x603, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]),
            sdo(2, 0x583, [0x43, 0x00, 0x10, 0, 0x92, 0x01, 0x02, 0]),
            // node 4: an answer whose request was not seen; node 6: a response for another
            // object than the request's.
            sdo(3, 0x584, [0x43, 0x00, 0x10, 0, 0x92, 0x01, 0x02, 0]),
            sdo(4, 0x606, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]),
            sdo(5, 0x586, [0x43, 0x18, 0x10, 1, 0x92, 0x01, 0x02, 0]),
        ]);
        let nodes: Vec<u8> = t.nodes.iter().map(|(n, _)| n.node).collect();
        assert_eq!(nodes, [3]);
        assert_eq!(t.nodes.other_frames(), 3);
    }

    #[test]
    fn malformed_heartbeats_outnumbering_good_ones_make_no_node() {
        let mut n = Nodes::new(&Decoder::new(Dictionary::default(), Vec::new()));
        for b in [0x09, 0x33, 0x05, 0x05] {
            n.heartbeat(k(9), 0, &hb(b));
        }
        assert!(n.is_empty());
        n.heartbeat(k(9), 0, &hb(0x85));
        assert_eq!(n.len(), 1);
    }
}
