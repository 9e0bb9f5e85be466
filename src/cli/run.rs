//! `cotui run IFACE NODE [PROCEDURE] [NAME=VALUE ...] [--list] [--dry-run]`: a profile's
//! named procedure, each step printed before it is sent.

use super::commander::{BusArgs, ms_arg, node_arg, report, run};
use crate::command::exec::{offline_run, run_summary};
use crate::command::grammar::{DEFAULT_TIMEOUT_MS, run_command};
use crate::command::{Command, CommandError, Outcome};
use clap::Args;

/// Arguments of `cotui run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The procedure (e.g. `pv`), then its parameters as NAME=VALUE; none: list the procedures.
    pub words: Vec<String>,
    /// List the node's procedures with their descriptions and parameters.
    #[arg(long)]
    pub list: bool,
    /// Print the steps and their frames without sending anything.
    #[arg(long)]
    pub dry_run: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    /// Bind a device profile to a node: NODE=NAME (the procedures come from it).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
}

/// Runs `cotui run`; returns the exit status. Listing and `--dry-run` need no bus.
pub fn run_run(args: &RunArgs) -> i32 {
    let words: Vec<&str> = args.words.iter().map(String::as_str).collect();
    let prepared = run_command(args.node, &words, args.list, args.dry_run, args.timeout).and_then(|cmd| {
        let bindings = super::bind::bindings(&args.profiles, &args.eds)?;
        Ok((cmd, bindings))
    });
    let (cmd, bindings) = match prepared {
        Ok(p) => p,
        Err(e) => return report(&args.bus, "run", Err(CommandError::Usage(e))),
    };
    let Command::Run {
        node,
        procedure,
        args: params,
        dry_run,
        timeout_ms,
    } = cmd
    else {
        return report(&args.bus, "run", Err(CommandError::Usage("not a run command".into())));
    };
    // Checks the procedure and its parameters before the bus is opened.
    let offline = offline_run(&bindings, node, procedure.as_deref(), &params, dry_run);
    let (name, json_out) = match (offline, procedure) {
        (Err(e), _) => return report(&args.bus, "run", Err(CommandError::Usage(e))),
        (Ok((json, text)), None) => return report(&args.bus, "run", Ok(Outcome { json, text })),
        (Ok((json, text)), Some(_)) if dry_run => return report(&args.bus, "run", Ok(Outcome { json, text })),
        (Ok(_), Some(name)) => (name, args.bus.json),
    };
    run(&args.bus, "run", |bus| async move {
        let dict = bindings.dictionary(node);
        let plan = crate::command::run::plan(dict, node, &name, &params).map_err(CommandError::Usage)?;
        let mut print = |line: &str| {
            if !json_out {
                println!("{line}");
            }
        };
        let json = crate::command::run::run(&bus, dict, &plan, timeout_ms, &mut print).await?;
        let text = run_summary(&json);
        Ok(Outcome { json, text })
    })
}
