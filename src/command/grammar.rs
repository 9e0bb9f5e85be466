//! The command grammar shared by the command line and the TUI palette:
//! `parse_command("sdo read 2 0x6041")` gives the same [`Command`] as
//! `cotui sdo read IFACE 2 0x6041`.

use super::record::{Limits, LogFormat, WriteMode};
use crate::od::DataType;

/// An NMT command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NmtAction {
    Start,
    Stop,
    PreOp,
    ResetNode,
    ResetComm,
}

impl NmtAction {
    /// The NMT command specifier.
    pub fn cs(self) -> u8 {
        match self {
            NmtAction::Start => 0x01,
            NmtAction::Stop => 0x02,
            NmtAction::PreOp => 0x80,
            NmtAction::ResetNode => 0x81,
            NmtAction::ResetComm => 0x82,
        }
    }
    /// The word used on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            NmtAction::Start => "start",
            NmtAction::Stop => "stop",
            NmtAction::PreOp => "preop",
            NmtAction::ResetNode => "reset-node",
            NmtAction::ResetComm => "reset-comm",
        }
    }
    /// Parses `start|stop|preop|reset-node|reset-comm`.
    pub fn parse(word: &str) -> Result<NmtAction, String> {
        Ok(match word {
            "start" => NmtAction::Start,
            "stop" => NmtAction::Stop,
            "preop" | "pre-op" | "preoperational" => NmtAction::PreOp,
            "reset-node" => NmtAction::ResetNode,
            "reset-comm" => NmtAction::ResetComm,
            _ => {
                return Err(format!(
                    "unknown NMT command `{word}`: use start, stop, preop, reset-node or reset-comm"
                ));
            }
        })
    }
}

/// A CiA 402 drive command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriveAction {
    Enable,
    Disable,
    QuickStop,
    FaultReset,
    Status,
    /// Set the mode of operation (0x6060) and wait for 0x6061 to show it.
    Mode(i8),
}

impl DriveAction {
    /// Parses `enable|disable|quick-stop|fault-reset|status|mode MODE`.
    pub fn parse(word: &str, arg: Option<&str>) -> Result<DriveAction, String> {
        Ok(match word {
            "enable" => DriveAction::Enable,
            "disable" => DriveAction::Disable,
            "quick-stop" | "quickstop" => DriveAction::QuickStop,
            "fault-reset" => DriveAction::FaultReset,
            "status" => DriveAction::Status,
            "mode" => DriveAction::Mode(parse_mode(arg.ok_or("drive mode needs a MODE (e.g. pv, csp, 3)")?)?),
            _ => {
                return Err(format!(
                    "unknown drive command `{word}`: use enable, disable, quick-stop, fault-reset, status or mode MODE"
                ));
            }
        })
    }
    /// The word used on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            DriveAction::Enable => "enable",
            DriveAction::Disable => "disable",
            DriveAction::QuickStop => "quick-stop",
            DriveAction::FaultReset => "fault-reset",
            DriveAction::Status => "status",
            DriveAction::Mode(_) => "mode",
        }
    }
}

/// A mode of operation by CiA 402 abbreviation (`pp`, `pv`, `pt`, `hm`, `ip`, `csp`, `csv`, `cst`) or number.
pub fn parse_mode(text: &str) -> Result<i8, String> {
    Ok(match text.to_ascii_lowercase().as_str() {
        "pp" => 1,
        "vl" => 2,
        "pv" => 3,
        "pt" | "tq" => 4,
        "hm" | "homing" => 6,
        "ip" => 7,
        "csp" => 8,
        "csv" => 9,
        "cst" => 10,
        other => parse_int(other)
            .filter(|v| (-128..=127).contains(v))
            .map(|v| v as i8)
            .ok_or_else(|| format!("unknown mode `{text}`: use pp, pv, pt, hm, ip, csp, csv, cst or a number"))?,
    })
}

/// Options of an SDO transfer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SdoOptions {
    /// `--type`: how to encode/decode the value (else from the dictionary, else raw).
    pub data_type: Option<DataType>,
    /// `--block`: force a block transfer.
    pub block: bool,
    /// `--timeout`: ms to wait for each server response.
    pub timeout_ms: u64,
    /// `--deadline`: ms the whole transfer may take (`None`: the client's default, see
    /// [`crate::sdo::client::ClientConfig::default_deadline_ns`]).
    pub deadline_ms: Option<u64>,
}

