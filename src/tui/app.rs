//! The application state and what every action does to it. Pure state transitions:
//! no terminal here, so tests drive it directly.

use super::keymap::{Action, Key, Keymap, Lookup};
use super::live::{Request, Requests};
use super::messages::{Level, Messages};
use super::palette::{self, COMMANDER_WORDS, Planned};
use super::prompt::{Prompt, PromptKind};
use super::rows::{Row, RowCache};
use super::source::{Control, Feed};
use crate::analysis::filter::{Filter, FilterError};
use crate::analysis::search::{Found, Search};
use crate::analysis::trace::Trace;
use crate::analysis::view::View;
use crate::command::Command;
use crate::command::stop::{Commanded, StopOptions, is_powered};
use crate::decode::Decoded;
use crate::od::bind::Bindings;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use std::collections::BTreeSet;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::time::SystemTime;
use std::time::{Duration, Instant};

/// The main-area panes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pane {
    Trace,
    Nodes,
    Sdo,
    Stats,
    Plot,
}

impl Pane {
    /// Every pane in tab order.
    pub const ALL: [Pane; 5] = [Pane::Trace, Pane::Nodes, Pane::Sdo, Pane::Stats, Pane::Plot];
    /// Tab title.
    pub fn title(self) -> &'static str {
        match self {
            Pane::Trace => "Trace",
            Pane::Nodes => "Nodes",
            Pane::Sdo => "SDO",
            Pane::Stats => "Stats",
            Pane::Plot => "Plot",
        }
    }
}

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
    /// The interface error in force (with the command that fixes it).
    pub bus_error: Option<String>,
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
            feed: Some(feed),
            control,
            requests: None,
        }
    }

    /// A live source that also runs palette commands.
    pub fn live(name: &str, kind: SourceKind, feed: Receiver<Feed>, requests: Requests) -> SourceInfo {
        SourceInfo {
            requests: Some(requests),
            ..SourceInfo::new(name, kind, feed, None)
        }
    }
}

/// Scroll state of a list pane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListState {
    /// Selected row.
    pub selected: usize,
    /// First visible row.
    pub offset: usize,
}

impl ListState {
    /// Keeps `selected` within `len` rows and visible in `height` rows.
    pub fn clamp(&mut self, len: usize, height: usize) {
        self.selected = self.selected.min(len.saturating_sub(1));
        let h = height.max(1);
        if self.selected < self.offset {
            self.offset = self.selected;
        } else if self.selected >= self.offset + h {
            self.offset = self.selected + 1 - h;
        }
        self.offset = self.offset.min(len.saturating_sub(h));
    }
}

/// Where the last draw put things (for mouse clicks and page sizes).
#[derive(Clone, Copy, Debug, Default)]
pub struct Layout {
    /// Rows of the main table, without header.
    pub table: Rect,
    /// Lines the message log popup shows at once.
    pub messages: usize,
}

/// The whole application state.
pub struct App {
    /// Frames and what is derived from them.
    pub trace: Trace,
    /// The filtered view of the trace.
    pub view: View,
    /// Key bindings.
    pub keymap: Keymap,
    /// The pane in the main area.
    pub pane: Pane,
    /// Trace pane scroll state (rows of the view).
    pub trace_list: ListState,
    /// Follow the newest frame.
    pub follow: bool,
    /// Nodes pane selection.
    pub nodes_list: ListState,
    /// SDO pane selection.
    pub sdo_list: ListState,
    /// SDO transaction expanded to its frames.
    pub sdo_expanded: Option<usize>,
    /// Stats pane selection.
    pub stats_list: ListState,
    /// Plot: index into the series keys.
    pub series_sel: usize,
    /// Help popup shown.
    pub help: bool,
    /// The prompt being edited.
    pub prompt: Option<Prompt>,
    /// The search in force (`n`/`N`), running over the trace in the background.
    pub search: Option<Search>,
    /// A message for the status bar (result of the last command).
    pub message: Option<String>,
    /// Every result, event and error of the session (the message log popup).
    pub messages: Messages,
    /// The message log popup is shown.
    pub messages_shown: bool,
    /// Lines the message log is scrolled up from its end.
    pub messages_back: usize,
    /// Palette history, newest last.
    pub history: Vec<String>,
    /// The capture source.
    pub source: SourceInfo,
    /// Decoded rows of the visible window.
    pub rows: RowCache,
    /// The selected frame decoded, with its position.
    pub detail: Option<(usize, Decoded)>,
    /// Frames per second over the last rate tick.
    pub rate: f64,
    /// Set when the user quits.
    pub quit: bool,
    /// Layout of the last draw.
    pub layout: Layout,
    /// Node bindings (object names and types for palette previews).
    pub bindings: Bindings,
    /// A commander line waiting for `y`.
    pub confirm: Option<Planned>,
    /// Nodes cotui commanded on the bus (from the frames it sent): what stop-all stops,
    /// besides the drives seen powered.
    pub commanded: Commanded,
    /// Quitting waits for `y`: these drives cotui commanded are still powered.
    pub quit_confirm: Option<Vec<u8>>,
    pending: Vec<Key>,
    rate_mark: (Instant, usize),
    /// Set when something changed since the last draw.
    pub dirty: bool,
    // --- node liveness (branch `live`): bus events for the message log, and the clock
    // that lets a silent node be found lost when no frame arrives.
    /// Bus events (node lost/back, boot-ups, state changes, EMCY, SDO aborts, controller
    /// state), oldest first, the newest [`NODE_EVENTS`] kept.
    pub node_events: Vec<crate::analysis::Event>,
    /// The newest frame's time and when it was taken in: the capture clock of a live
    /// source or replay runs on from there.
    capture_clock: Option<(u64, Instant)>,
}

/// Bus events kept in [`App::node_events`].
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

/// Names the palette completes.
pub const PALETTE_COMMANDS: &[&str] = &[
    "filter", "search", "goto", "time", "speed", "pause", "resume", "plot", "export", "help", "messages", "quit",
];

