//! The capture side of the application: the trace and what feeds it (the source, its
//! replay controls and the live task's requests), the recording, the drives cotui
//! commanded, the bus events and the frame rate. No screen here: what the screen must
//! hear goes out as [`Event`]s.

use super::event::{Event, Queue};
use super::keymap::Action;
use super::live::{Request, Requests};
use super::messages::Level;
use super::record::Recorder;
use super::source::{Control, Extent, Feed, Position};
use crate::analysis::trace::Trace;
use crate::command::stop::Commanded;
use crate::decode::cia402::DriveState;
use crate::frame::Frame;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::time::Instant;

/// How the frames come in.
#[derive(Clone, Debug, PartialEq)]
pub enum SourceKind {
    /// A log loaded at once.
    Open,
    /// A log played by its timestamps.
    Replay { speed: f64 },
    /// A live interface.
    Live { listen_only: bool },
    /// The in-process simulated bus.
    Demo { listen_only: bool },
}

/// The capture source as the status bar shows it.
pub struct SourceInfo {
    /// Name (file or interface).
    pub name: String,
    /// Kind.
    pub kind: SourceKind,
    /// Paused by the user.
    pub paused: bool,
    /// The source has ended.
    pub done: bool,
    /// Frames the UI could not take (dropped).
    pub drops: u64,
    /// The interface error in force (with the command that fixes it): the first interface's
    /// in trouble when there are several.
    pub bus_error: Option<String>,
    /// Each live interface's condition by its index (`error-active`, `bus-off`, ...), and
    /// its error in force.
    pub buses: std::collections::BTreeMap<u16, (&'static str, Option<String>)>,
    /// A replay starts over at its end.
    pub looping: bool,
    /// Where a replay is, and the size of its log once measured.
    pub replay: (Option<Position>, Option<Extent>),
    feed: Option<Receiver<Feed>>,
    control: Option<Sender<Control>>,
    requests: Option<Requests>,
}

impl SourceInfo {
    /// A source fed by `feed`, commanded through `control` (replays).
    pub fn new(name: &str, kind: SourceKind, feed: Receiver<Feed>, control: Option<Sender<Control>>) -> SourceInfo {
        SourceInfo {
            name: name.to_string(),
            kind,
            paused: false,
            done: false,
            drops: 0,
            bus_error: None,
            buses: std::collections::BTreeMap::new(),
            looping: false,
            replay: (None, None),
            feed: Some(feed),
            control,
            requests: None,
        }
    }

    /// True when a replay has played its last frame (it waits for a seek back or a rewind).
    pub fn replay_at_end(&self) -> bool {
        matches!(self.replay, (Some(p), Some(e)) if e.frames > 0 && p.frames >= e.frames)
    }

    /// A live source that also runs palette commands.
    pub fn live(name: &str, kind: SourceKind, feed: Receiver<Feed>, requests: Requests) -> SourceInfo {
        SourceInfo {
            requests: Some(requests),
            ..SourceInfo::new(name, kind, feed, None)
        }
    }
}

/// What taking from the source did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Flow {
    /// Something came in; more may be waiting.
    Took,
    /// Nothing is waiting.
    Empty,
    /// The source ended.
    Ended,
}

/// Bus events kept in [`Capture::node_events`].
pub const NODE_EVENTS: usize = 1000;

/// How much a bus event matters in the message log.
fn event_level(what: &crate::analysis::What) -> Level {
    use crate::analysis::What;
    match what {
        What::HeartbeatLost { .. } | What::BusState { .. } | What::BootUp { rebooted: true, .. } => Level::Warn,
        What::Emcy { .. } | What::SdoAbort { .. } => Level::Warn,
        _ => Level::Info,
    }
}

/// The capture: the trace and everything that feeds it or is sent on its bus.
pub struct Capture {
    trace: Trace,
    source: SourceInfo,
    recording: Option<Recorder>,
    commanded: Commanded,
    node_events: Vec<crate::analysis::Event>,
    rate: f64,
    rate_mark: (Instant, usize),
    /// The newest frame's time and when it was taken in: the capture clock of a live
    /// source or replay runs on from there.
    clock: Option<(u64, Instant)>,
}

