//! The live capture task (`cotui live IFACE`, `cotui demo`): a thread with its own tokio
//! runtime that opens the bus, forwards every frame in batches, reopens the interface when
//! it fails, and runs the palette's commands on the same bus ([`Jobs`]: listed by `jobs`,
//! stopped one by one by `jobs stop ID`, cancelled by stop-all before it stops the drives,
//! cyclic SYNC/RPDO/raw senders first).

use super::frame_feed::{BACKLOG_FRAMES, FrameFeed};
use super::messages::Level;
use super::source::{BusNote, Feed};
use super::watch_board::SharedBoard;
use crate::bus::{Bus, BusError, BusState, Event, StateChange};
use crate::command::cyclic::{self, Progress};
use crate::command::stop::{Commanded, StopOptions, stop_nodes};
use crate::command::transmit_list::Resolved;
use crate::command::transmit_run::{ListProgress, transmit_list};
use crate::command::{self, Command, Spec};
use crate::decode::cia402::DriveState;
use crate::frame::Frame;
use crate::od::bind::Bindings;
use crate::sim::control::Control;
use crate::sim::demo::Demo;
use std::collections::BTreeSet;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
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
    /// `jobs`: list the palette commands still running (cyclic ones with their count so far).
    ListJobs,
    /// `jobs stop ID`: stop one of them, with its timing report.
    StopJob(u32),
    /// `sim fault|silence|resume|reboot|mains|status ...` (`line` as typed): make a node of
    /// the demo's simulation fail; refused on other sources.
    Sim { line: String, control: Control },
    /// The Transmit pane's list changed: stop sending the previous one, send `entries`
    /// (the disabled ones listed, not sent), counts in `progress` (one per entry).
    Transmit {
        entries: Vec<Resolved>,
        progress: ListProgress,
    },
    /// The Watch pane's list changed: stop its polls, poll each group of `board` still
    /// polling something (what they read goes on the board).
    Watch { board: SharedBoard },
}

/// A handle to send requests to the live task.
pub type Requests = UnboundedSender<Request>;

/// Frames per batch.
const BATCH: usize = 1024;
/// Capacity of the feed channel in batches; when full, frames wait in the
/// [`FrameFeed`]'s backlog.
const QUEUE: usize = 256;

/// Starts capturing `ifaces` (at least one; `demo` and `demo2` are simulated buses: the
/// first demo bus runs `demo`, the standard demo when `None`, the others the standard demo),
/// one capture task per interface on one runtime, their frames tagged with the interface's
/// index in `ifaces`. Palette commands go to the first interface; they use `bindings` for
/// object names and types. The first interface's task also runs what the TUI `hosted`.
pub fn start(
    ifaces: &[String],
    listen_only: bool,
    bindings: Bindings,
    demo: Option<crate::sim::Simulation>,
    hosted: super::hosted::Hosted,
) -> (Receiver<Feed>, Requests) {
    let (tx, rx) = sync_channel(QUEUE);
    let (req_tx, req_rx) = unbounded_channel();
    let ifaces = ifaces.to_vec();
    std::thread::spawn(move || {
        let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
            Ok(rt) => rt,
            Err(e) => {
                let _ = tx.send(Feed::Status(format!("cannot start the bus task: {e}")));
                let _ = tx.send(Feed::Done);
                return;
            }
        };
        if tx.send(Feed::Interfaces(ifaces.clone())).is_err() {
            return;
        }
        let mut demo = demo;
        let mut first = Some((req_rx, hosted));
        let local = tokio::task::LocalSet::new();
        for (i, iface) in ifaces.into_iter().enumerate() {
            let sim = if crate::connect::is_demo(&iface) {
                Some(demo.take().unwrap_or_else(crate::sim::Simulation::demo))
            } else {
                None
            };
            let bus = Capture {
                index: i as u16,
                iface,
                listen_only,
            };
            let (req, hosted) = first.take().unzip();
            local.spawn_local(capture(bus, bindings.clone(), tx.clone(), req, sim, hosted));
        }
        drop(tx);
        // The capture ends when every interface's task has (the UI went away, or a bus closed).
        rt.block_on(local);
    });
    (rx, req_tx)
}

