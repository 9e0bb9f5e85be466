//! Cyclic traffic timing for the diagnosis: the SYNC period and its jitter, and PDOs that
//! stop arriving within their event time (0x1800/0x1400 sub 5 seen on the bus) or their
//! measured period. Pure: times are frame timestamps (ns) passed in.

use crate::frame::NodeKey;
use std::collections::HashMap;

const MS: u64 = 1_000_000;
/// Intervals used to learn a period.
const LEARN: usize = 8;
/// A learned period holds when every learning interval is within this share of it.
const REGULAR: f64 = 0.2;
/// A SYNC interval this far off the period (share of it) is off time...
const SYNC_OFF: f64 = 0.1;
/// ...and at least this far (timestamps of a loaded PC wobble by a few hundred µs).
const SYNC_OFF_MIN_NS: u64 = MS / 2;
/// Off-time intervals kept for the timeline.
const KEPT: usize = 10;

/// The median of `v` (sorted in place); 0 when empty.
fn median(v: &mut [u64]) -> u64 {
    v.sort_unstable();
    v.get(v.len() / 2).copied().unwrap_or(0)
}

/// A period learned from the first [`LEARN`] intervals, if they are regular.
fn regular(learn: &[u64]) -> Option<u64> {
    let mut v = learn.to_vec();
    let p = median(&mut v);
    let tol = (p as f64 * REGULAR) as u64;
    (p > 0 && v.iter().all(|iv| iv.abs_diff(p) <= tol)).then_some(p)
}

/// One SYNC interval that was off time: the frame that ended it, when, and its length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffTime {
    /// Frame number of the SYNC that came off time.
    pub frame: u64,
    /// Its time (ns).
    pub t_ns: u64,
    /// The interval before it (ns).
    pub interval_ns: u64,
}

/// SYNC period and jitter statistics.
#[derive(Clone, Debug, Default)]
pub struct SyncTiming {
    last: Option<u64>,
    learn: Vec<(u64, u64, u64)>,
    period: Option<u64>,
    /// Learning found the intervals irregular: nothing to judge against.
    irregular: bool,
    n: u64,
    mean: f64,
    m2: f64,
    min: u64,
    max: u64,
    /// Intervals off time.
    pub off: u64,
    /// The first off-time intervals.
    pub kept: Vec<OffTime>,
}

/// What [`SyncTiming::summary`] reports.
#[derive(Clone, Debug, PartialEq)]
pub struct SyncSummary {
    /// The period (median of the first intervals, ns).
    pub period_ns: u64,
    /// Intervals measured.
    pub intervals: u64,
    /// Shortest and longest interval (ns).
    pub min_ns: u64,
    pub max_ns: u64,
    /// Standard deviation of the intervals (ns).
    pub std_ns: f64,
    /// Intervals off time (more than 10 % and 0.5 ms off the period).
    pub off: u64,
}

impl SyncTiming {
    /// A SYNC frame `frame` at `t_ns`.
    pub fn sync(&mut self, frame: u64, t_ns: u64) {
        let Some(last) = self.last.replace(t_ns) else {
            return;
        };
        let iv = t_ns.saturating_sub(last);
        if self.irregular {
            return;
        }
        match self.period {
            Some(_) => self.interval(frame, t_ns, iv),
            None => {
                self.learn.push((frame, t_ns, iv));
                if self.learn.len() == LEARN {
                    let ivs: Vec<u64> = self.learn.iter().map(|l| l.2).collect();
                    self.period = regular(&ivs);
                    self.irregular = self.period.is_none();
                    for (f, t, iv) in std::mem::take(&mut self.learn) {
                        self.interval(f, t, iv);
                    }
                }
            }
        }
    }

    fn interval(&mut self, frame: u64, t_ns: u64, iv: u64) {
        let Some(p) = self.period else { return };
        self.n += 1;
        let x = iv as f64;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
        self.min = if self.n == 1 { iv } else { self.min.min(iv) };
        self.max = self.max.max(iv);
        let tol = ((p as f64 * SYNC_OFF) as u64).max(SYNC_OFF_MIN_NS);
        if iv.abs_diff(p) > tol {
            self.off += 1;
            if self.kept.len() < KEPT {
                self.kept.push(OffTime {
                    frame,
                    t_ns,
                    interval_ns: iv,
                });
            }
        }
    }

    /// Period and jitter, once a period was learned.
    pub fn summary(&self) -> Option<SyncSummary> {
        let period_ns = self.period?;
        Some(SyncSummary {
            period_ns,
            intervals: self.n,
            min_ns: self.min,
            max_ns: self.max,
            std_ns: if self.n > 1 {
                (self.m2 / (self.n - 1) as f64).sqrt()
            } else {
                0.0
            },
            off: self.off,
        })
    }
}

/// Which PDO: node (of its interface), transmit (TPDO) or receive, number 1..512.
pub type PdoKey = (NodeKey, bool, u16);

