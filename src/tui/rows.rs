//! Decoded, formatted rows of the visible trace window, kept between draws.
//!
//! Rows are made only for the positions on screen. Rows still on screen after a scroll or
//! new frames are kept; new positions are decoded by a decoder that goes on from where the
//! last window ended, so following the tail decodes only the new frames.

use super::panes::trace_time::{SAME_ID_BOUND, Stamps};
use crate::analysis::trace::Trace;
use crate::decode::{Decoder, Kind};
use crate::frame::{Flags, hex};
use std::collections::HashMap;

/// One formatted row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Trace position.
    pub pos: usize,
    /// The timestamps the time column reads in each mode.
    pub stamps: Stamps,
    /// COB-ID text (`181`, `18FF1234`), `R` suffix for remote frames.
    pub cob: String,
    /// Kind.
    pub kind: Kind,
    /// Node text.
    pub node: String,
    /// Payload in hex.
    pub data: String,
    /// Decoded label.
    pub label: String,
    /// Why the frame is malformed, if it is.
    pub malformed: Option<String>,
}

/// The rows of the visible window.
#[derive(Default)]
pub struct RowCache {
    rows: HashMap<usize, Row>,
    walker: Option<(Decoder, usize)>,
}

impl RowCache {
    /// Makes rows for `positions` (rising), reusing those already made.
    pub fn fill(&mut self, trace: &Trace, positions: &[usize]) {
        self.rows.retain(|p, _| positions.binary_search(p).is_ok());
        let missing: Vec<usize> = positions
            .iter()
            .copied()
            .filter(|p| !self.rows.contains_key(p))
            .collect();
        if missing.is_empty() {
            return;
        }
        let t0 = trace.store.packed(0).ts_ns;
        let decoded = trace.decode_with(&mut self.walker, &missing);
        for (pos, d) in missing.into_iter().zip(decoded) {
            let f = trace.store.frame(pos);
            let cob = match (f.is_err(), f.is_ext()) {
                (true, _) => "ERR".to_string(),
                (false, true) => format!("{:08X}", f.id),
                (false, false) => format!("{:03X}", f.id),
            };
            let row = Row {
                pos,
                stamps: Stamps {
                    ts_ns: f.ts_ns,
                    start_ns: t0,
                    prev_ns: pos.checked_sub(1).map(|p| trace.store.packed(p).ts_ns),
                    prev_id_ns: prev_same_id(trace, pos),
                },
                cob: if f.is_rtr() { format!("{cob}R") } else { cob },
                kind: d.kind,
                node: d.node.map(|n| n.to_string()).unwrap_or_default(),
                data: hex::spaced(f.payload()),
                label: d.label,
                malformed: d.malformed,
            };
            self.rows.insert(pos, row);
        }
    }

    /// The row of a position, if made.
    pub fn get(&self, pos: usize) -> Option<&Row> {
        self.rows.get(&pos)
    }
}

/// The timestamp of the frame before `pos` with the same identifier (and frame format),
/// looking back at most [`SAME_ID_BOUND`] frames.
fn prev_same_id(trace: &Trace, pos: usize) -> Option<u64> {
    let this = trace.store.packed(pos);
    let key = |p: &crate::analysis::store::Packed| (p.id, p.flags & (Flags::EXT | Flags::ERR));
    (pos.saturating_sub(SAME_ID_BOUND)..pos)
        .rev()
        .map(|i| trace.store.packed(i))
        .find(|p| key(p) == key(&this))
        .map(|p| p.ts_ns)
}
