//! `cotui decode FILE...`: the headless decoder.

use super::{EXIT_OK, EXIT_UNAVAILABLE, EXIT_USAGE};
use crate::analysis::EventTracker;
use crate::decode::{Decoder, Kind};
use crate::frame::{Frame, Interfaces};
use crate::log::Outcome;
use crate::log::read_ahead;
use crate::output::{jsonl, summary::Summary, text};
use crate::sdo::Transaction;
use clap::{Args, ValueEnum};
use std::io::{self, BufRead, BufReader, Write};

/// Output formats of `cotui decode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// candump-like lines with the decoded label.
    Text,
    /// One JSON object per frame (see README, "JSONL contract").
    Jsonl,
    /// A pcapng capture for Wireshark (binary: with -o FILE or a redirected stdout).
    /// `run` hands it to `decode_out` before decoding, so the matches below that pair it
    /// with `Jsonl` never see it.
    Pcapng,
    /// Two Parquet tables, frames and decoded values (with -o DIR or -o NAME.parquet;
    /// see README, "Parquet tables"). `run` hands it to `decode_parquet` before decoding.
    Parquet,
}

/// Arguments of `cotui decode`.
#[derive(Args, Debug)]
pub struct DecodeArgs {
    /// Log files (candump -l/-L, candump screen output, Vector ASC); `-` reads stdin.
    #[arg(required = true)]
    pub files: Vec<String>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: OutputFormat,
    /// Print reassembled SDO transactions instead of frames.
    #[arg(long)]
    pub transactions: bool,
    /// Print per-node and per-kind totals only.
    #[arg(long, conflicts_with = "transactions")]
    pub summary: bool,
    /// Print bus events instead of frames: boot-up, NMT state change, heartbeat lost/back,
    /// heartbeat period (0x1017), EMCY, SDO abort, controller state (error frames).
    #[arg(long, conflicts_with_all = ["transactions", "summary"])]
    pub events: bool,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
    /// Write to FILE instead of stdout (`-` is stdout).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<String>,
}

/// What a decode run writes, chosen once from the arguments.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Frames(OutputFormat),
    Transactions(OutputFormat),
    Summary(OutputFormat),
    Events(OutputFormat),
}

/// Runs `cotui decode`; returns the exit status.
pub fn run(args: &DecodeArgs) -> i32 {
    if args.format == OutputFormat::Pcapng {
        return super::decode_out::pcapng(args);
    }
    if args.format == OutputFormat::Parquet {
        return super::decode_parquet::run(args);
    }
    let mut decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return EXIT_USAGE;
        }
    };
    let mut events = EventTracker::new(|n| decoder.dictionary(n));
    let mode = if args.events {
        Mode::Events(args.format)
    } else if args.summary {
        Mode::Summary(args.format)
    } else if args.transactions {
        Mode::Transactions(args.format)
    } else {
        Mode::Frames(args.format)
    };
    let mut out = match super::decode_out::open(args.output.as_deref(), false) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return EXIT_USAGE;
        }
    };
    let mut summary = Summary::default();
    let mut status = EXIT_OK;
    for path in &args.files {
        let Some(input) = open_input(path, "decode") else {
            status = EXIT_UNAVAILABLE;
            continue;
        };
        let mut sinks = Sinks {
            summary: &mut summary,
            events: &mut events,
        };
        match decode_stream(path, input, &mut decoder, mode, &mut sinks, &mut out) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => return status,
            Err(e) => {
                eprintln!("cotui decode: {path}: {e}");
                status = EXIT_UNAVAILABLE;
            }
        }
    }
    let result = finish(&mut decoder, mode, &mut summary, &mut out).and_then(|_| out.flush());
    match result {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            eprintln!("cotui decode: {e}");
            EXIT_UNAVAILABLE
        }
        _ => status,
    }
}

/// What the modes that look at the whole input keep across files.
struct Sinks<'a> {
    summary: &'a mut Summary,
    events: &'a mut EventTracker,
}

