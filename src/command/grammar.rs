//! What the commander's command language means: the [`Command`] a line parses into (see
//! [`super::syntax`] for the words), its actions and options, and the number, node and type
//! parsers the declaration uses.

use super::record::{Limits, LogFormat, WriteMode};
use super::syntax::ParseError;
use crate::od::DataType;

/// A mode of operation by CiA 402 abbreviation (`pp`, `pv`, `pt`, `hm`, `ip`, `csp`, `csv`, `cst`) or number.
pub fn parse_mode(text: &str) -> Result<i8, ParseError> {
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
            .ok_or_else(|| {
                ParseError::Invalid(format!(
                    "unknown mode `{text}`: use pp, pv, pt, hm, ip, csp, csv, cst or a number"
                ))
            })?,
    })
}

/// Default SDO response timeout in ms.
pub const DEFAULT_TIMEOUT_MS: u64 = 1000;

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
    Nmt(super::nmt::Nmt),
    /// `sdo read NODE OBJECT ...`, `sdo write NODE OBJECT VALUE ...`.
    Sdo(super::object::Sdo),
    /// `drive NODE ACTION [MODE] [--timeout MS]`.
    Drive(super::drive::Drive),
    /// `scan [--listen MS] [--probe] [--timeout MS]`.
    Scan {
        listen_ms: u64,
        probe: bool,
        timeout_ms: u64,
    },
    /// `record -o FILE [--count N] [--duration MS] [--force | --append] [--format candump|pcapng|blf]`.
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
    /// `lss ACTION [WORDS...] [--timeout MS] [--vendor V] [--product P] [--store]`: an LSS
    /// master service (CiA 305), addressed to every slave in configuration state.
    Lss {
        action: super::lss::LssAction,
        timeout_ms: u64,
    },
    /// `send FRAME [--every MS] [--count N]`: a raw frame in candump's compact form.
    Send(super::send::Send),
    /// `sync --period MS [--counter N] [--count N] [--cob-id ID]`: the SYNC producer.
    Sync(super::sync::Sync),
    /// `pdo NODE send rpdoK NAME=VALUE ... [--every MS] [--count N]`: an RPDO encoded
    /// through the node's mapping.
    Pdo {
        node: u8,
        /// The RPDO number (1-based).
        num: u16,
        assignments: Vec<(String, String)>,
        schedule: super::cyclic::Schedule,
    },
    /// `pdo NODE [--timeout MS]`: reads every PDO's communication and mapping parameters.
    PdoRead { node: u8, timeout_ms: u64 },
    /// `pdo NODE map PDO OBJECT... [--type T] [--event MS] [--inhibit T] [--cob-id ID]
    /// [--dry-run] [--force] [--timeout MS]`: the CiA 301 remapping sequence.
    PdoMap(super::pdo::MapSpec),
    /// `dcf save|load|diff NODE ...`: a node's configuration as a CiA 306 DCF.
    Dcf(super::dcf::DcfCommand),
}

impl Command {
    /// True when the command writes its data to stdout (`-o -`): its report (text or JSON)
    /// then goes to stderr, so that stdout is the data alone.
    pub fn data_to_stdout(&self) -> bool {
        match self {
            Command::Record { output, .. } => output == "-",
            Command::Sdo(c) => super::spec::Spec::data_to_stdout(c),
            Command::Dcf(d) => matches!(&d.action, super::dcf::DcfAction::Save { output, .. } if output == "-"),
            _ => false,
        }
    }
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
pub fn parse_assignments(words: &[&str]) -> Result<Vec<(String, String)>, ParseError> {
    words
        .iter()
        .map(|w| match w.split_once('=') {
            Some((n, v)) if !n.is_empty() => Ok((n.to_string(), v.to_string())),
            _ => Err(ParseError::Invalid(format!(
                "`{w}` is not a parameter: write NAME=VALUE, e.g. speed=100"
            ))),
        })
        .collect()
}

/// The `run` command from its words after NODE: `[PROCEDURE] [NAME=VALUE ...]`.
pub fn run_spec(node: u8, rest: &[&str], list: bool, dry_run: bool, timeout_ms: u64) -> Result<RunSpec, ParseError> {
    let (procedure, assignments) = match rest.split_first() {
        Some((p, more)) if !p.contains('=') => (Some(p.to_string()), more),
        _ => (None, rest),
    };
    let args = parse_assignments(assignments)?;
    if procedure.is_none() && !args.is_empty() {
        return Err(ParseError::Invalid(
            "run: give the PROCEDURE before its NAME=VALUE parameters".into(),
        ));
    }
    if list && procedure.is_some() {
        return Err(ParseError::Invalid("run: give a PROCEDURE or --list, not both".into()));
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
pub fn parse_node(text: &str, allow_all: bool) -> Result<u8, ParseError> {
    let lo = if allow_all { 0 } else { 1 };
    match parse_int(text) {
        Some(n) if (lo..=127).contains(&n) => Ok(n as u8),
        _ => Err(ParseError::Invalid(format!(
            "node `{text}` must be a number {lo}..127 (decimal or 0x hex)"
        ))),
    }
}

/// Parses a `--type` name: u8..u64, i8..i64, f32, f64, bool, string, octets (hex), domain.
pub fn parse_type(name: &str) -> Result<DataType, ParseError> {
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
            return Err(ParseError::Invalid(format!(
                "unknown type `{name}`: use u8..u64, i8..i64, f32, f64, bool, string, octets or domain"
            )));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
