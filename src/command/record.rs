//! `record`: writes every frame on the bus to a candump `-l` log (our own frames included),
//! whole lines only, at least every [`FLUSH_MS`] ms; on stop it first reads what the kernel
//! still holds. Times when nothing could be captured (interface down or gone, bus-off) are
//! the recording's gaps.

use super::error::{CommandError, ParseError};
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::time_order::{self, TimeOrder};
use super::words::{TypedWords, count_arg, ms_arg, ms_or_zero_arg};
use crate::bus::{Bus, BusError, Event, StateChange, Subscription};
use crate::frame::Frame;
use crate::log::export::{AscWriter, TrcWriter};
use crate::log::writer::LogWriter;
use crate::logio::sink::{LineSink, Target};
use std::fs::{File, OpenOptions};
use std::future::Future;
use std::time::{Duration, Instant};

/// Written lines never wait longer than this (while frames keep coming) before they go out.
pub const FLUSH_MS: u64 = 200;

/// When a recording stops (besides `stop` resolving).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Limits {
    /// Stop after this many frames.
    pub count: Option<u64>,
    /// Stop after this many ms.
    pub duration_ms: Option<u64>,
}

/// What to do when the output file exists.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WriteMode {
    /// Refuse (a usage error naming `--force` and `--append`).
    #[default]
    New,
    /// Overwrite it (`--force`).
    Overwrite,
    /// Append to it (`--append`).
    Append,
}

/// A time when nothing could be captured.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Gap {
    /// The interface.
    pub iface: String,
    /// Start, ns since the Unix epoch.
    pub from_ns: u64,
    /// End (capture resumed, or the recording stopped), ns since the Unix epoch.
    pub to_ns: u64,
    /// Why (`interface down`, `interface missing`, `bus-off`).
    pub reason: String,
}

/// What a recording wrote and what it missed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Recorded {
    /// Frames written to the log.
    pub frames: u64,
    /// Frames that never reached the log: dropped by the kernel on a full socket buffer,
    /// or overrun in cotui's queue. A complete recording has 0.
    pub dropped: u64,
    /// Times when the bus could not be captured. A complete recording has none.
    pub gaps: Vec<Gap>,
}

