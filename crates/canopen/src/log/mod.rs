//! Log formats: candump `-l` logs, candump's screen output, Vector ASC, PEAK TRC and PEAK
//! CSV, python-can CSV and SavvyCAN CSV, plus a candump log writer; [`blf`] and [`mf4`] hold the byte-level halves
//! of Vector BLF and ASAM MDF4 bus logging (their file IO and zlib live in cotui's `logio`).
//!
//! Each format has a line parser (`parse_line(&mut self, &[u8], &mut Interfaces)`) that
//! works on bytes, allocates nothing per line and never panics. [`LogReader`] drives one
//! over any [`BufRead`], parsing lines in place in the source's buffer (or in one reused
//! line buffer when a line straddles it), and counts what it saw.

pub mod asc;
mod asc_date;
pub mod blf;
pub mod candump;
pub mod csv;
mod cursor;
pub mod export;
#[cfg(test)]
mod fast_check;
mod lex;
pub mod mf4;
pub mod peak_csv;
pub mod savvycan;
pub mod screen;
mod status;
pub mod trc;
pub mod writer;

use std::fmt;
use std::io::{self, BufRead};

use crate::frame::{Frame, Interfaces};

/// The log formats cotui reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// candump `-l` / `-L`: `(1436509052.249713) can0 123#1122`.
    Candump,
    /// candump's default screen output: `  can0  123   [2]  11 22`.
    Screen,
    /// Vector ASC: `   0.001000 1  123             Rx   d 2 11 22`.
    Asc,
    /// PEAK TRC 1.0 to 2.1: `      1         0.100 DT  1      0181 Rx -  2    11 22`.
    Trc,
    /// python-can CSV: `1700000000.1,0x181,0,0,0,2,ESI=`.
    Csv,
    /// SavvyCAN CSV: `166064000,00000181,false,Rx,0,2,11,22,`.
    Savvycan,
    /// PEAK CSV (PEAK-Converter's export of a trace): `1,1841.300,1,Rx,DT,0181,-,2,11,22`.
    PeakCsv,
}

/// Why a line was not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SkipReason {
    /// Empty or blank.
    Blank,
    /// A comment or other text that is not a frame line.
    Comment,
    /// candump's `DROPCOUNT: ...` notice.
    DropCount,
    /// A CAN XL frame (not modelled).
    CanXl,
    /// A header or block line (ASC `date`, `base`, `Begin Triggerblock`, ...).
    Header,
    /// A timed event that is not a CAN frame (ASC `Start of measurement`, `TxRq`, ...).
    Event,
    /// A detail line of candump `-e` under an error frame (starts with a tab).
    ErrorDetail,
}

impl SkipReason {
    /// Every reason, in [`Counts`] order.
    pub const ALL: [SkipReason; 7] = [
        SkipReason::Blank,
        SkipReason::Comment,
        SkipReason::DropCount,
        SkipReason::CanXl,
        SkipReason::Header,
        SkipReason::Event,
        SkipReason::ErrorDetail,
    ];

    /// Short lower-case name for summaries.
    pub fn label(self) -> &'static str {
        match self {
            SkipReason::Blank => "blank",
            SkipReason::Comment => "comment",
            SkipReason::DropCount => "dropcount",
            SkipReason::CanXl => "can-xl",
            SkipReason::Header => "header",
            SkipReason::Event => "event",
            SkipReason::ErrorDetail => "error-detail",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// What one line held, as returned by the per-format parsers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Line {
    /// A frame.
    Frame(Frame),
    /// Not a frame, for this reason.
    Skip(SkipReason),
}

/// A malformed line: 1-based byte column and what was wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// 1-based byte column of the problem.
    pub column: usize,
    /// What was wrong.
    pub message: &'static str,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "column {}: {}", self.column, self.message)
    }
}

impl std::error::Error for ParseError {}

/// What [`LogReader`] made of one input line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A frame.
    Frame(Frame),
    /// Not a frame, for this reason.
    Skip(SkipReason),
    /// A malformed line; the message says where (column) and what was wrong.
    Warning(String),
}

/// Running totals of a [`LogReader`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Lines that gave a frame.
    pub frames: u64,
    /// Malformed lines.
    pub warnings: u64,
    /// Frame lines with text after the frame that was not read (comments, annotations).
    pub ignored_tail: u64,
    /// The number of the first such line.
    pub first_ignored_tail: Option<u64>,
    skipped: [u64; SkipReason::ALL.len()],
}

