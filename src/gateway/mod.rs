//! `cotui gateway`: a CiA 309-3 ASCII gateway with CANopenNode `canopend`'s command set
//! and answers, over stdin/stdout, a Unix socket or TCP.
//!
//! The text side is pure: [`line`] parses a request, [`types`] prints and parses the data
//! types, [`answer`] writes answers and notifications, [`watch`] finds what to notify of in
//! the bus frames. [`session`] runs a request through the command layer (SDO client, NMT,
//! LSS master) on the bus; [`serve`] is the IO (clients, bounded lines, notifications) and
//! [`listen`] the sockets it listens on.

pub mod answer;
pub mod line;
pub mod listen;
pub mod serve;
pub mod session;
pub mod types;
pub mod watch;
