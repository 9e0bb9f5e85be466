//! The application: routes keys, actions and the palette's lines between the capture side
//! ([`Capture`]: the trace and what feeds it) and the screen side ([`Screen`]: the focus,
//! the panes, the popups, the prompt). The parts and the panes answer with events
//! (`src/tui/event.rs`), which [`App`] routes; recording ([`super::record`]),
//! stop-all ([`super::stop`]), read-all ([`super::read_all`]) and export
//! ([`super::export`]) live in their own modules. Pure state transitions: no terminal
//! here, so tests drive it directly.

pub use super::capture::{Capture, SourceInfo, SourceKind};
pub use super::screen::{Layout, Screen};

use super::capture::Flow;
use super::commands::{self, PALETTE_COMMANDS, Ran};
use super::event::{Event, ObjectRequest, Queue};
use super::keymap::{Action, Key, Keymap, Lookup};
use super::live::Request;
use super::messages::Level;
use super::palette::{self, Planned, commander_words};
use super::panes::{Ctx, Pane, Selected};
use super::prompt::{Edit, PromptKind};
use super::{read_all, record, stop, transmit, watch};
use crate::analysis::trace::Trace;
use crate::od::bind::Bindings;
use crossterm::event::{KeyCode, KeyEvent, MouseEvent};
use std::collections::BTreeSet;
use std::time::{Duration, Instant};

/// The whole application: the capture, the screen, the keys and the dictionaries.
pub struct App {
    capture: Capture,
    screen: Screen,
    keymap: Keymap,
    /// Node bindings (object names and types for palette previews and commands).
    bindings: Bindings,
    /// Set when the user quits.
    quit: bool,
    /// Set when the user answered the quit question with "stop them first": the session
    /// quits once the stop-all confirms every drive stopped.
    quit_after_stop: bool,
    /// Set when something changed since the last draw.
    dirty: bool,
}

/// What the palette completes from: the nodes heard (the node table) and the dictionaries
/// the commander uses (the bindings).
struct Heard<'a>(&'a Trace, &'a Bindings);

impl crate::command::complete::Known for Heard<'_> {
    fn nodes(&self) -> Vec<u8> {
        let mut ids: Vec<u8> = self.0.nodes.iter().map(|(id, _)| id.node).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
    fn dictionary(&self, node: u8) -> &crate::od::Dictionary {
        self.1.dictionary(node)
    }
}

impl App {
    /// An application showing `trace`, fed by `source`.
    pub fn new(trace: Trace, keymap: Keymap, source: SourceInfo) -> App {
        let bindings = Bindings::new();
        App {
            capture: Capture::new(trace, source),
            screen: Screen::default(),
            keymap,
            bindings,
            quit: false,
            quit_after_stop: false,
            dirty: true,
        }
    }

    /// The capture side: the trace, the source, the recording, the commanded drives.
    pub fn capture(&self) -> &Capture {
        &self.capture
    }

    /// The capture side, to change.
    pub fn capture_mut(&mut self) -> &mut Capture {
        &mut self.capture
    }

    /// The screen side: the focus, the panes, the popups, the prompt, the messages.
    pub fn screen(&self) -> &Screen {
        &self.screen
    }

    /// The screen side, to change.
    pub fn screen_mut(&mut self) -> &mut Screen {
        &mut self.screen
    }

    /// Frames and what is derived from them.
    pub fn trace(&self) -> &Trace {
        self.capture.trace()
    }

    /// The capture source.
    pub fn source(&self) -> &SourceInfo {
        self.capture.source()
    }

    /// The message in the status line (result of the last command).
    pub fn message(&self) -> Option<&str> {
        self.screen.message()
    }

    /// The pane in the main area.
    pub fn focus(&self) -> Pane {
        self.screen.focus()
    }

    /// Key bindings.
    pub fn keymap(&self) -> &Keymap {
        &self.keymap
    }

    /// Uses `keymap` from now on.
    pub fn set_keymap(&mut self, keymap: Keymap) {
        self.keymap = keymap;
    }

    /// Uses `bindings` (object names and types) for the palette from now on.
    pub fn set_bindings(&mut self, bindings: Bindings) {
        self.bindings = bindings;
    }

    /// True once the user quit.
    pub fn quits(&self) -> bool {
        self.quit
    }

    /// True when something changed since the last draw.
    pub fn dirty(&self) -> bool {
        self.dirty
    }

    /// The screen was drawn: nothing changed since.
    pub fn drawn(&mut self) {
        self.dirty = false;
    }

    /// Asks for a draw (the terminal was resized, or given back after a suspend).
    pub fn redraw(&mut self) {
        self.dirty = true;
    }

    /// Takes frames from the source for up to `budget`; true when more are waiting.
    pub fn ingest(&mut self, budget: Duration) -> bool {
        let start = Instant::now();
        loop {
            let mut q = Queue::default();
            let flow = self.capture.take(&mut q);
            self.route(q);
            match flow {
                Flow::Empty => return false,
                Flow::Ended => {
                    self.dirty = true;
                    return false;
                }
                Flow::Took => self.dirty = true,
            }
            if start.elapsed() >= budget {
                return true;
            }
        }
    }

