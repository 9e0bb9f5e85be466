//! Runs a parsed [`Command`] on a bus: the one entry point the command line and the
//! TUI palette share. Each result comes as one JSON object plus its text form.

use super::error::CommandError;
use super::grammar::{Command, RunSpec};
use super::spec::{Ctx, Outcome, Spec};
use super::to_json;
use crate::bus::{Bus, BusError};
use crate::od::bind::Bindings;
use serde::Serialize;
use serde_json::Value as Json;

/// Runs `cmd` on `bus`; `bindings` give node dictionaries (object names, aliases, types).
/// A `record` without limits runs until its future is dropped (the log is flushed then).
pub async fn execute(bus: &Bus, cmd: &Command, bindings: &Bindings) -> Result<Outcome, CommandError> {
    let progress = super::cyclic::Progress::default();
    execute_until(bus, cmd, bindings, progress, std::future::pending()).await
}

/// [`execute`], where a cyclic command (`send`, `sync`, `pdo`) notes its timing in
/// `progress` and stops (and reports) when `stop` completes.
pub async fn execute_until(
    bus: &Bus,
    cmd: &Command,
    bindings: &Bindings,
    progress: super::cyclic::Progress,
    stop: impl std::future::Future<Output = ()> + Send,
) -> Result<Outcome, CommandError> {
    let stop = std::pin::pin!(stop);
    if let Some(src) = super::cyclic::source(cmd, bindings) {
        let report = super::cyclic::transmit(bus, src?, progress, stop).await?;
        let text = report.text();
        return Ok(Outcome::new(report, text));
    }
    let ctx = Ctx {
        bus,
        bindings,
        progress,
        stop,
    };
    let json = match cmd {
        Command::Nmt(c) => return c.run(ctx).await,
        Command::Run(spec) => return run_procedure(bus, bindings, spec).await,
        Command::Dcf(c) => return super::dcf::execute(bus, bindings.dictionary(c.node), c).await,
        Command::Stop {
            nodes,
            listen_ms,
            options,
        } => return super::stop::stop(bus, nodes, *listen_ms, *options).await?.into_result(),
        Command::Sdo(c) => return c.run(ctx).await,
        Command::Drive(c) => return c.run(ctx).await,
        Command::Scan {
            listen_ms,
            probe,
            timeout_ms,
        } => {
            let nodes = super::scan::scan(bus, *listen_ms, *probe, *timeout_ms).await?;
            to_json(&Scanned {
                ok: true,
                nodes: nodes.iter().map(|n| n.to_json()).collect(),
            })
        }
        Command::Lss { action, timeout_ms } => to_json(&super::lss::lss(bus, *action, *timeout_ms).await?),
        Command::PdoRead { node, timeout_ms } => {
            let pdos = super::pdo::read_all(bus, *node, *timeout_ms).await?;
            let (json, text) = super::pdo::read_report(*node, bindings.dictionary(*node), &pdos);
            return Ok(Outcome::new(json, text));
        }
        Command::PdoMap(spec) => {
            let dict = bindings.dictionary(spec.node);
            let (json, text) = if spec.dry_run {
                super::pdo::dry_run(dict, spec)?
            } else {
                super::pdo::map(bus, dict, spec).await?
            };
            return Ok(Outcome::new(json, text));
        }
        Command::Record {
            output,
            limits,
            mode,
            format,
        } => {
            let mut out = super::record::open_output(output, *mode, *format)?;
            let forever = std::future::pending::<()>();
            let n = super::record::record(bus, &mut out, *limits, *format, forever, |_| {}).await?;
            if let Some(m) = n.gap_message(output) {
                return Err(CommandError::Bus(BusError::Io {
                    iface: bus.name().to_string(),
                    reason: format!("{} frames written, but {m}", n.frames),
                }));
            }
            n.to_json(output)
        }
        // Handled above by `cyclic::source`.
        Command::Send(_) | Command::Sync(_) | Command::Pdo { .. } => {
            return Err(CommandError::Usage("internal: cyclic command without a source".into()));
        }
    };
    let text = text(cmd, &json);
    Ok(Outcome::new(json, text))
}

/// `scan --json`.
#[derive(Serialize)]
struct Scanned {
    ok: bool,
    nodes: Vec<Json>,
}

