//! The bus layer: one [`Bus`] handle over two implementations, SocketCAN
//! ([`socketcan::open`]) and an in-process virtual bus ([`virt::VirtualBus`]).
//!
//! Every handle delivers every frame on the bus to every [`Subscription`],
//! including the frames this handle sent (marked [`Flags::TX`]), so that
//! consumers decode what we send with the same decoder as what we receive.
//! A listen-only handle has no send path at all: [`Bus::send`] returns
//! [`BusError::ListenOnly`] and nothing is written.
//!
//! A third kind of handle reaches a bus on another machine through a socketcand server
//! ([`socketcand::open`], `socketcand://HOST:PORT/CHANNEL`); it behaves as a SocketCAN handle.
//!
//! A SocketCAN handle follows its interface by name: down and up, deleted and created
//! again, bus-off and error-passive from error frames. Each change reaches the
//! subscriptions as an [`Event::State`] in order with the frames ([`Subscription::next`]);
//! [`Subscription::recv`] gives frames only and turns a loss of capture into an error.

pub mod bitrate;
mod error;
mod pace;
mod sdo_turns;
pub mod socketcan;
pub mod socketcand;
pub mod state;
pub mod virt;

pub use error::BusError;
pub use state::{BusState, StateChange};

use crate::frame::{Flags, Frame};
use std::fmt;
use std::sync::Arc;
use tokio::sync::{broadcast, oneshot};

/// Frames buffered per subscription before the slowest one starts losing frames.
pub const QUEUE_DEPTH: usize = 8192;

/// One item on the broadcast channel: the endpoint that sent it (0 = another node or the reader) and what.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Carried {
    pub origin: u32,
    pub item: Item,
}

/// What the broadcast channel carries.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Item {
    Frame(Frame),
    State(StateChange),
    /// A read error (errno) of a SocketCAN reader that is not a change of state.
    Fault(i32),
}

/// What a subscription delivers, in bus order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A frame.
    Frame(Frame),
    /// The interface or controller changed state (SocketCAN only).
    State(StateChange),
}

/// The way a handle writes frames.
#[derive(Clone)]
enum Sender {
    Virtual(virt::Port),
    Socket(Arc<socketcan::Writer>),
    Remote(Arc<socketcand::Link>),
}

/// The clock of a handle's frame timestamps.
#[derive(Clone)]
enum Clock {
    /// `CLOCK_REALTIME`, as `SO_TIMESTAMPNS` (SocketCAN).
    Wall,
    /// The virtual bus's clock.
    Virtual(virt::Clock),
    /// The server's clock as seen from here; holds the reader of the connection.
    Remote(Arc<socketcand::Shared>),
}

/// A handle on one bus: subscribe to frames, send frames (unless listen-only).
#[derive(Clone)]
pub struct Bus {
    name: String,
    endpoint: u32,
    events: broadcast::Sender<Carried>,
    sender: Option<Sender>,
    /// The SocketCAN reader task and its socket (none on the virtual bus).
    socket: Option<Arc<socketcan::Shared>>,
    /// The clock of the frames' timestamps.
    clock: Clock,
    /// One SDO transfer per node at a time, shared by every handle of this bus.
    turns: sdo_turns::SdoTurns,
}

impl fmt::Debug for Bus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Bus")
            .field("name", &self.name)
            .field("listen_only", &self.is_listen_only())
            .finish()
    }
}

