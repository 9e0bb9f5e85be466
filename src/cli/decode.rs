//! `cotui decode FILE...`: the headless decoder.

use super::input;
use crate::analysis::trace::{Trace, Views};
use crate::command::ExitCode;
use crate::decode::Decoder;
use crate::frame::json::write_line;
use crate::od::Dictionary;
use crate::output::busload::{Bitrate, BusLoad};
use crate::output::{jsonl, summary::Summary, text};
use crate::sdo::Transaction;
use clap::{Args, ValueEnum};
use std::io::{self, Write};

/// Output formats of `cotui decode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// candump-like lines with the decoded label.
    Text,
    /// One JSON object per frame (see README, "JSONL contract").
    Jsonl,
    /// A pcapng capture for Wireshark (binary: with -o FILE or a redirected stdout).
    // `run` hands it to `decode_out` before decoding, so the matches below that pair it
    // with `Jsonl` never see it.
    Pcapng,
    /// A Vector BLF log for CANalyzer/CANoe and python-can (binary: with -o FILE or a
    /// redirected stdout; the header's totals are filled in only in a file).
    // `run` hands it to `decode_out` before decoding, as pcapng.
    Blf,
    /// Two Parquet tables, frames and decoded values (with -o DIR or -o NAME.parquet;
    /// see README, "Parquet tables").
    // `run` hands it to `decode_parquet` before decoding.
    Parquet,
    /// A Vector ASC log (frames only).
    // `run` hands it (and Trc) to `decode_out` before decoding.
    Asc,
    /// A PEAK TRC 2.1 log (frames only).
    Trc,
}

/// Arguments of `cotui decode`.
#[derive(Args, Debug)]
pub struct DecodeArgs {
    /// Log files (candump -l/-L, candump screen output, Vector ASC, PEAK TRC, python-can
    /// CSV); `-` reads stdin. Several are merged by time into one capture; an interface
    /// name in several files is the same bus (one bus's log split in parts) unless
    /// --iface-per-file.
    #[arg(required = true)]
    pub files: Vec<String>,
    /// With several files: each file's interfaces are its own buses, named FILE:IFACE
    /// (two buses recorded apart, both as can0, stay apart).
    #[arg(long)]
    pub iface_per_file: bool,
    #[command(flatten)]
    pub input: super::input::InputArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: OutputFormat,
    /// Print reassembled SDO transactions instead of frames.
    #[arg(long)]
    pub transactions: bool,
    /// Print per-node and per-kind totals only.
    #[arg(long, conflicts_with = "transactions")]
    pub summary: bool,
    /// Bus bit rate for the `--summary` bus load, in bit/s (500000, 500k, 1M); without it
    /// 500 kbit/s is assumed, and the summary says so.
    #[arg(long, value_parser = super::tui::bitrate_arg, value_name = "R")]
    pub bitrate: Option<u64>,
    /// Print bus events instead of frames: boot-up, NMT state change, heartbeat lost/back,
    /// heartbeat period (0x1017), EMCY, SDO abort, controller state (error frames).
    #[arg(long, conflicts_with_all = ["transactions", "summary"])]
    pub events: bool,
    /// Print one record per SYNC cycle instead of frames: its synchronous TPDOs with their
    /// time after the SYNC, the window 0x1007 and the TPDOs after it (late); text ends
    /// with a summary (cycles, mean and longest period, the slowest cycle, late TPDOs).
    #[arg(long, conflicts_with_all = ["transactions", "summary", "events", "filter", "trigger"])]
    pub sync_cycles: bool,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
    /// Only frames (or with --transactions, SDO transfers; with --summary, the totals of
    /// frames) matching EXPR, in the TUI's filter language (docs/TUI.md, "Filter and search").
    #[arg(long, value_name = "EXPR")]
    pub filter: Option<String>,
    /// Write to FILE instead of stdout (`-` is stdout); with --trigger, the directory of
    /// the window files.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<String>,
    /// Capture windows around each hit of EXPR (a filter, `hb lost`, `bootup`, `bus-off`,
    /// `error-passive`, `incident KIND`, or `A then B within DUR`): one file per window in
    /// -o DIR (candump -l, or --format pcapng|asc|trc|blf) with a JSON sidecar; with
    /// --format jsonl and no -o, one JSON line per window (README, "Capture triggers").
    #[arg(long, value_name = "EXPR")]
    pub trigger: Option<String>,
    /// With --trigger: keep DUR before each hit (`30s`, `500ms`; a bare number is ms).
    #[arg(long, value_name = "DUR", default_value = "10s", value_parser = crate::command::words::ms_or_zero_arg, requires = "trigger")]
    pub pre: u64,
    /// With --trigger: keep DUR after each hit (hits inside a window extend it).
    #[arg(long, value_name = "DUR", default_value = "10s", value_parser = crate::command::words::ms_or_zero_arg, requires = "trigger")]
    pub post: u64,
}

