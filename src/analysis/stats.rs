//! Per-COB-ID statistics (count, period and its min/max/jitter, the rate and the age at
//! capture time "now") and the bus load over the last second.
//!
//! "Now" is capture time: the newest frame timestamp or clock tick seen ([`Stats::tick`]),
//! never the wall clock. The rate of a COB-ID is its frames in the last second of capture
//! time (the same window as the bus load), so a COB-ID that stops falls to 0 within a
//! second; its age (time since its last frame) grows with later frames and ticks, and
//! [`IdStats::stale`] tells when it passed [`STALE_PERIODS`] of its mean periods.

use crate::frame::Frame;
use crate::output::busload::Bitrate;
use crate::wire::WireFigures;
use crate::wire::cache::FiguresCache;
use std::collections::{BTreeMap, VecDeque};

/// Statistics of one identifier.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IdStats {
    /// Frames seen.
    pub count: u64,
    /// First frame time (ns).
    pub first_ns: u64,
    /// Last frame time (ns).
    pub last_ns: u64,
    /// Store position of the last frame.
    pub last_pos: usize,
    /// Store position of the frame before it.
    pub prev_pos: Option<usize>,
    /// Frames in the last second of capture time (see [`Stats::now_ns`]).
    pub in_window: u32,
    last_gap: f64,
    min_gap: f64,
    max_gap: f64,
    sum_gap: f64,
    sum_gap2: f64,
}

/// A COB-ID is stale (dimmed in the receive list) once its age passes this many of its
/// mean periods, as PCAN-View does.
pub const STALE_PERIODS: f64 = 3.0;

/// The window of the rate and the bus load: one second of capture time.
pub const WINDOW_NS: u64 = 1_000_000_000;

impl IdStats {
    /// Mean period in seconds (None with fewer than two frames).
    pub fn period(&self) -> Option<f64> {
        (self.count > 1).then(|| self.sum_gap / (self.count - 1) as f64)
    }
    /// The last period (between the last two frames) in seconds.
    pub fn last_period(&self) -> Option<f64> {
        (self.count > 1).then_some(self.last_gap)
    }
    /// Standard deviation of the period in seconds.
    pub fn jitter(&self) -> Option<f64> {
        let p = self.period()?;
        let var = self.sum_gap2 / (self.count - 1) as f64 - p * p;
        Some(var.max(0.0).sqrt())
    }
    /// The shortest period in seconds (None with fewer than two frames).
    pub fn min_period(&self) -> Option<f64> {
        (self.count > 1).then_some(self.min_gap)
    }
    /// The longest period in seconds (None with fewer than two frames).
    pub fn max_period(&self) -> Option<f64> {
        (self.count > 1).then_some(self.max_gap)
    }
    /// Frames per second over the identifier's whole span (1 / mean period).
    pub fn mean_rate(&self) -> f64 {
        match self.period() {
            Some(p) if p > 0.0 => 1.0 / p,
            _ => 0.0,
        }
    }
    /// Seconds of capture time since the last frame, at capture time `now_ns`.
    pub fn age(&self, now_ns: u64) -> f64 {
        now_ns.saturating_sub(self.last_ns) as f64 / 1e9
    }
    /// True when, at `now_ns`, the age passed [`STALE_PERIODS`] mean periods (never for an
    /// identifier seen once: it has no period).
    pub fn stale(&self, now_ns: u64) -> bool {
        match self.period() {
            Some(p) => self.age(now_ns) > STALE_PERIODS * p,
            None => false,
        }
    }
}

/// A frame in the window of [`Stats`]: its time, its bits on the bus, its identifier's
/// entry and its interface.
#[derive(Clone, Copy, Debug)]
struct InWindow {
    ts_ns: u64,
    bits: u32,
    entry: u32,
    iface: u16,
}

/// Statistics of every identifier plus the bus load.
pub struct Stats {
    /// Each identifier's index in `entries`, in id order.
    ids: BTreeMap<(bool, u32), u32>,
    entries: Vec<IdStats>,
    /// Index in `entries` (+1, 0 for none) of each 11-bit id: no map search per frame.
    base: Vec<u32>,
    bitrate: Bitrate,
    window_bits: u64,
    /// The bits in the window per interface index (the bus load of each bus).
    iface_bits: Vec<u64>,
    /// The frames in the window, oldest first, with what their leaving takes back: each
    /// frame's bits are counted once, as it comes, not again as it leaves, and the store is
    /// not read again.
    window: VecDeque<InWindow>,
    /// The figures of the frames seen, for those that come again.
    figures: FiguresCache,
    now_ns: u64,
    /// The first frame's time.
    start_ns: Option<u64>,
}

