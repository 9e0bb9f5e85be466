//! The logs that `decode` and `diagnose` read: opening one, walking its frames batch by
//! batch (parsed on a second thread, bad lines reported on stderr as `FILE:LINE: warning:`)
//! and the closing counts of what was skipped.

use crate::frame::{Frame, Interfaces};
use crate::log::{Counts, Format, LogReader, Outcome};
use crate::logio::read_ahead;
use clap::{Args, ValueEnum};
use std::io::{self, BufRead, BufReader};

/// The log formats a user can name with `--input-format`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum InputFormat {
    /// candump -l / -L logs.
    Candump,
    /// candump's screen output (any -t mode).
    Screen,
    /// Vector ASC.
    Asc,
    /// PEAK TRC 1.0 to 2.1.
    Trc,
    /// python-can CSV.
    Csv,
}

impl InputFormat {
    /// The reader's format.
    pub fn format(self) -> Format {
        match self {
            InputFormat::Candump => Format::Candump,
            InputFormat::Screen => Format::Screen,
            InputFormat::Asc => Format::Asc,
            InputFormat::Trc => Format::Trc,
            InputFormat::Csv => Format::Csv,
        }
    }
}

/// `--input-format`, shared by the commands that read logs.
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct InputArgs {
    /// Read the logs as this format instead of detecting it from their content.
    #[arg(long = "input-format", value_enum, value_name = "FORMAT")]
    pub input_format: Option<InputFormat>,
}

impl InputArgs {
    /// The format to read logs as; `None`: detected from each log's content.
    pub fn format(self) -> Option<Format> {
        self.input_format.map(InputFormat::format)
    }
}

/// An opened log and the format it is to be read as (`None`: detected).
pub struct Input {
    src: Box<dyn BufRead + Send>,
    format: Option<Format>,
}

/// A log to read as `format` (`None`: detected): stdin for `-`, else the file; `None`
/// (with the message on stderr, `what` naming the command) when it cannot be opened.
pub fn open_input(path: &str, what: &str, format: Option<Format>) -> Option<Input> {
    if path == "-" {
        let src = Box::new(BufReader::with_capacity(1 << 16, io::stdin()));
        return Some(Input { src, format });
    }
    match std::fs::File::open(path) {
        Ok(f) => Some(Input {
            src: Box::new(BufReader::with_capacity(1 << 16, f)),
            format,
        }),
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
/// batch, in order. What was detected beyond the format (a screen capture's timestamp
/// mode) is said on stderr first. Returns what the reader counted; a read error, or the
/// first error of `consume` (which stops reading), is returned instead.
pub fn for_each_frame(
    path: &str,
    input: Input,
    mut consume: impl FnMut(Frames<'_>) -> io::Result<()>,
) -> io::Result<Counts> {
    let reader = LogReader::open(input.src, input.format)?;
    if let Some(what) = reader.detected() {
        eprintln!("{path}: {what}");
    }
    let mut ifaces = Interfaces::default();
    let finished = read_ahead::for_each_batch(reader, |batch| {
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