impl Counts {
    /// Lines skipped for `reason`.
    pub fn skipped(&self, reason: SkipReason) -> u64 {
        self.skipped[reason.index()]
    }
    /// Lines skipped for any reason.
    pub fn skipped_total(&self) -> u64 {
        self.skipped.iter().sum()
    }
    /// Counts one outcome of a reader outside this module (the binary log readers).
    pub fn record(&mut self, outcome: &Outcome) {
        match outcome {
            Outcome::Frame(_) => self.frames += 1,
            Outcome::Skip(r) => self.skipped[r.index()] += 1,
            Outcome::Warning(_) => self.warnings += 1,
        }
    }
}

/// Guesses the format from the first non-empty lines of `sample` (e.g. the reader's first
/// buffer). Comments, `DROPCOUNT` lines and blank lines are passed over; `None` when no
/// line decides. A TRC header (`;$FILEVERSION`, `;$STARTTIME`) is TRC unless the first
/// line after it is a PEAK CSV row (PEAK-Converter copies the header into its CSV).
pub(crate) fn detect(sample: &[u8]) -> Option<Format> {
    let mut trc_header = false;
    for line in sample.split(|&b| b == b'\n').take(64) {
        let s = lex::trim_end(line);
        if s.starts_with(b";$FILEVERSION") || s.starts_with(b";$STARTTIME") {
            trc_header = true;
        } else if trc_header && !s.is_empty() && !s.starts_with(b";") {
            return Some(if peak_csv::is_peak_csv(s) {
                Format::PeakCsv
            } else {
                Format::Trc
            });
        } else if !trc_header && let Some(f) = detect_line(s) {
            return Some(f);
        }
    }
    trc_header.then_some(Format::Trc)
}

/// The format one line belongs to, if it tells.
fn detect_line(line: &[u8]) -> Option<Format> {
    let s = lex::trim_end(line);
    if s == csv::HEADER {
        return Some(Format::Csv);
    }
    if s.starts_with(savvycan::HEADER_START) {
        return Some(Format::Savvycan);
    }
    if peak_csv::is_peak_csv(s) {
        return Some(Format::PeakCsv);
    }
    let mut toks = lex::Tokens::new(s, 0);
    let (_, first) = toks.next()?;
    let second = toks.peek().map(|(_, t)| t);
    // TRC 1.x: `     1)      1841  0001    8  00 ...`.
    if let Some((b')', number)) = first.split_last()
        && lex::dec_u32(number).is_some()
    {
        return Some(Format::Trc);
    }
    if first.starts_with(b"(") {
        // candump log: `(ts) iface id#data`; screen: `(ts)  iface  id  [n] ...`.
        let third = lex::Tokens::new(s, toks.pos()).nth(1).map(|(_, t)| t);
        return match third {
            Some(t) if t.contains(&b'#') => Some(Format::Candump),
            Some(_) => Some(Format::Screen),
            None => None,
        };
    }
    let is_time = |t: &[u8]| lex::timestamp(t, 0).is_ok_and(|(_, end)| end == t.len() && t.contains(&b'.'));
    match first {
        b"date" | b"base" | b"Begin" | b"no" | b"internal" => return Some(Format::Asc),
        _ if is_time(first) => return Some(Format::Asc),
        _ => {}
    }
    // Screen without timestamp: `iface id [n]` or `iface RX - - id [n]`.
    let rest: Vec<&[u8]> = lex::Tokens::new(s, 0).skip(1).map(|(_, t)| t).take(5).collect();
    let is_len = |t: &[u8]| {
        t.first().is_some_and(|&b| b == b'[' || b == b'{') && t.last().is_some_and(|&b| b == b']' || b == b'}')
    };
    if second.is_some() && (rest.get(1).is_some_and(|t| is_len(t)) || rest.get(4).is_some_and(|t| is_len(t))) {
        return Some(Format::Screen);
    }
    None
}