impl Stats {
    /// Empty statistics for a bus at `bitrate` (bit/s, or a [`Bitrate`] with its source).
    pub fn new(bitrate: impl Into<Bitrate>) -> Stats {
        let bitrate = bitrate.into();
        Stats {
            ids: BTreeMap::new(),
            entries: Vec::new(),
            base: vec![0; 0x800],
            bitrate: Bitrate {
                bps: bitrate.bps.max(1),
                ..bitrate
            },
            window_bits: 0,
            iface_bits: Vec::new(),
            window: VecDeque::new(),
            figures: FiguresCache::new(),
            now_ns: 0,
            start_ns: None,
        }
    }

    /// Frames per second of `s` now: its frames in the last second of capture time, or,
    /// while the capture spans less than that, its frames per second since the capture
    /// began (0 at the first instant).
    pub fn rate(&self, s: &IdStats) -> f64 {
        let span = self
            .start_ns
            .map_or(0, |t0| self.now_ns.saturating_sub(t0))
            .min(WINDOW_NS);
        if span == 0 {
            0.0
        } else {
            s.in_window as f64 * 1e9 / span as f64
        }
    }

    /// Capture time now (ns): the newest frame time or tick seen.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// The bus bit rate used for the load, and where it came from.
    pub fn bitrate(&self) -> &Bitrate {
        &self.bitrate
    }

    /// Adds `frame`, just stored at position `pos`.
    pub fn add(&mut self, frame: &Frame, pos: usize, figures: Option<WireFigures>) {
        let i = self.index(frame.is_ext(), frame.id);
        let s = &mut self.entries[i];
        if s.count == 0 {
            s.first_ns = frame.ts_ns;
        } else {
            let gap = frame.ts_ns.saturating_sub(s.last_ns) as f64 / 1e9;
            s.sum_gap += gap;
            s.sum_gap2 += gap * gap;
            s.last_gap = gap;
            if s.count == 1 {
                (s.min_gap, s.max_gap) = (gap, gap);
            } else {
                s.min_gap = s.min_gap.min(gap);
                s.max_gap = s.max_gap.max(gap);
            }
            s.prev_pos = Some(s.last_pos);
        }
        s.last_pos = pos;
        s.count += 1;
        s.last_ns = frame.ts_ns;
        s.in_window += 1;
        self.start_ns.get_or_insert(frame.ts_ns);
        let figures = figures.unwrap_or_else(|| self.figures.figures(frame));
        let bits = figures.map_or(0, |f| u64::from(f.bus_bits()));
        self.window.push_back(InWindow {
            ts_ns: frame.ts_ns,
            bits: bits as u32,
            entry: i as u32,
            iface: frame.iface,
        });
        self.window_bits += bits;
        let k = frame.iface as usize;
        if self.iface_bits.len() <= k {
            self.iface_bits.resize(k + 1, 0);
        }
        self.iface_bits[k] += bits;
        self.tick(frame.ts_ns);
    }

    /// Capture time has reached `now_ns` (a frame's time, or the capture clock when no
    /// frame comes): frames older than the window leave the rates and the bus load.
    pub fn tick(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        // The window is (now - 1 s, now]; nothing leaves it in the first second.
        let Some(since) = self.now_ns.checked_sub(WINDOW_NS) else {
            return;
        };
        while let Some(&old) = self.window.front()
            && old.ts_ns <= since
        {
            self.window.pop_front();
            let bits = u64::from(old.bits);
            self.window_bits = self.window_bits.saturating_sub(bits);
            if let Some(b) = self.iface_bits.get_mut(usize::from(old.iface)) {
                *b = b.saturating_sub(bits);
            }
            let e = &mut self.entries[old.entry as usize];
            e.in_window = e.in_window.saturating_sub(1);
        }
    }

    /// The index in `entries` of an identifier, added on first sight.
    fn index(&mut self, ext: bool, id: u32) -> usize {
        let slot = if ext { None } else { self.base.get_mut(id as usize) };
        if let Some(&i) = slot.as_deref()
            && i > 0
        {
            return i as usize - 1;
        }
        let next = self.entries.len() as u32;
        let i = *self.ids.entry((ext, id)).or_insert(next);
        if i == next {
            self.entries.push(IdStats::default());
        }
        if let Some(s) = slot {
            *s = i + 1;
        }
        i as usize
    }

    /// Bus load in percent over the last second of the trace.
    pub fn load_percent(&self) -> f64 {
        self.window_bits as f64 * 100.0 / self.bitrate.bps as f64
    }

