//! The logs that `decode` and `diagnose` read: opening one, walking its frames batch by
//! batch (parsed on a second thread, bad lines reported on stderr as `FILE:LINE: warning:`)
//! and the closing counts of what was skipped.

use crate::frame::{Frame, Interfaces};
use crate::log::{Counts, Format, Outcome};
use crate::logio::read_ahead;
pub use crate::logio::reader::report_counts;
use crate::logio::reader::{Binary, Log, ReadAs};
use crate::wire::WireFigures;
use clap::{Args, ValueEnum};
use std::io::{self, BufReader};

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
    /// SavvyCAN CSV (`Time Stamp,ID,Extended,Dir,Bus,LEN,D1,...`).
    Savvycan,
    /// PEAK CSV (PEAK-Converter's CSV of a trace: `Number,Time,Bus,Direction,Type,ID,...`).
    PeakCsv,
    /// Vector BLF.
    Blf,
    /// ASAM MDF4 bus logging (a file, not stdin).
    Mf4,
}

impl InputFormat {
    /// The reader's format.
    pub fn format(self) -> ReadAs {
        match self {
            InputFormat::Candump => ReadAs::Text(Format::Candump),
            InputFormat::Screen => ReadAs::Text(Format::Screen),
            InputFormat::Asc => ReadAs::Text(Format::Asc),
            InputFormat::Trc => ReadAs::Text(Format::Trc),
            InputFormat::Csv => ReadAs::Text(Format::Csv),
            InputFormat::Savvycan => ReadAs::Text(Format::Savvycan),
            InputFormat::PeakCsv => ReadAs::Text(Format::PeakCsv),
            InputFormat::Blf => ReadAs::Binary(Binary::Blf),
            InputFormat::Mf4 => ReadAs::Binary(Binary::Mf4),
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
    pub fn format(self) -> Option<ReadAs> {
        self.input_format.map(InputFormat::format)
    }
}

/// What a command reads: one log, or several merged by time into one capture (see
/// [`super::merge`]).
pub enum Input {
    /// One log.
    One(Log),
    /// Several logs (path, log), and whether each file's interfaces are its own
    /// (`FILE:IFACE`) rather than the same buses by name.
    Merged(Vec<(String, Log)>, bool),
}

impl From<Log> for Input {
    fn from(log: Log) -> Input {
        Input::One(log)
    }
}

/// The inputs of a command given `files`, read as `format` (`None`: detected): one log as
/// it is, several as one merged capture named `a.log + b.log` (`per_file`: see
/// [`Input::Merged`]). Files that cannot be opened are said on stderr and left out; the
/// flag is true when one was.
pub fn open_inputs(
    files: &[String],
    what: &str,
    per_file: bool,
    format: Option<ReadAs>,
) -> (Vec<(String, Input)>, bool) {
    let mut opened = Vec::new();
    let mut failed = false;
    for path in files {
        match open_input(path, what, format) {
            Some(log) => opened.push((path.clone(), log)),
            None => failed = true,
        }
    }
    if files.len() < 2 {
        return (
            opened.into_iter().map(|(p, log)| (p, Input::One(log))).collect(),
            failed,
        );
    }
    if opened.is_empty() {
        return (Vec::new(), failed);
    }
    let label = opened.iter().map(|(p, _)| p.as_str()).collect::<Vec<_>>().join(" + ");
    (vec![(label, Input::Merged(opened, per_file))], failed)
}

/// A log to read as `format` (`None`: detected): stdin for `-`, else the file; `None`
/// (with the message on stderr, `what` naming the command) when it cannot be opened.
pub fn open_input(path: &str, what: &str, format: Option<ReadAs>) -> Option<Log> {
    if path == "-" {
        let src = Box::new(BufReader::with_capacity(1 << 16, io::stdin()));
        return Some(Log::new(src, format));
    }
    match std::fs::File::open(path) {
        Ok(f) => Some(Log::file(f, format)),
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
    /// The wire figures of the frames, when the reader worked them out
    /// ([`for_each_frame_figured`]); empty otherwise.
    figures: std::slice::Iter<'a, WireFigures>,
    /// The interface names the frames' `iface` indices refer to.
    pub ifaces: &'a Interfaces,
}

impl<'a> Frames<'a> {
    /// The next frame with its wire figures, when the reader worked them out.
    pub fn next_figured(&mut self) -> Option<(u64, &'a Frame, Option<WireFigures>)> {
        for (line, outcome) in self.lines.by_ref() {
            match outcome {
                Outcome::Frame(f) => return Some((*line, f, self.figures.next().copied())),
                Outcome::Skip(_) => {}
                Outcome::Warning(msg) => eprintln!("{}:{line}: warning: {msg}", self.path),
            }
        }
        None
    }
}

impl<'a> Iterator for Frames<'a> {
    type Item = (u64, &'a Frame);

    fn next(&mut self) -> Option<(u64, &'a Frame)> {
        self.next_figured().map(|(line, frame, _)| (line, frame))
    }
}

/// Reads `input` (named `path` in warnings) and calls `consume` with the frames of each
/// batch, in order. What was detected beyond the format (a screen capture's timestamp
/// mode) is said on stderr first. Returns what the reader counted; a read error, or the
/// first error of `consume` (which stops reading), is returned instead. Merged logs report
/// their counts file by file as they end (the counts returned are then empty).
pub fn for_each_frame(
    path: &str,
    input: impl Into<Input>,
    consume: impl FnMut(Frames<'_>) -> io::Result<()>,
) -> io::Result<Counts> {
    for_each_frame_figured(path, input.into(), false, consume)
}

/// [`for_each_frame`] for a caller that counts bus load when `figured`: the reader of one
/// log then works out each frame's wire figures on its own thread ([`Frames::next_figured`]);
/// merged logs come without them.
pub fn for_each_frame_figured(
    path: &str,
    input: Input,
    figured: bool,
    mut consume: impl FnMut(Frames<'_>) -> io::Result<()>,
) -> io::Result<Counts> {
    let log = match input {
        Input::One(log) => log,
        Input::Merged(inputs, per_file) => {
            super::merge::for_each_merged(
                inputs,
                per_file,
                |said| said.to_stderr(),
                |lines, ifaces| {
                    consume(Frames {
                        path,
                        lines: lines.iter(),
                        figures: [].iter(),
                        ifaces,
                    })
                },
            )?;
            return Ok(Counts::default());
        }
    };
    let reader = log.reader(path)?;
    let mut ifaces = Interfaces::default();
    let finished = read_ahead::for_each_batch(reader, figured, |batch| {
        for name in &batch.new_interfaces {
            ifaces.intern(name);
        }
        consume(Frames {
            path,
            lines: batch.lines.iter(),
            figures: batch.figures.iter(),
            ifaces: &ifaces,
        })
    })??;
    match finished.error {
        Some(e) => Err(e),
        None => Ok(finished.counts),
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
