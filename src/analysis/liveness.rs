//! The event tracker: a heartbeat consumer per node plus the other bus events.
//!
//! Each node's expected heartbeat period comes from 0x1017 seen on the bus (an SDO write
//! or read), else from the 0x1017 default of its dictionary (EDS/DCF or profile), else
//! from the median of its recent heartbeat intervals. A node is *lost* once time passes
//! 1.5 periods after its last heartbeat, *back* when a heartbeat returns, and a boot-up
//! says it (re)started. A guarded node (RTR requests on 0x700 + node) is lost when a
//! request is still unanswered as the next one goes out.
//!
//! There is no clock inside: time is the timestamp of each frame, plus [`EventTracker::tick`]
//! for a live bus where no frame may arrive. A loss is dated at the deadline that passed,
//! so the same frames give the same events whether they come from a log or live.

use super::events::{Event, PeriodSource, What};
use crate::decode::emcy::Emcy;
use crate::decode::error_frame;
use crate::decode::heartbeat::{Heartbeat, NmtState};
use crate::decode::{Body, Decoded};
use crate::frame::{Frame, NodeKey};
use crate::od::Dictionary;
use crate::sdo::{Outcome, Transaction};
use std::collections::BTreeMap;

/// Heartbeat intervals kept per node for the measured period.
const INTERVALS: usize = 8;
/// Intervals needed before a measured period arms the deadline.
const MIN_INTERVALS: usize = 2;

/// What the tracker knows about one node's error control.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeLiveness {
    /// Last NMT state from a heartbeat or guarding response (Pre-operational after a boot-up).
    pub state: Option<NmtState>,
    /// Time of the last heartbeat, guarding response or boot-up (ns).
    pub last_heartbeat_ns: Option<u64>,
    /// 0x1017 seen on the bus since the last boot-up (ms, 0 = heartbeat off).
    pub configured_ms: Option<u16>,
    /// 0x1017 default of the node's dictionary (ms), when it has a non-zero one.
    pub default_ms: Option<u16>,
    /// When the node was found lost (the deadline that passed); None while alive.
    pub lost_at_ns: Option<u64>,
    /// Deadlines missed plus guarding requests left unanswered.
    pub missed: u64,
    /// Boot-up messages seen.
    pub boot_ups: u64,
    /// A guarding request is waiting for its response (time of the request).
    pub guard_request_ns: Option<u64>,
    /// Guarding requests were seen for the node: guarding, not heartbeat timing, decides.
    pub guarded: bool,
    intervals: [u64; INTERVALS],
    n_intervals: usize,
    next_interval: usize,
}

impl NodeLiveness {
    /// True while the node is lost.
    pub fn is_lost(&self) -> bool {
        self.lost_at_ns.is_some()
    }

    /// The median of the recent heartbeat intervals (ns); the upper median for an even
    /// count, so one early heartbeat does not shorten it.
    pub fn measured_ns(&self) -> Option<u64> {
        if self.n_intervals == 0 {
            return None;
        }
        let mut v = self.intervals[..self.n_intervals].to_vec();
        v.sort_unstable();
        Some(v[v.len() / 2])
    }

    /// The period the node's heartbeats are expected at (ns) and where it comes from;
    /// None when unknown or when 0x1017 = 0 switched the heartbeat off.
    pub fn expected(&self) -> Option<(u64, PeriodSource)> {
        match self.configured_ms {
            Some(0) => None,
            Some(ms) => Some((u64::from(ms) * 1_000_000, PeriodSource::Sdo)),
            None => match self.default_ms {
                Some(ms) => Some((u64::from(ms) * 1_000_000, PeriodSource::Dictionary)),
                None if self.n_intervals >= MIN_INTERVALS => self.measured_ns().map(|p| (p, PeriodSource::Measured)),
                None => None,
            },
        }
    }

