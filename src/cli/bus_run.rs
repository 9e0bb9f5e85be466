//! Running one command on a bus and reporting its outcome: the bus options every commander
//! subcommand takes, a tokio runtime around the command, and its result printed as text or
//! JSON on the stream the command leaves free.

use crate::bus::Bus;
use crate::command::{Command, CommandError, ExitCode, Outcome, Spec};
use clap::Args;
use std::future::Future;

/// Options every commander subcommand takes, before its own.
#[derive(Args, Debug, Clone)]
pub struct BusArgs {
    /// SocketCAN interface (e.g. can0, vcan0), `demo` for the built-in simulated bus, or
    /// socketcand://HOST:PORT/CHANNEL for a bus served by `cotui serve` or socketcand.
    pub iface: String,
    /// Open the bus without a send path: nothing is ever written to it.
    #[arg(long, global = true)]
    pub listen_only: bool,
    /// Print one JSON object instead of text (failures included).
    #[arg(long, global = true)]
    pub json: bool,
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
