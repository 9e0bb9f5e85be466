//! Reads from the Objects pane: one object (`enter`), or every readable object of a node
//! one after the other (read-all, which goes on as each result comes back and ends with a
//! summary). The pane keeps what was read; this sends the reads and says what happens.

use super::capture::Capture;
use super::event::{Event, Queue};
use super::keymap::{Action, Keymap};
use super::live::Request;
use super::messages::Level;
use super::palette;
use super::panes::objects::{ObjectsPane, Step, read_line};
use crate::frame::NodeKey;
use crate::od::bind::Bindings;

/// True when SDO reads can go out; else says why not (listen-only, or a log: no bus).
fn can_read(capture: &Capture, what: &str, q: &mut Queue) -> bool {
    if capture.listen_only() {
        q.push(Event::Say(
            Level::Error,
            format!("{what}: listen-only — nothing can be sent, so no object can be read"),
        ));
        return false;
    }
    if !capture.has_bus() {
        q.push(Event::Say(
            Level::Error,
            format!(
                "{what}: this source is a log file, there is no bus to read from (use `cotui live IFACE` or `cotui demo`)"
            ),
        ));
        return false;
    }
    true
}

/// Reads `node` `index`:`sub` as the palette's `sdo read` line (run through `q`).
pub(crate) fn read(
    capture: &Capture,
    objects: &mut ObjectsPane,
    bindings: &Bindings,
    (node, index, sub): (NodeKey, u16, u8),
    q: &mut Queue,
) {
    let line = read_line(node.node, index, sub);
    if !can_read(capture, &line, q) {
        return;
    }
    objects.sent(&line, node, index, sub);
    match palette::plan(&line, bindings, |_| None) {
        Ok(_) => q.push(Event::Run(line)),
        // E.g. an object of the decoder's dictionary the session's bindings lack.
        Err(e) => {
            let text = format!("{line}: error: {e}");
            q.push(Event::Say(Level::Error, text.clone()));
            objects.result(&text, capture.trace().nodes.now_ns());
        }
    }
}

/// Starts reading every object of `objects` of `node`.
pub(crate) fn start(
    capture: &Capture,
    objects_pane: &mut ObjectsPane,
    bindings: &Bindings,
    keymap: &Keymap,
    (node, objects): (NodeKey, Vec<(u16, u8)>),
    q: &mut Queue,
) {
    let what = format!("read all node {}", node.node);
    if objects.is_empty() {
        q.push(Event::Say(Level::Info, format!("{what}: no readable object known")));
    } else if can_read(capture, &what, q) {
        let stop = keymap.key_for(Action::ReadAll).unwrap_or_default();
        q.push(Event::Say(
            Level::Info,
            format!(
                "{what}: reading {} objects one after the other ({stop} again stops)",
                objects.len()
            ),
        ));
        let step = objects_pane.start_read_all(node, objects);
        go_on(capture, objects_pane, bindings, step, q);
    }
}

/// A palette command's result came back: the Objects pane notes it, a read-all goes on.
pub(crate) fn result(capture: &Capture, objects: &mut ObjectsPane, bindings: &Bindings, text: &str, q: &mut Queue) {
    let step = objects.result(text, capture.trace().nodes.now_ns());
    go_on(capture, objects, bindings, step, q);
}

/// Goes on with a read-all: sends its next read (without the per-line "sending"
/// notice), or says how it ended.
fn go_on(capture: &Capture, objects: &mut ObjectsPane, bindings: &Bindings, mut step: Step, q: &mut Queue) {
    loop {
        match step {
            Step::Next(line) => match palette::plan(&line, bindings, |_| None) {
                Ok(p) => {
                    capture.request(Request::Run {
                        line: p.line,
                        command: p.command,
                    });
                    return;
                }
                Err(e) => {
                    let text = format!("{line}: error: {e}");
                    q.push(Event::Log(Level::Error, text.clone()));
                    step = objects.result(&text, capture.trace().nodes.now_ns());
                }
            },
            Step::Finished(text) => {
                let failed = text.lines().count() > 1;
                q.push(Event::Say(if failed { Level::Warn } else { Level::Info }, text));
                return;
            }
            Step::NotOurs | Step::Noted => return,
        }
    }
}
