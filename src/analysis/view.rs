//! A filtered view of the trace: the positions of matching frames, built incrementally.
//!
//! With no filter the view is the whole trace and holds no vector. Otherwise `rows` holds
//! the matching positions in order (4 bytes per match). Scanning runs in slices under a
//! time budget so the screen stays live while a filter goes through tens of millions of
//! frames. A frame is judged first on what the store keeps (kind, node, ID, time); only
//! frames whose result depends on their decoded form are decoded, one decoder walking
//! forward through the slice. With an `abort` condition, an SDO frame whose transfer has
//! not ended yet waits until it has (or until the source ends: [`View::settle`]).

use super::filter::{Ended, Facts, Filter, Subject, Transfer, Tri};
use super::trace::Trace;
use crate::decode::{Decoded, Decoder, Kind};
use std::collections::HashMap;
use std::time::{Duration, Instant};

/// A filtered view.
#[derive(Default)]
pub struct View {
    /// The filter in force.
    pub filter: Filter,
    rows: Vec<u32>,
    scanned: usize,
    /// Trace position -> index of the completed transaction it belongs to (`abort` only).
    transfers: HashMap<u32, u32>,
    transactions_seen: usize,
    /// SDO frames waiting for their transfer to end.
    pending: Vec<u32>,
    /// No more frames will come: a transfer not ended now never will.
    settled: bool,
    /// The decoder that decoded the last frames judged, and the next position it takes.
    walker: Option<(Decoder, usize)>,
}

/// Frames judged between two looks at the time budget (a few milliseconds when every
/// frame is decoded).
const SLICE: usize = 2048;

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

    /// The matching positions found so far (empty for the empty filter).
    pub fn positions(&self) -> &[u32] {
        &self.rows
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
        if self.filter.is_empty() || trace.is_empty() {
            return 100;
        }
        (self.scanned * 100 / trace.len()) as u8
    }

    /// Frames scanned so far.
    pub fn scanned(&self) -> usize {
        self.scanned
    }

    /// Says that no more frames will come (the log is loaded, the replay ended): SDO
    /// frames of transfers that never ended are judged as in no transfer.
    pub fn settle(&mut self) {
        self.settled = true;
    }

    fn subject<'a>(&self, trace: &'a Trace, pos: usize, t0_ns: u64, decoded: Option<&'a Decoded>) -> Subject<'a> {
        let facts = Facts::from(&trace.store.packed(pos));
        let transfer = if !self.filter.needs_transfer() || !matches!(facts.kind, Kind::SdoTx | Kind::SdoRx) {
            Transfer::Known(None)
        } else if let Some(&k) = self.transfers.get(&(pos as u32)) {
            Transfer::Known(trace.transactions.outcome(k as usize).map(|o| Ended::of(&o)))
        } else if self.settled {
            Transfer::Known(None)
        } else {
            Transfer::Unknown
        };
        Subject {
            facts,
            t0_ns,
            iface: trace.ifaces.name(trace.store.packed(pos).iface),
            decoded,
            transfer,
        }
    }

    /// Scans new frames for up to `budget` (at least one slice); returns true when work is left.
    pub fn advance(&mut self, trace: &Trace, budget: Duration) -> bool {
        if self.filter.is_empty() || trace.is_empty() {
            return false;
        }
        let start = Instant::now();
        let t0 = trace.store.packed(0).ts_ns;
        if self.filter.needs_transfer() {
            self.index_transfers(trace);
            self.resolve_pending(trace, t0);
        }
        let mut walker = self.walker.take();
        while self.scanned < trace.len() {
            let end = ((self.scanned / SLICE + 1) * SLICE).min(trace.len());
            let mut undecided = Vec::new();
            let mut hits = Vec::new();
            for pos in self.scanned..end {
                match self.filter.eval(&self.subject(trace, pos, t0, None)) {
                    Tri::True => hits.push(pos as u32),
                    Tri::Unknown => undecided.push(pos),
                    Tri::False => {}
                }
            }
            if !undecided.is_empty() {
                let decoded = trace.decode_with(&mut walker, &undecided);
                for (&pos, d) in undecided.iter().zip(&decoded) {
                    match self.filter.eval(&self.subject(trace, pos, t0, Some(d))) {
                        Tri::True => hits.push(pos as u32),
                        Tri::Unknown => self.pending.push(pos as u32),
                        Tri::False => {}
                    }
                }
                hits.sort_unstable();
            }
            self.rows.extend_from_slice(&hits);
            self.scanned = end;
            if start.elapsed() >= budget {
                break;
            }
        }
        self.walker = walker;
        self.scanned < trace.len()
    }

    /// Adds the frames of newly completed transactions to the position index.
    fn index_transfers(&mut self, trace: &Trace) {
        let seen = self.transactions_seen;
        for (k, t) in trace
            .transactions
            .iter_from(seen)
            .enumerate()
            .map(|(i, t)| (seen + i, t))
        {
            for &seq in &t.frames {
                self.transfers.insert(seq.saturating_sub(1) as u32, k as u32);
            }
        }
        self.transactions_seen = trace.transactions.len();
    }

    /// Judges the waiting SDO frames whose transfer has ended (all of them once settled).
    fn resolve_pending(&mut self, trace: &Trace, t0: u64) {
        let ready: Vec<usize> = self
            .pending
            .iter()
            .filter(|p| self.settled || self.transfers.contains_key(p))
            .map(|&p| p as usize)
            .collect();
        if ready.is_empty() {
            return;
        }
        self.pending
            .retain(|p| !(self.settled || self.transfers.contains_key(p)));
        let decoded = trace.decode_positions(&ready);
        for (&pos, d) in ready.iter().zip(&decoded) {
            if self.filter.eval(&self.subject(trace, pos, t0, Some(d))) == Tri::True {
                let at = self.rows.partition_point(|&p| (p as usize) < pos);
                self.rows.insert(at, pos as u32);
            }
        }
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

    #[test]
    fn an_abort_filter_waits_for_the_transfer_to_end() {
        let mut t = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        let up = crate::frame::Frame::classic(0x602, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]);
        t.push(&crate::frame::Frame::classic(0x702, &[0x05]));
        t.push(&up);
        let mut aborted = View::new(Filter::parse("abort").unwrap());
        let mut other = View::new(Filter::parse("not abort").unwrap());
        aborted.advance(&t, Duration::from_millis(50));
        other.advance(&t, Duration::from_millis(50));
        // The upload has no answer yet: only the heartbeat is judged.
        assert_eq!((aborted.len(&t), other.positions()), (0, &[0u32][..]));
        t.push(&crate::frame::Frame::classic(0x582, &[0x80, 0x41, 0x60, 0, 0, 0, 2, 6]));
        t.push(&up);
        aborted.advance(&t, Duration::from_millis(50));
        other.advance(&t, Duration::from_millis(50));
        assert_eq!(aborted.positions(), [1, 2]);
        // The second upload never ends: judged as in no transfer once the source ended.
        assert_eq!(other.positions(), [0]);
        other.settle();
        other.advance(&t, Duration::from_millis(50));
        assert_eq!(other.positions(), [0, 3]);
    }
}
