//! Decoded, formatted rows of the visible trace window, kept between draws.
//!
//! Rows are made only for the positions on screen. Rows still on screen after a scroll or
//! new frames are kept; new positions are decoded by a decoder that goes on from where the
//! last window ended, so following the tail decodes only the new frames.

use crate::analysis::trace::Trace;
use crate::decode::{Decoder, Kind};
use crate::frame::hex;
use std::collections::HashMap;

/// One formatted row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Trace position.
    pub pos: usize,
    /// Time since the first frame, seconds.
    pub time: f64,
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
                time: f.ts_ns.saturating_sub(t0) as f64 / 1e9,
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
