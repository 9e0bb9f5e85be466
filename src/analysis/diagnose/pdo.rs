//! PDO detector: PDOs that stop arriving within their event time or measured period
//! (`pdo_missing`, or a warning when they come again) and synchronous TPDOs sent after the
//! SYNC window 0x1007 closed (`pdo_late`). Starts from the dictionaries' sync windows and
//! TPDO transmission types, and follows what SDO transfers write to them.

use super::detector::Detector;
use super::timeline::{At, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::analysis::sync_cycles::SyncDefaults;
use crate::analysis::timing::{PdoGap, PdoKey, PdoTiming, PeriodFrom};
use crate::decode::heartbeat::NmtState;
use crate::frame::NodeKey;
use crate::sdo::transaction::{Outcome, Transaction};
use std::collections::{BTreeMap, HashMap};

/// A node-ID's default sync window (ns) and TPDO transmission types, for each interface.
type NodeDefaults = (u8, Option<u64>, Vec<(u16, u8)>);

/// `TPDO3` or `RPDO1`.
fn pdo_name((_, transmit, num): PdoKey) -> String {
    format!("{}PDO{num}", if transmit { "T" } else { "R" })
}

/// Finds missing and late PDOs.
#[derive(Clone, Default)]
pub(super) struct Pdos {
    timing: PdoTiming,
    /// The incident of each PDO that stopped, while it is missing.
    gaps: HashMap<PdoKey, usize>,
    /// The synchronous window length 0x1007 of each node (ns).
    sync_window: BTreeMap<NodeKey, u64>,
    /// The dictionaries' sync windows (ns) and TPDO transmission types per node-ID: each
    /// interface's nodes start from them.
    defaults: Vec<NodeDefaults>,
}

impl Pdos {
    /// Node-ID `node`'s dictionary has `defaults`.
    pub(super) fn add_defaults(&mut self, node: u8, (window, types): &SyncDefaults) {
        if window.is_some() || !types.is_empty() {
            self.defaults.push((node, window.map(|us| us * 1000), types.clone()));
        }
    }

    /// The nodes of interface `iface` start from the dictionaries' defaults.
    pub(super) fn apply_defaults(&mut self, iface: u16) {
        for (n, window, types) in &self.defaults {
            let key = NodeKey::new(iface, *n);
            if let Some(ns) = window {
                self.sync_window.insert(key, *ns);
            }
            for (num, t) in types {
                self.timing.transmission_type((key, true, *num), *t);
            }
        }
    }

    /// PDOs of `node` (None: all nodes) of `iface` stop for a reason (NMT, boot-up): their
    /// silence is no gap.
    pub(super) fn pause(&mut self, iface: u16, node: Option<u8>) {
        self.timing.pause(iface, node);
    }

    /// A PDO of `node` arrived (number `num`, TPDO when `transmit`); `last_sync`: the last
    /// SYNC.
    pub(super) fn arrived(
        &mut self,
        tl: &mut Timeline,
        node: NodeKey,
        transmit: bool,
        num: u16,
        last_sync: Option<At>,
    ) {
        let at = tl.at;
        if transmit
            && let (Some(&window), Some(sync)) = (self.sync_window.get(&node), last_sync)
            && at.t.saturating_sub(sync.t) > window
            && self.timing.synchronous((node, transmit, num))
        {
            let name = pdo_name((node, transmit, num));
            let i = tl.grouped(Some(node), Problem::PdoLate, u32::from(num), at.t);
            let inc = &mut tl.incidents[i];
            inc.status = Status::Warning;
            inc.title = match inc.count {
                1 => format!("{name} sent after the SYNC window closed"),
                n => format!("{name} sent after the SYNC window closed ({n} times)"),
            };
            inc.cause = Some(format!("synchronous window 0x1007 = {} µs", window / 1000));
            let late = at.t.saturating_sub(sync.t) as f64 / 1e6;
            tl.step(i, at, format!("{name} {late:.3} ms after the SYNC (#{})", sync.frame));
        }
        if num > 0
            && let Some(gap) = self.timing.pdo((node, transmit, num), at.frame, at.t)
        {
            self.gap(tl, gap);
        }
    }

    fn gap(&mut self, tl: &mut Timeline, gap: PdoGap) {
        match gap {
            PdoGap::Missing {
                key,
                last_frame,
                last_ns,
                period_ns,
                from,
            } => {
                let n = key.0;
                let node = tl.node(n);
                // PDOs flow in "operational" only; a silent node is its own incident.
                if node.last_state.is_some_and(|(_, s)| s != NmtState::Operational) || node.silence.is_some() {
                    return;
                }
                let name = pdo_name(key);
                let detail = (u32::from(key.1) << 16) | u32::from(key.2);
                let i = tl.grouped(Some(n), Problem::PdoMissing, detail, last_ns);
                let every = match from {
                    PeriodFrom::EventTimer => format!("at least every {:.1} ms (event time)", period_ns as f64 / 1e6),
                    PeriodFrom::Measured => format!("every {:.1} ms (measured)", period_ns as f64 / 1e6),
                };
                let inc = &mut tl.incidents[i];
                inc.status = Status::Open;
                inc.title = format!("{name} stopped arriving");
                if inc.cause.is_none() {
                    inc.cause = Some(format!("{name} expected {every}"));
                }
                let at = At {
                    frame: last_frame,
                    t: last_ns,
                };
                tl.step(i, at, format!("Last {name} before the gap"));
                self.gaps.insert(key, i);
            }
            PdoGap::Back { key, gap_ns } => {
                let Some(i) = self.gaps.remove(&key) else { return };
                let name = pdo_name(key);
                let at = tl.at;
                let inc = &mut tl.incidents[i];
                inc.status = Status::Warning;
                inc.last_ns = at.t;
                inc.title = if inc.count == 1 {
                    format!("{name} stopped for a while, then came again")
                } else {
                    format!("{name} stopped {} times, came again each time", inc.count)
                };
                tl.step(i, at, format!("{name} again after {:.3} s", gap_ns as f64 / 1e9));
            }
        }
    }
}

impl Detector for Pdos {
    /// PDOs overdue at `now` become (or add to) incidents.
    #[inline]
    fn tick(&mut self, tl: &mut Timeline, now: u64) {
        for gap in self.timing.due(now) {
            self.gap(tl, gap);
        }
    }

    fn transaction(&mut self, _tl: &mut Timeline, t: &Transaction) {
        if t.outcome != Outcome::Ok || t.data.is_empty() {
            return;
        }
        let v = super::detector::value(t);
        match (t.index, t.sub) {
            (0x1800..=0x19FF, 5) => self
                .timing
                .event_timer((t.key(), true, t.index - 0x1800 + 1), u64::from(v & 0xFFFF)),
            (0x1800..=0x19FF, 2) => self
                .timing
                .transmission_type((t.key(), true, t.index - 0x1800 + 1), v as u8),
            (0x1007, 0) if v > 0 => {
                self.sync_window.insert(t.key(), u64::from(v) * 1000);
            }
            (0x1007, 0) => {
                self.sync_window.remove(&t.key());
            }
            (0x1400..=0x15FF, 5) => self
                .timing
                .event_timer((t.key(), false, t.index - 0x1400 + 1), u64::from(v & 0xFFFF)),
            _ => {}
        }
    }

    fn end(&mut self, tl: &mut Timeline, end: At) {
        self.tick(tl, end.t);
        for (key, i) in std::mem::take(&mut self.gaps) {
            let name = pdo_name(key);
            tl.step(i, end, format!("No {name} after that, until the end of the capture"));
            tl.incidents[i].last_ns = end.t;
        }
    }
}