/// What the user is told of a TRC file.
fn trc_label(v: trc::Version) -> &'static str {
    match v {
        trc::Version::V1_0 => "PEAK TRC 1.0",
        trc::Version::V1_1 => "PEAK TRC 1.1",
        trc::Version::V1_2 => "PEAK TRC 1.2",
        trc::Version::V1_3 => "PEAK TRC 1.3",
        trc::Version::V2_0 => "PEAK TRC 2.0",
        trc::Version::V2_1 => "PEAK TRC 2.1",
    }
}

/// The parser of one format, with its state.
#[derive(Debug)]
enum Parser {
    Candump(candump::Parser),
    Screen(screen::Parser),
    Asc(Box<asc::Parser>),
    Trc(Box<trc::Parser>),
    Csv(csv::Parser),
    Savvycan(savvycan::Parser),
    PeakCsv(Box<peak_csv::Parser>),
}

/// The longest line a reader takes: a longer one (e.g. a file with no line ends) is
/// skipped with a warning, so no input can exhaust memory.
pub(crate) const MAX_LINE: usize = 1 << 20;

/// Streams a log line by line, yielding `(line_number, Outcome)` for every line.
///
/// Lines are parsed as bytes in place (one reused buffer gathers a line that straddles the
/// source's buffer), so non-UTF-8 input only gives warnings on the lines concerned. A line
/// longer than [`MAX_LINE`] is a warning, its bytes are read past and not kept. IO errors
/// end the stream.
#[derive(Debug)]
pub struct LogReader<R> {
    src: R,
    buf: Vec<u8>,
    line_no: u64,
    format: Format,
    parser: Parser,
    ifaces: Interfaces,
    counts: Counts,
    frame: Frame,
    detected: Option<&'static str>,
}

impl<R: BufRead> LogReader<R> {
    /// A reader that detects the format from the start of `src` (candump when undecided).
    pub fn new(src: R) -> io::Result<Self> {
        LogReader::open(src, None)
    }

    /// A reader of `format`, or of the format detected from the start of `src` (candump
    /// when undecided); the variant (screen timestamp mode) is detected in either case.
    pub fn open(mut src: R, format: Option<Format>) -> io::Result<Self> {
        let sample = src.fill_buf()?;
        let format = format.or_else(|| detect(sample)).unwrap_or(Format::Candump);
        let times = (format == Format::Screen).then(|| screen::detect_times(sample));
        let detected = match format {
            Format::Trc => Some(trc_label(trc::detect_version(sample))),
            Format::Csv => Some("python-can CSV"),
            Format::Savvycan => Some("SavvyCAN CSV"),
            Format::PeakCsv => Some("PEAK CSV"),
            _ => None,
        };
        let mut reader = LogReader::with_format(src, format);
        reader.detected = detected;
        if let (Some(times), Parser::Screen(p)) = (times, &mut reader.parser) {
            p.set_delta(times == screen::Times::Delta);
            reader.detected = (times != screen::Times::None).then(|| times.label());
        }
        Ok(reader)
    }

    /// A reader for a known format.
    pub fn with_format(src: R, format: Format) -> Self {
        let parser = match format {
            Format::Candump => Parser::Candump(candump::Parser::new()),
            Format::Screen => Parser::Screen(screen::Parser::new()),
            Format::Asc => Parser::Asc(Box::default()),
            Format::Trc => Parser::Trc(Box::default()),
            Format::Csv => Parser::Csv(csv::Parser::new()),
            Format::Savvycan => Parser::Savvycan(savvycan::Parser::new()),
            Format::PeakCsv => Parser::PeakCsv(Box::default()),
        };
        LogReader {
            src,
            buf: Vec::with_capacity(256),
            line_no: 0,
            format,
            parser,
            ifaces: Interfaces::default(),
            counts: Counts::default(),
            frame: Frame::default(),
            detected: None,
        }
    }

