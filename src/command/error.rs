//! Why a command failed, with the exit status of each case.

use super::report::Reported;
use super::report::to_json;
use crate::bus::BusError;
use crate::sdo::abort_text;
use clap::error::ErrorKind;
use serde::Serialize;

/// The process exit status of cotui, one value per kind of outcome (docs/COMMANDER.md,
/// "Exit status").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ExitCode {
    /// 0: done.
    Ok = 0,
    /// 1: usage or internal error (bad arguments, a file that cannot be written...).
    Usage = 1,
    /// 2: input or bus unavailable (missing, down, no permission, listen-only), or a
    /// recording with gaps.
    Unavailable = 2,
    /// 3: SDO abort, or an LSS slave refused a configuration.
    Abort = 3,
    /// 4: timeout (an SDO answer, or a transfer's deadline).
    Timeout = 4,
    /// 5: a drive sequence or a procedure's wait failed, or a stop was not confirmed.
    Drive = 5,
    /// 6: the node differs from what was asked: its configuration from a DCF (`dcf diff`,
    /// or a `dcf load` whose values did not read back), or a `pdo map` read back.
    Differs = 6,
}

impl ExitCode {
    /// The number the process exits with.
    pub fn code(self) -> i32 {
        self as i32
    }
}

/// The status compares with its number: `assert_eq!(e.exit_code(), 3)`.
impl PartialEq<i32> for ExitCode {
    fn eq(&self, other: &i32) -> bool {
        self.code() == *other
    }
}

/// Why a command line is not a command.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseError {
    /// A palette line with an unbalanced quote.
    #[error("unterminated quote")]
    Quote,
    /// An empty palette line; the commands there are, comma-separated.
    #[error("empty command; commands: {0}")]
    Empty(String),
    /// The declaration refused the words: an unknown flag, an extra or missing word, a bad
    /// value. `message` is clap's error line (with its tips), `usage` the command's usage.
    #[error("{message}")]
    Rejected { message: String, usage: String },
    /// `--help`: the help text.
    #[error("{0}")]
    Help(String),
    /// Words the declaration accepts that do not make a command (e.g. a MODE after
    /// `drive N enable`, a parameter before the procedure).
    #[error("{0}")]
    Invalid(String),
}

impl From<clap::Error> for ParseError {
    fn from(e: clap::Error) -> Self {
        let text = e.render().to_string();
        if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
            return ParseError::Help(text.trim_end().to_string());
        }
        let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
        let first = lines.next().unwrap_or("");
        let mut message = first.strip_prefix("error: ").unwrap_or(first).to_string();
        let mut usage = String::new();
        for l in lines {
            if let Some(u) = l.strip_prefix("Usage: ") {
                usage = u.to_string();
            } else if l.starts_with("For more information") {
                break;
            } else if l.starts_with("tip: to pass") {
                // `-- --flag`: no line of ours takes a value that starts with `-`.
            } else if usage.is_empty() {
                // The arguments missing, the tips: part of the message.
                message.push_str(if l.starts_with("tip: ") { "; " } else { " " });
                message.push_str(l);
            }
        }
        ParseError::Rejected { message, usage }
    }
}

/// A failed command.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CommandError {
    /// The words are not a command (see [`ParseError`]).
    #[error(transparent)]
    Syntax(#[from] ParseError),
    /// Bad arguments or a local problem (object, value, file, type).
    #[error("{0}")]
    Usage(String),
    /// The bus could not be opened or used.
    #[error(transparent)]
    Bus(#[from] BusError),
    /// The SDO transfer was aborted (by the server, or by us for a protocol error, when
    /// `reason` says what the server did wrong).
    #[error(
        "SDO {index:04X}:{sub:02X} on node {node} aborted by the {}: 0x{code:08X} {}{}",
        if *.by_server { "server" } else { "client" },
        abort_text(*.code),
        .reason.as_ref().map(|r| format!(" ({r})")).unwrap_or_default()
    )]
    Abort {
        node: u8,
        index: u16,
        sub: u8,
        code: u32,
        by_server: bool,
        reason: Option<String>,
    },
    /// No answer in time.
    #[error("{0}")]
    Timeout(String),
    /// An LSS slave answered a configure or store service with an error code.
    #[error("LSS {service}: the slave refused: {text} (error code {error})")]
    LssRefused {
        service: &'static str,
        error: u8,
        spec: u8,
        text: String,
    },
    /// A drive sequence step did not happen; `reason` says why, from what the bus shows.
    #[error("drive {node}: {step} failed: {reason}")]
    Drive { node: u8, step: String, reason: String },
    /// A procedure stopped at step `step` of `of` because of `cause`; `report` is the run's
    /// JSON so far (`procedure`, `node`, `steps` done, the failed one last).
    #[error("`{procedure}` stopped at step {step}/{of}: {cause}")]
    Step {
        procedure: String,
        step: usize,
        of: usize,
        report: Reported,
        cause: Box<CommandError>,
    },
    /// A stop did not confirm every drive stopped (or could not send at all); `report` is
    /// the stop's JSON (`nodes` with `stopped` and `reason` each), `text` its text.
    #[error("{text}")]
    NotStopped { report: Reported, text: String },
    /// A command that finished with a report that is a failure (`dcf diff` found
    /// differences, `dcf load` was refused, a `pdo map` did not read back as written):
    /// `report` is its JSON, `text` its text, `error` the JSON `error` word.
    #[error("{text}")]
    Report {
        exit: ExitCode,
        error: &'static str,
        report: Reported,
        text: String,
    },
}