    /// The time after which the node counts as lost, when heartbeat timing applies.
    pub fn deadline(&self) -> Option<u64> {
        if self.guarded || self.is_lost() {
            return None;
        }
        let (p, _) = self.expected()?;
        Some(self.last_heartbeat_ns?.saturating_add(p).saturating_add(p / 2))
    }

    fn add_interval(&mut self, ns: u64) {
        self.intervals[self.next_interval] = ns;
        self.next_interval = (self.next_interval + 1) % INTERVALS;
        self.n_intervals = (self.n_intervals + 1).min(INTERVALS);
    }

    fn forget_intervals(&mut self) {
        self.n_intervals = 0;
        self.next_interval = 0;
    }
}

/// CAN controller states, from SocketCAN error frames.
fn controller_state(class: u32, data: &[u8]) -> Option<&'static str> {
    let ctrl = data.get(1).copied().unwrap_or(0);
    if class & 0x040 != 0 {
        Some("bus_off")
    } else if class & 0x004 != 0 && ctrl & 0x30 != 0 {
        Some("error_passive")
    } else if class & 0x004 != 0 && ctrl & 0x0C != 0 {
        Some("error_warning")
    } else if class & 0x100 != 0 || (class & 0x004 != 0 && ctrl & 0x40 != 0) {
        Some("error_active")
    } else {
        None
    }
}

/// Turns decoded frames and SDO transactions into [`Event`]s and per-node liveness.
#[derive(Clone, Debug)]
pub struct EventTracker {
    nodes: BTreeMap<NodeKey, NodeLiveness>,
    defaults: Vec<Option<u16>>,
    /// Controller state per interface name.
    buses: Vec<(String, &'static str)>,
    events: Vec<Event>,
    now_ns: u64,
    /// No deadline is earlier than this (it may be stale-early, never late).
    next_deadline: Option<u64>,
}

impl EventTracker {
    /// A tracker whose nodes take their default heartbeat period from `dict(node)`'s
    /// 0x1017 default value (ignored when 0 or absent).
    pub fn new<'a>(dict: impl Fn(u8) -> &'a Dictionary) -> EventTracker {
        let defaults = (0..128u8)
            .map(|n| {
                let d = dict(n).object(0x1017, 0)?.default.as_ref()?.as_i64()?;
                u16::try_from(d).ok().filter(|ms| *ms > 0)
            })
            .collect();
        EventTracker {
            nodes: BTreeMap::new(),
            defaults,
            buses: Vec::new(),
            events: Vec::new(),
            now_ns: 0,
            next_deadline: None,
        }
    }

    /// The newest time seen (frame timestamps and ticks), ns.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// What is known about `node`.
    pub fn node(&self, node: NodeKey) -> Option<&NodeLiveness> {
        self.nodes.get(&node)
    }

    /// The events since the last call, in time order.
    pub fn take_events(&mut self) -> Vec<Event> {
        std::mem::take(&mut self.events)
    }

    /// Events waiting to be taken.
    pub fn pending(&self) -> usize {
        self.events.len()
    }

    fn entry(&mut self, node: NodeKey) -> &mut NodeLiveness {
        let default_ms = self.defaults.get(node.node as usize).copied().flatten();
        self.nodes.entry(node).or_insert_with(|| NodeLiveness {
            default_ms,
            ..NodeLiveness::default()
        })
    }

    fn push(&mut self, t_ns: u64, node: Option<NodeKey>, what: What) {
        let (node, iface) = match node {
            Some(k) => (Some(k.node), k.iface),
            None => (None, 0),
        };
        self.events.push(Event {
            t_ns,
            node,
            iface,
            what,
        });
    }

    /// Takes note of `node`'s deadline after a change.
    fn rearm(&mut self, node: NodeKey) {
        if let Some(d) = self.nodes.get(&node).and_then(NodeLiveness::deadline) {
            self.next_deadline = Some(self.next_deadline.map_or(d, |n| n.min(d)));
        }
    }

