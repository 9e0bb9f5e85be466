//! The trace: the one analysis pipeline. Frames go in through [`Trace::push`]; the views
//! chosen at construction ([`Views`]) are derived from them as they come. The TUI keeps
//! them all ([`Views::All`]); each headless command keeps only the view it prints
//! ([`Views::Summary`], [`Views::Transactions`], [`Views::Events`], [`Views::Diagnosis`],
//! [`Views::SyncCycles`]),
//! a fast path of the same `push`, not a copy of its loop; [`Views::Frames`] decodes every
//! frame with its label for `cotui decode --filter`.
//!
//! Decoding is stateful (learned COB-IDs and PDO mappings, modes of operation, SDO transfer
//! context), so a frame's label depends on everything before it. With every view, the indexing
//! pass runs one [`Decoder`] over every frame as it arrives, but keeps only the frame's kind
//! and node (in the store), the SDO transactions (see [`Transfers`]), node and COB-ID
//! statistics and the numeric signal series. Every [`CHECKPOINT`] frames it keeps a clone of
//! the decoder state. To show rows `a..b`, [`Trace::decode_range`] clones the checkpoint at
//! or before `a`, replays the frames up to `a` through it (cheaply: only SDO and PDO frames
//! change state) and decodes `a..b`. So labels are exact, at most `CHECKPOINT` frames are
//! replayed per window, and the checkpoints cost well under a byte per frame.

use super::diagnose::{Diagnoser, feed};
use super::liveness::EventTracker;
use super::nodes::Nodes;
use super::series::Series;
use super::stats::Stats;
use super::store::Store;
use super::sync_cycles::SyncCycles;
use super::transfer_list::TransferList;
use super::transfers::Transfers;
use super::values::Values;
use crate::decode::{Body, Decoded, Decoder, Kind};
use crate::frame::{Frame, Interfaces, NodeKey};
use crate::output::busload::Bitrate;
use crate::output::summary::Summary;
use crate::sdo::Transaction;
use crate::wire::WireFigures;

/// Which views a [`Trace`] derives from its frames, chosen once at construction. Each
/// mode other than [`Views::All`] is the fast path of one headless command: it decodes
/// only as far as its view needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Views {
    /// Everything the TUI panes show: the store with decoder checkpoints, the SDO
    /// transactions, nodes, statistics, series, values and the diagnosis.
    All,
    /// Only the totals per kind and node, [`Trace::summary`] (`cotui decode --summary`):
    /// frames are classified, not decoded.
    Summary,
    /// Only the SDO transfers, [`Trace::transactions`] (`cotui decode --transactions`):
    /// frames are tracked, not labelled.
    Transactions,
    /// Only the bus events, [`Trace::events`] (`cotui decode --events`): heartbeats,
    /// EMCYs and error frames are decoded, SDO frames tracked.
    Events,
    /// Only the diagnosis, [`Trace::diagnosis`] (`cotui diagnose`): frames are decoded as
    /// far as the diagnosis reads them.
    Diagnosis,
    /// Only the SYNC cycles, [`Trace::cycles`] (`cotui decode --sync-cycles`): frames are
    /// routed, SDO frames tracked (for the windows and transmission types they write).
    SyncCycles,
    /// Every frame decoded with its label, [`Trace::take_decoded`], and the SDO transfers
    /// each completes, [`Trace::take_transactions`] (`cotui decode --filter`, which judges
    /// and prints them; the totals of `--filter --summary` go to [`Trace::summary`]).
    Frames,
}

/// Frames between two decoder checkpoints.
pub const CHECKPOINT: usize = 8192;

