//! The live capture task (`cotui live IFACE`, `cotui demo`): a thread with its own tokio
//! runtime that opens the bus, forwards every frame in batches, reopens the interface when
//! it fails, and runs the palette's commands on the same bus.

use super::source::Feed;
use crate::bus::{self, Bus, BusError};
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
    let mut lost = 0u64;
    loop {
        let bus = match bus::open(&iface, listen_only).await {
            Ok(b) => b,
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
                continue;
            }
        };
        if tx.send(Feed::BusOk).is_err() {
            return;
        }
        let mut sub = bus.subscribe();
        let mut reported = 0u64;
        let mut batch = Vec::with_capacity(BATCH);
        let mut flush = tokio::time::interval(Duration::from_millis(10));
        let failed = loop {
            tokio::select! {
                got = sub.recv() => match got {
                    Ok(mut f) => {
                        f.iface = 0;
                        batch.push(f);
                        if batch.len() >= BATCH && !offer(&tx, Feed::Frames(std::mem::take(&mut batch)), &mut lost) {
                            return;
                        }
                    }
                    Err(e) => break e,
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
        };
        if !batch.is_empty() {
            offer(&tx, Feed::Frames(std::mem::take(&mut batch)), &mut lost);
        }
        if tx.send(Feed::BusError(failed.to_string())).is_err() {
            return;
        }
        if failed == BusError::Closed {
            let _ = tx.send(Feed::Done);
            return;
        }
        tokio::time::sleep(Duration::from_secs(1)).await;
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
