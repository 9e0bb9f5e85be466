//! SYNC cycles: per SYNC period of each interface, which synchronous TPDOs came and how
//! long after the SYNC (their lanes), the synchronous window 0x1007 in force and the TPDOs
//! sent after it closed (late). A SYNC frame opens a cycle, the next SYNC of the same
//! interface closes it (its period). A TPDO is synchronous when its node's transmission
//! type 0x1800+n sub 2 is 0..=240 (from the dictionaries' defaults or an SDO write seen);
//! while that is unknown, every TPDO between two SYNCs counts. The window is the node's
//! 0x1007 (dictionary default or SDO write), else the last one written on the interface.
//! Pure: frames with their timestamps and positions in, cycles out.

use crate::decode::Kind;
use crate::frame::{Frame, NodeKey};
use crate::od::Dictionary;
use crate::sdo::transaction::{Outcome, Transaction};
use std::collections::{BTreeMap, VecDeque};

/// TPDOs a cycle keeps: a SYNC that never comes again leaves its cycle open while
/// TPDOs go on, and memory stays flat (the others are counted in [`Cycle::dropped`]).
pub const SLOTS_KEPT: usize = 1024;

/// Cycles waiting behind an open cycle of another interface before
/// [`SyncCycles::take_closed`] ends that one (its SYNC stopped), keeping memory flat.
const BACKLOG: usize = 4096;

/// One synchronous TPDO of a cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slot {
    /// Its COB-ID.
    pub cob_id: u32,
    /// The node that sent it.
    pub node: u8,
    /// The TPDO number (1 for TPDO1).
    pub pdo: u16,
    /// Time since the cycle's SYNC (µs; at most 4295 s, a longer gap is saturated).
    pub offset_us: u32,
    /// Sent after the synchronous window closed.
    pub late: bool,
}

/// One SYNC period of an interface.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Cycle {
    /// The interface (index into the trace's interface table).
    pub iface: u16,
    /// Trace position of the SYNC frame that opened it.
    pub sync_pos: u64,
    /// Time of that SYNC (ns).
    pub start_ns: u64,
    /// Time to the next SYNC of the interface (ns); None for the last cycle.
    pub period_ns: Option<u64>,
    /// The SYNC's counter byte, when it carries one.
    pub counter: Option<u8>,
    /// The synchronous window (0x1007, µs) in force when it opened, if known: the last
    /// one written on the interface, else a node's dictionary default.
    pub window_us: Option<u64>,
    /// The synchronous TPDOs, in order of arrival (the first [`SLOTS_KEPT`]).
    pub frames: Vec<Slot>,
    /// Synchronous TPDOs beyond [`SLOTS_KEPT`], not kept (nor judged late).
    pub dropped: u64,
}

impl Cycle {
    /// How many of its TPDOs came late.
    pub fn late(&self) -> usize {
        self.frames.iter().filter(|s| s.late).count()
    }
}

/// Running totals of the cycles (what the text summary prints).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Totals {
    /// Cycles opened.
    pub cycles: u64,
    /// Cycles with a period (closed by a next SYNC).
    pub periods: u64,
    /// Sum of the periods (ns).
    pub period_sum_ns: u64,
    /// The longest period: (ns, its cycle's interface and start).
    pub slowest: Option<(u64, u16, u64)>,
    /// Late TPDOs.
    pub late_frames: u64,
    /// Cycles with at least one late TPDO.
    pub late_cycles: u64,
}

/// A cycle as kept (56 bytes): [`Cycle`] with its TPDOs in its interface's [`Lanes`].
#[derive(Clone, Copy, Debug)]
struct Kept {
    sync_pos: u64,
    start_ns: u64,
    /// [`NO_PERIOD`] for none.
    period_ns: u64,
    /// 0 for none (a window of 0 is no window).
    window_us: u64,
    dropped: u64,
    /// Index of its first TPDO in its interface's lanes (counted from the first ever kept).
    first_slot: u64,
    slots: u16,
    late: u16,
    iface: u16,
    counter: Option<u8>,
}

