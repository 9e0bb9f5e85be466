//! The commander: the CLI and the palette's commands against the demo bus, the SDO client
//! against the SDO server and misbehaving peers, and (ignored here, run in the vbus guest:
//! `socketcan_live::`) the SocketCAN layer on a real vcan.

// Test code may unwrap: a failed unwrap is a failed test with its location.
#![allow(clippy::unwrap_used)]

mod cli_bitrate;
mod cli_commander;
mod cli_cyclic;
mod cli_refusals;
mod cli_run;
mod cli_streams;
mod command_language;
mod commander_demo;
mod dcf_demo;
mod every_procedure;
mod json_snapshots;
mod lists;
mod lss_sim;
mod pdo_config;
mod procedure_run;
mod record_buses;
mod run;
mod sdo_client_misbehave;
mod sdo_client_server;
mod sdo_proptest;
mod second_producer;
mod socketcan_live;
mod socketcand;
mod trigger_live;