    /// What [`LogReader::open`] detected beyond the format's name, for the user (e.g.
    /// `candump screen output, delta times (-td)`); `None` for plain candump and ASC logs.
    pub fn detected(&self) -> Option<&'static str> {
        self.detected
    }

    /// The format being read.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Interface names seen so far (frames hold indexes into it).
    pub fn interfaces(&self) -> &Interfaces {
        &self.ifaces
    }

    /// Totals so far.
    pub fn counts(&self) -> &Counts {
        &self.counts
    }

    /// The next line's number (1-based) and outcome; `None` at the end of input.
    ///
    /// A line that lies whole in the source's buffer is parsed in place; one that straddles
    /// the buffer's end is gathered in the reader's own line buffer (reused, never shrunk).
    pub fn next_line(&mut self) -> io::Result<Option<(u64, Outcome)>> {
        let available = self.src.fill_buf()?;
        if let Some(n) = self.parser.parse_fast(available, &mut self.ifaces, &mut self.frame) {
            self.src.consume(n);
            self.line_no += 1;
            self.counts.frames += 1;
            return Ok(Some((self.line_no, Outcome::Frame(self.frame))));
        }
        self.general_line()
    }

    /// Appends the next lines to `out`, as [`LogReader::next_line`] gives them, until `out`
    /// holds `max` or the input ends. Runs of the format's common lines are read in one go
    /// from the source's buffer by its fast path.
    pub fn fill(&mut self, out: &mut Vec<(u64, Outcome)>, max: usize) -> io::Result<()> {
        while out.len() < max {
            let buf = self.src.fill_buf()?;
            let before = out.len();
            let mut run = FastRun {
                buf,
                ifaces: &mut self.ifaces,
                frame: &mut self.frame,
                line_no: &mut self.line_no,
                out,
                max,
            };
            let at = match &mut self.parser {
                Parser::Candump(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
                Parser::Screen(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
                Parser::Asc(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
                Parser::Trc(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
                Parser::Csv(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
                Parser::PeakCsv(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
                Parser::Savvycan(p) => run.lines(|b, i, f| p.parse_fast(b, i, f)),
            };
            self.counts.frames += (out.len() - before) as u64;
            self.src.consume(at);
            if out.len() == max {
                break;
            }
            match self.general_line()? {
                Some(item) => out.push(item),
                None => break,
            }
        }
        Ok(())
    }

    /// [`LogReader::next_line`] by the format's general parser.
    fn general_line(&mut self) -> io::Result<Option<(u64, Outcome)>> {
        let available = self.src.fill_buf()?;
        if available.is_empty() {
            return Ok(None);
        }
        let parsed = if let Some(pos) = memchr::memchr(b'\n', available) {
            let parsed = parse(&mut self.parser, &mut self.ifaces, &mut self.frame, &available[..=pos]);
            self.src.consume(pos + 1);
            parsed
        } else {
            if !self.gather_line()? {
                self.line_no += 1;
                self.counts.warnings += 1;
                return Ok(Some((
                    self.line_no,
                    Outcome::Warning(format!("line longer than {} MiB, skipped", MAX_LINE >> 20)),
                )));
            }
            parse(&mut self.parser, &mut self.ifaces, &mut self.frame, &self.buf)
        };
        self.line_no += 1;
        let outcome = match parsed {
            Ok(None) => {
                self.counts.frames += 1;
                if self.parser.ignored_tail() {
                    self.counts.ignored_tail += 1;
                    self.counts.first_ignored_tail.get_or_insert(self.line_no);
                }
                Outcome::Frame(self.frame)
            }
            Ok(Some(r)) => {
                self.counts.skipped[r.index()] += 1;
                Outcome::Skip(r)
            }
            Err(e) => {
                self.counts.warnings += 1;
                Outcome::Warning(e.to_string())
            }
        };
        Ok(Some((self.line_no, outcome)))
    }
}

impl<R: BufRead> LogReader<R> {
    /// Gathers the next line (through its `\n`) into the line buffer; false when it is longer
    /// than [`MAX_LINE`]: then its bytes are consumed up to the line end and dropped.
    fn gather_line(&mut self) -> io::Result<bool> {
        self.buf.clear();
        let mut fits = true;
        loop {
            let chunk = self.src.fill_buf()?;
            if chunk.is_empty() {
                return Ok(fits);
            }
            let (take, done) = match memchr::memchr(b'\n', chunk) {
                Some(p) => (p + 1, true),
                None => (chunk.len(), false),
            };
            if fits && self.buf.len() + take <= MAX_LINE {
                self.buf.extend_from_slice(&chunk[..take]);
            } else {
                fits = false;
                self.buf.clear();
            }
            self.src.consume(take);
            if done {
                return Ok(fits);
            }
        }
    }
}

/// A run of fast-path lines read from one source buffer into a batch.
struct FastRun<'a> {
    buf: &'a [u8],
    ifaces: &'a mut Interfaces,
    frame: &'a mut Frame,
    line_no: &'a mut u64,
    out: &'a mut Vec<(u64, Outcome)>,
    max: usize,
}

impl FastRun<'_> {
    /// Pushes the frames `fast` reads from the start of the buffer on, until it leaves a
    /// line to the general parser or the batch is full; returns the bytes read.
    #[inline]
    fn lines(&mut self, mut fast: impl FnMut(&[u8], &mut Interfaces, &mut Frame) -> Option<usize>) -> usize {
        let mut at = 0;
        while self.out.len() < self.max
            && let Some(n) = fast(&self.buf[at..], self.ifaces, self.frame)
        {
            at += n;
            *self.line_no += 1;
            self.out.push((*self.line_no, Outcome::Frame(*self.frame)));
        }
        at
    }
}

impl Parser {
    /// The format's fast path for its common line at the start of `buf` (see
    /// `candump::Parser::parse_fast`); `None` leaves the line to the general parser.
    #[inline]
    fn parse_fast(&mut self, buf: &[u8], ifaces: &mut Interfaces, frame: &mut Frame) -> Option<usize> {
        match self {
            Parser::Candump(p) => p.parse_fast(buf, ifaces, frame),
            Parser::Screen(p) => p.parse_fast(buf, ifaces, frame),
            Parser::Asc(p) => p.parse_fast(buf, ifaces, frame),
            Parser::Trc(p) => p.parse_fast(buf, ifaces, frame),
            Parser::Csv(p) => p.parse_fast(buf, ifaces, frame),
            Parser::PeakCsv(p) => p.parse_fast(buf, ifaces, frame),
            Parser::Savvycan(p) => p.parse_fast(buf, ifaces, frame),
        }
    }

    /// True when the last frame line had text after the frame that was ignored.
    fn ignored_tail(&self) -> bool {
        match self {
            Parser::Candump(p) => p.ignored_tail(),
            Parser::Screen(p) => p.ignored_tail(),
            Parser::Asc(_) | Parser::Trc(_) | Parser::Csv(_) | Parser::Savvycan(_) | Parser::PeakCsv(_) => false,
        }
    }
}

/// Parses `line` with `parser`; a frame goes to `frame` (`Ok(None)`), a skip returns its reason.
fn parse(
    parser: &mut Parser,
    ifaces: &mut Interfaces,
    frame: &mut Frame,
    line: &[u8],
) -> Result<Option<SkipReason>, ParseError> {
    match parser {
        Parser::Candump(p) => p.parse_into(line, ifaces, frame),
        Parser::Screen(p) => into(p.parse_line(line, ifaces), frame),
        Parser::Asc(p) => into(p.parse_line(line, ifaces), frame),
        Parser::Trc(p) => into(p.parse_line(line, ifaces), frame),
        Parser::Csv(p) => into(p.parse_line(line, ifaces), frame),
        Parser::Savvycan(p) => into(p.parse_line(line, ifaces), frame),
        Parser::PeakCsv(p) => into(p.parse_line(line, ifaces), frame),
    }
}

/// A [`Line`] in the shape of `candump::Parser::parse_into`: frames go to `frame`.
fn into(line: Result<Line, ParseError>, frame: &mut Frame) -> Result<Option<SkipReason>, ParseError> {
    match line? {
        Line::Frame(f) => {
            *frame = f;
            Ok(None)
        }
        Line::Skip(r) => Ok(Some(r)),
    }
}

impl<R: BufRead> Iterator for LogReader<R> {
    type Item = io::Result<(u64, Outcome)>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_line().transpose()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_each_format_past_comments() {
        assert_eq!(
            detect(b"# hi\n\nDROPCOUNT: x\n(1700000000.000001) can0 123#11\n"),
            Some(Format::Candump)
        );
        assert_eq!(detect(b"  can0  123   [3]  11 22 33\n"), Some(Format::Screen));
        assert_eq!(
            detect(b" (1700000000.123456)  can0  123   [1]  11\n"),
            Some(Format::Screen)
        );
        assert_eq!(
            detect(b"  vcan0  TX - -  123   [0]  remote request\n"),
            Some(Format::Screen)
        );
        assert_eq!(
            detect(b"date Tue Nov 14 22:13:20 2023\nbase hex  timestamps absolute\n"),
            Some(Format::Asc)
        );
        assert_eq!(
            detect(b"   0.001000 1  123             Rx   d 1 11\n"),
            Some(Format::Asc)
        );
        assert_eq!(detect(b";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n"), Some(Format::Trc));
        assert_eq!(
            detect(b";####\n;   Start time\n     1)      1841  0001    8  00 00\n"),
            Some(Format::Trc)
        );
        assert_eq!(
            detect(b"timestamp,arbitration_id,extended,remote,error,dlc,data\r\n"),
            Some(Format::Csv)
        );
        assert_eq!(
            detect(b"Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8\n"),
            Some(Format::Savvycan)
        );
        // PEAK CSV: its rows, its column names, or rows under a copied TRC header.
        assert_eq!(
            detect(b"; PEAK-Converter\n1,1841.300,1,Rx,DT,0181,-,2,11,22\n"),
            Some(Format::PeakCsv)
        );
        assert_eq!(
            detect(
                b";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n;\nNumber;Time;Bus;Direction;Type;ID;Reserved;Length;D0\n"
            ),
            Some(Format::PeakCsv)
        );
        assert_eq!(
            detect(b";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n      1         0.100 DT  1      0181 Rx -  2    11 22\n"),
            Some(Format::Trc)
        );
        assert_eq!(
            detect(b";$FILEVERSION=2.1\n;$COLUMNS=O,T,B,I,d,R,L,D\n         0.100 DT  1      0181 Rx -  2    11 22\n"),
            Some(Format::Trc),
            "not ASC though the line starts with a time"
        );
        assert_eq!(detect(b"hello\n\n"), None);
    }

    #[test]
    fn reader_numbers_lines_counts_and_goes_on_after_bad_bytes() {
        let input: &[u8] = b"(1.000000) can0 123#11\n\xFF\xFE garbage\n(1.000000) c\xFF 123#11\nDROPCOUNT: 1\n\n(2.000000) can0 124#\n";
        let mut r = LogReader::new(input).unwrap();
        assert_eq!(r.format(), Format::Candump);
        let all: Vec<(u64, Outcome)> = r.by_ref().map(Result::unwrap).collect();
        assert_eq!(all.len(), 6);
        assert!(matches!(all[0], (1, Outcome::Frame(f)) if f.id == 0x123));
        assert_eq!(all[1], (2, Outcome::Skip(SkipReason::Comment)));
        assert_eq!(
            all[2],
            (
                3,
                Outcome::Warning("column 12: interface name is not valid UTF-8".into())
            )
        );
        assert_eq!(all[3], (4, Outcome::Skip(SkipReason::DropCount)));
        assert_eq!(all[4], (5, Outcome::Skip(SkipReason::Blank)));
        assert!(matches!(all[5], (6, Outcome::Frame(f)) if f.id == 0x124 && f.ts_ns == 2_000_000_000));
        let c = r.counts();
        assert_eq!((c.frames, c.warnings, c.skipped_total()), (2, 1, 3));
        assert_eq!(c.skipped(SkipReason::DropCount), 1);
        assert_eq!(r.interfaces().names(), ["can0"]);
    }

    #[test]
    fn lines_straddling_the_source_buffer_parse_the_same() {
        let text: &[u8] =
            b"(1.000000) can0 123#1122\n\n(2.000000)   vcan10 12345678##5AABBCCDDEEFF0011 T\n(3.5) can0 7FF#R8_9";
        fn all<R: BufRead>(r: LogReader<R>) -> Vec<(u64, Outcome)> {
            r.map(Result::unwrap).collect()
        }
        let whole = all(LogReader::with_format(text, Format::Candump));
        for cap in [1, 2, 7, 16, 33] {
            let small = std::io::BufReader::with_capacity(cap, text);
            assert_eq!(
                all(LogReader::with_format(small, Format::Candump)),
                whole,
                "capacity {cap}"
            );
        }
        assert_eq!(whole.len(), 4);
        assert!(matches!(whole[3], (4, Outcome::Frame(f)) if f.raw_dlc == 9));
    }

    #[test]
    fn batches_read_as_line_by_line_whatever_the_buffer() {
        let mut text = Vec::new();
        for k in 0..40u32 {
            text.extend_from_slice(
                format!(
                    "(1700000000.{k:06}) can{} {:03X}#{}\n",
                    k % 3,
                    k * 37,
                    "A5".repeat((k % 9) as usize)
                )
                .as_bytes(),
            );
            if k % 7 == 0 {
                text.extend_from_slice(b"# note\n(1700000000.000001) can0 12G#11\n(1.5) can0 123#R\n");
            }
        }
        text.extend_from_slice(b"(1700000000.000002) can0 123#11");
        let one_by_one: Vec<(u64, Outcome)> = LogReader::with_format(&text[..], Format::Candump)
            .map(Result::unwrap)
            .collect();
        assert_eq!(one_by_one.len(), 40 + 6 * 3 + 1);
        for (cap, max) in [(1, 3), (30, 7), (64, 1000), (1 << 16, 5), (1 << 16, 1000)] {
            let mut r = LogReader::with_format(std::io::BufReader::with_capacity(cap, &text[..]), Format::Candump);
            let mut all = Vec::new();
            loop {
                let mut batch = Vec::new();
                r.fill(&mut batch, max).unwrap();
                let last = batch.len() < max;
                all.extend(batch);
                if last {
                    break;
                }
            }
            assert_eq!(all, one_by_one, "capacity {cap}, batches of {max}");
            assert_eq!((r.counts().frames, r.counts().warnings), (40 + 6 + 1, 6));
        }
    }

    #[test]
    fn annotations_after_frames_are_read_past_and_counted() {
        let input: &[u8] = b"can0  70A   [1]  00   # bootup\n\
            ...\n\
            can0  60A   [8]  40 17 10 00 00 00 00 00     // SDO request\n\
            (0.1)  vcan0  603   [2]  A2 7F   '..' < response\n\
            can0  123   [1]  11 22\n";
        let mut r = LogReader::with_format(input, Format::Screen);
        let all: Vec<(u64, Outcome)> = r.by_ref().map(Result::unwrap).collect();
        assert!(matches!(all[0], (1, Outcome::Frame(f)) if f.id == 0x70A && f.len == 1));
        assert_eq!(all[1], (2, Outcome::Skip(SkipReason::Comment)), "an elision line");
        assert!(matches!(all[2], (3, Outcome::Frame(f)) if f.id == 0x60A));
        assert!(matches!(all[3], (4, Outcome::Frame(f)) if f.id == 0x603 && f.len == 2));
        // Without # or an ASCII column, extra text may be a wrong length: still an error.
        assert_eq!(
            all[4],
            (
                5,
                Outcome::Warning("column 21: unexpected text after the data bytes".into())
            )
        );
        assert_eq!((r.counts().ignored_tail, r.counts().first_ignored_tail), (3, Some(1)));
    }

    #[test]
    fn a_line_longer_than_the_cap_is_a_warning_and_reading_goes_on() {
        let mut input = vec![b'7'; MAX_LINE + 10];
        input.extend_from_slice(b"\n(1.000000) can0 123#11\n");
        let r = LogReader::with_format(std::io::BufReader::with_capacity(4096, &input[..]), Format::Candump);
        let all: Vec<(u64, Outcome)> = r.map(Result::unwrap).collect();
        assert_eq!(all[0], (1, Outcome::Warning("line longer than 1 MiB, skipped".into())));
        assert!(matches!(all[1], (2, Outcome::Frame(f)) if f.id == 0x123));
        // A capped line at the very end (no line end at all, like /dev/zero) ends the same way.
        let endless = vec![0u8; MAX_LINE * 2];
        let r = LogReader::with_format(std::io::BufReader::with_capacity(4096, &endless[..]), Format::Candump);
        let all: Vec<(u64, Outcome)> = r.map(Result::unwrap).collect();
        assert_eq!(all, [(1, Outcome::Warning("line longer than 1 MiB, skipped".into()))]);
    }

    #[test]
    fn last_line_without_newline_is_read() {
        let mut r = LogReader::with_format(&b"(1.000000) can0 123#11"[..], Format::Candump);
        assert!(matches!(r.next_line().unwrap(), Some((1, Outcome::Frame(_)))));
        assert_eq!(r.next_line().unwrap(), None);
    }
}
