//! The live capture task (`cotui live IFACE`, `cotui demo`): a thread with its own tokio
//! runtime that opens the bus, forwards every frame in batches, reopens the interface when
//! it fails, and runs the palette's commands on the same bus ([`Jobs`]: cancelled by
//! stop-all before it stops the drives).

use super::messages::Level;
use super::source::Feed;
use crate::bus::{Bus, BusError, BusState, Event, StateChange};
use crate::command::stop::{Commanded, StopOptions, stop_nodes};
use crate::command::{self, Command};
use crate::decode::cia402::DriveState;
use crate::frame::Frame;
use crate::od::bind::Bindings;
use std::collections::BTreeSet;
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::time::Duration;
use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};
use tokio::task::AbortHandle;

/// What the UI asks the live task to do.
#[derive(Debug)]
pub enum Request {
    /// Run a palette command (`line` as typed); the result comes back as [`Feed::Result`].
    Run { line: String, command: Command },
    /// Stop-all: cancel every command still running, then quick stop and disable voltage on
    /// `nodes` and on every node this task saw cotui command.
    StopAll { nodes: BTreeSet<u8>, options: StopOptions },
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
    // Nodes a stop confirmed stopped, from the stop task back to this loop.
    let (stopped_tx, mut stopped) = unbounded_channel();
    let mut jobs = Jobs::new(stopped_tx);
    let bus = loop {
        match crate::connect::open(&iface, listen_only).await {
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
                            Some(r) => jobs.refuse(r, &e, &tx),
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
                    jobs.observe(&f);
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
                Some(r) => jobs.start(&bus, r, &bindings, &tx),
                None => return,
            },
            Some(nodes) = stopped.recv() => jobs.stopped(&nodes),
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

/// The commands the live task runs for the palette, and the nodes cotui commanded. Owned
/// by the capture loop: it sees every frame first, so no lock is taken per frame.
struct Jobs {
    /// Running commands (the palette line and its task), cancelled by stop-all.
    running: Vec<(String, AbortHandle)>,
    /// Nodes cotui commanded, from the frames it sent; a confirmed stop forgets a node.
    commanded: Commanded,
    /// Where a stop task sends the nodes it confirmed stopped (see [`Jobs::stopped`]).
    stopped_tx: UnboundedSender<Vec<u8>>,
}

impl Jobs {
    fn new(stopped_tx: UnboundedSender<Vec<u8>>) -> Jobs {
        Jobs {
            running: Vec::new(),
            commanded: Commanded::default(),
            stopped_tx,
        }
    }

    /// Notes a frame on the bus (ours, marked TX, may command a node).
    fn observe(&mut self, f: &Frame) {
        self.commanded.observe(f);
    }

    /// Forgets the nodes a stop confirmed stopped.
    fn stopped(&mut self, nodes: &[u8]) {
        nodes.iter().for_each(|n| self.commanded.forget(*n));
    }

    /// Starts a request on `bus`; its result goes to `tx` when it ends.
    fn start(&mut self, bus: &Bus, r: Request, bindings: &Bindings, tx: &SyncSender<Feed>) {
        self.running.retain(|(_, h)| !h.is_finished());
        let (bus, tx) = (bus.clone(), tx.clone());
        match r {
            Request::Run { line, command } => {
                let bindings = bindings.clone();
                let label = line.clone();
                let task = tokio::spawn(async move {
                    let (level, text) = match command::execute(&bus, &command, &bindings).await {
                        Ok(o) => (Level::Info, format!("{line}: {}", o.text)),
                        Err(e) => (Level::Error, format!("{line}: error: {e}")),
                    };
                    let _ = tx.send(Feed::Result(level, text));
                });
                self.running.push((label, task.abort_handle()));
            }
            Request::StopAll { mut nodes, options } => {
                // Cancel first: on this single-threaded runtime no cancelled task runs again,
                // so nothing it would have sent goes out after the stop.
                let cancelled = self.cancel_all();
                nodes.extend(self.commanded.nodes());
                let stopped_tx = self.stopped_tx.clone();
                tokio::spawn(async move {
                    let (level, text) = match stop_nodes(&bus, &nodes, options).await {
                        Ok(mut report) => {
                            report.cancelled = cancelled;
                            let _ =
                                stopped_tx.send(report.nodes.iter().filter(|n| n.stopped).map(|n| n.node).collect());
                            let level = if report.all_stopped() { Level::Info } else { Level::Warn };
                            (level, format!("stop all: {}", report.text()))
                        }
                        Err(e) => (Level::Error, e.to_string()),
                    };
                    let _ = tx.send(Feed::Result(level, text));
                });
            }
        }
    }

    /// Aborts every running command; returns their lines.
    fn cancel_all(&mut self) -> Vec<String> {
        self.running
            .drain(..)
            .filter(|(_, h)| !h.is_finished())
            .map(|(line, h)| {
                h.abort();
                line
            })
            .collect()
    }

    /// Answers a request while the bus is unavailable (`why`): nothing can be sent, but a
    /// stop still cancels what is running.
    fn refuse(&mut self, r: Request, why: &BusError, tx: &SyncSender<Feed>) {
        let text = match r {
            Request::Run { line, .. } => format!("{line}: not sent: {why}"),
            Request::StopAll { .. } => {
                let cancelled = self.cancel_all();
                format!(
                    "stop all: NOTHING sent, the bus is unavailable ({why}); cancelled: {}",
                    if cancelled.is_empty() {
                        "nothing was running".into()
                    } else {
                        cancelled.join("; ")
                    }
                )
            }
        };
        let _ = tx.send(Feed::Result(Level::Error, text));
    }
}

/// The drive state assumed for a preview when the node's state is unknown.
pub const UNKNOWN_STATE: DriveState = DriveState::SwitchOnDisabled;
