//! The application's internal events: what the capture side, the screen side and the panes
//! ask of each other, queued and routed by [`crate::tui::app::App`] (the shape of gitui's
//! `InternalEvent` queue). A part never reaches into another: it pushes an event.

use super::keymap::Action;
use super::messages::Level;
use super::panes::objects::ObjectRequest;
use crate::command::stop::StopOptions;
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
}

/// The events waiting to be routed, oldest first.
#[derive(Debug, Default)]
pub(crate) struct Queue(VecDeque<Event>);

impl Queue {
    /// Adds `e` at the end.
    pub(crate) fn push(&mut self, e: Event) {
        self.0.push_back(e);
    }

    /// Takes the oldest event.
    pub(crate) fn pop(&mut self) -> Option<Event> {
        self.0.pop_front()
    }
}
