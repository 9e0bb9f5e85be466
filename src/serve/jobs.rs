//! A client's BCM send jobs (`< add >`): one task each, sending its frame on the client's
//! bus handle now and every interval until `< delete >` or the client leaves (as socketcand
//! removes them when its BCM socket closes); `< update >` swaps the frame, the timer kept.

use crate::audit::Audit;
use crate::bus::Bus;
use crate::frame::Frame;
use std::collections::BTreeMap;
use std::time::Duration;
use tokio::sync::watch;
use tokio::task::AbortHandle;
use tokio::time::MissedTickBehavior;

/// The send jobs of one client, by identifier; all end when dropped.
#[derive(Default)]
pub struct Jobs(BTreeMap<(u32, bool), (watch::Sender<Frame>, AbortHandle)>);

impl Jobs {
    /// Starts sending `frame` every `interval_ns` (0: once), replacing the job of its
    /// identifier; a failed send ends the job with an audit line naming `who`.
    pub fn add(&mut self, bus: &Bus, frame: Frame, interval_ns: u64, who: String, audit: Audit) {
        self.delete(frame.id, frame.is_ext());
        let (tx, mut rx) = watch::channel(frame);
        let bus = bus.clone();
        let task = tokio::spawn(async move {
            let mut tick = tokio::time::interval(Duration::from_nanos(interval_ns.max(1)));
            tick.set_missed_tick_behavior(MissedTickBehavior::Skip);
            loop {
                tick.tick().await;
                let f = *rx.borrow_and_update();
                if let Err(e) = bus.send(&f).await {
                    audit.say(&format!("{who}: send job {} ended: {e}", crate::command::candump(&f)));
                    return;
                }
                if interval_ns == 0 {
                    return;
                }
            }
        });
        self.0.insert((frame.id, frame.is_ext()), (tx, task.abort_handle()));
    }

    /// New content for the job of `frame`'s identifier; false when there is none.
    pub fn update(&mut self, frame: Frame) -> bool {
        match self.0.get(&(frame.id, frame.is_ext())) {
            Some((tx, _)) => tx.send(frame).is_ok(),
            None => false,
        }
    }

    /// Ends the job of `id`.
    pub fn delete(&mut self, id: u32, ext: bool) {
        if let Some((_, task)) = self.0.remove(&(id, ext)) {
            task.abort();
        }
    }
}

impl Drop for Jobs {
    fn drop(&mut self) {
        for (_, task) in self.0.values() {
            task.abort();
        }
    }
}