impl Recorded {
    /// The JSON summary: `frames`, `dropped`, `gaps: [{from, to, reason}]` (seconds since
    /// the Unix epoch, as the log's timestamps), `output`; `ok` is false when there are gaps.
    pub fn report(&self, output: &str) -> RecordedJson {
        let secs = |ns: u64| ns as f64 / 1e9;
        let message = self.gap_message(output);
        RecordedJson {
            ok: self.gaps.is_empty(),
            frames: self.frames,
            dropped: self.dropped,
            gaps: self
                .gaps
                .iter()
                .map(|g| GapJson {
                    iface: g.iface.clone(),
                    from: secs(g.from_ns),
                    to: secs(g.to_ns),
                    reason: g.reason.clone(),
                })
                .collect(),
            output: output.to_string(),
            error: message.as_ref().map(|_| "bus"),
            message,
        }
    }
    /// Why the recording is incomplete, if it has gaps.
    pub fn gap_message(&self, output: &str) -> Option<String> {
        let total: u64 = self.gaps.iter().map(|g| g.to_ns.saturating_sub(g.from_ns)).sum();
        // With gaps on several buses, each says its bus.
        let several = self.gaps.iter().any(|g| g.iface != self.gaps[0].iface);
        (!self.gaps.is_empty()).then(|| {
            format!(
                "{output} has {} gap(s), {:.1} s in all, when nothing could be captured ({})",
                self.gaps.len(),
                total as f64 / 1e9,
                self.gaps
                    .iter()
                    .map(|g| if several {
                        format!("{} {}", g.iface, g.reason)
                    } else {
                        g.reason.clone()
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
    }
}

/// `record --json`: the summary of a recording.
#[derive(Debug, serde::Serialize)]
pub struct RecordedJson {
    ok: bool,
    frames: u64,
    dropped: u64,
    gaps: Vec<GapJson>,
    output: String,
    /// `bus` when the recording has gaps.
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<&'static str>,
    /// What the gaps were, when there are any.
    #[serde(skip_serializing_if = "Option::is_none")]
    message: Option<String>,
}

impl RecordedJson {
    /// `12 frames written to out.log`.
    pub fn text(&self) -> String {
        format!("{} frames written to {}", self.frames, self.output)
    }
}

/// A time nothing could be captured, in seconds since the Unix epoch.
#[derive(Debug, serde::Serialize)]
struct GapJson {
    iface: String,
    from: f64,
    to: f64,
    reason: String,
}

/// `record -o FILE [--count N] [--duration MS] [--force | --append] [--format F]`.
#[derive(clap::Args, Clone, Debug)]
pub struct RecordArgs {
    /// More interfaces recorded into the same log, after the first (each frame keeps its
    /// interface: its candump name, a pcapng interface, ASC/TRC/BLF channels 1, 2, ...).
    #[arg(value_name = "IFACE")]
    pub more: Vec<String>,
    /// The log file to write (candump -l format; `-` for stdout). An existing file is
    /// refused unless --force or --append.
    #[arg(short = 'o', long)]
    pub output: String,
    /// Stop after this many frames.
    #[arg(long, value_parser = count_arg)]
    pub count: Option<u64>,
    /// Stop after DUR (a bare number is ms, or 30s, 2min; else at Ctrl-C, SIGTERM, SIGHUP
    /// or SIGQUIT).
    #[arg(long, value_parser = ms_arg)]
    pub duration: Option<u64>,
    /// Overwrite an existing output file.
    #[arg(long, conflicts_with = "append")]
    pub force: bool,
    /// Append to an existing output file.
    #[arg(long)]
    pub append: bool,
    /// The file format: candump (-l lines), pcapng (for Wireshark), asc (Vector ASC), trc
    /// (PEAK TRC 2.1) or blf (Vector BLF, for CANalyzer/CANoe and python-can); the binary
    /// ones not to a terminal.
    #[arg(long, default_value = "candump", value_parser = TypedWords::new(&["candump", "pcapng", "asc", "trc", "blf"], LogFormat::parse))]
    pub format: LogFormat,
    /// Flight recorder: keep the last --pre in memory and write a window file (into -o
    /// DIR, with a JSON sidecar) around each hit of EXPR: a filter, `hb lost`, `bootup`,
    /// `bus-off`, `error-passive`, `iface down`, `incident KIND`, `A then B within DUR`;
    /// --count is then a number of windows (README, "Capture triggers").
    #[arg(long, value_name = "EXPR")]
    pub trigger: Option<String>,
    /// With --trigger: keep DUR before each hit (`30s`, `500ms`; a bare number is ms).
    #[arg(long, value_name = "DUR", default_value = "10s", value_parser = ms_or_zero_arg, requires = "trigger")]
    pub pre: u64,
    /// With --trigger: keep DUR after each hit (hits inside a window extend it).
    #[arg(long, value_name = "DUR", default_value = "10s", value_parser = ms_or_zero_arg, requires = "trigger")]
    pub post: u64,
}

/// `record --trigger`: the trigger's words and its window (ms before and after a hit).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TriggerWords {
    /// The trigger (parsed by the front end, with the session's dictionaries).
    pub expr: String,
    /// ms kept before a hit.
    pub pre_ms: u64,
    /// ms kept after a hit.
    pub post_ms: u64,
}

/// A recording of the bus to a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Record {
    /// The interfaces recorded besides the command's bus.
    pub more: Vec<String>,
    pub output: String,
    pub limits: Limits,
    pub mode: WriteMode,
    pub format: LogFormat,
    /// `--trigger`: windows around its hits instead of the whole bus.
    pub trigger: Option<TriggerWords>,
}

impl<D> CommandArgs<D> for RecordArgs {
    type Spec = Record;
    const NAME: &'static str = "record";

    fn spec(&self) -> Result<Record, ParseError> {
        Ok(Record {
            more: self.more.clone(),
            output: self.output.clone(),
            limits: Limits {
                count: self.count,
                duration_ms: self.duration,
            },
            mode: match (self.force, self.append) {
                (true, _) => WriteMode::Overwrite,
                (_, true) => WriteMode::Append,
                _ => WriteMode::New,
            },
            format: self.format,
            trigger: self.trigger.as_ref().map(|expr| TriggerWords {
                expr: expr.clone(),
                pre_ms: self.pre,
                post_ms: self.post,
            }),
        })
    }
}

impl Spec for Record {
    /// It sends nothing.
    fn preview(&self, _known: &Known<'_>) -> Result<Preview, CommandError> {
        Ok(Preview::sends(format!("nothing: records the bus to {}", self.output)))
    }

    /// The palette records with `record start FILE` (the TUI's own recording).
    fn palette_refusal(&self) -> Option<CommandError> {
        Some(CommandError::Usage(
            "record runs from the command line (`cotui record IFACE -o FILE`)".into(),
        ))
    }

    /// Records until a limit (a record without limits runs until its future is dropped; the
    /// log is flushed then).
    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        if !self.more.is_empty() {
            return Err(CommandError::Usage(
                "several interfaces are recorded from the command line (`cotui record IF1 IF2 -o FILE`)".into(),
            ));
        }
        let mut out = open_output(&self.output, self.mode, self.format)?;
        let forever = std::future::pending::<()>();
        let bus = [(ctx.bus.name().to_string(), ctx.bus.clone())];
        let n = record(&bus, &mut out, self.limits, self.format, forever, |_| {}).await?;
        if let Some(m) = n.gap_message(&self.output) {
            return Err(CommandError::Bus(BusError::Io {
                iface: ctx.bus.name().to_string(),
                reason: format!("{} frames written, but {m}", n.frames),
            }));
        }
        let report = n.report(&self.output);
        let text = report.text();
        Ok(Outcome::new(report, text))
    }

    fn data_to_stdout(&self) -> bool {
        self.output == "-"
    }
}

/// Opens the log: `-` is stdout; an existing file is refused unless `mode` says overwrite or
/// append. Appending is refused when the file is of the other format (candump lines onto a
/// pcapng file, or pcapng onto a text log), which would leave neither readable.
pub fn open_output(
    path: &str,
    mode: WriteMode,
    format: LogFormat,
) -> Result<LineSink<Box<dyn Target + Send>>, CommandError> {
    if path == "-" {
        return Ok(LineSink::new(Box::new(std::io::stdout()), 0));
    }
    if mode == WriteMode::Append && format == LogFormat::Blf {
        return Err(CommandError::Usage(
            "a BLF file cannot be appended to (its header holds the totals): write another file".into(),
        ));
    }
    if mode == WriteMode::Append {
        if matches!(format, LogFormat::Asc | LogFormat::Trc) {
            return Err(CommandError::Usage(
                "--append goes with candump or pcapng: an ASC or TRC log has one header, with its start time".into(),
            ));
        }
        refuse_other_format(path, format)?;
    }
    let mut o = OpenOptions::new();
    match mode {
        WriteMode::New => o.write(true).create_new(true),
        WriteMode::Overwrite => o.write(true).create(true).truncate(true),
        WriteMode::Append => o.append(true).create(true),
    };
    let file: File = o.open(path).map_err(|e| {
        CommandError::Usage(if e.kind() == std::io::ErrorKind::AlreadyExists {
            format!("{path} exists; --force overwrites it, --append adds to it")
        } else {
            format!("cannot create {path}: {e}")
        })
    })?;
    let len = file.metadata().map(|m| m.len()).unwrap_or(0);
    Ok(LineSink::new(Box::new(file), len))
}

/// Refuses to append `format` to the existing, non-empty file at `path` of the other format
/// (told by the pcapng section header's first four bytes).
fn refuse_other_format(path: &str, format: LogFormat) -> Result<(), CommandError> {
    use std::io::Read;
    let mut head = [0u8; 4];
    let Ok(n) = File::open(path).and_then(|f| f.take(4).read(&mut head)) else {
        return Ok(());
    };
    if n == 0 {
        return Ok(());
    }
    let pcapng = n == 4 && head == [0x0A, 0x0D, 0x0D, 0x0A];
    let (is, given) = match (pcapng, format) {
        (true, LogFormat::Candump) => ("pcapng", "candump lines"),
        (false, LogFormat::Pcapng) => ("not pcapng (a text log?)", "pcapng"),
        // BLF, ASC and TRC are refused before (they cannot be appended to at all).
        _ => return Ok(()),
    };
    Err(CommandError::Usage(format!(
        "{path} is {is}: --append would add {given} to it and leave it unreadable; \
         append with its own --format, or write another file"
    )))
}

/// Records frames from `buses` (each with the interface name its frames are logged with)
/// into `out` until `stop` resolves, a limit is reached or every bus is closed; then reads
/// every frame still queued, writes it, and flushes. Frames of several buses are written in
/// the order of their timestamps ([`TimeOrder`]), each with its bus: a candump interface
/// name, a pcapng interface, an ASC/TRC/BLF channel (1, 2, ... in the order given). Each
/// change of a bus's state goes to `note` as a line for the user. A write error stops the
/// recording (the log keeps whole lines only).
pub async fn record<T: Target>(
    buses: &[(String, Bus)],
    out: &mut LineSink<T>,
    limits: Limits,
    format: LogFormat,
    stop: impl Future<Output = ()>,
    mut note: impl FnMut(String),
) -> Result<Recorded, CommandError> {
    let mut rxs: Vec<Subscription> = buses.iter().map(|(_, b)| b.subscribe()).collect();
    let names: Vec<String> = buses.iter().map(|(n, _)| n.clone()).collect();
    let mut rec = Recording::new(Encoder::start(format, out, &names), names, limits.count);
    let mut closed = vec![false; buses.len()];
    let deadline = limits
        .duration_ms
        .map(|ms| tokio::time::Instant::now() + Duration::from_millis(ms));
    let until = async {
        match deadline {
            Some(d) => tokio::time::sleep_until(d).await,
            None => std::future::pending().await,
        }
    };
    // Held frames of several buses go on after at most the hold, also when no frame comes.
    let mut release = tokio::time::interval(time_order::HOLD / 2);
    release.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    tokio::pin!(stop);
    tokio::pin!(until);
    while rec.more() && closed.contains(&false) {
        tokio::select! {
            _ = &mut stop => break,
            _ = &mut until => break,
            _ = release.tick(), if !rec.order.is_empty() => {
                rec.release(out, false);
                rec.flush(out)?;
            }
            (i, got) = next_of(&mut rxs, &closed) => {
                // Write whatever else is queued before polling the stop conditions again.
                let mut next = Some((i, got));
                while let Some((i, got)) = next {
                    if !rec.take(i, got, out, &mut note)? {
                        closed[i] = true;
                    }
                    next = if rec.more() { try_next_of(&mut rxs, &closed) } else { None };
                    if next.is_some() && rec.flushed.elapsed() >= Duration::from_millis(FLUSH_MS) {
                        rec.flush(out)?;
                    }
                }
                rec.flush(out)?;
            }
        }
    }
    if rec.more() && closed.contains(&false) {
        // Stopped: what the kernel queued before the stop belongs to the recording.
        let caught = futures_all(buses.iter().map(|(_, b)| b.catch_up()));
        tokio::pin!(caught);
        loop {
            tokio::select! {
                biased;
                (i, got) = next_of(&mut rxs, &closed) => {
                    if !rec.take(i, got, out, &mut note)? {
                        closed[i] = true;
                    }
                    if !rec.more() || !closed.contains(&false) {
                        break;
                    }
                }
                _ = &mut caught => break,
            }
        }
        while rec.more()
            && let Some((i, got)) = try_next_of(&mut rxs, &closed)
        {
            if !rec.take(i, got, out, &mut note)? {
                closed[i] = true;
            }
        }
    }
    rec.release(out, true);
    rec.flush(out)?;
    rec.writer.finish(out).map_err(|e| {
        CommandError::Usage(format!(
            "writing the end of the log failed: {e} ({} frames written)",
            out.lines()
        ))
    })?;
    let end = now_ns();
    for (i, open) in rec.open_gaps.iter_mut().enumerate() {
        if let Some((from_ns, reason)) = open.take() {
            rec.gaps.push(Gap {
                iface: rec.ifaces[i].clone(),
                from_ns,
                to_ns: end,
                reason,
            });
        }
    }
    let dropped = buses.iter().map(|(_, b)| b.dropped()).sum::<u64>() + rxs.iter().map(Subscription::lost).sum::<u64>();
    Ok(Recorded {
        frames: out.lines(),
        dropped,
        gaps: rec.gaps,
    })
}

/// The next event of any bus not closed, with the bus's index (pending when all are).
async fn next_of(rxs: &mut [Subscription], closed: &[bool]) -> (usize, Result<Event, BusError>) {
    // One receive per bus, kept across polls (each holds its waker); a broadcast receive is
    // cancel-safe: those dropped unfinished lose nothing.
    let mut waits: Vec<_> = rxs
        .iter_mut()
        .enumerate()
        .filter(|(i, _)| !closed[*i])
        .map(|(i, rx)| Box::pin(async move { (i, rx.next().await) }))
        .collect();
    std::future::poll_fn(|cx| {
        waits
            .iter_mut()
            .find_map(|w| match w.as_mut().poll(cx) {
                std::task::Poll::Ready(got) => Some(got),
                std::task::Poll::Pending => None,
            })
            .map_or(std::task::Poll::Pending, std::task::Poll::Ready)
    })
    .await
}

/// An event already queued on any bus not closed, with the bus's index.
fn try_next_of(rxs: &mut [Subscription], closed: &[bool]) -> Option<(usize, Result<Event, BusError>)> {
    rxs.iter_mut()
        .enumerate()
        .filter(|(i, _)| !closed[*i])
        .find_map(|(i, rx)| rx.try_next().map(|got| (i, got)))
}

/// Resolves when every future of `all` has.
async fn futures_all<F: Future<Output = ()>>(all: impl Iterator<Item = F>) {
    for f in all {
        f.await;
    }
}

/// The file format of a recording.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LogFormat {
    /// candump `-l` lines.
    #[default]
    Candump,
    /// pcapng for Wireshark (LINKTYPE_CAN_SOCKETCAN, nanosecond timestamps).
    Pcapng,
    /// Vector ASC (the header comes with the first frame; no `--append`).
    Asc,
    /// PEAK TRC 2.1 (the header comes with the first frame; no `--append`).
    Trc,
    /// Vector BLF for CANalyzer/CANoe and python-can (zlib containers, 1 ns timestamps).
    Blf,
}

impl LogFormat {
    /// Parses `candump`, `pcapng`, `asc`, `trc` or `blf`.
    pub fn parse(word: &str) -> Result<LogFormat, ParseError> {
        match word {
            "candump" | "log" => Ok(LogFormat::Candump),
            "pcapng" => Ok(LogFormat::Pcapng),
            "asc" => Ok(LogFormat::Asc),
            "trc" => Ok(LogFormat::Trc),
            "blf" => Ok(LogFormat::Blf),
            _ => Err(ParseError::Invalid(format!(
                "unknown record format `{word}`: use candump, pcapng, asc, trc or blf"
            ))),
        }
    }
}

/// Turns frames into the records of a log format (a recording's, a trigger window's).
pub(crate) enum Encoder {
    Candump(LogWriter),
    /// The interfaces described so far (a pcapng interface block precedes an interface's
    /// first frame).
    Pcapng(Vec<String>),
    Asc(AscWriter, String),
    Trc(TrcWriter, String),
    /// Frames gather into a container, which goes out at every flush.
    Blf(Box<crate::output::blf::BlfEncoder>),
}

impl Encoder {
    /// A fresh encoder for the buses `ifaces`; a pcapng one starts the file with its section
    /// header, candump lines pad the names as `candump -l IF1 IF2` does.
    pub(crate) fn start<T: Target>(format: LogFormat, out: &mut LineSink<T>, ifaces: &[String]) -> Encoder {
        match format {
            LogFormat::Candump => Encoder::Candump(LogWriter::new().pad_to(ifaces)),
            LogFormat::Pcapng => {
                out.buffer().extend_from_slice(&crate::output::pcapng::section_header());
                out.end_record(false);
                Encoder::Pcapng(Vec::new())
            }
            LogFormat::Asc => Encoder::Asc(AscWriter::new(), String::new()),
            LogFormat::Trc => Encoder::Trc(TrcWriter::new(), String::new()),
            LogFormat::Blf => Encoder::Blf(Box::default()),
        }
    }