    /// Background work: filter scanning and the search. True when work is left.
    pub fn work(&mut self, budget: Duration) -> bool {
        let (trace, done) = (self.capture.trace(), self.capture.source().done);
        let (more, changed) = self.screen.work(trace, done, budget);
        self.dirty |= changed;
        more
    }

    /// Periodic update of the frame rate and of node liveness.
    pub fn tick(&mut self) {
        self.liveness_tick(Instant::now());
        if self.capture.rate_tick() {
            self.dirty = true;
        }
    }

    /// Advances the node table and the trigger to the capture time at wall time `now`
    /// (live and replay).
    fn liveness_tick(&mut self, now: Instant) {
        let mut q = Queue::default();
        if self.capture.liveness_tick(now, &mut q) {
            self.dirty = true;
        }
        if let Some(t) = self.capture.now_ns(now)
            && self.screen.trigger_tick(self.capture.trace(), t)
        {
            self.dirty = true;
        }
        self.route(q);
    }

    /// Does what the queued events ask, oldest first (an event may queue more).
    fn route(&mut self, mut q: Queue) {
        while let Some(e) = q.pop() {
            self.dirty = true;
            match e {
                Event::Say(level, text) => self.screen.say(level, &text),
                Event::Log(level, text) => self.screen.log(level, &text),
                Event::Note(text) => self.screen.set_message(Some(text)),
                Event::Reset => self.screen.reset(),
                Event::Result(level, text) => {
                    self.screen.say(level, &text);
                    let objects = self.screen.objects_mut();
                    read_all::result(&self.capture, objects, &self.bindings, &text, &mut q);
                }
                Event::Stopped(level, text, failed) => self.stopped(level, &text, &failed),
                Event::Follow(on) => self.screen.follow(on),
                Event::Object(r) => self.object_request(r, &mut q),
                Event::Detail => self.screen.toggle_detail(),
                Event::Filter(text) => self.screen.show_filtered(self.capture.trace(), &text),
                Event::Show(pos) => self.screen.show(self.capture.trace(), pos),
                Event::Select(pos) => self.screen.select_in_trace(self.capture.trace(), pos),
                Event::Run(line) => self.run_command(&line),
                Event::Act(a) => self.act(a),
                Event::Replay(a) => self.capture.replay_key(a, &mut q),
                Event::StopAll(nodes, options) => {
                    watch::stop_all(self.screen.watch_mut(), &mut q);
                    let pane = self.screen.transmit_mut();
                    transmit::disable_all(&self.capture, pane, &self.bindings, &mut q);
                    let objects = self.screen.objects_mut();
                    stop::stop_all(&self.capture, objects, &nodes, options, &mut q);
                }
                Event::TransmitStopped(why) => {
                    let pane = self.screen.transmit_mut();
                    transmit::stopped_elsewhere(pane, &self.bindings, &why, &mut q);
                }
                Event::Quit => self.request_quit(),
                Event::Watch(ask) => {
                    let (pane, objects) = self.screen.watch_and_objects();
                    if let Some(text) = watch::ask(&self.capture, pane, objects, ask, &mut q) {
                        self.screen.prompt_mut().open(PromptKind::Palette, &text);
                    }
                }
                Event::Transmit(ask) => {
                    let pane = self.screen.transmit_mut();
                    if let Some((text, cursor)) = transmit::ask(&self.capture, pane, &self.bindings, ask, &mut q) {
                        self.screen.prompt_mut().open_at(PromptKind::Transmit, &text, cursor);
                    }
                }
            }
        }
    }

