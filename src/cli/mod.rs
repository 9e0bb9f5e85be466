//! The command line: clap definitions and one module per subcommand.

pub mod bind;
pub mod commander;
pub mod decode;
mod decode_filter;
mod decode_out;
mod decode_parquet;
pub mod diagnose;
pub mod drive;
pub mod nmt;
pub mod record;
pub mod run;
pub mod scan;
pub mod sdo;
pub mod stop;
pub mod tui;

use clap::{Parser, Subcommand};

/// Exit status: done.
pub const EXIT_OK: i32 = 0;
/// Exit status: usage or internal error.
pub const EXIT_USAGE: i32 = 1;
/// Exit status: input or bus unavailable.
pub const EXIT_UNAVAILABLE: i32 = 2;

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
    /// Send an NMT command: cotui nmt IFACE start|stop|preop|reset-node|reset-comm NODE [--wait].
    Nmt(nmt::NmtArgs),
    /// Read or write an object by SDO (IFACE `demo` for the simulated bus).
    #[command(subcommand)]
    Sdo(sdo::SdoCommand),
    /// CiA 402 drive: cotui drive IFACE NODE enable|disable|quick-stop|fault-reset|status|mode MODE.
    Drive(drive::DriveArgs),
    /// Run a profile's procedure step by step: cotui run IFACE NODE PROCEDURE [NAME=VALUE ...] [--dry-run];
    /// without PROCEDURE (or with --list), list the node's procedures.
    Run(run::RunArgs),
    /// List the nodes on the bus with their identity.
    Scan(scan::ScanArgs),
    /// Record the bus to a candump -l log.
    Record(record::RecordArgs),
    /// Emergency stop: quick stop, then disable voltage, on every CiA 402 drive found powered
    /// (or the --node ones); reads each statusword back. Exit 0 only when all are confirmed.
    Stop(stop::StopArgs),
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
pub fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { EXIT_USAGE } else { EXIT_OK };
        }
    };
    VERBOSE.store(cli.verbose, std::sync::atomic::Ordering::Relaxed);
    match cli.command {
        None => {
            print!("{USAGE}");
            EXIT_OK
        }
        Some(Command::Decode(args)) => decode::run(&args),
        Some(Command::Diagnose(args)) => diagnose::run(&args),
        Some(Command::Bench(args)) => crate::bench::run(&args),
        Some(Command::Open(args)) => tui::run_open(&args),
        Some(Command::Replay(args)) => tui::run_replay(&args),
        Some(Command::Live(args)) => tui::run_live(&args),
        Some(Command::Demo(args)) => tui::run_demo(&args),
        Some(Command::Nmt(args)) => nmt::run_nmt(&args),
        Some(Command::Sdo(cmd)) => sdo::run_sdo(&cmd),
        Some(Command::Drive(args)) => drive::run_drive(&args),
        Some(Command::Run(args)) => run::run_run(&args),
        Some(Command::Scan(args)) => scan::run_scan(&args),
        Some(Command::Record(args)) => record::run_record(&args),
        Some(Command::Stop(args)) => stop::run_stop(&args),
    }
}