/// What a decode run keeps across its inputs, chosen once from the arguments: a bare
/// decoder when it prints frames, else the trace that derives the one view it prints.
enum Pipeline {
    Frames(Box<Decoder>),
    View(Box<Trace>),
}

/// Runs `cotui decode`; returns the exit status.
pub fn run(args: &DecodeArgs) -> ExitCode {
    if args.sync_cycles && !matches!(args.format, OutputFormat::Text | OutputFormat::Jsonl) {
        eprintln!("cotui decode: --sync-cycles writes text or jsonl");
        return ExitCode::Usage;
    }
    if let Some(expr) = &args.filter {
        return super::decode_filter::run(args, expr);
    }
    if matches!(args.format, OutputFormat::Pcapng | OutputFormat::Blf) {
        return super::decode_out::frames(args);
    }
    if args.format == OutputFormat::Parquet {
        return super::decode_parquet::run(args);
    }
    if matches!(args.format, OutputFormat::Asc | OutputFormat::Trc) {
        return super::decode_out::text_log(args, args.format == OutputFormat::Asc);
    }
    let decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let view = if args.sync_cycles {
        Some(Views::SyncCycles)
    } else if args.events {
        Some(Views::Events)
    } else if args.summary {
        Some(Views::Summary)
    } else if args.transactions {
        Some(Views::Transactions)
    } else {
        None
    };
    let mut run = match view {
        Some(v) => {
            let mut trace = Trace::headless(decoder, v);
            trace.summary.bus = BusLoad::new(Bitrate::given_or_assumed(args.bitrate));
            Pipeline::View(Box::new(trace))
        }
        None => Pipeline::Frames(Box::new(decoder)),
    };
    let mut out = match super::decode_out::open(args.output.as_deref(), None) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let mut names = Vec::new();
    let mut status = ExitCode::Ok;
    let (inputs, failed) = input::open_inputs(&args.files, "decode", args.iface_per_file, args.input.format());
    if failed {
        status = ExitCode::Unavailable;
    }
    for (path, input) in inputs {
        let path = &path;
        match decode_stream(path, input, &mut run, args.format, &mut names, &mut out) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => return status,
            Err(e) => {
                status = out.blame().report(Some(path), &e);
                if out.blame().output_failed() {
                    return status;
                }
            }
        }
    }
    let result = finish(&mut run, args.format, &names, &mut out).and_then(|_| out.flush());
    match result {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => out.blame().report(None, &e),
        _ => status,
    }
}

/// Keeps `names` up with a source's interface table (which grows as names appear).
pub(super) fn note_interfaces(names: &mut Vec<String>, ifaces: &crate::frame::Interfaces) {
    let all = ifaces.names();
    if all.len() > names.len() {
        names.extend(all[names.len()..].iter().cloned());
    }
}

/// The interface name shown with a node-level record (event, transaction, summary row):
/// only when the input has several interfaces, so that node 5 of can0 and node 5 of can1
/// tell apart; a capture of one interface prints as it always did.
pub(super) fn shown_iface(names: &[String], iface: u16) -> Option<&str> {
    (names.len() > 1).then(|| names.get(usize::from(iface)).map_or("?", String::as_str))
}

/// Decodes one input into `out` (parsing runs on a second thread). `names`: the interface
/// names of the input so far (see [`note_interfaces`]).
fn decode_stream(
    path: &str,
    input: input::Input,
    run: &mut Pipeline,
    fmt: OutputFormat,
    names: &mut Vec<String>,
    out: &mut impl Write,
) -> io::Result<()> {
    // Event text lines go to `buf`, all other lines to `json`; a run writes only one of
    // them. `label` is scratch space for transaction labels.
    let mut buf = String::with_capacity(1 << 16);
    let mut json = Vec::with_capacity(1 << 16);
    let mut label = String::new();
    if let Pipeline::View(trace) = run {
        trace.new_input();
    }
    let counts = input::for_each_frame(path, input, |frames| {
        let ifaces = frames.ifaces;
        note_interfaces(names, ifaces);
        match run {
            Pipeline::Frames(decoder) => {
                for (line, frame) in frames {
                    let d = decoder.decode(frame);
                    match fmt {
                        OutputFormat::Text => text::write_line(&mut json, frame, ifaces, &d),
                        OutputFormat::Jsonl
                        | OutputFormat::Pcapng
                        | OutputFormat::Parquet
                        | OutputFormat::Asc
                        | OutputFormat::Trc
                        | OutputFormat::Blf => jsonl::write_frame(&mut json, line, frame, ifaces, &d),
                    }
                    decoder.recycle(d);
                }
                // Only --transactions prints them; dropping them keeps memory flat.
                decoder.take_transactions();
            }
            Pipeline::View(trace) => {
                trace.name_interfaces(ifaces);
                for (_, frame) in frames {
                    trace.push(frame);
                }
                write_view(trace, fmt, names, &mut buf, &mut json, &mut label);
            }
        }
        out.write_all(buf.as_bytes())?;
        out.write_all(&json)?;
        buf.clear();
        json.clear();
        Ok(())
    })?;
    input::report_counts(path, &counts);
    Ok(())
}