impl App {
    /// An application showing `trace`, fed by `source`.
    pub fn new(trace: Trace, keymap: Keymap, source: SourceInfo) -> App {
        let bindings = Bindings::new().expect("the built-in profiles load");
        App {
            trace,
            view: View::default(),
            keymap,
            pane: Pane::Trace,
            trace_list: ListState::default(),
            follow: true,
            nodes_list: ListState::default(),
            sdo_list: ListState::default(),
            sdo_expanded: None,
            stats_list: ListState::default(),
            series_sel: 0,
            help: false,
            prompt: None,
            search: None,
            message: None,
            messages: Messages::default(),
            messages_shown: false,
            messages_back: 0,
            history: Vec::new(),
            source,
            rows: RowCache::default(),
            detail: None,
            rate: 0.0,
            quit: false,
            layout: Layout::default(),
            confirm: None,
            bindings,
            commanded: Commanded::default(),
            quit_confirm: None,
            pending: Vec::new(),
            rate_mark: (Instant::now(), 0),
            dirty: true,
            node_events: Vec::new(),
            capture_clock: None,
        }
    }

    /// Takes frames from the source for up to `budget`; true when more are waiting.
    pub fn ingest(&mut self, budget: Duration) -> bool {
        let start = Instant::now();
        loop {
            let Some(feed) = &self.source.feed else {
                return false;
            };
            match feed.try_recv() {
                Ok(Feed::Frames(batch)) => {
                    for f in &batch {
                        self.commanded.observe(f);
                        self.trace.push(f);
                    }
                    self.capture_clock = batch.last().map(|f| (f.ts_ns, Instant::now()));
                    self.collect_node_events();
                    self.dirty = true;
                }
                Ok(Feed::Interfaces(names)) => {
                    for n in names {
                        self.trace.ifaces.intern(&n);
                    }
                }
                Ok(Feed::Reset) => {
                    self.trace.clear();
                    self.view = View::new(self.view.filter.clone());
                    self.restart_search();
                    self.rows = RowCache::default();
                    self.detail = None;
                    self.trace_list = ListState::default();
                    self.rate_mark = (Instant::now(), 0);
                    self.capture_clock = None;
                    self.dirty = true;
                }
                Ok(Feed::Status(s)) => self.say(Level::Info, &s),
                Ok(Feed::Result(level, s)) => self.say(level, &s),
                Ok(Feed::Lost(n)) => {
                    self.source.drops += n;
                    self.dirty = true;
                }
                Ok(Feed::BusError(e)) => {
                    if self.source.bus_error.as_ref() != Some(&e) {
                        self.log(Level::Error, &e);
                    }
                    self.source.bus_error = Some(e);
                    self.capture_clock = None;
                    self.dirty = true;
                }
                Ok(Feed::BusOk(note)) => {
                    // A recovery is news (the error it ends was shown); the first "capturing" is not.
                    if self.source.bus_error.take().is_some() {
                        self.say(Level::Info, &note);
                    }
                    self.dirty = true;
                }
                Ok(Feed::Done) | Err(TryRecvError::Disconnected) => {
                    self.trace.store.shrink();
                    self.source.done = true;
                    self.source.feed = None;
                    self.dirty = true;
                    return false;
                }
                Err(TryRecvError::Empty) => return false,
            }
            if start.elapsed() >= budget {
                return true;
            }
        }
    }

    /// Background work: filter scanning and the search. True when work is left.
    pub fn work(&mut self, budget: Duration) -> bool {
        if self.source.done {
            self.view.settle();
        }
        let before = self.view.len(&self.trace);
        let more = self.view.advance(&self.trace, budget);
        if self.view.len(&self.trace) != before {
            self.dirty = true;
        }
        self.search_work(budget) || more
    }

    /// Searches on; a jump that waited for its match goes there now.
    fn search_work(&mut self, budget: Duration) -> bool {
        let Some(s) = &mut self.search else { return false };
        if self.source.done {
            s.settle();
        }
        let before = (s.count(), s.progress(&self.trace));
        let more = s.advance(&self.trace, budget);
        if (s.count(), s.progress(&self.trace)) != before {
            self.dirty = true;
        }
        if let Some(found) = s.poll(&self.trace) {
            self.show_found(found);
        }
        more
    }

    /// The capture time now (ns on the frames' time base) for a live source (the newest
    /// frame's time plus the wall time since it was taken in, so delivery delays only make
    /// it late) or a running replay (times its speed); None for a loaded log, a paused or
    /// finished source, an interface in error (its silence says nothing about the nodes),
    /// or before the first frame.
    fn capture_now_ns(&self, now: Instant) -> Option<u64> {
        let speed = match self.source.kind {
            SourceKind::Live { .. } | SourceKind::Demo { .. } => 1.0,
            SourceKind::Replay { speed } if speed > 0.0 && !self.source.paused => speed,
            _ => return None,
        };
        if self.source.done || self.source.bus_error.is_some() {
            return None;
        }
        let (ts, at) = self.capture_clock?;
        Some(ts + (now.saturating_duration_since(at).as_secs_f64() * speed * 1e9) as u64)
    }

    /// Advances the node table to the capture time at wall time `now` (live and replay).
    fn liveness_tick(&mut self, now: Instant) {
        if let Some(t) = self.capture_now_ns(now) {
            self.trace.nodes.tick(t);
            if self.collect_node_events() {
                self.dirty = true;
            }
        }
    }

    /// Periodic update of the frame rate and of node liveness.
    pub fn tick(&mut self) {
        self.liveness_tick(Instant::now());
        let (t, n) = self.rate_mark;
        let dt = t.elapsed().as_secs_f64();
        if dt >= 0.5 {
            self.rate = self.trace.len().saturating_sub(n) as f64 / dt;
            self.rate_mark = (Instant::now(), self.trace.len());
            self.dirty = true;
        }
    }

    /// Moves new bus events from the node table to the message log (each with its capture
    /// time) and to [`App::node_events`] (the newest [`NODE_EVENTS`] kept); a lost node, a
    /// reboot or a controller state change also goes to the status line. True when there
    /// were any.
    fn collect_node_events(&mut self) -> bool {
        use crate::analysis::What;
        let events = self.trace.nodes.take_events();
        let t0 = self.start_ns();
        for e in &events {
            let at = e.t_ns.saturating_sub(t0) as f64 / 1e9;
            self.messages.push(
                SystemTime::now(),
                event_level(&e.what),
                &format!("[t={at:.3} s] {}", e.text()),
            );
        }
        let notable = events.iter().rev().find(|e| {
            matches!(
                e.what,
                What::HeartbeatLost { .. } | What::BootUp { rebooted: true, .. } | What::BusState { .. }
            )
        });
        if let Some(e) = notable {
            self.message = Some(e.text());
        }
        let any = !events.is_empty();
        self.node_events.extend(events);
        let excess = self.node_events.len().saturating_sub(NODE_EVENTS);
        self.node_events.drain(..excess);
        any
    }