impl Capture {
    /// A capture of `trace`, fed by `source`.
    pub fn new(trace: Trace, source: SourceInfo) -> Capture {
        Capture {
            trace,
            source,
            recording: None,
            commanded: Commanded::default(),
            node_events: Vec::new(),
            rate: 0.0,
            rate_mark: (Instant::now(), 0),
            clock: None,
        }
    }

    /// Frames and what is derived from them.
    pub fn trace(&self) -> &Trace {
        &self.trace
    }

    /// The trace, to change (tests feed frames straight in).
    #[cfg(test)]
    pub(crate) fn trace_mut(&mut self) -> &mut Trace {
        &mut self.trace
    }

    /// Runs `:expect` (see [`super::expect::command`]) on the trace's diagnosis.
    pub(crate) fn expect(&mut self, rest: &str) -> Result<(String, Vec<String>), String> {
        super::expect::command(rest, &mut self.trace)
    }

    /// The capture source.
    pub fn source(&self) -> &SourceInfo {
        &self.source
    }

    /// The capture source, to change.
    pub fn source_mut(&mut self) -> &mut SourceInfo {
        &mut self.source
    }

    /// Frames per second over the last rate tick.
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// Bus events (node lost/back, boot-ups, state changes, EMCY, SDO aborts, controller
    /// state), oldest first, the newest [`NODE_EVENTS`] kept.
    pub fn node_events(&self) -> &[crate::analysis::Event] {
        &self.node_events
    }

    /// The recording in progress (`record start FILE`), if any.
    pub fn recording(&self) -> Option<&Recorder> {
        self.recording.as_ref()
    }

    /// The recording slot, for `record start` / `record stop`.
    pub(crate) fn recording_mut(&mut self) -> &mut Option<Recorder> {
        &mut self.recording
    }

    /// Nodes cotui commanded on the bus (from the frames it sent): what stop-all stops,
    /// besides the drives seen powered.
    pub fn commanded(&self) -> &Commanded {
        &self.commanded
    }

    /// Notes a frame cotui sent (tests stand in for the bus).
    #[cfg(test)]
    pub(crate) fn observe(&mut self, f: &Frame) {
        self.commanded.observe(f);
    }

    /// The drive state of node `node` seen last.
    pub(crate) fn drive_state(&self, node: u8) -> Option<DriveState> {
        self.trace.nodes.by_id(node).and_then(|n| n.drive)
    }

    /// True when the source cannot send (listen-only).
    pub(crate) fn listen_only(&self) -> bool {
        matches!(
            self.source.kind,
            SourceKind::Live { listen_only: true } | SourceKind::Demo { listen_only: true }
        )
    }

    /// True when there is a bus to send on (a live or demo source).
    pub(crate) fn has_bus(&self) -> bool {
        self.source.requests.is_some()
    }

    /// Asks the live task; false when the source has no bus.
    pub(crate) fn request(&self, r: Request) -> bool {
        match &self.source.requests {
            Some(req) => {
                let _ = req.send(r);
                true
            }
            None => false,
        }
    }

    /// Sends `c` to a replay; false when the source is not a replay.
    pub(crate) fn control(&self, c: Control) -> bool {
        match &self.source.control {
            Some(ctl) => {
                let _ = ctl.send(c);
                true
            }
            None => false,
        }
    }

