//! Integration tests of the headless decoder and its inputs and outputs: golden output of
//! `cotui decode`/`diagnose`, log formats against can-utils, Wireshark's dissector, EDS import
//! against python canopen, pcapng/Parquet read back by their own tools (Parquet also by Spark), fuzzing.

// Test code may unwrap: a failed unwrap is a failed test with its location.
#![allow(clippy::unwrap_used)]

mod architecture;
mod bench_scratch;
mod boot_config;
mod bounded_memory;
mod cut_short;
mod decode_golden;
mod decode_proptest;
mod diagnose_golden;
mod diagnose_peer;
mod eds_import;
mod explain_golden;
mod formats_binary;
mod formats_mf4;
mod formats_mixed;
mod formats_python_can;
mod json_contract;
mod log_can_utils;
mod log_formats;
mod log_fuzz;
mod no_panic;
mod parquet_duckdb;
mod parquet_full;
mod parquet_spark;
mod pcapng;
mod profile_example;
mod realworld_block;
mod run;
mod socketcand_fuzz;
mod split_logs;
mod sync_cycles;
mod track_path;
mod triggers;
mod two_buses;
mod wireshark;
