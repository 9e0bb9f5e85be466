//! The in-process virtual bus: a tokio broadcast channel with any number of endpoints.
//!
//! Every endpoint sees every frame, its own marked [`crate::frame::Flags::TX`]. Frames are
//! stamped when sent with wall-clock time that advances with tokio's clock, so a
//! test with paused time gets deterministic timestamps.

use super::sdo_turns::SdoTurns;
use super::{Bus, BusError, Carried, Item, QUEUE_DEPTH, Sender};
use crate::frame::Frame;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use tokio::sync::broadcast;
use tokio::time::Instant;

/// A virtual CAN bus living in this process.
#[derive(Clone)]
pub struct VirtualBus {
    name: String,
    events: broadcast::Sender<Carried>,
    next_endpoint: Arc<AtomicU32>,
    clock: Clock,
    /// The SDO turns of every endpoint (tools on one virtual bus wait for each other too).
    turns: SdoTurns,
}

/// The clock of a virtual bus: wall-clock time at creation plus tokio's elapsed time.
#[derive(Clone, Copy)]
pub(super) struct Clock {
    epoch_ns: u64,
    start: Instant,
}

impl Clock {
    pub(super) fn now_ns(&self) -> u64 {
        self.epoch_ns + self.start.elapsed().as_nanos() as u64
    }
}

/// The send side of one virtual endpoint.
#[derive(Clone)]
pub(super) struct Port {
    events: broadcast::Sender<Carried>,
    clock: Clock,
}

impl Port {
    pub(super) fn send(&self, origin: u32, mut frame: Frame) -> Result<(), BusError> {
        frame.ts_ns = self.clock.now_ns();
        // No subscriber is not an error: the frame went out on an idle bus.
        let _ = self.events.send(Carried {
            origin,
            item: Item::Frame(frame),
        });
        Ok(())
    }
}

impl VirtualBus {
    /// A new empty bus called `name` (shown as the interface name).
    pub fn new(name: &str) -> VirtualBus {
        let epoch_ns = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(0);
        VirtualBus {
            name: name.to_string(),
            events: broadcast::channel(QUEUE_DEPTH).0,
            next_endpoint: Arc::new(AtomicU32::new(1)),
            clock: Clock {
                epoch_ns,
                start: Instant::now(),
            },
            turns: SdoTurns::default(),
        }
    }
    /// A new endpoint (one node or one tool) on the bus. A listen-only endpoint has no send path.
    pub fn endpoint(&self, listen_only: bool) -> Bus {
        let endpoint = self.next_endpoint.fetch_add(1, Ordering::Relaxed);
        Bus {
            name: self.name.clone(),
            endpoint,
            events: self.events.clone(),
            sender: (!listen_only).then(|| {
                Sender::Virtual(Port {
                    events: self.events.clone(),
                    clock: self.clock,
                })
            }),
            socket: None,
            clock: super::Clock::Virtual(self.clock),
            turns: self.turns.clone(),
        }
    }
    /// The bus time now in nanoseconds, as frames sent now would be stamped.
    pub fn now_ns(&self) -> u64 {
        self.clock.now_ns()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Flags;

    #[tokio::test]
    async fn every_endpoint_sees_every_frame_with_its_own_marked_tx() {
        let bus = VirtualBus::new("vbus");
        let a = bus.endpoint(false);
        let b = bus.endpoint(false);
        let mut ra = a.subscribe();
        let mut rb = b.subscribe();
        a.send(&Frame::classic(0x601, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]))
            .await
            .unwrap();
        b.send(&Frame::classic(0x581, &[0x4B, 0x41, 0x60, 0, 0x37, 2, 0, 0]))
            .await
            .unwrap();
        let (a1, a2) = (ra.recv().await.unwrap(), ra.recv().await.unwrap());
        let (b1, b2) = (rb.recv().await.unwrap(), rb.recv().await.unwrap());
        assert_eq!((a1.id, a1.flags.has(Flags::TX)), (0x601, true));
        assert_eq!((a2.id, a2.flags.has(Flags::TX)), (0x581, false));
        assert_eq!((b1.id, b1.flags.has(Flags::TX)), (0x601, false));
        assert_eq!((b2.id, b2.flags.has(Flags::TX)), (0x581, true));
        assert_eq!(b2.payload(), &[0x4B, 0x41, 0x60, 0, 0x37, 2, 0, 0]);
    }

    #[tokio::test]
    async fn listen_only_endpoint_cannot_send_and_nothing_reaches_the_bus() {
        let bus = VirtualBus::new("vbus");
        let watcher = bus.endpoint(false);
        let mut rx = watcher.subscribe();
        let quiet = bus.endpoint(true);
        assert!(quiet.is_listen_only());
        assert_eq!(quiet.send(&Frame::classic(0, &[1, 0])).await, Err(BusError::ListenOnly));
        assert!(rx.try_recv().is_none());
    }

    #[tokio::test(start_paused = true)]
    async fn timestamps_follow_tokio_time() {
        let bus = VirtualBus::new("vbus");
        let a = bus.endpoint(false);
        let mut rx = a.subscribe();
        a.send(&Frame::classic(0x80, &[])).await.unwrap();
        tokio::time::sleep(std::time::Duration::from_millis(250)).await;
        a.send(&Frame::classic(0x80, &[])).await.unwrap();
        let t1 = rx.recv().await.unwrap().ts_ns;
        let t2 = rx.recv().await.unwrap().ts_ns;
        assert_eq!(t2 - t1, 250_000_000);
    }
}