/// Where a PDO's expected interval comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeriodFrom {
    /// The event timer (sub 5 of its communication parameters) written on the bus.
    EventTimer,
    /// Measured: the first intervals were regular.
    Measured,
}

/// One PDO's arrivals.
#[derive(Clone, Debug, Default)]
struct Stream {
    /// The last arrival: frame number and time.
    last: Option<(u64, u64)>,
    learn: Vec<u64>,
    measured: Option<u64>,
    irregular: bool,
    event_timer: Option<u64>,
    /// Transmission type 1..=240 (sent after SYNC) written on the bus.
    synchronous: bool,
    /// A gap was reported and the PDO has not come back yet.
    missing: bool,
}

impl Stream {
    fn expected(&self) -> Option<(u64, PeriodFrom)> {
        match (self.event_timer, self.measured) {
            (Some(e), _) => Some((e, PeriodFrom::EventTimer)),
            (None, Some(m)) => Some((m, PeriodFrom::Measured)),
            _ => None,
        }
    }

    /// When the PDO is overdue: three periods (two event times) after the last arrival.
    fn deadline(&self) -> Option<u64> {
        let (_, t) = self.last?;
        if self.missing {
            return None;
        }
        let (p, from) = self.expected()?;
        let allowed = match from {
            PeriodFrom::EventTimer => 2 * p,
            PeriodFrom::Measured => 3 * p,
        };
        Some(t + allowed.max(20 * MS))
    }
}

/// A PDO gap found by [`PdoTiming::due`] or ended by [`PdoTiming::pdo`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PdoGap {
    /// Overdue: the last arrival (frame, time), the expected period and where it is from.
    Missing {
        key: PdoKey,
        last_frame: u64,
        last_ns: u64,
        period_ns: u64,
        from: PeriodFrom,
    },
    /// Came back after a reported gap of `gap_ns`.
    Back { key: PdoKey, gap_ns: u64 },
}

/// PDOs 1..=[`FAST_PDOS`] of each node are found by direct index (the common ones).
const FAST_PDOS: usize = 8;
/// No stream yet in a [`PdoTiming::slot`] entry.
const NONE: u32 = u32::MAX;

/// Where `key` is in [`PdoTiming::slot`], for PDOs 1..=[`FAST_PDOS`].
fn fast_slot((node, transmit, num): PdoKey) -> Option<usize> {
    let num = usize::from(num);
    // The first interface's (a capture of one bus has only that one).
    (node.iface == 0 && (1..=FAST_PDOS).contains(&num))
        .then(|| (usize::from(node.node & 0x7F) * 2 + usize::from(transmit)) * FAST_PDOS + num - 1)
}

/// Arrival times of every PDO, and the event timers seen written. Looked up per PDO
/// frame, so the common PDOs take an array index, not a map search.
#[derive(Clone, Debug, Default)]
pub struct PdoTiming {
    /// Every PDO seen, in the order first seen.
    streams: Vec<(PdoKey, Stream)>,
    /// Index in `streams` of PDOs 1..=[`FAST_PDOS`] per node and direction ([`NONE`]:
    /// not seen); empty until the first PDO.
    slot: Vec<u32>,
    /// Index in `streams` of the other PDOs.
    more: HashMap<PdoKey, usize>,
    next: Option<u64>,
}

impl PdoTiming {
    #[inline]
    fn find(&self, key: PdoKey) -> Option<usize> {
        match fast_slot(key) {
            Some(i) => self.slot.get(i).filter(|s| **s != NONE).map(|s| *s as usize),
            None => self.more.get(&key).copied(),
        }
    }

    /// The stream of `key`, made on first use.
    #[inline]
    fn stream(&mut self, key: PdoKey) -> &mut Stream {
        let i = match self.find(key) {
            Some(i) => i,
            None => {
                let i = self.streams.len();
                self.streams.push((key, Stream::default()));
                match fast_slot(key) {
                    Some(f) => {
                        if self.slot.is_empty() {
                            self.slot = vec![NONE; 128 * 2 * FAST_PDOS];
                        }
                        self.slot[f] = i as u32;
                    }
                    None => {
                        self.more.insert(key, i);
                    }
                }
                i
            }
        };
        &mut self.streams[i].1
    }

    /// A PDO `key` arrived (frame `frame` at `t_ns`); returns a gap that it ends.
    pub fn pdo(&mut self, key: PdoKey, frame: u64, t_ns: u64) -> Option<PdoGap> {
        let s = self.stream(key);
        let prev = s.last.replace((frame, t_ns));
        let back = std::mem::take(&mut s.missing);
        if let Some((_, last)) = prev
            && s.measured.is_none()
            && !s.irregular
        {
            s.learn.push(t_ns.saturating_sub(last));
            if s.learn.len() == LEARN {
                s.measured = regular(&s.learn);
                s.irregular = s.measured.is_none();
                s.learn = Vec::new();
            }
        }
        if let Some(d) = s.deadline() {
            self.next = Some(self.next.map_or(d, |n| n.min(d)));
        }
        match (back, prev) {
            (true, Some((_, last))) => Some(PdoGap::Back {
                key,
                gap_ns: t_ns.saturating_sub(last),
            }),
            _ => None,
        }
    }