    /// Logs `text` and shows its first line in the status line.
    pub fn say(&mut self, level: Level, text: &str) {
        self.log(level, text);
        let mut lines = text.lines();
        let first = lines.next().unwrap_or("");
        let more = lines.count();
        self.message = Some(if more == 0 {
            first.to_string()
        } else {
            format!("{first} (+{more} lines: `m` shows the message log)")
        });
        self.dirty = true;
    }

    /// Logs `text` without touching the status line.
    pub fn log(&mut self, level: Level, text: &str) {
        self.messages.push(SystemTime::now(), level, text);
        self.dirty = true;
    }

    /// Rows in the trace view.
    pub fn view_len(&self) -> usize {
        self.view.len(&self.trace)
    }

    /// Visible height of the main table.
    fn page(&self) -> usize {
        (self.layout.table.height as usize).max(1)
    }

    /// Handles a key press.
    pub fn key(&mut self, ev: KeyEvent) {
        self.dirty = true;
        if let Some(nodes) = self.quit_confirm.take() {
            match ev.code {
                KeyCode::Char('y') => self.quit = true,
                KeyCode::Char('s') => self.stop_all(&nodes, StopOptions::default()),
                _ => self.message = Some("not quitting".into()),
            }
            return;
        }
        if let Some(p) = self.confirm.take() {
            if ev.code == KeyCode::Char('y') {
                self.send(p);
            } else {
                self.message = Some("not sent".into());
            }
            return;
        }
        if self.prompt.is_some() {
            self.prompt_key(ev);
            self.preview();
            return;
        }
        let Some(k) = Key::from_event(&ev) else { return };
        self.pending.push(k);
        match self.keymap.lookup(&self.pending) {
            Lookup::Action(a) => {
                self.pending.clear();
                self.act(a);
            }
            Lookup::Pending => {}
            Lookup::None => {
                self.pending.clear();
                if let Lookup::Action(a) = self.keymap.lookup(&[k]) {
                    self.act(a);
                }
            }
        }
    }

    fn prompt_key(&mut self, ev: KeyEvent) {
        let Some(p) = self.prompt.as_mut() else { return };
        let ctrl = ev.modifiers.contains(KeyModifiers::CONTROL);
        match ev.code {
            KeyCode::Esc => self.prompt = None,
            KeyCode::Char('c') if ctrl => self.prompt = None,
            KeyCode::Enter => {
                let p = self
                    .prompt
                    .take()
                    .unwrap_or_else(|| Prompt::new(PromptKind::Palette, ""));
                self.submit(p);
            }
            KeyCode::Char('a') if ctrl => p.jump(false),
            KeyCode::Char('e') if ctrl => p.jump(true),
            KeyCode::Char('u') if ctrl => *p = Prompt::new(p.kind, ""),
            KeyCode::Char(c) => p.insert(c),
            KeyCode::Backspace => p.backspace(),
            KeyCode::Delete => p.delete(),
            KeyCode::Left => p.move_by(-1),
            KeyCode::Right => p.move_by(1),
            KeyCode::Home => p.jump(false),
            KeyCode::End => p.jump(true),
            KeyCode::Up => p.history(&self.history, true),
            KeyCode::Down => p.history(&self.history, false),
            KeyCode::Tab if p.kind == PromptKind::Palette => {
                let words: Vec<&str> = PALETTE_COMMANDS.iter().chain(COMMANDER_WORDS).copied().collect();
                let shown = p.complete(&words);
                if !shown.is_empty() {
                    self.message = Some(shown.join("  "));
                }
            }
            _ => {}
        }
    }

    /// While typing a commander line, shows the frames it would send.
    fn preview(&mut self) {
        let Some(p) = &self.prompt else { return };
        let first = p.text.split_whitespace().next().unwrap_or("");
        if p.kind == PromptKind::Palette && COMMANDER_WORDS.contains(&first) {
            self.message = Some(match palette::plan(&p.text, &self.bindings, |n| self.drive_state(n)) {
                Ok(pl) => format!("will send: {}", pl.preview),
                Err(e) => e,
            });
        }
    }

    fn drive_state(&self, node: u8) -> Option<crate::decode::cia402::DriveState> {
        self.trace.nodes.get(node).and_then(|n| n.drive)
    }

    /// Runs a commander line: asks for confirmation first when it needs one.
    fn commander(&mut self, line: &str) {
        match palette::plan(line, &self.bindings, |n| self.drive_state(n)) {
            Ok(p) => match &p.confirm {
                Some(why) => {
                    self.message = Some(format!("{why}: {} — press y to send, any other key cancels", p.preview));
                    self.confirm = Some(p);
                }
                None => self.send(p),
            },
            Err(e) => self.message = Some(e),
        }
    }

    fn send(&mut self, p: Planned) {
        let Some(req) = &self.source.requests else {
            self.say(
                Level::Error,
                "not sent: this source has no bus (use `cotui live IFACE` or `cotui demo`)",
            );
            return;
        };
        let _ = req.send(Request::Run {
            line: p.line.clone(),
            command: p.command,
        });
        self.say(Level::Info, &format!("{}: sending {}", p.line, p.preview));
    }

    /// True when the source cannot send (listen-only).
    fn listen_only(&self) -> bool {
        matches!(
            self.source.kind,
            SourceKind::Live { listen_only: true } | SourceKind::Demo { listen_only: true }
        )
    }

    /// The drives stop-all stops: those cotui commanded, those seen powered, and `extra`.
    pub fn stop_targets(&self, extra: &[u8]) -> BTreeSet<u8> {
        let mut t: BTreeSet<u8> = self.commanded.nodes().chain(extra.iter().copied()).collect();
        t.extend(
            self.trace
                .nodes
                .iter()
                .filter(|(_, n)| n.drive.is_some_and(is_powered))
                .map(|(id, _)| *id),
        );
        t
    }

    /// The emergency stop: the live task cancels everything it runs for us, then stops every
    /// target (see [`App::stop_targets`]) and reports per node whether it is confirmed.
    fn stop_all(&mut self, extra: &[u8], options: StopOptions) {
        if self.listen_only() {
            self.say(
                Level::Error,
                "stop all: listen-only — NOTHING can be sent, no drive was stopped; stop them another way",
            );
            return;
        }
        let Some(req) = &self.source.requests else {
            self.say(Level::Warn, "stop all: this source has no bus (a log), nothing to stop");
            return;
        };
        let nodes = self.stop_targets(extra);
        let _ = req.send(Request::StopAll {
            nodes: nodes.clone(),
            options,
        });
        let list = if nodes.is_empty() {
            "every drive cotui commanded".to_string()
        } else {
            format!(
                "nodes {}",
                nodes.iter().map(u8::to_string).collect::<Vec<_>>().join(", ")
            )
        };
        self.say(
            Level::Warn,
            &format!("stop all: cancelling running commands; quick stop, then disable voltage on {list}"),
        );
    }

