//! The flight recorder's files: each window of [`crate::analysis::trigger::window`] goes
//! to `DIR/<trigger time>-<trigger>.<ext>` (candump `-l` by default, or a record format)
//! with a JSON sidecar `DIR/<same>.json` (the trigger, its hits, the window, the frames and
//! the diagnosis of the window's frames); without a directory, one JSON line per window on
//! stdout. `decode --trigger` over logs ([`run_decode`]) and `record --trigger` on a live
//! bus (`super::trigger_live`) both write through [`Recorder`].

use super::decode_args::{DecodeArgs, OutputFormat};
use super::input::{for_each_frame, report_counts};
use crate::analysis::trace::{Trace, Views};
use crate::analysis::trigger::Trigger;
use crate::analysis::trigger::detect::Detector;
use crate::analysis::trigger::window::{Closed, Hit, Out, RING_FRAMES, Windows};
use crate::command::ExitCode;
use crate::command::record::{Encoder, LogFormat};
use crate::decode::Decoder;
use crate::frame::{Frame, Interfaces};
use crate::logio::sink::{LineSink, Target};
use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The trigger's settings as given.
pub struct Settings {
    /// The trigger's text (`--trigger`).
    pub expr: String,
    /// `--pre` (ms).
    pub pre_ms: u64,
    /// `--post` (ms).
    pub post_ms: u64,
}

/// A window's file: its path, its sink and the format's encoder.
type WindowFile = (PathBuf, LineSink<Box<dyn Target + Send>>, Encoder);

/// The window being written.
struct Current {
    file: Option<WindowFile>,
    start_ns: u64,
    hits: Vec<Hit>,
    frames: u64,
    diagnosis: Trace,
}

/// Writes the windows a [`Windows`] gives.
pub struct Recorder {
    dir: Option<PathBuf>,
    format: LogFormat,
    trigger: Trigger,
    settings: (u64, u64),
    decoder: Decoder,
    ifaces: Interfaces,
    current: Option<Current>,
    /// Windows written so far.
    pub windows: u64,
}

/// `20261202T061500.123Z` of a time in ns since the Unix epoch.
pub fn stamp(t_ns: u64) -> String {
    let secs = t_ns / 1_000_000_000;
    let (y, m, d) = canopen::calendar::civil_from_days((secs / 86_400) as i64);
    let s = secs % 86_400;
    format!(
        "{y:04}{m:02}{d:02}T{:02}{:02}{:02}.{:03}Z",
        s / 3600,
        s / 60 % 60,
        s % 60,
        t_ns / 1_000_000 % 1000
    )
}

fn extension(format: LogFormat) -> &'static str {
    match format {
        LogFormat::Candump => "log",
        LogFormat::Pcapng => "pcapng",
        LogFormat::Asc => "asc",
        LogFormat::Trc => "trc",
        LogFormat::Blf => "blf",
    }
}

fn format_name(format: LogFormat) -> &'static str {
    match format {
        LogFormat::Candump => "candump",
        LogFormat::Pcapng => "pcapng",
        LogFormat::Asc => "asc",
        LogFormat::Trc => "trc",
        LogFormat::Blf => "blf",
    }
}

/// Seconds (µs precision) of a time in ns, as the logs' timestamps.
fn secs(t_ns: u64) -> f64 {
    (t_ns / 1000) as f64 / 1e6
}

impl Recorder {
    /// Windows of `trigger` to files in `dir` (made if missing) in `format`, or (no `dir`)
    /// as JSON lines on stdout.
    pub fn new(
        dir: Option<&Path>,
        format: LogFormat,
        trigger: Trigger,
        settings: &Settings,
        decoder: Decoder,
    ) -> Result<Recorder, String> {
        if let Some(d) = dir {
            std::fs::create_dir_all(d).map_err(|e| format!("cannot make {}: {e}", d.display()))?;
        }
        Ok(Recorder {
            dir: dir.map(Path::to_path_buf),
            format,
            trigger,
            settings: (settings.pre_ms, settings.post_ms),
            decoder,
            ifaces: Interfaces::default(),
            current: None,
            windows: 0,
        })
    }

    /// Takes note of the frames' interface table.
    pub fn name_interfaces(&mut self, ifaces: &Interfaces) {
        for name in ifaces.names().iter().skip(self.ifaces.names().len()) {
            self.ifaces.intern(name);
        }
        if let Some(c) = &mut self.current {
            c.diagnosis.name_interfaces(&self.ifaces);
        }
    }

    /// Writes what the windows gave.
    pub fn take(&mut self, outs: &mut Vec<Out>) -> io::Result<()> {
        for o in outs.drain(..) {
            match o {
                Out::Open { start_ns, hit } => self.open(start_ns, hit)?,
                Out::Frame(f) => self.frame(&f),
                Out::Hit(h) => {
                    if let Some(c) = &mut self.current {
                        c.hits.push(h);
                    }
                }
                Out::Close(c) => self.close(&c)?,
            }
        }
        Ok(())
    }

