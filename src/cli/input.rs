//! The logs that `decode` and `diagnose` read: opening one, walking its frames batch by
//! batch (parsed on a second thread, bad lines reported on stderr as `FILE:LINE: warning:`)
//! and the closing counts of what was skipped.

use crate::frame::{Frame, Interfaces};
use crate::log::{Counts, Outcome};
use crate::logio::read_ahead;
use std::io::{self, BufRead, BufReader};

/// What a command reads: one log, or several merged by time into one capture (see
/// [`super::merge`]).
pub enum Input {
    /// One log.
    One(Box<dyn BufRead + Send>),
    /// Several logs (path, reader), and whether each file's interfaces are its own
    /// (`FILE:IFACE`) rather than the same buses by name.
    Merged(Vec<(String, Box<dyn BufRead + Send>)>, bool),
}

impl From<Box<dyn BufRead + Send>> for Input {
    fn from(r: Box<dyn BufRead + Send>) -> Input {
        Input::One(r)
    }
}

/// The inputs of a command given `files`: one log as it is, several as one merged capture
/// named `a.log + b.log` (`per_file`: see [`Input::Merged`]). Files that cannot be opened
/// are said on stderr and left out; the flag is true when one was.
pub fn open_inputs(files: &[String], what: &str, per_file: bool) -> (Vec<(String, Input)>, bool) {
    let mut opened = Vec::new();
    let mut failed = false;
    for path in files {
        match open_input(path, what) {
            Some(r) => opened.push((path.clone(), r)),
            None => failed = true,
        }
    }
    if files.len() < 2 {
        return (opened.into_iter().map(|(p, r)| (p, Input::One(r))).collect(), failed);
    }
    if opened.is_empty() {
        return (Vec::new(), failed);
    }
    let label = opened.iter().map(|(p, _)| p.as_str()).collect::<Vec<_>>().join(" + ");
    (vec![(label, Input::Merged(opened, per_file))], failed)
}

/// A log to read: stdin for `-`, else the file; `None` (with the message on stderr, `what`
/// naming the command) when it cannot be opened.
pub fn open_input(path: &str, what: &str) -> Option<Box<dyn BufRead + Send>> {
    if path == "-" {
        return Some(Box::new(BufReader::with_capacity(1 << 16, io::stdin())));
    }
    match std::fs::File::open(path) {
        Ok(f) => Some(Box::new(BufReader::with_capacity(1 << 16, f))),
        Err(e) => {
            eprintln!("cotui {what}: {path}: {e}");
            None
        }
    }
}

/// The frames of one batch, in input order: an iterator of (1-based line, frame) that
/// prints each malformed line's warning as it passes it.
pub struct Frames<'a> {
    path: &'a str,
    lines: std::slice::Iter<'a, (u64, Outcome)>,
    /// The interface names the frames' `iface` indices refer to.
    pub ifaces: &'a Interfaces,
}

impl<'a> Iterator for Frames<'a> {
    type Item = (u64, &'a Frame);

    fn next(&mut self) -> Option<(u64, &'a Frame)> {
        for (line, outcome) in self.lines.by_ref() {
            match outcome {
                Outcome::Frame(f) => return Some((*line, f)),
                Outcome::Skip(_) => {}
                Outcome::Warning(msg) => eprintln!("{}:{line}: warning: {msg}", self.path),
            }
        }
        None
    }
}

/// Reads `input` (named `path` in warnings) and calls `consume` with the frames of each
/// batch, in order. Returns what the reader counted; a read error, or the first error of
/// `consume` (which stops reading), is returned instead. Merged logs report their counts
/// file by file as they end (the counts returned are then empty).
pub fn for_each_frame(
    path: &str,
    input: impl Into<Input>,
    mut consume: impl FnMut(Frames<'_>) -> io::Result<()>,
) -> io::Result<Counts> {
    let input = match input.into() {
        Input::One(r) => r,
        Input::Merged(inputs, per_file) => {
            super::merge::for_each_merged(inputs, per_file, |lines, ifaces| {
                consume(Frames {
                    path,
                    lines: lines.iter(),
                    ifaces,
                })
            })?;
            return Ok(Counts::default());
        }
    };
    let mut ifaces = Interfaces::default();
    let finished = read_ahead::for_each_batch(input, |batch| {
        for name in &batch.new_interfaces {
            ifaces.intern(name);
        }
        consume(Frames {
            path,
            lines: batch.lines.iter(),
            ifaces: &ifaces,
        })
    })??;
    match finished.error {
        Some(e) => Err(e),
        None => Ok(finished.counts),
    }
}

/// Prints what a reader skipped or could not read in `path` (nothing when every line was a frame).
pub fn report_counts(path: &str, c: &Counts) {
    if c.warnings > 0 || c.skipped_total() > 0 {
        eprintln!(
            "{path}: {} frames, {} lines skipped, {} malformed lines",
            c.frames,
            c.skipped_total(),
            c.warnings
        );
    }
    if let Some(first) = c.first_ignored_tail {
        eprintln!(
            "{path}: {} frame lines had text after the frame, not read (comments; first: line {first})",
            c.ignored_tail
        );
    }
}

/// The first name given twice among `names` (interfaces of one session), if any.
pub fn repeated(names: &[String]) -> Option<&str> {
    names
        .iter()
        .enumerate()
        .find(|(i, n)| names[..*i].contains(n))
        .map(|(_, n)| n.as_str())
}
