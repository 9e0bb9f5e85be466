//! `cotui drive IFACE NODE enable|disable|quick-stop|fault-reset|status|mode MODE`.

use super::commander::{BusArgs, ms_arg, node_arg, run_command};
use crate::command::grammar::DEFAULT_TIMEOUT_MS;
use crate::command::{Command, DriveAction};
use clap::Args;

/// Arguments of `cotui drive`.
#[derive(Args, Debug)]
pub struct DriveArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// enable, disable, quick-stop, fault-reset, status, or mode.
    pub action: String,
    /// The mode for `mode`: pp, pv, pt, hm, ip, csp, csv, cst or a number.
    pub mode: Option<String>,
    /// How long to wait for each SDO answer, and half of how long each step may take, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

/// Runs `cotui drive`; returns the exit status.
pub fn run_drive(args: &DriveArgs) -> i32 {
    let cmd = DriveAction::parse(&args.action, args.mode.as_deref()).map(|action| Command::Drive {
        node: args.node,
        action,
        timeout_ms: args.timeout,
    });
    run_command(&args.bus, "drive", cmd, &[], &[])
}
