//! Per-COB-ID statistics (count, rate, period, jitter) and the bus load over the last second.

use super::store::{Packed, Store};
use std::collections::BTreeMap;

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
    last_gap: f64,
    sum_gap: f64,
    sum_gap2: f64,
}

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
    /// Frames per second over the identifier's span.
    pub fn rate(&self) -> f64 {
        match self.period() {
            Some(p) if p > 0.0 => 1.0 / p,
            _ => 0.0,
        }
    }
}

/// Statistics of every identifier plus the bus load.
pub struct Stats {
    /// Each identifier's index in `entries`, in id order.
    ids: BTreeMap<(bool, u32), u32>,
    entries: Vec<IdStats>,
    /// Index in `entries` (+1, 0 for none) of each 11-bit id: no map search per frame.
    base: Vec<u32>,
    bitrate: u64,
    window_bits: u64,
    window_start: usize,
}

impl Stats {
    /// Empty statistics for a bus at `bitrate` bit/s.
    pub fn new(bitrate: u64) -> Stats {
        Stats {
            ids: BTreeMap::new(),
            entries: Vec::new(),
            base: vec![0; 0x800],
            bitrate: bitrate.max(1),
            window_bits: 0,
            window_start: 0,
        }
    }

    /// The bus bit rate used for the load.
    pub fn bitrate(&self) -> u64 {
        self.bitrate
    }

    /// Adds the frame just stored (the last one in `store`).
    pub fn add(&mut self, p: &Packed, store: &Store) {
        let i = self.index(p.is_ext(), p.id);
        let s = &mut self.entries[i];
        if s.count == 0 {
            s.first_ns = p.ts_ns;
        } else {
            let gap = p.ts_ns.saturating_sub(s.last_ns) as f64 / 1e9;
            s.sum_gap += gap;
            s.sum_gap2 += gap * gap;
            s.last_gap = gap;
            s.prev_pos = Some(s.last_pos);
        }
        s.last_pos = store.len() - 1;
        s.count += 1;
        s.last_ns = p.ts_ns;
        self.window_bits += p.wire_bits();
        let since = p.ts_ns.saturating_sub(1_000_000_000);
        while self.window_start < store.len() && store.packed(self.window_start).ts_ns < since {
            self.window_bits -= store.packed(self.window_start).wire_bits();
            self.window_start += 1;
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
        self.window_bits as f64 * 100.0 / self.bitrate as f64
    }

    /// Frames in the last second of the trace.
    pub fn window_frames(&self, store: &Store) -> usize {
        store.len() - self.window_start
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
    use crate::decode::Kind;
    use crate::frame::Frame;

    #[test]
    fn period_jitter_rate_and_load() {
        let mut store = Store::new();
        let mut st = Stats::new(125_000);
        for (i, t) in [0u64, 10, 20, 32, 40].iter().enumerate() {
            let mut f = Frame::classic(0x181, &[i as u8; 8]);
            f.ts_ns = t * 1_000_000;
            let at = store.push(&f, Kind::Tpdo, Some(1));
            st.add(&store.packed(at).clone(), &store);
        }
        let s = st.iter().next().unwrap().1;
        assert_eq!(s.count, 5);
        assert!((s.period().unwrap() - 0.010).abs() < 1e-9);
        assert!(s.jitter().unwrap() > 0.001);
        assert!((s.rate() - 100.0).abs() < 1e-6);
        assert!((s.last_period().unwrap() - 0.008).abs() < 1e-9);
        assert_eq!((s.last_pos, s.prev_pos), (4, Some(3)));
        // 5 base frames of 8 bytes, 135 bits each at worst (see store::wire_bits), in the
        // last second: 675 bits of 125000 = 0.54 %.
        assert!((st.load_percent() - 0.54).abs() < 1e-9, "{}", st.load_percent());
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
            st.add(&store.packed(at).clone(), &store);
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
}