    /// The load of one bus (interface index `iface`) in percent over the last second of the
    /// trace; 0 for an interface without frames.
    pub fn iface_load_percent(&self, iface: u16) -> f64 {
        let bits = self.iface_bits.get(iface as usize).copied().unwrap_or(0);
        bits as f64 * 100.0 / self.bitrate.bps as f64
    }

    /// Frames in the last second of the trace.
    pub fn window_frames(&self) -> usize {
        self.window.len()
    }

    /// Every identifier: (extended, id) and its statistics, in id order.
    pub fn iter(&self) -> impl Iterator<Item = (&(bool, u32), &IdStats)> {
        self.ids.iter().map(|(k, &i)| (k, &self.entries[i as usize]))
    }

    /// Number of identifiers seen.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True when nothing was seen.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::store::Store;
    use crate::decode::Kind;

    #[test]
    fn period_jitter_rate_and_load() {
        let mut store = Store::new();
        let mut st = Stats::new(125_000);
        for (i, t) in [0u64, 10, 20, 32, 40].iter().enumerate() {
            let mut f = Frame::classic(0x181, &[i as u8; 8]);
            f.ts_ns = t * 1_000_000;
            let at = store.push(&f, Kind::Tpdo, Some(1));
            st.add(&store.frame(at), at, None);
        }
        let s = *st.iter().next().unwrap().1;
        assert_eq!(s.count, 5);
        assert!((s.period().unwrap() - 0.010).abs() < 1e-9);
        assert!(s.jitter().unwrap() > 0.001);
        assert!((s.mean_rate() - 100.0).abs() < 1e-6);
        assert_eq!(s.in_window, 5, "5 frames in the last second");
        // A capture shorter than the window: frames per second since it began.
        assert!((st.rate(&s) - 125.0).abs() < 1e-6, "5 frames in 40 ms: {}", st.rate(&s));
        assert!((s.last_period().unwrap() - 0.008).abs() < 1e-9);
        assert_eq!((s.last_pos, s.prev_pos), (4, Some(3)));
        // 5 base frames of 8 bytes, their exact bits on the wire (crate::wire) in the last
        // second, of 125000.
        let bits: u64 = (0..5).map(|i| store.bus_bits(i)).sum();
        assert_eq!(
            bits,
            (0..5u8)
                .map(|i| crate::output::busload::bus_bits(&Frame::classic(0x181, &[i; 8])))
                .sum::<u64>()
        );
        assert!(
            (st.load_percent() - bits as f64 * 100.0 / 125_000.0).abs() < 1e-9,
            "{}",
            st.load_percent()
        );
    }

    #[test]
    fn each_bus_has_its_own_load() {
        let mut store = Store::new();
        let mut st = Stats::new(125_000);
        for (iface, t) in [(0u16, 0u64), (1, 5), (1, 10), (0, 1_500)] {
            let mut f = Frame::classic(0x181, &[0; 8]);
            (f.iface, f.ts_ns) = (iface, t * 1_000_000);
            let at = store.push(&f, Kind::Tpdo, Some(1));
            st.add(&store.frame(at), at, None);
        }
        // In the last second (0.5 s to 1.5 s): one frame of can0, none of can1.
        let bits = crate::output::busload::bus_bits(&Frame::classic(0x181, &[0; 8]));
        assert!(
            (st.iface_load_percent(0) - bits as f64 * 100.0 / 125_000.0).abs() < 1e-9,
            "{}",
            st.iface_load_percent(0)
        );
        assert_eq!(st.iface_load_percent(1), 0.0);
        assert_eq!(st.iface_load_percent(7), 0.0, "an interface without frames");
        assert!((st.load_percent() - st.iface_load_percent(0)).abs() < 1e-9);
    }

    #[test]
    fn identifiers_are_counted_apart_and_listed_in_id_order() {
        let mut store = Store::new();
        let mut st = Stats::new(125_000);
        let mut err = Frame::classic(0x4, &[0; 8]);
        err.flags = crate::frame::Flags(crate::frame::Flags::ERR);
        let frames = [
            Frame::classic(0x701, &[5]),
            Frame::classic(0x181, &[1]),
            Frame::classic(0x181_0000, &[2]),
            Frame::classic(0x181, &[1]),
            err,
            Frame::classic(0x7FF, &[]),
            Frame::classic(0x181_0000, &[2]),
            Frame::classic(0x181, &[1]),
        ];
        for f in &frames {
            let at = store.push(f, Kind::Other, None);
            st.add(&store.frame(at), at, None);
        }
        let got: Vec<((bool, u32), u64, usize)> = st.iter().map(|(k, s)| (*k, s.count, s.last_pos)).collect();
        assert_eq!(
            got,
            [
                ((false, 0x4), 1, 4),
                ((false, 0x181), 3, 7),
                ((false, 0x701), 1, 0),
                ((false, 0x7FF), 1, 5),
                ((true, 0x181_0000), 2, 6)
            ]
        );
        assert_eq!(st.len(), 5);
    }