/// One interface a capture task opens.
struct Capture {
    /// Its index in the interface table (the frames' `iface`).
    index: u16,
    iface: String,
    listen_only: bool,
}

impl Capture {
    fn note(&self, state: &'static str, text: String) -> BusNote {
        BusNote {
            iface: self.index,
            state,
            text,
        }
    }
}

/// The next request, or never when this task takes none (an interface besides the first).
async fn next_request(req: &mut Option<UnboundedReceiver<Request>>) -> Option<Request> {
    match req {
        Some(r) => r.recv().await,
        None => std::future::pending().await,
    }
}

/// Opens the bus (retrying every second until it can), then forwards frames in batches
/// and every change of the interface or controller state: [`Feed::BusError`] (with the
/// fix) when capture stops or the controller is in trouble, [`Feed::BusOk`] when it is
/// back. The bus handle follows the interface by name, so capture resumes by itself. With
/// `req`, the task also runs the palette's commands on this bus, and `hosted`'s servers;
/// `demo` is the simulation of a demo bus.
async fn capture(
    cap: Capture,
    bindings: Bindings,
    tx: SyncSender<Feed>,
    mut req: Option<UnboundedReceiver<Request>>,
    mut demo: Option<crate::sim::Simulation>,
    hosted: Option<super::hosted::Hosted>,
) {
    let Capture {
        index,
        ref iface,
        listen_only,
    } = cap;
    // Nodes a stop confirmed stopped, from the stop task back to this loop.
    let (stopped_tx, mut stopped) = unbounded_channel();
    let mut jobs = Jobs::new(stopped_tx);
    // The demo's simulation, for `sim` commands (none on a real interface).
    let mut sim: Option<Demo> = None;
    let bus = loop {
        if crate::connect::is_demo(iface) {
            let d = Demo::spawn(demo.take().unwrap_or_else(crate::sim::Simulation::demo), listen_only);
            let bus = d.bus.clone();
            sim = Some(d);
            break bus;
        }
        match crate::connect::open(iface, listen_only).await {
            Ok(b) => break b,
            Err(e) => {
                if tx.send(Feed::BusError(cap.note("unavailable", e.to_string()))).is_err() {
                    return;
                }
                // Answer requests while waiting, so the palette never hangs.
                let wait = tokio::time::sleep(Duration::from_secs(1));
                tokio::pin!(wait);
                loop {
                    tokio::select! {
                        _ = &mut wait => break,
                        r = next_request(&mut req) => match r {
                            Some(r) => jobs.refuse(r, &e, &tx),
                            None => return,
                        },
                    }
                }
            }
        }
    };
    if tx
        .send(Feed::BusOk(cap.note("capturing", format!("{iface}: capturing"))))
        .is_err()
    {
        return;
    }
    // The hosted servers' audit lines, to the message log in order with the frames.
    let (log_tx, mut log) = unbounded_channel();
    if let Some(h) = hosted {
        h.start(&bus, sim.as_ref().map(|d| &d.vbus), &log_tx);
    }
    let mut feed = FrameFeed::new(tx.clone(), BACKLOG_FRAMES);
    // Frames dropped (past the backlog's bound) not yet reported.
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
                    f.iface = index;
                    jobs.observe(&f);
                    batch.push(f);
                    if batch.len() >= BATCH && !feed.frames(std::mem::take(&mut batch)) {
                        return;
                    }
                }
                Ok(Event::State(s)) => {
                    // Frames before the change first, so the trace and the notice agree.
                    if !feed.frames(std::mem::take(&mut batch)) || !feed.send(state_feed(&cap, &s, &mut stopped_at)) {
                        return;
                    }
                }
                Err(BusError::Closed) => {
                    feed.frames(std::mem::take(&mut batch));
                    // The source ends once every interface's task has: the feed then closes.
                    let _ = feed.send(Feed::BusError(cap.note("closed", format!("{iface}: {}", BusError::Closed))));
                    return;
                }
                Err(e) => {
                    if tx.send(Feed::Status(e.to_string())).is_err() {
                        return;
                    }
                }
            },
            _ = flush.tick() => {
                if !feed.frames(std::mem::take(&mut batch)) {
                    return;
                }
                lost += feed.take_lost();
                let total = lost + sub.lost() - reported;
                if total > 0 && feed.channel().try_send(Feed::Lost(total)).is_ok() {
                    lost = 0;
                    reported = sub.lost();
                }
            }
            r = next_request(&mut req) => match r {
                Some(Request::Sim { line, control }) => {
                    let feed = simulate(sim.as_ref(), &line, control).await;
                    let _ = tx.send(feed);
                }
                Some(r) => jobs.start(&bus, r, &bindings, &tx),
                None => return,
            },
            Some(nodes) = stopped.recv() => jobs.stopped(&nodes),
            Some(line) = log.recv() => {
                if !feed.frames(std::mem::take(&mut batch)) || !feed.send(Feed::Result(Level::Info, line)) {
                    return;
                }
            }
        }
    }
}

