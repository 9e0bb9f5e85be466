//! The Watch pane's polls on the bus task: one task per poll group of the [`Board`], each
//! running the rounds of `cotui watch` ([`crate::command::watch_poll`]) on its period and
//! noting what they read on the board. One [`NodeLocks`] for all groups: polls never
//! overlap per node.

use super::watch_board::{Group, SharedBoard, lock};
use crate::bus::Bus;
use crate::command::watch_poll::{NodeLocks, Schedule, Target, round};
use crate::od::bind::Bindings;
use tokio::task::AbortHandle;

/// Starts a task per group of `board` still polling something; their handles (aborting
/// one stops its polls at once: no task of its own is left behind).
pub(crate) fn start(bus: &Bus, board: &SharedBoard, bindings: &Bindings) -> Vec<AbortHandle> {
    let locks = NodeLocks::default();
    lock(board)
        .groups()
        .into_iter()
        .map(|g| {
            let (bus, board, bindings, locks) = (bus.clone(), board.clone(), bindings.clone(), locks.clone());
            tokio::spawn(async move { poll_group(&bus, &board, &bindings, &locks, g).await }).abort_handle()
        })
        .collect()
}

/// Polls group `g` on its period until nothing of it is left to poll.
async fn poll_group(bus: &Bus, board: &SharedBoard, bindings: &Bindings, locks: &NodeLocks, g: Group) {
    let mut schedule = Schedule::every(g.every_ms);
    loop {
        schedule.next().await;
        let (ids, targets): (Vec<u64>, Vec<_>) = lock(board)
            .polled(g.id)
            .into_iter()
            .map(|(id, w)| (id, Some(Target::of(w, bindings.dictionary(w.node)))))
            .unzip();
        if ids.is_empty() {
            return;
        }
        let t_ns = bus.now_ns();
        let samples = round(bus, &targets, g.timeout_ms, locks).await;
        lock(board).took(t_ns, bus.now_ns(), ids.into_iter().zip(samples).collect(), |w, s| {
            w.take(bindings.dictionary(w.node), s)
        });
    }
}