impl Bus {
    /// The interface name (`demo` for the simulated bus).
    pub fn name(&self) -> &str {
        &self.name
    }
    /// True when the handle was opened listen-only and cannot send.
    pub fn is_listen_only(&self) -> bool {
        self.sender.is_none()
    }
    /// Frames the kernel dropped because this handle's socket buffer was full (0 on the
    /// virtual bus, which cannot drop). Frames a slow subscription missed are in [`Subscription::lost`].
    pub fn dropped(&self) -> u64 {
        self.socket.as_ref().map_or(0, |s| s.dropped())
    }
    /// Resolves once every frame the kernel had queued for this handle when called (and
    /// every state change before it) is on the subscriptions; at once on the virtual bus.
    /// Keep reading the subscriptions while waiting: a full subscription loses frames.
    pub async fn catch_up(&self) {
        if let Some(s) = &self.socket {
            let (tx, rx) = oneshot::channel();
            if s.catch_up(tx) {
                let _ = rx.await;
            }
        }
    }
    /// The bus time now in nanoseconds, on the clock of the frames' receive timestamps
    /// ([`Frame::ts_ns`]): the wall clock (`CLOCK_REALTIME`, as `SO_TIMESTAMPNS`) on SocketCAN,
    /// the virtual bus's clock (which follows tokio's, paused or not) on a virtual bus, the
    /// server's clock less the network delay on a socketcand bus (see [`socketcand`]).
    pub fn now_ns(&self) -> u64 {
        match &self.clock {
            Clock::Virtual(c) => c.now_ns(),
            Clock::Remote(r) => r.link.now_ns(),
            Clock::Wall => std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos() as u64),
        }
    }
    /// Puts `frame` on every subscription as received from another node, keeping its
    /// timestamp, as the SocketCAN reader does with a frame the kernel stamped earlier.
    #[cfg(test)]
    pub(crate) fn inject(&self, frame: Frame) {
        let _ = self.events.send(Carried {
            origin: 0,
            item: Item::Frame(frame),
        });
    }
    /// Waits for `node`'s SDO turn: no other transfer of this bus's handles to `node` runs
    /// until the guard is dropped. `None` at once on a handle [`Bus::ahead_of_turns`].
    pub(crate) async fn sdo_turn(&self, node: u8) -> Option<tokio::sync::MutexGuard<'_, ()>> {
        self.turns.take(node).await
    }
    /// This handle, its SDO transfers never waiting for a turn (a stop goes first).
    pub fn ahead_of_turns(&self) -> Bus {
        Bus {
            turns: self.turns.ahead(),
            ..self.clone()
        }
    }
    /// A new subscription that sees every frame from now on.
    pub fn subscribe(&self) -> Subscription {
        Subscription {
            name: self.name.clone(),
            endpoint: self.endpoint,
            rx: self.events.subscribe(),
            lost: 0,
        }
    }
    /// Sends one frame. It comes back on every subscription of this handle marked [`Flags::TX`].
    pub async fn send(&self, frame: &Frame) -> Result<(), BusError> {
        let mut frame = *frame;
        frame.flags.set(Flags::TX, false);
        match &self.sender {
            None => Err(BusError::ListenOnly),
            Some(Sender::Virtual(port)) => port.send(self.endpoint, frame),
            Some(Sender::Socket(w)) => w.write(&frame).await,
            Some(Sender::Remote(l)) => l.write(&frame).await,
        }
    }
}

/// A stream of the frames on a bus, in order.
pub struct Subscription {
    name: String,
    endpoint: u32,
    rx: broadcast::Receiver<Carried>,
    lost: u64,
}

impl Subscription {
    /// The next frame or state change; frames sent through this subscription's handle carry
    /// [`Flags::TX`]. A read error of the interface is returned once and the stream goes on.
    pub async fn next(&mut self) -> Result<Event, BusError> {
        loop {
            match self.rx.recv().await {
                Ok(c) => return self.unpack(c),
                Err(broadcast::error::RecvError::Lagged(n)) => self.lost += n,
                Err(broadcast::error::RecvError::Closed) => return Err(BusError::Closed),
            }
        }
    }
    /// The next frame or state change if one is queued, without waiting.
    pub fn try_next(&mut self) -> Option<Result<Event, BusError>> {
        loop {
            match self.rx.try_recv() {
                Ok(c) => return Some(self.unpack(c)),
                Err(broadcast::error::TryRecvError::Lagged(n)) => self.lost += n,
                Err(broadcast::error::TryRecvError::Empty) => return None,
                Err(broadcast::error::TryRecvError::Closed) => return Some(Err(BusError::Closed)),
            }
        }
    }
    /// The next frame. When capture stops (interface down or gone, bus-off) the error,
    /// naming the fix, is returned once and the stream goes on; the return of capture is skipped.
    pub async fn recv(&mut self) -> Result<Frame, BusError> {
        loop {
            let got = self.next().await;
            if let Some(r) = self.frame_of(got) {
                return r;
            }
        }
    }
    /// The next frame if one is queued, without waiting (as [`Subscription::recv`]).
    pub fn try_recv(&mut self) -> Option<Result<Frame, BusError>> {
        loop {
            let got = self.try_next()?;
            if let Some(r) = self.frame_of(got) {
                return Some(r);
            }
        }
    }

    /// The frame or error `recv` returns for an event; none for a return of capture.
    fn frame_of(&self, got: Result<Event, BusError>) -> Option<Result<Frame, BusError>> {
        match got {
            Ok(Event::Frame(f)) => Some(Ok(f)),
            Ok(Event::State(s)) => s.error(&self.name).map(Err),
            Err(e) => Some(Err(e)),
        }
    }
    /// Frames this subscription missed because it read too slowly.
    pub fn lost(&self) -> u64 {
        self.lost
    }

    fn unpack(&self, c: Carried) -> Result<Event, BusError> {
        match c.item {
            Item::Frame(mut f) => {
                f.flags.set(Flags::TX, c.origin != 0 && c.origin == self.endpoint);
                Ok(Event::Frame(f))
            }
            Item::State(s) => Ok(Event::State(s)),
            Item::Fault(errno) => Err(BusError::Io {
                iface: self.name.clone(),
                reason: socketcan::errno_text(errno),
            }),
        }
    }
}
