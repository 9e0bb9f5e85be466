//! The Watch pane's polls on the bus task: one task per poll group of the [`Board`], each
//! running the rounds of `cotui watch` ([`crate::command::watch_poll`]) on its period and
//! noting what they read on the board. Every read waits for its node's SDO turn
//! ([`Bus::sdo_turn`]): polls of two groups, and palette reads, never overlap per node.

use super::watch_board::{Group, SharedBoard, lock};
use crate::bus::Bus;
use crate::command::watch_poll::{Schedule, Target, round};
use crate::od::bind::Bindings;
use tokio::task::AbortHandle;

/// The poll tasks of the board's groups, by group id.
#[derive(Default)]
pub(crate) struct Polls(Vec<(u64, AbortHandle)>);

impl Polls {
    /// Brings the tasks in line with `board`: a task per group still polling something; a
    /// group's running task is kept (its rows are read afresh each round, so a deleted row
    /// is simply not read again), a task whose group is gone is aborted (its polls stop at
    /// once), a new group gets a task.
    pub(crate) fn follow(&mut self, bus: &Bus, board: &SharedBoard, bindings: &Bindings) {
        let groups = lock(board).groups();
        self.0.retain(|(id, task)| {
            let keep = !task.is_finished() && groups.iter().any(|g| g.id == *id);
            if !keep {
                task.abort();
            }
            keep
        });
        for g in groups {
            if self.0.iter().any(|(id, _)| *id == g.id) {
                continue;
            }
            let (bus, board, bindings) = (bus.clone(), board.clone(), bindings.clone());
            let task = tokio::spawn(async move { poll_group(&bus, &board, &bindings, g).await });
            self.0.push((g.id, task.abort_handle()));
        }
    }

    /// Stops every poll at once; true when one was running.
    pub(crate) fn stop(&mut self) -> bool {
        let any = self.0.iter().any(|(_, t)| !t.is_finished());
        self.0.drain(..).for_each(|(_, t)| t.abort());
        any
    }
}

/// Polls group `g` on its period until nothing of it is left to poll.
async fn poll_group(bus: &Bus, board: &SharedBoard, bindings: &Bindings, g: Group) {
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
        let samples = round(bus, &targets, g.timeout_ms).await;
        lock(board).took(t_ns, bus.now_ns(), ids.into_iter().zip(samples).collect(), |w, s| {
            w.take(bindings.dictionary(w.node), s)
        });
    }
}
