//! One reader for every log format: the binary formats are told by their magic bytes, the
//! rest goes to the core's line reader (which tells the text formats apart itself).

use crate::frame::Interfaces;
use crate::log::{Counts, Format, LogReader, Outcome};
use crate::logio::blf::BlfReader;
use std::io::{self, BufRead};

/// The binary log formats, told apart from the text ones by their first bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binary {
    /// Vector BLF (`LOGG`).
    Blf,
}

impl Binary {
    /// The binary format whose magic bytes `start` begins with.
    pub fn detect(start: &[u8]) -> Option<Binary> {
        start
            .starts_with(crate::log::blf::FILE_SIGNATURE)
            .then_some(Binary::Blf)
    }
}

/// A log reader of any format, yielding `(position, Outcome)`: the line number of a text
/// log, the object number of a binary one (its warnings give byte offsets).
pub enum Reader<R> {
    /// candump, screen, ASC, TRC or CSV text.
    Text(LogReader<R>),
    /// Vector BLF.
    Blf(BlfReader<R>),
}

/// The format a log is read as when the user names it (`--input-format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadAs {
    /// A text format of the core's line reader.
    Text(Format),
    /// A binary format.
    Binary(Binary),
}

impl<R: BufRead> Reader<R> {
    /// A reader for `src`, in `format` or, when `None`, in the format its first bytes tell
    /// (a binary format's magic bytes, else the line reader's detection).
    pub fn open(mut src: R, format: Option<ReadAs>) -> io::Result<Self> {
        let format = match format {
            Some(f) => Some(f),
            None => Binary::detect(src.fill_buf()?).map(ReadAs::Binary),
        };
        Ok(match format {
            Some(ReadAs::Binary(Binary::Blf)) => Reader::Blf(BlfReader::new(src)),
            Some(ReadAs::Text(f)) => Reader::Text(LogReader::open(src, Some(f))?),
            None => Reader::Text(LogReader::open(src, None)?),
        })
    }

    /// What was detected beyond the format, to say to the user (a screen capture's
    /// timestamp mode).
    pub fn detected(&self) -> Option<&'static str> {
        match self {
            Reader::Text(r) => r.detected(),
            Reader::Blf(_) => None,
        }
    }

    /// Interface names seen so far (frames hold indexes into it).
    pub fn interfaces(&self) -> &Interfaces {
        match self {
            Reader::Text(r) => r.interfaces(),
            Reader::Blf(r) => r.interfaces(),
        }
    }

    /// Totals so far.
    pub fn counts(&self) -> &Counts {
        match self {
            Reader::Text(r) => r.counts(),
            Reader::Blf(r) => r.counts(),
        }
    }

    /// Appends outcomes to `out` until it holds `max` or the input ends.
    pub fn fill(&mut self, out: &mut Vec<(u64, Outcome)>, max: usize) -> io::Result<()> {
        match self {
            Reader::Text(r) => r.fill(out, max),
            Reader::Blf(r) => r.fill(out, max),
        }
    }

    /// The next position and outcome; `None` at the end of input.
    pub fn next_line(&mut self) -> io::Result<Option<(u64, Outcome)>> {
        match self {
            Reader::Text(r) => r.next_line(),
            Reader::Blf(r) => r.next_line(),
        }
    }
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = io::Result<(u64, Outcome)>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_line().transpose()
    }
}

/// An opened log and the format it is to be read as (`None`: detected).
pub struct Log {
    src: Box<dyn BufRead + Send>,
    format: Option<ReadAs>,
}

impl Log {
    /// The log `src`, to be read as `format` (`None`: detected).
    pub fn new(src: Box<dyn BufRead + Send>, format: Option<ReadAs>) -> Log {
        Log { src, format }
    }

    /// The log's reader (the format detected unless named), after saying on stderr what
    /// was detected beyond the format (a screen capture's timestamp mode).
    pub fn reader(self, path: &str) -> io::Result<Reader<Box<dyn BufRead + Send>>> {
        let reader = Reader::open(self.src, self.format)?;
        if let Some(what) = reader.detected() {
            eprintln!("{path}: {what}");
        }
        Ok(reader)
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
