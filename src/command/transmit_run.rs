//! Sends a transmit list ([`super::transmit_list`]) on a bus: every enabled entry on its
//! own schedule, from one task and one subscription, until every entry is done, the
//! duration is over, the caller stops it, or a stop is seen on the bus.
//!
//! Timing is that of [`super::cyclic`]: each periodic entry stays on its grid, a tick missed
//! on a busy machine is dropped (never a burst), and the achieved period and jitter come
//! from the receive timestamps of our own frames as they come back marked TX. An echo is
//! counted for the first entry with that exact frame still waiting for one.
//!
//! Stop-all: a quick stop (controlword 0x0002 written by SDO, as `cotui stop` and the TUI's
//! stop-all send it) that another program puts on the bus disables every entry at once,
//! so the list cannot re-enable a drive someone is stopping.

use super::cyclic::Tally;
use super::drive::{STOP_CONTROLWORDS, controlword_frame};
use super::error::CommandError;
use super::transmit_list::Resolved;
use crate::bus::{Bus, BusError, Event};
use crate::frame::{Direction, Frame};
use serde::Serialize;
use std::future::Future;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::time::Instant;

/// How long to wait for the echoes of the last frames sent before reporting.
const ECHO_WAIT: Duration = Duration::from_secs(1);

/// `send --list --json`: each entry's frame, schedule and counts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ListReport {
    pub ok: bool,
    /// The list file.
    pub file: String,
    /// `--duration`, in ms (null: until every entry is done or stopped).
    pub duration_ms: Option<u64>,
    /// Why the entries were disabled before their end (a quick stop seen on the bus).
    pub stopped_by: Option<String>,
    pub entries: Vec<EntryReport>,
}

/// One entry of a [`ListReport`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EntryReport {
    /// Its index in the list (from 1) and its line in the file.
    pub entry: usize,
    pub line: usize,
    /// The exact frame, candump's compact form.
    pub frame: String,
    /// `601#40...` or `RPDO1 node 2 202#0F00...`.
    pub what: String,
    pub every_ms: Option<u64>,
    pub count: Option<u64>,
    pub enabled: bool,
    pub comment: Option<String>,
    /// Frames sent.
    pub sent: u64,
    /// Frames seen back on the bus, and the time from the first to the last of them (ms,
    /// by their receive timestamps).
    pub seen: u64,
    pub seen_span_ms: Option<f64>,
    pub mean_period_ms: Option<f64>,
    pub jitter_p99_ms: Option<f64>,
    pub jitter_max_ms: Option<f64>,
    /// Mapped signals not given, sent as 0 (RPDO entries).
    pub defaulted: Vec<String>,
}

impl ListReport {
    /// One line per entry: `entry 1 (line 3) 601#40...: 10 frames sent every 100 ms, ...`.
    pub fn text(&self) -> String {
        let mut lines: Vec<String> = self
            .entries
            .iter()
            .map(|e| {
                let head = format!("entry {} (line {})", e.entry, e.line);
                if !e.enabled {
                    return format!("{head} {}: disabled, not sent", e.what);
                }
                let mut t = format!("{head} {}: {} sent", e.what, plural(e.sent, "frame"));
                if let Some(p) = e.every_ms {
                    t.push_str(&format!(" every {p} ms"));
                }
                if let (Some(m), Some(p99), Some(max)) = (e.mean_period_ms, e.jitter_p99_ms, e.jitter_max_ms) {
                    t.push_str(&format!(
                        ", mean period {m:.3} ms, jitter p99 {p99:.3} ms, max {max:.3} ms ({} seen)",
                        e.seen
                    ));
                }
                if !e.defaulted.is_empty() {
                    t.push_str(&format!("; not given, sent as 0: {}", e.defaulted.join(", ")));
                }
                t
            })
            .collect();
        if let Some(why) = &self.stopped_by {
            lines.push(format!("every entry disabled: {why}"));
        }
        lines.join("\n")
    }
}

fn plural(n: u64, word: &str) -> String {
    format!("{n} {word}{}", if n == 1 { "" } else { "s" })
}

/// The counts of every entry so far, shared with whoever lists or stops the list.
pub type ListProgress = Arc<Mutex<Vec<Tally>>>;

/// One entry while the list runs.
struct Running {
    entry: Resolved,
    /// When it sends next (`None`: done, or disabled).
    due: Option<Instant>,
    sent: u64,
}

impl Running {
    fn period(&self) -> Option<Duration> {
        self.entry.schedule.every_ms.map(Duration::from_millis)
    }

    fn done(&self) -> bool {
        self.entry.schedule.total().is_some_and(|n| self.sent >= n)
    }
}

/// The node whose quick stop `f` is, when it is one sent by someone else (an RX frame).
fn quick_stop_of(f: &Frame) -> Option<u8> {
    let node = (f.id & 0x7F) as u8;
    (f.direction() == Direction::Rx
        && !f.is_ext()
        && (1..=127).contains(&node)
        && same_frame(f, &controlword_frame(node, STOP_CONTROLWORDS[0])))
    .then_some(node)
}

/// True when `echo` (a frame on the bus) is `sent` come back.
fn same_frame(echo: &Frame, sent: &Frame) -> bool {
    echo.id == sent.id && echo.is_ext() == sent.is_ext() && echo.payload() == sent.payload() && echo.len == sent.len
}

/// Notes an echo for the first entry with this frame still waiting for one.
fn note_echo(f: &Frame, entries: &[Running], progress: &ListProgress) {
    if f.direction() != Direction::Tx {
        return;
    }
    let mut tallies = lock_all(progress);
    if let Some(k) =
        (0..entries.len()).find(|k| same_frame(f, &entries[*k].entry.frame) && tallies[*k].seen < entries[*k].sent)
    {
        let period_ns = entries[k].entry.schedule.every_ms.map(|p| p * 1_000_000);
        tallies[k].echo(f.ts_ns, period_ns);
    }
}

