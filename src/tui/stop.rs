//! Stop-all (`ctrl-s`, the palette's `stop`) and the question before quitting: which
//! drives are stopped, what the live task is asked, and what the user is told.

use super::capture::Capture;
use super::event::{Event, Queue};
use super::live::Request;
use super::messages::Level;
use super::panes::objects::ObjectsPane;
use crate::command::stop::{StopOptions, is_powered};
use std::collections::BTreeSet;

/// The drives stop-all stops: those cotui commanded, those seen powered, and `extra`.
pub(crate) fn targets(capture: &Capture, extra: &[u8]) -> BTreeSet<u8> {
    let mut t: BTreeSet<u8> = capture.commanded().nodes().chain(extra.iter().copied()).collect();
    t.extend(
        capture
            .trace()
            .nodes
            .iter()
            .filter(|(_, n)| n.drive.is_some_and(is_powered))
            .map(|(id, _)| id.node),
    );
    t
}

/// The emergency stop: the read-all of the Objects pane ends, the live task cancels
/// everything it runs for us, then stops every target (see [`targets`]) and reports per
/// node whether it is confirmed. What the user is told goes to `q`.
pub(crate) fn stop_all(
    capture: &Capture,
    objects: &mut ObjectsPane,
    extra: &[u8],
    options: StopOptions,
    q: &mut Queue,
) {
    if capture.listen_only() {
        q.push(Event::Say(
            Level::Error,
            "stop all: listen-only — NOTHING can be sent, no drive was stopped; stop them another way".into(),
        ));
        return;
    }
    if let Some(summary) = objects.stop_read_all() {
        q.push(Event::Log(Level::Warn, summary));
    }
    if !capture.has_bus() {
        q.push(Event::Say(
            Level::Warn,
            "stop all: this source has no bus (a log), nothing to stop".into(),
        ));
        return;
    }
    let nodes = targets(capture, extra);
    capture.request(Request::StopAll {
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
    q.push(Event::Say(
        Level::Warn,
        format!("stop all: cancelling running commands; quick stop, then disable voltage on {list}"),
    ));
}

/// The drives cotui commanded that are still powered, which quitting asks about; none
/// when the source has no bus (nothing was commanded there).
pub(crate) fn still_powered(capture: &Capture) -> Vec<u8> {
    if !capture.has_bus() {
        return Vec::new();
    }
    capture
        .commanded()
        .nodes()
        .filter(|n| capture.drive_state(*n).is_some_and(is_powered))
        .collect()
}
