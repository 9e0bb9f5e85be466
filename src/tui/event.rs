//! The application's internal events: what the capture side, the screen side and the panes
//! ask of each other, queued and routed by [`crate::tui::app::App`] (the shape of gitui's
//! `InternalEvent` queue). A part never reaches into another: it pushes an event. A pane
//! answers an action the same way ([`crate::tui::panes::Component::handle`]).

use super::keymap::Action;
use super::messages::Level;
use crate::command::stop::StopOptions;
use crate::frame::NodeKey;
use std::collections::VecDeque;

/// One thing a part of the application asks the others.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Event {
    /// Log the text and show its first line in the status line.
    Say(Level, String),
    /// Log the text without touching the status line.
    Log(Level, String),
    /// Show the text in the status line (not logged).
    Note(String),
    /// The trace started over (a replay went back): the views start over too.
    Reset,
    /// A palette command's result came back from the live task.
    Result(Level, String),
    /// A stop-all's result came back: its text and the nodes not confirmed stopped.
    Stopped(Level, String, Vec<u8>),
    /// The trace follows its newest frame (true) or stays where it is (false).
    Follow(bool),
    /// What the Objects pane asks (read, write, read all, find).
    Object(ObjectRequest),
    /// Open (or close) the Detail view of the selected row, below the main pane on a
    /// narrow terminal.
    Detail,
    /// Show the trace with this filter.
    Filter(String),
    /// Show this trace position in the Trace pane, unfiltered.
    Show(usize),
    /// Select this trace position (or the nearest row the filter shows) in the Trace
    /// pane, the focus staying where it is.
    Select(usize),
    /// Run a palette line as if typed.
    Run(String),
    /// Do what an action says, as if its key was pressed.
    Act(Action),
    /// A replay key (pause, step, speed, seek, loop, rewind) for the capture source.
    Replay(Action),
    /// Stop every drive (and these nodes).
    StopAll(Vec<u8>, StopOptions),
    /// Quit (asking first while a commanded drive is powered).
    Quit,
    /// What the Transmit pane asks.
    Transmit(TransmitAsk),
    /// The Transmit pane's list stopped on the bus task (why): every entry is off.
    TransmitStopped(String),
    /// What the Watch pane asks.
    Watch(WatchAsk),
}

/// What the Watch pane asks of the application (row numbers from 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum WatchAsk {
    /// Open the palette for a `watch` line (of the selected row's node).
    Add(Option<u8>),
    /// Stop watching this row's object.
    Delete(usize),
    /// Show this row's object in the Objects pane.
    Open(usize),
}

/// What the Transmit pane asks of the application (row numbers from 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TransmitAsk {
    /// Enable or disable this entry.
    Toggle(usize),
    /// Open the prompt for a new entry.
    Add,
    /// Open the prompt holding this entry.
    Edit(usize),
    /// Delete this entry.
    Delete(usize),
    /// Save the list to its file.
    Save,
}

/// What the Objects pane asks of the application.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum ObjectRequest {
    /// Read this entry (an SDO upload through the palette).
    Read { node: NodeKey, index: u16, sub: u8 },
    /// Open the palette holding `text`, the cursor at character `cursor`; `note` for the
    /// status line (the value's type and scaling).
    Edit { text: String, cursor: usize, note: String },
    /// Read these entries of `node`, one after the other.
    ReadAll { node: NodeKey, objects: Vec<(u16, u8)> },
    /// Open the find prompt holding the current text.
    Find(String),
    /// Say this in the status line.
    Note(String),
}

/// The events waiting to be routed, oldest first.
#[derive(Debug, Default)]
pub(crate) struct Queue(VecDeque<Event>);

impl Queue {
    /// Adds `e` at the end.
    pub(crate) fn push(&mut self, e: Event) {
        self.0.push_back(e);
    }

    /// Adds `e` at the end and says the action it answers was taken: how a pane answers
    /// an action with an event.
    pub(crate) fn answer(&mut self, e: Event) -> bool {
        self.push(e);
        true
    }

    /// Takes the oldest event.
    pub(crate) fn pop(&mut self) -> Option<Event> {
        self.0.pop_front()
    }
}
