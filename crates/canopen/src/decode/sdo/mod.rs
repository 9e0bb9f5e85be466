//! SDO frames and transfers as the trace shows them: labels, JSON and values typed through
//! the dictionary. The protocol itself (codec, tracker, transactions) is [`crate::sdo`].

pub mod frame;
pub mod tracker;
pub mod transaction;
pub mod value;

pub use frame::SdoFrame;
pub use tracker::SdoTracker;

#[cfg(test)]
mod tracker_tests;