    /// Takes one item from the source; what the screen must hear goes to `q`.
    pub(crate) fn take(&mut self, q: &mut Queue) -> Flow {
        let Some(feed) = &self.source.feed else {
            return Flow::Empty;
        };
        match feed.try_recv() {
            Ok(Feed::Frames { frames: batch, figures }) => {
                let mut figures = figures.into_iter();
                for f in &batch {
                    self.commanded.observe(f);
                    self.trace.push_figured(f, figures.next());
                }
                self.clock = batch.last().map(|f| (f.ts_ns, Instant::now()));
                self.record(&batch, q);
                self.collect_node_events(q);
            }
            Ok(Feed::Interfaces(names)) => {
                for n in names {
                    self.trace.ifaces.intern(&n);
                }
            }
            Ok(Feed::Reset) => {
                self.trace.clear();
                self.rate_mark = (Instant::now(), 0);
                self.clock = None;
                q.push(Event::Reset);
            }
            Ok(Feed::Status(s)) => q.push(Event::Say(Level::Info, s)),
            Ok(Feed::Position(p)) => {
                self.source.replay.0 = Some(p);
                self.replay_end();
            }
            Ok(Feed::Extent(e)) => {
                self.source.replay.1 = Some(e);
                self.replay_end();
            }
            Ok(Feed::Result(level, s)) => q.push(Event::Result(level, s)),
            Ok(Feed::Stopped(level, s, failed)) => q.push(Event::Stopped(level, s, failed)),
            Ok(Feed::TransmitStopped(why)) => q.push(Event::TransmitStopped(why)),
            Ok(Feed::Lost(n)) => self.source.drops += n,
            Ok(Feed::BusError(note)) => {
                let bus = self.source.buses.entry(note.iface).or_insert((note.state, None));
                if bus.1.as_ref() != Some(&note.text) {
                    q.push(Event::Log(Level::Error, note.text.clone()));
                }
                *bus = (note.state, Some(note.text));
                self.source.bus_error = self.source.buses.values().find_map(|b| b.1.clone());
                self.clock = None;
            }
            Ok(Feed::BusOk(note)) => {
                // A recovery is news (the error it ends was shown); the first "capturing" is not.
                let was = self.source.buses.insert(note.iface, (note.state, None));
                if was.and_then(|b| b.1).is_some() {
                    q.push(Event::Say(Level::Info, note.text));
                }
                self.source.bus_error = self.source.buses.values().find_map(|b| b.1.clone());
            }
            Ok(Feed::Done) | Err(TryRecvError::Disconnected) => {
                // Transfers the input cut off are listed, as `decode --transactions` lists them.
                self.trace.end_of_input();
                self.trace.store.shrink();
                self.source.done = true;
                self.source.feed = None;
                return Flow::Ended;
            }
            Err(TryRecvError::Empty) => return Flow::Empty,
        }
        Flow::Took
    }

    /// A replay that played its last frame ended its input (until it goes back, which
    /// starts the trace over): the transfers it cut off are listed.
    fn replay_end(&mut self) {
        if self.source.replay_at_end() {
            self.trace.end_of_input();
        }
    }

    /// Writes a batch of frames to the recording, if one runs; a failed write ends it.
    fn record(&mut self, batch: &[Frame], q: &mut Queue) {
        let Some(r) = self.recording.as_mut() else { return };
        if let Err(e) = r.frames(batch, &self.trace.ifaces) {
            let (file, n) = (r.file.clone(), r.count());
            self.recording = None;
            q.push(Event::Say(
                Level::Error,
                format!("record: {file}: {e}; stopped, {n} whole frames kept"),
            ));
        }
    }

    /// The capture time now (ns on the frames' time base) for a live source (the newest
    /// frame's time plus the wall time since it was taken in, so delivery delays only make
    /// it late) or a running replay (times its speed); None for a loaded log, a paused or
    /// finished source, an interface in error (its silence says nothing about the nodes),
    /// or before the first frame.
    pub(crate) fn now_ns(&self, now: Instant) -> Option<u64> {
        let speed = match self.source.kind {
            SourceKind::Live { .. } | SourceKind::Demo { .. } => 1.0,
            SourceKind::Replay { speed } if speed > 0.0 && !self.source.paused => speed,
            _ => return None,
        };
        if self.source.done || self.source.replay_at_end() || self.source.bus_error.is_some() {
            return None;
        }
        let (ts, at) = self.clock?;
        Some(ts + (now.saturating_duration_since(at).as_secs_f64() * speed * 1e9) as u64)
    }

    /// Advances the node table to the capture time at wall time `now` (live and replay);
    /// true when that made bus events.
    pub(crate) fn liveness_tick(&mut self, now: Instant, q: &mut Queue) -> bool {
        match self.now_ns(now) {
            Some(t) => {
                self.trace.tick(t);
                self.collect_node_events(q)
            }
            None => false,
        }
    }

    /// Measures the frame rate every half second; true when it was measured.
    pub(crate) fn rate_tick(&mut self) -> bool {
        let (t, n) = self.rate_mark;
        let dt = t.elapsed().as_secs_f64();
        if dt < 0.5 {
            return false;
        }
        self.rate = self.trace.len().saturating_sub(n) as f64 / dt;
        self.rate_mark = (Instant::now(), self.trace.len());
        true
    }

