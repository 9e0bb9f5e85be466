//! Why a command failed, with the exit status of each case.

use crate::bus::BusError;
use crate::sdo::abort_text;

/// Exit status: done.
pub const EXIT_OK: i32 = 0;
/// Exit status: usage or internal error.
pub const EXIT_USAGE: i32 = 1;
/// Exit status: bus unavailable.
pub const EXIT_BUS: i32 = 2;
/// Exit status: SDO abort.
pub const EXIT_ABORT: i32 = 3;
/// Exit status: timeout.
pub const EXIT_TIMEOUT: i32 = 4;
/// Exit status: drive sequence failed.
pub const EXIT_DRIVE: i32 = 5;

/// A failed command.
#[derive(Clone, Debug, PartialEq)]
pub enum CommandError {
    /// Bad arguments or a local problem (file, type).
    Usage(String),
    /// The bus could not be opened or used.
    Bus(BusError),
    /// The SDO transfer was aborted (by the server, or by us for a protocol error, when
    /// `reason` says what the server did wrong).
    Abort {
        node: u8,
        index: u16,
        sub: u8,
        code: u32,
        by_server: bool,
        reason: Option<String>,
    },
    /// No answer in time.
    Timeout(String),
    /// A drive sequence step did not happen; `reason` says why, from what the bus shows.
    Drive { node: u8, step: String, reason: String },
    /// A procedure stopped at step `step` of `of` because of `cause`; `report` is the run's
    /// JSON so far (`procedure`, `node`, `steps` done, the failed one last).
    Step {
        procedure: String,
        step: usize,
        of: usize,
        report: Box<serde_json::Value>,
        cause: Box<CommandError>,
    },
    /// A stop did not confirm every drive stopped (or could not send at all); `report` is
    /// the stop's JSON (`nodes` with `stopped` and `reason` each), `text` its text.
    NotStopped {
        report: Box<serde_json::Value>,
        text: String,
    },
}

impl CommandError {
    /// The process exit status for this failure.
    pub fn exit_code(&self) -> i32 {
        match self {
            CommandError::Usage(_) => EXIT_USAGE,
            CommandError::Bus(_) => EXIT_BUS,
            CommandError::Abort { .. } => EXIT_ABORT,
            CommandError::Timeout(_) => EXIT_TIMEOUT,
            CommandError::Drive { .. } => EXIT_DRIVE,
            CommandError::Step { cause, .. } => cause.exit_code(),
            CommandError::NotStopped { .. } => EXIT_DRIVE,
        }
    }
    /// The `--json` object of the failure.
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::json;
        match self {
            CommandError::Usage(m) => json!({"ok": false, "error": "usage", "message": m}),
            CommandError::Bus(e) => json!({"ok": false, "error": "bus", "message": e.to_string()}),
            CommandError::Abort {
                node,
                index,
                sub,
                code,
                by_server,
                reason,
            } => {
                let mut v = json!({
                    "ok": false, "error": "sdo_abort", "node": node,
                    "index": index, "sub": sub,
                    "abort_code": code, "abort_text": abort_text(*code),
                    "aborted_by": if *by_server { "server" } else { "client" },
                    "message": self.to_string(),
                });
                if let (Some(r), Some(o)) = (reason, v.as_object_mut()) {
                    o.insert("reason".into(), r.as_str().into());
                }
                v
            }
            CommandError::Timeout(m) => json!({"ok": false, "error": "timeout", "message": m}),
            CommandError::NotStopped { report, text } => {
                let mut v = (**report).clone();
                if let Some(o) = v.as_object_mut() {
                    o.insert("ok".into(), false.into());
                    o.insert("error".into(), "not_stopped".into());
                    o.insert("message".into(), text.clone().into());
                }
                v
            }
            CommandError::Drive { node, step, reason } => json!({
                "ok": false, "error": "drive", "node": node, "step": step, "reason": reason,
                "message": self.to_string(),
            }),
            CommandError::Step {
                step, report, cause, ..
            } => {
                let mut v = cause.to_json();
                if let (Some(out), Some(r)) = (v.as_object_mut(), report.as_object()) {
                    for (k, x) in r {
                        out.insert(k.clone(), x.clone());
                    }
                    out.insert("ok".into(), false.into());
                    out.insert("failed_step".into(), (*step).into());
                    out.insert("message".into(), self.to_string().into());
                }
                v
            }
        }
    }
}

impl std::fmt::Display for CommandError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CommandError::Usage(m) | CommandError::Timeout(m) => write!(f, "{m}"),
            CommandError::NotStopped { text, .. } => write!(f, "{text}"),
            CommandError::Bus(e) => write!(f, "{e}"),
            CommandError::Abort {
                node,
                index,
                sub,
                code,
                by_server,
                reason,
            } => {
                write!(
                    f,
                    "SDO {index:04X}:{sub:02X} on node {node} aborted by the {}: 0x{code:08X} {}",
                    if *by_server { "server" } else { "client" },
                    abort_text(*code)
                )?;
                match reason {
                    Some(r) => write!(f, " ({r})"),
                    None => Ok(()),
                }
            }
            CommandError::Drive { node, step, reason } => write!(f, "drive {node}: {step} failed: {reason}"),
            CommandError::Step {
                procedure,
                step,
                of,
                cause,
                ..
            } => write!(f, "`{procedure}` stopped at step {step}/{of}: {cause}"),
        }
    }
}

impl From<BusError> for CommandError {
    fn from(e: BusError) -> Self {
        CommandError::Bus(e)
    }
}