/// Why a `sim` command is refused on a real bus.
fn not_simulated(line: &str) -> String {
    format!("{line}: only the demo's drives are simulated (`cotui demo`)")
}

/// Carries out a `sim` command on the demo's simulation: the nodes' frames (boot-up after a
/// reboot) go out from the simulation's side of the bus.
async fn simulate(demo: Option<&Demo>, line: &str, control: Control) -> Feed {
    let Some(demo) = demo else {
        return Feed::Result(Level::Error, not_simulated(line));
    };
    let now = demo.nodes.now_ns();
    let (text, frames) = match demo.sim.lock() {
        Ok(mut s) => control.apply(&mut s, now),
        Err(_) => return Feed::Result(Level::Error, format!("{line}: the simulation is unavailable")),
    };
    for f in &frames {
        if let Err(e) = demo.nodes.send(f).await {
            return Feed::Result(Level::Error, format!("{line}: {e}"));
        }
    }
    Feed::Result(Level::Info, format!("{line}: {text}"))
}

/// The feed item for a change of state: trouble (with the fix) or all well again (saying
/// how long capture was stopped, if it was).
fn state_feed(cap: &Capture, s: &StateChange, stopped_at: &mut Option<u64>) -> Feed {
    let (iface, state) = (cap.iface.as_str(), s.state.name());
    if !s.state.capturing() {
        stopped_at.get_or_insert(s.ts_ns);
    }
    if s.state != BusState::Active {
        return Feed::BusError(cap.note(state, s.text(iface)));
    }
    match stopped_at.take() {
        Some(t) => Feed::BusOk(cap.note(
            state,
            format!(
                "{iface}: capturing again after {:.1} s without capture",
                s.ts_ns.saturating_sub(t) as f64 / 1e9
            ),
        )),
        None => Feed::BusOk(cap.note(state, s.text(iface))),
    }
}

/// A palette command the live task runs.
struct Job {
    /// Its number in `jobs` (from 1).
    id: u32,
    /// The palette line.
    line: String,
    task: AbortHandle,
    /// A cyclic command's shared timing, what it sends and its period.
    cyclic: Option<(Progress, String, Option<u64>)>,
}

impl Job {
    /// `#2 sync --period 10: SYNC 080, every 10 ms, 123 sent` (the line for others).
    fn listed(&self) -> String {
        match &self.cyclic {
            Some((p, what, period)) => format!(
                "#{} {}: {what}, {}{} sent",
                self.id,
                self.line,
                period.map(|ms| format!("every {ms} ms, ")).unwrap_or_default(),
                cyclic::lock(p).sent
            ),
            None => format!("#{} {}", self.id, self.line),
        }
    }

