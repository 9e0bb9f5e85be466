//! What every detector answers to (the facade, [`super::Diagnoser`], routes to them), and
//! what they share of an SDO transfer.

use super::timeline::{At, Timeline};
use crate::frame::NodeKey;
use crate::sdo::transaction::Transaction;

/// What every detector does as the capture goes on and when it ends (the frames each one
/// reads, the facade hands it by their kind).
pub(super) trait Detector {
    /// The capture clock reached `now` (ns), at a frame or a tick: what is overdue by then.
    fn tick(&mut self, _tl: &mut Timeline, _now: u64) {}
    /// A completed SDO transfer, right after the frame that ended it.
    fn transaction(&mut self, _tl: &mut Timeline, _t: &Transaction) {}
    /// The capture ended at `end`: what the detector holds for the whole bus.
    fn end(&mut self, _tl: &mut Timeline, _end: At) {}
    /// The capture ended at `end`: what the detector holds for node `n`.
    fn end_node(&mut self, _tl: &mut Timeline, _n: NodeKey, _end: At) {}
}

/// The value of an SDO transfer's data (the first 4 bytes, little-endian).
pub(super) fn value(t: &Transaction) -> u32 {
    t.data.iter().take(4).rev().fold(0u32, |a, b| a << 8 | u32::from(*b))
}