/// The period of a cycle with none (no capture spans 2^64 ns).
const NO_PERIOD: u64 = u64::MAX;

/// The TPDOs of one interface's cycles, in order: a cycle's are contiguous, since an
/// interface has one open cycle at a time.
#[derive(Clone, Debug, Default)]
struct Lanes {
    slots: VecDeque<Slot>,
    /// How many were taken from the front.
    base: u64,
}

/// Default sync window (µs) and TPDO transmission types of a node-ID's dictionary.
type Defaults = (u8, Option<u64>, Vec<(u16, u8)>);

/// The SYNC cycles of a capture, built frame by frame.
#[derive(Clone, Debug, Default)]
pub struct SyncCycles {
    /// The cycles not yet taken, in order of their SYNC; `base` is the number taken.
    cycles: VecDeque<Kept>,
    base: usize,
    /// Their TPDOs, per interface.
    lanes: Vec<Lanes>,
    /// The open cycle of each interface (absolute index: `base` + position).
    open: Vec<Option<usize>>,
    /// 0x1007 per node (µs).
    windows: BTreeMap<NodeKey, u64>,
    /// The last 0x1007 written on each interface (µs).
    bus_window: BTreeMap<u16, u64>,
    /// Transmission types of TPDOs: (node, TPDO number) to 0x1800+n sub 2.
    types: BTreeMap<(NodeKey, u16), u8>,
    defaults: Vec<Defaults>,
    ifaces_seen: u16,
    totals: Totals,
}

/// A dictionary's default sync window (µs) and TPDO transmission types (PDO number, type).
pub(crate) type SyncDefaults = (Option<u64>, Vec<(u16, u8)>);

/// The sync window (0x1007, µs) and the transmission types of the TPDOs (0x1800.. sub 2)
/// that `dict` gives as default values (EDS `DefaultValue`, profile `default`).
pub(crate) fn sync_defaults(dict: &Dictionary) -> SyncDefaults {
    let default = |index: u16, sub: u8| dict.object(index, sub)?.default.as_ref()?.as_i64();
    let window = default(0x1007, 0)
        .and_then(|v| u64::try_from(v).ok())
        .filter(|v| *v > 0);
    // Only indexes some layer names (objects or index ranges) can have a default.
    let mut indexes: Vec<u16> = Vec::new();
    for layer in dict.layers() {
        indexes.extend(
            layer
                .objects
                .range((0x1800, 2)..=(0x19FF, 2))
                .filter(|(k, _)| k.1 == 2)
                .map(|(k, _)| k.0),
        );
        for r in layer
            .ranges
            .iter()
            .filter(|r| r.subs.get(&2).is_some_and(|o| o.default.is_some()))
        {
            indexes.extend(r.first.max(0x1800)..=r.last.min(0x19FF));
        }
    }
    indexes.sort_unstable();
    indexes.dedup();
    let types = indexes
        .into_iter()
        .filter_map(|i| Some((i - 0x1800 + 1, u8::try_from(default(i, 2)?).ok()?)))
        .collect();
    (window, types)
}

/// True for a transmission type that sends on SYNC (0 acyclic, 1..=240 every n-th SYNC).
fn synchronous(t: u8) -> bool {
    t <= 240
}

