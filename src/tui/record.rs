//! `record start FILE` / `record stop` in the palette: the frames the session receives
//! (cotui's own included, as they come back marked TX) go to a candump `-l` log, whole
//! lines only (a failed write cuts the file back to its last whole line, see
//! [`crate::logio::sink`]).

use super::capture::Capture;
use super::event::{Event, Queue};
use super::messages::Level;
use crate::command::CommandError;
use crate::command::record::{WriteMode, open_output};
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

/// What `record` in the palette asks for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RecordCommand {
    /// `record start FILE [--force | --append]`.
    Start { file: String, mode: WriteMode },
    /// `record stop`.
    Stop,
}

/// The words `record` takes in the palette (for completion).
pub const WORDS: &[&str] = &["start", "stop", "--force", "--append"];

/// How `record` is written in the palette.
pub const USAGE: &str = "record: use `record start FILE [--force | --append]` or `record stop`";

/// Parses the words after `record`.
pub fn parse(rest: &str) -> Result<RecordCommand, String> {
    let words: Vec<&str> = rest.split_whitespace().collect();
    match words.as_slice() {
        ["stop"] => Ok(RecordCommand::Stop),
        ["start", more @ ..] => {
            let (mut file, mut mode) = (None, WriteMode::New);
            for w in more {
                match *w {
                    "--force" if mode == WriteMode::New => mode = WriteMode::Overwrite,
                    "--append" if mode == WriteMode::New => mode = WriteMode::Append,
                    "--force" | "--append" => return Err("record: --force and --append exclude each other".into()),
                    w if w.starts_with("--") => return Err(format!("record: unknown option `{w}`; {USAGE}")),
                    w if file.is_none() => file = Some(w.to_string()),
                    w => return Err(format!("record: one FILE only (`{w}` is extra)")),
                }
            }
            let file = file.ok_or_else(|| USAGE.to_string())?;
            Ok(RecordCommand::Start { file, mode })
        }
        _ => Err(USAGE.into()),
    }
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
/// starts or ends the recording of `capture`; what the user is told goes to `q`.
pub(crate) fn command(capture: &mut Capture, rest: &str, q: &mut Queue) {
    let has_bus = capture.has_bus();
    let recording = capture.recording_mut();
    let (level, text) = match parse(rest) {
        Err(e) => (Level::Error, e),
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
        Ok(RecordCommand::Start { .. }) if !has_bus => (
            Level::Error,
            "record: only a live or demo session records what it receives; `export FILE` writes a log's view".into(),
        ),
        Ok(RecordCommand::Start { .. }) if recording.is_some() => {
            let file = recording.as_ref().map(|r| r.file.clone()).unwrap_or_default();
            (
                Level::Error,
                format!("record: already recording to {file} (`record stop` first)"),
            )
        }
        Ok(RecordCommand::Start { file, mode }) => match Recorder::start(&file, mode) {
            Ok(r) => {
                *recording = Some(r);
                (
                    Level::Info,
                    format!("record: recording the frames received to {file} (`record stop` ends it)"),
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
        assert_eq!(
            parse("start a.log --append"),
            Ok(RecordCommand::Start {
                file: "a.log".into(),
                mode: WriteMode::Append
            })
        );
        assert_eq!(parse("start"), Err(USAGE.to_string()));
        assert_eq!(parse("-o x.log"), Err(USAGE.to_string()));
        assert_eq!(
            parse("start a b"),
            Err("record: one FILE only (`b` is extra)".to_string())
        );
        assert!(parse("start a --force --append").unwrap_err().contains("exclude"));
    }
}
