//! The command line: clap definitions and one module per subcommand.

pub mod bench;
mod bind;
pub mod decode;

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
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Decode candump / ASC logs to text, JSON lines, SDO transactions or a summary.
    Decode(decode::DecodeArgs),
    /// Print throughput and memory figures of the decoder on a generated log.
    Bench(bench::BenchArgs),
}

/// Short usage printed by `cotui` without arguments.
pub const USAGE: &str = "\
cotui: a terminal CANopen bus analyzer and commander

Try it without hardware:   cotui demo
Decode a candump log:      cotui decode FILE [--format jsonl] [--transactions] [--summary]
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
    match cli.command {
        None => {
            print!("{USAGE}");
            EXIT_OK
        }
        Some(Command::Decode(args)) => decode::run(&args),
        Some(Command::Bench(args)) => bench::run(&args),
    }
}
