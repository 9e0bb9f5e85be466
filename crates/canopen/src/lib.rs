//! `canopen`: the CANopen protocol core of cotui, usable on its own.
//!
//! Everything here takes bytes and returns values: no IO, no clock, no terminal, no async
//! runtime. The modules, from the bottom up:
//!
//! - [`calendar`]: civil dates from day counts, and UTC date-time text.
//! - [`cob`]: the COB-IDs of the predefined connection set (`cob::sdo_request(node)`).
//! - [`frame`]: the [`frame::Frame`] value (classic and FD, 11/29-bit, flags, timestamp).
//! - [`log`]: streaming parsers of candump `-l`/`-L` logs, candump screen output and Vector
//!   ASC over any `BufRead`, and a candump log writer.
//! - [`od`]: object dictionaries: the built-in device profiles (`decoders/*.json`, included
//!   at build time), JSON profiles, EDS/DCF import and export, node bindings.
//! - [`sdo`]: SDO command bytes, the client and server state machines, the passive tracker.
//! - [`lss`]: the LSS master, fastscan and slave state machines.
//! - [`decode`]: the decoder registry: every frame in, its service, node and label out,
//!   with the bus state (SDO transfers, learned PDO mappings) kept between frames.
//! - [`wire`]: a frame rebuilt as a controller sends it (stuff bits, CRC, EOF) and its
//!   figures: bits, stuff bits, CRC, time on the bus.
//!
//! # Example
//! Decode a candump log held in memory:
//! ```
//! use canopen::decode::Decoder;
//! use canopen::log::{LogReader, Outcome};
//! use canopen::od::bind::Bindings;
//!
//! let log = b"(1.000000) can0 705#7F\n(1.100000) can0 605#4041600000000000\n\
//!             (1.101000) can0 585#4B41600037020000\n";
//! let mut decoder = Decoder::from_bindings(&Bindings::new());
//! let mut labels = Vec::new();
//! for line in LogReader::new(&log[..]).expect("in-memory log") {
//!     if let (_, Outcome::Frame(frame)) = line.expect("in-memory read") {
//!         labels.push(decoder.decode(&frame).label);
//!     }
//! }
//! assert_eq!(labels[0], "Heartbeat node 5: Pre-operational");
//! assert!(labels[2].contains("Statusword"), "{}", labels[2]);
//! ```

#![deny(unsafe_code)]

pub mod calendar;
pub mod cob;
pub mod decode;
pub mod frame;
pub mod log;
pub mod lss;
pub mod od;
pub mod sdo;
pub mod wire;
