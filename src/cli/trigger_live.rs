//! `cotui record IFACE --trigger EXPR --pre DUR --post DUR -o DIR`: the flight recorder on
//! a live bus ([`super::trigger::Flight`] over the bus's frames, a 100 ms clock tick and
//! the interface's state changes). Stops on SIGINT, SIGTERM, SIGHUP or SIGQUIT, at
//! `--duration` or after `--count` windows; on stop, the frames the kernel still holds
//! are taken first, then an open window is closed with what it has.

use super::trigger::{Flight, Settings};
use crate::analysis::trigger::detect::Link;
use crate::bus::{Bus, BusError, BusState, Event};
use crate::command::record::{Record, TriggerWords};
use crate::command::{CommandError, ExitCode};
use std::future::Future;
use std::io::Write;
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

/// Runs `record --trigger` on `iface` (opened listen-only if asked): what it wrote, or why
/// it could not (the caller reports it as any command's failure).
pub fn run(iface: &str, listen_only: bool, r: &Record, t: &TriggerWords) -> Result<Triggered, CommandError> {
    if r.output == "-" {
        return Err(CommandError::Usage("--trigger writes window files: give -o DIR".into()));
    }
    let decoder = super::bind::decoder(&[], &[]).map_err(|e| CommandError::Usage(e.to_string()))?;
    let trigger = super::trigger::parse("--trigger", &t.expr, &decoder).map_err(CommandError::Usage)?;
    let settings = Settings {
        expr: t.expr.clone(),
        pre_ms: t.pre_ms,
        post_ms: t.post_ms,
    };
    let mut flight =
        Flight::new(trigger, decoder, &settings, Some(Path::new(&r.output)), r.format).map_err(CommandError::Usage)?;
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| CommandError::Usage(format!("cannot start the runtime: {e}")))?;
    let mut n = rt.block_on(async {
        let handler = |kind: SignalKind| {
            signal(kind).map_err(|e| CommandError::Usage(format!("cannot install a signal handler: {e}")))
        };
        let mut signals = [
            handler(SignalKind::interrupt())?,
            handler(SignalKind::terminate())?,
            handler(SignalKind::hangup())?,
            handler(SignalKind::quit())?,
        ];
        let b = crate::connect::open(iface, listen_only).await?;
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
    })?;
    n.output = r.output.clone();
    Ok(n)
}

impl Triggered {
    /// Prints the report (JSON or a line) and says dropped frames on stderr; the exit status
    /// (2 when frames were dropped).
    pub fn say(&self, json: bool) -> ExitCode {
        let line = if json {
            crate::command::to_json(self).to_string()
        } else {
            format!(
                "{} window(s) written to {} ({} frames seen)",
                self.windows, self.output, self.frames
            )
        };
        // After SIGHUP the terminal may be gone: printing must not fail the recording.
        let _ = writeln!(std::io::stdout(), "{line}");
        if self.dropped == 0 {
            return ExitCode::Ok;
        }
        let _ = writeln!(
            std::io::stderr(),
            "cotui record: {} frames were dropped before they could be judged (the machine was too busy)",
            self.dropped
        );
        ExitCode::Unavailable
    }
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
                BusState::Down | BusState::Missing | BusState::Disconnected => Some(Link::Down),
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