/// Decodes one input into `out` (parsing runs on a second thread).
fn decode_stream(
    path: &str,
    input: Box<dyn BufRead + Send>,
    decoder: &mut Decoder,
    mode: Mode,
    sinks: &mut Sinks,
    out: &mut impl Write,
) -> io::Result<()> {
    let mut buf = String::with_capacity(1 << 16);
    let mut ifaces = Interfaces::default();
    let finished = read_ahead::for_each_batch(input, |batch| -> io::Result<()> {
        if let Some(i) = &batch.interfaces {
            ifaces = i.clone();
        }
        for (line, outcome) in &batch.lines {
            let frame: &Frame = match outcome {
                Outcome::Frame(f) => f,
                Outcome::Skip(_) => continue,
                Outcome::Warning(msg) => {
                    eprintln!("{path}:{line}: warning: {msg}");
                    continue;
                }
            };
            match mode {
                Mode::Summary(_) => {
                    let (kind, node) = decoder.classify(frame);
                    sinks.summary.add(kind, node);
                }
                Mode::Events(fmt) => {
                    let events = &mut *sinks.events;
                    // Only these kinds carry events; SDO frames are tracked by classify.
                    match decoder.classify(frame) {
                        (Kind::Heartbeat | Kind::Emcy | Kind::ErrorFrame, _) => {
                            let d = decoder.decode(frame);
                            events.frame(frame, ifaces.name(frame.iface), &d);
                        }
                        _ => events.tick(frame.ts_ns),
                    }
                    for t in decoder.take_transactions() {
                        events.transaction(&t);
                    }
                    for e in events.take_events() {
                        match fmt {
                            OutputFormat::Text => e.write_line(&mut buf),
                            // (pcapng and parquet never reach here: they are refused with --events)
                            OutputFormat::Jsonl | OutputFormat::Pcapng | OutputFormat::Parquet => {
                                e.write_json(&mut buf)
                            }
                        }
                    }
                }
                Mode::Frames(OutputFormat::Text) => {
                    let d = decoder.decode(frame);
                    text::write_line(&mut buf, frame, &ifaces, &d);
                }
                Mode::Frames(OutputFormat::Jsonl | OutputFormat::Pcapng | OutputFormat::Parquet) => {
                    let d = decoder.decode(frame);
                    jsonl::write_frame(&mut buf, *line, frame, &ifaces, &d);
                }
                Mode::Transactions(fmt) => {
                    decoder.decode(frame);
                    for t in decoder.take_transactions() {
                        write_transaction(&mut buf, &t, decoder, fmt);
                    }
                }
            }
        }
        if !matches!(mode, Mode::Transactions(_)) {
            // Only --transactions prints them; dropping the rest keeps memory flat.
            decoder.take_transactions();
        }
        out.write_all(buf.as_bytes())?;
        buf.clear();
        Ok(())
    })??;
    if let Some(e) = finished.error {
        return Err(e);
    }
    report_counts(path, &finished.counts);
    Ok(())
}

/// A log to read: stdin for `-`, else the file; `None` (with the message on stderr, `what`
/// naming the command) when it cannot be opened.
pub fn open_input(path: &str, what: &str) -> Option<Box<dyn BufRead + Send>> {
    if path == "-" {
        return Some(Box::new(BufReader::with_capacity(1 << 16, io::stdin())));
    }
    match std::fs::File::open(path) {
        Ok(f) => Some(Box::new(BufReader::with_capacity(1 << 16, f))),
        Err(e) => {
            eprintln!("cotui {what}: {path}: {e}");
            None
        }
    }
}

/// Prints what a reader skipped or could not read in `path` (nothing when every line was a frame).
pub fn report_counts(path: &str, c: &crate::log::Counts) {
    if c.warnings > 0 || c.skipped_total() > 0 {
        eprintln!(
            "{path}: {} frames, {} lines skipped, {} malformed lines",
            c.frames,
            c.skipped_total(),
            c.warnings
        );
    }
    if let Some(first) = c.first_ignored_tail {
        eprintln!(
            "{path}: {} frame lines had text after the frame, not read (comments; first: line {first})",
            c.ignored_tail
        );
    }
}

fn write_transaction(buf: &mut String, t: &Transaction, decoder: &Decoder, fmt: OutputFormat) {
    let dict = decoder.dictionary(t.node);
    match fmt {
        OutputFormat::Text => buf.push_str(&t.label(dict)),
        OutputFormat::Jsonl | OutputFormat::Pcapng | OutputFormat::Parquet => {
            buf.push_str(&t.to_json(dict).to_string())
        }
    }
    buf.push('\n');
}

/// Writes what is due at the end of all inputs.
fn finish(decoder: &mut Decoder, mode: Mode, summary: &mut Summary, out: &mut impl Write) -> io::Result<()> {
    let mut buf = String::new();
    match mode {
        Mode::Transactions(fmt) => {
            for t in decoder.finish() {
                write_transaction(&mut buf, &t, decoder, fmt);
            }
        }
        Mode::Summary(fmt) => {
            summary.finish();
            match fmt {
                OutputFormat::Text => buf.push_str(&summary.to_text()),
                OutputFormat::Jsonl | OutputFormat::Pcapng | OutputFormat::Parquet => {
                    buf.push_str(&summary.to_json().to_string());
                    buf.push('\n');
                }
            }
        }
        Mode::Frames(_) | Mode::Events(_) => {}
    }
    out.write_all(buf.as_bytes())
}