/// `run`: lists, dry-runs or runs a procedure; the text is a summary line, then every step
/// line and result.
async fn run_procedure(bus: &Bus, bindings: &Bindings, spec: &RunSpec) -> Result<Outcome, CommandError> {
    let (json, text) = offline_run(bindings, spec)?;
    let Some(name) = spec.procedure.as_deref().filter(|_| !spec.dry_run) else {
        return Ok(Outcome::new(json, text));
    };
    let dict = bindings.dictionary(spec.node);
    let plan = super::run::plan(dict, spec.node, name, &spec.args)?;
    let mut lines = Vec::new();
    let json = super::run::run(bus, dict, &plan, spec.timeout_ms, &mut |l| lines.push(l.to_string())).await?;
    // The summary first: the palette's message line shows one line.
    lines.insert(0, run_summary(&json));
    Ok(Outcome::new(json, lines.join("\n")))
}

/// What `run` gives without a bus: the listing (no procedure) or the dry run (also used to
/// check a procedure and its parameters before opening the bus).
pub fn offline_run(bindings: &Bindings, spec: &RunSpec) -> Result<(Json, String), super::run::PlanError> {
    let dict = bindings.dictionary(spec.node);
    match &spec.procedure {
        None => Ok(super::run::list(dict, spec.node)),
        Some(name) => {
            let plan = super::run::plan(dict, spec.node, name, &spec.args)?;
            let (mut json, text) = super::run::dry_run(&plan);
            if !spec.dry_run {
                json["dry_run"] = false.into();
            }
            Ok((json, text))
        }
    }
}

/// The last line of a successful run.
pub fn run_summary(v: &Json) -> String {
    format!(
        "`{}` on node {}: {} steps done",
        s(&v["procedure"]),
        v["node"],
        v["steps"].as_array().map_or(0, Vec::len)
    )
}

fn s(v: &Json) -> &str {
    v.as_str().unwrap_or("")
}

/// The text form of a successful command's JSON object.
pub fn text(cmd: &Command, v: &Json) -> String {
    match cmd {
        Command::Scan { .. } => scan_text(v),
        Command::Lss { .. } => s(&v["text"]).to_string(),
        Command::Record { .. } => format!("{} frames written to {}", v["frames"], s(&v["output"])),
        Command::Run(_) => run_summary(v),
        // Moved commands make their own text.
        Command::Nmt(_) | Command::Sdo(_) | Command::Drive(_) => String::new(),
        // A stop's text comes from its report (see `stop::StopReport::text`).
        Command::Stop { .. } => String::new(),
        // A cyclic command's text comes from its report (see `cyclic::Report::text`).
        Command::Send(_) | Command::Sync(_) | Command::Pdo { .. } => String::new(),
        // `pdo` reads and maps return their own text (see `pdo::read_report`, `pdo::map`).
        Command::PdoRead { .. } | Command::PdoMap(_) => String::new(),
        // A dcf command's text comes from its report (see `dcf`).
        Command::Dcf(_) => String::new(),
    }
}

fn scan_text(v: &Json) -> String {
    let nodes = v["nodes"].as_array().cloned().unwrap_or_default();
    if nodes.is_empty() {
        return "no nodes found (no heartbeat or boot-up heard; try --probe)".into();
    }
    let or_dash = |x: &Json| x.as_str().unwrap_or("-").to_string();
    nodes
        .iter()
        .map(|n| {
            let mut line = format!(
                "node {:>3}  {:<16} type {}  vendor {}  product {}  rev {}  serial {}  {}",
                n["node"],
                or_dash(&n["nmt"]),
                or_dash(&n["device_type"]),
                or_dash(&n["vendor_id"]),
                or_dash(&n["product_code"]),
                or_dash(&n["revision"]),
                or_dash(&n["serial"]),
                n["device_name"]
                    .as_str()
                    .map(|d| format!("\"{d}\""))
                    .unwrap_or_default()
            );
            if let Some(p) = n["profile"].as_str() {
                line.push_str(&format!("  profile {p} (--profile {}={p})", n["node"]));
            }
            if let Some(e) = n["sdo_error"].as_str() {
                line.push_str(&format!("  ({e})"));
            }
            line
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Writes a command's data to `path`; `-` is stdout (the command's report then goes to
/// stderr, see [`Command::data_to_stdout`]).
pub(crate) fn write_output(path: &str, data: &[u8]) -> Result<(), CommandError> {
    use std::io::Write;
    let written = if path == "-" {
        let mut out = std::io::stdout().lock();
        out.write_all(data).and_then(|()| out.flush())
    } else {
        std::fs::write(path, data)
    };
    written.map_err(|e| {
        let path = if path == "-" { "stdout" } else { path };
        CommandError::Usage(format!("cannot write {path}: {e}"))
    })
}