    /// The event timer of `key` was written: `ms` (0 switches it off).
    pub fn event_timer(&mut self, key: PdoKey, ms: u64) {
        self.stream(key).event_timer = (ms > 0).then_some(ms * MS);
    }

    /// The transmission type of `key` was written (sub 2): 1..=240 is synchronous.
    pub fn transmission_type(&mut self, key: PdoKey, t: u8) {
        self.stream(key).synchronous = (1..=240).contains(&t);
    }

    /// True when `key` was configured synchronous (transmission type 1..=240).
    pub fn synchronous(&self, key: PdoKey) -> bool {
        self.find(key).is_some_and(|i| self.streams[i].1.synchronous)
    }

    /// `node` of interface `iface` (None: every node of it) stops sending PDOs for a
    /// reason (NMT stop, pre-operational, reset, boot-up): its PDOs are not expected until
    /// they come again.
    pub fn pause(&mut self, iface: u16, node: Option<u8>) {
        for (k, s) in &mut self.streams {
            if k.0.iface == iface && node.is_none_or(|n| n == k.0.node) {
                s.last = None;
                s.missing = false;
            }
        }
    }

    /// PDOs overdue at `now_ns` (each reported once until it comes back), in PDO order
    /// (node, RPDO before TPDO, number). Called per frame: the common "none" is inline.
    #[inline]
    pub fn due(&mut self, now_ns: u64) -> Vec<PdoGap> {
        if self.next.is_none_or(|n| now_ns <= n) {
            return Vec::new();
        }
        self.overdue(now_ns)
    }

    fn overdue(&mut self, now_ns: u64) -> Vec<PdoGap> {
        let mut out = Vec::new();
        for (k, s) in &mut self.streams {
            if s.deadline().is_some_and(|d| d < now_ns)
                && let (Some((frame, t)), Some((p, from))) = (s.last, s.expected())
            {
                s.missing = true;
                out.push(PdoGap::Missing {
                    key: *k,
                    last_frame: frame,
                    last_ns: t,
                    period_ns: p,
                    from,
                });
            }
        }
        self.next = self.streams.iter().filter_map(|(_, s)| s.deadline()).min();
        out.sort_by_key(|g| match g {
            PdoGap::Missing { key, .. } | PdoGap::Back { key, .. } => *key,
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sync_period_is_learned_and_off_time_intervals_counted() {
        let mut s = SyncTiming::default();
        let mut t = 0;
        for i in 0..100u64 {
            t += if i == 50 { 15 * MS } else { 10 * MS };
            s.sync(i + 1, t);
        }
        let sum = s.summary().unwrap();
        assert_eq!(sum.period_ns, 10 * MS);
        assert_eq!(sum.off, 1);
        assert_eq!(sum.max_ns, 15 * MS);
        assert_eq!(s.kept[0].frame, 51);
    }

    #[test]
    fn a_regular_pdo_that_stops_is_missing_once_and_back_when_it_comes() {
        let mut p = PdoTiming::default();
        let key = (NodeKey::new(0, 2), true, 1);
        for i in 0..10u64 {
            assert_eq!(p.pdo(key, i + 1, i * 10 * MS), None);
        }
        assert!(p.due(100 * MS).is_empty());
        let gaps = p.due(200 * MS);
        assert!(matches!(
            gaps[..],
            [PdoGap::Missing {
                last_frame: 10,
                from: PeriodFrom::Measured,
                ..
            }]
        ));
        assert!(p.due(300 * MS).is_empty(), "reported once");
        assert_eq!(p.pdo(key, 11, 500 * MS), Some(PdoGap::Back { key, gap_ns: 410 * MS }));
    }

    #[test]
    fn irregular_pdos_are_not_judged_without_an_event_timer() {
        let mut p = PdoTiming::default();
        let key = (NodeKey::new(0, 2), true, 2);
        for (i, t) in [0u64, 5, 50, 55, 200, 210, 400, 401, 700].iter().enumerate() {
            p.pdo(key, i as u64 + 1, t * MS);
        }
        assert!(p.due(10_000 * MS).is_empty());
        p.event_timer(key, 100);
        p.pdo(key, 10, 10_000 * MS);
        assert_eq!(p.due(10_150 * MS), Vec::new());
        assert!(matches!(
            p.due(10_201 * MS)[..],
            [PdoGap::Missing {
                from: PeriodFrom::EventTimer,
                ..
            }]
        ));
    }
}
