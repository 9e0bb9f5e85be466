//! What a commander command is, once: its words (a clap `Args` type, [`CommandArgs`]), what it
//! will send ([`Spec::preview`], the exact frames from the protocol layer), how it runs
//! ([`Spec::run`]) and what it reports (a `#[derive(Serialize)]` type in an [`Outcome`]).
//! Each command is one module implementing these; `super::registry` lists them.

use super::cyclic::{Progress, Source};
use super::error::CommandError;
use super::syntax::ParseError;
use crate::bus::Bus;
use crate::decode::cia402::DriveState;
use crate::od::bind::Bindings;
use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;

/// A command's `--json` report: a `#[derive(Serialize)]` type, made JSON when it is written.
pub trait Report: Send + Sync {
    /// The JSON object written (keys sorted, as `--json` prints them).
    fn to_json(&self) -> serde_json::Value;
}

impl<T: serde::Serialize + Send + Sync> Report for T {
    fn to_json(&self) -> serde_json::Value {
        // Serializing these plain structs cannot fail; a failure would give null.
        serde_json::to_value(self).unwrap_or_default()
    }
}

/// A typed report, shared (an [`Outcome`], or the report a failure carries).
#[derive(Clone)]
pub struct Reported(Arc<dyn Report>);

impl Reported {
    /// Keeps `report` as it is until written.
    pub fn new(report: impl Report + 'static) -> Reported {
        Reported(Arc::new(report))
    }

    /// The JSON object written.
    pub fn to_json(&self) -> serde_json::Value {
        self.0.to_json()
    }
}

/// Shown as the JSON it writes.
impl fmt::Debug for Reported {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.to_json())
    }
}

/// Two reports are equal when they write the same JSON.
impl PartialEq for Reported {
    fn eq(&self, other: &Self) -> bool {
        self.to_json() == other.to_json()
    }
}

impl serde::Serialize for Reported {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(s)
    }
}

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

    /// True when it writes its data to stdout (`-o -`): its report then goes to stderr.
    fn data_to_stdout(&self) -> bool {
        false
    }
}

/// A command's words as clap declares them (`D`: the dictionary options where the command
/// line has them).
pub trait CommandArgs<D>: clap::Args {
    /// The command the words make.
    type Spec: Spec;

    /// What failures are prefixed with: `cotui sdo read: ...`.
    fn name(&self) -> &'static str;

    /// The command, or why the words make none (checks clap cannot make alone).
    fn spec(&self) -> Result<Self::Spec, ParseError>;

    /// The dictionary options, for a command that takes them.
    fn dict(&self) -> Option<&D> {
        None
    }
}

/// One entry of the commander's declaration: a command's words with the options in front
/// of them (`B`, see `super::syntax::On`), or a group of commands (`sdo read|write`).
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
