//! `cotui decode --filter EXPR`: the frames (or, with `--transactions`, the SDO transfers,
//! or with `--summary` the totals of the frames) that match an expression of the TUI's
//! filter language, judged as the TUI's filtered view judges them.

use super::decode::{DecodeArgs, OutputFormat, open_input, report_counts};
use super::{EXIT_OK, EXIT_UNAVAILABLE, EXIT_USAGE};
use crate::analysis::filter::stream::Stream;
use crate::analysis::filter::{Facts, Filter};
use crate::decode::{Decoder, Kind};
use crate::frame::Interfaces;
use crate::log::{Outcome, read_ahead};
use crate::output::{jsonl, summary::Summary, text};
use std::io::{self, Write};

/// What a matching frame gives: its output line, or its kind and node for the totals.
enum Out {
    Line(String),
    Count(Kind, Option<u8>),
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
    /// Frames taken so far (the decoder's sequence numbers).
    pos: u64,
    t0_ns: Option<u64>,
}

/// Runs a filtered `cotui decode`; returns the exit status.
pub fn run(args: &DecodeArgs, expr: &str) -> i32 {
    if args.events || matches!(args.format, OutputFormat::Pcapng | OutputFormat::Parquet) {
        eprintln!("cotui decode: --filter goes with text or jsonl frames, --transactions or --summary");
        return EXIT_USAGE;
    }
    let decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return EXIT_USAGE;
        }
    };
    let filter = match Filter::parse_with(expr, &decoder) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("cotui decode: --filter {expr:?}: {e}");
            return EXIT_USAGE;
        }
    };
    let mode = if args.transactions {
        Mode::Transactions
    } else if args.summary {
        Mode::Summary
    } else {
        Mode::Frames
    };
    let mut out = match super::decode_out::open(args.output.as_deref(), false) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return EXIT_USAGE;
        }
    };
    let mut run = Run {
        decoder,
        stream: Stream::new(filter.clone()),
        filter,
        mode,
        format: args.format,
        summary: Summary::default(),
        pos: 0,
        t0_ns: None,
    };
    let mut status = EXIT_OK;
    for path in &args.files {
        let Some(input) = open_input(path, "decode") else {
            status = EXIT_UNAVAILABLE;
            continue;
        };
        match run.file(path, input, &mut out) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => return status,
            Err(e) => {
                eprintln!("cotui decode: {path}: {e}");
                status = EXIT_UNAVAILABLE;
            }
        }
    }
    match run.finish(&mut out).and_then(|_| out.flush()) {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            eprintln!("cotui decode: {e}");
            EXIT_UNAVAILABLE
        }
        _ => status,
    }
}

impl Run {
    fn file(&mut self, path: &str, input: Box<dyn io::BufRead + Send>, out: &mut impl Write) -> io::Result<()> {
        let mut buf = String::with_capacity(1 << 16);
        let mut ifaces = Interfaces::default();
        let finished = read_ahead::for_each_batch(input, |batch| -> io::Result<()> {
            if let Some(i) = &batch.interfaces {
                ifaces = i.clone();
            }
            for (line, outcome) in &batch.lines {
                let frame = match outcome {
                    Outcome::Frame(f) => f,
                    Outcome::Skip(_) => continue,
                    Outcome::Warning(msg) => {
                        eprintln!("{path}:{line}: warning: {msg}");
                        continue;
                    }
                };
                let t0 = *self.t0_ns.get_or_insert(frame.ts_ns);
                self.decoder.set_seq(self.pos);
                let d = self.decoder.decode(frame);
                let done = self.decoder.take_transactions();
                if self.mode == Mode::Transactions {
                    for t in &done {
                        self.transaction(&mut buf, t, t0);
                    }
                    self.pos += 1;
                    continue;
                }
                let facts = Facts {
                    ts_ns: frame.ts_ns,
                    id: frame.id,
                    flags: frame.flags.0,
                    kind: d.kind,
                    node: d.node,
                };
                let (mode, format) = (self.mode, self.format);
                self.stream.frame(self.pos, facts, d, &done, |d| {
                    let mut s = String::new();
                    match (mode, format) {
                        (Mode::Summary, _) => return Out::Count(d.kind, d.node),
                        (_, OutputFormat::Text) => text::write_line(&mut s, frame, &ifaces, d),
                        _ => jsonl::write_frame(&mut s, *line, frame, &ifaces, d),
                    }
                    Out::Line(s)
                });
                self.pos += 1;
                let ready = self.stream.ready();
                self.take(&mut buf, ready);
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

    /// Writes (or counts) matching frames.
    fn take(&mut self, buf: &mut String, ready: Vec<Out>) {
        for o in ready {
            match o {
                Out::Count(kind, node) => self.summary.add(kind, node),
                Out::Line(s) => buf.push_str(&s),
            }
        }
    }

    fn transaction(&self, buf: &mut String, t: &crate::decode::sdo::Transaction, t0: u64) {
        let dict = self.decoder.dictionary(t.node);
        if !self.filter.matches_transaction(t, dict, t0) {
            return;
        }
        match self.format {
            OutputFormat::Text => buf.push_str(&t.label(dict)),
            _ => buf.push_str(&t.to_json(dict).to_string()),
        }
        buf.push('\n');
    }

    /// Writes what waited for the end of the input.
    fn finish(&mut self, out: &mut impl Write) -> io::Result<()> {
        let mut buf = String::new();
        match self.mode {
            Mode::Transactions => {
                let t0 = self.t0_ns.unwrap_or(0);
                for t in self.decoder.finish() {
                    self.transaction(&mut buf, &t, t0);
                }
            }
            Mode::Frames | Mode::Summary => {
                let rest = self.stream.finish();
                self.take(&mut buf, rest);
            }
        }
        if self.mode == Mode::Summary {
            self.summary.finish();
            match self.format {
                OutputFormat::Text => buf.push_str(&self.summary.to_text()),
                _ => {
                    buf.push_str(&self.summary.to_json().to_string());
                    buf.push('\n');
                }
            }
        }
        out.write_all(buf.as_bytes())
    }
}
