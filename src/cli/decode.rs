//! `cotui decode FILE...`: the headless decoder.

use super::decode_args::{DecodeArgs, OutputFormat};
use super::decode_records::{note_interfaces, shown_iface, write_summary, write_transaction};
use super::input;
use crate::analysis::trace::{Trace, Views};
use crate::command::ExitCode;
use crate::decode::Decoder;
use crate::output::busload::{Bitrate, BusLoad};
use crate::output::{jsonl, text};
use std::io::{self, Write};

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
    // A summary counts bus load: the reader's thread works out the wire figures.
    let figured = matches!(run, Pipeline::View(trace) if trace.views() == Views::Summary);
    let counts = input::for_each_frame_figured(path, input, figured, |mut frames| {
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
                while let Some((_, frame, figures)) = frames.next_figured() {
                    trace.push_figured(frame, figures);
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
