//! `cotui sdo read|write IFACE NODE OBJECT [VALUE] [--type T] [--block] [--timeout MS] [--deadline MS]`.

use super::commander::{BusArgs, ms_arg, node_arg, run_command};
use crate::command::grammar::{DEFAULT_TIMEOUT_MS, parse_type};
use crate::command::{Command, SdoOptions};
use crate::od::DataType;
use clap::{Args, Subcommand};

/// `cotui sdo` subcommands.
#[derive(Subcommand, Debug)]
pub enum SdoCommand {
    /// Read an object: `cotui sdo read can0 2 0x6041`.
    Read(SdoReadArgs),
    /// Write an object: `cotui sdo write can0 2 0x6060 3 --type i8`.
    Write(SdoWriteArgs),
}

/// Options of both directions.
#[derive(Args, Debug)]
pub struct Transfer {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// Object: 0x6041, 0x1018:1, or an object name from the node's profile.
    pub object: String,
    /// Value type: u8..u64, i8..i64, f32, f64, bool, string, octets (hex), domain (a file).
    #[arg(long = "type", short = 't', value_parser = parse_type)]
    pub data_type: Option<DataType>,
    /// Force a block transfer.
    #[arg(long)]
    pub block: bool,
    /// How long to wait for each server response, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    /// How long the whole transfer may take, in ms [default: the longer of 10 s and 10
    /// timeouts, plus 1 ms per byte of the size written or announced by the server].
    #[arg(long, value_parser = ms_arg)]
    pub deadline: Option<u64>,
    /// Bind a device profile to a node: NODE=NAME (names, aliases and types come from it).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
}

/// Arguments of `cotui sdo read`.
#[derive(Args, Debug)]
pub struct SdoReadArgs {
    #[command(flatten)]
    pub t: Transfer,
    /// Write the data read to this file (for domains).
    #[arg(long = "output", short = 'o')]
    pub output: Option<String>,
}

/// Arguments of `cotui sdo write`.
#[derive(Args, Debug)]
pub struct SdoWriteArgs {
    #[command(flatten)]
    pub t: Transfer,
    /// The value (a file path for `--type domain`, hex bytes for `--type octets`); negative numbers need no `--`.
    #[arg(allow_negative_numbers = true)]
    pub value: String,
}

/// Runs `cotui sdo`; returns the exit status.
pub fn run_sdo(cmd: &SdoCommand) -> i32 {
    match cmd {
        SdoCommand::Read(a) => {
            let t = &a.t;
            let cmd = Command::SdoRead {
                node: t.node,
                object: t.object.clone(),
                options: options(t),
                output: a.output.clone(),
            };
            run_command(&t.bus, "sdo read", Ok(cmd), &t.profiles, &t.eds)
        }
        SdoCommand::Write(a) => {
            let t = &a.t;
            let cmd = Command::SdoWrite {
                node: t.node,
                object: t.object.clone(),
                value: a.value.clone(),
                options: options(t),
            };
            run_command(&t.bus, "sdo write", Ok(cmd), &t.profiles, &t.eds)
        }
    }
}

fn options(t: &Transfer) -> SdoOptions {
    SdoOptions {
        data_type: t.data_type,
        block: t.block,
        timeout_ms: t.timeout,
        deadline_ms: t.deadline,
    }
}
