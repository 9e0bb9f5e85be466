//! Log IO at the edge: reading a log of any format ([`reader`], with Vector BLF's file and
//! zlib half in [`blf`] and ASAM MDF4's block tree in [`mf4`]) on a second thread ([`read_ahead`]) and writing whole
//! records to a file or stream ([`sink`]). The line parsers themselves are pure and live in
//! the protocol core (`canopen::log`).

pub mod blf;
pub mod mf4;
pub mod read_ahead;
pub mod reader;
pub mod sink;