    /// Writes out the open window's frames so far (live: at least every 200 ms).
    pub fn flush(&mut self) -> io::Result<()> {
        if let Some(Current {
            file: Some((_, sink, enc)),
            ..
        }) = &mut self.current
        {
            enc.flush(sink);
            sink.flush()?;
        }
        Ok(())
    }

    fn open(&mut self, start_ns: u64, hit: Hit) -> io::Result<()> {
        let file = match &self.dir {
            None => None,
            Some(dir) => {
                let base = format!("{}-{}", stamp(hit.t_ns), self.trigger.slug());
                let (path, f) = create_unique(dir, &base, extension(self.format))?;
                let mut sink: LineSink<Box<dyn Target + Send>> = LineSink::new(Box::new(f), 0);
                let enc = Encoder::start(self.format, &mut sink, &[]);
                Some((path, sink, enc))
            }
        };
        let mut diagnosis = Trace::headless(self.decoder.clone(), Views::Diagnosis);
        diagnosis.name_interfaces(&self.ifaces);
        self.current = Some(Current {
            file,
            start_ns,
            hits: vec![hit],
            frames: 0,
            diagnosis,
        });
        Ok(())
    }

    fn frame(&mut self, f: &Frame) {
        let Some(c) = &mut self.current else { return };
        c.frames += 1;
        c.diagnosis.push(f);
        if let Some((_, sink, enc)) = &mut c.file {
            enc.frame(sink, f, self.ifaces.name(f.iface));
        }
    }

    fn close(&mut self, closed: &Closed) -> io::Result<()> {
        let Some(mut c) = self.current.take() else {
            return Ok(());
        };
        self.windows += 1;
        let hits: Vec<serde_json::Value> = c
            .hits
            .iter()
            .map(|h| serde_json::json!({"t": secs(h.t_ns), "what": h.what}))
            .collect();
        let mut line = serde_json::json!({
            "trigger": self.trigger.source,
            "start": secs(c.start_ns),
            "end": secs(closed.end_ns),
            "hits": hits,
            "frames": c.frames,
            "cut_short": closed.cut_short,
        });
        let Some((path, mut sink, mut enc)) = c.file.take() else {
            let mut out = io::stdout().lock();
            writeln!(out, "{line}")?;
            return out.flush();
        };
        enc.flush(&mut sink);
        sink.flush()?;
        enc.finish(&mut sink)?;
        c.diagnosis.end_of_input();
        let diag = c.diagnosis.diagnosis;
        let origin = diag.origin_ns();
        let incidents = diag.finish();
        let extra = serde_json::json!({
            "file": path.file_name().map(|n| n.to_string_lossy().into_owned()),
            "format": format_name(self.format),
            "pre_ms": self.settings.0,
            "post_ms": self.settings.1,
            "ring_overflow": closed.ring_overflow,
            "ring_frames": RING_FRAMES,
            "diagnosis": incidents.iter().map(|i| i.to_json(origin)).collect::<Vec<_>>(),
        });
        if let (Some(l), serde_json::Value::Object(e)) = (line.as_object_mut(), extra) {
            l.extend(e);
        }
        let side = path.with_extension("json");
        std::fs::write(&side, format!("{line:#}\n"))?;
        eprintln!(
            "cotui: window {} ({} frames, {} hit(s))",
            path.display(),
            c.frames,
            c.hits.len()
        );
        Ok(())
    }
}

