//! The live capture task (`cotui live IFACE`, `cotui demo`): a thread with its own tokio
//! runtime that opens the bus, forwards every frame in batches, reopens the interface when
//! it fails, and runs the palette's commands on the same bus.

use super::source::Feed;
use crate::bus::{self, Bus, BusError, BusState, Event, StateChange};
use crate::command::{self, Command};
use crate::decode::cia402::DriveState;
use crate::od::bind::Bindings;
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::time::Duration;
use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};

/// What the UI asks the live task to do.
#[derive(Debug)]
pub enum Request {
    /// Run a palette command; the result comes back as [`Feed::Result`].
    Run(Command),
    /// Stop these drives: quick stop, then disable voltage.
    StopAll(Vec<u8>),
}

/// A handle to send requests to the live task.
pub type Requests = UnboundedSender<Request>;

/// Frames per batch.
const BATCH: usize = 1024;
/// Capacity of the feed channel in batches; when full, frames are dropped and counted.
const QUEUE: usize = 256;

/// Starts capturing `iface` (`demo` for the simulated bus); commands use `bindings` for
/// object names and types.
pub fn start(iface: &str, listen_only: bool, bindings: Bindings) -> (Receiver<Feed>, Requests) {
    let (tx, rx) = sync_channel(QUEUE);
    let (req_tx, req_rx) = unbounded_channel();
    let iface = iface.to_string();
    std::thread::spawn(move || {
        let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
            Ok(rt) => rt,
            Err(e) => {
                let _ = tx.send(Feed::Status(format!("cannot start the bus task: {e}")));
                let _ = tx.send(Feed::Done);
                return;
            }
        };
        rt.block_on(capture(iface, listen_only, bindings, tx, req_rx));
    });
    (rx, req_tx)
}

/// Sends a feed item; a full queue drops frames (counted) but never blocks the bus task.
fn offer(tx: &SyncSender<Feed>, item: Feed, lost: &mut u64) -> bool {
    match tx.try_send(item) {
        Ok(()) => true,
        Err(TrySendError::Full(Feed::Frames(b))) => {
            *lost += b.len() as u64;
            true
        }
        Err(TrySendError::Full(other)) => tx.send(other).is_ok(),
        Err(TrySendError::Disconnected(_)) => false,
    }
}

/// Opens the bus (retrying every second until it can), then forwards frames in batches
/// and every change of the interface or controller state: [`Feed::BusError`] (with the
/// fix) when capture stops or the controller is in trouble, [`Feed::BusOk`] when it is
/// back. The bus handle follows the interface by name, so capture resumes by itself.
async fn capture(
    iface: String,
    listen_only: bool,
    bindings: Bindings,
    tx: SyncSender<Feed>,
    mut req: UnboundedReceiver<Request>,
) {
    if tx.send(Feed::Interfaces(vec![iface.clone()])).is_err() {
        return;
    }
    let bus = loop {
        match bus::open(&iface, listen_only).await {
            Ok(b) => break b,
            Err(e) => {
                if tx.send(Feed::BusError(e.to_string())).is_err() {
                    return;
                }
                // Answer requests while waiting, so the palette never hangs.
                let wait = tokio::time::sleep(Duration::from_secs(1));
                tokio::pin!(wait);
                loop {
                    tokio::select! {
                        _ = &mut wait => break,
                        r = req.recv() => match r {
                            Some(_) => {
                                let _ = tx.send(Feed::Result(format!("not sent: {e}")));
                            }
                            None => return,
                        },
                    }
                }
            }
        }
    };
    if tx.send(Feed::BusOk(format!("{iface}: capturing"))).is_err() {
        return;
    }
    let mut lost = 0u64;
    let mut sub = bus.subscribe();
    let mut reported = 0u64;
    let mut batch = Vec::with_capacity(BATCH);
    let mut flush = tokio::time::interval(Duration::from_millis(10));
    // When capture stopped (ns), while it is stopped.
    let mut stopped_at: Option<u64> = None;
    loop {
        tokio::select! {
            got = sub.next() => match got {
                Ok(Event::Frame(mut f)) => {
                    f.iface = 0;
                    batch.push(f);
                    if batch.len() >= BATCH && !offer(&tx, Feed::Frames(std::mem::take(&mut batch)), &mut lost) {
                        return;
                    }
                }
                Ok(Event::State(s)) => {
                    // Frames before the change first, so the trace and the notice agree.
                    if !batch.is_empty() && !offer(&tx, Feed::Frames(std::mem::take(&mut batch)), &mut lost) {
                        return;
                    }
                    if tx.send(state_feed(&iface, &s, &mut stopped_at)).is_err() {
                        return;
                    }
                }
                Err(BusError::Closed) => {
                    offer(&tx, Feed::Frames(std::mem::take(&mut batch)), &mut lost);
                    let _ = tx.send(Feed::BusError(BusError::Closed.to_string()));
                    let _ = tx.send(Feed::Done);
                    return;
                }
                Err(e) => {
                    if tx.send(Feed::Status(e.to_string())).is_err() {
                        return;
                    }
                }
            },
            _ = flush.tick() => {
                if !batch.is_empty() && !offer(&tx, Feed::Frames(std::mem::take(&mut batch)), &mut lost) {
                    return;
                }
                let total = lost + sub.lost() - reported;
                if total > 0 && tx.try_send(Feed::Lost(total)).is_ok() {
                    lost = 0;
                    reported = sub.lost();
                }
            }
            r = req.recv() => match r {
                Some(r) => {
                    let bus = bus.clone();
                    let tx = tx.clone();
                    let bindings = bindings.clone();
                    tokio::spawn(async move {
                        let _ = tx.send(Feed::Result(run(&bus, r, &bindings).await));
                    });
                }
                None => return,
            },
        }
    }
}

/// The feed item for a change of state: trouble (with the fix) or all well again (saying
/// how long capture was stopped, if it was).
fn state_feed(iface: &str, s: &StateChange, stopped_at: &mut Option<u64>) -> Feed {
    if !s.state.capturing() {
        stopped_at.get_or_insert(s.ts_ns);
    }
    if s.state != BusState::Active {
        return Feed::BusError(s.text(iface));
    }
    match stopped_at.take() {
        Some(t) => Feed::BusOk(format!(
            "{iface}: capturing again after {:.1} s without capture",
            s.ts_ns.saturating_sub(t) as f64 / 1e9
        )),
        None => Feed::BusOk(s.text(iface)),
    }
}

/// Runs one request on `bus`; returns the text for the status line.
async fn run(bus: &Bus, r: Request, bindings: &Bindings) -> String {
    match r {
        Request::Run(c) => match command::execute(bus, &c, bindings).await {
            Ok(o) => o.text,
            Err(e) => format!("error: {e}"),
        },
        Request::StopAll(nodes) => {
            let mut out = Vec::new();
            for n in nodes {
                let r = async {
                    command::sdo::download(bus, n, 0x6040, 0, 0x0002u16.to_le_bytes().to_vec(), false, 500).await?;
                    command::sdo::download(bus, n, 0x6040, 0, 0x0000u16.to_le_bytes().to_vec(), false, 500).await
                }
                .await;
                out.push(match r {
                    Ok(()) => format!("node {n}: quick stop, voltage disabled"),
                    Err(e) => format!("node {n}: {e}"),
                });
            }
            format!("stop all: {}", out.join("; "))
        }
    }
}

/// The drive state assumed for a preview when the node's state is unknown.
pub const UNKNOWN_STATE: DriveState = DriveState::SwitchOnDisabled;