    /// Aborts the task; the line for the stop report (a cyclic job's with its timing so far).
    fn cancel(self) -> String {
        self.task.abort();
        match &self.cyclic {
            Some((p, what, period)) => format!("{} ({})", self.line, cyclic::lock(p).report(what, *period, &[]).text()),
            None => self.line,
        }
    }
}

/// The commands the live task runs for the palette, and the nodes cotui commanded. Owned
/// by the capture loop: it sees every frame first, so no lock is taken per frame.
struct Jobs {
    /// Running commands, cancelled by stop-all (cyclic ones included) or `jobs stop ID`.
    running: Vec<Job>,
    /// The id of the next job.
    next_id: u32,
    /// Nodes cotui commanded, from the frames it sent; a confirmed stop forgets a node.
    commanded: Commanded,
    /// Where a stop task sends the nodes it confirmed stopped (see [`Jobs::stopped`]).
    stopped_tx: UnboundedSender<Vec<u8>>,
    /// The Transmit pane's list being sent (one at a time: a new list replaces it).
    transmit: Option<AbortHandle>,
    /// The Watch pane's poll groups (a changed list starts and stops only what changed).
    watch: super::watch_run::Polls,
}

impl Jobs {
    fn new(stopped_tx: UnboundedSender<Vec<u8>>) -> Jobs {
        Jobs {
            running: Vec::new(),
            next_id: 1,
            commanded: Commanded::default(),
            stopped_tx,
            transmit: None,
            watch: Default::default(),
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
        self.running.retain(|j| !j.task.is_finished());
        let (bus, tx) = (bus.clone(), tx.clone());
        match r {
            Request::Run { line, command } => {
                let cyclic = command
                    .source(bindings)
                    .and_then(Result::ok)
                    .map(|s| (Progress::default(), s.what, s.schedule.every_ms));
                let progress = cyclic.as_ref().map(|c| c.0.clone()).unwrap_or_default();
                let bindings = bindings.clone();
                let label = line.clone();
                let task = tokio::spawn(async move {
                    let stop = std::future::pending();
                    let (level, text) = match command::execute_until(&bus, &command, &bindings, progress, stop).await {
                        Ok(o) => (Level::Info, format!("{line}: {}", o.text)),
                        Err(e) => (Level::Error, format!("{line}: error: {e}")),
                    };
                    let _ = tx.send(Feed::Result(level, text));
                });
                self.running.push(Job {
                    id: self.next_id,
                    line: label,
                    task: task.abort_handle(),
                    cyclic,
                });
                self.next_id += 1;
            }
            Request::Sim { line, .. } => {
                let _ = tx.send(Feed::Result(Level::Error, not_simulated(&line)));
            }
            Request::Transmit { entries, progress } => {
                if let Some(t) = self.transmit.take() {
                    t.abort();
                }
                let task = tokio::spawn(async move {
                    let stop = std::future::pending();
                    let feed = match transmit_list(&bus, "Transmit pane", entries, None, progress, stop).await {
                        Ok(r) => r.stopped_by.map(Feed::TransmitStopped),
                        Err(e) => Some(Feed::Result(Level::Error, format!("transmit: not sent: {e}"))),
                    };
                    if let Some(feed) = feed {
                        let _ = tx.send(feed);
                    }
                });
                self.transmit = Some(task.abort_handle());
            }
            Request::Watch { board } => {
                self.watch.follow(&bus, &board, bindings);
            }
            Request::ListJobs => {
                let text = if self.running.is_empty() {
                    "jobs: nothing running".to_string()
                } else {
                    let list: Vec<String> = self.running.iter().map(Job::listed).collect();
                    format!("jobs: {}", list.join("; "))
                };
                let _ = tx.send(Feed::Result(Level::Info, text));
            }
            Request::StopJob(id) => {
                let (level, text) = match self.running.iter().position(|j| j.id == id) {
                    Some(k) => (
                        Level::Info,
                        format!("jobs stop {id}: stopped {}", self.running.remove(k).cancel()),
                    ),
                    None => (
                        Level::Error,
                        format!("jobs stop {id}: no such job running (see `jobs`)"),
                    ),
                };
                let _ = tx.send(Feed::Result(level, text));
            }
            Request::StopAll { mut nodes, options } => {
                // Cancel first: on this single-threaded runtime no cancelled task runs again,
                // so nothing it would have sent goes out after the stop.
                let cancelled = self.cancel_all();
                nodes.extend(self.commanded.nodes());
                let stopped_tx = self.stopped_tx.clone();
                tokio::spawn(async move {
                    let (level, text, failed) = match stop_nodes(&bus, &nodes, options).await {
                        Ok(mut report) => {
                            report.cancelled = cancelled;
                            let _ =
                                stopped_tx.send(report.nodes.iter().filter(|n| n.stopped).map(|n| n.node).collect());
                            let level = if report.all_stopped() { Level::Info } else { Level::Warn };
                            let failed = report.nodes.iter().filter(|n| !n.stopped).map(|n| n.node).collect();
                            (level, format!("stop all: {}", report.text()), failed)
                        }
                        Err(e) => (Level::Error, e.to_string(), nodes.into_iter().collect()),
                    };
                    let _ = tx.send(Feed::Stopped(level, text, failed));
                });
            }
        }
    }

    /// Aborts every running command, cyclic ones (SYNC, RPDOs, raw frames) first; returns
    /// their lines (a cyclic one's with its timing report).
    fn cancel_all(&mut self) -> Vec<String> {
        let mut cancelled = Vec::new();
        if let Some(t) = self.transmit.take().filter(|t| !t.is_finished()) {
            t.abort();
            cancelled.push("the Transmit pane's list".to_string());
        }
        if self.watch.stop() {
            cancelled.push("the Watch pane's polls".to_string());
        }
        self.running.sort_by_key(|j| j.cyclic.is_none());
        cancelled.extend(
            self.running
                .drain(..)
                .filter(|j| !j.task.is_finished())
                .map(Job::cancel),
        );
        cancelled
    }

    /// Answers a request while the bus is unavailable (`why`): nothing can be sent, but a
    /// stop still cancels what is running.
    fn refuse(&mut self, r: Request, why: &BusError, tx: &SyncSender<Feed>) {
        let text = match r {
            Request::Run { line, .. } => format!("{line}: not sent: {why}"),
            Request::ListJobs | Request::StopJob(_) => format!("jobs: the bus is unavailable ({why})"),
            Request::Transmit { .. } => format!("transmit: not sent: {why}"),
            Request::Watch { .. } => format!("watch: nothing polled: {why}"),
            Request::Sim { line, .. } => not_simulated(&line),
            Request::StopAll { mut nodes, .. } => {
                let cancelled = self.cancel_all();
                nodes.extend(self.commanded.nodes());
                let text = format!(
                    "stop all: NOTHING sent, the bus is unavailable ({why}); cancelled: {}",
                    if cancelled.is_empty() {
                        "nothing was running".into()
                    } else {
                        cancelled.join("; ")
                    }
                );
                let _ = tx.send(Feed::Stopped(Level::Error, text, nodes.into_iter().collect()));
                return;
            }
        };
        let _ = tx.send(Feed::Result(Level::Error, text));
    }
}

/// The drive state assumed for a preview when the node's state is unknown.
pub const UNKNOWN_STATE: DriveState = DriveState::SwitchOnDisabled;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::parse_command;