/// Creates `dir/base.ext`, or `dir/base-2.ext`, ... when it exists.
fn create_unique(dir: &Path, base: &str, ext: &str) -> io::Result<(PathBuf, File)> {
    for n in 1.. {
        let name = if n == 1 {
            format!("{base}.{ext}")
        } else {
            format!("{base}-{n}.{ext}")
        };
        let path = dir.join(name);
        match OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(f) => return Ok((path, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => {
                return Err(io::Error::new(
                    e.kind(),
                    format!("cannot create {}: {e}", path.display()),
                ));
            }
        }
    }
    unreachable!("an unbounded range ends only by returning")
}

/// The flight recorder: the trigger's detector, the windows and their files, fed one
/// stream (a log's frames, or a live bus's frames, clock ticks and state changes).
pub struct Flight {
    detector: Detector,
    windows: Windows,
    recorder: Recorder,
    outs: Vec<Out>,
    hits: Vec<Hit>,
}

impl Flight {
    /// A flight recorder of `trigger` writing into `dir` (or JSON lines on stdout).
    pub fn new(
        trigger: Trigger,
        decoder: Decoder,
        settings: &Settings,
        dir: Option<&Path>,
        format: LogFormat,
    ) -> Result<Flight, String> {
        let detector = Detector::new(&trigger, &decoder);
        let ms = 1_000_000;
        let windows = Windows::new(settings.pre_ms.saturating_mul(ms), settings.post_ms.saturating_mul(ms));
        Ok(Flight {
            detector,
            windows,
            recorder: Recorder::new(dir, format, trigger, settings, decoder)?,
            outs: Vec::new(),
            hits: Vec::new(),
        })
    }

    /// Takes note of the frames' interface table.
    pub fn name_interfaces(&mut self, ifaces: &Interfaces) {
        self.detector.name_interfaces(ifaces);
        self.recorder.name_interfaces(ifaces);
    }

    /// The next frame: into the ring or the open window, then judged by the trigger.
    pub fn frame(&mut self, f: &Frame) -> io::Result<()> {
        self.windows.frame(f, &mut self.outs);
        self.detector.frame(f, &mut self.hits);
        self.write()
    }

    /// The clock reached `now_ns` without a frame.
    pub fn tick(&mut self, now_ns: u64) -> io::Result<()> {
        self.detector.tick(now_ns, &mut self.hits);
        for h in self.hits.drain(..) {
            self.windows.hit(h, &mut self.outs);
        }
        self.windows.tick(now_ns, &mut self.outs);
        self.write()?;
        self.recorder.flush()
    }

    /// The live interface changed state.
    pub fn link(&mut self, t_ns: u64, link: crate::analysis::trigger::detect::Link) -> io::Result<()> {
        self.detector.link(t_ns, link, &mut self.hits);
        self.write()
    }

    /// The stream ended: an open window closes with what it has.
    pub fn finish(&mut self) -> io::Result<()> {
        self.detector.finish(&mut self.hits);
        for h in self.hits.drain(..) {
            self.windows.hit(h, &mut self.outs);
        }
        self.windows.finish(&mut self.outs);
        self.recorder.take(&mut self.outs)
    }

    /// Windows written (closed) so far.
    pub fn windows(&self) -> u64 {
        self.recorder.windows
    }

    /// True while a window is open.
    pub fn is_open(&self) -> bool {
        self.windows.is_open()
    }

    fn write(&mut self) -> io::Result<()> {
        for h in self.hits.drain(..) {
            self.windows.hit(h, &mut self.outs);
        }
        self.recorder.take(&mut self.outs)
    }
}

/// Parses `--trigger` for command `cmd`, its error with the column and the excerpt.
pub fn parse(cmd: &str, expr: &str, decoder: &Decoder) -> Result<Trigger, String> {
    Trigger::parse(expr, decoder).map_err(|e| format!("{cmd}: --trigger {:?}: {e}", e.excerpt(expr)))
}

/// `cotui decode --trigger EXPR [--pre DUR] [--post DUR] [-o DIR] FILE...`: one file per
/// window (or, without `-o`, one JSON line per window).
pub fn run_decode(args: &DecodeArgs) -> ExitCode {
    let settings = &Settings {
        expr: args.trigger.clone().unwrap_or_default(),
        pre_ms: args.pre,
        post_ms: args.post,
    };
    let format = match args.format {
        OutputFormat::Text => LogFormat::Candump,
        OutputFormat::Jsonl if args.output.is_none() => LogFormat::Candump,
        OutputFormat::Pcapng => LogFormat::Pcapng,
        OutputFormat::Asc => LogFormat::Asc,
        OutputFormat::Trc => LogFormat::Trc,
        OutputFormat::Blf => LogFormat::Blf,
        OutputFormat::Jsonl | OutputFormat::Parquet => {
            eprintln!(
                "cotui decode: --trigger writes candump, pcapng, asc, trc or blf windows to -o DIR, or (--format jsonl without -o) one JSON line per window"
            );
            return ExitCode::Usage;
        }
    };
    if args.filter.is_some() || args.summary || args.transactions || args.events {
        eprintln!("cotui decode: --trigger goes alone (not with --filter, --summary, --transactions or --events)");
        return ExitCode::Usage;
    }
    let dir = match (args.output.as_deref(), args.format) {
        (None, OutputFormat::Jsonl) => None,
        (None | Some("-"), _) => {
            eprintln!(
                "cotui decode: --trigger needs -o DIR for the window files (or --format jsonl for one line per window)"
            );
            return ExitCode::Usage;
        }
        (Some(d), _) => Some(PathBuf::from(d)),
    };
    let decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let trigger = match parse("cotui decode", &settings.expr, &decoder) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::Usage;
        }
    };
    let mut flight = match Flight::new(trigger, decoder, settings, dir.as_deref(), format) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let mut status = ExitCode::Ok;
    let (inputs, failed) = super::input::open_inputs(&args.files, "decode", args.iface_per_file, args.input.format());
    if failed {
        status = ExitCode::Unavailable;
    }
    for (path, input) in inputs {
        let counts = for_each_frame(&path, input, |frames| {
            flight.name_interfaces(frames.ifaces);
            for (_, frame) in frames {
                flight.frame(frame)?;
            }
            Ok(())
        });
        match counts {
            Ok(c) => report_counts(&path, &c),
            Err(e) => {
                eprintln!("cotui decode: {path}: {e}");
                status = ExitCode::Unavailable;
            }
        }
    }
    if let Err(e) = flight.finish() {
        eprintln!("cotui decode: {e}");
        return ExitCode::Unavailable;
    }
    if flight.windows() == 0 {
        eprintln!("cotui decode: the trigger `{}` never fired", settings.expr);
    }
    status
}
