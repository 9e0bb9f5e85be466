//! The command line: clap definitions and one module per subcommand.

pub mod bind;
pub mod commander;
pub mod decode;
mod decode_filter;
mod decode_out;
mod decode_parquet;
pub mod diagnose;
pub mod input;
pub mod record;
pub mod run;
pub mod sim;
pub mod tui;

use crate::command::{CommandError, ExitCode, ParseError};
use clap::{Parser, Subcommand};

/// cotui: a terminal CANopen bus analyzer and commander.
#[derive(Parser, Debug)]
#[command(name = "cotui", version, about, long_about = None, arg_required_else_help = false)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Print every warning (by default, one line per kind with a count).
    #[arg(long, global = true)]
    pub verbose: bool,
}

/// Set from `--verbose` at start.
static VERBOSE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// True when `--verbose` was given.
pub fn verbose() -> bool {
    VERBOSE.load(std::sync::atomic::Ordering::Relaxed)
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Decode candump / ASC logs to text, JSON lines, SDO transactions, a summary or pcapng.
    Decode(decode::DecodeArgs),
    /// What went wrong on the bus, in plain words: incidents with cause, timeline and what to check.
    Diagnose(diagnose::DiagnoseArgs),
    /// Print throughput and memory figures of the decoder on a generated log.
    Bench(crate::bench::BenchArgs),
    /// Open a log in the interactive analyzer (loads at once; browse, filter, search).
    Open(tui::OpenArgs),
    /// Replay a log in the interactive analyzer, paced by its timestamps.
    Replay(tui::ReplayArgs),
    /// Capture a SocketCAN interface in the interactive analyzer, with the command palette.
    Live(tui::LiveArgs),
    /// The interactive analyzer on an in-process bus with simulated CiA 402 drives.
    Demo(tui::DemoArgs),
    /// The commander: nmt, sdo, drive, run, scan, record, stop, lss (see docs/COMMANDER.md).
    #[command(flatten)]
    Commander(commander::CliCommander),
    /// Simulated CiA 402 drives on a SocketCAN interface for other tools to talk to (SDO,
    /// NMT, PDO, SYNC, EMCY, LSS); stdin lines make them fail: fault/silence/reboot NODE.
    Sim(sim::SimArgs),
}

/// Short usage printed by `cotui` without arguments.
pub const USAGE: &str = "\
cotui: a terminal CANopen bus analyzer and commander

Try it without hardware:   cotui demo
Browse a log:              cotui open FILE
Replay a log:              cotui replay FILE [--speed 2]
Decode a candump log:      cotui decode FILE [--format jsonl] [--transactions] [--summary]
What went wrong:           cotui diagnose FILE [--format jsonl] [--check]
All commands:              cotui --help
";

/// Runs the command line and returns the process exit status.
pub fn run() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => return refused(e, std::env::args_os().skip(1)),
    };
    VERBOSE.store(cli.verbose, std::sync::atomic::Ordering::Relaxed);
    match cli.command {
        None => {
            print!("{USAGE}");
            ExitCode::Ok
        }
        Some(Command::Decode(args)) => decode::run(&args),
        Some(Command::Diagnose(args)) => diagnose::run(&args),
        Some(Command::Bench(args)) => crate::bench::run(&args),
        Some(Command::Open(args)) => tui::run_open(&args),
        Some(Command::Replay(args)) => tui::run_replay(&args),
        Some(Command::Live(args)) => tui::run_live(&args),
        Some(Command::Demo(args)) => tui::run_demo(&args),
        Some(Command::Sim(args)) => sim::run_sim(&args),
        Some(Command::Commander(c)) => commander::run_commander(&c),
    }
}

/// Prints why the command line was refused (or the help it asked for) and gives the exit
/// status. With `--json` among the `args` a refusal is also one JSON object on stdout, as
/// every other failure of a command that takes `--json`.
pub fn refused(e: clap::Error, args: impl IntoIterator<Item = std::ffi::OsString>) -> ExitCode {
    let _ = e.print();
    if !e.use_stderr() {
        return ExitCode::Ok;
    }
    if args.into_iter().take_while(|a| a != "--").any(|a| a == "--json") {
        println!("{}", CommandError::Syntax(ParseError::from(e)).to_json());
    }
    ExitCode::Usage
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_declaration_is_consistent() {
        // Duplicate names, flags or argument groups (e.g. from flattening the commander's
        // declaration) would only panic when that subcommand is parsed.
        Cli::command().debug_assert();
    }

    #[test]
    fn a_refused_line_gives_exit_status_1_and_help_0() {
        let refused_with = |args: &[&str]| {
            let e = Cli::try_parse_from(args).unwrap_err();
            refused(e, args.iter().map(std::ffi::OsString::from))
        };
        assert_eq!(
            refused_with(&["cotui", "nmt", "demo", "start", "2", "--block", "--json"]),
            ExitCode::Usage
        );
        assert_eq!(refused_with(&["cotui", "nmt", "--help"]), ExitCode::Ok);
    }
}
