//! `cotui record IFACE [IFACE...] -o FILE [--count N] [--duration MS] [--force | --append]`:
//! a candump `-l` log of the bus (of several buses: one log, frames in time order, each with
//! its interface). Stops on SIGINT, SIGTERM, SIGHUP or SIGQUIT (after writing every frame
//! the kernel still holds) or at a limit; lines go out at least every 200 ms, so `kill -9`
//! loses at most that much. Gaps (interface down or gone, bus-off) are reported on stderr as
//! they happen and make the exit status 2.

use super::bus_run::{BusArgs, Stream, report_to};
use crate::command::record::{LogFormat, Record, Recorded, open_output, record};
use crate::command::{CommandError, ExitCode};
use std::io::Write;
use tokio::signal::unix::{SignalKind, signal};

/// Runs `cotui record` (its arguments: [`crate::command::record::RecordArgs`]); returns the
/// exit status: 0 complete, 2 when the bus could not be opened or the recording has gaps, 1
/// for a usage or write error.
pub fn run_record(bus: &BusArgs, r: &Record) -> ExitCode {
    let (path, format) = (r.output.as_str(), r.format);
    let mut ifaces = vec![bus.iface.clone()];
    ifaces.extend(r.more.iter().cloned());
    if let Some(twice) = super::input::repeated(&ifaces) {
        return report_to(
            bus,
            "record",
            Stream::Stderr,
            Err(CommandError::Usage(format!(
                "{twice} is given twice: name each interface once"
            ))),
        );
    }
    if format != LogFormat::Candump && path == "-" && std::io::IsTerminal::is_terminal(&std::io::stdout()) {
        return report_to(
            bus,
            "record",
            Stream::Stderr,
            Err(CommandError::Usage(format!(
                "{} is binary: write it to a file (-o FILE) or a pipe, not to a terminal",
                if format == LogFormat::Blf { "BLF" } else { "pcapng" }
            ))),
        );
    }
    let result = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| CommandError::Usage(format!("cannot start the runtime: {e}")))
        .and_then(|rt| rt.block_on(capture(bus, &ifaces, r)));
    // `-o -`: stdout is the log; every report goes to stderr.
    let to = if path == "-" { Stream::Stderr } else { Stream::Stdout };
    let n = match result {
        Ok(n) => n,
        Err(e) => return report_to(bus, "record", to, Err(e)),
    };
    let report = n.report(path);
    // After SIGHUP the terminal may be gone: printing must not fail the recording.
    if bus.json {
        to.line(&crate::command::to_json(&report).to_string());
    } else {
        to.line(&report.text());
    }
    if n.dropped > 0 {
        say(&format!(
            "{} frames were dropped before they could be logged (the machine was too busy; \
             as non-root, raising net.core.rmem_max gives the socket a larger buffer)",
            n.dropped
        ));
    }
    match n.gap_message(path) {
        Some(m) => {
            say(&m);
            ExitCode::Unavailable
        }
        None => ExitCode::Ok,
    }
}

/// Opens the buses and the log, and records until a signal or a limit.
async fn capture(args: &BusArgs, ifaces: &[String], r: &Record) -> Result<Recorded, CommandError> {
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
    let mut buses = Vec::with_capacity(ifaces.len());
    for iface in ifaces {
        buses.push((iface.clone(), crate::connect::open(iface, args.listen_only).await?));
    }
    let mut out = open_output(&r.output, r.mode, r.format)?;
    let [int, term, hup, quit] = &mut signals;
    let stop = async {
        tokio::select! {
            _ = int.recv() => {}
            _ = term.recv() => {}
            _ = hup.recv() => {}
            _ = quit.recv() => {}
        }
    };
    record(&buses, &mut out, r.limits, r.format, stop, |line| say(&line)).await
}

/// One line on stderr; a closed terminal is not an error.
fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "cotui record: {line}");
}
