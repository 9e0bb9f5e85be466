//! Frames of several buses put back in time order: each bus delivers its own frames in order,
//! but two buses' deliveries interleave late or early by a few ms (each has its own reader).
//! [`TimeOrder`] holds frames briefly and hands them on by timestamp: a frame goes on once a
//! frame [`HOLD`] later has been seen on any bus, or once it has waited [`HOLD`] itself (a
//! quiet bus holds nothing back for longer).

use crate::frame::Frame;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::{Duration, Instant};

/// How long a frame may wait for an earlier one of another bus.
pub const HOLD: Duration = Duration::from_millis(50);

/// One held frame: ordered by timestamp, then by arrival.
#[derive(Debug)]
struct Held {
    ts_ns: u64,
    seq: u64,
    arrived: Instant,
    frame: Frame,
}

impl PartialEq for Held {
    fn eq(&self, other: &Self) -> bool {
        (self.ts_ns, self.seq) == (other.ts_ns, other.seq)
    }
}
impl Eq for Held {}
impl PartialOrd for Held {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Held {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        (self.ts_ns, self.seq).cmp(&(other.ts_ns, other.seq))
    }
}

/// Frames waiting to be handed on in time order.
#[derive(Debug, Default)]
pub struct TimeOrder {
    held: BinaryHeap<Reverse<Held>>,
    seq: u64,
    /// The latest timestamp seen on any bus.
    newest_ns: u64,
}

impl TimeOrder {
    /// Holds `frame`, which arrived at `now`.
    pub fn push(&mut self, frame: Frame, now: Instant) {
        self.newest_ns = self.newest_ns.max(frame.ts_ns);
        self.seq += 1;
        self.held.push(Reverse(Held {
            ts_ns: frame.ts_ns,
            seq: self.seq,
            arrived: now,
            frame,
        }));
    }

    /// The earliest held frame, if it may go on at `now`.
    pub fn pop_ready(&mut self, now: Instant) -> Option<Frame> {
        let Reverse(top) = self.held.peek()?;
        let hold_ns = HOLD.as_nanos() as u64;
        let overtaken = top.ts_ns.saturating_add(hold_ns) <= self.newest_ns;
        let waited = now.saturating_duration_since(top.arrived) >= HOLD;
        (overtaken || waited).then(|| self.pop()).flatten()
    }

    /// The earliest held frame, whatever its age (at the end of a recording).
    pub fn pop(&mut self) -> Option<Frame> {
        self.held.pop().map(|Reverse(h)| h.frame)
    }

    /// Whether frames are held.
    pub fn is_empty(&self) -> bool {
        self.held.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(ms: u64, iface: u16) -> Frame {
        let mut f = Frame::classic(0x100 + u32::from(iface), &[]);
        f.ts_ns = ms * 1_000_000;
        f.iface = iface;
        f
    }

    #[test]
    fn frames_of_two_buses_come_out_by_time() {
        let t0 = Instant::now();
        let mut o = TimeOrder::default();
        // Bus 1's frame of 10 ms is delivered after bus 0's of 12 ms.
        o.push(at(12, 0), t0);
        o.push(at(10, 1), t0);
        assert_eq!(o.pop_ready(t0), None, "nothing later than both by the hold yet");
        o.push(at(80, 0), t0);
        let ts: Vec<u64> = std::iter::from_fn(|| o.pop_ready(t0))
            .map(|f| f.ts_ns / 1_000_000)
            .collect();
        assert_eq!(ts, [10, 12]);
        // A quiet bus: the last frame goes on once it has waited the hold.
        assert_eq!(o.pop_ready(t0 + HOLD / 2), None);
        assert_eq!(o.pop_ready(t0 + HOLD).map(|f| f.ts_ns), Some(80_000_000));
        assert!(o.is_empty());
    }
}