impl SyncCycles {
    /// Empty, starting from what the dictionaries give as defaults (0x1007, 0x1800+n sub 2).
    pub fn new<'a>(dict: impl Fn(u8) -> &'a Dictionary) -> SyncCycles {
        let mut s = SyncCycles::default();
        // Unbound nodes share one dictionary: each distinct one is read once.
        let mut seen: Vec<(Vec<*const crate::od::Profile>, SyncDefaults)> = Vec::new();
        for n in 1..128u8 {
            let d = dict(n);
            let layers: Vec<_> = d.layers().iter().map(std::sync::Arc::as_ptr).collect();
            let i = match seen.iter().position(|(l, _)| *l == layers) {
                Some(i) => i,
                None => {
                    seen.push((layers, sync_defaults(d)));
                    seen.len() - 1
                }
            };
            let (window, types) = &seen[i].1;
            if window.is_some() || !types.is_empty() {
                s.defaults.push((n, *window, types.clone()));
            }
        }
        s
    }

    /// Interfaces up to `iface` are seen: their nodes start from the defaults.
    fn see_interfaces(&mut self, iface: u16) {
        for i in self.ifaces_seen..=iface {
            for (n, window, types) in &self.defaults {
                let key = NodeKey::new(i, *n);
                if let Some(w) = window {
                    self.windows.insert(key, *w);
                }
                for (num, t) in types {
                    self.types.insert((key, *num), *t);
                }
            }
        }
        self.ifaces_seen = iface.saturating_add(1);
    }

    /// Takes a frame at trace position `pos` that the decoder routes to `kind`, `node` and
    /// PDO number `pdo` (as `Decoder::peek` says).
    pub fn frame(&mut self, frame: &Frame, pos: u64, (kind, node, pdo): (Kind, Option<u8>, u16)) {
        if frame.iface >= self.ifaces_seen {
            self.see_interfaces(frame.iface);
        }
        if frame.is_rtr() || frame.is_err() {
            return;
        }
        match (kind, node) {
            (Kind::Sync, _) => self.sync(frame, pos),
            (Kind::Tpdo, Some(n)) => self.tpdo(frame, NodeKey::of(frame, n), pdo),
            _ => {}
        }
    }

    fn sync(&mut self, frame: &Frame, pos: u64) {
        let i = usize::from(frame.iface);
        if self.open.len() <= i {
            self.open.resize(i + 1, None);
        }
        if self.lanes.len() <= i {
            self.lanes.resize_with(i + 1, Lanes::default);
        }
        if let Some(c) = self.open[i].and_then(|a| self.cycles.get_mut(a - self.base)) {
            let period = frame.ts_ns.saturating_sub(c.start_ns).min(NO_PERIOD - 1);
            c.period_ns = period;
            let t = &mut self.totals;
            t.periods += 1;
            t.period_sum_ns += period;
            if t.slowest.is_none_or(|(p, _, _)| period > p) {
                t.slowest = Some((period, c.iface, c.start_ns));
            }
        }
        self.totals.cycles += 1;
        let lanes = &self.lanes[i];
        self.cycles.push_back(Kept {
            iface: frame.iface,
            sync_pos: pos,
            start_ns: frame.ts_ns,
            period_ns: NO_PERIOD,
            counter: frame.payload().first().copied(),
            window_us: self.window_of(frame.iface).unwrap_or(0),
            first_slot: lanes.base + lanes.slots.len() as u64,
            slots: 0,
            late: 0,
            dropped: 0,
        });
        self.open[i] = Some(self.base + self.cycles.len() - 1);
    }

    /// The window of interface `iface`: the last 0x1007 written there, else that of its
    /// lowest node with one (a dictionary default).
    fn window_of(&self, iface: u16) -> Option<u64> {
        let nodes = self
            .windows
            .range(NodeKey::new(iface, 0)..=NodeKey::new(iface, u8::MAX));
        self.bus_window.get(&iface).or(nodes.map(|(_, w)| w).next()).copied()
    }

    fn tpdo(&mut self, frame: &Frame, key: NodeKey, pdo: u16) {
        if self.types.get(&(key, pdo)).is_some_and(|t| !synchronous(*t)) {
            return;
        }
        let window = self
            .windows
            .get(&key)
            .or_else(|| self.bus_window.get(&key.iface))
            .copied();
        let open = self.open.get(usize::from(frame.iface)).copied().flatten();
        let Some(c) = open.and_then(|a| self.cycles.get_mut(a - self.base)) else {
            return;
        };
        if usize::from(c.slots) >= SLOTS_KEPT {
            c.dropped += 1;
            return;
        }
        let offset_us = frame.ts_ns.saturating_sub(c.start_ns) / 1000;
        let late = window.is_some_and(|w| offset_us > w);
        if late {
            self.totals.late_frames += 1;
            if c.late == 0 {
                self.totals.late_cycles += 1;
            }
            c.late += 1;
        }
        c.slots += 1;
        // The open cycle's interface has lanes: its SYNC made them.
        let Some(lanes) = self.lanes.get_mut(usize::from(frame.iface)) else {
            return;
        };
        lanes.slots.push_back(Slot {
            cob_id: frame.id,
            node: key.node,
            pdo,
            offset_us: u32::try_from(offset_us).unwrap_or(u32::MAX),
            late,
        });
    }

    /// Learns the windows (0x1007) and transmission types (0x1800+n sub 2) an SDO
    /// transfer wrote or read.
    pub fn transaction(&mut self, t: &Transaction) {
        if t.outcome != Outcome::Ok || t.data.is_empty() {
            return;
        }
        let v = t.data.iter().take(4).rev().fold(0u32, |a, b| a << 8 | u32::from(*b));
        let key = t.key();
        if t.iface >= self.ifaces_seen {
            self.see_interfaces(t.iface);
        }
        match (t.index, t.sub) {
            (0x1007, 0) if v > 0 => {
                self.windows.insert(key, u64::from(v));
                self.bus_window.insert(t.iface, u64::from(v));
            }
            (0x1007, 0) => {
                self.windows.remove(&key);
                self.bus_window.remove(&t.iface);
            }
            (0x1800..=0x19FF, 2) => {
                self.types.insert((key, t.index - 0x1800 + 1), v as u8);
            }
            _ => {}
        }
    }

    /// The input ended: the open cycles stay without a period and can be taken.
    pub fn end(&mut self) {
        self.open.clear();
    }

    /// Number of cycles not taken.
    pub fn len(&self) -> usize {
        self.cycles.len()
    }

    /// True when no cycle is kept.
    pub fn is_empty(&self) -> bool {
        self.cycles.is_empty()
    }

    /// Cycle `i` of those not taken, in order of their SYNC (the open ones last on their
    /// interface).
    pub fn get(&self, i: usize) -> Option<Cycle> {
        let c = self.cycles.get(i)?;
        let lanes = self.lanes.get(usize::from(c.iface))?;
        let from = (c.first_slot - lanes.base) as usize;
        Some(Cycle {
            iface: c.iface,
            sync_pos: c.sync_pos,
            start_ns: c.start_ns,
            period_ns: (c.period_ns != NO_PERIOD).then_some(c.period_ns),
            counter: c.counter,
            window_us: (c.window_us != 0).then_some(c.window_us),
            frames: lanes.slots.range(from..from + usize::from(c.slots)).copied().collect(),
            dropped: c.dropped,
        })
    }

    /// Takes the cycles that are closed, up to the first still open (a headless command
    /// prints them as they close, keeping memory flat).
    pub fn take_closed(&mut self) -> Vec<Cycle> {
        if self.cycles.len() > BACKLOG {
            // An interface whose SYNC stopped holds the others' cycles back: its cycle
            // ends without a period.
            let front = self.base;
            self.open
                .iter_mut()
                .filter(|o| **o == Some(front))
                .for_each(|o| *o = None);
        }
        let first_open = self.open.iter().flatten().min().copied().unwrap_or(usize::MAX);
        let n = first_open.saturating_sub(self.base).min(self.cycles.len());
        let taken: Vec<Cycle> = (0..n).filter_map(|i| self.get(i)).collect();
        // An interface's taken cycles are the first of its own, so their TPDOs are the
        // first of its lanes.
        for c in self.cycles.drain(..n) {
            if let Some(lanes) = self.lanes.get_mut(usize::from(c.iface)) {
                lanes.slots.drain(..usize::from(c.slots));
                lanes.base += u64::from(c.slots);
            }
        }
        self.base += n;
        taken
    }

    /// How many cycles were taken so far.
    pub fn taken(&self) -> usize {
        self.base
    }

    /// The totals so far.
    pub fn totals(&self) -> Totals {
        self.totals
    }

    /// Index (into [`SyncCycles::cycles`]) of the cycle with the longest period.
    pub fn slowest(&self) -> Option<usize> {
        let periods = self.cycles.iter().enumerate();
        let with = periods.filter_map(|(i, c)| (c.period_ns != NO_PERIOD).then_some((c.period_ns, i)));
        // The first of equal periods.
        with.max_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1))).map(|(_, i)| i)
    }

    /// Index of the first cycle after `after` (from the first with None) with a late
    /// TPDO, round again after the last.
    pub fn next_late(&self, after: Option<usize>) -> Option<usize> {
        let n = self.cycles.len();
        let from = after.map_or(0, |a| a + 1);
        (0..n).map(|k| (from + k) % n).find(|&i| self.cycles[i].late > 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;

    fn frame(id: u32, data: &[u8], ms: f64) -> Frame {
        let mut f = Frame::classic(id, data);
        f.ts_ns = (ms * 1e6) as u64;
        f
    }

    /// An expedited SDO download of `data` to `node`, as the decoder reassembles it.
    fn write(node: u8, index: u16, sub: u8, data: &[u8]) -> Transaction {
        let mut d = Decoder::new(Dictionary::default(), Vec::new());
        let cmd = 0x23 | ((4 - data.len() as u8) << 2);
        let [lo, hi] = index.to_le_bytes();
        let mut req = vec![cmd, lo, hi, sub];
        req.extend_from_slice(data);
        req.resize(8, 0);
        d.decode(&Frame::classic(0x600 + u32::from(node), &req));
        d.decode(&Frame::classic(
            0x580 + u32::from(node),
            &[0x60, lo, hi, sub, 0, 0, 0, 0],
        ));
        let mut t = d.take_transactions();
        assert_eq!(t.len(), 1);
        t.remove(0)
    }

    /// Every cycle not taken.
    fn all(s: &SyncCycles) -> Vec<Cycle> {
        (0..s.len()).filter_map(|i| s.get(i)).collect()
    }

    fn push(s: &mut SyncCycles, f: &Frame, pos: u64) {
        let kind = match f.id {
            0x80 => (Kind::Sync, None, 0),
            0x181..=0x1FF => (Kind::Tpdo, Some((f.id - 0x180) as u8), 1),
            0x281..=0x2FF => (Kind::Tpdo, Some((f.id - 0x280) as u8), 2),
            _ => (Kind::Other, None, 0),
        };
        s.frame(f, pos, kind);
    }

    #[test]
    fn tpdos_land_in_their_cycle_and_late_ones_are_marked_once_the_window_is_known() {
        let mut s = SyncCycles::default();
        let frames = [
            frame(0x181, &[1], 0.5), // before any SYNC: in no cycle
            frame(0x080, &[1], 1.0),
            frame(0x181, &[1], 1.8),
            frame(0x282, &[1], 2.0),
            frame(0x080, &[2], 11.0),
            frame(0x181, &[1], 11.9),
            frame(0x282, &[1], 14.5),
            frame(0x080, &[3], 21.2),
        ];
        for (i, f) in frames.iter().enumerate() {
            if i == 4 {
                s.transaction(&write(1, 0x1007, 0, &[0xD0, 0x07, 0, 0]));
            }
            push(&mut s, f, i as u64);
        }
        s.end();
        let c: Vec<Cycle> = s.take_closed();
        assert_eq!(c.len(), 3);
        assert_eq!(
            (c[0].sync_pos, c[0].counter, c[0].period_ns),
            (1, Some(1), Some(10_000_000))
        );
        assert_eq!(c[0].window_us, None);
        let offs: Vec<(u32, u32, bool)> = c[0].frames.iter().map(|f| (f.cob_id, f.offset_us, f.late)).collect();
        assert_eq!(offs, [(0x181, 800, false), (0x282, 1000, false)]);
        // The window 2000 µs written to node 1 holds for the interface.
        assert_eq!(c[1].window_us, Some(2000));
        let offs: Vec<(u32, u32, bool)> = c[1].frames.iter().map(|f| (f.cob_id, f.offset_us, f.late)).collect();
        assert_eq!(offs, [(0x181, 900, false), (0x282, 3500, true)]);
        assert_eq!((c[1].late(), c[1].period_ns), (1, Some(10_200_000)));
        assert_eq!(c[2].period_ns, None);
        let t = s.totals();
        assert_eq!((t.cycles, t.periods, t.late_frames, t.late_cycles), (3, 2, 1, 1));
        assert_eq!(t.slowest, Some((10_200_000, 0, 11_000_000)));
    }

    #[test]
    fn an_asynchronous_tpdo_has_no_lane_and_the_jumps_find_slowest_and_late_cycles() {
        let mut s = SyncCycles::default();
        s.transaction(&write(2, 0x1801, 2, &[0xFE]));
        s.transaction(&write(1, 0x1007, 0, &[0xE8, 0x03]));
        let frames = [
            frame(0x080, &[], 0.0),
            frame(0x181, &[], 0.5),
            frame(0x282, &[], 0.6),
            frame(0x080, &[], 10.0),
            frame(0x181, &[], 11.5),
            frame(0x080, &[], 22.0),
            frame(0x080, &[], 32.0),
            frame(0x181, &[], 33.5),
        ];
        for (i, f) in frames.iter().enumerate() {
            push(&mut s, f, i as u64);
        }
        let c = all(&s);
        assert_eq!(c.len(), 4);
        assert_eq!(c[0].frames.len(), 1, "TPDO2 of node 2 is event-driven (254)");
        assert_eq!(c[0].counter, None);
        assert_eq!(s.slowest(), Some(1));
        assert_eq!(s.next_late(None), Some(1));
        assert_eq!(s.next_late(Some(1)), Some(3));
        assert_eq!(s.next_late(Some(3)), Some(1));
        // Only closed cycles are taken while the last is open.
        assert_eq!(s.take_closed().len(), 3);
        assert_eq!(s.take_closed().len(), 0);
        s.end();
        assert_eq!(s.take_closed().len(), 1);
    }

    #[test]
    fn a_cycle_whose_sync_never_comes_again_keeps_a_bounded_number_of_tpdos() {
        let mut s = SyncCycles::default();
        push(&mut s, &frame(0x080, &[], 0.0), 0);
        for i in 0..SLOTS_KEPT + 10 {
            push(&mut s, &frame(0x181, &[], 1.0 + i as f64), i as u64 + 1);
        }
        let c = &all(&s)[0];
        assert_eq!((c.frames.len(), c.dropped), (SLOTS_KEPT, 10));
    }

    #[test]
    fn a_dictionary_default_window_holds_until_the_bus_writes_one() {
        let mut s = SyncCycles::default();
        s.defaults.push((2, Some(1500), vec![(1, 1)]));
        push(&mut s, &frame(0x080, &[], 0.0), 0);
        push(&mut s, &frame(0x182, &[], 1.6), 1);
        s.transaction(&write(1, 0x1007, 0, &[0xD0, 0x07, 0, 0]));
        push(&mut s, &frame(0x080, &[], 10.0), 2);
        push(&mut s, &frame(0x181, &[], 11.6), 3);
        let c = all(&s);
        assert_eq!(c[0].window_us, Some(1500));
        assert!(c[0].frames[0].late, "1600 µs after the SYNC, window 1500 µs");
        assert_eq!(c[1].window_us, Some(2000));
        assert!(!c[1].frames[0].late, "node 1 has the window written: 2000 µs");
    }

    #[test]
    fn an_interface_whose_sync_stopped_does_not_hold_back_the_others() {
        let mut s = SyncCycles::default();
        let mut quiet = frame(0x080, &[], 0.0);
        quiet.iface = 1;
        push(&mut s, &quiet, 0);
        for i in 0..BACKLOG as u64 + 2 {
            push(&mut s, &frame(0x080, &[], 1.0 + i as f64), i + 1);
        }
        let taken = s.take_closed();
        assert_eq!(taken.len(), BACKLOG + 2, "all but can0's open cycle");
        assert_eq!((taken[0].iface, taken[0].period_ns), (1, None));
        assert!(s.take_closed().is_empty());
    }

    #[test]
    fn each_interface_has_its_own_cycles() {
        let mut s = SyncCycles::default();
        let mut a = frame(0x080, &[], 0.0);
        let mut b = frame(0x080, &[], 2.0);
        b.iface = 1;
        let mut p = frame(0x181, &[], 3.0);
        p.iface = 1;
        push(&mut s, &a, 0);
        push(&mut s, &b, 1);
        push(&mut s, &p, 2);
        a.ts_ns = 10_000_000;
        push(&mut s, &a, 3);
        let c = all(&s);
        assert_eq!(
            (c[0].iface, c[0].period_ns, c[0].frames.len()),
            (0, Some(10_000_000), 0)
        );
        assert_eq!((c[1].iface, c[1].period_ns, c[1].frames[0].offset_us), (1, None, 1000));
        // Can0's first cycle is closed but can1's (older than can0's second) is not.
        assert_eq!(s.take_closed().len(), 1);
    }

    /// Two interfaces' cycles interleave, each with its own TPDOs; taking the closed ones
    /// (while the other interface's are open) leaves every later cycle its own TPDOs.
    #[test]
    fn taken_cycles_leave_the_others_their_tpdos() {
        let mut s = SyncCycles::default();
        let mut pos = 0;
        let mut taken = Vec::new();
        for k in 0..40u64 {
            let iface = (k % 2) as u16;
            let t = k * 10_000_000 + u64::from(iface) * 1_000_000;
            let mut sync = frame(0x080, &[k as u8], 0.0);
            (sync.iface, sync.ts_ns) = (iface, t);
            push(&mut s, &sync, pos);
            pos += 1;
            // k TPDOs of node k % 7 + 1 (none in some cycles), at k µs steps.
            for j in 0..k % 4 {
                let mut p = frame(0x181 + (k % 7) as u32, &[], 0.0);
                (p.iface, p.ts_ns) = (iface, t + (j + 1) * 1000);
                push(&mut s, &p, pos);
                pos += 1;
            }
            if k % 5 == 4 {
                taken.extend(s.take_closed());
            }
        }
        s.end();
        taken.extend(s.take_closed());
        assert_eq!(taken.len(), 40);
        for (k, c) in taken.iter().enumerate() {
            let k = k as u64;
            assert_eq!((c.iface, c.counter), ((k % 2) as u16, Some(k as u8)), "cycle {k}");
            let got: Vec<(u32, u32)> = c.frames.iter().map(|f| (f.cob_id, f.offset_us)).collect();
            let want: Vec<(u32, u32)> = (0..k % 4).map(|j| (0x181 + (k % 7) as u32, (j as u32 + 1))).collect();
            assert_eq!(got, want, "cycle {k}");
        }
        assert!(
            s.lanes.iter().all(|l| l.slots.is_empty()),
            "every TPDO went with its cycle"
        );
    }
}
