//! `cotui decode --filter EXPR`: the frames (or, with `--transactions`, the SDO transfers,
//! or with `--summary` the totals of the frames) that match an expression of the TUI's
//! filter language, judged as the TUI's filtered view judges them.

use super::decode::{DecodeArgs, OutputFormat, write_summary, write_transaction};
use super::input::{for_each_frame, open_input, report_counts};
use crate::analysis::filter::stream::Stream;
use crate::analysis::filter::{Facts, Filter};
use crate::analysis::transfers::Transfers;
use crate::command::ExitCode;
use crate::decode::{Decoder, Kind};
use crate::output::{jsonl, summary::Summary, text};
use std::io::{self, Write};

/// What a matching frame gives: its output line, or its kind and node for the totals.
enum Out {
    Line(Vec<u8>),
    /// A frame of (interface, kind, node) to count.
    Count(u16, Kind, Option<u8>),
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
    decoder: Decoder,
    filter: Filter,
    mode: Mode,
    format: OutputFormat,
    stream: Stream<Out>,
    summary: Summary,
    /// The SDO transfers of `--transactions`, as the TUI's SDO pane takes them.
    transfers: Transfers,
    /// Interface names of the input so far.
    names: Vec<String>,
    /// Frames taken so far (the decoder's sequence numbers).
    pos: u64,
    t0_ns: Option<u64>,
}

/// Runs a filtered `cotui decode`; returns the exit status.
pub fn run(args: &DecodeArgs, expr: &str) -> ExitCode {
    if args.events
        || matches!(
            args.format,
            OutputFormat::Pcapng | OutputFormat::Blf | OutputFormat::Parquet
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
    let mut run = Run {
        decoder,
        stream: Stream::new(filter.clone()),
        filter,
        mode,
        format: args.format,
        summary: Summary::default(),
        transfers: Transfers::new(),
        names: Vec::new(),
        pos: 0,
        t0_ns: None,
    };
    let mut status = ExitCode::Ok;
    for path in &args.files {
        let Some(input) = open_input(path, "decode") else {
            status = ExitCode::Unavailable;
            continue;
        };
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
    fn file(&mut self, path: &str, input: Box<dyn io::BufRead + Send>, out: &mut impl Write) -> io::Result<()> {
        let mut buf = Vec::with_capacity(1 << 16);
        let counts = for_each_frame(path, input, |frames| {
            let ifaces = frames.ifaces;
            super::decode::note_interfaces(&mut self.names, ifaces);
            self.summary.name_interfaces(ifaces);
            for (line, frame) in frames {
                let t0 = *self.t0_ns.get_or_insert(frame.ts_ns);
                self.decoder.set_seq(self.pos);
                if self.mode == Mode::Transactions {
                    // Only the transfers are printed: no frame labels.
                    self.decoder.track(frame);
                    for t in self.transfers.completed(&mut self.decoder) {
                        self.transaction(&mut buf, &t, t0);
                    }
                    self.pos += 1;
                    continue;
                }
                let d = self.decoder.decode(frame);
                let done = self.decoder.take_transactions();
                let facts = Facts {
                    ts_ns: frame.ts_ns,
                    id: frame.id,
                    flags: frame.flags.0,
                    kind: d.kind,
                    node: d.node,
                };
                let (mode, format) = (self.mode, self.format);
                self.stream.frame(self.pos, facts, d, &done, |d| {
                    let mut s = Vec::new();
                    match (mode, format) {
                        (Mode::Summary, _) => return Out::Count(frame.iface, d.kind, d.node),
                        (_, OutputFormat::Text) => text::write_line(&mut s, frame, ifaces, d),
                        _ => jsonl::write_frame(&mut s, line, frame, ifaces, d),
                    }
                    Out::Line(s)
                });
                self.pos += 1;
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
                Out::Count(iface, kind, node) => self.summary.add_on(iface, kind, node),
                Out::Line(s) => buf.extend_from_slice(&s),
            }
        }
    }

    fn transaction(&self, buf: &mut Vec<u8>, t: &crate::sdo::Transaction, t0: u64) {
        let dict = self.decoder.dictionary(t.node);
        if !self.filter.matches_transaction(t, dict, t0) {
            return;
        }
        let iface = super::decode::shown_iface(&self.names, t.iface);
        write_transaction(buf, &mut String::new(), t, dict, iface, self.format);
    }

    /// Writes what waited for the end of the input.
    fn finish(&mut self, out: &mut impl Write) -> io::Result<()> {
        let mut buf = Vec::new();
        match self.mode {
            Mode::Transactions => {
                let t0 = self.t0_ns.unwrap_or(0);
                for t in self.transfers.end(&mut self.decoder) {
                    self.transaction(&mut buf, &t, t0);
                }
            }
            Mode::Frames | Mode::Summary => {
                let rest = self.stream.finish();
                self.take(&mut buf, rest);
            }
        }
        if self.mode == Mode::Summary {
            write_summary(&mut buf, &mut self.summary, self.format);
        }
        out.write_all(&buf)
    }
}