    /// Moves new bus events from the node table to the message log (each with its capture
    /// time) and to [`Capture::node_events`] (the newest [`NODE_EVENTS`] kept); a lost node,
    /// a reboot or a controller state change also goes to the status line. True when there
    /// were any.
    fn collect_node_events(&mut self, q: &mut Queue) -> bool {
        use crate::analysis::What;
        let events = self.trace.nodes.take_events();
        let t0 = super::panes::start_ns(&self.trace);
        for e in &events {
            let at = e.t_ns.saturating_sub(t0) as f64 / 1e9;
            q.push(Event::Log(event_level(&e.what), format!("[t={at:.3} s] {}", e.text())));
        }
        let notable = events.iter().rev().find(|e| {
            matches!(
                e.what,
                What::HeartbeatLost { .. } | What::BootUp { rebooted: true, .. } | What::BusState { .. }
            )
        });
        if let Some(e) = notable {
            q.push(Event::Note(e.text()));
        }
        let any = !events.is_empty();
        self.node_events.extend(events);
        let excess = self.node_events.len().saturating_sub(NODE_EVENTS);
        self.node_events.drain(..excess);
        any
    }

    /// Pauses (`true`) or resumes the capture; a paused trace stops following.
    pub(crate) fn set_paused(&mut self, p: bool, q: &mut Queue) {
        self.source.paused = p;
        // The replay clock restarts from the next frame.
        self.clock = None;
        self.control(Control::Pause(p));
        if p {
            q.push(Event::Follow(false));
        }
    }

    /// Sets a replay's speed; the text says what it is now. None: the source is no replay.
    pub(crate) fn set_speed(&mut self, x: f64) -> Option<String> {
        match (&mut self.source.kind, &self.source.control) {
            (SourceKind::Replay { speed }, Some(c)) => {
                *speed = x;
                let _ = c.send(Control::Speed(x));
                Some(if x == 0.0 {
                    "speed: as fast as possible".into()
                } else {
                    format!("speed ×{x}")
                })
            }
            _ => None,
        }
    }

    /// Sends `c` to a replay, whose newest frame the trace then follows; false when the
    /// source is not a replay.
    pub(crate) fn replay_control(&self, c: Control, q: &mut Queue) -> bool {
        let sent = self.control(c);
        if sent {
            q.push(Event::Follow(true));
        }
        sent
    }

    /// Does what a replay key says (pause, speed, step, loop, step back, rewind, seek).
    pub(crate) fn replay_key(&mut self, a: Action, q: &mut Queue) {
        match a {
            Action::Pause => {
                let p = !self.source.paused;
                self.set_paused(p, q);
                if !p {
                    q.push(Event::Follow(true));
                }
            }
            Action::SpeedUp | Action::SpeedDown => {
                if let SourceKind::Replay { speed } = self.source.kind {
                    let base = if speed <= 0.0 { 1.0 } else { speed };
                    let x = if a == Action::SpeedUp { base * 2.0 } else { base / 2.0 };
                    let x = x.clamp(*super::source::SPEEDS.start(), *super::source::SPEEDS.end());
                    let said = self
                        .set_speed(x)
                        .unwrap_or_else(|| super::commands::CommandError::NoSpeed.to_string());
                    q.push(Event::Note(said));
                }
            }
            Action::Step if self.source.paused && self.replay_control(Control::Step, q) => {}
            Action::Step => q.push(Event::Note("step: pause a replay first".into())),
            Action::Loop => {
                let on = !self.source.looping;
                if self.control(Control::Loop(on)) {
                    self.source.looping = on;
                    q.push(Event::Note(format!("replay loop {}", if on { "on" } else { "off" })));
                } else {
                    q.push(Event::Note("loop: only a replay can loop".into()));
                }
            }
            Action::StepBack | Action::Rewind => {
                let c = if a == Action::Rewind {
                    Control::Rewind
                } else {
                    Control::StepBack
                };
                if !self.replay_control(c, q) {
                    q.push(Event::Note("only a replay can step back or rewind".into()));
                }
            }
            Action::SeekForward | Action::SeekBack => {
                let d: i64 = if a == Action::SeekForward {
                    10_000_000_000
                } else {
                    -10_000_000_000
                };
                if !self.replay_control(Control::Seek(d), q) {
                    q.push(Event::Note("seek: only a replay can seek".into()));
                }
            }
            _ => {}
        }
    }
}
