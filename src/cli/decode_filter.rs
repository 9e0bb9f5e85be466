//! `cotui decode --filter EXPR`: the frames (or, with `--transactions`, the SDO transfers,
//! or with `--summary` the totals of the frames) that match an expression of the TUI's
//! filter language, judged as the TUI's filtered view judges them. The frames go through
//! the one analysis pipeline ([`Trace`]): [`Views::Frames`] decodes them with their labels,
//! [`Views::Transactions`] lists the transfers as `decode --transactions` does.

use super::decode_args::{DecodeArgs, OutputFormat};
use super::decode_records::{write_summary, write_transaction};
use super::input::{for_each_frame, report_counts};
use crate::analysis::filter::stream::Stream;
use crate::analysis::filter::{Facts, Filter};
use crate::analysis::trace::{Trace, Views};
use crate::command::ExitCode;
use crate::decode::Kind;
use crate::output::busload::{Bitrate, BusLoad};
use crate::output::{jsonl, text};
use std::io::{self, Write};

/// What a matching frame gives: its output line, or the frame with its kind and node for
/// the totals.
enum Out {
    /// The frame's line as written.
    Line(Vec<u8>),
    /// A frame to count in the `--summary` totals (held by value: no allocation per
    /// matching frame), with its kind and node.
    Count(crate::frame::Frame, Kind, Option<u8>),
}

/// What a filtered run writes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Frames,
    Transactions,
    Summary,
}

/// State carried across input files.
struct Run {
    /// The pipeline: with `--transactions` it lists the transfers (as the TUI's SDO pane
    /// takes them), else it decodes every frame; `--summary` totals go to its summary.
    trace: Trace,
    filter: Filter,
    mode: Mode,
    format: OutputFormat,
    stream: Stream<Out>,
    /// Interface names of the input so far.
    names: Vec<String>,
    /// Frames taken so far (their positions in the stream).
    pos: u64,
    t0_ns: Option<u64>,
}

/// Runs a filtered `cotui decode`; returns the exit status.
pub fn run(args: &DecodeArgs, expr: &str) -> ExitCode {
    if args.events
        || matches!(
            args.format,
            OutputFormat::Pcapng | OutputFormat::Parquet | OutputFormat::Asc | OutputFormat::Trc | OutputFormat::Blf
        )
    {
        eprintln!("cotui decode: --filter goes with text or jsonl frames, --transactions or --summary");
        return ExitCode::Usage;
    }
    let decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let filter = match Filter::parse_with(expr, &decoder) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("cotui decode: --filter {:?}: {e}", e.excerpt(expr));
            return ExitCode::Usage;
        }
    };
    let mode = if args.transactions {
        Mode::Transactions
    } else if args.summary {
        Mode::Summary
    } else {
        Mode::Frames
    };
    let mut out = match super::decode_out::open(args.output.as_deref(), None) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let views = if mode == Mode::Transactions {
        Views::Transactions
    } else {
        Views::Frames
    };
    let mut trace = Trace::headless(decoder, views);
    trace.summary.bus = BusLoad::new(Bitrate::given_or_assumed(args.bitrate));
    let mut run = Run {
        trace,
        stream: Stream::new(filter.clone()),
        filter,
        mode,
        format: args.format,
        names: Vec::new(),
        pos: 0,
        t0_ns: None,
    };
    let mut status = ExitCode::Ok;
    let (inputs, failed) = super::input::open_inputs(&args.files, "decode", args.iface_per_file, args.input.format());
    if failed {
        status = ExitCode::Unavailable;
    }
    for (path, input) in inputs {
        let path = &path;
        match run.file(path, input, &mut out) {
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
    match run.finish(&mut out).and_then(|_| out.flush()) {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => out.blame().report(None, &e),
        _ => status,
    }
}

impl Run {
    fn file(&mut self, path: &str, input: super::input::Input, out: &mut impl Write) -> io::Result<()> {
        let mut buf = Vec::with_capacity(1 << 16);
        self.trace.new_input();
        let counts = for_each_frame(path, input, |frames| {
            let ifaces = frames.ifaces;
            super::decode_records::note_interfaces(&mut self.names, ifaces);
            self.trace.name_interfaces(ifaces);
            for (line, frame) in frames {
                let t0 = *self.t0_ns.get_or_insert(frame.ts_ns);
                self.trace.push(frame);
                let pos = self.pos;
                self.pos += 1;
                let Some(d) = self.trace.take_decoded() else {
                    // --transactions: only the transfers are printed, no frame labels.
                    for t in self.trace.take_transactions() {
                        self.transaction(&mut buf, &t, t0);
                    }
                    continue;
                };
                let done = self.trace.take_transactions();
                let facts = Facts {
                    ts_ns: frame.ts_ns,
                    id: frame.id,
                    flags: frame.flags.0,
                    kind: d.kind,
                    node: d.node,
                };
                let (mode, format) = (self.mode, self.format);
                let iface = self.trace.ifaces.name(frame.iface);
                self.stream.frame(pos, (facts, iface), d, &done, |d| {
                    let mut s = Vec::new();
                    match (mode, format) {
                        (Mode::Summary, _) => return Out::Count(*frame, d.kind, d.node),
                        (_, OutputFormat::Text) => text::write_line(&mut s, frame, ifaces, d),
                        _ => jsonl::write_frame(&mut s, line, frame, ifaces, d),
                    }
                    Out::Line(s)
                });
                let ready = self.stream.ready();
                self.take(&mut buf, ready);
            }
            out.write_all(&buf)?;
            buf.clear();
            Ok(())
        })?;
        report_counts(path, &counts);
        Ok(())
    }

    /// Writes (or counts) matching frames.
    fn take(&mut self, buf: &mut Vec<u8>, ready: Vec<Out>) {
        for o in ready {
            match o {
                Out::Count(frame, kind, node) => self.trace.summary.add_frame(&frame, kind, node, None),
                Out::Line(s) => buf.extend_from_slice(&s),
            }
        }
    }

    fn transaction(&self, buf: &mut Vec<u8>, t: &crate::sdo::Transaction, t0: u64) {
        let dict = self.trace.decoder().dictionary(t.node);
        if !self
            .filter
            .matches_transaction(t, self.trace.ifaces.name(t.iface), dict, t0)
        {
            return;
        }
        let iface = super::decode_records::shown_iface(&self.names, t.iface);
        write_transaction(buf, &mut String::new(), t, dict, iface, self.format);
    }

    /// Writes what waited for the end of the input.
    fn finish(&mut self, out: &mut impl Write) -> io::Result<()> {
        let mut buf = Vec::new();
        match self.mode {
            Mode::Transactions => {
                let t0 = self.t0_ns.unwrap_or(0);
                self.trace.end_of_input();
                for t in self.trace.take_transactions() {
                    self.transaction(&mut buf, &t, t0);
                }
            }
            Mode::Frames | Mode::Summary => {
                let rest = self.stream.finish();
                self.take(&mut buf, rest);
            }
        }
        if self.mode == Mode::Summary {
            write_summary(&mut buf, &mut self.trace.summary, self.format);
        }
        out.write_all(&buf)
    }
}
