//! The commander subcommands (`cotui nmt|sdo|drive|run|scan|record|stop|lss|send|sync|pdo IFACE ...`): the
//! declaration of [`crate::command::syntax`] with the bus options in front, the tokio
//! runtime, opening the bus and printing one result or failure.

use crate::bus::Bus;
use crate::command::{Command, CommandError, Commander, ExitCode, Outcome, Spec};
use clap::Args;
use std::future::Future;

/// The commander subcommands as the command line takes them.
pub type CliCommander = Commander<BusArgs, DictArgs>;

/// Options every commander subcommand takes, before its own.
#[derive(Args, Debug, Clone)]
pub struct BusArgs {
    /// SocketCAN interface (e.g. can0, vcan0), `demo` for the built-in simulated bus, or
    /// socketcand://HOST:PORT/CHANNEL for a bus served by `cotui serve` or socketcand.
    pub iface: String,
    /// Open the bus without a send path: nothing is ever written to it.
    #[arg(long)]
    pub listen_only: bool,
    /// Print one JSON object instead of text (failures included).
    #[arg(long)]
    pub json: bool,
}

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

/// Runs `body` on a fresh single-threaded tokio runtime with the bus of `args` open, then
/// prints its outcome (text, or the JSON object with `--json`) or its failure; returns the exit status.
pub fn run<F, Fut>(args: &BusArgs, what: &str, body: F) -> ExitCode
where
    F: FnOnce(Bus) -> Fut,
    Fut: Future<Output = Result<Outcome, CommandError>>,
{
    run_to(args, what, Stream::Stdout, body)
}

/// Where a command's report goes: stdout, or stderr when stdout carries the command's data
/// (`-o -`), so that a pipe gets the data alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    Stdout,
    Stderr,
}

impl Stream {
    /// Stderr for a command that writes its data to stdout, else stdout.
    pub fn report_of(cmd: &Command) -> Stream {
        if cmd.data_to_stdout() {
            Stream::Stderr
        } else {
            Stream::Stdout
        }
    }

    /// Writes one line; a closed stream (a gone terminal, a closed pipe) is not an error.
    pub fn line(self, text: &str) {
        use std::io::Write;
        let _ = match self {
            Stream::Stdout => writeln!(std::io::stdout(), "{text}"),
            Stream::Stderr => writeln!(std::io::stderr(), "{text}"),
        };
    }
}

/// [`run`], with the report on `to`.
pub fn run_to<F, Fut>(args: &BusArgs, what: &str, to: Stream, body: F) -> ExitCode
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
    report_to(args, what, to, result)
}

/// Prints `result` (text, or JSON with `--json`; failures also to stderr) and gives the exit status.
pub fn report(args: &BusArgs, what: &str, result: Result<Outcome, CommandError>) -> ExitCode {
    report_to(args, what, Stream::Stdout, result)
}

/// [`report`], with the outcome (text or JSON) on `to`.
pub fn report_to(args: &BusArgs, what: &str, to: Stream, result: Result<Outcome, CommandError>) -> ExitCode {
    match result {
        Ok(o) => {
            if args.json {
                to.line(&o.json().to_string());
            } else if !o.text.is_empty() {
                to.line(&o.text);
            }
            ExitCode::Ok
        }
        Err(e) => {
            if args.json {
                to.line(&e.to_json().to_string());
            }
            eprintln!("cotui {what}: {e}");
            e.exit_code()
        }
    }
}