    /// The next result the live task reports (waiting in tokio time, which is paused).
    async fn result(rx: &Receiver<Feed>) -> String {
        loop {
            match rx.try_recv() {
                Ok(Feed::Result(_, text) | Feed::Stopped(_, text, _)) => return text,
                Ok(_) => {}
                Err(_) => tokio::time::sleep(Duration::from_millis(5)).await,
            }
        }
    }

    /// One of our SYNCs (the demo bus has its own SYNC producer).
    fn ours(f: &Frame) -> bool {
        f.id == 0x080 && f.direction() == crate::frame::Direction::Tx
    }

    #[tokio::test(start_paused = true)]
    async fn cyclic_jobs_are_listed_stopped_one_by_one_and_by_stop_all() {
        let bus = crate::sim::demo::start(false);
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let (tx, rx) = sync_channel(64);
        let (stopped_tx, _stopped) = unbounded_channel();
        let mut jobs = Jobs::new(stopped_tx);
        let mut sub = bus.subscribe();
        for line in ["sync --period 10", "send 123#01 --every 20"] {
            let mut command = parse_command(line).unwrap();
            // As the palette runs it: its trace check replaces the listening (the demo bus
            // has its own SYNC producer).
            if let crate::command::Command::Sync(s) = &mut command {
                s.listen.ms = 0;
            }
            jobs.start(
                &bus,
                Request::Run {
                    line: line.into(),
                    command,
                },
                &bindings,
                &tx,
            );
        }
        let mut syncs = 0;
        while syncs < 5 {
            let f = sub.recv().await.unwrap();
            syncs += ours(&f) as u64;
        }
        jobs.start(&bus, Request::ListJobs, &bindings, &tx);
        let list = result(&rx).await;
        assert!(
            list.starts_with("jobs: #1 sync --period 10: SYNC 080, every 10 ms, "),
            "{list}"
        );
        assert!(
            list.contains("; #2 send 123#01 --every 20: 123#01, every 20 ms, "),
            "{list}"
        );

        jobs.start(&bus, Request::StopJob(1), &bindings, &tx);
        let stopped = result(&rx).await;
        assert!(
            stopped.starts_with("jobs stop 1: stopped sync --period 10 (SYNC 080: "),
            "{stopped}"
        );
        let sent: u64 = stopped
            .split("SYNC 080: ")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap();
        // No SYNC after the stop: every one on the bus was counted in the report.
        tokio::time::sleep(Duration::from_millis(200)).await;
        while let Some(f) = sub.try_recv() {
            syncs += ours(&f.unwrap()) as u64;
        }
        assert_eq!(syncs, sent);
        jobs.start(&bus, Request::StopJob(1), &bindings, &tx);
        assert_eq!(result(&rx).await, "jobs stop 1: no such job running (see `jobs`)");

        let options = StopOptions {
            timeout_ms: 50,
            ramp_ms: 10,
        };
        let nodes = BTreeSet::new();
        jobs.start(&bus, Request::StopAll { nodes, options }, &bindings, &tx);
        let report = result(&rx).await;
        assert!(
            report.contains("cancelled: send 123#01 --every 20 (123#01: "),
            "{report}"
        );
        jobs.start(&bus, Request::ListJobs, &bindings, &tx);
        assert_eq!(result(&rx).await, "jobs: nothing running");
    }