/// Appends what the view of `trace` has to print so far: the SDO transfers it listed or
/// the events it found (a summary prints at the end only).
fn write_view(
    trace: &mut Trace,
    fmt: OutputFormat,
    names: &[String],
    buf: &mut String,
    json: &mut Vec<u8>,
    label: &mut String,
) {
    match trace.views() {
        Views::Transactions => {
            for t in trace.take_transactions() {
                let iface = shown_iface(names, t.iface);
                write_transaction(json, label, &t, trace.decoder().dictionary(t.node), iface, fmt);
            }
        }
        Views::Events => {
            for e in trace.events.take_events() {
                let iface = shown_iface(names, e.iface);
                match fmt {
                    OutputFormat::Text => e.write_line_on(buf, iface),
                    // (pcapng, blf and parquet never reach here: they are refused with --events)
                    OutputFormat::Jsonl
                    | OutputFormat::Pcapng
                    | OutputFormat::Parquet
                    | OutputFormat::Asc
                    | OutputFormat::Trc
                    | OutputFormat::Blf => e.write_json_on(json, iface),
                }
            }
        }
        Views::SyncCycles => {
            let first = trace.cycles.taken() == 0;
            let done = trace.cycles.take_closed();
            if first && !done.is_empty() && fmt == OutputFormat::Text {
                super::decode_sync::write_header(buf);
            }
            for c in &done {
                super::decode_sync::write_cycle(json, buf, c, names, fmt != OutputFormat::Text);
            }
        }
        Views::All | Views::Summary | Views::Diagnosis | Views::Frames => {}
    }
}

/// Appends one transaction to `out`: its label line (built in the scratch `label`) or its
/// JSON line.
pub(super) fn write_transaction(
    out: &mut Vec<u8>,
    label: &mut String,
    t: &Transaction,
    dict: &Dictionary,
    iface: Option<&str>,
    fmt: OutputFormat,
) {
    match fmt {
        OutputFormat::Text => {
            label.clear();
            // Several interfaces: `can1 node 2: Upload 0x6041:00 ...`.
            if let Some(i) = iface {
                label.push_str(i);
                label.push_str(" node ");
                label.push_str(&t.node.to_string());
                label.push_str(": ");
            }
            t.write_label(label, dict);
            out.extend_from_slice(label.as_bytes());
            out.push(b'\n');
        }
        OutputFormat::Jsonl
        | OutputFormat::Pcapng
        | OutputFormat::Parquet
        | OutputFormat::Asc
        | OutputFormat::Trc
        | OutputFormat::Blf => {
            let mut j = t.to_json(dict);
            j.iface = iface;
            write_line(out, &j)
        }
    }
}

/// Appends the totals of a `--summary` run in `fmt`.
pub(super) fn write_summary(out: &mut Vec<u8>, summary: &mut Summary, fmt: OutputFormat) {
    summary.finish();
    match fmt {
        OutputFormat::Text => out.extend_from_slice(summary.to_text().as_bytes()),
        OutputFormat::Jsonl
        | OutputFormat::Pcapng
        | OutputFormat::Parquet
        | OutputFormat::Asc
        | OutputFormat::Trc
        | OutputFormat::Blf => write_line(out, &summary.to_json()),
    }
}

/// Writes what is due at the end of all inputs.
fn finish(run: &mut Pipeline, fmt: OutputFormat, names: &[String], out: &mut impl Write) -> io::Result<()> {
    let Pipeline::View(trace) = run else {
        return Ok(());
    };
    trace.end_of_input();
    let mut buf = Vec::new();
    if trace.views() == Views::Summary {
        write_summary(&mut buf, &mut trace.summary, fmt);
    } else {
        let mut text = String::new();
        let mut label = String::new();
        write_view(trace, fmt, names, &mut text, &mut buf, &mut label);
        if trace.views() == Views::SyncCycles && fmt == OutputFormat::Text {
            super::decode_sync::write_totals(&mut text, &trace.cycles.totals(), names);
        }
        out.write_all(text.as_bytes())?;
    }
    out.write_all(&buf)
}
