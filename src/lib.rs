//! cotui: a terminal CANopen bus analyzer and commander.
//!
//! The protocol core is its own crate, [`canopen`] (`crates/canopen`): frames, log parsers,
//! object dictionaries, SDO/LSS state machines and the decoder registry, pure. This crate
//! holds what is built on it: the analysis, the writers, the buses, the simulation, the
//! commands and the two front ends (TUI and CLI). The core's modules are re-exported here
//! under their own names, so `cotui::decode` is `canopen::decode`.

pub use canopen::{calendar, cob, decode, frame, log, lss, od, sdo, wire};

pub mod analysis;
pub mod audit;
pub mod bench;
pub mod bus;
pub mod cli;
pub mod command;
pub mod connect;
pub mod files;
pub mod gateway;
pub mod logio;
pub mod output;
pub mod serve;
pub mod sim;
pub mod tui;
