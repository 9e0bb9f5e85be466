//! cotui: a terminal CANopen bus analyzer and commander.
//!
//! The protocol core (`frame`, `log`, `od`, `decode`) is pure: it takes bytes
//! and returns values, with no IO, clock or terminal. Sources, panes and the
//! command line live at the edges and call into it.

pub mod analysis;
pub mod bench;
pub mod bus;
pub mod cli;
pub mod command;
pub mod connect;
pub mod decode;
pub mod frame;
pub mod log;
pub mod lss;
pub mod od;
pub mod output;
pub mod sdo;
pub mod sim;
pub mod tui;
