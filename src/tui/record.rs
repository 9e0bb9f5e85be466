//! `record start FILE` / `record stop` in the palette: the frames the session receives
//! (cotui's own included, as they come back marked TX) go to a candump `-l` log, whole
//! lines only (a failed write cuts the file back to its last whole line, see
//! [`crate::logio::sink`]). With a trigger in force (`:trigger EXPR --pre DUR --post DUR`)
//! only its windows are written ([`Gate`]: the detector and windows of `record --trigger`).

use super::event::{Event, Queue};
use super::messages::Level;
use crate::analysis::trigger::Trigger;
use crate::analysis::trigger::detect::Detector;
use crate::analysis::trigger::window::{Hit, Out, Windows};
use crate::command::record::{WriteMode, open_output};
use crate::command::{CommandError, ParseError};
use crate::decode::Decoder;
use crate::frame::{Frame, Interfaces};
use crate::log::writer::LogWriter;
use crate::logio::sink::{LineSink, Target};

/// A recording in progress.
pub struct Recorder {
    /// The file written.
    pub file: String,
    sink: LineSink<Box<dyn Target + Send>>,
    writer: LogWriter,
    line: String,
    /// The trigger whose windows alone are written.
    gate: Option<Gate>,
}

/// A trigger gating a recording: each frame goes into the ring or the open window, then
/// the trigger judges it; only the frames of the windows come out.
pub struct Gate {
    /// The trigger's text.
    pub source: String,
    detector: Detector,
    windows: Windows,
    hits: Vec<Hit>,
    outs: Vec<Out>,
}

impl Gate {
    /// The windows of `pre_ms` before and `post_ms` after each hit of `trigger`.
    pub fn new(trigger: &Trigger, pre_ms: u64, post_ms: u64, decoder: &Decoder) -> Gate {
        Gate {
            source: trigger.source.clone(),
            detector: Detector::new(trigger, decoder),
            windows: Windows::new(pre_ms.saturating_mul(1_000_000), post_ms.saturating_mul(1_000_000)),
            hits: Vec::new(),
            outs: Vec::new(),
        }
    }

    /// The frames of `batch` (with those the ring held before a hit) that belong to a window.
    fn pass(&mut self, batch: &[Frame], ifaces: &Interfaces) -> Vec<Frame> {
        self.detector.name_interfaces(ifaces);
        let mut keep = Vec::new();
        for f in batch {
            self.windows.frame(f, &mut self.outs);
            self.detector.frame(f, &mut self.hits);
            for h in self.hits.drain(..) {
                self.windows.hit(h, &mut self.outs);
            }
            keep.extend(self.outs.drain(..).filter_map(|o| match o {
                Out::Frame(f) => Some(f),
                _ => None,
            }));
        }
        keep
    }
}

/// What `record` in the palette asks for (the words after `record`, as clap declares them).
#[derive(clap::Subcommand, Clone, Debug, PartialEq, Eq)]
pub enum RecordCommand {
    /// Record the frames the session receives to FILE (candump -l).
    Start(StartArgs),
    /// End the recording.
    Stop,
}

/// `record start FILE [--force | --append]`.
#[derive(clap::Args, Clone, Debug, PartialEq, Eq)]
pub struct StartArgs {
    /// The log to write. An existing file is refused unless --force or --append.
    pub file: String,
    /// Overwrite an existing file.
    #[arg(long, conflicts_with = "append")]
    pub force: bool,
    /// Append to an existing file.
    #[arg(long)]
    pub append: bool,
}

impl StartArgs {
    /// What to do when the file exists.
    pub fn mode(&self) -> WriteMode {
        match (self.force, self.append) {
            (true, _) => WriteMode::Overwrite,
            (_, true) => WriteMode::Append,
            _ => WriteMode::New,
        }
    }
}

/// The palette's `record` line.
#[derive(clap::Parser, Debug)]
#[command(
    name = "record",
    no_binary_name = true,
    disable_help_subcommand = true,
    disable_version_flag = true
)]
struct RecordLine {
    #[command(subcommand)]
    command: RecordCommand,
}

/// The declaration, built once.
fn declaration() -> &'static clap::Command {
    static CMD: std::sync::OnceLock<clap::Command> = std::sync::OnceLock::new();
    CMD.get_or_init(|| {
        let mut c = <RecordLine as clap::CommandFactory>::command();
        c.build();
        c
    })
}

/// The words `record` takes in the palette (for completion), from the declaration: its
/// subcommands, then their flags.
pub fn words() -> Vec<String> {
    let cmd = declaration();
    let subs = cmd.get_subcommands();
    let flags = cmd.get_subcommands().flat_map(|s| {
        s.get_arguments()
            .filter_map(|a| a.get_long())
            .filter(|l| *l != "help")
            .map(|l| format!("--{l}"))
    });
    subs.map(|s| s.get_name().to_string()).chain(flags).collect()
}

/// Parses the words after `record` (split like a shell line).
pub fn parse(rest: &str) -> Result<RecordCommand, ParseError> {
    let words = shlex::split(rest).ok_or(ParseError::Quote)?;
    let matches = declaration().clone().try_get_matches_from(words)?;
    let line = <RecordLine as clap::FromArgMatches>::from_arg_matches(&matches)?;
    Ok(line.command)
}

impl Recorder {
    /// Opens `file` (an existing one is refused unless `mode` says overwrite or append);
    /// with a `gate`, only its trigger's windows are written.
    pub fn start(file: &str, mode: WriteMode, gate: Option<Gate>) -> Result<Recorder, CommandError> {
        if file == "-" {
            return Err(CommandError::Usage(
                "record: the terminal is the TUI's, give a file".into(),
            ));
        }
        Ok(Recorder {
            file: file.to_string(),
            sink: open_output(file, mode, crate::command::record::LogFormat::Candump)?,
            writer: LogWriter::new(),
            line: String::new(),
            gate,
        })
    }

