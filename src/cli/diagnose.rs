//! `cotui diagnose FILE...`: what went wrong on the bus, as a short ranked list of incidents.

use super::input;
use crate::analysis::{Diagnoser, Incident, Status};
use crate::command::ExitCode;
use crate::decode::Kind;
use crate::frame::json::write_line;
use clap::{Args, ValueEnum};
use std::io::{self, Write};

/// Output formats of `cotui diagnose`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DiagnoseFormat {
    /// A report in plain words.
    Text,
    /// One JSON object per incident (see README, "Diagnosis").
    Jsonl,
}

/// Arguments of `cotui diagnose`.
#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Log files (candump -l/-L, candump screen output, Vector ASC), read as one capture;
    /// `-` reads stdin.
    #[arg(required = true)]
    pub files: Vec<String>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: DiagnoseFormat,
    /// Exit status 1 when an incident is still open at the end of the capture.
    #[arg(long)]
    pub check: bool,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
}

/// Runs `cotui diagnose`; returns the exit status.
pub fn run(args: &DiagnoseArgs) -> ExitCode {
    let mut decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui diagnose: {e}");
            return ExitCode::Usage;
        }
    };
    let mut diag = Diagnoser::new(|n| decoder.dictionary(n));
    let mut status = ExitCode::Ok;
    for path in &args.files {
        let Some(input) = input::open_input(path, "diagnose") else {
            status = ExitCode::Unavailable;
            continue;
        };
        let result = input::for_each_frame(path, input, |frames| {
            let ifaces = frames.ifaces;
            for (_, frame) in frames {
                // Frames that cannot tell the diagnosis anything are not decoded.
                let (kind, node, pdo) = decoder.peek(frame);
                let skip = match kind {
                    Kind::Sync | Kind::Time | Kind::Lss | Kind::Other => true,
                    // SDO frames: tracked without building the label nobody reads.
                    Kind::SdoRx | Kind::SdoTx => {
                        let s = decoder.sdo_frame(frame);
                        diag.sdo(frame, node.unwrap_or(0), kind == Kind::SdoRx, s.as_ref());
                        for t in decoder.take_transactions() {
                            diag.transaction(&t);
                        }
                        continue;
                    }
                    Kind::Tpdo | Kind::Rpdo => {
                        let n = node.unwrap_or(0);
                        !diag.wants_pdo(n, pdo, decoder.mapping(n, kind == Kind::Tpdo, pdo))
                    }
                    _ => false,
                };
                if skip {
                    diag.skip(frame, kind, node, pdo);
                    continue;
                }
                let d = decoder.decode(frame);
                diag.frame(frame, ifaces.name(frame.iface), &d);
                for t in decoder.take_transactions() {
                    diag.transaction(&t);
                }
            }
            Ok(())
        });
        if let Err(e) = result {
            eprintln!("cotui diagnose: {path}: {e}");
            status = ExitCode::Unavailable;
        }
    }
    for t in decoder.finish() {
        diag.transaction(&t);
    }
    let origin = diag.origin_ns();
    let frames = diag.frames();
    let incidents = diag.finish();
    let out = match args.format {
        DiagnoseFormat::Text => report(&incidents, origin, frames).into_bytes(),
        DiagnoseFormat::Jsonl => {
            let mut out = Vec::new();
            for i in &incidents {
                write_line(&mut out, &i.to_json(origin));
            }
            out
        }
    };
    let mut stdout = io::stdout().lock();
    if let Err(e) = stdout.write_all(&out).and_then(|_| stdout.flush())
        && e.kind() != io::ErrorKind::BrokenPipe
    {
        eprintln!("cotui diagnose: {e}");
        return ExitCode::Unavailable;
    }
    if status == ExitCode::Ok && args.check && incidents.iter().any(|i| i.status == Status::Open) {
        return ExitCode::Usage;
    }
    status
}

/// The text report: a headline with the counts, then one block per incident.
pub fn report(incidents: &[Incident], origin: u64, frames: u64) -> String {
    let count = |s: Status| incidents.iter().filter(|i| i.status == s).count();
    let (open, recovered, warning) = (count(Status::Open), count(Status::Recovered), count(Status::Warning));
    let mut out = if incidents.is_empty() {
        format!("No problems found in {frames} frames.\n")
    } else if open > 0 {
        format!(
            "Needs attention: {open} open, {recovered} recovered, {warning} warnings ({frames} frames). Start from the top.\n"
        )
    } else {
        format!("Problems occurred, none left open: {recovered} recovered, {warning} warnings ({frames} frames).\n")
    };
    for (n, inc) in incidents.iter().enumerate() {
        out.push('\n');
        inc.write_text(n + 1, origin, &mut out);
    }
    out
}
