//! `cotui record IFACE -o FILE [--count N] [--duration MS]`: a candump `-l` log of the bus,
//! flushed and summed up on Ctrl-C.

use super::commander::{BusArgs, ms_arg, run};
use crate::command::exec::text;
use crate::command::record::{Limits, record};
use crate::command::{Command, CommandError, Outcome};
use clap::Args;

/// Arguments of `cotui record`.
#[derive(Args, Debug)]
pub struct RecordArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// The log file to write (candump -l format; `-` for stdout).
    #[arg(short = 'o', long)]
    pub output: String,
    /// Stop after this many frames.
    #[arg(long)]
    pub count: Option<u64>,
    /// Stop after this many ms (else at Ctrl-C).
    #[arg(long, value_parser = ms_arg)]
    pub duration: Option<u64>,
}

/// Runs `cotui record`; returns the exit status.
pub fn run_record(args: &RecordArgs) -> i32 {
    let limits = Limits {
        count: args.count,
        duration_ms: args.duration,
    };
    let path = args.output.clone();
    let cmd = Command::Record {
        output: path.clone(),
        limits,
    };
    run(&args.bus, "record", |bus| async move {
        let stop = async {
            // Without a signal handler, Ctrl-C would kill us before the log is flushed.
            if tokio::signal::ctrl_c().await.is_err() {
                std::future::pending::<()>().await;
            }
        };
        let n = if path == "-" {
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            record(&bus, &mut out, limits, stop).await?
        } else {
            let file =
                std::fs::File::create(&path).map_err(|e| CommandError::Usage(format!("cannot create {path}: {e}")))?;
            let mut out = std::io::BufWriter::new(file);
            record(&bus, &mut out, limits, stop).await?
        };
        if n.dropped > 0 {
            eprintln!(
                "cotui record: {} frames were dropped before they could be logged (the machine was too busy; \
                 as non-root, raising net.core.rmem_max gives the socket a larger buffer)",
                n.dropped
            );
        }
        let json = serde_json::json!({"ok": true, "frames": n.frames, "dropped": n.dropped, "output": path});
        Ok(Outcome {
            text: text(&cmd, &json),
            json,
        })
    })
}