    /// Writes `frames` as whole candump lines.
    pub fn frames(&mut self, frames: &[Frame], ifaces: &Interfaces) -> std::io::Result<()> {
        let kept;
        let frames = match &mut self.gate {
            Some(g) => {
                kept = g.pass(frames, ifaces);
                &kept[..]
            }
            None => frames,
        };
        for f in frames {
            self.line.clear();
            self.writer.write_line(&mut self.line, f, ifaces.name(f.iface));
            self.sink.buffer().extend_from_slice(self.line.as_bytes());
            self.sink.end_record(true);
        }
        self.sink.flush()
    }

    /// The trigger whose windows alone are written.
    pub fn gated(&self) -> Option<&str> {
        self.gate.as_ref().map(|g| g.source.as_str())
    }

    /// Frames written so far.
    pub fn count(&self) -> u64 {
        self.sink.lines()
    }

    /// Ends the recording; the frames written.
    pub fn stop(mut self) -> std::io::Result<u64> {
        self.sink.flush()?;
        Ok(self.sink.lines())
    }
}

/// `record start FILE [--force | --append]` / `record stop` (the words after `record`):
/// starts or ends `recording` (of a capture with a bus when `has_bus`); what the user is
/// told goes to `q`.
/// With a `gate` (the trigger in force), only the trigger's windows are written.
pub(crate) fn command(has_bus: bool, recording: &mut Option<Recorder>, rest: &str, gate: Option<Gate>, q: &mut Queue) {
    let (level, text) = match parse(rest) {
        Err(e) => (Level::Error, format!("record: {e}")),
        Ok(RecordCommand::Stop) => match recording.take() {
            None => (Level::Info, "record: not recording".to_string()),
            Some(r) => {
                let file = r.file.clone();
                match r.stop() {
                    Ok(n) => (Level::Info, format!("record: stopped, {n} frames in {file}")),
                    Err(e) => (Level::Error, format!("record: {file}: {e}")),
                }
            }
        },
        Ok(RecordCommand::Start(_)) if !has_bus => (
            Level::Error,
            "record: only a live or demo session records what it receives; `export FILE` writes a log's view".into(),
        ),
        Ok(RecordCommand::Start(_)) if recording.is_some() => {
            let file = recording.as_ref().map(|r| r.file.clone()).unwrap_or_default();
            (
                Level::Error,
                format!("record: already recording to {file} (`record stop` first)"),
            )
        }
        Ok(RecordCommand::Start(start)) => match Recorder::start(&start.file, start.mode(), gate) {
            Ok(r) => {
                let what = match r.gated() {
                    Some(t) => format!("the windows of trigger `{t}`"),
                    None => "the frames received".into(),
                };
                *recording = Some(r);
                (
                    Level::Info,
                    format!("record: recording {what} to {} (`record stop` ends it)", start.file),
                )
            }
            Err(e) => (Level::Error, format!("record: {e}")),
        },
    };
    q.push(Event::Say(level, text));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_words_parse_or_say_how() {
        assert_eq!(parse("stop"), Ok(RecordCommand::Stop));
        let Ok(RecordCommand::Start(start)) = parse("start a.log --append") else {
            panic!("not a start");
        };
        assert_eq!((start.file.as_str(), start.mode()), ("a.log", WriteMode::Append));
        let err = |rest: &str| parse(rest).unwrap_err().to_string();
        assert!(err("start").contains("<FILE>"), "{}", err("start"));
        assert!(err("-o x.log").contains("'-o'"), "{}", err("-o x.log"));
        assert_eq!(err("start a b"), "unexpected argument 'b' found");
        assert!(err("start a --force --append").contains("cannot be used with"));
        assert_eq!(words(), ["start", "stop", "--force", "--append"]);
    }

    #[test]
    fn with_a_trigger_only_its_windows_are_recorded() {
        let decoder = Decoder::new(crate::od::Dictionary::default(), Vec::new());
        let trigger = Trigger::parse("emcy", &decoder).unwrap();
        let gate = Gate::new(&trigger, 1_000, 500, &decoder);
        let path = std::env::temp_dir().join(format!("cotui-rec-gate-{}.log", std::process::id()));
        let file = path.to_string_lossy().into_owned();
        let mut r = Recorder::start(&file, WriteMode::Overwrite, Some(gate)).unwrap();
        assert_eq!(r.gated(), Some("emcy"));
        let mut ifaces = Interfaces::default();
        ifaces.intern("can0");
        // A heartbeat every 100 ms for 10 s, an EMCY at 5.05 s.
        let mut batch = Vec::new();
        for i in 0..100u64 {
            let mut f = Frame::classic(0x701, &[0x05]);
            f.ts_ns = i * 100_000_000;
            batch.push(f);
            if i == 50 {
                let mut e = Frame::classic(0x081, &[0x10, 0x23, 0x11, 0, 0, 0, 0, 0]);
                e.ts_ns = 5_050_000_000;
                batch.push(e);
            }
        }
        r.frames(&batch[..40], &ifaces).unwrap();
        r.frames(&batch[40..], &ifaces).unwrap();
        assert_eq!(r.stop().unwrap(), 16, "4.1 s to 5.5 s: 15 heartbeats and the EMCY");
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.lines()
                .next()
                .unwrap()
                .starts_with("(0000000004.100000) can0 701#05"),
            "{text}"
        );
        assert!(text.contains("081#1023110000000000"), "{text}");
        assert!(
            text.lines().last().unwrap().starts_with("(0000000005.500000)"),
            "{text}"
        );
        std::fs::remove_file(&path).unwrap();
    }
}
