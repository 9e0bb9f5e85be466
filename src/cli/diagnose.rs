//! `cotui diagnose FILE...` (or `--live IFACE...`): what went wrong on the bus, as a short
//! ranked list of incidents.

use super::input;
use crate::analysis::boot_story::Boot;
use crate::analysis::trace::{Trace, Views};
use crate::analysis::{Incident, Status};
use crate::command::ExitCode;
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
    /// Log files (candump -l/-L, candump screen output, Vector ASC, PEAK TRC, python-can
    /// CSV), merged by time into one capture (an interface name in several files is the
    /// same bus unless --iface-per-file); `-` reads stdin.
    #[arg(required_unless_present = "live")]
    pub files: Vec<String>,
    /// With several files: each file's interfaces are its own buses, named FILE:IFACE
    /// (two buses recorded apart, both as can0, stay apart).
    #[arg(long, conflicts_with = "live")]
    pub iface_per_file: bool,
    #[command(flatten)]
    pub input: super::input::InputArgs,
    /// Diagnose live SocketCAN interfaces (or socketcand://HOST:PORT/CHANNEL) instead (listen-only: nothing is sent; several
    /// are captured together, each node known by interface and node-ID) until Ctrl-C
    /// (SIGINT or SIGTERM) or `--duration`, then report as for a log.
    #[arg(long, value_name = "IFACE", num_args = 1.., conflicts_with = "files")]
    pub live: Option<Vec<String>>,
    /// With `--live`: stop after DUR (a bare number is seconds; or `500ms`, `30s`, `2min`).
    #[arg(long, value_name = "DUR", value_parser = crate::command::words::seconds_arg)]
    pub duration: Option<u64>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: DiagnoseFormat,
    /// Exit status 1 when an incident is still open at the end of the capture (a boot
    /// configured otherwise than its reference or --expect is one).
    #[arg(long)]
    pub check: bool,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
    /// The configuration a node's boots should write: NODE=FILE.dcf (the ParameterValue
    /// of each writable object; one equal to its DefaultValue need not be written).
    #[arg(long = "expect", value_name = "NODE=FILE")]
    pub expect: Vec<String>,
    /// List each node's boots (boot-up or NMT reset up to Operational) with their
    /// configuration writes, NMT commands and findings, instead of the incidents.
    #[arg(long)]
    pub boots: bool,
}

