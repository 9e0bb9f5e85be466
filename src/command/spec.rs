//! What a commander command is, once: its words (a clap `Args` type, [`CommandArgs`]), what it
//! will send ([`Spec::preview`], the exact frames from the protocol layer), how it runs
//! ([`Spec::run`]) and what it reports (a `#[derive(Serialize)]` type in an [`Outcome`]).
//! Each command is one module implementing these; `super::registry` lists them.

use super::cyclic::{Progress, Source};
use super::error::{CommandError, ParseError};
use super::report::{Report, Reported};
use crate::bus::Bus;
use crate::decode::cia402::DriveState;
use crate::od::bind::Bindings;
use std::future::Future;
use std::pin::Pin;

/// The result of a command: its typed report (the `--json` object) and the human text.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub report: Reported,
    pub text: String,
}

impl Outcome {
    /// An outcome of `report` with the text `text`.
    pub fn new(report: impl Report + 'static, text: impl Into<String>) -> Outcome {
        Outcome {
            report: Reported::new(report),
            text: text.into(),
        }
    }

    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        self.report.to_json()
    }
}

/// A frame in candump's compact form (`602#2B40600006000000`), as previews show frames.
pub fn candump(f: &crate::frame::Frame) -> String {
    let mut s = String::new();
    crate::log::writer::push_compact(&mut s, f);
    s
}

/// What a command will send, shown before it is sent.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Preview {
    /// The frames it sends, candump style, or a description when they depend on answers.
    pub frames: String,
    /// Why it must be confirmed, if it must.
    pub confirm: Option<String>,
}

impl Preview {
    /// A preview that needs no confirming.
    pub fn sends(frames: impl Into<String>) -> Preview {
        Preview {
            frames: frames.into(),
            confirm: None,
        }
    }
}

/// What a preview knows of the session: the node dictionaries and the drives' states.
pub struct Known<'a> {
    pub bindings: &'a Bindings,
    /// A node's last CiA 402 state seen, if any.
    pub drive_state: &'a dyn Fn(u8) -> Option<DriveState>,
}

/// What a command runs with.
pub struct Ctx<'a> {
    pub bus: &'a Bus,
    pub bindings: &'a Bindings,
    /// Where a cyclic command notes its timing.
    pub progress: Progress,
    /// Completes when a cyclic command (or a record) should stop.
    pub stop: Pin<&'a mut (dyn Future<Output = ()> + Send)>,
    /// Where a command that runs in steps (`run`) says each step as it happens; `None`:
    /// the steps are part of its text.
    pub lines: Option<&'a mut (dyn FnMut(&str) + Send)>,
}

/// One command of the commander, parsed (see [`CommandArgs`] for its declaration).
pub trait Spec {
    /// What it will send, before it is sent.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError>;

    /// Runs it on the bus.
    fn run(&self, ctx: Ctx<'_>) -> impl Future<Output = Result<Outcome, CommandError>> + Send;

    /// The frames of a cyclic command (send, sync, pdo send); `None` for the others.
    fn source(&self, _bindings: &Bindings) -> Option<Result<Source, CommandError>> {
        None
    }

    /// True when it runs until stopped or for a while on a schedule (send, sync, pdo send):
    /// the command line then stops it at Ctrl-C, with its report.
    fn cyclic(&self) -> bool {
        false
    }

    /// True when it writes its data to stdout (`-o -`): its report then goes to stderr.
    fn data_to_stdout(&self) -> bool {
        false
    }

    /// Why the TUI's palette does not run it, if it does not (data to stdout would land in
    /// the middle of the screen).
    fn palette_refusal(&self) -> Option<CommandError> {
        self.data_to_stdout()
            .then(|| CommandError::Usage("-o - (stdout) is for the command line; in the TUI give a file".into()))
    }

    /// True when its dictionaries are checked before the bus is opened, [`Spec::offline`]
    /// answering without one (`run`, `pdo map --dry-run`).
    fn answers_offline(&self) -> bool {
        false
    }

    /// Its outcome without a bus (a listing, a dry run) or why it is refused before the bus
    /// is opened; `None`: it runs on the bus.
    fn offline(&self, _bindings: &Bindings) -> Option<Result<Outcome, CommandError>> {
        None
    }

    /// The one node it is about, for a `--eds FILE` given without `NODE=` (`dcf`).
    fn node(&self) -> Option<u8> {
        None
    }
}

/// A command's words as clap declares them (`D`: the dictionary options where the command
/// line has them).
pub trait CommandArgs<D>: clap::Args {
    /// The command the words make.
    type Spec: Spec;

    /// What failures are prefixed with: `cotui sdo read: ...`.
    const NAME: &'static str;

    /// The command, or why the words make none (checks clap cannot make alone).
    fn spec(&self) -> Result<Self::Spec, ParseError>;

    /// The dictionary options, for a command that takes them.
    fn dict(&self) -> Option<&D> {
        None
    }
}

/// One entry of the commander's declaration: a command's words with the options in front
/// of them (`B`, see `super::words::On`), or a group of commands (`sdo read|write`).
pub trait Declared<B, D> {
    /// The command the words make.
    type Spec: Spec;

    /// The options in front of the command (the command line's bus options).
    fn bus(&self) -> &B;

    /// The dictionary options, for a command that takes them.
    fn dict(&self) -> Option<&D>;

    /// What failures are prefixed with: `cotui sdo read: ...`.
    fn name(&self) -> &'static str;

    /// The command, or why the words make none.
    fn spec(&self) -> Result<Self::Spec, ParseError>;
}

/// The preview of a cyclic command: its first frame, its schedule, `extra` (the SYNC
/// counter), whether it runs as a job and the mapped signals sent as 0.
pub(crate) fn cyclic_preview(cmd: &impl Spec, known: &Known<'_>, extra: &str) -> Result<Preview, CommandError> {
    let mut src = cmd
        .source(known.bindings)
        .unwrap_or_else(|| Err(CommandError::Usage("not a cyclic command".into())))?;
    let mut text = format!("{} {}{extra}", candump(&src.frame(0)), src.schedule.text());
    if src.schedule.total().is_none() {
        text.push_str(" (a job: `jobs` lists, `jobs stop ID` or stop-all stops)");
    }
    if !src.defaulted.is_empty() {
        text.push_str(&format!("; not given, sent as 0: {}", src.defaulted.join(", ")));
    }
    Ok(Preview::sends(text))
}

/// Runs a cyclic command until its schedule ends or `ctx.stop` completes; its report.
pub(crate) async fn cyclic_run(cmd: &impl Spec, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
    let src = cmd
        .source(ctx.bindings)
        .unwrap_or_else(|| Err(CommandError::Usage("not a cyclic command".into())))?;
    let report = super::cyclic::transmit(ctx.bus, src, ctx.progress, ctx.stop).await?;
    let text = report.text();
    Ok(Outcome::new(report, text))
}
