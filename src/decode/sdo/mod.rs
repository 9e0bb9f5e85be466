//! SDO (service data object) decoding: abort codes, per-frame meaning and
//! passive reassembly of expedited, segmented and block transfers.

pub mod abort;
pub mod crc;
pub mod frame;
pub mod resync;
pub mod tracker;
pub mod transaction;
pub mod value;

pub use abort::{abort_text, known_abort_text};
pub use frame::{SdoCommand, SdoFrame, Side};
pub use tracker::SdoTracker;
pub use transaction::{Channel, Outcome, Problem, Protocol, Transaction, TransferDirection};

#[cfg(test)]
mod tracker_tests;
