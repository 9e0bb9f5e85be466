//! The SDO protocol: the command-byte [`codec`], abort codes, the block CRC, and the three
//! state machines built on them — the [`client`] (what cotui runs to read and write a
//! node's objects), the [`server`] (what a simulated node answers with) and the passive
//! [`tracker`] that reassembles [`transaction`]s from a capture. All pure: frames and time
//! in, frames, results and transactions out.

pub mod abort;
pub mod client;
pub mod codec;
pub mod crc;
pub mod resync;
pub mod server;
pub mod tracker;
pub mod transaction;

pub use abort::{abort_text, known_abort_text};
pub use codec::{SdoCommand, Side};
pub use transaction::{Channel, Outcome, Problem, Protocol, Transaction, TransferDirection};
