//! `send FRAME [--every MS] [--count N]`: a raw frame in candump's compact form, once, N
//! times or every MS ms (see [`super::cyclic`] for the timing and its report); `send --list
//! FILE [--duration MS]`: a transmit list ([`super::transmit_list`] for the file,
//! [`super::transmit_run`] for the sending).

use super::cyclic::{Schedule, Source};
use super::error::CommandError;
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::transmit_list::Resolved;
use super::transmit_run::{ListProgress, transmit_list};
use super::words::{ParseError, Repeat, frame_arg, ms_arg};
use crate::frame::Frame;
use crate::od::bind::Bindings;

/// `send FRAME [--every MS] [--count N]` or `send --list FILE [--duration MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct SendArgs<D: clap::Args> {
    /// The frame, as cansend takes it: `123#DEADBEEF`, `123#R`, 29-bit `12345678#00`.
    #[arg(value_parser = frame_arg, required_unless_present = "list")]
    pub frame: Option<Frame>,
    /// Send a transmit list instead: a JSON file of entries (raw frames or RPDO signals by
    /// name, each with its period, count, enabled flag, comment; README "Transmit list").
    #[arg(long, value_name = "FILE", conflicts_with_all = ["frame", "every", "count"])]
    pub list: Option<String>,
    /// With --list: stop this many ms after the first frames (else when every entry is done, or at Ctrl-C).
    #[arg(long, value_parser = ms_arg)]
    pub duration: Option<u64>,
    #[command(flatten)]
    pub repeat: Repeat,
    #[command(flatten)]
    pub dict: D,
}

/// A raw frame to send on a schedule, or a transmit list.
#[derive(Clone, Debug, PartialEq)]
pub enum Send {
    /// `send FRAME`.
    Frame { frame: Frame, schedule: Schedule },
    /// `send --list FILE [--duration MS]`.
    List { path: String, duration_ms: Option<u64> },
}

impl<D: clap::Args> CommandArgs<D> for SendArgs<D> {
    type Spec = Send;

    const NAME: &'static str = "send";

    fn dict(&self) -> Option<&D> {
        Some(&self.dict)
    }

    fn spec(&self) -> Result<Send, ParseError> {
        match (&self.list, self.frame) {
            (Some(path), _) => Ok(Send::List {
                path: path.clone(),
                duration_ms: self.duration,
            }),
            (None, Some(_)) if self.duration.is_some() => Err(ParseError::Invalid(
                "--duration goes with --list (one frame stops after --count N)".into(),
            )),
            (None, Some(frame)) => Ok(Send::Frame {
                frame,
                schedule: self.repeat.schedule(),
            }),
            (None, None) => Err(ParseError::Invalid("give a FRAME or --list FILE".into())),
        }
    }
}

/// The entries of the list file at `path`, each with its exact frame; a bad file or entry
/// is named with its path, entry and line.
pub fn load_list(path: &str, bindings: &Bindings) -> Result<Vec<Resolved>, CommandError> {
    let bytes = crate::files::read_at_most(std::path::Path::new(path), 1 << 20, "not a transmit list")
        .map_err(|e| CommandError::Usage(format!("cannot read {path}: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| CommandError::Usage(format!("{path}: not UTF-8 text ({e})")))?;
    let fail = |e: super::transmit_list::ListError| {
        let lines: Vec<String> = e.problems.iter().map(|p| format!("{path}: {p}")).collect();
        CommandError::Usage(lines.join("\n"))
    };
    super::transmit_list::load(&text, bindings).map_err(fail)
}

/// The preview of a list: each entry's frame and schedule.
fn list_preview(entries: &[Resolved], duration_ms: Option<u64>) -> String {
    let items: Vec<String> = entries
        .iter()
        .map(|e| {
            let state = if e.enabled {
                e.schedule.text()
            } else {
                "disabled".into()
            };
            format!("#{} {} {state}", e.index, e.what)
        })
        .collect();
    let mut text = items.join("; ");
    match duration_ms {
        Some(ms) => text.push_str(&format!(" (for {ms} ms)")),
        None if entries.iter().any(|e| e.enabled && e.schedule.total().is_none()) => {
            text.push_str(" (a job: `jobs` lists, `jobs stop ID` or stop-all stops)")
        }
        None => {}
    }
    text
}

impl Spec for Send {
    /// The frame and how often; for a list, every entry's frame and schedule.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        match self {
            Send::Frame { .. } => super::spec::cyclic_preview(self, known, ""),
            Send::List { path, duration_ms } => Ok(Preview::sends(list_preview(
                &load_list(path, known.bindings)?,
                *duration_ms,
            ))),
        }
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        match self {
            Send::Frame { .. } => super::spec::cyclic_run(self, ctx).await,
            Send::List { path, duration_ms } => {
                let entries = load_list(path, ctx.bindings)?;
                let report =
                    transmit_list(ctx.bus, path, entries, *duration_ms, ListProgress::default(), ctx.stop).await?;
                let text = report.text();
                Ok(Outcome::new(report, text))
            }
        }
    }

    fn cyclic(&self) -> bool {
        true
    }

    /// A list is checked (read, every entry encoded) before the bus is opened.
    fn answers_offline(&self) -> bool {
        matches!(self, Send::List { .. })
    }

    fn offline(&self, bindings: &Bindings) -> Option<Result<Outcome, CommandError>> {
        match self {
            Send::List { path, .. } => load_list(path, bindings).err().map(Err),
            Send::Frame { .. } => None,
        }
    }

    fn source(&self, _bindings: &Bindings) -> Option<Result<Source, CommandError>> {
        let Send::Frame { frame, schedule } = self else {
            return None;
        };
        let f = *frame;
        Some(Ok(Source {
            what: super::spec::candump(&f),
            next: Box::new(move |_| f),
            defaulted: Vec::new(),
            schedule: *schedule,
        }))
    }
}