    /// Puts out what the encoder holds back (a BLF container), before the sink flushes.
    pub(crate) fn flush<T: Target>(&mut self, out: &mut LineSink<T>) {
        if let Encoder::Blf(enc) = self {
            let n = enc.container(out.buffer());
            if n > 0 {
                out.end_frames(n);
            }
        }
    }

    /// The end of the recording: a BLF file gets its header (in a file, with its totals).
    pub(crate) fn finish<T: Target>(&mut self, out: &mut LineSink<T>) -> std::io::Result<()> {
        match self {
            Encoder::Asc(w, text) => {
                w.finish(text);
                if !text.is_empty() {
                    out.buffer().extend_from_slice(text.as_bytes());
                    text.clear();
                    out.end_record(false);
                }
                out.flush()
            }
            Encoder::Blf(enc) => {
                let n = enc.finish(out.buffer());
                out.end_frames(n);
                out.flush()?;
                out.target().rewrite_start(&enc.header())
            }
            Encoder::Candump(_) | Encoder::Pcapng(_) | Encoder::Trc(..) => Ok(()),
        }
    }

    /// Appends `f` (seen on `iface`) to `out` as one record.
    pub(crate) fn frame<T: Target>(&mut self, out: &mut LineSink<T>, f: &Frame, iface: &str) {
        match self {
            // Writing to a Vec cannot fail.
            Encoder::Candump(w) => {
                let _ = w.write_io(out.buffer(), f, iface);
            }
            Encoder::Pcapng(seen) => {
                let id = match seen.iter().position(|n| n == iface) {
                    Some(i) => i,
                    None => {
                        out.buffer()
                            .extend_from_slice(&crate::output::pcapng::interface_description(iface));
                        seen.push(iface.to_string());
                        seen.len() - 1
                    }
                };
                out.buffer()
                    .extend_from_slice(&crate::output::pcapng::enhanced_packet(id as u32, f));
            }
            Encoder::Asc(w, text) => {
                w.write_line(text, f, iface);
                out.buffer().extend_from_slice(text.as_bytes());
                text.clear();
            }
            Encoder::Trc(w, text) => {
                w.write_line(text, f, iface);
                out.buffer().extend_from_slice(text.as_bytes());
                text.clear();
            }
            Encoder::Blf(enc) => {
                let n = enc.frame(out.buffer(), iface, f);
                if n > 0 {
                    out.end_frames(n);
                }
                return;
            }
        }
        out.end_record(true);
    }
}

/// A recording in progress.
struct Recording {
    writer: Encoder,
    /// The interface name of each bus, by index.
    ifaces: Vec<String>,
    /// Frames taken (written to the sink's buffer, or held in `order`).
    frames: u64,
    count: Option<u64>,
    /// Frames of several buses waiting for their turn (unused with one bus).
    order: TimeOrder,
    /// Per bus: start (ns) and reason of the gap in progress.
    open_gaps: Vec<Option<(u64, String)>>,
    gaps: Vec<Gap>,
    flushed: Instant,
}

impl Recording {
    fn new(writer: Encoder, ifaces: Vec<String>, count: Option<u64>) -> Recording {
        Recording {
            writer,
            open_gaps: vec![None; ifaces.len()],
            ifaces,
            frames: 0,
            count,
            order: TimeOrder::default(),
            gaps: Vec::new(),
            flushed: Instant::now(),
        }
    }

