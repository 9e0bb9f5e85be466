//! SDO on the bus as a party to it: the client (what cotui runs to read and write a
//! node's objects) and the server (what a simulated node answers with). Both are pure
//! state machines: frames and time in, frames and completions out.

pub mod client;
pub mod server;
