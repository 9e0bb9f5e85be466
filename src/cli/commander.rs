//! The commander subcommands (`cotui nmt|sdo|drive|run|scan|record|stop|lss|send|sync|pdo IFACE ...`): the
//! declaration of [`crate::command::syntax`] with the bus options in front, the tokio
//! runtime, opening the bus and printing one result or failure.

use crate::bus::Bus;
use crate::command::syntax::Commander;
use crate::command::{Command, CommandError, ExitCode, Outcome};
use clap::Args;
use std::future::Future;

/// The commander subcommands as the command line takes them.
pub type CliCommander = Commander<BusArgs, DictArgs>;

/// Options every commander subcommand takes, before its own.
#[derive(Args, Debug, Clone)]
pub struct BusArgs {
    /// SocketCAN interface (e.g. can0, vcan0), or `demo` for the built-in simulated bus.
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
    let (bus, mut dict) = (c.bus(), c.dict().cloned().unwrap_or_default());
    let cmd = match c.command() {
        Ok(cmd) => cmd,
        Err(e) => return report(bus, what(c), Err(e.into())),
    };
    if let Command::Dcf(d) = &cmd {
        // `dcf ... --eds FILE`: the EDS of the one node the command is about.
        for e in &mut dict.eds {
            if !e.contains('=') {
                *e = format!("{}={e}", d.node);
            }
        }
    }
    match cmd {
        Command::Run(spec) => super::run::run_run(bus, &dict, &spec),
        // A dry run needs no bus (not even an interface that exists).
        Command::PdoMap(spec) if spec.dry_run => {
            let result = super::bind::bindings_on(&bus.iface, &dict.profiles, &dict.eds)
                .map_err(CommandError::from)
                .and_then(|b| crate::command::pdo::dry_run(b.dictionary(spec.node), &spec))
                .map(|(json, text)| Outcome::new(json, text));
            report(bus, what(c), result)
        }
        Command::Record {
            output,
            limits,
            mode,
            format,
        } => super::record::run_record(bus, &output, limits, mode, format),
        cmd @ (Command::Send(_) | Command::Sync(_) | Command::Pdo { .. }) => {
            let bindings = super::bind::bindings_on(&bus.iface, &dict.profiles, &dict.eds);
            run(bus, what(c), |bus| async move {
                // Ctrl-C stops a cyclic send; the report follows.
                let ctrl_c = async {
                    if tokio::signal::ctrl_c().await.is_err() {
                        std::future::pending::<()>().await;
                    }
                };
                let progress = crate::command::cyclic::Progress::default();
                crate::command::execute_until(&bus, &cmd, &bindings?, progress, ctrl_c).await
            })
        }
        cmd => {
            let bindings = super::bind::bindings_on(&bus.iface, &dict.profiles, &dict.eds);
            let report_to = Stream::report_of(&cmd);
            run_to(bus, what(c), report_to, |bus| async move {
                crate::command::execute(&bus, &cmd, &bindings?).await
            })
        }
    }
}

/// The subcommand's name, as failures are prefixed (`cotui sdo read: ...`).
fn what(c: &CliCommander) -> &'static str {
    use crate::command::syntax::DcfCommand;
    match c {
        Commander::Nmt(_) => "nmt",
        Commander::Sdo(g) => crate::command::spec::Declared::<BusArgs, DictArgs>::name(g),
        Commander::Drive(_) => "drive",
        Commander::Run(_) => "run",
        Commander::Scan(_) => "scan",
        Commander::Record(_) => "record",
        Commander::Stop(_) => "stop",
        Commander::Lss(_) => "lss",
        Commander::Send(_) => "send",
        Commander::Sync(_) => "sync",
        Commander::Pdo(_) => "pdo",
        Commander::Dcf(DcfCommand::Save(_)) => "dcf save",
        Commander::Dcf(DcfCommand::Load(_)) => "dcf load",
        Commander::Dcf(DcfCommand::Diff(_)) => "dcf diff",
    }
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
