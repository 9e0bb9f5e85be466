//! The screen side of the application: the focus, the panes, the popups (help, message
//! log, Detail below), the prompt line, the search, the status line and its message log,
//! the questions waiting for a key, and where the last draw put things. It sees the trace
//! but never changes it; what the capture must do goes out as [`Event`]s.

use super::bookmarks::Sidecar;
use super::event::{Event, Queue};
use super::keymap::{Action, Key, Keymap};
use super::messages::{Level, Messages};
use super::palette::Planned;
use super::panes::detail::DetailPane;
use super::panes::help::HelpPopup;
use super::panes::messages::MessagesPopup;
use super::panes::objects::ObjectsPane;
use super::panes::trace_time::TimeMode;
use super::panes::{Component, Ctx, Pane, Panes, Selected};
use super::prompt::{PromptBar, PromptKind};
use super::trigger::TriggerScan;
use crate::analysis::filter::{Filter, FilterError};
use crate::analysis::search::{Found, Search};
use crate::analysis::trace::Trace;
use crate::analysis::view::View;
use crate::command::stop::StopOptions;
use crossterm::event::{KeyEvent, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use std::time::{Duration, SystemTime};

/// Where the last draw put things (for mouse clicks and page sizes).
#[derive(Clone, Copy, Debug, Default)]
pub struct Layout {
    /// Rows of the main table, without header.
    pub table: Rect,
    /// The side column (compact nodes, Detail) was shown: the terminal is wide enough.
    pub side: bool,
}

/// The screen: what is shown and where the keys go.
pub struct Screen {
    focus: Pane,
    panes: Panes,
    detail: DetailPane,
    help: HelpPopup,
    prompt: PromptBar,
    search: Option<Search>,
    message: Option<String>,
    messages: Messages,
    log_popup: MessagesPopup,
    layout: Layout,
    /// A commander line waiting for `y`.
    confirm: Option<Planned>,
    /// Quitting waits for `y`: these drives cotui commanded are still powered.
    quit_confirm: Option<Vec<u8>>,
    /// The keys of a binding typed so far.
    pending: Vec<Key>,
    /// Text waiting to go to the terminal's clipboard (see [`Screen::take_clipboard`]).
    clipboard: Option<String>,
    /// Where the bookmarks of the log opened go (`cotui open FILE`; none live).
    bookmarks: Option<Sidecar>,
}

impl Default for Screen {
    fn default() -> Screen {
        Screen {
            focus: Pane::Trace,
            panes: Panes::default(),
            detail: DetailPane::default(),
            help: HelpPopup::default(),
            prompt: PromptBar::default(),
            search: None,
            message: None,
            messages: Messages::default(),
            log_popup: MessagesPopup::default(),
            layout: Layout::default(),
            confirm: None,
            quit_confirm: None,
            pending: Vec::new(),
            clipboard: None,
            bookmarks: None,
        }
    }
}

impl Screen {
    /// The pane in the main area (the one keys go to).
    pub fn focus(&self) -> Pane {
        self.focus
    }

    /// Brings pane `p` to the main area.
    pub fn focus_on(&mut self, p: Pane) {
        self.focus = p;
    }

    /// The main-area panes (each owns its selection and what it shows).
    pub fn panes(&self) -> &Panes {
        &self.panes
    }

    /// The Objects pane, for the read-all that runs through it.
    pub(crate) fn transmit_mut(&mut self) -> &mut super::panes::transmit::TransmitPane {
        self.panes.transmit_mut()
    }

    /// The Watch pane, to change.
    pub(crate) fn watch_mut(&mut self) -> &mut super::panes::watch::WatchPane {
        self.panes.watch_mut()
    }

    /// The Watch pane and the Objects pane, to change both (enter on a watched object).
    pub(crate) fn watch_and_objects(&mut self) -> (&mut super::panes::watch::WatchPane, &mut ObjectsPane) {
        self.panes.watch_and_objects()
    }

    /// The Objects pane, to change.
    pub(crate) fn objects_mut(&mut self) -> &mut ObjectsPane {
        self.panes.objects_mut()
    }

    /// The Detail pane (beside the main pane, or toggled below it on a narrow terminal).
    pub fn detail(&self) -> &DetailPane {
        &self.detail
    }

    /// The help popup.
    pub fn help(&self) -> &HelpPopup {
        &self.help
    }

    /// The help popup, to change (tests show it).
    #[cfg(test)]
    pub(crate) fn help_mut(&mut self) -> &mut HelpPopup {
        &mut self.help
    }

    /// The prompt line (filter, search, palette) and its history.
    pub fn prompt(&self) -> &PromptBar {
        &self.prompt
    }

    /// The prompt line, to change.
    pub(crate) fn prompt_mut(&mut self) -> &mut PromptBar {
        &mut self.prompt
    }

    /// The search in force (`n`/`N`), running over the trace pane's view in the background.
    pub fn search(&self) -> Option<&Search> {
        self.search.as_ref()
    }

    /// The message in the status line (result of the last command).
    pub fn message(&self) -> Option<&str> {
        self.message.as_deref()
    }

    /// Shows `text` in the status line (None clears it), without logging it.
    pub fn set_message(&mut self, text: Option<String>) {
        self.message = text;
    }

    /// Takes the message off the status line.
    pub fn take_message(&mut self) -> Option<String> {
        self.message.take()
    }

    /// Every result, event and error of the session.
    pub fn messages(&self) -> &Messages {
        &self.messages
    }

    /// The message log, to add to (tests fill it).
    #[cfg(test)]
    pub(crate) fn messages_mut(&mut self) -> &mut Messages {
        &mut self.messages
    }

    /// The message log popup.
    pub fn log_popup(&self) -> &MessagesPopup {
        &self.log_popup
    }

    /// The message log popup, to size before a draw.
    pub fn log_popup_mut(&mut self) -> &mut MessagesPopup {
        &mut self.log_popup
    }

    /// Layout of the last draw.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// The layout, set by the draw.
    pub fn layout_mut(&mut self) -> &mut Layout {
        &mut self.layout
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
    }

    /// Logs `text` without touching the status line.
    pub fn log(&mut self, level: Level, text: &str) {
        self.messages.push(SystemTime::now(), level, text);
    }

    /// Visible height of the main table.
    pub(crate) fn page(&self) -> usize {
        (self.layout.table.height as usize).max(1)
    }

    /// What the panes see: the trace, the page height, whether the capture is paused.
    pub(crate) fn ctx<'a>(&self, trace: &'a Trace, paused: bool) -> Ctx<'a> {
        Ctx {
            trace,
            page: self.page(),
            paused,
        }
    }

    /// The trace started over: the views forget their rows (the filter and search stay).
    pub(crate) fn reset(&mut self) {
        // A replay going back is no longer at its end.
        if self.message.as_deref() == Some("replay finished") {
            self.message = None;
        }
        self.panes.trace_mut().reset();
        self.restart_search();
        self.detail.reset();
    }

    /// Background work: filter scanning and the search; returns (work is left, something
    /// changed on screen).
    pub(crate) fn work(&mut self, trace: &Trace, done: bool, budget: Duration) -> (bool, bool) {
        let (more, changed) = self.panes.trace_mut().work(trace, done, budget);
        if changed && let Some(t) = self.panes.trace().trigger() {
            let hits: Vec<u64> = t.hits().iter().map(|&p| trace.store.packed(p).ts_ns).collect();
            self.panes.plot_mut().set_hits(hits);
        }
        let (searching, found) = self.search_work(trace, done, budget);
        (more || searching, changed || found)
    }

    /// Searches on; a jump that waited for its match goes there now.
    fn search_work(&mut self, trace: &Trace, done: bool, budget: Duration) -> (bool, bool) {
        let Some(s) = &mut self.search else {
            return (false, false);
        };
        if done {
            s.settle();
        }
        let before = (s.count(), s.progress(trace));
        let more = s.advance(trace, budget);
        let mut changed = (s.count(), s.progress(trace)) != before;
        if let Some(found) = s.poll(trace) {
            changed = true;
            self.show_found(trace, found);
        }
        (more, changed)
    }

    /// Follows the newest frame (`true`) or stays on the selection.
    pub(crate) fn follow(&mut self, on: bool) {
        self.panes.trace_mut().set_follow(on);
    }

    /// Parses a filter or search with the object names of the dictionaries in use.
    fn parse_expr(&mut self, trace: &Trace, what: &str, text: &str) -> Result<Filter, FilterError> {
        Filter::parse_with(text, trace.decoder()).inspect_err(|e| self.message = Some(format!("{what}: {e}")))
    }

    /// Applies a filter text; a parse error goes to the status bar and keeps the old filter.
    pub(crate) fn apply_filter(&mut self, trace: &Trace, text: &str) -> Result<(), FilterError> {
        let f = self.parse_expr(trace, "filter", text)?;
        let page = self.page();
        self.panes.trace_mut().set_filter(trace, f, page);
        self.message = None;
        self.restart_search();
        Ok(())
    }

    /// Starts a search and jumps to its first match after the selection (when found).
    pub(crate) fn apply_search(&mut self, trace: &Trace, text: &str) -> Result<(), FilterError> {
        let f = self.parse_expr(trace, "search", text)?;
        if f.is_empty() {
            self.search = None;
            return Ok(());
        }
        let mut s = Search::new(f, self.panes.trace().filter());
        s.advance(trace, Duration::from_millis(30));
        self.search = Some(s);
        self.jump_match(trace, true);
        Ok(())
    }

    /// `:trigger EXPR [--pre DUR] [--post DUR]` puts a trigger in force (its hits marked
    /// in the Trace and the Plot, walked with `n`/`N` when no search is); `:trigger off`
    /// or an empty text ends it. A parse error (with its column) goes to the status bar.
    pub(crate) fn apply_trigger(&mut self, trace: &Trace, text: &str) -> Result<String, String> {
        if text.is_empty() || text == "off" {
            self.panes.trace_mut().set_trigger(None);
            self.panes.plot_mut().set_hits(Vec::new());
            return Ok("trigger off".into());
        }
        let mut t = TriggerScan::parse(text, trace).map_err(|e| format!("trigger: {e}"))?;
        t.advance(trace, Duration::from_millis(30));
        let hits: Vec<u64> = t.hits().iter().map(|&p| trace.store.packed(p).ts_ns).collect();
        let summary = t.summary(trace);
        self.panes.trace_mut().set_trigger(Some(t));
        self.panes.plot_mut().set_hits(hits);
        Ok(summary)
    }

    /// The capture clock reached `now_ns` with no new frame: the trigger's time-only hits
    /// (`hb lost` on a silent bus); true when one was found.
    pub(crate) fn trigger_tick(&mut self, trace: &Trace, now_ns: u64) -> bool {
        self.panes.trace_mut().trigger_tick(trace, now_ns)
    }

    /// The trigger in force.
    pub fn trigger(&self) -> Option<&TriggerScan> {
        self.panes.trace().trigger()
    }

    /// Keeps the bookmarks of `log` (opened with `cotui open`) in its sidecar file, and
    /// shows those kept there.
    pub fn keep_bookmarks(&mut self, log: &std::path::Path) {
        let mut side = Sidecar::of(log);
        match side.load() {
            Ok(marks) => {
                if !marks.is_empty() {
                    self.message = Some(format!("{} bookmarks from {}", marks.len(), side.path.display()));
                }
                self.panes.trace_mut().set_marks(marks);
            }
            Err(e) => self.log(Level::Warn, &format!("bookmarks not loaded: {e}")),
        }
        self.bookmarks = Some(side);
    }

    /// The bookmarks, one line each: `#FRAME at T s (note)`.
    pub fn bookmark_lines(&self, trace: &Trace) -> Vec<String> {
        let start = super::panes::start_ns(trace);
        self.panes
            .trace()
            .marks_with_times(trace)
            .into_iter()
            .map(|(p, ns)| {
                let note = self
                    .bookmarks
                    .as_ref()
                    .and_then(|b| b.note(p))
                    .map(|n| format!(" ({n})"))
                    .unwrap_or_default();
                format!("#{} at {:.6} s{note}", p + 1, ns.saturating_sub(start) as f64 / 1e9)
            })
            .collect()
    }

    /// Writes the bookmarks to the sidecar file (when the log has one).
    fn save_bookmarks(&mut self, trace: &Trace) {
        let Some(side) = &self.bookmarks else { return };
        if let Err(e) = side.save(&self.panes.trace().marks_with_times(trace)) {
            self.log(Level::Error, &format!("bookmarks not saved: {e}"));
            self.message = Some(format!("bookmarks not saved: {e}"));
        }
    }

    /// Jumps to the next (or previous) hit of the trigger, wrapping.
    fn jump_hit(&mut self, trace: &Trace, forward: bool) {
        let from = self.selected_position(trace);
        let Some(t) = self.panes.trace().trigger() else { return };
        let Some((rank, pos, wrapped)) = t.step(from, forward) else {
            self.message = Some(format!("trigger {}: no hit yet", t.trigger.source));
            return;
        };
        let wrap = if wrapped { " (wrapped around)" } else { "" };
        self.message = Some(format!(
            "trigger hit {} of {} at frame {}{wrap}",
            rank + 1,
            t.hits().len(),
            pos + 1
        ));
        self.select_position(trace, pos);
    }

    /// Shows the help popup (`help` in the palette).
    pub(crate) fn show_help(&mut self) {
        self.help.show();
    }

    /// The trace pane's view (the rows the filter in force shows).
    pub fn view(&self) -> &View {
        self.panes.trace().view()
    }

    /// Sets the Objects pane's query (what the Find prompt typed).
    pub(crate) fn find_objects(&mut self, text: &str) {
        self.panes.objects_mut().set_query(text);
    }

    /// After a prompt refused `text` (a bad expression): opens it again with the text, the
    /// cursor where it is wrong.
    pub(crate) fn reopen(&mut self, kind: PromptKind, text: &str, column: usize) {
        self.prompt.open_at(kind, text, column.saturating_sub(1));
    }

    /// The search in force starts over (the filter it searches within changed).
    fn restart_search(&mut self) {
        if let Some(s) = self.search.take() {
            self.search = Some(Search::new(s.filter, self.panes.trace().filter()));
        }
    }

    /// The trace position of the selected row of the trace.
    pub(crate) fn selected_position(&self, trace: &Trace) -> Option<usize> {
        self.panes.trace().selected_position(trace)
    }

    /// What the Trace pane's time column shows.
    pub(crate) fn time_mode(&self) -> TimeMode {
        self.panes.trace().time_mode()
    }

    /// Shows the Trace pane's time column in `mode`.
    pub(crate) fn set_time_mode(&mut self, mode: TimeMode) {
        self.panes.trace_mut().set_time_mode(mode);
    }

    /// Shows trace position `pos` in the Trace pane.
    pub(crate) fn select_position(&mut self, trace: &Trace, pos: usize) {
        let page = self.page();
        self.focus = Pane::Trace;
        self.panes.trace_mut().select_position(trace, pos, page);
    }

    /// Selects trace position `pos` in the Trace pane (the nearest row its filter
    /// shows), the focus staying.
    pub(crate) fn select_in_trace(&mut self, trace: &Trace, pos: usize) {
        let page = self.page();
        self.panes.trace_mut().select_position(trace, pos, page);
    }

    /// Shows trace position `pos` in the Trace pane, unfiltered.
    pub(crate) fn show(&mut self, trace: &Trace, pos: usize) {
        let page = self.page();
        self.panes.trace_mut().show(trace, pos, page);
        self.focus = Pane::Trace;
    }

    /// Jumps to the next (or previous) match of the search; when the search has not got
    /// there yet, the jump waits for it and the selection stays.
    fn jump_match(&mut self, trace: &Trace, forward: bool) {
        let from = self.selected_position(trace);
        let Some(s) = &mut self.search else {
            self.message = Some("no search: press the search key first".into());
            return;
        };
        let found = s.find(trace, from, forward);
        if found == Found::Searching {
            s.ask(from, forward);
            self.message = Some(format!(
                "searching `{}`: {}% searched, the selection stays until a match is found",
                s.filter.source,
                s.progress(trace)
            ));
            return;
        }
        self.show_found(trace, found);
    }

    /// Selects a match the search found and says which one it is.
    fn show_found(&mut self, trace: &Trace, found: Found) {
        let Some(s) = &self.search else { return };
        match found {
            Found::At { pos, wrapped } => {
                let of = if s.complete(trace) {
                    format!("{} of {}", s.rank(pos), s.count())
                } else {
                    format!("{} of {} so far", s.rank(pos), s.count())
                };
                let wrap = if wrapped { " (wrapped around)" } else { "" };
                self.message = Some(format!("match {of} at frame {}{wrap}", pos + 1));
                self.select_position(trace, pos);
            }
            Found::Nothing => self.message = Some(format!("no match for `{}`", s.filter.source)),
            Found::Searching => {}
        }
    }

    /// `plot NODE INDEX:SUB`: shows that series in the Plot pane; false when none was seen.
    pub(crate) fn plot(&mut self, trace: &Trace, node: u8, index: u16, sub: u8) -> bool {
        let ok = self.panes.plot_mut().select(trace, node, index, sub);
        if ok {
            self.focus = Pane::Plot;
        }
        ok
    }

    /// `plot mode ...`: lays out the Plot pane's y axes; the Plot pane comes to the front.
    pub(crate) fn set_plot_mode(&mut self, mode: super::panes::plot::PlotMode) {
        self.panes.plot_mut().set_mode(mode);
        self.focus = Pane::Plot;
    }

    /// What the Detail pane shows: the focused pane's selection, else the trace's.
    pub fn selected(&self, trace: &Trace, paused: bool) -> Option<Selected> {
        self.panes
            .get(self.focus)
            .selected(&self.ctx(trace, paused))
            .or_else(|| self.selected_position(trace).map(Selected::Frame))
    }

    /// Tells the Objects pane the Nodes pane's selection (its node unless one is picked
    /// there): when the user selects in the Nodes pane, or while the Objects pane has none.
    /// Not on every frame: a node appearing above the selection does not change it.
    fn sync_objects_node(&mut self, trace: &Trace) {
        self.panes.sync_objects_node(trace);
    }

    /// A commander line waiting for `y`: asks.
    pub(crate) fn ask_confirm(&mut self, p: Planned, why: &str) {
        self.message = Some(format!("y send · any other key cancels — {why}: {}", p.preview));
        self.confirm = Some(p);
    }

    /// Takes the commander line waiting for `y`, if any.
    pub(crate) fn take_confirm(&mut self) -> Option<Planned> {
        self.confirm.take()
    }

    /// True while a commander line waits for `y`.
    pub fn confirming(&self) -> bool {
        self.confirm.is_some()
    }

    /// Quitting waits for `y`: the drives `powered` that cotui commanded are still powered.
    pub(crate) fn ask_quit(&mut self, powered: Vec<u8>, keymap: &Keymap) {
        self.quit_confirm = Some(powered);
        self.message = self.question(keymap).map(|(hint, text)| format!("{hint} — {text}"));
    }

    /// Puts the message log's selected entry, whole, on the clipboard and says so on the
    /// status line (not in the log, so the entry selected stays the one copied).
    fn copy_entry(&mut self) {
        let Some(e) = self.log_popup.index(&self.messages).and_then(|i| self.messages.get(i)) else {
            self.message = Some("nothing to copy: the message log is empty".into());
            return;
        };
        self.message = Some(format!(
            "copied the {} entry ({} lines) to the clipboard (OSC 52, if the terminal supports it)",
            crate::tui::messages::clock(e.at),
            e.text.lines().count().max(1)
        ));
        self.clipboard = Some(e.text.clone());
    }

    /// Takes the text waiting to go to the terminal's clipboard, if any.
    pub fn take_clipboard(&mut self) -> Option<String> {
        self.clipboard.take()
    }

    /// Takes the drives a quit question is about, if one waits.
    pub(crate) fn take_quit_confirm(&mut self) -> Option<Vec<u8>> {
        self.quit_confirm.take()
    }

    /// True while quitting waits for `y`.
    pub fn quit_asked(&self) -> bool {
        self.quit_confirm.is_some()
    }

    /// The question waiting for a key, if any: the key hint first (`y send · any other key
    /// cancels`), then what it is about.
    pub fn question(&self, keymap: &Keymap) -> Option<(String, String)> {
        if let Some(nodes) = &self.quit_confirm {
            let stop = keymap.key_for(Action::StopAll).unwrap_or_default();
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

    /// The keys of a binding typed so far, to add to or clear.
    pub(crate) fn pending(&mut self) -> &mut Vec<Key> {
        &mut self.pending
    }

    /// A key for the popups that take keys themselves (the help popup's find text, the
    /// Plot pane's signal picker); false when none takes it.
    pub(crate) fn popup_key(&mut self, ev: KeyEvent, trace: &Trace, keymap: &Keymap) -> bool {
        if self.help.shown() && self.help.typing() {
            self.help.type_key(ev, keymap);
            return true;
        }
        self.panes.plot_mut().picker_key(ev, trace)
    }

    /// Does what an action says: the message log popup takes it first while shown, then
    /// the help popup and the Detail pane below, then the focused pane, then the screen;
    /// what is the capture's (quit, stop-all, replay keys) and what the panes ask of the
    /// rest goes to `q`.
    pub(crate) fn act(&mut self, a: Action, trace: &Trace, paused: bool, keymap: &Keymap, q: &mut Queue) {
        if self.log_popup.shown() && a == Action::Copy {
            self.copy_entry();
            return;
        }
        if self.log_popup.shown() && self.log_popup.handle(a, &self.messages) {
            return;
        }
        if self.help.handle(a, keymap) {
            return;
        }
        if a == Action::Back && self.detail.shown() && !self.layout.side {
            self.detail.hide();
            return;
        }
        let focus = self.focus;
        let ctx = self.ctx(trace, paused);
        let taken = self.panes.get_mut(focus).handle(a, &ctx, q);
        if focus == Pane::Nodes {
            // A node selected in the Nodes pane is the one the Objects pane shows.
            self.sync_objects_node(trace);
        }
        if !taken {
            self.screen_action(a, trace, paused, q);
        }
        if a == Action::Bookmark {
            self.save_bookmarks(trace);
        }
    }

    /// Opens or closes the Detail view (`expand` in the trace): toggled below the main
    /// pane on a narrow terminal; beside it on a wide one it is always shown.
    pub(crate) fn toggle_detail(&mut self) {
        if !self.layout.side {
            self.detail.toggle();
        }
    }

    /// Shows the trace with the filter `text` (`expand` on a node, COB-ID or PDO row).
    pub(crate) fn show_filtered(&mut self, trace: &Trace, text: &str) {
        let _ = self.apply_filter(trace, text);
        self.focus = Pane::Trace;
    }

    /// An action no pane took.
    fn screen_action(&mut self, a: Action, trace: &Trace, paused: bool, q: &mut Queue) {
        match a {
            Action::Quit => q.push(Event::Quit),
            Action::StopAll => q.push(Event::StopAll(Vec::new(), StopOptions::default())),
            Action::Pause
            | Action::SpeedUp
            | Action::SpeedDown
            | Action::Step
            | Action::Loop
            | Action::StepBack
            | Action::Rewind
            | Action::SeekForward
            | Action::SeekBack => q.push(Event::Replay(a)),
            Action::Messages => self.log_popup.toggle(),
            Action::Back => {
                self.search = None;
                self.message = None;
            }
            Action::Follow => {
                let on = !self.panes.trace().following();
                self.panes.trace_mut().set_follow(on);
                self.focus = Pane::Trace;
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
            Action::PaneProblems => self.focus = Pane::Problems,
            Action::PaneTransmit => self.focus = Pane::Transmit,
            Action::PaneWatch => self.focus = Pane::Watch,
            Action::TransmitAdd | Action::TransmitDelete => {
                self.message = Some(format!(
                    "{}: only in the Transmit (9) and Watch (0) panes",
                    a.name().replace("transmit_", "")
                ))
            }
            Action::Copy => self.message = Some("copy: only in the message log (m)".into()),
            Action::EditObject | Action::ReadAll => {
                self.message = Some(format!("{}: only in the Objects pane", a.name().replace('_', " ")))
            }
            Action::Filter => {
                let text = self.panes.trace().filter().source.clone();
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
            Action::NextMatch | Action::PrevMatch if self.search.is_none() && self.trigger().is_some() => {
                self.jump_hit(trace, a == Action::NextMatch)
            }
            Action::NextMatch => self.jump_match(trace, true),
            Action::PrevMatch => self.jump_match(trace, false),
            Action::ClearFilter => {
                let _ = self.apply_filter(trace, "");
            }
            Action::Palette => self.prompt.open(PromptKind::Palette, ""),
            Action::NextSeries | Action::PrevSeries => {
                self.panes.plot_mut().step(trace, a == Action::NextSeries);
                self.focus = Pane::Plot;
            }
            // From another pane: the pane that does it comes to the front and takes it
            // (sorting, SYNC cycles: the Stats pane; picking, zooming: the Plot pane).
            Action::TimeMode | Action::Bookmark | Action::NextBookmark => {
                self.focus = Pane::Trace;
                let ctx = self.ctx(trace, paused);
                self.panes.get_mut(self.focus).handle(a, &ctx, q);
            }
            Action::Sort
            | Action::SyncCycles
            | Action::SlowestCycle
            | Action::NextLateCycle
            | Action::PlotPick
            | Action::PlotMode
            | Action::ZoomIn
            | Action::ZoomOut => {
                let stats = matches!(
                    a,
                    Action::Sort | Action::SyncCycles | Action::SlowestCycle | Action::NextLateCycle
                );
                self.focus = if stats { Pane::Stats } else { Pane::Plot };
                let ctx = self.ctx(trace, paused);
                self.panes.get_mut(self.focus).handle(a, &ctx, q);
            }
            // From any pane: the next frame of the incident selected in the Problems pane, so
            // that pressing it again in the trace walks through the incident's frames.
            // From any pane: the boot stories in the Problems pane.
            Action::Boots => {
                self.focus = Pane::Problems;
                let ctx = self.ctx(trace, paused);
                self.panes.problems_mut().handle(a, &ctx, q);
            }
            Action::ShowFrames => {
                let ctx = self.ctx(trace, paused);
                self.panes.problems_mut().refresh(&ctx);
                self.panes.problems_mut().handle(a, &ctx, q);
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
    pub(crate) fn mouse(&mut self, ev: MouseEvent, trace: &Trace, paused: bool) {
        let (t, focus) = (self.layout.table, self.focus);
        let ctx = self.ctx(trace, paused);
        let pane = self.panes.get_mut(focus);
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
            self.sync_objects_node(trace);
        }
    }

    /// Before drawing: keeps the list panes' selections within their rows and visible in
    /// `height` rows, pins the trace selection to the newest row in follow mode, decodes the
    /// visible trace window (`rows` rows), the tail strip and what the Detail pane shows.
    pub fn prepare(&mut self, trace: &Trace, paused: bool, height: usize, rows: usize, tail: &[usize]) {
        if self.panes.objects().node().is_none() {
            self.sync_objects_node(trace);
        }
        let ctx = self.ctx(trace, paused);
        for p in [
            Pane::Nodes,
            Pane::Stats,
            Pane::Sdo,
            Pane::Objects,
            Pane::Pdo,
            Pane::Problems,
            Pane::Transmit,
            Pane::Watch,
        ] {
            self.panes.get_mut(p).fit(height, &ctx);
        }
        self.panes.trace_mut().prepare(trace, rows, tail);
        let selected = self.selected(trace, paused);
        self.detail.update(trace, selected);
    }
}