    /// Quits, unless a drive cotui commanded is still powered: then asks first.
    fn request_quit(&mut self) {
        let powered: Vec<u8> = self
            .commanded
            .nodes()
            .filter(|n| self.trace.nodes.get(*n).and_then(|i| i.drive).is_some_and(is_powered))
            .collect();
        if powered.is_empty() || self.source.requests.is_none() {
            self.quit = true;
            return;
        }
        let stop = self.keymap.key_for(super::keymap::Action::StopAll).unwrap_or_default();
        self.message = Some(format!(
            "drive(s) {} that cotui commanded are still powered: y quits anyway, s stops them first ({stop}              any time), any other key stays",
            powered.iter().map(u8::to_string).collect::<Vec<_>>().join(", ")
        ));
        self.quit_confirm = Some(powered);
    }

    fn submit(&mut self, p: Prompt) {
        let text = p.text.trim().to_string();
        if !text.is_empty() && self.history.last() != Some(&text) {
            self.history.push(text.clone());
        }
        let applied = match p.kind {
            PromptKind::Filter => self.apply_filter(&p.text),
            PromptKind::Search => self.apply_search(&p.text),
            PromptKind::Palette => {
                self.run_command(&text);
                Ok(())
            }
        };
        // A bad expression keeps the prompt open with the text, the cursor where it is wrong.
        if let Err(e) = applied {
            let mut again = Prompt::new(p.kind, &p.text);
            again.cursor = (e.column - 1).min(again.cursor);
            self.prompt = Some(again);
        }
    }

    /// Applies a filter text; a parse error goes to the status bar and keeps the old filter.
    pub fn set_filter(&mut self, text: &str) {
        let _ = self.apply_filter(text);
    }

    /// Parses a filter or search with the object names of the dictionaries in use.
    fn parse_expr(&mut self, what: &str, text: &str) -> Result<Filter, FilterError> {
        Filter::parse_with(text, self.trace.decoder()).inspect_err(|e| self.message = Some(format!("{what}: {e}")))
    }

    fn apply_filter(&mut self, text: &str) -> Result<(), FilterError> {
        let f = self.parse_expr("filter", text)?;
        let pos = self.selected_position();
        self.view = View::new(f);
        self.view.advance(&self.trace, Duration::from_millis(30));
        self.trace_list.selected = pos.map(|p| self.view.row_of(p)).unwrap_or(0);
        self.trace_list.clamp(self.view_len(), self.page());
        self.message = None;
        self.rows = RowCache::default();
        self.restart_search();
        Ok(())
    }

    fn set_search(&mut self, text: &str) {
        let _ = self.apply_search(text);
    }

    /// Starts a search and jumps to its first match after the selection (when found).
    fn apply_search(&mut self, text: &str) -> Result<(), FilterError> {
        let f = self.parse_expr("search", text)?;
        if f.is_empty() {
            self.search = None;
            return Ok(());
        }
        let mut s = Search::new(f, &self.view.filter);
        s.advance(&self.trace, Duration::from_millis(30));
        self.search = Some(s);
        self.jump_match(true);
        Ok(())
    }

    /// The search in force starts over (the filter it searches within changed).
    fn restart_search(&mut self) {
        if let Some(s) = self.search.take() {
            self.search = Some(Search::new(s.filter, &self.view.filter));
        }
    }

    /// Runs a palette command; the result goes to the status bar.
    pub fn run_command(&mut self, line: &str) {
        let (cmd, rest) = line.split_once(' ').unwrap_or((line, ""));
        let rest = rest.trim();
        let result: Result<String, String> = match cmd {
            "" => Ok(String::new()),
            "filter" => {
                self.set_filter(rest);
                return;
            }
            "search" => {
                self.set_search(rest);
                return;
            }
            "goto" => rest
                .parse::<usize>()
                .map_err(|_| format!("goto: `{rest}` is not a frame number"))
                .map(|n| {
                    self.select_position(n.saturating_sub(1));
                    format!("frame {n}")
                }),
            "time" => rest
                .parse::<f64>()
                .map_err(|_| format!("time: `{rest}` is not seconds"))
                .map(|s| {
                    let t0 = self.start_ns();
                    let pos = self.trace.store.position_at(t0 + (s.max(0.0) * 1e9) as u64);
                    self.select_position(pos);
                    format!("t = {s} s")
                }),
            "speed" => match rest.parse::<f64>() {
                Ok(x) if x >= 0.0 => self.set_speed(x),
                _ => Err(format!("speed: `{rest}` is not a factor (0 = as fast as possible)")),
            },
            "pause" => self.set_paused(true),
            "resume" => self.set_paused(false),
            "plot" => self.plot_command(rest),
            "help" => {
                self.help = true;
                Ok(String::new())
            }
            "export" => self.export_command(rest),
            "messages" => {
                self.messages_shown = true;
                self.messages_back = 0;
                Ok(String::new())
            }
            "quit" => {
                self.request_quit();
                return;
            }
            "stop" => {
                match crate::command::parse_command(line) {
                    Ok(Command::Stop { nodes, options, .. }) => self.stop_all(&nodes, options),
                    Ok(_) => {}
                    Err(e) => self.say(Level::Error, &format!("stop: {e}")),
                }
                return;
            }
            w if COMMANDER_WORDS.contains(&w) => {
                self.commander(line);
                return;
            }
            other => Err(format!(
                "unknown command `{other}` (commands: {} {})",
                PALETTE_COMMANDS.join(" "),
                COMMANDER_WORDS.join(" ")
            )),
        };
        self.message = match result {
            Ok(s) if s.is_empty() => None,
            Ok(s) => Some(s),
            Err(e) => {
                self.log(Level::Error, &format!("{line}: {e}"));
                Some(e)
            }
        };
    }