    fn more(&self) -> bool {
        self.count.is_none_or(|c| self.frames < c)
    }

    /// Takes one event of bus `bus`; false when that bus is closed.
    fn take<T: Target>(
        &mut self,
        bus: usize,
        got: Result<Event, BusError>,
        out: &mut LineSink<T>,
        note: &mut impl FnMut(String),
    ) -> Result<bool, CommandError> {
        match got {
            Ok(Event::Frame(mut f)) => {
                f.iface = bus as u16;
                self.frames += 1;
                if self.ifaces.len() == 1 {
                    self.writer.frame(out, &f, &self.ifaces[0]);
                } else {
                    self.order.push(f, Instant::now());
                    self.release(out, false);
                }
            }
            Ok(Event::State(s)) => self.state(bus, s, note),
            Err(BusError::Closed) => return Ok(false),
            Err(e) => note(e.to_string()),
        }
        Ok(true)
    }

    /// Writes the held frames whose turn has come (`all`: every one, at the end).
    fn release<T: Target>(&mut self, out: &mut LineSink<T>, all: bool) {
        let now = Instant::now();
        while let Some(f) = if all {
            self.order.pop()
        } else {
            self.order.pop_ready(now)
        } {
            self.writer.frame(out, &f, &self.ifaces[usize::from(f.iface)]);
        }
    }

