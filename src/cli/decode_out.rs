//! Where `cotui decode` writes (`-o FILE`, `-o -` or stdout) and its pcapng, BLF, ASC
//! and TRC exports.

use super::decode_args::DecodeArgs;
use super::input;
use crate::command::ExitCode;
use crate::frame::Frame;
use crate::log::export::{AscWriter, TrcWriter};
use crate::output::blf::BlfWriter;
use crate::output::pcapng::PcapngWriter;
use std::cell::Cell;
use std::io::{self, IsTerminal, Write};
use std::rc::Rc;

/// Why the output of `cotui decode` cannot be opened.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{0} is binary: not writing it to a terminal (use -o FILE, or redirect stdout)")]
    BinaryToTerminal(&'static str),
    #[error("{0}: {1} is binary: not writing it to a terminal")]
    BinaryToTerminalFile(String, &'static str),
    #[error("{path}: {source}")]
    Create { path: String, source: io::Error },
}

/// The output of `cotui decode`: it remembers a failed write, so that an error is blamed
/// on the output (exit 1, "cannot write OUT") and not on the input being read.
pub struct Output {
    inner: Box<dyn Write>,
    failed: Blame,
}

/// Who an I/O error of a decode run is blamed on (see [`Output`]).
#[derive(Clone)]
pub struct Blame {
    name: Rc<str>,
    failed: Rc<Cell<bool>>,
}

impl Blame {
    /// Prints `e` for the user, blaming the output when a write failed, else `input` (the
    /// file being read, if any); gives the exit status: 1 for the output (a file that cannot
    /// be written), 2 for an input.
    pub fn report(&self, input: Option<&str>, e: &io::Error) -> ExitCode {
        if self.failed.get() {
            eprintln!("cotui decode: cannot write {}: {e}", self.name);
            ExitCode::Usage
        } else {
            match input {
                Some(path) => eprintln!("cotui decode: {path}: {e}"),
                None => eprintln!("cotui decode: {e}"),
            }
            ExitCode::Unavailable
        }
    }
    /// Whether a write to the output failed (the run cannot go on).
    pub fn output_failed(&self) -> bool {
        self.failed.get()
    }
}

impl Output {
    /// A handle that tells, after an error, whether the output failed.
    pub fn blame(&self) -> Blame {
        self.failed.clone()
    }
    fn new(inner: Box<dyn Write>, name: &str) -> Output {
        Output {
            inner,
            failed: Blame {
                name: name.into(),
                failed: Rc::new(Cell::new(false)),
            },
        }
    }
    fn noted<T>(&self, r: io::Result<T>) -> io::Result<T> {
        if r.as_ref().is_err_and(|e| e.kind() != io::ErrorKind::Interrupted) {
            self.failed.failed.set(true);
        }
        r
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let r = self.inner.write(buf);
        self.noted(r)
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        let r = self.inner.write_all(buf);
        self.noted(r)
    }
    fn flush(&mut self) -> io::Result<()> {
        let r = self.inner.flush();
        self.noted(r)
    }
}

/// The output stream: `path` (`None` or `-` is stdout). Binary output (`binary` names its
/// format) is refused when it would go to a terminal.
pub fn open(path: Option<&str>, binary: Option<&'static str>) -> Result<Output, OutputError> {
    let name = path.filter(|p| *p != "-").unwrap_or("stdout");
    open_stream(path, binary).map(|w| Output::new(w, name))
}

fn open_stream(path: Option<&str>, binary: Option<&'static str>) -> Result<Box<dyn Write>, OutputError> {
    match path {
        None | Some("-") => {
            let stdout = io::stdout();
            if let Some(format) = binary
                && stdout.is_terminal()
            {
                return Err(OutputError::BinaryToTerminal(format));
            }
            Ok(Box::new(io::BufWriter::with_capacity(1 << 16, stdout.lock())))
        }
        Some(p) => match std::fs::File::create(p) {
            Ok(f) if binary.is_some() && f.is_terminal() => Err(OutputError::BinaryToTerminalFile(
                p.to_string(),
                binary.unwrap_or_default(),
            )),
            Ok(f) => Ok(Box::new(io::BufWriter::with_capacity(1 << 16, f))),
            Err(source) => Err(OutputError::Create {
                path: p.to_string(),
                source,
            }),
        },
    }
}

/// A binary log of frames that `cotui decode` writes frame by frame.
trait FrameOut {
    fn write_frame(&mut self, iface: &str, f: &Frame) -> io::Result<()>;
    /// Writes what is left and flushes.
    fn finish(&mut self) -> io::Result<()>;
}

impl<W: Write> FrameOut for PcapngWriter<W> {
    fn write_frame(&mut self, iface: &str, f: &Frame) -> io::Result<()> {
        PcapngWriter::write_frame(self, iface, f)
    }
    fn finish(&mut self) -> io::Result<()> {
        self.flush()
    }
}

/// A BLF writer and the file (if any) whose header gets the final totals.
struct BlfOut<W: Write> {
    w: BlfWriter<W>,
    file: Option<String>,
}

impl<W: Write> FrameOut for BlfOut<W> {
    fn write_frame(&mut self, iface: &str, f: &Frame) -> io::Result<()> {
        self.w.write_frame(iface, f)
    }
    fn finish(&mut self) -> io::Result<()> {
        let header = self.w.finish()?;
        match &self.file {
            Some(path) => {
                use std::os::unix::fs::FileExt;
                std::fs::OpenOptions::new()
                    .write(true)
                    .open(path)?
                    .write_all_at(&header, 0)
            }
            None => Ok(()),
        }
    }
}

/// `cotui decode FILE... --format pcapng|blf`: every frame of every input, in order (one
/// pcapng interface description per interface name; BLF channels by name).
pub fn frames(args: &DecodeArgs) -> ExitCode {
    let name = if args.format == super::decode_args::OutputFormat::Blf {
        "BLF"
    } else {
        "pcapng"
    };
    if args.transactions || args.summary || args.events {
        eprintln!(
            "cotui decode: --format {} writes frames; it does not go with --transactions, --summary or --events",
            name.to_lowercase()
        );
        return ExitCode::Usage;
    }
    let out = match open(args.output.as_deref(), Some(name)) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let blame = out.blame();
    let mut w: Box<dyn FrameOut> = if name == "BLF" {
        Box::new(BlfOut {
            w: BlfWriter::new(out),
            file: args.output.clone().filter(|p| p != "-"),
        })
    } else {
        match PcapngWriter::new(out) {
            Ok(w) => Box::new(w),
            Err(e) => return blame.report(None, &e),
        }
    };
    let mut status = ExitCode::Ok;
    let (inputs, failed) = input::open_inputs(&args.files, "decode", args.iface_per_file, args.input.format());
    if failed {
        status = ExitCode::Unavailable;
    }
    for (path, input) in inputs {
        let path = &path;
        if let Err(e) = write_stream(path, input, w.as_mut()) {
            if e.kind() == io::ErrorKind::BrokenPipe {
                return status;
            }
            status = blame.report(Some(path), &e);
            if blame.output_failed() {
                return status;
            }
        }
    }
    match w.finish() {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => blame.report(None, &e),
        _ => status,
    }
}

/// Writes the frames of one input (parsed on a second thread); reports what was skipped.
fn write_stream(path: &str, input: input::Input, w: &mut dyn FrameOut) -> io::Result<()> {
    let counts = input::for_each_frame(path, input, |frames| {
        let ifaces = frames.ifaces;
        for (_, f) in frames {
            w.write_frame(ifaces.name(f.iface), f)?;
        }
        Ok(())
    })?;
    input::report_counts(path, &counts);
    Ok(())
}

/// A text log writer: Vector ASC or PEAK TRC 2.1.
enum LogOut {
    Asc(AscWriter),
    Trc(TrcWriter),
}

/// `cotui decode FILE... --format asc|trc`: every frame of every input, in order, as a
/// Vector ASC (`asc`) or PEAK TRC 2.1 log.
pub fn text_log(args: &DecodeArgs, asc: bool) -> ExitCode {
    let name = if asc { "asc" } else { "trc" };
    if args.transactions || args.summary || args.events {
        eprintln!(
            "cotui decode: --format {name} writes frames; it does not go with --transactions, --summary or --events"
        );
        return ExitCode::Usage;
    }
    let mut out = match open(args.output.as_deref(), None) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let blame = out.blame();
    let mut w = if asc {
        LogOut::Asc(AscWriter::new())
    } else {
        LogOut::Trc(TrcWriter::new())
    };
    let mut status = ExitCode::Ok;
    let mut text = String::with_capacity(1 << 16);
    for path in &args.files {
        let Some(input) = input::open_input(path, "decode", args.input.format()) else {
            status = ExitCode::Unavailable;
            continue;
        };
        let counts = input::for_each_frame(path, input, |frames| {
            let ifaces = frames.ifaces;
            for (_, f) in frames {
                match &mut w {
                    LogOut::Asc(a) => a.write_line(&mut text, f, ifaces.name(f.iface)),
                    LogOut::Trc(t) => t.write_line(&mut text, f, ifaces.name(f.iface)),
                }
            }
            out.write_all(text.as_bytes())?;
            text.clear();
            Ok(())
        });
        match counts {
            Ok(c) => input::report_counts(path, &c),
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => return status,
            Err(e) => {
                status = blame.report(Some(path), &e);
                if blame.output_failed() {
                    return status;
                }
            }
        }
    }
    if let LogOut::Asc(a) = &mut w {
        a.finish(&mut text);
    }
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => blame.report(None, &e),
        _ => status,
    }
}