    /// `export FILE [--format candump|jsonl|pcapng] [--force]`: the rows the view shows.
    fn export_command(&mut self, rest: &str) -> Result<String, String> {
        use super::export::{ExportFormat, export};
        let (mut file, mut format, mut force) = (None, None, false);
        let mut words = rest.split_whitespace();
        while let Some(w) = words.next() {
            match w {
                "--force" => force = true,
                "--format" => {
                    let f = words.next().ok_or("export: --format needs candump, jsonl or pcapng")?;
                    format = Some(ExportFormat::parse(f).map_err(|e| format!("export: {e}"))?);
                }
                w if w.starts_with("--") => return Err(format!("export: unknown option `{w}`")),
                w if file.is_none() => file = Some(w.to_string()),
                w => return Err(format!("export: one FILE only (`{w}` is extra)")),
            }
        }
        let file = file.ok_or("export: usage `export FILE [--format candump|jsonl|pcapng] [--force]`")?;
        let path = std::path::Path::new(&file);
        let format = format.unwrap_or_else(|| ExportFormat::of_path(path));
        let scanned = self.view.progress(&self.trace);
        let n = export(&self.trace, &self.view, path, format, force).map_err(|e| {
            let hint = if e.kind() == std::io::ErrorKind::AlreadyExists {
                " (add --force to overwrite)"
            } else {
                ""
            };
            format!("export: {file}: {e}{hint}")
        })?;
        let text = format!(
            "exported {n} frames to {file} ({format:?}){}",
            if scanned < 100 {
                format!("; the filter had scanned {scanned}% of the trace")
            } else {
                String::new()
            }
        );
        self.log(Level::Info, &text);
        Ok(text)
    }

    fn plot_command(&mut self, rest: &str) -> Result<String, String> {
        let mut it = rest.split_whitespace();
        let (Some(node), Some(obj)) = (it.next(), it.next()) else {
            return Err("plot: usage `plot NODE INDEX[:SUB]`, e.g. `plot 1 6064:00`".into());
        };
        let node: u8 = node.parse().map_err(|_| format!("plot: `{node}` is not a node-ID"))?;
        let (i, s) = obj.split_once(':').unwrap_or((obj, "0"));
        let index =
            u16::from_str_radix(i.trim_start_matches("0x"), 16).map_err(|_| format!("plot: bad index `{i}`"))?;
        let sub = u8::from_str_radix(s, 16).map_err(|_| format!("plot: bad sub-index `{s}`"))?;
        let keys = self.trace.series.keys();
        match keys.iter().position(|k| *k == (node, index, sub)) {
            Some(at) => {
                self.series_sel = at;
                self.pane = Pane::Plot;
                Ok(String::new())
            }
            None => Err(format!(
                "plot: no numeric values of node {node} 0x{index:04X}:{sub:02X} seen"
            )),
        }
    }

    fn set_speed(&mut self, x: f64) -> Result<String, String> {
        match (&mut self.source.kind, &self.source.control) {
            (SourceKind::Replay { speed }, Some(c)) => {
                *speed = x;
                let _ = c.send(Control::Speed(x));
                Ok(if x == 0.0 {
                    "speed: as fast as possible".into()
                } else {
                    format!("speed ×{x}")
                })
            }
            _ => Err("speed: only a replay has a speed".into()),
        }
    }

    fn set_paused(&mut self, p: bool) -> Result<String, String> {
        self.source.paused = p;
        // The replay clock restarts from the next frame.
        self.capture_clock = None;
        if let Some(c) = &self.source.control {
            let _ = c.send(Control::Pause(p));
        }
        if p {
            self.follow = false;
        }
        Ok(String::new())
    }

    /// The timestamp of the first frame.
    pub fn start_ns(&self) -> u64 {
        if self.trace.is_empty() {
            0
        } else {
            self.trace.store.packed(0).ts_ns
        }
    }

    /// The trace position of the selected row.
    pub fn selected_position(&self) -> Option<usize> {
        let n = self.view_len();
        (n > 0).then(|| self.view.position(self.trace_list.selected.min(n - 1)))
    }

    fn select_position(&mut self, pos: usize) {
        self.follow = false;
        self.pane = Pane::Trace;
        self.trace_list.selected = self.view.row_of(pos);
        self.trace_list.clamp(self.view_len(), self.page());
    }

    /// Jumps to the next (or previous) match of the search; when the search has not got
    /// there yet, the jump waits for it and the selection stays.
    fn jump_match(&mut self, forward: bool) {
        let from = self.selected_position();
        let Some(s) = &mut self.search else {
            self.message = Some("no search: press the search key first".into());
            return;
        };
        let found = s.find(&self.trace, from, forward);
        if found == Found::Searching {
            s.ask(from, forward);
            self.message = Some(format!(
                "searching `{}`: {}% searched, the selection stays until a match is found",
                s.filter.source,
                s.progress(&self.trace)
            ));
            return;
        }
        self.show_found(found);
    }

    /// Selects a match the search found and says which one it is.
    fn show_found(&mut self, found: Found) {
        let Some(s) = &self.search else { return };
        self.dirty = true;
        match found {
            Found::At { pos, wrapped } => {
                let of = if s.complete(&self.trace) {
                    format!("{} of {}", s.rank(pos), s.count())
                } else {
                    format!("{} of {} so far", s.rank(pos), s.count())
                };
                let wrap = if wrapped { " (wrapped around)" } else { "" };
                self.message = Some(format!("match {of} at frame {}{wrap}", pos + 1));
                self.select_position(pos);
            }
            Found::Nothing => self.message = Some(format!("no match for `{}`", s.filter.source)),
            Found::Searching => {}
        }
    }

    fn list(&mut self) -> Option<(&mut ListState, usize)> {
        let n = match self.pane {
            Pane::Trace => self.view_len(),
            Pane::Nodes => self.trace.nodes.len(),
            Pane::Sdo => match self.sdo_expanded {
                Some(t) => self.trace.transactions.get(t).map(|t| t.frames.len()).unwrap_or(0),
                None => self.trace.transactions.len(),
            },
            Pane::Stats => self.trace.stats.len(),
            Pane::Plot => return None,
        };
        let l = match self.pane {
            Pane::Trace => &mut self.trace_list,
            Pane::Nodes => &mut self.nodes_list,
            Pane::Sdo => &mut self.sdo_list,
            _ => &mut self.stats_list,
        };
        Some((l, n))
    }

    fn scroll(&mut self, delta: isize) {
        let page = self.page();
        if self.pane == Pane::Trace {
            self.follow = false;
        }
        if let Some((l, n)) = self.list() {
            l.selected = (l.selected as isize + delta).clamp(0, n.saturating_sub(1) as isize) as usize;
            l.clamp(n, page);
        }
    }

