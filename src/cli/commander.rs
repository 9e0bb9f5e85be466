//! What the commander subcommands share: `IFACE`, `--listen-only`, `--json`, the tokio
//! runtime, opening the bus and printing one result or failure.

use crate::bus::Bus;
use crate::command::error::EXIT_OK;
use crate::command::{Command, CommandError, Outcome};
use clap::Args;
use std::future::Future;

/// Options every commander subcommand takes.
#[derive(Args, Debug, Clone)]
pub struct BusArgs {
    /// SocketCAN interface (e.g. can0, vcan0), or `demo` for the built-in simulated bus.
    pub iface: String,
    /// Open the bus without a send path: nothing is ever written to it.
    #[arg(long)]
    pub listen_only: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `body` on a fresh single-threaded tokio runtime with the bus of `args` open, then
/// prints its outcome (text, or the JSON object with `--json`) or its failure; returns the exit status.
pub fn run<F, Fut>(args: &BusArgs, what: &str, body: F) -> i32
where
    F: FnOnce(Bus) -> Fut,
    Fut: Future<Output = Result<Outcome, CommandError>>,
{
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => {
            return report(
                args,
                what,
                Err(CommandError::Usage(format!("cannot start the runtime: {e}"))),
            );
        }
    };
    let result = rt.block_on(async {
        let bus = crate::connect::open(&args.iface, args.listen_only).await?;
        body(bus).await
    });
    report(args, what, result)
}

/// Runs one parsed command (see [`crate::command::execute`]) with `--profile`/`--eds` bindings.
pub fn run_command(
    args: &BusArgs,
    what: &str,
    cmd: Result<Command, String>,
    profiles: &[String],
    eds: &[String],
) -> i32 {
    let prepared = cmd.map_err(CommandError::Usage).and_then(|c| {
        Ok((
            c,
            super::bind::bindings_on(&args.iface, profiles, eds).map_err(CommandError::Usage)?,
        ))
    });
    run(args, what, |bus| async move {
        let (cmd, bindings) = prepared?;
        crate::command::execute(&bus, &cmd, &bindings).await
    })
}

/// Prints `result` (text, or JSON with `--json`; failures also to stderr) and gives the exit status.
pub fn report(args: &BusArgs, what: &str, result: Result<Outcome, CommandError>) -> i32 {
    match result {
        Ok(o) => {
            if args.json {
                println!("{}", o.json);
            } else if !o.text.is_empty() {
                println!("{}", o.text);
            }
            EXIT_OK
        }
        Err(e) => {
            if args.json {
                println!("{}", e.to_json());
            }
            eprintln!("cotui {what}: {e}");
            e.exit_code()
        }
    }
}

/// Parses NODE (decimal or 0x hex; 0 = all where allowed) for clap.
pub fn node_arg(text: &str) -> Result<u8, String> {
    crate::command::grammar::parse_node(text, false)
}

/// Parses NODE allowing 0 (all nodes) for clap.
pub fn node_or_all_arg(text: &str) -> Result<u8, String> {
    crate::command::grammar::parse_node(text, true)
}

/// Parses a positive number of ms for clap.
pub fn ms_arg(text: &str) -> Result<u64, String> {
    crate::command::grammar::parse_int(text)
        .filter(|v| *v > 0)
        .map(|v| v as u64)
        .ok_or(format!("`{text}` must be a positive number of ms"))
}