    /// What the panes see: the trace, the page height, whether the capture is paused.
    pub fn ctx(&self) -> Ctx<'_> {
        self.screen.ctx(self.capture.trace(), self.capture.source().paused)
    }

    /// Handles a key press.
    pub fn key(&mut self, ev: KeyEvent) {
        self.dirty = true;
        // A question waiting for a key takes that key, whatever it is: it answers and does
        // nothing else, except that a key opening a prompt (`:`, `/`, the search key) also
        // opens it afresh, so the line typed next goes there, never to the keymap.
        if let Some(nodes) = self.screen.take_quit_confirm() {
            match ev.code {
                KeyCode::Char('y') => self.quit = true,
                KeyCode::Char('s') => {
                    self.quit_after_stop = true;
                    self.stop_all(&nodes, Default::default());
                }
                _ => {
                    self.screen.set_message(Some("not quitting".into()));
                    self.reopen_prompt(&ev);
                }
            }
            return;
        }
        if let Some(p) = self.screen.take_confirm() {
            if ev.code == KeyCode::Char('y') {
                self.send(p);
            } else {
                self.screen.set_message(Some("not sent".into()));
                self.reopen_prompt(&ev);
            }
            return;
        }
        if self.screen.popup_key(ev, self.capture.trace(), &self.keymap) {
            return;
        }
        if self.screen.prompt().editing().is_some() {
            // The candidates a completion lists stay on the status line; else the preview.
            if !self.prompt_key(ev) {
                self.preview();
            }
            if let Some(p) = self.screen.prompt().editing().filter(|p| p.kind == PromptKind::Find) {
                let text = p.text.clone();
                self.screen.find_objects(&text);
            }
            return;
        }
        let Some(k) = Key::from_event(&ev) else { return };
        self.screen.pending().push(k);
        match self.keymap.lookup(self.screen.pending()) {
            Lookup::Action(a) => {
                self.screen.pending().clear();
                self.act(a);
            }
            Lookup::Pending => {}
            Lookup::None => {
                self.screen.pending().clear();
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
            self.screen.pending().clear();
            self.act(a);
        }
    }

    /// The question waiting for a key, if any: the key hint first (`y send · any other key
    /// cancels`), then what it is about.
    pub fn question(&self) -> Option<(String, String)> {
        self.screen.question(&self.keymap)
    }

    /// Edits the prompt line; true when a completion listed its candidates.
    fn prompt_key(&mut self, ev: KeyEvent) -> bool {
        match self.screen.prompt_mut().key(ev) {
            Edit::Submit(kind, text) => self.submit(kind, &text),
            Edit::Complete => {
                let before = self.screen.prompt().before_cursor();
                let trace = self.capture.trace();
                let words: Vec<String> = if let Some(rest) = before.strip_prefix("plot ") {
                    plot_completions(trace, rest)
                } else if before.starts_with("record ") {
                    record::words()
                } else if before.contains(' ') {
                    crate::command::syntax::completions(&before, &Heard(trace, &self.bindings))
                } else {
                    PALETTE_COMMANDS
                        .iter()
                        .chain(commander_words())
                        .map(|w| w.to_string())
                        .collect()
                };
                let shown = self
                    .screen
                    .prompt_mut()
                    .complete(&words.iter().map(String::as_str).collect::<Vec<_>>());
                if !shown.is_empty() {
                    self.screen.set_message(Some(shown.join("  ")));
                    return true;
                }
            }
            Edit::Editing | Edit::Cancelled => {}
        }
        false
    }

    /// While typing a commander line, shows the frames it would send.
    fn preview(&mut self) {
        let Some(p) = self.screen.prompt().editing() else {
            return;
        };
        let first = p.text.split_whitespace().next().unwrap_or("");
        if p.kind == PromptKind::Palette && commander_words().contains(&first) {
            // The preview says before enter when nothing can go out.
            let blocked = if self.capture.listen_only() {
                Some("listen-only")
            } else if !self.capture.has_bus() {
                Some("this source has no bus")
            } else {
                None
            };
            let said = match self.plan(&p.text) {
                Ok(pl) => match blocked {
                    Some(why) => format!("blocked: {why} — would send {}", pl.preview),
                    None => format!("will send: {}", pl.preview),
                },
                Err(e) => e.to_string(),
            };
            self.screen.set_message(Some(said));
        }
    }

    /// Plans a commander line ([`palette::plan`]), with the second-producer warning
    /// ([`palette::warn_second_producer`]).
    fn plan(&self, line: &str) -> Result<Planned, crate::command::CommandError> {
        let mut p = palette::plan(line, &self.bindings, |n| self.capture.drive_state(n))?;
        let trace = self.capture.trace();
        palette::warn_second_producer(&mut p, trace, crate::tui::panes::start_ns(trace));
        Ok(p)
    }

    /// Runs a commander line: asks for confirmation first when it needs one.
    fn commander(&mut self, line: &str) {
        match self.plan(line) {
            Ok(p) => match p.confirm.clone() {
                Some(why) => self.screen.ask_confirm(p, &why),
                None => self.send(p),
            },
            Err(e) => self.screen.set_message(Some(e.to_string())),
        }
    }

    fn send(&mut self, p: Planned) {
        let text = format!("{}: sending {}", p.line, p.preview);
        let sent = self.capture.request(Request::Run {
            line: p.line,
            command: p.command,
        });
        if sent {
            self.screen.say(Level::Info, &text);
        } else {
            self.screen.say(
                Level::Error,
                "not sent: this source has no bus (use `cotui live IFACE` or `cotui demo`)",
            );
        }
    }

    /// The drives stop-all stops: those cotui commanded, those seen powered, and `extra`.
    pub fn stop_targets(&self, extra: &[u8]) -> BTreeSet<u8> {
        stop::targets(&self.capture, extra)
    }

    /// The emergency stop (see [`stop::stop_all`]).
    fn stop_all(&mut self, extra: &[u8], options: crate::command::stop::StopOptions) {
        let mut q = Queue::default();
        q.push(Event::StopAll(extra.to_vec(), options));
        self.route(q);
    }

    /// A stop-all ended (`failed`: the nodes not confirmed stopped): says how, and quits
    /// when the user asked to stop before quitting and every drive is confirmed stopped.
    fn stopped(&mut self, level: Level, text: &str, failed: &[u8]) {
        self.screen.say(level, text);
        if !std::mem::take(&mut self.quit_after_stop) {
            return;
        }
        if level == Level::Info && failed.is_empty() {
            self.quit = true;
        } else if failed.is_empty() {
            self.screen
                .say(Level::Error, "not quitting: the stop-all failed (see the message log)");
        } else {
            let nodes = failed.iter().map(u8::to_string).collect::<Vec<_>>().join(", ");
            self.screen.say(
                Level::Error,
                &format!("not quitting: node(s) {nodes} NOT confirmed stopped (see the message log)"),
            );
        }
    }

    /// Quits, unless a drive cotui commanded is still powered: then asks first.
    fn request_quit(&mut self) {
        let powered = stop::still_powered(&self.capture);
        if powered.is_empty() {
            self.quit = true;
        } else {
            self.screen.ask_quit(powered, &self.keymap);
        }
    }

    /// Runs a line entered at a prompt (the filter, search or palette prompt).
    fn submit(&mut self, kind: PromptKind, text: &str) {
        let trace = self.capture.trace();
        let applied = match kind {
            PromptKind::Filter => self.screen.apply_filter(trace, text),
            PromptKind::Search => self.screen.apply_search(trace, text),
            PromptKind::Palette => {
                self.run_command(text);
                Ok(())
            }
            PromptKind::Find => {
                self.screen.find_objects(text);
                Ok(())
            }
            PromptKind::Transmit => {
                let mut q = Queue::default();
                let pane = self.screen.transmit_mut();
                match transmit::submit(&self.capture, pane, &self.bindings, text, &mut q) {
                    Ok(()) => self.route(q),
                    Err(e) => {
                        self.screen
                            .prompt_mut()
                            .open_at(PromptKind::Transmit, text, text.chars().count());
                        self.screen.set_message(Some(e));
                    }
                }
                return;
            }
        };
        // A bad expression keeps the prompt open with the text, the cursor where it is wrong.
        if let Err(e) = applied {
            self.screen.reopen(kind, text, e.column);
        }
    }

    /// Applies a filter text; a parse error goes to the status bar and keeps the old filter.
    pub fn set_filter(&mut self, text: &str) {
        let _ = self.screen.apply_filter(self.capture.trace(), text);
    }

    /// Loads the transmit list file at `path` into the Transmit pane and sends its enabled
    /// entries (`--transmit FILE`); a bad entry is shown with its line, the others work.
    pub fn load_transmit(&mut self, path: &std::path::Path) -> Result<(), String> {
        let mut q = Queue::default();
        let pane = self.screen.transmit_mut();
        transmit::load(&self.capture, pane, &self.bindings, path, &mut q)?;
        self.route(q);
        Ok(())
    }

    /// Runs a palette line: a built-in command ([`commands::run`]) or a commander line;
    /// the result goes to the status bar.
    pub fn run_command(&mut self, line: &str) {
        self.dirty = true;
        let mut q = Queue::default();
        if line.split_whitespace().next() == Some("watch") {
            watch::command(&self.capture, self.screen.watch_mut(), &self.bindings, line, &mut q);
        } else if commands::run(line, &mut self.capture, &mut self.screen, &mut q) == Ran::Commander {
            self.commander(line);
        }
        self.route(q);
    }

    /// Does what the Objects pane asked.
    fn object_request(&mut self, r: ObjectRequest, q: &mut Queue) {
        let objects = self.screen.objects_mut();
        match r {
            ObjectRequest::Read { node, index, sub } => {
                read_all::read(&self.capture, objects, &self.bindings, (node, index, sub), q)
            }
            ObjectRequest::ReadAll { node, objects: list } => {
                read_all::start(&self.capture, objects, &self.bindings, &self.keymap, (node, list), q)
            }
            ObjectRequest::Edit { .. } if self.capture.listen_only() => self.screen.say(
                Level::Error,
                "write: listen-only — nothing can be sent, so no object can be written",
            ),
            ObjectRequest::Edit { text, cursor, note } => {
                self.screen.prompt_mut().open_at(PromptKind::Palette, &text, cursor);
                self.preview();
                let message = match self.screen.take_message() {
                    Some(m) => format!("{note} · {m}"),
                    None => note,
                };
                self.screen.set_message(Some(message));
            }
            ObjectRequest::Find(text) => self.screen.prompt_mut().open(PromptKind::Find, &text),
            ObjectRequest::Note(text) => self.screen.set_message(Some(text)),
        }
    }

    /// The timestamp of the first frame.
    pub fn start_ns(&self) -> u64 {
        super::panes::start_ns(self.capture.trace())
    }

    /// The trace position of the selected row of the trace.
    pub fn selected_position(&self) -> Option<usize> {
        self.screen.selected_position(self.capture.trace())
    }

    /// What the Detail pane shows: the focused pane's selection, else the trace's.
    pub fn selected(&self) -> Option<Selected> {
        self.screen.selected(self.capture.trace(), self.capture.source().paused)
    }

    /// Does what an action says: the screen offers it to its popups and the focused pane
    /// and does what is its own; the rest (quit, stop-all, replay keys, what the panes ask
    /// of the capture) comes back as events, routed here.
    pub fn act(&mut self, a: Action) {
        self.dirty = true;
        let mut q = Queue::default();
        let (trace, paused) = (self.capture.trace(), self.capture.source().paused);
        self.screen.act(a, trace, paused, &self.keymap, &mut q);
        self.route(q);
    }

    /// Handles a mouse event: the wheel scrolls the focused pane, a left click selects a row.
    pub fn mouse(&mut self, ev: MouseEvent) {
        self.dirty = true;
        self.screen
            .mouse(ev, self.capture.trace(), self.capture.source().paused);
    }

    /// Before drawing: the screen fits its panes to `height` rows, the trace window to
    /// `rows` rows and the tail strip `tail` (see [`Screen::prepare`]).
    pub fn prepare(&mut self, height: usize, rows: usize, tail: &[usize]) {
        let (trace, paused) = (self.capture.trace(), self.capture.source().paused);
        self.screen.prepare(trace, paused, height, rows, tail);
    }
}