    fn state(&mut self, bus: usize, s: StateChange, note: &mut impl FnMut(String)) {
        let iface = &self.ifaces[bus];
        let open = &mut self.open_gaps[bus];
        match (&open, s.state.capturing()) {
            (None, false) => {
                *open = Some((s.ts_ns, s.state.name().to_string()));
                note(format!("{}; a gap in the recording starts", s.text(iface)));
            }
            (Some((from, reason)), true) => {
                note(format!(
                    "{iface}: capturing again after {:.1} s ({reason}); the gap ends",
                    s.ts_ns.saturating_sub(*from) as f64 / 1e9
                ));
                self.gaps.push(Gap {
                    iface: iface.clone(),
                    from_ns: *from,
                    to_ns: s.ts_ns,
                    reason: reason.clone(),
                });
                *open = None;
                if s.state != crate::bus::BusState::Active {
                    note(s.text(iface));
                }
            }
            _ => note(s.text(iface)),
        }
    }

    fn flush<T: Target>(&mut self, out: &mut LineSink<T>) -> Result<(), CommandError> {
        self.flushed = Instant::now();
        self.writer.flush(out);
        if !out.pending() {
            return Ok(());
        }
        out.flush().map_err(|e| {
            CommandError::Usage(format!(
                "writing the log failed: {e}; it ends with the last whole line ({} frames)",
                out.lines()
            ))
        })
    }
}

/// Wall-clock time in ns since the Unix epoch (the clock of frame timestamps).
fn now_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::BusState;
    use crate::frame::Frame;