    #[tokio::test(start_paused = true)]
    async fn stop_all_disables_every_entry_of_a_transmit_list_before_it_stops_the_drives() {
        let bus = crate::sim::demo::start(false);
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let path = std::env::temp_dir().join(format!("cotui-live-list-{}.json", std::process::id()));
        std::fs::write(
            &path,
            r#"{"entries": [{"frame": "123#01", "every_ms": 10}, {"frame": "124#02", "every_ms": 30}]}"#,
        )
        .unwrap();
        let line = format!("send --list {}", path.display());
        let (tx, rx) = sync_channel(64);
        let (stopped_tx, _stopped) = unbounded_channel();
        let mut jobs = Jobs::new(stopped_tx);
        let mut sub = bus.subscribe();
        let command = parse_command(&line).unwrap();
        jobs.start(
            &bus,
            Request::Run {
                line: line.clone(),
                command,
            },
            &bindings,
            &tx,
        );
        let listed = |f: &Frame| f.direction() == crate::frame::Direction::Tx && (f.id == 0x123 || f.id == 0x124);
        let mut seen = 0;
        while seen < 6 {
            seen += listed(&sub.recv().await.unwrap()) as u32;
        }
        let options = StopOptions {
            timeout_ms: 50,
            ramp_ms: 10,
        };
        jobs.start(
            &bus,
            Request::StopAll {
                nodes: BTreeSet::from([2]),
                options,
            },
            &bindings,
            &tx,
        );
        // Every frame of the list still queued went out before the stop's first frame, none after.
        let mut stop_seen = false;
        let report = loop {
            while let Some(Ok(f)) = sub.try_recv() {
                if f.id == crate::cob::sdo_request(2) {
                    stop_seen = true;
                }
                assert!(!(stop_seen && listed(&f)), "a list frame after the stop: {f:?}");
            }
            if let Ok(Feed::Stopped(_, text, _)) = rx.try_recv() {
                break text;
            }
            tokio::time::sleep(Duration::from_millis(5)).await;
        };
        assert!(stop_seen);
        assert!(report.contains(&format!("cancelled: {line}")), "{report}");
        tokio::time::sleep(Duration::from_millis(200)).await;
        while let Some(Ok(f)) = sub.try_recv() {
            assert!(!listed(&f), "a list frame after the stop: {f:?}");
        }
    }

