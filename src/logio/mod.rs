//! Log IO at the edge: reading a log on a second thread ([`read_ahead`]) and writing whole
//! records to a file or stream ([`sink`]). The line parsers themselves are pure and live in
//! the protocol core (`canopen::log`).

pub mod read_ahead;
pub mod sink;
