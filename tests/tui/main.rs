//! The interactive analyzer end to end: the real binary in tmux, and its command line.

// Test code may unwrap: a failed unwrap is a failed test with its location.
#![allow(clippy::unwrap_used)]

mod agreement;
mod filter_search;
mod hosted;
mod objects_demo;
mod objects_tmux;
mod open_logs;
mod own_reads;
mod problems;
mod receive_list;
mod remote;
mod screen;
mod sdo_sequence;
mod tmux;
mod transmit_demo;
mod tui_cli;
mod tui_tmux;
mod two_buses;
mod watch_demo;
