//! `cotui nmt IFACE start|stop|preop|reset-node|reset-comm NODE [--wait]`.

use super::commander::{BusArgs, ms_arg, node_or_all_arg, run_command};
use crate::command::grammar::NMT_WAIT_MS;
use crate::command::{Command, NmtAction};
use clap::Args;

/// Arguments of `cotui nmt`.
#[derive(Args, Debug)]
pub struct NmtArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// start, stop, preop, reset-node or reset-comm.
    #[arg(value_parser = NmtAction::parse)]
    pub action: NmtAction,
    /// Node id 1..127, or 0 for all nodes.
    #[arg(value_parser = node_or_all_arg)]
    pub node: u8,
    /// Wait for the heartbeat (or boot-up after a reset) that confirms the command.
    #[arg(long)]
    pub wait: bool,
    /// How long --wait waits, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = NMT_WAIT_MS)]
    pub timeout: u64,
}

/// Runs `cotui nmt`; returns the exit status.
pub fn run_nmt(args: &NmtArgs) -> i32 {
    let cmd = Command::Nmt {
        action: args.action,
        node: args.node,
        wait: args.wait,
        timeout_ms: args.timeout,
    };
    run_command(&args.bus, "nmt", Ok(cmd), &[], &[])
}
