//! `cotui record IFACE --trigger EXPR --pre DUR --post DUR -o DIR`: the flight recorder on
//! a live bus ([`super::trigger::Flight`] over the bus's frames, a 100 ms clock tick and
//! the interface's state changes). Stops on SIGINT, SIGTERM, SIGHUP or SIGQUIT, at
//! `--duration` or after `--count` windows; on stop, the frames the kernel still holds
//! are taken first, then an open window is closed with what it has.

use super::commander::{BusArgs, Stream, report_to};
use super::trigger::{Flight, Settings};
use crate::analysis::trigger::detect::Link;
use crate::bus::{Bus, BusError, BusState, Event};
use crate::command::record::{Record, TriggerWords};
use crate::command::{CommandError, ExitCode};
use std::future::Future;
use std::path::Path;
use std::time::Duration;
use tokio::signal::unix::{SignalKind, signal};

/// How often the capture clock ticks on a quiet bus (heartbeats found lost, windows closed,
/// written frames flushed).
const TICK: Duration = Duration::from_millis(100);

/// What a triggered recording did.
#[derive(Debug, serde::Serialize)]
pub struct Triggered {
    /// Windows written.
    pub windows: u64,
    /// Frames seen on the bus.
    pub frames: u64,
    /// Frames the kernel or cotui's queue dropped (a complete capture has 0).
    pub dropped: u64,
    /// The directory of the window files.
    pub output: String,
}

/// Runs `record --trigger`; returns the exit status (1: usage, 2: the bus).
pub fn run(bus: &BusArgs, r: &Record, t: &TriggerWords) -> ExitCode {
    let usage = |m: String| report_to(bus, "record", Stream::Stdout, Err(CommandError::Usage(m)));
    if r.output == "-" {
        return usage("--trigger writes window files: give -o DIR".into());
    }
    let decoder = match super::bind::decoder(&[], &[]) {
        Ok(d) => d,
        Err(e) => return usage(e.to_string()),
    };
    let trigger = match super::trigger::parse("--trigger", &t.expr, &decoder) {
        Ok(x) => x,
        Err(e) => return usage(e),
    };
    let settings = Settings {
        expr: t.expr.clone(),
        pre_ms: t.pre_ms,
        post_ms: t.post_ms,
    };
    let mut flight = match Flight::new(trigger, decoder, &settings, Some(Path::new(&r.output)), r.format) {
        Ok(f) => f,
        Err(e) => return usage(e),
    };
    let result = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| CommandError::Usage(format!("cannot start the runtime: {e}")))
        .and_then(|rt| {
            rt.block_on(async {
                let handler = |kind: SignalKind| {
                    signal(kind).map_err(|e| CommandError::Usage(format!("cannot install a signal handler: {e}")))
                };
                let mut signals = [
                    handler(SignalKind::interrupt())?,
                    handler(SignalKind::terminate())?,
                    handler(SignalKind::hangup())?,
                    handler(SignalKind::quit())?,
                ];
                let b = crate::connect::open(&bus.iface, bus.listen_only).await?;
                let [int, term, hup, quit] = &mut signals;
                let stop = async {
                    tokio::select! {
                        _ = int.recv() => {}
                        _ = term.recv() => {}
                        _ = hup.recv() => {}
                        _ = quit.recv() => {}
                    }
                };
                capture(&b, &mut flight, r.limits.count, r.limits.duration_ms, stop).await
            })
        });
    let mut n = match result {
        Ok(n) => n,
        Err(e) => return report_to(bus, "record", Stream::Stdout, Err(e)),
    };
    n.output = r.output.clone();
    if bus.json {
        Stream::Stdout.line(&crate::command::to_json(&n).to_string());
    } else {
        Stream::Stdout.line(&format!(
            "{} window(s) written to {} ({} frames seen)",
            n.windows, n.output, n.frames
        ));
    }
    if n.dropped > 0 {
        eprintln!(
            "cotui record: {} frames were dropped before they could be judged (the machine was too busy)",
            n.dropped
        );
        return ExitCode::Unavailable;
    }
    ExitCode::Ok
}

/// Feeds `bus` to `flight` until `stop` resolves, `duration_ms` passes or `max_windows`
/// windows are written; then the frames still queued, then the open window is closed.
pub async fn capture(
    bus: &Bus,
    flight: &mut Flight,
    max_windows: Option<u64>,
    duration_ms: Option<u64>,
    stop: impl Future<Output = ()>,
) -> Result<Triggered, CommandError> {
    let io = |e: std::io::Error| CommandError::Usage(format!("writing a window failed: {e}"));
    let mut ifaces = crate::frame::Interfaces::default();
    ifaces.intern(bus.name());
    flight.name_interfaces(&ifaces);
    let mut rx = bus.subscribe();
    let mut frames = 0u64;
    let mut tick = tokio::time::interval(TICK);
    let end = duration_ms.map(|ms| tokio::time::Instant::now() + Duration::from_millis(ms));
    let until = async {
        match end {
            Some(e) => tokio::time::sleep_until(e).await,
            None => std::future::pending().await,
        }
    };
    tokio::pin!(stop);
    tokio::pin!(until);
    let done = |f: &Flight| max_windows.is_some_and(|m| f.windows() >= m);
    let mut closed = false;
    while !done(flight) {
        tokio::select! {
            _ = &mut stop => break,
            _ = &mut until => break,
            _ = tick.tick() => flight.tick(bus.now_ns()).map_err(io)?,
            got = rx.next() => {
                if !take(got, bus.name(), flight, &mut frames).map_err(io)? {
                    closed = true;
                    break;
                }
            }
        }
    }
    if !closed && !done(flight) {
        // Stopped: what the kernel queued before the stop belongs to the capture.
        let caught = bus.catch_up();
        tokio::pin!(caught);
        loop {
            tokio::select! {
                biased;
                got = rx.next() => {
                    if !take(got, bus.name(), flight, &mut frames).map_err(io)? {
                        break;
                    }
                }
                _ = &mut caught => break,
            }
        }
        while let Some(got) = rx.try_next() {
            if !take(got, bus.name(), flight, &mut frames).map_err(io)? {
                break;
            }
        }
    }
    flight.finish().map_err(io)?;
    Ok(Triggered {
        windows: flight.windows(),
        frames,
        dropped: bus.dropped() + rx.lost(),
        output: String::new(),
    })
}

/// One event of the bus into the flight recorder; false when the bus is closed.
fn take(got: Result<Event, BusError>, iface: &str, flight: &mut Flight, frames: &mut u64) -> std::io::Result<bool> {
    match got {
        Ok(Event::Frame(f)) => {
            *frames += 1;
            flight.frame(&f)?;
        }
        Ok(Event::State(s)) => {
            eprintln!("cotui record: {}", s.text(iface));
            let link = match s.state {
                BusState::Down | BusState::Missing => Some(Link::Down),
                BusState::BusOff => Some(Link::BusOff),
                BusState::Passive => Some(Link::Passive),
                BusState::Active | BusState::Warning => None,
            };
            if let Some(l) = link {
                flight.link(s.ts_ns, l)?;
            }
        }
        Err(BusError::Closed) => return Ok(false),
        Err(e) => eprintln!("cotui record: {e}"),
    }
    Ok(true)
}
