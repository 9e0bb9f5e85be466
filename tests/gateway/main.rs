//! `cotui gateway`: the CiA 309-3 ASCII gateway driven by a small client of our own speaking
//! canopend's lines (stdio and TCP), the sessions in process against the demo bus (what
//! reaches the bus, the node table), and the line parser fuzzed.

// Test code may unwrap: a failed unwrap is a failed test with its location.
#![allow(clippy::unwrap_used)]

mod client;
mod fuzz;
mod in_process;
mod stdio;
mod tcp;
