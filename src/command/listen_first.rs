//! Before `sync` or `nmt` sends: listen a short window of bus time for another producer of
//! the same broadcast (a SYNC producer, an NMT master), with the TUI palette's detector
//! ([`crate::analysis::producers`]); one heard refuses the command unless `--force`.

use super::error::{CommandError, ExitCode};
use crate::analysis::producers::{self, Heard};
use crate::bus::{Bus, BusError};
use serde::Serialize;
use std::future::Future;
use std::pin::Pin;
use std::time::Duration;

/// How long `sync` and `nmt` listen by default before sending (ms of bus time).
pub const LISTEN_MS: u64 = 300;

/// How a command listens before it sends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Listen {
    /// The window in ms of bus time (0: send without listening).
    pub ms: u64,
    /// Send even when another producer is heard (the report says what was heard).
    pub force: bool,
}

/// Another producer heard while listening (`other_producer` in `--json`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct OtherProducer {
    /// What it is: `SYNC producer` or `NMT master`.
    pub producer: &'static str,
    /// The COB-ID heard (integer, 128 = 0x080).
    pub cob_id: u32,
    /// How many of its frames were heard.
    pub heard: usize,
    /// When the last one was heard, in ms after listening began.
    pub last_after_ms: u64,
    /// How long cotui listened (ms of bus time).
    pub listened_ms: u64,
}

impl OtherProducer {
    /// `another SYNC producer is on the bus: 0x080 heard 3 times in 300 ms of listening, the
    /// last 250 ms after it began`.
    pub fn text(&self) -> String {
        format!(
            "another {} is on the bus: 0x{:03X} heard {} time{} in {} ms of listening, the last {} ms after it began",
            self.producer,
            self.cob_id,
            self.heard,
            if self.heard == 1 { "" } else { "s" },
            self.listened_ms,
            self.last_after_ms
        )
    }
}

/// The refusal's `--json` object (`error: "other_producer"`).
#[derive(Debug, Serialize)]
struct Refused {
    other_producer: OtherProducer,
    message: String,
}

/// The command's stop (Ctrl-C), as [`super::spec::Ctx::stop`] holds it.
pub type Stop<'a, 'b> = &'b mut Pin<&'a mut (dyn Future<Output = ()> + Send)>;

/// Before sending `cob_id` as `producer`: fails at once on a listen-only handle (nothing
/// could be sent), listens `listen.ms` of bus time, and refuses (exit 2) when another
/// producer was heard, unless `listen.force`; `stop` while listening ends it at once with
/// nothing sent (exit 2, `error: "stopped"`). What was heard, if anything, for the report.
pub async fn before_sending(
    bus: &Bus,
    cob_id: u32,
    producer: &'static str,
    listen: Listen,
    stop: Stop<'_, '_>,
) -> Result<Option<OtherProducer>, CommandError> {
    if bus.is_listen_only() {
        return Err(BusError::ListenOnly.into());
    }
    let Some(other) = hear(bus, cob_id, producer, listen.ms, stop).await? else {
        return Ok(None);
    };
    if listen.force {
        return Ok(Some(other));
    }
    let message = format!(
        "refused, nothing sent: {}; --force sends anyway, --listen 0 skips listening",
        other.text()
    );
    let json = Refused {
        other_producer: other,
        message: message.clone(),
    };
    Err(nothing_sent("other_producer", json, message))
}

/// A listen that ends the command with nothing sent (exit 2): its `--json` object and text.
fn nothing_sent(error: &'static str, json: impl super::report::Report + 'static, text: String) -> CommandError {
    CommandError::Report {
        exit: ExitCode::Unavailable,
        error,
        report: super::report::Reported::new(json),
        text,
    }
}

/// Stopped while listening: the failure, its `--json` object `{error: "stopped", ...}`.
fn stopped(producer: &str, listened_ms: u64) -> CommandError {
    #[derive(Serialize)]
    struct Stopped {
        listened_ms: u64,
        message: String,
    }
    let message =
        format!("stopped after {listened_ms} ms of listening for another {producer}, before sending: nothing sent");
    let json = Stopped {
        listened_ms,
        message: message.clone(),
    };
    nothing_sent("stopped", json, message)
}

/// Listens `ms` of bus time (until a frame stamped past the window, or the timer on a quiet
/// bus, or `stop`) for frames of `cob_id` another producer sent; None when none was heard
/// (or ms is 0).
async fn hear(
    bus: &Bus,
    cob_id: u32,
    producer: &'static str,
    ms: u64,
    stop: Stop<'_, '_>,
) -> Result<Option<OtherProducer>, CommandError> {
    if ms == 0 {
        return Ok(None);
    }
    let mut rx = bus.subscribe();
    let start = bus.now_ns();
    let end = start + ms * 1_000_000;
    let timer = tokio::time::sleep(Duration::from_millis(ms));
    tokio::pin!(timer);
    let mut heard: Option<Heard> = None;
    loop {
        let f = tokio::select! {
            _ = &mut *stop => return Err(stopped(producer, bus.now_ns().saturating_sub(start) / 1_000_000)),
            _ = &mut timer => break,
            got = rx.recv() => match got {
                Ok(f) => f,
                Err(BusError::Closed) => break,
                Err(e) => return Err(e.into()),
            },
        };
        if f.ts_ns >= end {
            break;
        }
        if producers::from_other(f.id, f.flags, cob_id) {
            heard = Some(Heard::note(heard, f.ts_ns));
        }
    }
    Ok(heard.map(|h| OtherProducer {
        producer,
        cob_id,
        heard: h.count,
        last_after_ms: h.last_ns.saturating_sub(start) / 1_000_000,
        listened_ms: ms,
    }))
}
