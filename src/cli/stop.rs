//! `cotui stop IFACE [--node N]...`: the emergency stop from the command line.

use super::commander::{BusArgs, ms_arg, node_arg, run_command};
use crate::command::Command;
use crate::command::grammar::DEFAULT_TIMEOUT_MS;
use crate::command::stop::{DEFAULT_LISTEN_MS, DEFAULT_RAMP_MS, StopOptions};
use clap::Args;

/// Arguments of `cotui stop`.
#[derive(Args, Debug)]
pub struct StopArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Stop this node (repeatable). Without it, every CiA 402 drive found powered is stopped.
    #[arg(long = "node", value_parser = node_arg)]
    pub nodes: Vec<u8>,
    /// How long to listen for nodes before reading their statuswords, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_LISTEN_MS)]
    pub listen: u64,
    /// How long a drive may take to finish its quick stop ramp before voltage is disabled, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_RAMP_MS)]
    pub ramp: u64,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

/// Runs `cotui stop`; exit 0 only when every drive targeted is confirmed stopped, else 5.
pub fn run_stop(args: &StopArgs) -> i32 {
    let cmd = Command::Stop {
        nodes: args.nodes.clone(),
        listen_ms: args.listen,
        options: StopOptions {
            timeout_ms: args.timeout,
            ramp_ms: args.ramp,
        },
    };
    run_command(&args.bus, "stop", Ok(cmd), &[], &[])
}
