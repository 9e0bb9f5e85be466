//! One poll round of a watch list, shared by `cotui watch` ([`super::watch`]) and the TUI's
//! Watch pane: the nodes of a round polled side by side in one task, each node's objects
//! one after the other (each read waits for the node's SDO turn, [`Bus::sdo_turn`], so a
//! palette read or another watch group never overlaps a poll); [`Schedule`] the period (a round still running when the
//! next is due makes that one skipped, never a burst). What a failed poll shows (absent,
//! timeout, abort) is [`sample_of_error`].

use super::error::CommandError;
use super::sdo::upload;
use super::value::decode;
use super::watch_table::{Sample, Watched};
use crate::bus::Bus;
use crate::od::DataType;
use std::future::Future;
use std::pin::Pin;
use std::task::Poll;
use std::time::Duration;
use tokio::time::{Instant, Interval, MissedTickBehavior};

/// Abort codes that say the object is not on the node: no object, no sub-index.
pub const ABSENT: [u32; 2] = [0x0602_0000, 0x0609_0011];

/// One object to read in a round.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Target {
    pub node: u8,
    pub index: u16,
    pub sub: u8,
    /// Its type from the node's dictionary (how the bytes read are decoded).
    pub ty: Option<DataType>,
}

impl Target {
    /// What a round reads of `w`: its object and type in `dict` (its node's dictionary).
    pub fn of(w: &Watched, dict: &crate::od::Dictionary) -> Target {
        Target {
            node: w.node,
            index: w.index,
            sub: w.sub,
            ty: dict.object(w.index, w.sub).map(|i| i.data_type),
        }
    }
}

/// What a failed poll shows.
pub fn sample_of_error(e: &CommandError) -> Sample {
    match e {
        CommandError::Abort {
            code, by_server: true, ..
        } if ABSENT.contains(code) => Sample::Absent(format!("abort 0x{code:08X} {}", crate::sdo::abort_text(*code))),
        CommandError::Abort { code, .. } => Sample::Failed(format!("abort 0x{code:08X}")),
        CommandError::Timeout(_) => Sample::Failed("timeout".into()),
        other => Sample::Failed(other.to_string()),
    }
}

/// Reads `targets` (all of one node) one after the other; (position, sample).
async fn node_round(bus: &Bus, targets: Vec<(usize, Target)>, timeout_ms: u64) -> Vec<(usize, Sample)> {
    let mut out = Vec::with_capacity(targets.len());
    for (k, t) in targets {
        let s = match upload(bus, t.node, t.index, t.sub, false, timeout_ms).await {
            Ok(data) => Sample::Value(decode(&data, t.ty)),
            Err(e) => sample_of_error(&e),
        };
        out.push((k, s));
    }
    out
}

/// Runs `futs` side by side in the calling task (no task spawned: cancelling the caller
/// cancels every poll at once); their outputs in order.
async fn join_all<F: Future>(futs: Vec<F>) -> Vec<F::Output> {
    let mut futs: Vec<Pin<Box<F>>> = futs.into_iter().map(Box::pin).collect();
    let mut out: Vec<Option<F::Output>> = futs.iter().map(|_| None).collect();
    std::future::poll_fn(|cx| {
        let mut pending = false;
        for (f, o) in futs.iter_mut().zip(out.iter_mut()) {
            if o.is_none() {
                match f.as_mut().poll(cx) {
                    Poll::Ready(v) => *o = Some(v),
                    Poll::Pending => pending = true,
                }
            }
        }
        if pending { Poll::Pending } else { Poll::Ready(()) }
    })
    .await;
    out.into_iter().flatten().collect()
}

/// One round: one sample per target, in order (`None`: not polled, [`Sample::Skipped`]).
/// The nodes side by side, each node's objects one after the other.
pub async fn round(bus: &Bus, targets: &[Option<Target>], timeout_ms: u64) -> Vec<Sample> {
    let mut nodes: Vec<u8> = targets.iter().flatten().map(|t| t.node).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let per_node = nodes.into_iter().map(|node| {
        let mine = targets
            .iter()
            .enumerate()
            .filter_map(|(k, t)| t.filter(|t| t.node == node).map(|t| (k, t)))
            .collect();
        node_round(bus, mine, timeout_ms)
    });
    let mut samples = vec![Sample::Skipped; targets.len()];
    for (k, s) in join_all(per_node.collect()).await.into_iter().flatten() {
        samples[k] = s;
    }
    samples
}

/// The period of the rounds: the first at once, then every `every_ms`; a round that ran
/// past its successor's time skips it (counted).
pub struct Schedule {
    tick: Interval,
    every_ms: u64,
    last: Option<Instant>,
    /// Rounds skipped because the one before was still running.
    pub skipped: u64,
}

impl Schedule {
    /// Rounds every `every_ms` (at least 1 ms).
    pub fn every(every_ms: u64) -> Schedule {
        let every_ms = every_ms.max(1);
        let mut tick = tokio::time::interval(Duration::from_millis(every_ms));
        tick.set_missed_tick_behavior(MissedTickBehavior::Skip);
        Schedule {
            tick,
            every_ms,
            last: None,
            skipped: 0,
        }
    }

    /// Waits for the next round's time.
    pub async fn next(&mut self) {
        let at = self.tick.tick().await;
        if let Some(prev) = self.last {
            let periods = (at - prev).as_millis() as u64 / self.every_ms;
            self.skipped += periods.saturating_sub(1);
        }
        self.last = Some(at);
    }
}
