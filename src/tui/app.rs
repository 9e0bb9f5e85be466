//! The application: the state the panes share (the trace, the source, the focus, the
//! messages, the key map) and the routing of keys and actions to the focused pane
//! ([`crate::tui::panes`]) and the popups. Pure state transitions: no terminal here, so
//! tests drive it directly.

use super::keymap::{Action, Key, Keymap, Lookup};
use super::live::{Request, Requests};
use super::messages::{Level, Messages};
use super::palette::{self, Planned, commander_words};
use super::panes::detail::DetailPane;
use super::panes::help::HelpPopup;
use super::panes::messages::MessagesPopup;
use super::panes::{Component, Ctx, Outcome, Pane, Panes, Selected};
use super::prompt::{Edit, PromptBar, PromptKind};
use super::source::{Control, Feed};
use crate::analysis::filter::{Filter, FilterError};
use crate::analysis::search::{Found, Search};
use crate::analysis::trace::Trace;
use crate::command::Command;
use crate::command::stop::{Commanded, StopOptions, is_powered};
use crate::od::bind::Bindings;
use crossterm::event::{KeyCode, KeyEvent, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use std::collections::BTreeSet;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::time::SystemTime;
use std::time::{Duration, Instant};

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
    /// A replay starts over at its end.
    pub looping: bool,
    /// Where a replay is, and the size of its log once measured.
    pub replay: (Option<super::source::Position>, Option<super::source::Extent>),
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

/// Where the last draw put things (for mouse clicks and page sizes).
#[derive(Clone, Copy, Debug, Default)]
pub struct Layout {
    /// Rows of the main table, without header.
    pub table: Rect,
    /// The side column (compact nodes, Detail) was shown: the terminal is wide enough.
    pub side: bool,
}

/// The whole application state.
pub struct App {
    /// Frames and what is derived from them.
    pub trace: Trace,
    /// Key bindings.
    pub keymap: Keymap,
    /// The pane in the main area (the one keys go to).
    pub focus: Pane,
    /// The main-area panes (each owns its selection and what it shows).
    pub panes: Panes,
    /// The Detail pane (beside the main pane, or toggled below it on a narrow terminal).
    pub detail: DetailPane,
    /// The help popup.
    pub help: HelpPopup,
    /// The prompt line (filter, search, palette) and its history.
    pub prompt: PromptBar,
    /// The search in force (`n`/`N`), running over the trace pane's view in the background.
    pub search: Option<Search>,
    /// A message for the status bar (result of the last command).
    pub message: Option<String>,
    /// Every result, event and error of the session.
    pub messages: Messages,
    /// The message log popup.
    pub log_popup: MessagesPopup,
    /// The capture source.
    pub source: SourceInfo,
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
    /// `record start FILE`: the frames received go to this candump log.
    pub recording: Option<super::record::Recorder>,
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

/// What the palette completes from: the nodes heard (the node table) and the dictionaries
/// the commander uses (the bindings).
struct Heard<'a>(&'a App);

impl crate::command::complete::Known for Heard<'_> {
    fn nodes(&self) -> Vec<u8> {
        let mut ids: Vec<u8> = self.0.trace.nodes.iter().map(|(id, _)| id.node).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
    fn dictionary(&self, node: u8) -> &crate::od::Dictionary {
        self.0.bindings.dictionary(node)
    }
}

/// Names the palette completes.
pub const PALETTE_COMMANDS: &[&str] = &[
    "filter", "search", "goto", "time", "speed", "pause", "resume", "rewind", "loop", "plot", "export", "help",
    "messages", "quit", "jobs", "sim",
];

/// Why a built-in palette command (`goto`, `time`, `speed`, `plot`, `export`, ...) failed;
/// the text is what the status bar shows.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// `goto` without a frame number.
    #[error("goto: `{0}` is not a frame number")]
    NotAFrame(String),
    /// `time` without seconds.
    #[error("time: `{0}` is not seconds")]
    NotSeconds(String),
    /// `speed` without a factor.
    #[error("speed: `{0}` is not a factor from 0.01 to 1000 (0 = as fast as possible)")]
    NotAFactor(String),
    /// A replay command on a source that is not a replay.
    #[error("{0}: only a replay can do that")]
    NoReplay(&'static str),
    /// `speed` on a source that is not a replay.
    #[error("speed: only a replay has a speed")]
    NoSpeed,
    /// `plot` without a node and an object.
    #[error("plot: usage `plot NODE INDEX[:SUB]`, e.g. `plot 1 6064:00`")]
    PlotUsage,
    /// `plot` with a bad node-ID.
    #[error("plot: `{0}` is not a node-ID")]
    NotANode(String),
    /// `plot` with a bad index.
    #[error("plot: bad index `{0}`")]
    BadIndex(String),
    /// `plot` with a bad sub-index.
    #[error("plot: bad sub-index `{0}`")]
    BadSub(String),
    /// `plot` of an object with no numeric value seen.
    #[error("plot: no numeric values of node {node} 0x{index:04X}:{sub:02X} seen")]
    NoSeries { node: u8, index: u16, sub: u8 },
    /// `export --format` without a format.
    #[error("export: --format needs candump, jsonl or pcapng")]
    FormatMissing,
    /// `export --format` with an unknown format.
    #[error("export: {0}")]
    Format(#[from] super::export::UnknownFormat),
    /// `export` with an unknown option.
    #[error("export: unknown option `{0}`")]
    ExportOption(String),
    /// `export` with more than one file.
    #[error("export: one FILE only (`{0}` is extra)")]
    ExtraFile(String),
    /// `export` without a file.
    #[error("export: usage `export FILE [--format candump|jsonl|pcapng] [--force]`")]
    ExportUsage,
    /// The export file could not be written.
    #[error("export: {file}: {source}{hint}", hint = overwrite_hint(source))]
    Export { file: String, source: std::io::Error },
    /// A word that is no command.
    #[error("unknown command `{0}` (commands: {palette} {commander})", palette = PALETTE_COMMANDS.join(" "), commander = commander_words().join(" "))]
    Unknown(String),
}

/// What to add to an export error: how to overwrite an existing file.
fn overwrite_hint(e: &std::io::Error) -> &'static str {
    if e.kind() == std::io::ErrorKind::AlreadyExists {
        " (add --force to overwrite)"
    } else {
        ""
    }
}

impl App {
    /// An application showing `trace`, fed by `source`.
    pub fn new(trace: Trace, keymap: Keymap, source: SourceInfo) -> App {
        let bindings = Bindings::new().expect("the built-in profiles load");
        App {
            trace,
            keymap,
            focus: Pane::Trace,
            panes: Panes::default(),
            detail: DetailPane::default(),
            help: HelpPopup::default(),
            prompt: PromptBar::default(),
            search: None,
            message: None,
            messages: Messages::default(),
            log_popup: MessagesPopup::default(),
            source,
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
            recording: None,
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
                    self.record(&batch);
                    self.collect_node_events();
                    self.dirty = true;
                }
                Ok(Feed::Interfaces(names)) => {
                    for n in names {
                        self.trace.ifaces.intern(&n);
                    }
                }
                Ok(Feed::Reset) => {
                    // A replay going back is no longer at its end.
                    if self.message.as_deref() == Some("replay finished") {
                        self.message = None;
                    }
                    self.trace.clear();
                    self.panes.trace.reset();
                    self.restart_search();
                    self.detail.reset();
                    self.rate_mark = (Instant::now(), 0);
                    self.capture_clock = None;
                    self.dirty = true;
                }
                Ok(Feed::Status(s)) => self.say(Level::Info, &s),
                Ok(Feed::Position(p)) => {
                    self.source.replay.0 = Some(p);
                    self.replay_end();
                    self.dirty = true;
                }
                Ok(Feed::Extent(e)) => {
                    self.source.replay.1 = Some(e);
                    self.replay_end();
                }
                Ok(Feed::Result(level, s)) => {
                    self.say(level, &s);
                    let step = self.panes.objects.result(&s, self.trace.nodes.now_ns());
                    self.read_all_step(step);
                }
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
                    // Transfers the input cut off are listed, as `decode --transactions` lists them.
                    self.trace.end_of_input();
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

    /// A replay that played its last frame ended its input (until it goes back, which
    /// starts the trace over): the transfers it cut off are listed.
    fn replay_end(&mut self) {
        if self.source.replay_at_end() {
            self.trace.end_of_input();
        }
    }

    /// Background work: filter scanning and the search. True when work is left.
    pub fn work(&mut self, budget: Duration) -> bool {
        let view = &mut self.panes.trace.view;
        if self.source.done {
            view.settle();
        }
        let before = view.len(&self.trace);
        let more = view.advance(&self.trace, budget);
        if view.len(&self.trace) != before {
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
        if self.source.done || self.source.replay_at_end() || self.source.bus_error.is_some() {
            return None;
        }
        let (ts, at) = self.capture_clock?;
        Some(ts + (now.saturating_duration_since(at).as_secs_f64() * speed * 1e9) as u64)
    }

    /// Advances the node table to the capture time at wall time `now` (live and replay).
    fn liveness_tick(&mut self, now: Instant) {
        if let Some(t) = self.capture_now_ns(now) {
            self.trace.tick(t);
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

    /// Visible height of the main table.
    fn page(&self) -> usize {
        (self.layout.table.height as usize).max(1)
    }

    /// What the panes see: the trace, the page height, whether the capture is paused.
    pub fn ctx(&self) -> Ctx<'_> {
        Ctx {
            trace: &self.trace,
            page: self.page(),
            paused: self.source.paused,
        }
    }

    /// The panes, to change, and what they see.
    fn panes_mut(&mut self) -> (&mut Panes, Ctx<'_>) {
        let ctx = Ctx {
            trace: &self.trace,
            page: self.page(),
            paused: self.source.paused,
        };
        (&mut self.panes, ctx)
    }

    /// Handles a key press.
    pub fn key(&mut self, ev: KeyEvent) {
        self.dirty = true;
        // A question waiting for a key takes that key, whatever it is: it answers and does
        // nothing else, except that a key opening a prompt (`:`, `/`, the search key) also
        // opens it afresh, so the line typed next goes there, never to the keymap.
        if let Some(nodes) = self.quit_confirm.take() {
            match ev.code {
                KeyCode::Char('y') => self.quit = true,
                KeyCode::Char('s') => self.stop_all(&nodes, StopOptions::default()),
                _ => {
                    self.message = Some("not quitting".into());
                    self.reopen_prompt(&ev);
                }
            }
            return;
        }
        if let Some(p) = self.confirm.take() {
            if ev.code == KeyCode::Char('y') {
                self.send(p);
            } else {
                self.message = Some("not sent".into());
                self.reopen_prompt(&ev);
            }
            return;
        }
        if self.help.shown && self.help.typing {
            self.help.type_key(ev, &self.keymap);
            return;
        }
        if let Some(picker) = self.panes.plot.picker.as_mut() {
            use super::panes::picker::PickerEdit;
            match picker.key(ev, &self.trace) {
                PickerEdit::Editing => {}
                PickerEdit::Closed => self.panes.plot.picker = None,
                PickerEdit::Toggle(k) => {
                    self.panes.plot.toggle(&self.trace, k);
                    self.panes.plot.picker = None;
                }
            }
            return;
        }
        if self.prompt.editing.is_some() {
            // The candidates a completion lists stay on the status line; else the preview.
            if !self.prompt_key(ev) {
                self.preview();
            }
            if let Some(p) = self.prompt.editing.as_ref().filter(|p| p.kind == PromptKind::Find) {
                let text = p.text.clone();
                self.panes.objects.set_query(&text);
            }
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

    /// After a question was answered with `ev`: when `ev` alone is the key of the palette,
    /// the filter or the search, that prompt opens (a fresh line); any other key does nothing.
    fn reopen_prompt(&mut self, ev: &KeyEvent) {
        let Some(k) = Key::from_event(ev) else { return };
        if let Lookup::Action(a @ (Action::Palette | Action::Filter | Action::Search)) = self.keymap.lookup(&[k]) {
            self.pending.clear();
            self.act(a);
        }
    }

    /// The question waiting for a key, if any: the key hint first (`y send · any other key
    /// cancels`), then what it is about.
    pub fn question(&self) -> Option<(String, String)> {
        if let Some(nodes) = &self.quit_confirm {
            let stop = self.keymap.key_for(Action::StopAll).unwrap_or_default();
            let list = nodes.iter().map(u8::to_string).collect::<Vec<_>>().join(", ");
            return Some((
                "y quit · s stop them first · any other key stays".into(),
                format!("drive(s) {list} that cotui commanded are still powered (stop all any time: {stop})"),
            ));
        }
        let p = self.confirm.as_ref()?;
        let why = p.confirm.as_deref().unwrap_or("confirm");
        Some(("y send · any other key cancels".into(), format!("{why}: {}", p.preview)))
    }

    /// Edits the prompt line; true when a completion listed its candidates.
    fn prompt_key(&mut self, ev: KeyEvent) -> bool {
        match self.prompt.key(ev) {
            Edit::Submit(kind, text) => self.submit(kind, &text),
            Edit::Complete => {
                let before: String = self
                    .prompt
                    .editing
                    .as_ref()
                    .map(|p| p.text.chars().take(p.cursor).collect())
                    .unwrap_or_default();
                let words: Vec<String> = if let Some(rest) = before.strip_prefix("plot ") {
                    self.plot_completions(rest)
                } else if before.starts_with("record ") {
                    super::record::WORDS.iter().map(|w| w.to_string()).collect()
                } else if before.contains(' ') {
                    crate::command::syntax::completions(&before, &Heard(self))
                } else {
                    PALETTE_COMMANDS
                        .iter()
                        .chain(commander_words())
                        .map(|w| w.to_string())
                        .collect()
                };
                let shown = self
                    .prompt
                    .complete(&words.iter().map(String::as_str).collect::<Vec<_>>());
                if !shown.is_empty() {
                    self.message = Some(shown.join("  "));
                    return true;
                }
            }
            Edit::Editing | Edit::Cancelled => {}
        }
        false
    }

    /// `plot NODE INDEX:SUB`: the nodes with a series, then that node's series.
    fn plot_completions(&self, rest: &str) -> Vec<String> {
        let done: Vec<&str> = if rest.ends_with(' ') || rest.is_empty() {
            rest.split_whitespace().collect()
        } else {
            let w: Vec<&str> = rest.split_whitespace().collect();
            w[..w.len() - 1].to_vec()
        };
        let keys = self.trace.series.keys();
        match done[..] {
            [] => {
                let nodes: BTreeSet<u8> = keys.iter().map(|k| k.0.node).collect();
                nodes.iter().map(u8::to_string).collect()
            }
            [node] => keys
                .iter()
                .filter(|k| node.parse() == Ok(k.0.node))
                .map(|k| format!("{:04X}:{:02X}", k.1, k.2))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// While typing a commander line, shows the frames it would send.
    fn preview(&mut self) {
        let Some(p) = &self.prompt.editing else { return };
        let first = p.text.split_whitespace().next().unwrap_or("");
        if p.kind == PromptKind::Palette && commander_words().contains(&first) {
            // The preview says before enter when nothing can go out.
            let blocked = if self.listen_only() {
                Some("listen-only")
            } else if self.source.requests.is_none() {
                Some("this source has no bus")
            } else {
                None
            };
            self.message = Some(match palette::plan(&p.text, &self.bindings, |n| self.drive_state(n)) {
                Ok(pl) => match blocked {
                    Some(why) => format!("blocked: {why} — would send {}", pl.preview),
                    None => format!("will send: {}", pl.preview),
                },
                Err(e) => e.to_string(),
            });
        }
    }

    fn drive_state(&self, node: u8) -> Option<crate::decode::cia402::DriveState> {
        self.trace.nodes.by_id(node).and_then(|n| n.drive)
    }

    /// Runs a commander line: asks for confirmation first when it needs one.
    fn commander(&mut self, line: &str) {
        match palette::plan(line, &self.bindings, |n| self.drive_state(n)) {
            Ok(p) => match &p.confirm {
                Some(why) => {
                    self.message = Some(format!("y send · any other key cancels — {why}: {}", p.preview));
                    self.confirm = Some(p);
                }
                None => self.send(p),
            },
            Err(e) => self.message = Some(e.to_string()),
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

    /// `jobs` (list the running palette commands) or `jobs stop ID`: asks the live task.
    fn jobs_command(&mut self, rest: &str) {
        let request = match rest.split_whitespace().collect::<Vec<_>>()[..] {
            [] => Request::ListJobs,
            ["stop", id] if id.parse::<u32>().is_ok() => Request::StopJob(id.parse().unwrap_or(0)),
            _ => return self.say(Level::Error, "jobs: use `jobs` or `jobs stop ID`"),
        };
        match &self.source.requests {
            Some(req) => {
                let _ = req.send(request);
            }
            None => self.say(Level::Info, "jobs: this source has no bus, nothing runs"),
        }
    }

    /// `sim fault NODE CODE`, `sim silence NODE`, `sim reboot NODE`, ... on the demo's
    /// simulated drives (the words of `cotui sim`'s stdin): asks the live task.
    fn sim_command(&mut self, line: &str, rest: &str) {
        let control = match crate::sim::control::Control::parse(rest) {
            Ok(c) => c,
            Err(e) => return self.say(Level::Error, &format!("sim: {e}")),
        };
        match (&self.source.kind, &self.source.requests) {
            (SourceKind::Demo { .. }, Some(req)) => {
                let _ = req.send(Request::Sim {
                    line: line.to_string(),
                    control,
                });
            }
            _ => self.say(Level::Error, "sim: only the demo's drives are simulated (`cotui demo`)"),
        }
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
                .map(|(id, _)| id.node),
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
        if let Some(summary) = self.panes.objects.stop_read_all() {
            self.log(Level::Warn, &summary);
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
            .filter(|n| self.trace.nodes.by_id(*n).and_then(|i| i.drive).is_some_and(is_powered))
            .collect();
        if powered.is_empty() || self.source.requests.is_none() {
            self.quit = true;
            return;
        }
        self.quit_confirm = Some(powered);
        self.message = self.question().map(|(hint, text)| format!("{hint} — {text}"));
    }

    /// Runs a line entered at a prompt (the filter, search or palette prompt).
    fn submit(&mut self, kind: PromptKind, text: &str) {
        let applied = match kind {
            PromptKind::Filter => self.apply_filter(text),
            PromptKind::Search => self.apply_search(text),
            PromptKind::Palette => {
                self.run_command(text);
                Ok(())
            }
            PromptKind::Find => {
                self.panes.objects.set_query(text);
                Ok(())
            }
        };
        // A bad expression keeps the prompt open with the text, the cursor where it is wrong.
        if let Err(e) = applied {
            self.prompt.open(kind, text);
            if let Some(p) = self.prompt.editing.as_mut() {
                p.cursor = (e.column - 1).min(p.cursor);
            }
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
        let page = self.page();
        self.panes.trace.set_filter(&self.trace, f, page);
        self.message = None;
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
        let mut s = Search::new(f, &self.panes.trace.view.filter);
        s.advance(&self.trace, Duration::from_millis(30));
        self.search = Some(s);
        self.jump_match(true);
        Ok(())
    }

    /// The search in force starts over (the filter it searches within changed).
    fn restart_search(&mut self) {
        if let Some(s) = self.search.take() {
            self.search = Some(Search::new(s.filter, &self.panes.trace.view.filter));
        }
    }

    /// Runs a palette command; the result goes to the status bar.
    pub fn run_command(&mut self, line: &str) {
        let (cmd, rest) = line.split_once(' ').unwrap_or((line, ""));
        let rest = rest.trim();
        let result: Result<String, CommandError> = match cmd {
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
                .map_err(|_| CommandError::NotAFrame(rest.to_string()))
                .map(|n| {
                    if !self.replay_control(Control::GotoFrame(n as u64)) {
                        self.select_position(n.saturating_sub(1));
                    }
                    format!("frame {n}")
                }),
            "time" => rest
                .parse::<f64>()
                .map_err(|_| CommandError::NotSeconds(rest.to_string()))
                .map(|s| {
                    if !self.replay_control(Control::GotoTime((s.max(0.0) * 1e9) as u64)) {
                        let t0 = self.start_ns();
                        let pos = self.trace.store.position_at(t0 + (s.max(0.0) * 1e9) as u64);
                        self.select_position(pos);
                    }
                    format!("t = {s} s")
                }),
            "rewind" if self.replay_control(Control::Rewind) => Ok("rewind".into()),
            "rewind" => Err(CommandError::NoReplay("rewind")),
            "speed" => match rest.parse::<f64>() {
                Ok(x) if super::source::valid_speed(x) => self.set_speed(x),
                _ => Err(CommandError::NotAFactor(rest.to_string())),
            },
            "pause" => {
                self.set_paused(true);
                Ok(String::new())
            }
            "resume" => {
                self.set_paused(false);
                Ok(String::new())
            }
            "loop" => {
                self.act(Action::Loop);
                return;
            }
            "plot" => self.plot_command(rest),
            "help" => {
                self.help.shown = true;
                Ok(String::new())
            }
            "export" => self.export_command(rest),
            "messages" => {
                self.log_popup.open();
                Ok(String::new())
            }
            "quit" => {
                self.request_quit();
                return;
            }
            "jobs" => {
                self.jobs_command(rest);
                return;
            }
            "record" => {
                self.record_command(rest);
                return;
            }
            "sim" => {
                self.sim_command(line, rest);
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
            w if commander_words().contains(&w) => {
                self.commander(line);
                return;
            }
            other => Err(CommandError::Unknown(other.to_string())),
        };
        self.message = match result {
            Ok(s) if s.is_empty() => None,
            Ok(s) => Some(s),
            Err(e) => {
                self.log(Level::Error, &format!("{line}: {e}"));
                Some(e.to_string())
            }
        };
    }

    /// Tells the Objects pane the Nodes pane's selection (its node unless one is picked
    /// there): when the user selects in the Nodes pane, or while the Objects pane has none.
    /// Not on every frame: a node appearing above the selection does not change it.
    fn sync_objects_node(&mut self) {
        let n = self
            .trace
            .nodes
            .iter()
            .nth(self.panes.nodes.list.selected)
            .map(|(n, _)| n.node);
        self.panes.objects.set_nodes_selection(n);
    }

    /// True when SDO reads can go out; else says why not (listen-only, or a log: no bus).
    fn can_read(&mut self, what: &str) -> bool {
        if self.listen_only() {
            self.say(
                Level::Error,
                &format!("{what}: listen-only — nothing can be sent, so no object can be read"),
            );
            return false;
        }
        if self.source.requests.is_none() {
            self.say(
                Level::Error,
                &format!(
                    "{what}: this source is a log file, there is no bus to read from (use `cotui live IFACE` or `cotui demo`)"
                ),
            );
            return false;
        }
        true
    }

    /// Does what the Objects pane asked.
    fn object_request(&mut self, r: super::panes::objects::ObjectRequest) {
        use super::panes::objects::{ObjectRequest, read_line};
        match r {
            ObjectRequest::Read { node, index, sub } => {
                let line = read_line(node, index, sub);
                if self.can_read(&line) {
                    self.panes.objects.sent(&line, node, index, sub);
                    match palette::plan(&line, &self.bindings, |_| None) {
                        Ok(_) => self.run_command(&line),
                        // E.g. an object of the decoder's dictionary the session's bindings lack.
                        Err(e) => {
                            let text = format!("{line}: error: {e}");
                            self.say(Level::Error, &text);
                            self.panes.objects.result(&text, self.trace.nodes.now_ns());
                        }
                    }
                }
            }
            ObjectRequest::Edit { .. } if self.listen_only() => self.say(
                Level::Error,
                "write: listen-only — nothing can be sent, so no object can be written",
            ),
            ObjectRequest::Edit { text, cursor, note } => {
                self.prompt.open(PromptKind::Palette, &text);
                if let Some(p) = self.prompt.editing.as_mut() {
                    p.cursor = cursor;
                }
                self.preview();
                self.message = Some(match self.message.take() {
                    Some(m) => format!("{note} · {m}"),
                    None => note,
                });
            }
            ObjectRequest::ReadAll { node, objects } => {
                let what = format!("read all node {node}");
                if objects.is_empty() {
                    self.say(Level::Info, &format!("{what}: no readable object known"));
                } else if self.can_read(&what) {
                    let stop = self.keymap.key_for(Action::ReadAll).unwrap_or_default();
                    self.say(
                        Level::Info,
                        &format!(
                            "{what}: reading {} objects one after the other ({stop} again stops)",
                            objects.len()
                        ),
                    );
                    let step = self.panes.objects.start_read_all(node, objects);
                    self.read_all_step(step);
                }
            }
            ObjectRequest::Find(text) => self.prompt.open(PromptKind::Find, &text),
            ObjectRequest::Note(text) => self.message = Some(text),
        }
    }

    /// Goes on with a read-all: sends its next read (without the per-line "sending"
    /// notice), or says how it ended.
    fn read_all_step(&mut self, mut step: super::panes::objects::Step) {
        use super::panes::objects::Step;
        loop {
            match step {
                Step::Next(line) => match palette::plan(&line, &self.bindings, |_| None) {
                    Ok(p) => {
                        if let Some(req) = &self.source.requests {
                            let _ = req.send(Request::Run {
                                line: p.line,
                                command: p.command,
                            });
                        }
                        return;
                    }
                    Err(e) => {
                        let text = format!("{line}: error: {e}");
                        self.log(Level::Error, &text);
                        step = self.panes.objects.result(&text, self.trace.nodes.now_ns());
                    }
                },
                Step::Finished(text) => {
                    let failed = text.lines().count() > 1;
                    self.say(if failed { Level::Warn } else { Level::Info }, &text);
                    return;
                }
                Step::NotOurs | Step::Noted => return,
            }
        }
    }

    /// `record start FILE [--force | --append]` / `record stop`: the frames the session
    /// receives to a candump log.
    fn record_command(&mut self, rest: &str) {
        use super::record::{RecordCommand, Recorder, parse};
        match parse(rest) {
            Err(e) => self.say(Level::Error, &e),
            Ok(RecordCommand::Stop) => match self.recording.take() {
                None => self.say(Level::Info, "record: not recording"),
                Some(r) => {
                    let file = r.file.clone();
                    match r.stop() {
                        Ok(n) => self.say(Level::Info, &format!("record: stopped, {n} frames in {file}")),
                        Err(e) => self.say(Level::Error, &format!("record: {file}: {e}")),
                    }
                }
            },
            Ok(RecordCommand::Start { .. }) if self.source.requests.is_none() => self.say(
                Level::Error,
                "record: only a live or demo session records what it receives; `export FILE` writes a log's view",
            ),
            Ok(RecordCommand::Start { .. }) if self.recording.is_some() => {
                let file = self.recording.as_ref().map(|r| r.file.clone()).unwrap_or_default();
                self.say(
                    Level::Error,
                    &format!("record: already recording to {file} (`record stop` first)"),
                );
            }
            Ok(RecordCommand::Start { file, mode }) => match Recorder::start(&file, mode) {
                Ok(r) => {
                    self.recording = Some(r);
                    self.say(
                        Level::Info,
                        &format!("record: recording the frames received to {file} (`record stop` ends it)"),
                    );
                }
                Err(e) => self.say(Level::Error, &format!("record: {e}")),
            },
        }
    }

    /// Writes a batch of frames to the recording, if one runs; a failed write ends it.
    fn record(&mut self, batch: &[crate::frame::Frame]) {
        let Some(r) = self.recording.as_mut() else { return };
        if let Err(e) = r.frames(batch, &self.trace.ifaces) {
            let (file, n) = (r.file.clone(), r.count());
            self.recording = None;
            self.say(
                Level::Error,
                &format!("record: {file}: {e}; stopped, {n} whole frames kept"),
            );
        }
    }

    /// `export FILE [--format candump|jsonl|pcapng] [--force]`: the rows the view shows.
    fn export_command(&mut self, rest: &str) -> Result<String, CommandError> {
        use super::export::{ExportFormat, export};
        let (mut file, mut format, mut force) = (None, None, false);
        let mut words = rest.split_whitespace();
        while let Some(w) = words.next() {
            match w {
                "--force" => force = true,
                "--format" => {
                    let f = words.next().ok_or(CommandError::FormatMissing)?;
                    format = Some(ExportFormat::parse(f)?);
                }
                w if w.starts_with("--") => return Err(CommandError::ExportOption(w.to_string())),
                w if file.is_none() => file = Some(w.to_string()),
                w => return Err(CommandError::ExtraFile(w.to_string())),
            }
        }
        let file = file.ok_or(CommandError::ExportUsage)?;
        let path = std::path::Path::new(&file);
        let format = format.unwrap_or_else(|| ExportFormat::of_path(path));
        let view = &self.panes.trace.view;
        let scanned = view.progress(&self.trace);
        let n = export(&self.trace, view, path, format, force).map_err(|source| CommandError::Export {
            file: file.clone(),
            source,
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

    fn plot_command(&mut self, rest: &str) -> Result<String, CommandError> {
        let mut it = rest.split_whitespace();
        let (Some(node), Some(obj)) = (it.next(), it.next()) else {
            return Err(CommandError::PlotUsage);
        };
        let node: u8 = node.parse().map_err(|_| CommandError::NotANode(node.to_string()))?;
        let (i, s) = obj.split_once(':').unwrap_or((obj, "0"));
        let index =
            u16::from_str_radix(i.trim_start_matches("0x"), 16).map_err(|_| CommandError::BadIndex(i.to_string()))?;
        let sub = u8::from_str_radix(s, 16).map_err(|_| CommandError::BadSub(s.to_string()))?;
        if self.panes.plot.select(&self.trace, node, index, sub) {
            self.focus = Pane::Plot;
            Ok(String::new())
        } else {
            Err(CommandError::NoSeries { node, index, sub })
        }
    }

    /// Sends `c` to a replay, whose newest frame the trace then follows; false when the
    /// source is not a replay.
    fn replay_control(&mut self, c: Control) -> bool {
        let Some(ctl) = &self.source.control else { return false };
        let _ = ctl.send(c);
        self.panes.trace.follow = true;
        true
    }

    fn set_speed(&mut self, x: f64) -> Result<String, CommandError> {
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
            _ => Err(CommandError::NoSpeed),
        }
    }

    fn set_paused(&mut self, p: bool) {
        self.source.paused = p;
        // The replay clock restarts from the next frame.
        self.capture_clock = None;
        if let Some(c) = &self.source.control {
            let _ = c.send(Control::Pause(p));
        }
        if p {
            self.panes.trace.follow = false;
        }
    }

    /// The timestamp of the first frame.
    pub fn start_ns(&self) -> u64 {
        super::panes::start_ns(&self.trace)
    }

    /// The trace position of the selected row of the trace.
    pub fn selected_position(&self) -> Option<usize> {
        self.panes.trace.selected_position(&self.trace)
    }

    /// Shows trace position `pos` in the Trace pane.
    fn select_position(&mut self, pos: usize) {
        let page = self.page();
        self.focus = Pane::Trace;
        self.panes.trace.select_position(&self.trace, pos, page);
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

    /// What the Detail pane shows: the focused pane's selection, else the trace's.
    pub fn selected(&self) -> Option<Selected> {
        self.panes
            .get(self.focus)
            .selected(&self.ctx())
            .or_else(|| self.selected_position().map(Selected::Frame))
    }

    /// The Detail pane is toggled in below the main pane (a narrow terminal).
    fn detail_below(&self) -> bool {
        self.detail.shown && !self.layout.side
    }

    /// Does what an action says: the message log popup takes it first while shown, then
    /// the help popup and the Detail pane below, then the focused pane; what none of them
    /// takes is for the application.
    pub fn act(&mut self, a: Action) {
        self.dirty = true;
        if self.log_popup.shown && self.log_popup.handle(a, &self.messages) {
            return;
        }
        if self.help.handle(a, &self.keymap) {
            return;
        }
        if a == Action::Back && self.detail_below() {
            self.detail.shown = false;
            return;
        }
        let focus = self.focus;
        let (panes, ctx) = self.panes_mut();
        let outcome = panes.get_mut(focus).handle(a, &ctx);
        if focus == Pane::Nodes {
            // A node selected in the Nodes pane is the one the Objects pane shows.
            self.sync_objects_node();
        }
        match outcome {
            Outcome::Done => return,
            Outcome::Ignored => {}
            Outcome::Detail => {
                // Beside the main pane on a wide terminal; toggled below it on a narrow one.
                if !self.layout.side {
                    self.detail.shown = !self.detail.shown;
                }
                return;
            }
            Outcome::Filter(text) => {
                self.set_filter(&text);
                self.focus = Pane::Trace;
                return;
            }
            Outcome::Show(pos) => {
                let page = self.page();
                self.panes.trace.show(&self.trace, pos, page);
                self.focus = Pane::Trace;
                return;
            }
            Outcome::Object(r) => {
                self.object_request(r);
                return;
            }
        }
        match a {
            Action::Quit => self.request_quit(),
            Action::Messages => self.log_popup.toggle(),
            Action::Back => {
                self.search = None;
                self.message = None;
            }
            Action::Follow => {
                self.panes.trace.follow = !self.panes.trace.follow;
                self.focus = Pane::Trace;
            }
            Action::Pause => {
                let p = !self.source.paused;
                self.set_paused(p);
                if !p {
                    self.panes.trace.follow = true;
                }
            }
            Action::NextPane | Action::PrevPane => {
                let i = Pane::ALL.iter().position(|p| *p == self.focus).unwrap_or(0);
                let d = if a == Action::NextPane { 1 } else { Pane::ALL.len() - 1 };
                self.focus = Pane::ALL[(i + d) % Pane::ALL.len()];
            }
            Action::PaneTrace => self.focus = Pane::Trace,
            Action::PaneNodes => self.focus = Pane::Nodes,
            Action::PaneSdo => self.focus = Pane::Sdo,
            Action::PaneStats => self.focus = Pane::Stats,
            Action::PanePlot => self.focus = Pane::Plot,
            Action::PanePdo => self.focus = Pane::Pdo,
            Action::PaneObjects => self.focus = Pane::Objects,
            Action::EditObject | Action::ReadAll => {
                self.message = Some(format!("{}: only in the Objects pane", a.name().replace('_', " ")))
            }
            Action::PaneProblems => self.focus = Pane::Problems,
            Action::Filter => {
                let text = self.panes.trace.view.filter.source.clone();
                self.prompt.open(PromptKind::Filter, &text);
            }
            Action::Search => {
                let text = self
                    .search
                    .as_ref()
                    .map(|s| s.filter.source.clone())
                    .unwrap_or_default();
                self.prompt.open(PromptKind::Search, &text);
            }
            Action::NextMatch => self.jump_match(true),
            Action::PrevMatch => self.jump_match(false),
            Action::ClearFilter => self.set_filter(""),
            Action::Palette => self.prompt.open(PromptKind::Palette, ""),
            Action::StopAll => self.stop_all(&[], StopOptions::default()),
            Action::SpeedUp | Action::SpeedDown => {
                if let SourceKind::Replay { speed } = self.source.kind {
                    let base = if speed <= 0.0 { 1.0 } else { speed };
                    let x = if a == Action::SpeedUp { base * 2.0 } else { base / 2.0 };
                    let x = x.clamp(*super::source::SPEEDS.start(), *super::source::SPEEDS.end());
                    self.message = Some(self.set_speed(x).unwrap_or_else(|e| e.to_string()));
                }
            }
            Action::Step => match &self.source.control {
                Some(c) if self.source.paused => {
                    let _ = c.send(Control::Step);
                    self.panes.trace.follow = true;
                }
                _ => self.message = Some("step: pause a replay first".into()),
            },
            Action::Loop => {
                let on = !self.source.looping;
                match &self.source.control {
                    Some(c) => {
                        let _ = c.send(Control::Loop(on));
                        self.source.looping = on;
                        self.message = Some(format!("replay loop {}", if on { "on" } else { "off" }));
                    }
                    None => self.message = Some("loop: only a replay can loop".into()),
                }
            }
            Action::StepBack | Action::Rewind => {
                let c = if a == Action::Rewind {
                    Control::Rewind
                } else {
                    Control::StepBack
                };
                if !self.replay_control(c) {
                    self.message = Some("only a replay can step back or rewind".into());
                }
            }
            Action::SeekForward | Action::SeekBack => match &self.source.control {
                Some(c) => {
                    let d: i64 = if a == Action::SeekForward {
                        10_000_000_000
                    } else {
                        -10_000_000_000
                    };
                    let _ = c.send(Control::Seek(d));
                    self.panes.trace.follow = true;
                }
                None => self.message = Some("seek: only a replay can seek".into()),
            },
            Action::NextSeries | Action::PrevSeries => {
                self.panes.plot.step(&self.trace, a == Action::NextSeries);
                self.focus = Pane::Plot;
            }
            // From another pane: the Stats pane comes to the front and takes it.
            Action::Sort => {
                self.focus = Pane::Stats;
                let (panes, ctx) = self.panes_mut();
                panes.stats.handle(a, &ctx);
            }
            // From another pane: the Plot pane comes to the front and takes them.
            Action::PlotPick | Action::ZoomIn | Action::ZoomOut => {
                self.focus = Pane::Plot;
                let (panes, ctx) = self.panes_mut();
                panes.plot.handle(a, &ctx);
            }
            // From any pane: the next frame of the incident selected in the Problems pane, so
            // that pressing it again in the trace walks through the incident's frames.
            Action::ShowFrames => {
                let (panes, ctx) = self.panes_mut();
                panes.problems.refresh(&ctx);
                if let Outcome::Show(pos) = panes.problems.handle(a, &ctx) {
                    let page = self.page();
                    self.panes.trace.show(&self.trace, pos, page);
                    self.focus = Pane::Trace;
                }
            }
            // Taken by the help popup; row movement and `expand` in a pane without rows.
            Action::Help
            | Action::Down
            | Action::Up
            | Action::PageDown
            | Action::PageUp
            | Action::Top
            | Action::Bottom
            | Action::Expand => {}
        }
    }

    /// Handles a mouse event: the wheel scrolls the focused pane, a left click selects a row.
    pub fn mouse(&mut self, ev: MouseEvent) {
        self.dirty = true;
        let (t, focus) = (self.layout.table, self.focus);
        let (panes, ctx) = self.panes_mut();
        let pane = panes.get_mut(focus);
        match ev.kind {
            MouseEventKind::ScrollDown => pane.scroll(3, &ctx),
            MouseEventKind::ScrollUp => pane.scroll(-3, &ctx),
            MouseEventKind::Down(MouseButton::Left)
                if ev.column >= t.x && ev.column < t.x + t.width && ev.row >= t.y && ev.row < t.y + t.height =>
            {
                pane.click((ev.row - t.y) as usize, &ctx)
            }
            _ => {}
        }
        if focus == Pane::Nodes {
            self.sync_objects_node();
        }
    }

    /// Before drawing: keeps the list panes' selections within their rows and visible in
    /// `height` rows, pins the trace selection to the newest row in follow mode, decodes the
    /// visible trace window (`rows` rows), the tail strip and what the Detail pane shows.
    pub fn prepare(&mut self, height: usize, rows: usize, tail: &[usize]) {
        if self.panes.objects.node().is_none() {
            self.sync_objects_node();
        }
        let (panes, ctx) = self.panes_mut();
        for p in [
            Pane::Nodes,
            Pane::Stats,
            Pane::Sdo,
            Pane::Objects,
            Pane::Pdo,
            Pane::Problems,
        ] {
            panes.get_mut(p).fit(height, &ctx);
        }
        self.panes.trace.prepare(&self.trace, rows, tail);
        let selected = self.selected();
        self.detail.update(&self.trace, selected);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::panes::testutil::{app, frames};
    use crossterm::event::{KeyEvent, KeyModifiers};

    fn key(c: char) -> KeyEvent {
        KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)
    }

    #[test]
    fn transfers_cut_off_by_the_end_of_a_log_are_listed_when_it_is_read_or_replayed_to_the_end() {
        use crate::tui::source::{Extent, Position};
        // A download announcing 64 bytes, answered, then nothing more.
        let frames = || {
            [
                (0x603, [0x21, 0x01, 0x70, 0x01, 0x40, 0, 0, 0]),
                (0x583, [0x60, 0x01, 0x70, 0x01, 0, 0, 0, 0]),
            ]
            .iter()
            .map(|(id, d)| crate::frame::Frame::classic(*id, d))
            .collect::<Vec<_>>()
        };
        let fresh = |kind| {
            let (ftx, frx) = std::sync::mpsc::channel();
            let mut a = app();
            a.trace.clear();
            a.source = SourceInfo::new("x.log", kind, frx, None);
            ftx.send(Feed::Frames(frames())).unwrap();
            (a, ftx)
        };
        let (mut a, ftx) = fresh(SourceKind::Open);
        a.ingest(Duration::from_millis(100));
        assert!(a.trace.transactions.is_empty(), "still running while the log is read");
        ftx.send(Feed::Done).unwrap();
        a.ingest(Duration::from_millis(100));
        let t = &a.trace.transactions;
        assert_eq!(
            (t.len(), t[0].outcome.as_str(), t[0].cut_short_of()),
            (1, "incomplete", Some(64))
        );
        // A replay: at its last frame.
        let (mut a, ftx) = fresh(SourceKind::Replay { speed: 1.0 });
        let at = Position { frames: 2, ts_ns: 0 };
        ftx.send(Feed::Position(Position { frames: 1, ts_ns: 0 })).unwrap();
        ftx.send(Feed::Extent(Extent {
            frames: 2,
            first_ns: 0,
            last_ns: 0,
        }))
        .unwrap();
        a.ingest(Duration::from_millis(100));
        assert!(a.trace.transactions.is_empty(), "not at the end yet");
        ftx.send(Feed::Position(at)).unwrap();
        ftx.send(Feed::Position(at)).unwrap();
        a.ingest(Duration::from_millis(100));
        assert_eq!(a.trace.transactions.len(), 1, "listed once");
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
        assert!(
            a.trace
                .nodes
                .liveness(crate::frame::NodeKey::new(0, 2))
                .unwrap()
                .is_lost()
        );
        assert!(
            !a.trace
                .nodes
                .liveness(crate::frame::NodeKey::new(0, 5))
                .unwrap()
                .is_lost()
        );
        // No frame comes for a second of wall time: node 5 (every 100 ms) is lost too,
        // dated 150 ms after its last heartbeat.
        a.liveness_tick(taken + Duration::from_secs(1));
        let l = a.trace.nodes.liveness(crate::frame::NodeKey::new(0, 5)).unwrap();
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
    fn built_in_command_errors_say_what_is_wrong_and_go_to_the_log() {
        let mut a = app();
        let dir = std::env::temp_dir().join(format!("cotui-app-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("x.log");
        std::fs::write(&file, "").unwrap();
        let file = file.display().to_string();
        for (line, want) in [
            ("goto x", "goto: `x` is not a frame number".to_string()),
            ("speed 2", "speed: only a replay has a speed".into()),
            (
                "plot 1",
                "plot: usage `plot NODE INDEX[:SUB]`, e.g. `plot 1 6064:00`".into(),
            ),
            ("plot 1 60z1", "plot: bad index `60z1`".into()),
            ("plot 9 6041", "plot: no numeric values of node 9 0x6041:00 seen".into()),
            (
                "export a.log --format xml",
                "export: unknown export format `xml`: use candump, jsonl or pcapng".into(),
            ),
            ("export a.log b.log", "export: one FILE only (`b.log` is extra)".into()),
            (
                &format!("export {file}"),
                format!("export: {file}: File exists (os error 17) (add --force to overwrite)"),
            ),
        ] {
            a.run_command(line);
            assert_eq!(a.message.as_deref(), Some(want.as_str()), "{line}");
            let logged = a.messages.iter().last().map(|e| e.text.clone()).unwrap_or_default();
            assert_eq!(logged, format!("{line}: {want}"));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn palette_tab_completes_nodes_heard_objects_and_plot_series() {
        let mut a = app();
        let tab = KeyEvent::new(KeyCode::Tab, KeyModifiers::NONE);
        a.key(key(':'));
        for c in "sdo read ".chars() {
            a.key(key(c));
        }
        a.key(tab);
        assert_eq!(a.message.as_deref(), Some("1  2"), "the nodes heard");
        for c in "2 statusw".chars() {
            a.key(key(c));
        }
        a.key(tab);
        assert_eq!(
            a.prompt.editing.as_ref().map(|p| p.text.as_str()),
            Some("sdo read 2 Statusword ")
        );
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        a.key(key(':'));
        for c in "plot 1 ".chars() {
            a.key(key(c));
        }
        a.key(tab);
        assert_eq!(a.message.as_deref(), Some("1017:00  6041:00"));
    }

    #[test]
    fn palette_commander_lines_need_a_bus_and_confirm_broadcasts() {
        let mut a = app();
        a.key(key(':'));
        for c in "nmt reset-node 0".chars() {
            a.key(key(c));
        }
        // A log has no bus: the preview says so before enter.
        assert_eq!(
            a.message.as_deref(),
            Some("blocked: this source has no bus — would send 000#8100")
        );
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert!(a.confirm.is_some());
        a.key(key('y'));
        assert_eq!(
            a.message.as_deref(),
            Some("not sent: this source has no bus (use `cotui live IFACE` or `cotui demo`)")
        );
        assert_eq!(a.prompt.history, ["nmt reset-node 0"]);
    }

    #[test]
    fn the_key_that_cancels_a_confirmation_does_nothing_else_and_colon_opens_a_fresh_palette() {
        let typed = |a: &mut App, text: &str| {
            for c in text.chars() {
                a.key(key(c));
            }
        };
        let enter = KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE);
        let mut a = app();
        typed(&mut a, ":lss fastscan");
        a.key(enter);
        assert!(a.confirm.is_some());
        assert_eq!(
            a.question().map(|q| q.0).as_deref(),
            Some("y send · any other key cancels")
        );
        // `:` cancels and opens a new palette: the review's `lss inquire all` goes there,
        // its `q` does not quit, its `s` does not sort.
        a.key(key(':'));
        assert!(a.confirm.is_none() && a.question().is_none());
        typed(&mut a, "lss inquire all");
        assert!(!a.quit, "the q went to the palette");
        assert_eq!(
            a.focus,
            Pane::Trace,
            "the s did not sort (that brings the receive list up)"
        );
        assert_eq!(
            a.prompt.editing.as_ref().map(|p| p.text.as_str()),
            Some("lss inquire all")
        );
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        // Any other key only cancels: `4` does not switch to the Stats pane, `q` not quit.
        typed(&mut a, ":lss fastscan");
        a.key(enter);
        a.key(key('4'));
        assert_eq!((a.confirm.is_none(), a.focus), (true, Pane::Trace));
        assert_eq!(a.message.as_deref(), Some("not sent"));
        typed(&mut a, ":nmt stop 0");
        a.key(enter);
        a.key(key('q'));
        assert!(!a.quit && a.confirm.is_none(), "q cancelled, and only cancelled");
        // The next key is the user's again.
        a.key(key('4'));
        assert_eq!(a.focus, Pane::Stats);
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
    fn the_palette_preview_says_a_listen_only_session_blocks_the_frame() {
        let (mut a, _req) = live_app(true);
        a.key(key(':'));
        for c in "nmt stop 2".chars() {
            a.key(key(c));
        }
        assert_eq!(a.message.as_deref(), Some("blocked: listen-only — would send 000#0202"));
        // A session that can send previews what goes out.
        let (mut a, _req) = live_app(false);
        a.key(key(':'));
        for c in "nmt stop 2".chars() {
            a.key(key(c));
        }
        assert_eq!(a.message.as_deref(), Some("will send: 000#0202"));
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
        assert_eq!(
            a.question(),
            Some((
                "y quit · s stop them first · any other key stays".into(),
                "drive(s) 1 that cotui commanded are still powered (stop all any time: ctrl-s)".into()
            ))
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
        assert!(a.log_popup.shown);
        let s = crate::tui::panes::testutil::screen(&mut a, 120, 20);
        assert!(s.contains("Messages (3)"), "{s}");
        assert!(s.contains("node 3 syntron-ds"), "{s}");
        a.act(Action::Up);
        assert_eq!(a.log_popup.selected, Some(1), "up selects the entry before the newest");
        a.act(Action::Back);
        assert!(!a.log_popup.shown);
    }

    #[test]
    fn vim_keys_go_to_the_focused_pane_and_the_prompts() {
        let mut a = app();
        a.keymap = Keymap::load(("vim", crate::tui::keymap::VIM), &[]).unwrap();
        let _ = crate::tui::panes::testutil::screen(&mut a, 140, 20);
        for c in ['g', 'g'] {
            a.key(key(c));
        }
        assert_eq!((a.selected_position(), a.panes.trace.follow), (Some(0), false));
        a.key(key('j'));
        assert_eq!(a.selected_position(), Some(1));
        a.key(key('2'));
        a.key(key('j'));
        assert_eq!((a.focus, a.panes.nodes.list.selected), (Pane::Nodes, 1));
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert_eq!(a.focus, Pane::Trace);
        assert_eq!(a.panes.trace.view.filter.source, "node 2");
        a.key(key('F'));
        assert_eq!(a.prompt.editing.as_ref().map(|p| p.text.as_str()), Some("node 2"));
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        a.key(key('G'));
        assert!(a.panes.trace.follow);
    }

    #[test]
    fn the_mouse_scrolls_and_selects_in_the_focused_pane() {
        let mut a = app();
        let _ = crate::tui::panes::testutil::screen(&mut a, 140, 20);
        let mouse = |kind, row| MouseEvent {
            kind,
            column: 5,
            row,
            modifiers: KeyModifiers::NONE,
        };
        let last = a.selected_position();
        a.mouse(mouse(MouseEventKind::ScrollUp, 0));
        assert!(!a.panes.trace.follow);
        assert_eq!(a.selected_position(), last.map(|p| p - 3));
        a.act(Action::PaneNodes);
        let _ = crate::tui::panes::testutil::screen(&mut a, 140, 20);
        let t = a.layout.table;
        a.mouse(mouse(MouseEventKind::Down(MouseButton::Left), t.y + 1));
        assert_eq!(a.panes.nodes.list.selected, 1);
        // A click below the last node selects nothing new.
        a.mouse(mouse(MouseEventKind::Down(MouseButton::Left), t.y + 5));
        assert_eq!(a.panes.nodes.list.selected, 1);
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
        assert_eq!(a.panes.sdo.expanded, Some(4));
        a.act(Action::Down);
        a.act(Action::Expand);
        assert_eq!(a.focus, Pane::Trace);
        assert_eq!(a.selected_position(), Some(12));
    }
}
