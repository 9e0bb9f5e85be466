//! `cotui run IFACE NODE [PROCEDURE] [NAME=VALUE ...] [--list] [--dry-run]`: a profile's
//! named procedure, each step printed before it is sent.

use super::commander::{BusArgs, ms_arg, node_arg, report, run};
use crate::command::exec::{offline_run, run_summary};
use crate::command::grammar::{DEFAULT_TIMEOUT_MS, run_spec};
use crate::command::{CommandError, Outcome};
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
    let prepared = run_spec(args.node, &words, args.list, args.dry_run, args.timeout).and_then(|spec| {
        let bindings = super::bind::bindings_on(&args.bus.iface, &args.profiles, &args.eds)?;
        // Checks the procedure and its parameters before the bus is opened.
        let offline = offline_run(&bindings, &spec)?;
        Ok((spec, bindings, offline))
    });
    let (spec, bindings, (json, text)) = match prepared {
        Ok(p) => p,
        Err(e) => return report(&args.bus, "run", Err(CommandError::Usage(e))),
    };
    let Some(name) = spec.procedure.clone().filter(|_| !spec.dry_run) else {
        return report(&args.bus, "run", Ok(Outcome { json, text }));
    };
    let json_out = args.bus.json;
    run(&args.bus, "run", |bus| async move {
        let dict = bindings.dictionary(spec.node);
        let plan = crate::command::run::plan(dict, spec.node, &name, &spec.args).map_err(CommandError::Usage)?;
        let mut print = |line: &str| {
            if !json_out {
                println!("{line}");
            }
        };
        let json = crate::command::run::run(&bus, dict, &plan, spec.timeout_ms, &mut print).await?;
        let text = run_summary(&json);
        Ok(Outcome { json, text })
    })
}