/// Locks the tallies (a poisoned lock still holds the counts).
pub fn lock_all(p: &ListProgress) -> std::sync::MutexGuard<'_, Vec<Tally>> {
    p.lock().unwrap_or_else(|e| e.into_inner())
}

/// Sends `entries` on `bus` for `duration_ms` from the first frames sent (or until every entry is done, `stop`
/// completes, or a quick stop by someone else is seen), noting counts in `progress`; then
/// waits (up to a second) for the echoes of the frames sent and reports. A listen-only bus
/// is refused before anything.
pub async fn transmit_list(
    bus: &Bus,
    file: &str,
    entries: Vec<Resolved>,
    duration_ms: Option<u64>,
    progress: ListProgress,
    stop: impl Future<Output = ()>,
) -> Result<ListReport, CommandError> {
    if bus.is_listen_only() {
        return Err(BusError::ListenOnly.into());
    }
    *lock_all(&progress) = vec![Tally::default(); entries.len()];
    let mut rx = bus.subscribe();
    let start = Instant::now();
    let mut run: Vec<Running> = entries
        .into_iter()
        .map(|entry| Running {
            due: entry.enabled.then_some(start),
            entry,
            sent: 0,
        })
        .collect();
    let mut deadline = duration_ms.map(|ms| start + Duration::from_millis(ms));
    tokio::pin!(stop);
    let mut stopped_by = None;
    let mut anchored = false;
    while let Some(next) = run.iter().filter_map(|r| r.due).min() {
        if deadline.is_some_and(|d| next >= d) {
            // Nothing more is due inside the duration.
            break;
        }
        tokio::select! {
            _ = &mut stop => break,
            _ = tokio::time::sleep_until(next) => {}
            ev = rx.next() => {
                match ev {
                    Ok(Event::Frame(f)) => {
                        if let Some(node) = quick_stop_of(&f) {
                            stopped_by = Some(format!(
                                "a quick stop of node {node} was seen on the bus (a stop-all); nothing more sent"
                            ));
                            break;
                        }
                        note_echo(&f, &run, &progress);
                    }
                    Err(BusError::Closed) => break,
                    _ => {}
                }
                continue;
            }
        }
        let now = Instant::now();
        for (k, r) in run.iter_mut().enumerate() {
            if r.due.is_none_or(|d| d > now) {
                continue;
            }
            bus.send(&r.entry.frame).await?;
            r.sent += 1;
            lock_all(&progress)[k].sent = r.sent;
            r.due = match (r.done(), r.period(), r.due) {
                (true, ..) => None,
                // Once, `count` times: back to back.
                (false, None, due) => due,
                (false, Some(p), Some(due)) => {
                    // Stay on the grid; ticks already past are dropped, not caught up.
                    let mut next = due + p;
                    while next <= now {
                        next += p;
                    }
                    Some(next)
                }
                (false, Some(_), None) => None,
            };
        }
        if !anchored {
            // The grid and the duration start when the first frames are out: a slow first
            // send (a cold start) shifts them instead of dropping the ticks it took.
            anchored = true;
            let lag = Instant::now().saturating_duration_since(start);
            deadline = deadline.map(|d| d + lag);
            run.iter_mut().filter_map(|r| r.due.as_mut()).for_each(|d| *d += lag);
        }
    }
    // The echoes still queued (or on their way) of the frames sent.
    let until = Instant::now() + ECHO_WAIT;
    let waiting =
        |progress: &ListProgress, run: &[Running]| lock_all(progress).iter().zip(run).any(|(t, r)| t.seen < r.sent);
    while waiting(&progress, &run) {
        match tokio::time::timeout_at(until, rx.next()).await {
            Ok(Ok(Event::Frame(f))) => note_echo(&f, &run, &progress),
            Ok(Ok(_)) => {}
            Ok(Err(BusError::Closed)) | Err(_) => break,
            Ok(Err(_)) => {}
        }
    }
    let tallies = lock_all(&progress).clone();
    let entries = run
        .iter()
        .zip(&tallies)
        .map(|(r, t)| {
            let e = &r.entry;
            let timing = t.report(&e.what, e.schedule.every_ms, &e.defaulted);
            EntryReport {
                entry: e.index,
                line: e.line,
                frame: super::spec::candump(&e.frame),
                what: e.what.clone(),
                every_ms: e.schedule.every_ms,
                count: e.schedule.count,
                enabled: e.enabled,
                comment: e.comment.clone(),
                sent: r.sent,
                seen: t.seen,
                seen_span_ms: t.span_ns().map(|ns| ns as f64 / 1e6),
                mean_period_ms: timing.mean_period_ms,
                jitter_p99_ms: timing.jitter_p99_ms,
                jitter_max_ms: timing.jitter_max_ms,
                defaulted: e.defaulted.clone(),
            }
        })
        .collect();
    Ok(ListReport {
        ok: true,
        file: file.to_string(),
        duration_ms,
        stopped_by,
        entries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quick_stop_from_someone_else_is_recognised_and_ours_is_not() {
        let mut f = controlword_frame(3, 0x0002);
        assert_eq!(quick_stop_of(&f), Some(3));
        f.flags.set(crate::frame::Flags::TX, true);
        assert_eq!(quick_stop_of(&f), None);
        assert_eq!(quick_stop_of(&controlword_frame(3, 0x000F)), None);
    }
}
