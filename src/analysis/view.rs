//! A filtered view of the trace: the positions of matching frames, built incrementally.
//!
//! With no filter the view is the whole trace and holds no vector. Otherwise `rows` holds
//! the matching positions in order (4 bytes per match). Scanning runs in slices under a
//! time budget so the screen stays live while a filter goes through tens of millions of
//! frames. Filters on SDO objects or aborts are fed from completed transactions instead
//! of scanning, since a transfer's outcome is known only at its end.

use super::filter::Filter;
use super::trace::{CHECKPOINT, Trace};
use std::time::{Duration, Instant};

/// A filtered view.
#[derive(Default)]
pub struct View {
    /// The filter in force.
    pub filter: Filter,
    rows: Vec<u32>,
    scanned: usize,
    transactions_seen: usize,
}

impl View {
    /// A view with `filter`, not scanned yet.
    pub fn new(filter: Filter) -> View {
        View {
            filter,
            ..View::default()
        }
    }

    /// Rows in the view.
    pub fn len(&self, trace: &Trace) -> usize {
        if self.filter.is_empty() {
            trace.len()
        } else {
            self.rows.len()
        }
    }

    /// True when the view has no row.
    pub fn is_empty(&self, trace: &Trace) -> bool {
        self.len(trace) == 0
    }

    /// The trace position of row `r`.
    pub fn position(&self, r: usize) -> usize {
        if self.filter.is_empty() {
            r
        } else {
            self.rows[r] as usize
        }
    }

    /// The row showing trace position `pos`, or the first row after it.
    pub fn row_of(&self, pos: usize) -> usize {
        if self.filter.is_empty() {
            pos
        } else {
            self.rows.partition_point(|&p| (p as usize) < pos)
        }
    }

    /// Percent of the trace scanned so far (100 when up to date).
    pub fn progress(&self, trace: &Trace) -> u8 {
        if self.filter.is_empty() || self.filter.has_transfer_terms() || trace.is_empty() {
            return 100;
        }
        (self.scanned * 100 / trace.len()) as u8
    }

    /// Scans new frames for up to `budget`; returns true when work is left.
    pub fn advance(&mut self, trace: &Trace, budget: Duration) -> bool {
        if self.filter.is_empty() {
            return false;
        }
        if self.filter.has_transfer_terms() {
            self.add_transfers(trace);
            return false;
        }
        let start = Instant::now();
        while self.scanned < trace.len() {
            let end = ((self.scanned / CHECKPOINT + 1) * CHECKPOINT).min(trace.len());
            if self.filter.needs_label() {
                let decoded = trace.decode_range(self.scanned, end);
                for (k, d) in decoded.iter().enumerate() {
                    let pos = self.scanned + k;
                    if self.filter.matches(trace.store.packed(pos), false, Some(&d.label)) {
                        self.rows.push(pos as u32);
                    }
                }
            } else {
                for pos in self.scanned..end {
                    if self.filter.matches(trace.store.packed(pos), false, None) {
                        self.rows.push(pos as u32);
                    }
                }
            }
            self.scanned = end;
            if start.elapsed() >= budget {
                break;
            }
        }
        self.scanned < trace.len()
    }

    fn add_transfers(&mut self, trace: &Trace) {
        for t in &trace.transactions[self.transactions_seen..] {
            if !self.filter.transaction_matches(t) {
                continue;
            }
            for &seq in &t.frames {
                let pos = seq.saturating_sub(1) as usize;
                if pos >= trace.len() {
                    continue;
                }
                let label = if self.filter.needs_label() {
                    trace.decode_range(pos, pos + 1).pop().map(|d| d.label)
                } else {
                    None
                };
                if self.filter.matches(trace.store.packed(pos), true, label.as_deref()) {
                    let at = self.rows.partition_point(|&p| (p as usize) < pos);
                    if self.rows.get(at) != Some(&(pos as u32)) {
                        self.rows.insert(at, pos as u32);
                    }
                }
            }
        }
        self.transactions_seen = trace.transactions.len();
    }

    /// Bytes held by the row vector.
    pub fn bytes(&self) -> usize {
        self.rows.capacity() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::{Decoder, Kind};
    use crate::od::Dictionary;

    fn trace(n: u64) -> Trace {
        let mut t = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        for f in crate::sim::synth::Traffic::new(n, 0) {
            t.push(&f);
        }
        t
    }

    #[test]
    fn kind_node_text_and_object_filters_select_the_right_rows() {
        let t = trace(20_000);
        let mut v = View::new(Filter::parse("node 2 kind heartbeat").unwrap());
        while v.advance(&t, Duration::from_millis(50)) {}
        assert!(!v.is_empty(&t));
        for r in 0..v.len(&t) {
            let p = t.store.packed(v.position(r));
            assert_eq!((p.kind(), p.node(), p.id), (Kind::Heartbeat, Some(2), 0x702));
        }
        let mut text = View::new(Filter::parse("\"heartbeat node 2\"").unwrap());
        while text.advance(&t, Duration::from_millis(50)) {}
        assert_eq!(text.len(&t), v.len(&t));
        let mut obj = View::new(Filter::parse("6041").unwrap());
        obj.advance(&t, Duration::from_millis(50));
        assert!(!obj.is_empty(&t));
        for r in 0..obj.len(&t) {
            assert!(matches!(
                t.store.packed(obj.position(r)).kind(),
                Kind::SdoRx | Kind::SdoTx
            ));
        }
        assert_eq!(v.row_of(v.position(3)), 3);
    }
}
