//! `cotui open A.log B.log`: several logs in the TUI as one capture, merged by time as
//! `decode` merges them ([`super::merge`]), fed to the UI on a thread of their own. The
//! terminal belongs to the UI: what the merge has to say goes to the status bar (the count
//! of malformed lines with the first one), never to stderr.

use super::merge::{Said, for_each_merged};
use crate::logio::reader::{Log, ReadAs};
use crate::tui::source::Feed;
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, sync_channel};

/// Batches the UI may have queued before the reader waits.
const QUEUE: usize = 64;

/// The feed of the logs `files` merged by time, read as `format` (`None`: each detected),
/// named `a.log + b.log`; a file that cannot be opened is said on stderr (before the UI
/// starts) and makes it `None`.
pub fn open(files: &[PathBuf], per_file: bool, format: Option<ReadAs>) -> Option<(String, Receiver<Feed>)> {
    let mut inputs = Vec::with_capacity(files.len());
    for f in files {
        let path = f.display().to_string();
        inputs.push((path.clone(), super::input::open_input(&path, "open", format)?));
    }
    let name = inputs.iter().map(|(p, _)| p.as_str()).collect::<Vec<_>>().join(" + ");
    Some((name, merged_feed(inputs, per_file)))
}

/// Reads `inputs` (path, log) merged by time (`per_file`: each file's interfaces named
/// `FILE:IFACE`) and feeds their frames, the interface names as they appear, the notes and
/// the end.
pub fn merged_feed(inputs: Vec<(String, Log)>, per_file: bool) -> Receiver<Feed> {
    let (tx, rx) = sync_channel(QUEUE);
    std::thread::spawn(move || {
        let mut warnings = 0u64;
        let mut first: Option<String> = None;
        let mut skipped: Vec<String> = Vec::new();
        let mut sent = 0;
        let result = for_each_merged(
            inputs,
            per_file,
            |said| match said {
                Said::Warning { path, line, message } => {
                    warnings += 1;
                    first.get_or_insert_with(|| format!("{path}:{line}: {message}"));
                }
                Said::Counts { path, counts } if counts.skipped_total() > 0 => {
                    skipped.push(format!("{path}: {} lines skipped", counts.skipped_total()));
                }
                Said::Counts { .. } => {}
            },
            |lines, ifaces| {
                let gone = || std::io::Error::other("the UI has gone");
                let names = ifaces.names();
                if names.len() > sent {
                    tx.send(Feed::Interfaces(names[sent..].to_vec())).map_err(|_| gone())?;
                    sent = names.len();
                }
                let frames = lines.iter().filter_map(|(_, o)| match o {
                    crate::log::Outcome::Frame(f) => Some(*f),
                    _ => None,
                });
                tx.send(Feed::frames(frames.collect())).map_err(|_| gone())
            },
        );
        if let Err(e) = result {
            let _ = tx.send(Feed::Status(e.to_string()));
        }
        if let Some(first) = first {
            let _ = tx.send(Feed::Status(format!(
                "{warnings} malformed lines skipped (first: {first})"
            )));
        }
        for s in skipped {
            let _ = tx.send(Feed::Status(s));
        }
        let _ = tx.send(Feed::Done);
    });
    rx
}