impl CommandError {
    /// The process exit status for this failure.
    pub fn exit_code(&self) -> ExitCode {
        match self {
            CommandError::Syntax(_) | CommandError::Usage(_) => ExitCode::Usage,
            CommandError::Bus(_) => ExitCode::Unavailable,
            CommandError::Abort { .. } | CommandError::LssRefused { .. } => ExitCode::Abort,
            CommandError::Timeout(_) => ExitCode::Timeout,
            CommandError::Drive { .. } => ExitCode::Drive,
            CommandError::Step { cause, .. } => cause.exit_code(),
            CommandError::NotStopped { .. } => ExitCode::Drive,
            CommandError::Report { exit, .. } => *exit,
        }
    }
    /// The `--json` object of the failure.
    pub fn to_json(&self) -> serde_json::Value {
        let message = self.to_string();
        match self {
            CommandError::Syntax(_) | CommandError::Usage(_) => to_json(&Failure {
                ok: false,
                error: "usage",
                message,
            }),
            CommandError::Bus(_) => to_json(&Failure {
                ok: false,
                error: "bus",
                message,
            }),
            CommandError::Timeout(_) => to_json(&Failure {
                ok: false,
                error: "timeout",
                message,
            }),
            CommandError::Abort {
                node,
                index,
                sub,
                code,
                by_server,
                reason,
            } => to_json(&Aborted {
                ok: false,
                error: "sdo_abort",
                node: *node,
                index: *index,
                sub: *sub,
                abort_code: *code,
                abort_text: abort_text(*code),
                aborted_by: if *by_server { "server" } else { "client" },
                message,
                reason: reason.as_deref(),
            }),
            CommandError::LssRefused {
                service,
                error,
                spec,
                text,
            } => to_json(&LssRefused {
                ok: false,
                error: "lss_refused",
                service,
                error_code: *error,
                spec_error: *spec,
                reason: text,
                message,
            }),
            CommandError::NotStopped { report, .. } => {
                let mut v = report.to_json();
                if let Some(o) = v.as_object_mut() {
                    o.insert("ok".into(), false.into());
                    o.insert("error".into(), "not_stopped".into());
                    o.insert("message".into(), message.into());
                }
                v
            }
            CommandError::Report { error, report, .. } => {
                let mut v = report.to_json();
                if let Some(o) = v.as_object_mut() {
                    o.insert("ok".into(), false.into());
                    o.insert("error".into(), (*error).into());
                }
                v
            }
            CommandError::Drive { node, step, reason } => to_json(&DriveFailed {
                ok: false,
                error: "drive",
                node: *node,
                step,
                reason,
                message,
            }),
            CommandError::Step {
                step, report, cause, ..
            } => {
                let mut v = cause.to_json();
                let report = report.to_json();
                if let (Some(out), Some(r)) = (v.as_object_mut(), report.as_object()) {
                    for (k, x) in r {
                        out.insert(k.clone(), x.clone());
                    }
                    out.insert("ok".into(), false.into());
                    out.insert("failed_step".into(), (*step).into());
                    out.insert("message".into(), message.into());
                }
                v
            }
        }
    }
}

/// The JSON of a usage, bus or timeout failure.
#[derive(Serialize)]
struct Failure {
    ok: bool,
    error: &'static str,
    message: String,
}

/// The JSON of an SDO abort.
#[derive(Serialize)]
struct Aborted<'a> {
    ok: bool,
    error: &'static str,
    node: u8,
    index: u16,
    sub: u8,
    abort_code: u32,
    abort_text: &'static str,
    aborted_by: &'static str,
    message: String,
    /// What the server did wrong, when the client aborted.
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<&'a str>,
}

/// The JSON of a failed drive step.
#[derive(Serialize)]
struct DriveFailed<'a> {
    ok: bool,
    error: &'static str,
    node: u8,
    step: &'a str,
    reason: &'a str,
    message: String,
}

/// The JSON of an LSS configuration the slave refused.
#[derive(Serialize)]
struct LssRefused<'a> {
    ok: bool,
    error: &'static str,
    service: &'a str,
    error_code: u8,
    spec_error: u8,
    reason: &'a str,
    message: String,
}