    /// Time has reached `now_ns` (a frame's timestamp, or the capture clock when no frame
    /// comes): every node whose deadline is before it is lost, dated at its deadline.
    #[inline]
    pub fn tick(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        if self.next_deadline.is_none_or(|d| now_ns <= d) {
            return;
        }
        self.lose_overdue(now_ns);
    }

    /// Every node whose deadline is before `now_ns` is lost (see [`EventTracker::tick`]).
    fn lose_overdue(&mut self, now_ns: u64) {
        let mut due: Vec<(u64, NodeKey)> = self
            .nodes
            .iter()
            .filter_map(|(n, l)| l.deadline().filter(|d| *d < now_ns).map(|d| (d, *n)))
            .collect();
        due.sort_unstable();
        for (deadline, node) in due {
            let l = self.entry(node);
            let Some((period, source)) = l.expected() else { continue };
            let last = l.last_heartbeat_ns.unwrap_or(deadline);
            l.lost_at_ns = Some(deadline);
            l.missed += 1;
            let missed = l.missed;
            self.push(
                deadline,
                Some(node),
                What::HeartbeatLost {
                    period_ms: period as f64 / 1e6,
                    period_source: source,
                    silent_ms: deadline.saturating_sub(last) as f64 / 1e6,
                    guarding: false,
                    missed,
                },
            );
        }
        self.next_deadline = self.nodes.values().filter_map(NodeLiveness::deadline).min();
    }

    /// One decoded frame (called in frame order): advances time to its timestamp, then
    /// takes heartbeats, boot-ups, guarding, EMCY and error frames. `iface` names the
    /// frame's interface.
    pub fn frame(&mut self, frame: &Frame, iface: &str, decoded: &Decoded) {
        self.tick(frame.ts_ns);
        let node = NodeKey::of(frame, decoded.node.unwrap_or(0));
        match &decoded.body {
            Body::Heartbeat(h) => self.heartbeat(node, frame.ts_ns, h),
            Body::Emcy(e) => self.emcy(node, frame.ts_ns, e),
            Body::ErrorFrame { class } => self.error_frame(frame.ts_ns, iface, *class, frame.payload()),
            _ => {}
        }
    }

    /// A heartbeat, boot-up, guarding request or guarding response of `node` at `ts_ns`.
    pub fn heartbeat(&mut self, node: NodeKey, ts_ns: u64, h: &Heartbeat) {
        if node.node == 0 {
            return;
        }
        self.tick(ts_ns);
        if h.request {
            self.guard_request(node, ts_ns);
            return;
        }
        let Some(state) = h.state else { return };
        if state == NmtState::BootUp {
            self.boot_up(node, ts_ns);
            return;
        }
        let l = self.entry(node);
        l.guard_request_ns = None;
        let prev_state = l.state;
        let gap = l.last_heartbeat_ns.map(|t| ts_ns.saturating_sub(t));
        let back = l.lost_at_ns.take().is_some();
        // Equal (or out of order) timestamps say nothing about the period.
        match gap {
            Some(g) if !back && g > 0 => l.add_interval(g),
            _ => {}
        }
        l.last_heartbeat_ns = Some(ts_ns);
        l.state = Some(state);
        if back {
            let silent_ms = gap.unwrap_or(0) as f64 / 1e6;
            self.push(ts_ns, Some(node), What::HeartbeatBack { silent_ms });
        }
        if prev_state != Some(state) {
            self.push(
                ts_ns,
                Some(node),
                What::State {
                    from: prev_state,
                    to: state,
                },
            );
        }
        self.rearm(node);
    }