/// Default SDO response timeout in ms.
pub const DEFAULT_TIMEOUT_MS: u64 = 1000;

impl Default for SdoOptions {
    fn default() -> Self {
        SdoOptions {
            data_type: None,
            block: false,
            timeout_ms: DEFAULT_TIMEOUT_MS,
            deadline_ms: None,
        }
    }
}

/// Default wait of `nmt --wait` in ms.
pub const NMT_WAIT_MS: u64 = 2000;
/// Default SDO timeout of `scan` in ms (short: absent nodes cost this much).
pub const SCAN_TIMEOUT_MS: u64 = 300;
/// Default listening time of `scan` in ms (longer than common heartbeat periods).
pub const SCAN_LISTEN_MS: u64 = 1500;

/// One command of the commander (the interface is chosen separately).
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `nmt ACTION NODE [--wait] [--timeout MS]` (NODE 0 = all nodes).
    Nmt {
        action: NmtAction,
        node: u8,
        wait: bool,
        timeout_ms: u64,
    },
    /// `sdo read NODE OBJECT [--type T] [--block] [--timeout MS] [--deadline MS] [-o FILE]`.
    SdoRead {
        node: u8,
        object: String,
        options: SdoOptions,
        /// Also write the data read to this file (domains).
        output: Option<String>,
    },
    /// `sdo write NODE OBJECT VALUE [--type T] [--block] [--timeout MS] [--deadline MS]` (a file path for domains).
    SdoWrite {
        node: u8,
        object: String,
        value: String,
        options: SdoOptions,
    },
    /// `drive NODE ACTION [MODE] [--timeout MS]`.
    Drive {
        node: u8,
        action: DriveAction,
        timeout_ms: u64,
    },
    /// `scan [--listen MS] [--probe] [--timeout MS]`.
    Scan {
        listen_ms: u64,
        probe: bool,
        timeout_ms: u64,
    },
    /// `record -o FILE [--count N] [--duration MS] [--force | --append] [--format candump|pcapng]`.
    Record {
        output: String,
        limits: Limits,
        mode: WriteMode,
        format: LogFormat,
    },
    /// `run NODE PROCEDURE [NAME=VALUE ...] [--dry-run] [--timeout MS]`, or `run NODE [--list]`.
    Run(RunSpec),
    /// `stop [NODE ...] [--listen MS] [--ramp MS] [--timeout MS]`: quick stop and disable
    /// voltage on these nodes, or (none given) on every CiA 402 drive found powered.
    Stop {
        nodes: Vec<u8>,
        listen_ms: u64,
        options: super::stop::StopOptions,
    },
}

/// What `run` runs: a procedure of a node with its parameters, or (no procedure) the list.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunSpec {
    /// The target node.
    pub node: u8,
    /// `None`: list the node's procedures.
    pub procedure: Option<String>,
    /// Parameters as given, `NAME=VALUE` split at the first `=`.
    pub args: Vec<(String, String)>,
    /// Show the steps and frames without sending anything.
    pub dry_run: bool,
    /// ms to wait for each SDO answer.
    pub timeout_ms: u64,
}

/// Splits `NAME=VALUE` procedure arguments.
pub fn parse_assignments(words: &[&str]) -> Result<Vec<(String, String)>, String> {
    words
        .iter()
        .map(|w| match w.split_once('=') {
            Some((n, v)) if !n.is_empty() => Ok((n.to_string(), v.to_string())),
            _ => Err(format!("`{w}` is not a parameter: write NAME=VALUE, e.g. speed=100")),
        })
        .collect()
}

/// The `run` command from its words after NODE: `[PROCEDURE] [NAME=VALUE ...]`.
pub fn run_spec(node: u8, rest: &[&str], list: bool, dry_run: bool, timeout_ms: u64) -> Result<RunSpec, String> {
    let (procedure, assignments) = match rest.split_first() {
        Some((p, more)) if !p.contains('=') => (Some(p.to_string()), more),
        _ => (None, rest),
    };
    let args = parse_assignments(assignments)?;
    if procedure.is_none() && !args.is_empty() {
        return Err("run: give the PROCEDURE before its NAME=VALUE parameters".into());
    }
    if list && procedure.is_some() {
        return Err("run: give a PROCEDURE or --list, not both".into());
    }
    Ok(RunSpec {
        node,
        procedure,
        args,
        dry_run,
        timeout_ms,
    })
}