/// `plot NODE INDEX:SUB`: the nodes with a series, then that node's series.
fn plot_completions(trace: &Trace, rest: &str) -> Vec<String> {
    let done: Vec<&str> = if rest.ends_with(' ') || rest.is_empty() {
        rest.split_whitespace().collect()
    } else {
        let w: Vec<&str> = rest.split_whitespace().collect();
        w[..w.len() - 1].to_vec()
    };
    let keys = trace.series.keys();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::stop::StopOptions;
    use crate::tui::panes::testutil::{app, frames};
    use crate::tui::source::{Control, Feed};
    use crossterm::event::{KeyEvent, KeyModifiers};
    use crossterm::event::{MouseButton, MouseEventKind};
    use ratatui::layout::Rect;

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
            a.capture_mut().trace_mut().clear();
            *a.capture_mut().source_mut() = SourceInfo::new("x.log", kind, frx, None);
            ftx.send(Feed::frames(frames())).unwrap();
            (a, ftx)
        };
        let (mut a, ftx) = fresh(SourceKind::Open);
        a.ingest(Duration::from_millis(100));
        assert!(a.trace().transactions.is_empty(), "still running while the log is read");
        ftx.send(Feed::Done).unwrap();
        a.ingest(Duration::from_millis(100));
        let list = &a.trace().transactions;
        let t = list.get(0).expect("one transfer");
        assert_eq!(
            (list.len(), t.outcome.as_str(), t.cut_short_of()),
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
        assert!(a.trace().transactions.is_empty(), "not at the end yet");
        ftx.send(Feed::Position(at)).unwrap();
        ftx.send(Feed::Position(at)).unwrap();
        a.ingest(Duration::from_millis(100));
        assert_eq!(a.trace().transactions.len(), 1, "listed once");
    }

    /// A listen-only live app, `before` done on it, then fed node 5's heartbeat every 100 ms
    /// for 0.5 s of capture time from its node table's now (returned).
    fn live_app_with_heartbeats(before: impl FnOnce(&mut App)) -> (App, u64) {
        let (ftx, frx) = std::sync::mpsc::channel();
        let (rtx, _rrx) = tokio::sync::mpsc::unbounded_channel();
        let mut a = app();
        *a.capture_mut().source_mut() = SourceInfo::live("vcan0", SourceKind::Live { listen_only: true }, frx, rtx);
        let t0 = a.trace().nodes.now_ns();
        before(&mut a);
        let batch: Vec<crate::frame::Frame> = (1..=5u64)
            .map(|i| {
                let mut f = crate::frame::Frame::classic(0x705, &[0x05]);
                f.ts_ns = t0 + i * 100_000_000;
                f
            })
            .collect();
        ftx.send(Feed::frames(batch)).unwrap();
        a.ingest(Duration::from_millis(100));
        (a, t0)
    }

    #[test]
    fn a_live_node_that_falls_silent_is_lost_by_the_capture_clock() {
        let (mut a, t0) = live_app_with_heartbeats(|a| {
            a.capture_mut().trace_mut().nodes.take_events();
        });
        let taken = Instant::now();
        // Node 2 (heartbeats every 14 ms in the capture) was found lost by these frames.
        assert!(
            a.trace()
                .nodes
                .liveness(crate::frame::NodeKey::new(0, 2))
                .unwrap()
                .is_lost()
        );
        assert!(
            !a.trace()
                .nodes
                .liveness(crate::frame::NodeKey::new(0, 5))
                .unwrap()
                .is_lost()
        );
        // No frame comes for a second of wall time: node 5 (every 100 ms) is lost too,
        // dated 150 ms after its last heartbeat.
        a.liveness_tick(taken + Duration::from_secs(1));
        let l = a.trace().nodes.liveness(crate::frame::NodeKey::new(0, 5)).unwrap();
        assert_eq!(l.lost_at_ns, Some(t0 + 650_000_000));
        let msg = a.message().map(str::to_string).unwrap_or_default();
        assert!(
            msg.starts_with("node 5 heartbeat lost: no heartbeat for 150.0 ms"),
            "{msg}"
        );
        let names: Vec<(Option<u8>, &str)> = a
            .capture()
            .node_events()
            .iter()
            .map(|e| (e.node, e.what.name()))
            .collect();
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
        a.capture_mut().source_mut().bus_error = Some("vcan0 is down".into());
        assert_eq!(a.capture().now_ns(taken + Duration::from_secs(9)), None);
        a.capture_mut().source_mut().bus_error = None;
        a.capture_mut().source_mut().kind = SourceKind::Replay { speed: 1.0 };
        a.capture_mut().source_mut().paused = true;
        assert_eq!(a.capture().now_ns(taken + Duration::from_secs(9)), None);
    }

    #[test]
    fn hb_lost_on_a_silent_live_bus_is_a_trigger_hit_by_the_capture_clock() {
        let (mut a, _) = live_app_with_heartbeats(|a| a.run_command("trigger hb lost"));
        while a.work(Duration::from_millis(100)) {}
        let taken = Instant::now();
        let hits = |a: &App| a.screen().trigger().map(|t| t.hits().to_vec()).unwrap_or_default();
        let before = hits(&a);
        let last = a.trace().len() - 1;
        assert!(!before.contains(&last), "node 5 beats every 100 ms: {before:?}");
        // No frame for a second: no frame brings node 5's loss, the capture clock does, and
        // the hit is marked at the last frame before it.
        a.liveness_tick(taken + Duration::from_secs(1));
        assert_eq!(hits(&a), [before.clone(), vec![last]].concat());
        a.liveness_tick(taken + Duration::from_secs(2));
        assert_eq!(hits(&a), [before, vec![last]].concat(), "lost once");
    }

    #[test]
    fn replay_keys_send_pause_step_speed_and_seek() {
        let (_ftx, frx) = std::sync::mpsc::channel();
        let (ctx, crx) = std::sync::mpsc::channel();
        let mut a = app();
        *a.capture_mut().source_mut() = SourceInfo::new("r.log", SourceKind::Replay { speed: 1.0 }, frx, Some(ctx));
        a.act(Action::Step);
        assert_eq!(a.message(), Some("step: pause a replay first"));
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
        assert_eq!(a.source().kind, SourceKind::Replay { speed: 2.0 });
    }

    #[test]
    fn search_jumps_between_matches_and_goto_selects() {
        let mut a = app();
        a.screen_mut().layout_mut().table = Rect::new(0, 0, 100, 10);
        a.run_command("goto 1");
        a.run_command("search emcy");
        assert_eq!(a.selected_position(), Some(frames().len() - 1));
        assert_eq!(a.message(), Some("match 1 of 1 at frame 44"));
        // No later match: the search wraps around to the first one.
        a.run_command("search \"boot-up node 2\"");
        assert_eq!(a.message(), Some("match 1 of 1 at frame 2 (wrapped around)"));
        assert_eq!(a.selected_position(), Some(1));
        a.act(Action::PrevMatch);
        assert_eq!(a.selected_position(), Some(1));
        a.run_command("search \"no such label\"");
        assert_eq!(a.message(), Some("no match for `\"no such label\"`"));
        assert_eq!(a.selected_position(), Some(1), "no match: the selection stays");
        a.run_command("bogus");
        assert!(a.message().unwrap_or("").starts_with("unknown command `bogus`"));
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
                "plot: usage `plot NODE INDEX[:SUB]` (e.g. `plot 1 6064:00`) or `plot mode MODE`".into(),
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
            assert_eq!(a.message(), Some(want.as_str()), "{line}");
            let logged = a
                .screen()
                .messages()
                .iter()
                .last()
                .map(|e| e.text.clone())
                .unwrap_or_default();
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
        assert_eq!(a.message(), Some("1  2"), "the nodes heard");
        for c in "2 statusw".chars() {
            a.key(key(c));
        }
        a.key(tab);
        assert_eq!(
            a.screen().prompt().editing.as_ref().map(|p| p.text.as_str()),
            Some("sdo read 2 Statusword ")
        );
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        a.key(key(':'));
        for c in "plot 1 ".chars() {
            a.key(key(c));
        }
        a.key(tab);
        assert_eq!(a.message(), Some("1017:00  6041:00"));
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
            a.message(),
            // The fixture's own NMT frame (another master's, received) is warned of.
            Some(
                "blocked: this source has no bus — would send 000#8100 — warning: another NMT master is on the bus: 0x000 seen 1 time in the last 2 s, last at 0.006 s"
            )
        );
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert!(a.screen().confirming());
        a.key(key('y'));
        assert_eq!(
            a.message(),
            Some("not sent: this source has no bus (use `cotui live IFACE` or `cotui demo`)")
        );
        assert_eq!(a.screen().prompt().history, ["nmt reset-node 0"]);
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
        assert!(a.screen().confirming());
        assert_eq!(
            a.question().map(|q| q.0).as_deref(),
            Some("y send · any other key cancels")
        );
        // `:` cancels and opens a new palette: the review's `lss inquire all` goes there,
        // its `q` does not quit, its `s` does not sort.
        a.key(key(':'));
        assert!(!a.screen().confirming() && a.question().is_none());
        typed(&mut a, "lss inquire all");
        assert!(!a.quits(), "the q went to the palette");
        assert_eq!(
            a.focus(),
            Pane::Trace,
            "the s did not sort (that brings the receive list up)"
        );
        assert_eq!(
            a.screen().prompt().editing.as_ref().map(|p| p.text.as_str()),
            Some("lss inquire all")
        );
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        // Any other key only cancels: `4` does not switch to the Stats pane, `q` not quit.
        typed(&mut a, ":lss fastscan");
        a.key(enter);
        a.key(key('4'));
        assert_eq!((!a.screen().confirming(), a.focus()), (true, Pane::Trace));
        assert_eq!(a.message(), Some("not sent"));
        typed(&mut a, ":nmt stop 0");
        a.key(enter);
        a.key(key('q'));
        assert!(
            !a.quits() && !a.screen().confirming(),
            "q cancelled, and only cancelled"
        );
        // The next key is the user's again.
        a.key(key('4'));
        assert_eq!(a.focus(), Pane::Stats);
    }

    /// `app()` fed by a live source whose requests the test reads.
    fn live_app(listen_only: bool) -> (App, tokio::sync::mpsc::UnboundedReceiver<Request>) {
        let (_ftx, frx) = std::sync::mpsc::channel();
        let (rtx, rrx) = tokio::sync::mpsc::unbounded_channel();
        let mut a = app();
        *a.capture_mut().source_mut() = SourceInfo::live("vcan0", SourceKind::Live { listen_only }, frx, rtx);
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
        a.capture_mut().observe(&cw);
        a.key(ctrl('s'));
        match req.try_recv() {
            Ok(Request::StopAll { nodes, options }) => {
                assert_eq!(nodes.into_iter().collect::<Vec<_>>(), [1, 5]);
                assert_eq!(options, StopOptions::default());
            }
            other => panic!("expected a stop request, got {other:?}"),
        }
        assert_eq!(
            a.message(),
            Some("stop all: cancelling running commands; quick stop, then disable voltage on nodes 1, 5")
        );
        assert_eq!(a.screen().messages().iter().last().map(|e| e.level), Some(Level::Warn));
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
        assert_eq!(
            a.message(),
            Some(
                "blocked: listen-only — would send 000#0202 — warning: another NMT master is on the bus: 0x000 seen 1 time in the last 2 s, last at 0.006 s"
            )
        );
        // A session that can send previews what goes out.
        let (mut a, _req) = live_app(false);
        a.key(key(':'));
        for c in "nmt stop 2".chars() {
            a.key(key(c));
        }
        assert_eq!(
            a.message(),
            Some(
                "will send: 000#0202 — warning: another NMT master is on the bus: 0x000 seen 1 time in the last 2 s, last at 0.006 s"
            )
        );
    }

    #[test]
    fn stop_all_in_listen_only_says_nothing_can_be_sent() {
        let (mut a, mut req) = live_app(true);
        a.act(Action::StopAll);
        assert!(req.try_recv().is_err(), "no request in listen-only");
        assert!(a.message().unwrap_or("").contains("listen-only — NOTHING can be sent"));
        assert_eq!(a.screen().messages().iter().last().map(|e| e.level), Some(Level::Error));
    }

    #[test]
    fn quitting_with_a_commanded_drive_powered_asks_first() {
        let (mut a, _req) = live_app(false);
        a.act(Action::Quit);
        assert!(a.quits(), "nothing commanded: quits at once");
        let (mut a, mut req) = live_app(false);
        let mut cw = crate::frame::Frame::classic(0x601, &[0x2B, 0x40, 0x60, 0, 0x0F, 0, 0, 0]);
        cw.flags.set(crate::frame::Flags::TX, true);
        a.capture_mut().observe(&cw);
        a.act(Action::Quit);
        assert!(!a.quits());
        assert_eq!(
            a.question(),
            Some((
                "y quit · s stop them first · any other key stays".into(),
                "drive(s) 1 that cotui commanded are still powered (stop all any time: ctrl-s)".into()
            ))
        );
        a.key(key('n'));
        assert!(!a.quits() && !a.screen().quit_asked());
        assert!(req.try_recv().is_err(), "nothing sent by asking");
        a.run_command("quit");
        a.key(key('s'));
        assert!(!a.quits());
        assert!(matches!(req.try_recv(), Ok(Request::StopAll { .. })));
        a.act(Action::Quit);
        a.key(key('y'));
        assert!(a.quits());
    }

    #[test]
    fn stop_them_first_quits_once_every_drive_is_confirmed_stopped_and_stays_if_one_is_not() {
        for (level, failed, quits) in [(Level::Info, vec![], true), (Level::Warn, vec![1u8], false)] {
            let (ftx, frx) = std::sync::mpsc::channel();
            let (rtx, mut req) = tokio::sync::mpsc::unbounded_channel();
            let mut a = app();
            *a.capture_mut().source_mut() =
                SourceInfo::live("vcan0", SourceKind::Live { listen_only: false }, frx, rtx);
            let mut cw = crate::frame::Frame::classic(0x601, &[0x2B, 0x40, 0x60, 0, 0x0F, 0, 0, 0]);
            cw.flags.set(crate::frame::Flags::TX, true);
            a.capture_mut().observe(&cw);
            a.act(Action::Quit);
            a.key(key('s'));
            assert!(matches!(req.try_recv(), Ok(Request::StopAll { .. })));
            assert!(!a.quits(), "the stop is under way: not quitting yet");
            let text = if quits {
                "stop all: 1 drive(s) stopped and confirmed"
            } else {
                "stop all: 1 of 1 drive(s) NOT confirmed stopped"
            };
            ftx.send(Feed::Stopped(level, text.into(), failed)).unwrap();
            a.ingest(Duration::from_millis(50));
            assert_eq!(a.quits(), quits, "{:?}", a.message());
            if !quits {
                assert_eq!(
                    a.message(),
                    Some("not quitting: node(s) 1 NOT confirmed stopped (see the message log)")
                );
            }
        }
        // A stop-all not asked for by quitting never quits.
        let (ftx, frx) = std::sync::mpsc::channel();
        let mut a = app();
        *a.capture_mut().source_mut() = SourceInfo::new("demo", SourceKind::Demo { listen_only: false }, frx, None);
        ftx.send(Feed::Stopped(
            Level::Info,
            "stop all: 1 drive(s) stopped and confirmed".into(),
            vec![],
        ))
        .unwrap();
        a.ingest(Duration::from_millis(50));
        assert!(!a.quits());
        assert_eq!(a.message(), Some("stop all: 1 drive(s) stopped and confirmed"));
    }

    #[test]
    fn results_go_to_the_message_log_whole_and_the_status_line_shows_the_first_line() {
        let (ftx, frx) = std::sync::mpsc::channel();
        let mut a = app();
        *a.capture_mut().source_mut() = SourceInfo::new("demo", SourceKind::Demo { listen_only: false }, frx, None);
        ftx.send(Feed::Result(
            Level::Info,
            "scan: 2 nodes\nnode 2 aimotor\nnode 3 syntron-ds".into(),
        ))
        .unwrap();
        let note = |state, text: &str| crate::tui::source::BusNote {
            iface: 0,
            state,
            text: text.into(),
        };
        ftx.send(Feed::BusError(note(
            "interface down",
            "vcan0: interface went down; fix: sudo ip link set vcan0 up",
        )))
        .unwrap();
        ftx.send(Feed::BusOk(note(
            "error-active",
            "vcan0: capturing again after 2.0 s without capture",
        )))
        .unwrap();
        a.ingest(Duration::from_millis(50));
        // The recovery is the latest news on the status line; the log has all three.
        assert_eq!(a.message(), Some("vcan0: capturing again after 2.0 s without capture"));
        let lines: Vec<String> = a.screen().messages().lines().into_iter().map(|(_, l)| l).collect();
        assert_eq!(lines.len(), 5, "{lines:?}");
        assert!(lines[2].ends_with("  node 3 syntron-ds"));
        assert!(lines[3].ends_with("  vcan0: interface went down; fix: sudo ip link set vcan0 up"));
        assert!(lines[4].ends_with("  vcan0: capturing again after 2.0 s without capture"));
        a.key(key('m'));
        assert!(a.screen().log_popup().shown());
        let s = crate::tui::panes::testutil::screen(&mut a, 120, 20);
        assert!(s.contains("Messages (3)"), "{s}");
        assert!(s.contains("node 3 syntron-ds"), "{s}");
        a.act(Action::Up);
        assert_eq!(
            a.screen().log_popup().index(a.screen().messages()),
            Some(1),
            "up selects the entry before the newest"
        );
        a.act(Action::Back);
        assert!(!a.screen().log_popup().shown());
    }

    #[test]
    fn vim_keys_go_to_the_focused_pane_and_the_prompts() {
        let mut a = app();
        a.set_keymap(Keymap::load(("vim", crate::tui::keymap::VIM), &[]).unwrap());
        let _ = crate::tui::panes::testutil::screen(&mut a, 140, 20);
        for c in ['g', 'g'] {
            a.key(key(c));
        }
        assert_eq!(
            (a.selected_position(), a.screen().panes().trace().following()),
            (Some(0), false)
        );
        a.key(key('j'));
        assert_eq!(a.selected_position(), Some(1));
        a.key(key('2'));
        a.key(key('j'));
        assert_eq!(
            (a.focus(), a.screen().panes().nodes().selected_node(a.trace())),
            (Pane::Nodes, Some(crate::frame::NodeKey::new(0, 2)))
        );
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert_eq!(a.focus(), Pane::Trace);
        assert_eq!(a.screen().panes().trace().filter().source, "node 2");
        a.key(key('F'));
        assert_eq!(
            a.screen().prompt().editing.as_ref().map(|p| p.text.as_str()),
            Some("node 2")
        );
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        a.key(key('G'));
        assert!(a.screen().panes().trace().following());
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
        assert!(!a.screen().panes().trace().following());
        assert_eq!(a.selected_position(), last.map(|p| p - 3));
        a.act(Action::PaneNodes);
        let _ = crate::tui::panes::testutil::screen(&mut a, 140, 20);
        let t = a.screen().layout().table;
        a.mouse(mouse(MouseEventKind::Down(MouseButton::Left), t.y + 1));
        assert_eq!(
            a.screen().panes().nodes().selected_node(a.trace()).map(|n| n.node),
            Some(2)
        );
        // A click below the last node selects nothing new.
        a.mouse(mouse(MouseEventKind::Down(MouseButton::Left), t.y + 5));
        assert_eq!(
            a.screen().panes().nodes().selected_node(a.trace()).map(|n| n.node),
            Some(2)
        );
    }

    #[test]
    fn sdo_pane_expands_and_enter_on_a_frame_jumps_to_it_in_the_trace() {
        let mut a = app();
        a.screen_mut().layout_mut().table = Rect::new(0, 0, 100, 10);
        a.act(Action::PaneSdo);
        for _ in 0..4 {
            a.act(Action::Down);
        }
        a.act(Action::Expand);
        let s = crate::tui::panes::testutil::screen(&mut a, 100, 14);
        assert!(s.contains("SDO transfer 6041:00 node 2"), "{s}");
        a.act(Action::Down);
        a.act(Action::Expand);
        assert_eq!(a.focus(), Pane::Trace);
        assert_eq!(a.selected_position(), Some(12));
    }
}
