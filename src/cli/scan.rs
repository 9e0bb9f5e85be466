//! `cotui scan IFACE [--listen MS] [--probe]`.

use super::commander::{BusArgs, ms_arg, run_command};
use crate::command::Command;
use crate::command::grammar::{SCAN_LISTEN_MS, SCAN_TIMEOUT_MS};
use clap::Args;

/// Arguments of `cotui scan`.
#[derive(Args, Debug)]
pub struct ScanArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// How long to listen for heartbeats and boot-ups, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = SCAN_LISTEN_MS)]
    pub listen: u64,
    /// Also ask every node 1..127 for 0x1000 (finds nodes without heartbeat).
    #[arg(long)]
    pub probe: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = SCAN_TIMEOUT_MS)]
    pub timeout: u64,
}

/// Runs `cotui scan`; returns the exit status.
pub fn run_scan(args: &ScanArgs) -> i32 {
    let cmd = Command::Scan {
        listen_ms: args.listen,
        probe: args.probe,
        timeout_ms: args.timeout,
    };
    run_command(&args.bus, "scan", Ok(cmd), &[], &[])
}