/// Parses a number: decimal, `0x` hex, or negative decimal.
pub fn parse_int(text: &str) -> Option<i64> {
    let t = text.trim();
    let (neg, body) = match t.strip_prefix('-') {
        Some(b) => (true, b),
        None => (false, t.strip_prefix('+').unwrap_or(t)),
    };
    let v = match body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) {
        Some(h) if !h.is_empty() => i128::from_str_radix(&h.replace('_', ""), 16).ok()?,
        Some(_) => return None,
        None if !body.is_empty() && body.bytes().all(|b| b.is_ascii_digit() || b == b'_') => {
            body.replace('_', "").parse::<i128>().ok()?
        }
        None => return None,
    };
    let v = if neg { -v } else { v };
    (i64::MIN as i128..=u64::MAX as i128)
        .contains(&v)
        .then_some(if v > i64::MAX as i128 {
            v as u64 as i64
        } else {
            v as i64
        })
}

/// Parses a node id: 0..=127 where `allow_all`, else 1..=127.
pub fn parse_node(text: &str, allow_all: bool) -> Result<u8, String> {
    let lo = if allow_all { 0 } else { 1 };
    match parse_int(text) {
        Some(n) if (lo..=127).contains(&n) => Ok(n as u8),
        _ => Err(format!("node `{text}` must be a number {lo}..127 (decimal or 0x hex)")),
    }
}

/// Parses a `--type` name: u8..u64, i8..i64, f32, f64, bool, string, octets (hex), domain.
pub fn parse_type(name: &str) -> Result<DataType, String> {
    use DataType::*;
    Ok(match name.to_ascii_lowercase().as_str() {
        "u8" => U8,
        "u16" => U16,
        "u24" => U24,
        "u32" => U32,
        "u40" => U40,
        "u48" => U48,
        "u56" => U56,
        "u64" => U64,
        "i8" => I8,
        "i16" => I16,
        "i24" => I24,
        "i32" => I32,
        "i40" => I40,
        "i48" => I48,
        "i56" => I56,
        "i64" => I64,
        "f32" | "real32" => F32,
        "f64" | "real64" => F64,
        "bool" | "boolean" => Boolean,
        "string" | "str" | "vs" | "visible_string" => VisibleString,
        "octets" | "octet_string" | "hex" | "os" => OctetString,
        "domain" => Domain,
        _ => {
            return Err(format!(
                "unknown type `{name}`: use u8..u64, i8..i64, f32, f64, bool, string, octets or domain"
            ));
        }
    })
}

/// Splits a palette line into words, keeping `"quoted strings"` together.
fn words(line: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut any = false;
    for c in line.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                any = true;
            }
            c if c.is_whitespace() && !quoted => {
                if any {
                    out.push(std::mem::take(&mut cur));
                    any = false;
                }
            }
            c => {
                cur.push(c);
                any = true;
            }
        }
    }
    if quoted {
        return Err("unterminated quote".into());
    }
    if any {
        out.push(cur);
    }
    Ok(out)
}

fn positive(flag: &str, v: &str) -> Result<u64, String> {
    parse_int(v)
        .filter(|t| *t > 0)
        .map(|t| t as u64)
        .ok_or(format!("{flag} `{v}` must be a positive number"))
}