/// Runs `cotui diagnose`; returns the exit status.
pub fn run(args: &DiagnoseArgs) -> ExitCode {
    let decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui diagnose: {e}");
            return ExitCode::Usage;
        }
    };
    let expected = match crate::command::dcf::expect::read_all(&args.expect, &decoder) {
        Ok(e) => e,
        Err(e) => {
            eprintln!("cotui diagnose: {e}");
            return ExitCode::Usage;
        }
    };
    for w in &expected.warnings {
        eprintln!("cotui diagnose: warning: {w}");
    }
    let mut trace = Trace::headless(decoder, Views::Diagnosis);
    for (node, values) in expected.nodes {
        trace.diagnosis.expect(node, values);
    }
    if args.duration.is_some() && args.live.is_none() {
        eprintln!("cotui diagnose: --duration needs --live IFACE (a log ends by itself)");
        return ExitCode::Usage;
    }
    let mut status = ExitCode::Ok;
    if let Some(twice) = args.live.as_deref().and_then(input::repeated) {
        eprintln!("cotui diagnose: --live {twice} is given twice: name each interface once");
        return ExitCode::Usage;
    }
    // `--live IFACE...` takes every word after it: a log among them is a log given with
    // --live, refused as when it comes first.
    if let Some(log) = args.live.iter().flatten().find(|n| std::path::Path::new(n).is_file()) {
        eprintln!("cotui diagnose: {log} is a file: diagnose reads logs, or --live interfaces, not both");
        return ExitCode::Usage;
    }
    if let Some(ifaces) = &args.live
        && let Err(e) = live::capture(ifaces, args.duration, &mut trace)
    {
        eprintln!("cotui diagnose: {e}");
        return ExitCode::Unavailable;
    }
    let mut opened = args.live.is_some();
    let (inputs, failed) = input::open_inputs(&args.files, "diagnose", args.iface_per_file, args.input.format());
    if failed {
        status = ExitCode::Unavailable;
    }
    for (path, input) in inputs {
        let path = &path;
        opened = true;
        trace.new_input();
        let result = input::for_each_frame(path, input, |frames| {
            trace.name_interfaces(frames.ifaces);
            for (_, frame) in frames {
                trace.push(frame);
            }
            Ok(())
        });
        if let Err(e) = result {
            eprintln!("cotui diagnose: {path}: {e}");
            status = ExitCode::Unavailable;
        }
    }
    if !opened {
        // Nothing was read: a report of "no problems" would be false; the errors are said.
        return status;
    }
    trace.end_of_input();
    let diag = trace.diagnosis;
    let origin = diag.origin_ns();
    let frames = diag.frames();
    let (incidents, boots) = diag.finish_with_boots();
    let out = match args.format {
        DiagnoseFormat::Text if args.boots => boots_report(&boots, origin).into_bytes(),
        DiagnoseFormat::Jsonl if args.boots => {
            let mut out = Vec::new();
            for b in &boots {
                write_line(&mut out, &b.to_json(origin));
            }
            out
        }
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

/// `--live`: the frames of a SocketCAN interface, as they come.
mod live {
    use super::Trace;
    use crate::bus::{BusError, Subscription};
    use crate::frame::Frame;
    use std::pin::Pin;
    use std::task::Poll;
    use std::time::Duration;
    use tokio::signal::unix::{SignalKind, signal};

    /// How often the capture clock advances on a quiet bus (heartbeats missed by then count).
    const TICK: Duration = Duration::from_millis(100);

    /// The next frame of any of `subs`, with the index of its subscription.
    async fn next(subs: &mut [Subscription]) -> (usize, Result<Frame, BusError>) {
        type Recv<'a> = Pin<Box<dyn Future<Output = Result<Frame, BusError>> + 'a>>;
        let mut waiting: Vec<Recv> = subs.iter_mut().map(|s| Box::pin(s.recv()) as Recv).collect();
        std::future::poll_fn(|cx| {
            for (i, w) in waiting.iter_mut().enumerate() {
                if let Poll::Ready(got) = w.as_mut().poll(cx) {
                    return Poll::Ready((i, got));
                }
            }
            Poll::Pending
        })
        .await
    }

    /// Feeds the frames of `ifaces` (opened listen-only, each frame tagged with its
    /// interface's index) to the diagnosis of `trace` until SIGINT or SIGTERM, or for
    /// `duration_ms`; the capture clock ends at the bus time then.
    pub fn capture(ifaces: &[String], duration_ms: Option<u64>, trace: &mut Trace) -> Result<(), String> {
        let limit = duration_ms.map(Duration::from_millis);
        let rt = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the runtime: {e}"))?;
        rt.block_on(async {
            let handler = |kind| signal(kind).map_err(|e| format!("cannot install a signal handler: {e}"));
            let (mut int, mut term) = (handler(SignalKind::interrupt())?, handler(SignalKind::terminate())?);
            let mut buses = Vec::new();
            for iface in ifaces {
                buses.push(crate::connect::open(iface, true).await.map_err(|e| e.to_string())?);
                trace.ifaces.intern(iface);
            }
            let mut subs: Vec<Subscription> = buses.iter().map(|b| b.subscribe()).collect();
            let clock = &buses[0];
            let tagged = |i: usize, mut f: Frame| {
                f.iface = i as u16;
                f
            };
            let end = limit.map(|d| tokio::time::Instant::now() + d);
            let mut tick = tokio::time::interval(TICK);
            loop {
                let deadline = async {
                    match end {
                        Some(e) => tokio::time::sleep_until(e).await,
                        None => std::future::pending().await,
                    }
                };
                tokio::select! {
                    (i, got) = next(&mut subs) => match got {
                        Ok(f) => trace.push(&tagged(i, f)),
                        Err(BusError::Closed) => return Err(format!("{}: the bus was closed", ifaces[i])),
                        // The interface went down or away: said, and the capture goes on.
                        Err(e) => eprintln!("cotui diagnose: {e}"),
                    },
                    _ = tick.tick() => trace.tick(clock.now_ns()),
                    _ = int.recv() => break,
                    _ = term.recv() => break,
                    _ = deadline => break,
                }
            }
            // Frames the kernel still holds are part of the capture.
            for (i, sub) in subs.iter_mut().enumerate() {
                while let Some(Ok(f)) = sub.try_recv() {
                    trace.push(&tagged(i, f));
                }
            }
            trace.tick(clock.now_ns());
            Ok(())
        })
    }
}

/// The text of `--boots`: a headline with the counts, then one block per boot.
fn boots_report(boots: &[Boot], origin: u64) -> String {
    let nodes: std::collections::BTreeSet<_> = boots.iter().map(|b| b.node).collect();
    let differ = boots.iter().filter(|b| !b.findings.is_empty()).count();
    let mut out = format!(
        "{} of {}, {differ} with findings.\n",
        plural(boots.len(), "boot"),
        plural(nodes.len(), "node")
    );
    for b in boots {
        out.push('\n');
        b.write_text(origin, &mut out);
    }
    out
}

fn plural(n: usize, one: &str) -> String {
    if n == 1 {
        format!("1 {one}")
    } else {
        format!("{n} {one}s")
    }
}

/// The text report: a headline with the counts, then one block per incident.
pub fn report(incidents: &[Incident], origin: u64, frames: u64) -> String {
    let count = |s: Status| incidents.iter().filter(|i| i.status == s).count();
    let (open, recovered, warning) = (count(Status::Open), count(Status::Recovered), count(Status::Warning));
    // Notes for information only (entries a node lacks, read by the capturing host).
    let info = match count(Status::Info) {
        0 => String::new(),
        1 => ", 1 note".to_string(),
        n => format!(", {n} notes"),
    };
    let mut out = if incidents.len() == count(Status::Info) {
        format!("No problems found in {frames} frames{}.\n", info.replacen(',', ";", 1))
    } else if open > 0 {
        format!(
            "Needs attention: {open} open, {recovered} recovered, {warning} warnings{info} ({frames} frames). Start from the top.\n"
        )
    } else {
        format!(
            "Problems occurred, none left open: {recovered} recovered, {warning} warnings{info} ({frames} frames).\n"
        )
    };
    for (n, inc) in incidents.iter().enumerate() {
        out.push('\n');
        inc.write_text(n + 1, origin, &mut out);
    }
    out
}
