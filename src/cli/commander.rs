//! The commander subcommands (`cotui nmt|sdo|drive|run|scan|record|stop|lss|send|sync|pdo IFACE ...`): the
//! declaration of [`crate::command::syntax`] with the bus options in front, the tokio
//! runtime, opening the bus and printing one result or failure.

use super::bus_run::{BusArgs, Stream, report, run_to};
use crate::command::{Command, CommandError, Commander, ExitCode, Spec};
use clap::Args;

/// The commander subcommands as the command line takes them.
pub type CliCommander = Commander<BusArgs, DictArgs>;

/// The node dictionaries of the commands that name objects (`sdo`, `run`).
#[derive(Args, Debug, Clone, Default)]
pub struct DictArgs {
    /// Bind a device profile to a node: NODE=NAME (names, aliases, types and procedures come from it).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
}

/// Runs a commander subcommand; returns the exit status.
pub fn run_commander(c: &CliCommander) -> ExitCode {
    let (bus, mut dict, what) = (c.bus(), c.dict().cloned().unwrap_or_default(), c.name());
    let cmd = match c.command() {
        Ok(cmd) => cmd,
        Err(e) => return report(bus, what, Err(e.into())),
    };
    if let Some(node) = cmd.node() {
        // `dcf ... --eds FILE`: the EDS of the one node the command is about.
        for e in &mut dict.eds {
            if !e.contains('=') {
                *e = format!("{node}={e}");
            }
        }
    }
    if let Command::Record(r) = &cmd {
        if let Some(t) = &r.trigger {
            if !r.more.is_empty() {
                let several =
                    "--trigger records one interface: give one IFACE (several buses: one `record --trigger` each)";
                return report(bus, what, Err(CommandError::Usage(several.into())));
            }
            return match super::trigger_live::run(&bus.iface, bus.listen_only, r, t) {
                Ok(n) => n.say(bus.json),
                Err(e) => report(bus, what, Err(e)),
            };
        }
        // Signals stop a recording; its gaps are said after its report.
        return super::record::run_record(bus, r);
    }
    let bindings = super::bind::bindings_on(&bus.iface, &dict.profiles, &dict.eds).map_err(CommandError::from);
    if cmd.answers_offline() {
        // Checked (or answered: a listing, a dry run) before the bus is opened.
        let offline = bindings.as_ref().map_err(Clone::clone).map(|b| cmd.offline(b));
        match offline {
            Err(e) => return report(bus, what, Err(e)),
            Ok(Some(result)) => return report(bus, what, result),
            Ok(None) => {}
        }
    }
    let report_to = Stream::report_of(&cmd);
    let (json, cyclic) = (bus.json, cmd.cyclic());
    run_to(bus, what, report_to, |bus| async move {
        let bindings = bindings?;
        let progress = crate::command::cyclic::Progress::default();
        // Each step of a `run` printed as it happens (not with --json).
        let mut print = |line: &str| println!("{line}");
        let lines: Option<&mut (dyn FnMut(&str) + Send)> = if json { None } else { Some(&mut print) };
        if cyclic {
            // Ctrl-C stops a cyclic send; the report follows.
            let ctrl_c = async {
                if tokio::signal::ctrl_c().await.is_err() {
                    std::future::pending::<()>().await;
                }
            };
            crate::command::execute_saying(&bus, &cmd, &bindings, progress, ctrl_c, lines).await
        } else {
            crate::command::execute_saying(&bus, &cmd, &bindings, progress, std::future::pending(), lines).await
        }
    })
}
