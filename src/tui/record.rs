//! `record start FILE` / `record stop` in the palette: the frames the session receives
//! (cotui's own included, as they come back marked TX) go to a candump `-l` log, whole
//! lines only (a failed write cuts the file back to its last whole line, see
//! [`crate::logio::sink`]).

use super::event::{Event, Queue};
use super::messages::Level;
use crate::command::record::{WriteMode, open_output};
use crate::command::{CommandError, ParseError};
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
    /// Opens `file` (an existing one is refused unless `mode` says overwrite or append).
    pub fn start(file: &str, mode: WriteMode) -> Result<Recorder, CommandError> {
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
        })
    }

    /// Writes `frames` as whole candump lines.
    pub fn frames(&mut self, frames: &[Frame], ifaces: &Interfaces) -> std::io::Result<()> {
        for f in frames {
            self.line.clear();
            self.writer.write_line(&mut self.line, f, ifaces.name(f.iface));
            self.sink.buffer().extend_from_slice(self.line.as_bytes());
            self.sink.end_record(true);
        }
        self.sink.flush()
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
pub(crate) fn command(has_bus: bool, recording: &mut Option<Recorder>, rest: &str, q: &mut Queue) {
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
        Ok(RecordCommand::Start(start)) => match Recorder::start(&start.file, start.mode()) {
            Ok(r) => {
                *recording = Some(r);
                (
                    Level::Info,
                    format!(
                        "record: recording the frames received to {} (`record stop` ends it)",
                        start.file
                    ),
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
}