    fn boot_up(&mut self, node: NodeKey, ts_ns: u64) {
        let l = self.entry(node);
        let rebooted = l.boot_ups > 0 || l.state.is_some();
        let was_lost = l.lost_at_ns.take().is_some();
        l.boot_ups += 1;
        let boot_ups = l.boot_ups;
        // The node restarted with its stored parameters: what the bus said about 0x1017
        // and the measured intervals no longer hold.
        l.configured_ms = None;
        l.forget_intervals();
        l.guard_request_ns = None;
        l.state = Some(NmtState::PreOperational);
        l.last_heartbeat_ns = Some(ts_ns);
        self.push(
            ts_ns,
            Some(node),
            What::BootUp {
                rebooted,
                boot_ups,
                was_lost,
            },
        );
        self.rearm(node);
    }

    fn guard_request(&mut self, node: NodeKey, ts_ns: u64) {
        let l = self.entry(node);
        l.guarded = true;
        let unanswered = l.guard_request_ns.replace(ts_ns);
        let Some(asked) = unanswered else { return };
        l.missed += 1;
        if l.lost_at_ns.is_some() {
            return;
        }
        l.lost_at_ns = Some(ts_ns);
        let missed = l.missed;
        let silent = ts_ns.saturating_sub(l.last_heartbeat_ns.unwrap_or(asked));
        let period = ts_ns.saturating_sub(asked);
        self.push(
            ts_ns,
            Some(node),
            What::HeartbeatLost {
                period_ms: period as f64 / 1e6,
                period_source: PeriodSource::Measured,
                silent_ms: silent as f64 / 1e6,
                guarding: true,
                missed,
            },
        );
    }

    /// An EMCY of `node`.
    pub fn emcy(&mut self, node: NodeKey, ts_ns: u64, e: &Emcy) {
        self.tick(ts_ns);
        self.push(
            ts_ns,
            Some(node),
            What::Emcy {
                code: e.code,
                text: e.text.clone(),
                register: e.register,
            },
        );
    }

    /// A SocketCAN error frame on `iface`: an event when the controller state changes
    /// (error active is assumed before the first error frame).
    pub fn error_frame(&mut self, ts_ns: u64, iface: &str, class: u32, data: &[u8]) {
        self.tick(ts_ns);
        let Some(to) = controller_state(class, data) else {
            return;
        };
        let from = match self.buses.iter_mut().find(|(name, _)| name == iface) {
            Some((_, s)) => std::mem::replace(s, to),
            None => {
                self.buses.push((iface.to_string(), to));
                "error_active"
            }
        };
        if from != to {
            let detail = error_frame::describe(class, data).join("; ");
            self.push(
                ts_ns,
                None,
                What::BusState {
                    iface: iface.to_string(),
                    from,
                    to,
                    detail,
                },
            );
        }
    }

