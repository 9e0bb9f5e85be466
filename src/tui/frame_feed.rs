//! The live capture's end of the feed channel: frame batches the UI cannot take yet wait in
//! a bounded backlog, in order, instead of being dropped, so a UI busy for a moment (a big
//! redraw, a slow terminal) loses nothing; only past the backlog's bound are frames dropped
//! and counted.

use super::source::Feed;
use crate::frame::Frame;
use std::collections::VecDeque;
use std::sync::mpsc::{SyncSender, TrySendError};

/// The most frames kept waiting for the UI (~45 MB), on top of what the channel holds.
pub(super) const BACKLOG_FRAMES: usize = 1 << 19;

/// Batches of at most this many frames are merged while they wait.
const MERGE_UP_TO: usize = 1024;

/// The sending end of the feed with its backlog.
pub(super) struct FrameFeed {
    tx: SyncSender<Feed>,
    backlog: VecDeque<Vec<Frame>>,
    /// Frames in `backlog`.
    waiting: usize,
    /// Most frames `backlog` may hold.
    bound: usize,
    /// Frames dropped past the bound, not yet reported.
    lost: u64,
}

/// What a non-blocking send of a batch came to.
enum Offered {
    Sent,
    Full(Vec<Frame>),
    Gone,
}

impl FrameFeed {
    /// A feed over `tx` keeping at most `bound` frames waiting.
    pub(super) fn new(tx: SyncSender<Feed>, bound: usize) -> FrameFeed {
        FrameFeed {
            tx,
            backlog: VecDeque::new(),
            waiting: 0,
            bound,
            lost: 0,
        }
    }

    /// Offers a batch: sent when the channel has room and nothing waits before it, else
    /// kept behind what waits (dropped and counted only past the bound). Never blocks.
    /// False when the UI went away.
    pub(super) fn frames(&mut self, batch: Vec<Frame>) -> bool {
        if !self.flush() {
            return false;
        }
        if batch.is_empty() {
            return true;
        }
        let batch = if self.backlog.is_empty() {
            match self.try_frames(batch) {
                Offered::Sent => return true,
                Offered::Gone => return false,
                Offered::Full(b) => b,
            }
        } else {
            batch
        };
        self.keep(batch);
        true
    }

    fn keep(&mut self, mut batch: Vec<Frame>) {
        if self.waiting + batch.len() > self.bound {
            self.lost += batch.len() as u64;
            return;
        }
        self.waiting += batch.len();
        match self.backlog.back_mut() {
            Some(last) if last.len() + batch.len() <= MERGE_UP_TO => last.append(&mut batch),
            _ => self.backlog.push_back(batch),
        }
    }

    fn try_frames(&self, batch: Vec<Frame>) -> Offered {
        match self.tx.try_send(Feed::frames(batch)) {
            Ok(()) => Offered::Sent,
            Err(TrySendError::Full(Feed::Frames { frames: b, .. })) => Offered::Full(b),
            // Only frames are offered here.
            Err(TrySendError::Full(_)) => Offered::Sent,
            Err(TrySendError::Disconnected(_)) => Offered::Gone,
        }
    }

    /// Sends what waits, as far as the channel has room. False when the UI went away.
    pub(super) fn flush(&mut self) -> bool {
        while let Some(b) = self.backlog.pop_front() {
            let n = b.len();
            match self.try_frames(b) {
                Offered::Sent => self.waiting -= n,
                Offered::Full(b) => {
                    self.backlog.push_front(b);
                    return true;
                }
                Offered::Gone => return false,
            }
        }
        true
    }

    /// Sends an item that is not frames after every frame waiting before it, waiting for
    /// room as long as it takes (the order of frames and notices is kept). False when the
    /// UI went away.
    pub(super) fn send(&mut self, item: Feed) -> bool {
        while let Some(b) = self.backlog.pop_front() {
            self.waiting -= b.len();
            if self.tx.send(Feed::frames(b)).is_err() {
                return false;
            }
        }
        self.tx.send(item).is_ok()
    }

    /// The frames dropped past the bound since the last call.
    pub(super) fn take_lost(&mut self) -> u64 {
        std::mem::take(&mut self.lost)
    }

    /// The channel itself, for the notices that need no order with the frames.
    pub(super) fn channel(&self) -> &SyncSender<Feed> {
        &self.tx
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc::{Receiver, sync_channel};

    fn batch(from: u64, n: u64) -> Vec<Frame> {
        (from..from + n)
            .map(|i| Frame {
                ts_ns: i,
                ..Frame::default()
            })
            .collect()
    }

    fn drain(rx: &Receiver<Feed>) -> Vec<u64> {
        let mut times = Vec::new();
        while let Ok(f) = rx.try_recv() {
            if let Feed::Frames { frames: b, .. } = f {
                times.extend(b.iter().map(|f| f.ts_ns));
            }
        }
        times
    }

    #[test]
    fn a_ui_that_stops_taking_for_a_while_loses_no_frame_and_gets_them_in_order() {
        let (tx, rx) = sync_channel(2);
        let mut feed = FrameFeed::new(tx, 10_000);
        // 20 batches while the UI takes nothing: the channel holds 2, the rest wait.
        for i in 0..20 {
            assert!(feed.frames(batch(i * 100, 100)));
        }
        assert_eq!(feed.take_lost(), 0);
        let mut got = Vec::new();
        // The UI takes what the channel holds, the feed refills it, until all arrived.
        for _ in 0..20 {
            got.extend(drain(&rx));
            assert!(feed.flush());
        }
        got.extend(drain(&rx));
        assert_eq!(got, (0..2000).collect::<Vec<u64>>());
    }

    #[test]
    fn past_the_bound_frames_are_dropped_and_counted() {
        let (tx, rx) = sync_channel(1);
        let mut feed = FrameFeed::new(tx, 250);
        for i in 0..5 {
            assert!(feed.frames(batch(i * 100, 100)));
        }
        // One batch in the channel, two waiting (200 <= 250), two dropped.
        assert_eq!(feed.take_lost(), 200);
        assert_eq!(feed.take_lost(), 0);
        // The notice waits for room behind the frames: the UI takes them meanwhile.
        let sender = std::thread::spawn(move || feed.send(Feed::Status("state".into())));
        let (mut times, mut notes) = (Vec::new(), Vec::new());
        while notes.is_empty() {
            match rx.recv() {
                Ok(Feed::Frames { frames: b, .. }) => times.extend(b.iter().map(|f| f.ts_ns)),
                Ok(Feed::Status(s)) => notes.push(format!("{s} after {}", times.len())),
                Ok(_) => {}
                Err(e) => panic!("the feed closed: {e}"),
            }
        }
        assert!(sender.join().expect("the sender"));
        // The notice comes after every frame offered before it.
        assert_eq!(times, (0..300).collect::<Vec<u64>>());
        assert_eq!(notes, ["state after 300"]);
    }

    #[test]
    fn a_closed_ui_ends_the_feed() {
        let (tx, rx) = sync_channel(1);
        drop(rx);
        let mut feed = FrameFeed::new(tx, 100);
        assert!(!feed.frames(batch(0, 1)));
        assert!(!feed.send(Feed::Status("x".into())));
    }
}