    fn push(store: &mut Store, st: &mut Stats, id: u32, ms: u64) {
        let mut f = Frame::classic(id, &[0; 8]);
        f.ts_ns = ms * 1_000_000;
        let at = store.push(&f, Kind::Other, None);
        st.add(&store.frame(at), at, None);
    }

    #[test]
    fn a_cob_id_that_stops_falls_to_rate_0_and_ages_with_later_frames_and_ticks() {
        let mut store = Store::new();
        let mut st = Stats::new(500_000);
        // 0x183 and 0x080 every 100 ms for 2 s, then only 0x080 for 2 s more.
        for k in 0..=20 {
            push(&mut store, &mut st, 0x183, k * 100);
            push(&mut store, &mut st, 0x080, k * 100);
        }
        let get = |st: &Stats, id: u32| *st.iter().find(|(k, _)| k.1 == id).unwrap().1;
        let s = get(&st, 0x183);
        assert_eq!(st.rate(&s), 10.0, "(1 s, 2 s] holds 10 frames");
        assert_eq!(s.age(st.now_ns()), 0.0);
        assert!(!s.stale(st.now_ns()));
        // 0x183 stops; 0x080 goes on: after 250 ms (2.5 periods) not stale yet.
        push(&mut store, &mut st, 0x080, 2100);
        push(&mut store, &mut st, 0x080, 2200);
        let s = get(&st, 0x183);
        assert_eq!(st.rate(&s), 8.0, "2 of its frames left the window");
        assert!((s.age(st.now_ns()) - 0.2).abs() < 1e-9);
        assert!(!s.stale(st.now_ns()));
        push(&mut store, &mut st, 0x080, 2400);
        assert!(get(&st, 0x183).stale(st.now_ns()), "age 0.4 s > 3 x 100 ms");
        assert!(!get(&st, 0x080).stale(st.now_ns()));
        for k in 25..=40 {
            push(&mut store, &mut st, 0x080, k * 100);
        }
        let s = get(&st, 0x183);
        assert_eq!(st.rate(&s), 0.0, "no frame in the last second");
        assert!((s.age(st.now_ns()) - 2.0).abs() < 1e-9);
        assert_eq!(s.count, 21, "the count stays");
        assert_eq!(st.rate(&get(&st, 0x080)), 10.0);
        // No frame at all, only the capture clock: everything ages, the rates fall to 0.
        st.tick(60_000_000_000);
        assert_eq!(st.rate(&get(&st, 0x080)), 0.0);
        assert!((get(&st, 0x183).age(st.now_ns()) - 58.0).abs() < 1e-9);
        assert!(get(&st, 0x080).stale(st.now_ns()));
        assert_eq!(st.load_percent(), 0.0);
        assert_eq!(st.window_frames(), 0);
        // A tick back in time (a late one) does not turn the clock back.
        st.tick(1_000);
        assert_eq!(st.now_ns(), 60_000_000_000);
    }

    #[test]
    fn cycle_time_min_max_and_jitter_of_a_known_sequence() {
        let mut store = Store::new();
        let mut st = Stats::new(500_000);
        // Gaps 10, 12, 8, 10, 20 ms: mean 12 ms, min 8, max 20; variance of the gaps
        // (4 + 0 + 16 + 4 + 64) / 5 = 17.6 ms², so the jitter is 4.195 ms.
        for ms in [0, 10, 22, 30, 40, 60] {
            push(&mut store, &mut st, 0x202, ms);
        }
        let s = *st.iter().next().unwrap().1;
        assert!((s.period().unwrap() - 0.012).abs() < 1e-12);
        assert!((s.min_period().unwrap() - 0.008).abs() < 1e-12);
        assert!((s.max_period().unwrap() - 0.020).abs() < 1e-12);
        assert!(
            (s.jitter().unwrap() - 17.6e-6f64.sqrt()).abs() < 1e-9,
            "{:?}",
            s.jitter()
        );
        // One frame: no period, so no min/max/jitter, and never stale.
        push(&mut store, &mut st, 0x701, 70);
        let one = *st.iter().find(|(k, _)| k.1 == 0x701).unwrap().1;
        assert_eq!((one.min_period(), one.max_period(), one.jitter()), (None, None, None));
        assert!(!one.stale(100_000_000_000));
    }
}