/// Parses one palette line, e.g. `sdo read 2 0x6041`, `nmt start 0 --wait`,
/// `sdo write 2 0x6060 3 --type i8`, `drive 2 enable`, `drive 2 mode pv`, `scan`, `record -o f.log`.
pub fn parse_command(line: &str) -> Result<Command, String> {
    let all = words(line)?;
    let mut pos: Vec<&str> = Vec::new();
    let mut data_type = None;
    let (mut block, mut wait, mut probe, mut list, mut dry_run) = (false, false, false, false, false);
    let (mut output, mut timeout, mut listen, mut ramp, mut deadline) = (None, None, None, None, None);
    let mut limits = Limits::default();
    let mut mode = WriteMode::New;
    let mut format = LogFormat::Candump;
    let mut it = all.iter();
    while let Some(w) = it.next() {
        let mut value = |flag: &str| it.next().map(String::as_str).ok_or(format!("{flag} needs a value"));
        match w.as_str() {
            "--wait" => wait = true,
            "--block" => block = true,
            "--probe" => probe = true,
            "--list" => list = true,
            "--dry-run" => dry_run = true,
            "--force" | "--append" if mode != WriteMode::New => {
                return Err("record takes --force or --append, not both".into());
            }
            "--format" => format = LogFormat::parse(value("--format")?)?,
            "--force" => mode = WriteMode::Overwrite,
            "--append" => mode = WriteMode::Append,
            "--type" | "-t" => data_type = Some(parse_type(value("--type")?)?),
            "--timeout" => timeout = Some(positive("--timeout", value("--timeout")?)?),
            "--listen" => listen = Some(positive("--listen", value("--listen")?)?),
            "--ramp" => ramp = Some(positive("--ramp", value("--ramp")?)?),
            "--deadline" => deadline = Some(positive("--deadline", value("--deadline")?)?),
            "--count" => limits.count = Some(positive("--count", value("--count")?)?),
            "--duration" => limits.duration_ms = Some(positive("--duration", value("--duration")?)?),
            "-o" | "--output" => output = Some(value("-o")?.to_string()),
            w if w.starts_with('-') && w.len() > 1 && parse_int(w).is_none() => {
                return Err(format!("unknown option `{w}`"));
            }
            w => pos.push(w),
        }
    }
    let options = SdoOptions {
        data_type,
        block,
        timeout_ms: timeout.unwrap_or(DEFAULT_TIMEOUT_MS),
        deadline_ms: deadline,
    };
    let usage = "commands: nmt ACTION NODE, sdo read NODE OBJECT, sdo write NODE OBJECT VALUE, \
                 drive NODE ACTION, run NODE PROCEDURE [NAME=VALUE ...], scan, record -o FILE, stop [NODE ...]";
    match pos.as_slice() {
        ["nmt", action, node] => Ok(Command::Nmt {
            action: NmtAction::parse(action)?,
            node: parse_node(node, true)?,
            wait,
            timeout_ms: timeout.unwrap_or(NMT_WAIT_MS),
        }),
        ["sdo", "read", node, object] => Ok(Command::SdoRead {
            node: parse_node(node, false)?,
            object: object.to_string(),
            options,
            output,
        }),
        ["sdo", "write", node, object, value] => Ok(Command::SdoWrite {
            node: parse_node(node, false)?,
            object: object.to_string(),
            value: value.to_string(),
            options,
        }),
        ["drive", node, action, rest @ ..] if rest.len() <= 1 => Ok(Command::Drive {
            node: parse_node(node, false)?,
            action: DriveAction::parse(action, rest.first().copied())?,
            timeout_ms: timeout.unwrap_or(DEFAULT_TIMEOUT_MS),
        }),
        ["run", node, rest @ ..] => Ok(Command::Run(run_spec(
            parse_node(node, false)?,
            rest,
            list,
            dry_run,
            timeout.unwrap_or(DEFAULT_TIMEOUT_MS),
        )?)),
        ["scan"] => Ok(Command::Scan {
            listen_ms: listen.unwrap_or(SCAN_LISTEN_MS),
            probe,
            timeout_ms: timeout.unwrap_or(SCAN_TIMEOUT_MS),
        }),
        ["stop", nodes @ ..] => Ok(Command::Stop {
            nodes: nodes.iter().map(|n| parse_node(n, false)).collect::<Result<_, _>>()?,
            listen_ms: listen.unwrap_or(super::stop::DEFAULT_LISTEN_MS),
            options: super::stop::StopOptions {
                timeout_ms: timeout.unwrap_or(DEFAULT_TIMEOUT_MS),
                ramp_ms: ramp.unwrap_or(super::stop::DEFAULT_RAMP_MS),
            },
        }),
        ["record"] => Ok(Command::Record {
            output: output.ok_or("record needs -o FILE")?,
            limits,
            mode,
            format,
        }),
        [] => Err(format!("empty command; {usage}")),
        [first, ..] => Err(format!("cannot parse `{}` (after `{first}`); {usage}", all.join(" "))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_lines() {
        assert_eq!(
            parse_command("sdo read 2 0x6041").unwrap(),
            Command::SdoRead {
                node: 2,
                object: "0x6041".into(),
                options: SdoOptions::default(),
                output: None,
            }
        );
        assert_eq!(
            parse_command("sdo write 0x02 0x1008 \"my drive\" --type string --block --timeout 300").unwrap(),
            Command::SdoWrite {
                node: 2,
                object: "0x1008".into(),
                value: "my drive".into(),
                options: SdoOptions {
                    data_type: Some(DataType::VisibleString),
                    block: true,
                    timeout_ms: 300,
                    deadline_ms: None
                }
            }
        );
        assert_eq!(
            parse_command("nmt reset-node 0 --wait").unwrap(),
            Command::Nmt {
                action: NmtAction::ResetNode,
                node: 0,
                wait: true,
                timeout_ms: NMT_WAIT_MS,
            }
        );
        assert_eq!(
            parse_command("drive 3 mode csv").unwrap(),
            Command::Drive {
                node: 3,
                action: DriveAction::Mode(9),
                timeout_ms: DEFAULT_TIMEOUT_MS
            }
        );
        assert_eq!(
            parse_command("sdo write 2 0x60FF -100 --type i32")
                .map(|c| matches!(c, Command::SdoWrite { value, .. } if value == "-100")),
            Ok(true)
        );
        assert_eq!(
            parse_command("scan --probe --listen 500").unwrap(),
            Command::Scan {
                listen_ms: 500,
                probe: true,
                timeout_ms: SCAN_TIMEOUT_MS
            }
        );
        assert_eq!(
            parse_command("record -o out.log").unwrap(),
            Command::Record {
                output: "out.log".into(),
                limits: Limits::default(),
                mode: WriteMode::New,
                format: LogFormat::Candump,
            }
        );
        assert_eq!(
            parse_command("record -o out.log --append --count 5").unwrap(),
            Command::Record {
                output: "out.log".into(),
                limits: Limits {
                    count: Some(5),
                    duration_ms: None
                },
                mode: WriteMode::Append,
                format: LogFormat::Candump,
            }
        );
        assert!(matches!(
            parse_command("record --force -o out.log"),
            Ok(Command::Record {
                mode: WriteMode::Overwrite,
                ..
            })
        ));
        assert!(
            parse_command("record -o x --force --append")
                .unwrap_err()
                .contains("not both")
        );
    }

    #[test]
    fn errors_say_what_is_wrong() {
        assert_eq!(
            parse_command("sdo read 0 0x6041").unwrap_err(),
            "node `0` must be a number 1..127 (decimal or 0x hex)"
        );
        assert!(
            parse_command("nmt go 2")
                .unwrap_err()
                .contains("unknown NMT command `go`")
        );
        assert!(
            parse_command("sdo read 2 0x6041 --type u7")
                .unwrap_err()
                .contains("unknown type `u7`")
        );
        assert!(
            parse_command("drive 2 fly")
                .unwrap_err()
                .contains("unknown drive command")
        );
        assert!(parse_command("record").unwrap_err().contains("-o FILE"));
        assert!(parse_command("").unwrap_err().starts_with("empty command"));
    }

    #[test]
    fn run_lines() {
        assert_eq!(
            parse_command("run 2 pv speed=100 accel=0x10 --dry-run").unwrap(),
            Command::Run(RunSpec {
                node: 2,
                procedure: Some("pv".into()),
                args: vec![("speed".into(), "100".into()), ("accel".into(), "0x10".into())],
                dry_run: true,
                timeout_ms: DEFAULT_TIMEOUT_MS,
            })
        );
        assert!(matches!(
            parse_command("run 3 --list").unwrap(),
            Command::Run(RunSpec {
                node: 3,
                procedure: None,
                ..
            })
        ));
        assert!(parse_command("run 2 pv speed").unwrap_err().contains("NAME=VALUE"));
        assert!(parse_command("run 2 speed=1").unwrap_err().contains("PROCEDURE before"));
        assert!(parse_command("run 2 pv --list").unwrap_err().contains("not both"));
    }

    #[test]
    fn numbers() {
        assert_eq!(parse_int("0x1F"), Some(31));
        assert_eq!(parse_int("-5"), Some(-5));
        assert_eq!(parse_int("0xFFFFFFFFFFFFFFFF"), Some(-1));
        assert_eq!(parse_int("12a"), None);
        assert_eq!(parse_int("0x"), None);
        assert_eq!(parse_node("0x7F", false), Ok(127));
        assert!(parse_node("128", true).is_err());
    }
}