    /// Does what an action says.
    pub fn act(&mut self, a: Action) {
        self.dirty = true;
        let page = self.page() as isize;
        if self.messages_shown && self.messages_key(a) {
            return;
        }
        match a {
            Action::Quit => self.request_quit(),
            Action::Help => self.help = !self.help,
            Action::Messages => {
                self.messages_shown = !self.messages_shown;
                self.messages_back = 0;
            }
            Action::Down => self.scroll(1),
            Action::Up => self.scroll(-1),
            Action::PageDown => self.scroll(page),
            Action::PageUp => self.scroll(-page),
            Action::Top => self.scroll(isize::MIN / 2),
            Action::Bottom => {
                self.scroll(isize::MAX / 2);
                if self.pane == Pane::Trace {
                    self.follow = true;
                }
            }
            Action::Follow => {
                self.follow = !self.follow;
                self.pane = Pane::Trace;
            }
            Action::Pause => {
                let p = !self.source.paused;
                let _ = self.set_paused(p);
                if !p {
                    self.follow = true;
                }
            }
            Action::Expand => match self.pane {
                Pane::Sdo if self.sdo_expanded.is_none() && !self.trace.transactions.is_empty() => {
                    self.sdo_expanded = Some(self.sdo_list.selected);
                    self.sdo_list = ListState::default();
                }
                Pane::Sdo => {
                    if let Some(t) = self.sdo_expanded.and_then(|t| self.trace.transactions.get(t))
                        && let Some(seq) = t.frames.get(self.sdo_list.selected)
                    {
                        let pos = seq.saturating_sub(1) as usize;
                        self.view = View::new(Filter::default());
                        self.select_position(pos);
                    }
                }
                Pane::Nodes => {
                    let node = self.trace.nodes.iter().nth(self.nodes_list.selected).map(|(n, _)| *n);
                    if let Some(n) = node {
                        self.set_filter(&format!("node {n}"));
                        self.pane = Pane::Trace;
                    }
                }
                Pane::Stats => {
                    let id = self.trace.stats.iter().nth(self.stats_list.selected).map(|(k, _)| k.1);
                    if let Some(id) = id {
                        self.set_filter(&format!("id {id:X}"));
                        self.pane = Pane::Trace;
                    }
                }
                _ => {}
            },
            Action::Back => {
                if self.help {
                    self.help = false;
                } else if let Some(t) = self.sdo_expanded.take() {
                    self.sdo_list = ListState {
                        selected: t,
                        offset: t.saturating_sub(3),
                    };
                } else {
                    self.search = None;
                    self.message = None;
                }
            }
            Action::NextPane | Action::PrevPane => {
                let i = Pane::ALL.iter().position(|p| *p == self.pane).unwrap_or(0);
                let d = if a == Action::NextPane { 1 } else { Pane::ALL.len() - 1 };
                self.pane = Pane::ALL[(i + d) % Pane::ALL.len()];
            }
            Action::PaneTrace => self.pane = Pane::Trace,
            Action::PaneNodes => self.pane = Pane::Nodes,
            Action::PaneSdo => self.pane = Pane::Sdo,
            Action::PaneStats => self.pane = Pane::Stats,
            Action::PanePlot => self.pane = Pane::Plot,
            Action::Filter => self.prompt = Some(Prompt::new(PromptKind::Filter, &self.view.filter.source)),
            Action::Search => {
                let text = self
                    .search
                    .as_ref()
                    .map(|s| s.filter.source.clone())
                    .unwrap_or_default();
                self.prompt = Some(Prompt::new(PromptKind::Search, &text));
            }
            Action::NextMatch => self.jump_match(true),
            Action::PrevMatch => self.jump_match(false),
            Action::ClearFilter => self.set_filter(""),
            Action::Palette => self.prompt = Some(Prompt::new(PromptKind::Palette, "")),
            Action::StopAll => self.stop_all(&[], StopOptions::default()),
            Action::SpeedUp | Action::SpeedDown => {
                if let SourceKind::Replay { speed } = self.source.kind {
                    let base = if speed <= 0.0 { 1.0 } else { speed };
                    let x = if a == Action::SpeedUp { base * 2.0 } else { base / 2.0 };
                    self.message = Some(self.set_speed(x).unwrap_or_else(|e| e));
                }
            }
            Action::Step => match &self.source.control {
                Some(c) if self.source.paused => {
                    let _ = c.send(Control::Step);
                    self.follow = true;
                }
                _ => self.message = Some("step: pause a replay first".into()),
            },
            Action::SeekForward | Action::SeekBack => match &self.source.control {
                Some(c) => {
                    let d: i64 = if a == Action::SeekForward {
                        10_000_000_000
                    } else {
                        -10_000_000_000
                    };
                    let _ = c.send(Control::Seek(d));
                    self.follow = true;
                }
                None => self.message = Some("seek: only a replay can seek".into()),
            },
            Action::NextSeries | Action::PrevSeries => {
                let n = self.trace.series.keys().len().max(1);
                self.series_sel = if a == Action::NextSeries {
                    (self.series_sel + 1) % n
                } else {
                    (self.series_sel + n - 1) % n
                };
                self.pane = Pane::Plot;
            }
        }
    }

    /// Scrolls or closes the message log popup; false when `a` is not for it.
    fn messages_key(&mut self, a: Action) -> bool {
        let page = self.layout.messages.max(1);
        let most = self.messages.lines().len();
        let back = &mut self.messages_back;
        match a {
            Action::Up => *back += 1,
            Action::Down => *back = back.saturating_sub(1),
            Action::PageUp => *back += page,
            Action::PageDown => *back = back.saturating_sub(page),
            Action::Top => *back = most,
            Action::Bottom => *back = 0,
            Action::Back | Action::Messages => self.messages_shown = false,
            _ => return false,
        }
        self.messages_back = self.messages_back.min(most.saturating_sub(self.layout.messages));
        true
    }

    /// Handles a mouse event: wheel scrolls, left click selects a row.
    pub fn mouse(&mut self, ev: MouseEvent) {
        self.dirty = true;
        match ev.kind {
            MouseEventKind::ScrollDown => self.scroll(3),
            MouseEventKind::ScrollUp => self.scroll(-3),
            MouseEventKind::Down(MouseButton::Left) => {
                let t = self.layout.table;
                if ev.column >= t.x && ev.column < t.x + t.width && ev.row >= t.y && ev.row < t.y + t.height {
                    let page = self.page();
                    let r = (ev.row - t.y) as usize;
                    if self.pane == Pane::Trace {
                        self.follow = false;
                    }
                    if let Some((l, n)) = self.list() {
                        let want = l.offset + r;
                        if want < n {
                            l.selected = want;
                            l.clamp(n, page);
                        }
                    }
                }
            }
            _ => {}
        }
    }