/// Everything the panes show (or, in a headless mode, the one view a command prints),
/// built incrementally.
pub struct Trace {
    views: Views,
    /// Frames pushed (the positions the decoder numbers them by).
    pushed: u64,
    /// With [`Views::Frames`]: the last frame, decoded, until taken.
    decoded: Option<Decoded>,
    /// The frames (kept with [`Views::All`] only).
    pub store: Store,
    /// Interface names: those of the frames' source (see [`Trace::name_interfaces`]).
    pub ifaces: Interfaces,
    decoder: Decoder,
    /// The decoder as it was for a fresh start (used when nothing is checkpointed yet).
    initial: Decoder,
    checkpoints: Vec<Decoder>,
    /// With [`Views::All`]: SDO transactions in order of completion, then (once the input
    /// ended) those left running, as incomplete: the transfers `cotui decode
    /// --transactions` lists.
    pub transactions: TransferList,
    /// With [`Views::Transactions`] and [`Views::Frames`]: the same transfers, until taken.
    listed: Vec<Transaction>,
    transfers: Transfers,
    /// Per-node state.
    pub nodes: Nodes,
    /// Per-COB-ID statistics and bus load.
    pub stats: Stats,
    /// Numeric values over time (PDO signals, SDO reads).
    pub series: Series,
    /// The last value seen per node and object (SDO transfers, PDO signals).
    pub values: Values,
    /// What went wrong so far (the same diagnosis as `cotui diagnose`).
    pub diagnosis: Diagnoser,
    /// Frames per kind and node (kept with [`Views::Summary`]; with [`Views::Frames`],
    /// the caller counts the frames its filter takes).
    pub summary: Summary,
    /// The SYNC cycles and their synchronous TPDOs (kept with [`Views::All`] and
    /// [`Views::SyncCycles`]).
    pub cycles: SyncCycles,
    /// Bus events not yet taken (kept with [`Views::Events`] only).
    pub events: EventTracker,
    /// Changes of [`Trace::diagnosis`] (frames and clock ticks taken), for caches.
    pub diagnosis_version: u64,
}

impl Trace {
    /// An empty trace decoded with `decoder`, keeping every view (the TUI's).
    pub fn new(decoder: Decoder, bitrate: impl Into<Bitrate>) -> Trace {
        Trace::with_views(decoder, bitrate, Views::All)
    }

    /// An empty trace for a headless command, keeping `views` (the bus load, kept with
    /// [`Views::All`] only, would be counted against 500 kbit/s).
    pub fn headless(decoder: Decoder, views: Views) -> Trace {
        Trace::with_views(decoder, Bitrate::ASSUMED, views)
    }

    /// An empty trace decoded with `decoder` that keeps `views`.
    pub fn with_views(decoder: Decoder, bitrate: impl Into<Bitrate>, views: Views) -> Trace {
        let nodes = Nodes::new(&decoder);
        let diagnosis = Diagnoser::new(|n| decoder.dictionary(n));
        let events = EventTracker::new(|n| decoder.dictionary(n));
        let cycles = match views {
            Views::All | Views::SyncCycles => SyncCycles::new(|n| decoder.dictionary(n)),
            _ => SyncCycles::default(),
        };
        Trace {
            cycles,
            views,
            pushed: 0,
            decoded: None,
            diagnosis,
            summary: Summary::default(),
            events,
            diagnosis_version: 0,
            store: Store::new(),
            ifaces: Interfaces::default(),
            initial: decoder.clone(),
            decoder,
            checkpoints: Vec::new(),
            transactions: TransferList::default(),
            listed: Vec::new(),
            transfers: Transfers::new(),
            nodes,
            stats: Stats::new(bitrate),
            series: Series::default(),
            values: Values::default(),
        }
    }

    /// Forgets every frame (a replay seeking backwards starts over).
    pub fn clear(&mut self) {
        let bitrate = self.stats.bitrate().clone();
        *self = Trace::with_views(self.initial.clone(), bitrate, self.views);
    }

    /// The views this trace keeps.
    pub fn views(&self) -> Views {
        self.views
    }

    /// A new input begins whose frames number their interfaces from 0 again (a headless
    /// command reads each log file with its own interface table).
    pub fn new_input(&mut self) {
        self.ifaces = Interfaces::default();
    }

