//! How a reader that can outrun its subscribers (a socket's queue read in one go, a TCP
//! stream's buffered elements) lets them keep up: after each run of frames it yields, and
//! while they are half a queue behind it waits a millisecond, so the frames stay in the
//! kernel's buffer (or TCP's window) instead of being lost off the end of the broadcast.

use super::Carried;
use std::time::Duration;
use tokio::sync::broadcast;

/// Frames read between two chances for the subscribers to run.
const RUN: usize = 64;

/// Counts the frames a reader published and paces it.
#[derive(Default)]
pub(super) struct Pace {
    run: usize,
}

impl Pace {
    /// Called after each frame published on `events`.
    pub(super) async fn published(&mut self, events: &broadcast::Sender<Carried>) {
        self.run += 1;
        if self.run < RUN {
            return;
        }
        self.run = 0;
        if events.len() > super::QUEUE_DEPTH / 2 {
            // Still 64 frames/ms, faster than any CAN bus.
            tokio::time::sleep(Duration::from_millis(1)).await;
        } else {
            tokio::task::yield_now().await;
        }
    }
}
