//! `cotui run IFACE NODE [PROCEDURE] [NAME=VALUE ...] [--list] [--dry-run]`: a profile's
//! named procedure, each step printed before it is sent.

use super::commander::{BusArgs, DictArgs, report, run};
use crate::command::exec::{offline_run, run_summary};
use crate::command::{CommandError, ExitCode, Outcome, RunSpec};

/// Runs `cotui run`; returns the exit status. Listing and `--dry-run` need no bus.
pub fn run_run(bus: &BusArgs, dict: &DictArgs, spec: &RunSpec) -> ExitCode {
    let prepared = super::bind::bindings_on(&bus.iface, &dict.profiles, &dict.eds)
        .map_err(CommandError::from)
        .and_then(|bindings| {
            // Checks the procedure and its parameters before the bus is opened.
            let offline = offline_run(&bindings, spec)?;
            Ok((bindings, offline))
        });
    let (bindings, (json, text)) = match prepared {
        Ok(p) => p,
        Err(e) => return report(bus, "run", Err(e)),
    };
    let Some(name) = spec.procedure.clone().filter(|_| !spec.dry_run) else {
        return report(bus, "run", Ok(Outcome::new(json, text)));
    };
    let (json_out, spec) = (bus.json, spec.clone());
    run(bus, "run", |bus| async move {
        let dict = bindings.dictionary(spec.node);
        let plan = crate::command::run::plan(dict, spec.node, &name, &spec.args)?;
        let mut print = |line: &str| {
            if !json_out {
                println!("{line}");
            }
        };
        let json = crate::command::run::run(&bus, dict, &plan, spec.timeout_ms, &mut print).await?;
        let text = run_summary(&json);
        Ok(Outcome::new(json, text))
    })
}