    #[tokio::test(start_paused = true)]
    async fn the_transmit_pane_list_sends_its_enabled_entries_on_their_period_and_stop_all_cancels_it() {
        use crate::command::transmit_list::load_entry;
        let bus = crate::sim::demo::start(false);
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let (tx, rx) = sync_channel(64);
        let (stopped_tx, _stopped) = unbounded_channel();
        let mut jobs = Jobs::new(stopped_tx);
        let mut sub = bus.subscribe();
        let entries = vec![
            load_entry(r#"{"frame": "123#01", "every_ms": 10}"#, 1, &bindings).unwrap(),
            load_entry(r#"{"frame": "124#02", "every_ms": 10, "enabled": false}"#, 2, &bindings).unwrap(),
        ];
        let progress = ListProgress::default();
        jobs.start(
            &bus,
            Request::Transmit {
                entries,
                progress: progress.clone(),
            },
            &bindings,
            &tx,
        );
        // 200 ms of bus time from our first frame, by the frames' own timestamps.
        let mut first = None;
        let mut in_window = 0u64;
        loop {
            let f = sub.recv().await.unwrap();
            assert!(f.id != 0x124, "a disabled entry was sent: {f:?}");
            if f.id != 0x123 || f.direction() != crate::frame::Direction::Tx {
                continue;
            }
            let t0 = *first.get_or_insert(f.ts_ns);
            if f.ts_ns - t0 >= 200_000_000 {
                break;
            }
            in_window += 1;
        }
        assert_eq!(in_window, 20, "one frame every 10 ms");
        assert!(crate::command::transmit_run::lock_all(&progress)[0].sent >= 21);
        let options = StopOptions {
            timeout_ms: 50,
            ramp_ms: 10,
        };
        jobs.start(
            &bus,
            Request::StopAll {
                nodes: BTreeSet::new(),
                options,
            },
            &bindings,
            &tx,
        );
        let report = result(&rx).await;
        assert!(report.contains("cancelled: the Transmit pane's list"), "{report}");
        while sub.try_recv().is_some() {}
        tokio::time::sleep(Duration::from_millis(100)).await;
        while let Some(Ok(f)) = sub.try_recv() {
            assert!(f.id != 0x123, "a list frame after the stop: {f:?}");
        }
    }
}

#[cfg(test)]
mod watch_tests {
    use super::*;
    use crate::command::watch_table::Watched;
    use crate::tui::watch_board::{SharedBoard, lock};

    /// The object an upload request of ours to `node` asks for, if `f` is one.
    fn upload_of(f: &Frame, node: u8) -> Option<(u16, u8)> {
        let d = &f.data;
        (f.id == crate::cob::sdo_request(node) && f.direction() == crate::frame::Direction::Tx && d[0] == 0x40)
            .then(|| (u16::from_le_bytes([d[1], d[2]]), d[3]))
    }

    #[tokio::test(start_paused = true)]
    async fn the_watch_pane_polls_on_its_period_marks_the_absent_and_times_out_and_stop_all_cancels_it() {
        let bus = crate::sim::demo::start(false);
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let (tx, rx) = sync_channel(64);
        let (stopped_tx, _stopped) = unbounded_channel();
        let mut jobs = Jobs::new(stopped_tx);
        let mut sub = bus.subscribe();
        let board = SharedBoard::default();
        let d2 = bindings.dictionary(2);
        let objects = vec![
            Watched::new(d2, 2, 0x6041, 0),
            Watched::new(d2, 2, 0x2FFF, 0),
            Watched::new(bindings.dictionary(9), 9, 0x1000, 0),
        ];
        lock(&board).add(objects, 50, 20);
        jobs.start(&bus, Request::Watch { board: board.clone() }, &bindings, &tx);
        // 500 ms of bus time from our first request, by the frames' own timestamps.
        let (mut first, mut statusword, mut absent) = (None, 0, 0);
        loop {
            let f = sub.recv().await.unwrap();
            let t0 = *first.get_or_insert(f.ts_ns);
            if f.ts_ns - t0 >= 500_000_000 {
                break;
            }
            statusword += (upload_of(&f, 2) == Some((0x6041, 0))) as u32;
            absent += (upload_of(&f, 2) == Some((0x2FFF, 0))) as u32;
        }
        assert_eq!(statusword, 10, "one read every 50 ms");
        assert_eq!(absent, 1, "an object the node lacks is asked once");
        {
            let b = lock(&board);
            let [sw, gone, silent] = &b.rows[..] else {
                panic!("{:?}", b.rows)
            };
            assert!(sw.watched.reads >= 10 && sw.watched.last_text.is_some(), "{sw:?}");
            assert!(sw.at_ns.is_some());
            assert!(gone.watched.absent, "{gone:?}");
            assert!(
                gone.watched
                    .last_error
                    .as_deref()
                    .unwrap_or("")
                    .starts_with("abort 0x06020000"),
                "{gone:?}"
            );
            assert_eq!(silent.watched.last_error.as_deref(), Some("timeout"));
            assert!(silent.watched.failures >= 5, "the timeouts go on: {silent:?}");
        }
        let options = StopOptions {
            timeout_ms: 50,
            ramp_ms: 10,
        };
        jobs.start(
            &bus,
            Request::StopAll {
                nodes: BTreeSet::new(),
                options,
            },
            &bindings,
            &tx,
        );
        let report = loop {
            if let Ok(Feed::Stopped(_, text, _)) = rx.try_recv() {
                break text;
            }
            tokio::time::sleep(Duration::from_millis(5)).await;
        };
        assert!(report.contains("cancelled: the Watch pane's polls"), "{report}");
        while sub.try_recv().is_some() {}
        tokio::time::sleep(Duration::from_millis(300)).await;
        while let Some(Ok(f)) = sub.try_recv() {
            assert!(
                upload_of(&f, 2).is_none() && upload_of(&f, 9).is_none(),
                "a poll after the stop: {f:?}"
            );
        }
    }
}