    /// A completed SDO transfer: aborts become events, 0x1017 sets the node's period.
    pub fn transaction(&mut self, t: &Transaction) {
        if let Outcome::Aborted { code, text, by } = &t.outcome {
            self.push(
                t.end_ns,
                Some(t.key()),
                What::SdoAbort {
                    direction: t.direction.as_str(),
                    index: t.index,
                    sub: t.sub,
                    code: *code,
                    text,
                    by: by.as_str(),
                },
            );
            return;
        }
        if (t.index, t.sub) != (0x1017, 0) || !t.is_ok() || t.data.is_empty() {
            return;
        }
        let ms = u16::from_le_bytes([t.data[0], t.data.get(1).copied().unwrap_or(0)]);
        let l = self.entry(t.key());
        if l.configured_ms.replace(ms) != Some(ms) {
            self.push(t.end_ns, Some(t.key()), What::HeartbeatPeriod { period_ms: ms });
        }
        self.rearm(t.key());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;

    const MS: u64 = 1_000_000;

    fn frame(ms: u64, id: u32, data: &str) -> Frame {
        let mut f = if data == "R" {
            let mut f = Frame::classic(id, &[]);
            f.flags.set(crate::frame::Flags::RTR, true);
            f
        } else {
            let bytes: Vec<u8> = (0..data.len() / 2)
                .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).unwrap())
                .collect();
            Frame::classic(id, &bytes)
        };
        f.ts_ns = ms * MS;
        f
    }

    /// Runs `frames` (ms, COB-ID, hex data; `R` = remote request) through a decoder whose
    /// node 7 uses `dict`, and a tracker, then ticks to `end_ms`; returns the events as
    /// `t_ms node event`.
    fn run(frames: &[(u64, u32, &str)], end_ms: Option<u64>, dict: Option<Dictionary>) -> Vec<String> {
        let mut dec = Decoder::new(Dictionary::default(), vec![(7, dict.unwrap_or_default())]);
        let mut tr = EventTracker::new(|n| dec.dictionary(n));
        for (ms, id, data) in frames {
            let f = frame(*ms, *id, data);
            let d = dec.decode(&f);
            tr.frame(&f, "can0", &d);
            for t in dec.take_transactions() {
                tr.transaction(&t);
            }
        }
        if let Some(e) = end_ms {
            tr.tick(e * MS);
        }
        tr.take_events()
            .iter()
            .map(|e| {
                let node = e.node.map_or("-".into(), |n| n.to_string());
                format!("{} {node} {}", e.t_ns / MS, e.what.name())
            })
            .collect()
    }

    fn heartbeats(
        node: u32,
        from_ms: u64,
        to_ms: u64,
        every: u64,
        state: &'static str,
    ) -> Vec<(u64, u32, &'static str)> {
        (from_ms..=to_ms)
            .step_by(every as usize)
            .map(|t| (t, 0x700 + node, state))
            .collect()
    }

    #[test]
    fn a_silent_node_is_lost_at_one_and_a_half_measured_periods() {
        let mut f = heartbeats(5, 0, 1000, 100, "05");
        f.push((5000, 0x080, ""));
        assert_eq!(run(&f, None, None), ["0 5 state", "1150 5 heartbeat_lost"]);
    }

    #[test]
    fn no_loss_is_invented_after_the_log_ends() {
        let f = heartbeats(5, 0, 1000, 100, "05");
        assert_eq!(run(&f, None, None), ["0 5 state"]);
        let mut f = heartbeats(5, 0, 1000, 100, "05");
        f.push((1140, 0x080, ""));
        assert_eq!(run(&f, None, None), ["0 5 state"]);
        // A live tick past the deadline finds it.
        assert_eq!(run(&f, Some(1151), None), ["0 5 state", "1150 5 heartbeat_lost"]);
    }

    #[test]
    fn dies_reboots_and_comes_back() {
        let mut f = heartbeats(5, 0, 500, 100, "05");
        f.push((2000, 0x705, "00"));
        f.extend(heartbeats(5, 2100, 2300, 100, "7F"));
        f.extend(heartbeats(5, 2400, 2500, 100, "05"));
        assert_eq!(
            run(&f, None, None),
            ["0 5 state", "650 5 heartbeat_lost", "2000 5 boot_up", "2400 5 state",]
        );
        // Lost again, then back without a boot-up.
        let mut f = heartbeats(5, 0, 500, 100, "05");
        f.extend(heartbeats(5, 1500, 1800, 100, "05"));
        assert_eq!(
            run(&f, None, None),
            ["0 5 state", "650 5 heartbeat_lost", "1500 5 heartbeat_back"]
        );
    }

    #[test]
    fn one_late_heartbeat_does_not_change_the_measured_period() {
        let mut f = heartbeats(5, 0, 500, 100, "05");
        f.extend(heartbeats(5, 640, 1040, 100, "05"));
        f.push((2000, 0x080, ""));
        assert_eq!(run(&f, None, None), ["0 5 state", "1190 5 heartbeat_lost"]);
    }

    #[test]
    fn sdo_0x1017_sets_the_period_and_zero_switches_it_off() {
        // Write 0x1017 = 300 ms (expedited download, confirmed), heartbeats every 100 ms stop.
        let mut f = vec![(0, 0x605, "2B1710002C010000"), (1, 0x585, "6017100000000000")];
        f.extend(heartbeats(5, 100, 300, 100, "05"));
        f.push((1000, 0x080, ""));
        assert_eq!(
            run(&f, None, None),
            ["1 5 heartbeat_period", "100 5 state", "750 5 heartbeat_lost"]
        );
        let mut f = vec![(0, 0x605, "2B17100000000000"), (1, 0x585, "6017100000000000")];
        f.extend(heartbeats(5, 100, 300, 100, "05"));
        f.push((1000, 0x080, ""));
        assert_eq!(run(&f, None, None), ["1 5 heartbeat_period", "100 5 state"]);
    }

    #[test]
    fn the_dictionary_default_applies_from_the_first_heartbeat() {
        let eds =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/eds/minimal.eds")).unwrap();
        let mut b = crate::od::bind::Bindings::new();
        b.bind_eds(7, "minimal.eds", &eds);
        let f = vec![(0, 0x707, "05"), (1400, 0x080, ""), (1600, 0x080, "")];
        assert_eq!(
            run(&f, None, Some(b.dictionary(7).clone())),
            ["0 7 state", "1500 7 heartbeat_lost"]
        );
    }

    #[test]
    fn guarding_loses_a_node_on_an_unanswered_request() {
        let f = vec![
            (0, 0x702, "R"),
            (2, 0x702, "05"),
            (100, 0x702, "R"),
            (102, 0x702, "85"),
            (200, 0x702, "R"),
            (300, 0x702, "R"),
            (400, 0x702, "R"),
            (402, 0x702, "05"),
        ];
        assert_eq!(
            run(&f, Some(10_000), None),
            ["2 2 state", "300 2 heartbeat_lost", "402 2 heartbeat_back"]
        );
    }

    #[test]
    fn extreme_and_out_of_order_timestamps_neither_panic_nor_invent_losses() {
        let dict = Dictionary::default();
        let mut tr = EventTracker::new(|_| &dict);
        let hb = crate::decode::heartbeat::decode(&[0x05], false).0;
        for t in [0, u64::MAX / 2, u64::MAX - 1, 5, 5, u64::MAX] {
            tr.heartbeat(NodeKey::new(0, 9), t, &hb);
        }
        tr.tick(u64::MAX);
        let l = tr.node(NodeKey::new(0, 9)).unwrap();
        assert_eq!(l.deadline(), Some(u64::MAX));
        assert!(!l.is_lost());
    }

    #[test]
    fn emcy_abort_and_bus_state_events() {
        let f = vec![
            (0, 0x085, "3081110000000000"),
            (1, 0x604, "4000200000000000"),
            (2, 0x584, "8000200000000206"),
        ];
        assert_eq!(run(&f, None, None), ["0 5 emcy", "2 4 sdo_abort"]);
        let dict = Dictionary::default();
        let mut tr = EventTracker::new(|_| &dict);
        tr.error_frame(5, "can0", 0x004, &[0, 0x08, 0, 0, 0, 0, 0, 0]);
        tr.error_frame(6, "can0", 0x004, &[0, 0x08, 0, 0, 0, 0, 0, 0]);
        tr.error_frame(7, "can0", 0x040, &[0; 8]);
        tr.error_frame(8, "can0", 0x080, &[0; 8]);
        tr.error_frame(9, "can0", 0x100, &[0; 8]);
        let got: Vec<(u64, &str, &str)> = tr
            .take_events()
            .iter()
            .map(|e| match &e.what {
                What::BusState { from, to, .. } => (e.t_ns, *from, *to),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(
            got,
            [
                (5, "error_active", "error_warning"),
                (7, "error_warning", "bus_off"),
                (9, "bus_off", "error_active"),
            ]
        );
    }
}