    struct Mem(Vec<u8>);
    impl std::io::Write for Mem {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    impl Target for Mem {
        fn cut(&mut self, len: u64) -> std::io::Result<()> {
            self.0.truncate(len as usize);
            Ok(())
        }
        fn rewrite_start(&mut self, bytes: &[u8]) -> std::io::Result<()> {
            self.0[..bytes.len()].copy_from_slice(bytes);
            Ok(())
        }
    }

    fn state(ts_ns: u64, state: BusState) -> Result<Event, BusError> {
        Ok(Event::State(StateChange {
            ts_ns,
            state,
            counters: None,
        }))
    }

    #[test]
    fn loss_of_capture_is_a_gap_with_its_reason_and_notes() {
        let mut rec = Recording::new(Encoder::Candump(LogWriter::new()), vec!["vcan0".into()], None);
        let mut out = LineSink::new(Mem(Vec::new()), 0);
        let mut notes = Vec::new();
        let mut f = Frame::classic(0x123, &[1]);
        f.ts_ns = 1_000_000_000;
        let events = [
            Ok(Event::Frame(f)),
            state(2_000_000_000, BusState::Down),
            // Deleted while down: still the same gap, with the first reason.
            state(2_500_000_000, BusState::Missing),
            state(4_000_000_000, BusState::Active),
            state(5_000_000_000, BusState::Passive),
            state(6_000_000_000, BusState::BusOff),
            state(6_500_000_000, BusState::Active),
            Err(BusError::Closed),
        ];
        let taken: Vec<bool> = events
            .into_iter()
            .map(|e| rec.take(0, e, &mut out, &mut |n| notes.push(n)).unwrap())
            .collect();
        assert_eq!(taken, [true, true, true, true, true, true, true, false]);
        rec.flush(&mut out).unwrap();
        assert_eq!(out.lines(), 1);
        let gap = |from_ns, to_ns, reason: &str| Gap {
            iface: "vcan0".into(),
            from_ns,
            to_ns,
            reason: reason.into(),
        };
        assert_eq!(
            rec.gaps,
            [
                gap(2_000_000_000, 4_000_000_000, "interface down"),
                gap(6_000_000_000, 6_500_000_000, "bus-off")
            ]
        );
        assert!(notes[0].starts_with("vcan0: interface is down, not capturing; fix: sudo ip link set vcan0 up"));
        assert!(notes[0].ends_with("a gap in the recording starts"), "{}", notes[0]);
        assert!(notes[1].starts_with("vcan0: interface is gone"), "{}", notes[1]);
        assert_eq!(
            notes[2],
            "vcan0: capturing again after 2.0 s (interface down); the gap ends"
        );
        assert!(
            notes[3].starts_with("vcan0: controller error-passive; fix: check wiring"),
            "{}",
            notes[3]
        );
        let r = Recorded {
            frames: 1,
            dropped: 0,
            gaps: rec.gaps,
        };
        let v = super::super::to_json(&r.report("x.log"));
        assert_eq!((v["ok"].as_bool(), v["error"].as_str()), (Some(false), Some("bus")));
        assert_eq!(v["gaps"][0]["from"], 2.0);
        assert_eq!(v["gaps"][1]["reason"], "bus-off");
        assert_eq!(
            v["message"],
            "x.log has 2 gap(s), 2.5 s in all, when nothing could be captured (interface down, bus-off)"
        );
        let clean = super::super::to_json(&Recorded::default().report("x.log"));
        assert_eq!(
            (clean["ok"].as_bool(), clean["gaps"].as_array().map(Vec::len)),
            (Some(true), Some(0))
        );
    }

    #[test]
    fn an_existing_log_is_kept_unless_forced_or_appended() {
        let path = std::env::temp_dir().join(format!("cotui-rec-mode-{}.log", std::process::id()));
        std::fs::write(&path, "(1.000000) can0 123#01\n").unwrap();
        let p = path.to_str().unwrap();
        let e = open_output(p, WriteMode::New, LogFormat::Candump).err().unwrap();
        assert_eq!(
            e.to_string(),
            format!("{p} exists; --force overwrites it, --append adds to it")
        );
        assert_eq!(e.exit_code(), 1);
        let mut out = open_output(p, WriteMode::Append, LogFormat::Candump).unwrap();
        out.buffer().extend_from_slice(b"(2.000000) can0 123#02\n");
        out.flush().unwrap();
        drop(out);
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "(1.000000) can0 123#01\n(2.000000) can0 123#02\n"
        );
        drop(open_output(p, WriteMode::Overwrite, LogFormat::Candump).unwrap());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "");
        std::fs::remove_file(&path).unwrap();
    }
}
