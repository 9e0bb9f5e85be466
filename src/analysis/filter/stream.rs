//! Filtering a stream of decoded frames in order (`cotui decode --filter`): each frame
//! is judged as it comes; an SDO frame whose result depends on how its transfer ends
//! (`abort`) waits until the transfer is complete, and the frames after it wait with it
//! so the output keeps the input's order. Judged exactly as a filtered view of the same
//! frames ([`crate::analysis::view::View`]).

use super::{Ended, Facts, Filter, Subject, Transfer, Tri};
use crate::decode::{Decoded, Kind};
use crate::sdo::Transaction;
use std::collections::{HashMap, VecDeque};

/// One frame in the queue: its output when it matches, or what it takes to judge it.
struct Entry<T> {
    pos: u64,
    out: Option<T>,
    waiting: Option<(Facts, Decoded, String)>,
}

/// The filter over a stream; `T` is what a matching frame gives (e.g. its output line).
pub struct Stream<T> {
    filter: Filter,
    t0_ns: Option<u64>,
    queue: VecDeque<Entry<T>>,
}

impl<T> Stream<T> {
    /// A stream filtered by `filter`.
    pub fn new(filter: Filter) -> Stream<T> {
        Stream {
            filter,
            t0_ns: None,
            queue: VecDeque::new(),
        }
    }

    /// Takes the frame at position `pos` (0-based, the decoder's sequence numbers minus
    /// one), with what the store keeps of it and its interface's name, decoded as `d`; `completed` are the transfers its decoding completed. `out`
    /// makes what a match gives (called only for frames that match or may match).
    pub fn frame(
        &mut self,
        pos: u64,
        (facts, iface): (Facts, &str),
        d: Decoded,
        completed: &[Transaction],
        out: impl FnOnce(&Decoded) -> T,
    ) {
        let t0 = *self.t0_ns.get_or_insert(facts.ts_ns);
        let mut of: HashMap<u64, &Transaction> = HashMap::new();
        if self.filter.needs_transfer() {
            for t in completed {
                for &seq in &t.frames {
                    of.insert(seq.saturating_sub(1), t);
                }
            }
            for e in self.queue.iter_mut() {
                if let Some(t) = of.get(&e.pos) {
                    judge(&self.filter, e, t0, Transfer::Known(Some(Ended::of(&t.outcome))));
                }
            }
        }
        let transfer = match of.get(&pos) {
            Some(t) => Transfer::Known(Some(Ended::of(&t.outcome))),
            None if self.filter.needs_transfer() && matches!(facts.kind, Kind::SdoTx | Kind::SdoRx) => {
                Transfer::Unknown
            }
            None => Transfer::Known(None),
        };
        let subject = |decoded| Subject {
            facts,
            t0_ns: t0,
            iface,
            decoded,
            transfer,
        };
        let mut entry = Entry {
            pos,
            out: None,
            waiting: None,
        };
        match self.filter.eval(&subject(None)) {
            Tri::False => {}
            Tri::True => entry.out = Some(out(&d)),
            Tri::Unknown => match self.filter.eval(&subject(Some(&d))) {
                Tri::False => {}
                Tri::True => entry.out = Some(out(&d)),
                Tri::Unknown => {
                    entry.out = Some(out(&d));
                    entry.waiting = Some((facts, d, iface.to_string()));
                }
            },
        }
        if entry.waiting.is_some() || !self.queue.is_empty() || entry.out.is_some() {
            self.queue.push_back(entry);
        }
    }

    /// The judged matches, in input order, up to the first frame still waiting.
    pub fn ready(&mut self) -> Vec<T> {
        let mut out = Vec::new();
        while self.queue.front().is_some_and(|e| e.waiting.is_none()) {
            if let Some(x) = self.queue.pop_front().and_then(|e| e.out) {
                out.push(x);
            }
        }
        out
    }

    /// The input ended: frames of transfers that never ended are judged as in none.
    pub fn finish(&mut self) -> Vec<T> {
        let t0 = self.t0_ns.unwrap_or(0);
        for e in self.queue.iter_mut() {
            judge(&self.filter, e, t0, Transfer::Known(None));
        }
        self.ready()
    }
}

/// Judges a waiting entry now that its transfer is known.
fn judge<T>(filter: &Filter, e: &mut Entry<T>, t0_ns: u64, transfer: Transfer) {
    let Some((facts, d, iface)) = &e.waiting else { return };
    let s = Subject {
        facts: *facts,
        t0_ns,
        iface,
        decoded: Some(d),
        transfer,
    };
    if filter.eval(&s) != Tri::True {
        e.out = None;
    }
    e.waiting = None;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::trace::Trace;
    use crate::analysis::view::View;
    use crate::decode::Decoder;
    use crate::od::Dictionary;
    use std::time::Duration;

    /// The stream gives the same frames, in order, as a filtered view of the same trace.
    #[test]
    fn a_stream_selects_what_a_view_selects() {
        let frames: Vec<crate::frame::Frame> = crate::sim::synth::Traffic::new(30_000, 5).collect();
        let mut trace = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        for f in &frames {
            trace.push(f);
        }
        for text in [
            "abort",
            "not abort sdo",
            "abort 0x0602 or node 3 hb",
            "sdo !(6060 or abort)",
            "id 580-5ff time 0.5-1.5",
            "\"segment\" or emcy",
        ] {
            let f = Filter::parse(text).unwrap();
            let mut view = View::new(f.clone());
            view.settle();
            while view.advance(&trace, Duration::from_millis(50)) {}
            let want: Vec<u64> = view.positions().iter().map(|&p| u64::from(p)).collect();
            assert!(!want.is_empty(), "{text}");
            let mut dec = Decoder::new(Dictionary::default(), Vec::new());
            let mut s = Stream::new(f);
            let mut got = Vec::new();
            for (i, fr) in frames.iter().enumerate() {
                dec.set_seq(i as u64);
                let d = dec.decode(fr);
                let done = dec.take_transactions();
                let facts = Facts {
                    ts_ns: fr.ts_ns,
                    id: fr.id,
                    flags: fr.flags.0,
                    kind: d.kind,
                    node: d.node,
                };
                s.frame(i as u64, (facts, ""), d, &done, |_| i as u64);
                got.extend(s.ready());
            }
            got.extend(s.finish());
            assert_eq!(got, want, "{text}");
        }
    }
}
