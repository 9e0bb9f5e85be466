//! One reader for every log format: the binary formats are told by their magic bytes, the
//! rest goes to the core's line reader (which tells the text formats apart itself).

use crate::frame::Interfaces;
use crate::log::{Counts, Format, LogReader, Outcome};
use crate::logio::blf::BlfReader;
use crate::logio::mf4::{Mf4Reader, Source};
use std::io::{self, BufRead, Read, SeekFrom};

/// The binary log formats, told apart from the text ones by their first bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binary {
    /// Vector BLF (`LOGG`).
    Blf,
    /// ASAM MDF4 bus logging (`MDF     `).
    Mf4,
}

impl Binary {
    /// The binary format whose magic bytes `start` begins with.
    pub fn detect(start: &[u8]) -> Option<Binary> {
        if start.starts_with(crate::log::blf::FILE_SIGNATURE) {
            Some(Binary::Blf)
        } else if start.starts_with(crate::log::mf4::FILE_ID) {
            Some(Binary::Mf4)
        } else {
            None
        }
    }
}

/// Why an MF4 log cannot be read from a stream.
const MF4_NEEDS_A_FILE: &str = "an MF4 file is read by random access: give its path, not standard input or a pipe";

/// A log reader of any format, yielding `(position, Outcome)`: the line number of a text
/// log, the object number of a binary one (its warnings give byte offsets).
pub enum Reader<R> {
    /// candump, screen, ASC, TRC or CSV text.
    Text(LogReader<R>),
    /// Vector BLF.
    Blf(BlfReader<R>),
    /// ASAM MDF4 (a file: random access).
    Mf4(Box<Mf4Reader<Box<dyn Source>>>),
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
            Some(ReadAs::Binary(Binary::Mf4)) => {
                return Err(io::Error::new(io::ErrorKind::Unsupported, MF4_NEEDS_A_FILE));
            }
            Some(ReadAs::Text(f)) => Reader::Text(LogReader::open(src, Some(f))?),
            None => Reader::Text(LogReader::open(src, None)?),
        })
    }

    /// A reader for the file `src`, in `format` or the format its first bytes tell: an MF4
    /// file is read by random access, any other through `buffered(src)`.
    pub fn open_file<S: Source + 'static>(
        mut src: S,
        format: Option<ReadAs>,
        buffered: impl FnOnce(S) -> R,
    ) -> io::Result<Self> {
        let mf4 = match format {
            Some(f) => f == ReadAs::Binary(Binary::Mf4),
            None => {
                let mut start = [0u8; 8];
                let n = read_up_to(&mut src, &mut start)?;
                src.seek(SeekFrom::Start(0))?;
                Binary::detect(&start[..n]) == Some(Binary::Mf4)
            }
        };
        if mf4 {
            return Ok(Reader::Mf4(Box::new(Mf4Reader::new(Box::new(src)))));
        }
        Reader::open(buffered(src), format)
    }

    /// What was detected beyond the format, to say to the user (a screen capture's
    /// timestamp mode).
    pub fn detected(&self) -> Option<&'static str> {
        match self {
            Reader::Text(r) => r.detected(),
            Reader::Blf(_) => None,
            Reader::Mf4(_) => None,
        }
    }

    /// The format being read, as the user is told it (`Vector BLF`, `PEAK TRC 2.1`,
    /// `candump screen output, delta times (-td)`).
    pub fn format_name(&self) -> &'static str {
        match self {
            Reader::Text(r) => r.detected().unwrap_or(match r.format() {
                Format::Candump => "candump log",
                Format::Screen => "candump screen output",
                Format::Asc => "Vector ASC",
                Format::Trc => "PEAK TRC",
                Format::Csv => "python-can CSV",
                Format::Savvycan => "SavvyCAN CSV",
                Format::PeakCsv => "PEAK CSV",
            }),
            Reader::Blf(_) => "Vector BLF",
            Reader::Mf4(_) => "ASAM MDF4",
        }
    }

    /// Interface names seen so far (frames hold indexes into it).
    pub fn interfaces(&self) -> &Interfaces {
        match self {
            Reader::Text(r) => r.interfaces(),
            Reader::Blf(r) => r.interfaces(),
            Reader::Mf4(r) => r.interfaces(),
        }
    }

    /// Totals so far.
    pub fn counts(&self) -> &Counts {
        match self {
            Reader::Text(r) => r.counts(),
            Reader::Blf(r) => r.counts(),
            Reader::Mf4(r) => r.counts(),
        }
    }

    /// Appends outcomes to `out` until it holds `max` or the input ends.
    pub fn fill(&mut self, out: &mut Vec<(u64, Outcome)>, max: usize) -> io::Result<()> {
        match self {
            Reader::Text(r) => r.fill(out, max),
            Reader::Blf(r) => r.fill(out, max),
            Reader::Mf4(r) => r.fill(out, max),
        }
    }

    /// The next position and outcome; `None` at the end of input.
    pub fn next_line(&mut self) -> io::Result<Option<(u64, Outcome)>> {
        match self {
            Reader::Text(r) => r.next_line(),
            Reader::Blf(r) => r.next_line(),
            Reader::Mf4(r) => r.next_line(),
        }
    }
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = io::Result<(u64, Outcome)>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_line().transpose()
    }
}

/// Reads into `buf` until it is full or the source ends; the bytes read.
fn read_up_to(src: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match src.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// Where a log's bytes come from.
enum From {
    /// A stream (standard input).
    Stream(Box<dyn BufRead + Send>),
    /// A file (random access for MF4).
    File(std::fs::File),
}

/// An opened log and the format it is to be read as (`None`: detected).
pub struct Log {
    src: From,
    format: Option<ReadAs>,
}

impl Log {
    /// The log `src`, to be read as `format` (`None`: detected).
    pub fn new(src: Box<dyn BufRead + Send>, format: Option<ReadAs>) -> Log {
        Log {
            src: From::Stream(src),
            format,
        }
    }

    /// The log file `file`, to be read as `format` (`None`: detected).
    pub fn file(file: std::fs::File, format: Option<ReadAs>) -> Log {
        Log {
            src: From::File(file),
            format,
        }
    }

    /// The log's reader (the format detected unless named), after saying on stderr what
    /// was detected beyond the format (a screen capture's timestamp mode).
    pub fn reader(self, path: &str) -> io::Result<Reader<Box<dyn BufRead + Send>>> {
        let reader = match self.src {
            From::Stream(src) => Reader::open(src, self.format)?,
            From::File(f) => Reader::open_file(f, self.format, |f| {
                Box::new(io::BufReader::with_capacity(1 << 16, f)) as Box<dyn BufRead + Send>
            })?,
        };
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
