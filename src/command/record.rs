//! `record`: writes every frame on the bus to a candump `-l` log (our own frames included).

use super::error::CommandError;
use crate::bus::{Bus, BusError};
use crate::log::writer::LogWriter;
use std::future::Future;
use std::io::Write;

/// When a recording stops (besides `stop` resolving).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Limits {
    /// Stop after this many frames.
    pub count: Option<u64>,
    /// Stop after this many ms.
    pub duration_ms: Option<u64>,
}

/// What a recording wrote and what it missed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Recorded {
    /// Frames written to the log.
    pub frames: u64,
    /// Frames that never reached the log: dropped by the kernel on a full socket buffer,
    /// or overrun in cotui's queue. A complete recording has 0.
    pub dropped: u64,
}

/// Records frames from `bus` into `out` until `stop` resolves or a limit is reached.
/// Read errors of the interface are skipped.
pub async fn record<W: Write>(
    bus: &Bus,
    out: &mut W,
    limits: Limits,
    stop: impl Future<Output = ()>,
) -> Result<Recorded, CommandError> {
    let mut rx = bus.subscribe();
    let mut writer = LogWriter::new();
    let iface = bus.name().to_string();
    let mut n = 0u64;
    let io_err = |e: std::io::Error| CommandError::Usage(format!("writing the log failed: {e}"));
    let deadline = limits
        .duration_ms
        .map(|ms| tokio::time::Instant::now() + std::time::Duration::from_millis(ms));
    let until = async {
        match deadline {
            Some(d) => tokio::time::sleep_until(d).await,
            None => std::future::pending().await,
        }
    };
    tokio::pin!(stop);
    tokio::pin!(until);
    let more = |n: u64| limits.count.is_none_or(|c| n < c);
    'frames: while more(n) {
        tokio::select! {
            _ = &mut stop => break,
            _ = &mut until => break,
            got = rx.recv() => {
                // Write whatever else is queued before polling the stop conditions again.
                let mut next = Some(got);
                while let Some(got) = next {
                    match got {
                        Ok(f) => {
                            writer.write_io(out, &f, &iface).map_err(io_err)?;
                            n += 1;
                        }
                        Err(BusError::Closed) => break 'frames,
                        Err(_) => {}
                    }
                    next = if more(n) { rx.try_recv() } else { None };
                }
            }
        }
    }
    out.flush().map_err(io_err)?;
    Ok(Recorded {
        frames: n,
        dropped: bus.dropped() + rx.lost(),
    })
}