    /// Takes note of the interface table of the frames' source, which grows as names
    /// appear: call it with the newest before pushing its frames.
    pub fn name_interfaces(&mut self, source: &Interfaces) {
        let known = self.ifaces.names().len();
        for name in source.names().iter().skip(known) {
            self.ifaces.intern(name);
        }
        if matches!(self.views, Views::Summary | Views::Frames) {
            self.summary.name_interfaces(source);
        }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    /// True when no frame arrived yet.
    pub fn is_empty(&self) -> bool {
        self.store.is_empty()
    }

    /// Adds one frame: derives the views kept from it. One path for every mode: the
    /// frame is numbered, decoded as far as the views need (with [`Views::All`]:
    /// checkpointed, classified into the store, counted in nodes and statistics), then the
    /// SDO transfers it completed go to the views that take them.
    pub fn push(&mut self, frame: &Frame) {
        self.push_figured(frame, None);
    }

    /// [`Trace::push`] of a frame whose wire figures were worked out already (by the
    /// thread that read it); `None`: worked out here when a view counts bits.
    pub fn push_figured(&mut self, frame: &Frame, figures: Option<WireFigures>) {
        let pos = self.pushed;
        self.pushed += 1;
        let all = self.views == Views::All;
        if all {
            if (pos as usize).is_multiple_of(CHECKPOINT) {
                self.checkpoints.push(self.decoder.clone());
            }
            self.nodes.tick(frame.ts_ns);
            self.diagnosis_version += 1;
        }
        self.decoder.set_seq(pos);
        match self.views {
            Views::All => {
                let peeked @ (kind, node, _) = self.diagnose(frame);
                self.cycles.frame(frame, pos, peeked);
                let at = self.store.push(frame, kind, node);
                self.stats.add(frame, at, figures);
                if let Some(n) = node {
                    self.nodes.frame(NodeKey::of(frame, n), frame.ts_ns);
                }
            }
            Views::Diagnosis => {
                self.diagnose(frame);
            }
            Views::Summary => {
                let (kind, node) = self.decoder.classify(frame);
                self.summary.add_frame(frame, kind, node, figures);
            }
            // Only the transfers are kept: frames are tracked, not labelled.
            Views::Transactions => self.decoder.track(frame),
            // Only these kinds carry events; SDO frames are tracked by classify.
            Views::Events => match self.decoder.classify(frame) {
                (Kind::Heartbeat | Kind::Emcy | Kind::ErrorFrame, _) => {
                    let d = self.decoder.decode(frame);
                    self.events.frame(frame, self.ifaces.name(frame.iface), &d);
                    self.decoder.recycle(d);
                }
                _ => self.events.tick(frame.ts_ns),
            },
            Views::SyncCycles => {
                let peeked = self.decoder.peek(frame);
                if matches!(peeked.0, Kind::SdoRx | Kind::SdoTx) {
                    self.decoder.classify(frame);
                }
                self.cycles.frame(frame, pos, peeked);
            }
            Views::Frames => self.decoded = Some(self.decoder.decode(frame)),
        }
        self.completed();
    }

    /// The frame as far as the diagnosis (and with [`Views::All`], the panes) read it:
    /// PDOs decoded to their values, without the names, texts and labels that rows decode
    /// anew from checkpoints; other frames through the diagnosis feed (SDO frames tracked
    /// without labels, the rest only routed). Returns the frame's kind, node and PDO number.
    fn diagnose(&mut self, frame: &Frame) -> (Kind, Option<u8>, u16) {
        let peeked @ (kind, _, _) = self.decoder.peek(frame);
        let iface = self.ifaces.name(frame.iface);
        let all = self.views == Views::All;
        if all && matches!(kind, Kind::Tpdo | Kind::Rpdo) {
            let d = self.decoder.pdo_values(frame, peeked);
            self.diagnosis.frame(frame, iface, &d);
            self.observe(frame, &d);
        } else if let Some(d) = feed(&mut self.decoder, &mut self.diagnosis, frame, peeked, iface) {
            if all {
                match d.kind {
                    Kind::ErrorFrame => self.nodes.error_frame(frame.ts_ns, iface, frame.id, frame.payload()),
                    Kind::Emcy | Kind::Heartbeat => self.observe(frame, &d),
                    _ => {}
                }
            }
            self.decoder.recycle(d);
        }
        peeked
    }

    /// The SDO transfers the last frame completed, to the views that take them.
    fn completed(&mut self) {
        let done = self.transfers.completed(&mut self.decoder);
        if done.is_empty() {
            return;
        }
        match self.views {
            Views::All => {
                for t in done {
                    self.diagnosis.transaction(&t);
                    self.nodes.transaction(&t);
                    self.series.transaction(&t, self.decoder.dictionary(t.node));
                    self.values.transaction(&t, self.decoder.dictionary(t.node));
                    self.cycles.transaction(&t);
                    self.transactions.push(t);
                }
            }
            Views::Transactions | Views::Frames => self.listed.extend(done),
            Views::Events => done.iter().for_each(|t| self.events.transaction(t)),
            Views::Diagnosis => done.iter().for_each(|t| self.diagnosis.transaction(t)),
            Views::SyncCycles => done.iter().for_each(|t| self.cycles.transaction(t)),
            // None is kept: memory stays flat.
            Views::Summary => {}
        }
    }

    /// With [`Views::Frames`]: the last frame pushed, decoded with its label (once).
    pub fn take_decoded(&mut self) -> Option<Decoded> {
        self.decoded.take()
    }

    /// The input ended (a loaded log read to its end): the SDO transfers still running
    /// are listed as incomplete, as `cotui decode --transactions` lists them. They were
    /// not completed, so nodes and values do not take them; the diagnosis of `cotui
    /// diagnose` ([`Views::Diagnosis`]) sees them end (it opens no incident for them).
    pub fn end_of_input(&mut self) {
        let rest = self.transfers.end(&mut self.decoder);
        match self.views {
            Views::All => rest.into_iter().for_each(|t| self.transactions.push(t)),
            Views::Transactions => self.listed.extend(rest),
            Views::Diagnosis => {
                for t in &rest {
                    self.diagnosis.transaction(t);
                }
            }
            Views::SyncCycles => self.cycles.end(),
            Views::Summary | Views::Events | Views::Frames => {}
        }
    }

    /// Takes the SDO transactions listed so far (a headless command prints them as they
    /// come, keeping memory flat).
    pub fn take_transactions(&mut self) -> Vec<Transaction> {
        std::mem::take(&mut self.listed)
    }

    fn observe(&mut self, frame: &Frame, d: &Decoded) {
        let n = d.node.unwrap_or(0);
        let key = NodeKey::of(frame, n);
        let (profile, mode) = (self.decoder.dictionary(n).profile_name(), self.decoder.mode(key));
        match &d.body {
            Body::Heartbeat(h) => self.nodes.heartbeat(key, frame.ts_ns, h),
            Body::Emcy(e) => self.nodes.emcy(key, frame.ts_ns, e),
            Body::Pdo(p) => {
                self.nodes.pdo(key, p, profile, mode);
                self.series.pdo(key, frame.ts_ns, p, self.decoder.dictionary(n));
                self.values.pdo(key, frame.ts_ns, p, mode);
                return;
            }
            _ => {}
        }
        self.nodes.profile(key, profile, mode);
    }

    /// The capture clock reached `now_ns` with no new frame (live or a running replay):
    /// node liveness and the diagnosis catch up.
    pub fn tick(&mut self, now_ns: u64) {
        match self.views {
            Views::All => {
                self.nodes.tick(now_ns);
                self.stats.tick(now_ns);
                self.diagnosis.tick(now_ns);
                self.diagnosis_version += 1;
            }
            Views::Diagnosis => self.diagnosis.tick(now_ns),
            Views::Events => self.events.tick(now_ns),
            Views::Summary | Views::Transactions | Views::SyncCycles | Views::Frames => {}
        }
    }

    /// Decodes the frames `start..end` exactly as the indexing pass did.
    pub fn decode_range(&self, start: usize, end: usize) -> Vec<Decoded> {
        let positions: Vec<usize> = (start..end.min(self.len())).collect();
        self.decode_positions(&positions)
    }

    /// Decodes the frames at `positions` (rising) exactly as the indexing pass did. One
    /// decoder walks forward; it restarts from a checkpoint only when that is closer.
    pub fn decode_positions(&self, positions: &[usize]) -> Vec<Decoded> {
        self.decode_with(&mut None, positions)
    }

    /// Like [`Trace::decode_positions`], going on from `walker` (a decoder and the next
    /// position it would take) when that is closer than a checkpoint, and leaving the
    /// walker after the last position so the next window can go on from there.
    pub fn decode_with(&self, walker: &mut Option<(Decoder, usize)>, positions: &[usize]) -> Vec<Decoded> {
        let mut out = Vec::with_capacity(positions.len());
        for &pos in positions {
            if pos >= self.len() {
                break;
            }
            let base = pos / CHECKPOINT * CHECKPOINT;
            let (dec, next) = match walker.take() {
                Some((d, next)) if next <= pos && next >= base => (d, next),
                _ => (
                    self.checkpoints.get(pos / CHECKPOINT).unwrap_or(&self.initial).clone(),
                    base,
                ),
            };
            let mut dec = dec;
            for i in next..pos {
                let p = self.store.packed(i);
                if matches!(p.kind(), Kind::SdoRx | Kind::SdoTx | Kind::Tpdo | Kind::Rpdo) {
                    dec.set_seq(i as u64);
                    dec.decode(&self.store.frame(i));
                    dec.forget_transactions();
                }
            }
            dec.set_seq(pos as u64);
            out.push(dec.decode(&self.store.frame(pos)));
            dec.forget_transactions();
            *walker = Some((dec, pos + 1));
        }
        out
    }

    /// The dictionary name the decoder uses for `node`.
    pub fn object_name(&self, node: u8, index: u16, sub: u8) -> Option<String> {
        self.decoder.dictionary(node).name(index, sub).map(str::to_string)
    }

    /// The decoder state after the last frame.
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// Number of decoder checkpoints kept.
    pub fn checkpoint_count(&self) -> usize {
        self.checkpoints.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::Dictionary;

    fn decoder() -> Decoder {
        Decoder::new(Dictionary::default(), Vec::new())
    }

    #[test]
    fn indexed_pdo_values_and_series_names_equal_a_full_decode() {
        let read = |p: &std::path::Path| std::fs::read(p);
        let b = crate::od::bind::Bindings::from_args(&["1=aimotor".to_string(), "2=aimotor".to_string()], &[], &read)
            .unwrap();
        let mut t = Trace::new(Decoder::from_bindings(&b), 500_000);
        let mut full = Decoder::from_bindings(&b);
        let mut values = std::collections::BTreeMap::new();
        let mut names = std::collections::BTreeMap::new();
        for (i, f) in crate::sim::synth::Traffic::new(20_000, 0).enumerate() {
            t.push(&f);
            full.set_seq(i as u64);
            let d = full.decode(&f);
            if let (Body::Pdo(p), Some(n)) = (&d.body, d.node) {
                let n = NodeKey::of(&f, n);
                for s in &p.signals {
                    values.insert((n, s.index, s.sub), s.value.clone());
                    names.entry((n, s.index, s.sub)).or_insert_with(|| s.name.clone());
                }
            }
            full.take_transactions();
        }
        assert!(values.len() > 1, "the traffic maps PDO signals");
        let mut compared = 0;
        for (&(n, index, sub), v) in &values {
            let seen = t.values.get(n, index, sub).and_then(|e| e.last.as_ref()).unwrap();
            // An SDO transfer after the last PDO carries the last value then.
            if seen.via == crate::analysis::values::Via::Pdo {
                assert_eq!(&seen.value, v, "{n:?} {index:04X}:{sub}");
                compared += 1;
            }
        }
        assert!(compared > 0);
        for (key, name) in &names {
            if let Some(line) = t.series.get(key) {
                assert_eq!(&line.name, name);
            }
        }
        assert!(names.keys().any(|k| t.series.get(k).is_some()));
    }

    #[test]
    fn window_labels_equal_a_full_sequential_decode() {
        let mut t = Trace::new(decoder(), 500_000);
        let frames: Vec<Frame> = crate::sim::synth::Traffic::new(3 * CHECKPOINT as u64 + 77, 0).collect();
        for f in &frames {
            t.push(f);
        }
        let mut full = decoder();
        let want: Vec<String> = frames
            .iter()
            .enumerate()
            .map(|(i, f)| {
                full.set_seq(i as u64);
                full.decode(f).label
            })
            .collect();
        for start in [0, CHECKPOINT - 3, 2 * CHECKPOINT + 40] {
            let got: Vec<String> = t.decode_range(start, start + 30).into_iter().map(|d| d.label).collect();
            assert_eq!(got, want[start..start + 30]);
        }
        let scattered = [5, 9000, 9001, 2 * CHECKPOINT + 1, 3 * CHECKPOINT + 70];
        let got: Vec<String> = t.decode_positions(&scattered).into_iter().map(|d| d.label).collect();
        let want_s: Vec<String> = scattered.iter().map(|&i| want[i].clone()).collect();
        assert_eq!(got, want_s);
        assert!(!t.transactions.is_empty());
        let first = t.transactions.get(0).expect("a transfer");
        let f = t.store.packed(first.frames[0] as usize - 1);
        assert!(matches!(f.kind(), Kind::SdoRx | Kind::SdoTx));
    }
}
