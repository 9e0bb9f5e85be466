//! `cotui record IFACE -o FILE [--count N] [--duration MS] [--force | --append]`: a candump
//! `-l` log of the bus. Stops on SIGINT, SIGTERM, SIGHUP or SIGQUIT (after writing every frame
//! the kernel still holds) or at a limit; lines go out at least every 200 ms, so `kill -9`
//! loses at most that much. Gaps (interface down or gone, bus-off) are reported on stderr as
//! they happen and make the exit status 2.

use super::commander::{BusArgs, ms_arg, report};
use crate::command::error::{EXIT_BUS, EXIT_OK};
use crate::command::exec::text;
use crate::command::record::{Limits, LogFormat, Recorded, WriteMode, open_output, record};
use crate::command::{Command, CommandError};
use clap::Args;
use std::io::Write;
use tokio::signal::unix::{SignalKind, signal};

/// Arguments of `cotui record`.
#[derive(Args, Debug)]
pub struct RecordArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// The log file to write (candump -l format; `-` for stdout). An existing file is
    /// refused unless --force or --append.
    #[arg(short = 'o', long)]
    pub output: String,
    /// Stop after this many frames.
    #[arg(long)]
    pub count: Option<u64>,
    /// Stop after this many ms (else at Ctrl-C, SIGTERM, SIGHUP or SIGQUIT).
    #[arg(long, value_parser = ms_arg)]
    pub duration: Option<u64>,
    /// Overwrite an existing output file.
    #[arg(long, conflicts_with = "append")]
    pub force: bool,
    /// Append to an existing output file.
    #[arg(long)]
    pub append: bool,
    /// The file format: candump (-l lines) or pcapng (for Wireshark; not to a terminal).
    #[arg(long, default_value = "candump", value_parser = LogFormat::parse)]
    pub format: LogFormat,
}

/// Runs `cotui record`; returns the exit status: 0 complete, 2 when the bus could not be
/// opened or the recording has gaps, 1 for a usage or write error.
pub fn run_record(args: &RecordArgs) -> i32 {
    let limits = Limits {
        count: args.count,
        duration_ms: args.duration,
    };
    let mode = if args.force {
        WriteMode::Overwrite
    } else if args.append {
        WriteMode::Append
    } else {
        WriteMode::New
    };
    let path = args.output.clone();
    if args.format == LogFormat::Pcapng && path == "-" && std::io::IsTerminal::is_terminal(&std::io::stdout()) {
        return report(
            &args.bus,
            "record",
            Err(CommandError::Usage(
                "pcapng is binary: write it to a file (-o FILE) or a pipe, not to a terminal".into(),
            )),
        );
    }
    let result = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| CommandError::Usage(format!("cannot start the runtime: {e}")))
        .and_then(|rt| rt.block_on(capture(&args.bus, &path, (limits, args.format), mode)));
    let n = match result {
        Ok(n) => n,
        Err(e) => return report(&args.bus, "record", Err(e)),
    };
    let cmd = Command::Record {
        output: path.clone(),
        limits,
        mode,
        format: args.format,
    };
    let json = n.to_json(&path);
    // After SIGHUP the terminal may be gone: printing must not fail the recording.
    if args.bus.json {
        let _ = writeln!(std::io::stdout(), "{json}");
    } else {
        let _ = writeln!(std::io::stdout(), "{}", text(&cmd, &json));
    }
    if n.dropped > 0 {
        say(&format!(
            "{} frames were dropped before they could be logged (the machine was too busy; \
             as non-root, raising net.core.rmem_max gives the socket a larger buffer)",
            n.dropped
        ));
    }
    match n.gap_message(&path) {
        Some(m) => {
            say(&m);
            EXIT_BUS
        }
        None => EXIT_OK,
    }
}

/// Opens the bus and the log, and records until a signal or a limit.
async fn capture(
    args: &BusArgs,
    path: &str,
    (limits, format): (Limits, LogFormat),
    mode: WriteMode,
) -> Result<Recorded, CommandError> {
    // Handlers first: from here on a signal stops the recording cleanly instead of killing it.
    let handler = |kind: SignalKind| {
        signal(kind).map_err(|e| CommandError::Usage(format!("cannot install a signal handler: {e}")))
    };
    let mut signals = [
        handler(SignalKind::interrupt())?,
        handler(SignalKind::terminate())?,
        handler(SignalKind::hangup())?,
        handler(SignalKind::quit())?,
    ];
    let bus = crate::connect::open(&args.iface, args.listen_only).await?;
    let mut out = open_output(path, mode)?;
    let [int, term, hup, quit] = &mut signals;
    let stop = async {
        tokio::select! {
            _ = int.recv() => {}
            _ = term.recv() => {}
            _ = hup.recv() => {}
            _ = quit.recv() => {}
        }
    };
    record(&bus, &mut out, limits, format, stop, |line| say(&line)).await
}

/// One line on stderr; a closed terminal is not an error.
fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "cotui record: {line}");
}