    /// Before drawing: pins the selection to the newest row in follow mode and decodes the
    /// visible window (`height` rows), the tail strip and the selected frame.
    pub fn prepare(&mut self, height: usize, tail: &[usize]) {
        let n = self.view_len();
        if self.follow {
            self.trace_list.selected = n.saturating_sub(1);
        }
        self.trace_list.clamp(n, height);
        let mut positions: Vec<usize> = (self.trace_list.offset..(self.trace_list.offset + height).min(n))
            .map(|r| self.view.position(r))
            .collect();
        positions.extend_from_slice(tail);
        positions.sort_unstable();
        positions.dedup();
        self.rows.fill(&self.trace, &positions);
        let sel = self.selected_position();
        if sel != self.detail.as_ref().map(|(p, _)| *p) {
            self.detail = sel.and_then(|p| self.trace.decode_positions(&[p]).pop().map(|d| (p, d)));
        }
    }

    /// The decoded row for a trace position, when it is in the visible window.
    pub fn row(&self, pos: usize) -> Option<&Row> {
        self.rows.get(pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::panes::testutil::{app, frames};
    use crossterm::event::KeyEvent;

    fn key(c: char) -> KeyEvent {
        KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)
    }

    #[test]
    fn a_live_node_that_falls_silent_is_lost_by_the_capture_clock() {
        let (ftx, frx) = std::sync::mpsc::channel();
        let (rtx, _rrx) = tokio::sync::mpsc::unbounded_channel();
        let mut a = app();
        a.source = SourceInfo::live("vcan0", SourceKind::Live { listen_only: true }, frx, rtx);
        let t0 = a.trace.nodes.now_ns();
        a.trace.nodes.take_events();
        let batch: Vec<crate::frame::Frame> = (1..=5u64)
            .map(|i| {
                let mut f = crate::frame::Frame::classic(0x705, &[0x05]);
                f.ts_ns = t0 + i * 100_000_000;
                f
            })
            .collect();
        ftx.send(Feed::Frames(batch)).unwrap();
        a.ingest(Duration::from_millis(100));
        let taken = Instant::now();
        // Node 2 (heartbeats every 14 ms in the capture) was found lost by these frames.
        assert!(a.trace.nodes.liveness(2).unwrap().is_lost());
        assert!(!a.trace.nodes.liveness(5).unwrap().is_lost());
        // No frame comes for a second of wall time: node 5 (every 100 ms) is lost too,
        // dated 150 ms after its last heartbeat.
        a.liveness_tick(taken + Duration::from_secs(1));
        let l = a.trace.nodes.liveness(5).unwrap();
        assert_eq!(l.lost_at_ns, Some(t0 + 650_000_000));
        let msg = a.message.clone().unwrap_or_default();
        assert!(
            msg.starts_with("node 5 heartbeat lost: no heartbeat for 150.0 ms"),
            "{msg}"
        );
        let names: Vec<(Option<u8>, &str)> = a.node_events.iter().map(|e| (e.node, e.what.name())).collect();
        assert_eq!(
            names,
            [
                (Some(2), "heartbeat_lost"),
                (Some(5), "state"),
                (Some(1), "heartbeat_lost"),
                (Some(5), "heartbeat_lost")
            ]
        );
        // An interface in error, or a paused replay: the clock stands still.
        a.source.bus_error = Some("vcan0 is down".into());
        assert_eq!(a.capture_now_ns(taken + Duration::from_secs(9)), None);
        a.source.bus_error = None;
        a.source.kind = SourceKind::Replay { speed: 1.0 };
        a.source.paused = true;
        assert_eq!(a.capture_now_ns(taken + Duration::from_secs(9)), None);
    }

    #[test]
    fn replay_keys_send_pause_step_speed_and_seek() {
        let (_ftx, frx) = std::sync::mpsc::channel();
        let (ctx, crx) = std::sync::mpsc::channel();
        let mut a = app();
        a.source = SourceInfo::new("r.log", SourceKind::Replay { speed: 1.0 }, frx, Some(ctx));
        a.act(Action::Step);
        assert_eq!(a.message.as_deref(), Some("step: pause a replay first"));
        for k in [' ', '.', '+', '+', '-', ' '] {
            a.key(key(k));
        }
        a.act(Action::SeekBack);
        let sent: Vec<Control> = crx.try_iter().collect();
        assert_eq!(
            sent,
            [
                Control::Pause(true),
                Control::Step,
                Control::Speed(2.0),
                Control::Speed(4.0),
                Control::Speed(2.0),
                Control::Pause(false),
                Control::Seek(-10_000_000_000),
            ]
        );
        assert_eq!(a.source.kind, SourceKind::Replay { speed: 2.0 });
    }

    #[test]
    fn search_jumps_between_matches_and_goto_selects() {
        let mut a = app();
        a.layout.table = Rect::new(0, 0, 100, 10);
        a.run_command("goto 1");
        a.run_command("search emcy");
        assert_eq!(a.selected_position(), Some(frames().len() - 1));
        assert_eq!(a.message.as_deref(), Some("match 1 of 1 at frame 44"));
        // No later match: the search wraps around to the first one.
        a.run_command("search \"boot-up node 2\"");
        assert_eq!(a.message.as_deref(), Some("match 1 of 1 at frame 2 (wrapped around)"));
        assert_eq!(a.selected_position(), Some(1));
        a.act(Action::PrevMatch);
        assert_eq!(a.selected_position(), Some(1));
        a.run_command("search \"no such label\"");
        assert_eq!(a.message.as_deref(), Some("no match for `\"no such label\"`"));
        assert_eq!(a.selected_position(), Some(1), "no match: the selection stays");
        a.run_command("bogus");
        assert!(
            a.message
                .as_deref()
                .unwrap_or("")
                .starts_with("unknown command `bogus`")
        );
    }

    #[test]
    fn palette_commander_lines_need_a_bus_and_confirm_broadcasts() {
        let mut a = app();
        a.key(key(':'));
        for c in "nmt reset-node 0".chars() {
            a.key(key(c));
        }
        assert_eq!(a.message.as_deref(), Some("will send: 000#8100"));
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert!(a.confirm.is_some());
        a.key(key('y'));
        assert_eq!(
            a.message.as_deref(),
            Some("not sent: this source has no bus (use `cotui live IFACE` or `cotui demo`)")
        );
        assert_eq!(a.history, ["nmt reset-node 0"]);
    }

    /// `app()` fed by a live source whose requests the test reads.
    fn live_app(listen_only: bool) -> (App, tokio::sync::mpsc::UnboundedReceiver<Request>) {
        let (_ftx, frx) = std::sync::mpsc::channel();
        let (rtx, rrx) = tokio::sync::mpsc::unbounded_channel();
        let mut a = app();
        a.source = SourceInfo::live("vcan0", SourceKind::Live { listen_only }, frx, rtx);
        (a, rrx)
    }

    fn ctrl(c: char) -> KeyEvent {
        KeyEvent::new(KeyCode::Char(c), KeyModifiers::CONTROL)
    }

    #[test]
    fn stop_all_targets_drives_seen_powered_and_commanded_and_logs_it() {
        let (mut a, mut req) = live_app(false);
        // Node 1 shows Operation enabled in its TPDO; node 5 got a controlword from us.
        let mut cw = crate::frame::Frame::classic(0x605, &[0x2B, 0x40, 0x60, 0, 0x0F, 0, 0, 0]);
        cw.flags.set(crate::frame::Flags::TX, true);
        a.commanded.observe(&cw);
        a.key(ctrl('s'));
        match req.try_recv() {
            Ok(Request::StopAll { nodes, options }) => {
                assert_eq!(nodes.into_iter().collect::<Vec<_>>(), [1, 5]);
                assert_eq!(options, StopOptions::default());
            }
            other => panic!("expected a stop request, got {other:?}"),
        }
        assert_eq!(
            a.message.as_deref(),
            Some("stop all: cancelling running commands; quick stop, then disable voltage on nodes 1, 5")
        );
        assert_eq!(a.messages.iter().last().map(|e| e.level), Some(Level::Warn));
        // The palette's `stop 7` adds node 7.
        a.run_command("stop 7 --ramp 300");
        match req.try_recv() {
            Ok(Request::StopAll { nodes, options }) => {
                assert_eq!(nodes.into_iter().collect::<Vec<_>>(), [1, 5, 7]);
                assert_eq!(options.ramp_ms, 300);
            }
            other => panic!("expected a stop request, got {other:?}"),
        }
    }

    #[test]
    fn stop_all_in_listen_only_says_nothing_can_be_sent() {
        let (mut a, mut req) = live_app(true);
        a.act(Action::StopAll);
        assert!(req.try_recv().is_err(), "no request in listen-only");
        assert!(
            a.message
                .as_deref()
                .unwrap_or("")
                .contains("listen-only — NOTHING can be sent")
        );
        assert_eq!(a.messages.iter().last().map(|e| e.level), Some(Level::Error));
    }

    #[test]
    fn quitting_with_a_commanded_drive_powered_asks_first() {
        let (mut a, _req) = live_app(false);
        a.act(Action::Quit);
        assert!(a.quit, "nothing commanded: quits at once");
        let (mut a, mut req) = live_app(false);
        let mut cw = crate::frame::Frame::classic(0x601, &[0x2B, 0x40, 0x60, 0, 0x0F, 0, 0, 0]);
        cw.flags.set(crate::frame::Flags::TX, true);
        a.commanded.observe(&cw);
        a.act(Action::Quit);
        assert!(!a.quit);
        assert!(
            a.message
                .as_deref()
                .unwrap_or("")
                .starts_with("drive(s) 1 that cotui commanded are still powered")
        );
        a.key(key('n'));
        assert!(!a.quit && a.quit_confirm.is_none());
        assert!(req.try_recv().is_err(), "nothing sent by asking");
        a.run_command("quit");
        a.key(key('s'));
        assert!(!a.quit);
        assert!(matches!(req.try_recv(), Ok(Request::StopAll { .. })));
        a.act(Action::Quit);
        a.key(key('y'));
        assert!(a.quit);
    }

    #[test]
    fn results_go_to_the_message_log_whole_and_the_status_line_shows_the_first_line() {
        let (ftx, frx) = std::sync::mpsc::channel();
        let mut a = app();
        a.source = SourceInfo::new("demo", SourceKind::Demo { listen_only: false }, frx, None);
        ftx.send(Feed::Result(
            Level::Info,
            "scan: 2 nodes\nnode 2 aimotor\nnode 3 syntron-ds".into(),
        ))
        .unwrap();
        ftx.send(Feed::BusError(
            "vcan0: interface went down; fix: sudo ip link set vcan0 up".into(),
        ))
        .unwrap();
        ftx.send(Feed::BusOk("vcan0: capturing again after 2.0 s without capture".into()))
            .unwrap();
        a.ingest(Duration::from_millis(50));
        // The recovery is the latest news on the status line; the log has all three.
        assert_eq!(
            a.message.as_deref(),
            Some("vcan0: capturing again after 2.0 s without capture")
        );
        let lines: Vec<String> = a.messages.lines().into_iter().map(|(_, l)| l).collect();
        assert_eq!(lines.len(), 5, "{lines:?}");
        assert!(lines[2].ends_with("  node 3 syntron-ds"));
        assert!(lines[3].ends_with("  vcan0: interface went down; fix: sudo ip link set vcan0 up"));
        assert!(lines[4].ends_with("  vcan0: capturing again after 2.0 s without capture"));
        a.key(key('m'));
        assert!(a.messages_shown);
        let s = crate::tui::panes::testutil::screen(&mut a, 120, 20);
        assert!(s.contains("Messages (3)"), "{s}");
        assert!(s.contains("node 3 syntron-ds"), "{s}");
        a.act(Action::Up);
        assert_eq!(a.messages_back, 0, "all lines fit: nothing to scroll");
        a.act(Action::Back);
        assert!(!a.messages_shown);
    }

    #[test]
    fn sdo_pane_expands_and_enter_on_a_frame_jumps_to_it_in_the_trace() {
        let mut a = app();
        a.layout.table = Rect::new(0, 0, 100, 10);
        a.act(Action::PaneSdo);
        for _ in 0..4 {
            a.act(Action::Down);
        }
        a.act(Action::Expand);
        assert_eq!(a.sdo_expanded, Some(4));
        a.act(Action::Down);
        a.act(Action::Expand);
        assert_eq!(a.pane, Pane::Trace);
        assert_eq!(a.selected_position(), Some(12));
    }
}
