//! Where `cotui decode` writes (`-o FILE`, `-o -` or stdout) and its pcapng export.

use super::decode::DecodeArgs;
use super::input;
use crate::command::ExitCode;
use crate::output::pcapng::PcapngWriter;
use std::io::{self, BufRead, IsTerminal, Write};

/// Why the output of `cotui decode` cannot be opened.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("pcapng is binary: not writing it to a terminal (use -o FILE, or redirect stdout)")]
    BinaryToTerminal,
    #[error("{0}: pcapng is binary: not writing it to a terminal")]
    BinaryToTerminalFile(String),
    #[error("{path}: {source}")]
    Create { path: String, source: io::Error },
}

/// The output stream: `path` (`None` or `-` is stdout). Binary output is refused when
/// it would go to a terminal.
pub fn open(path: Option<&str>, binary: bool) -> Result<Box<dyn Write>, OutputError> {
    match path {
        None | Some("-") => {
            let stdout = io::stdout();
            if binary && stdout.is_terminal() {
                return Err(OutputError::BinaryToTerminal);
            }
            Ok(Box::new(io::BufWriter::with_capacity(1 << 16, stdout.lock())))
        }
        Some(p) => match std::fs::File::create(p) {
            Ok(f) if binary && f.is_terminal() => Err(OutputError::BinaryToTerminalFile(p.to_string())),
            Ok(f) => Ok(Box::new(io::BufWriter::with_capacity(1 << 16, f))),
            Err(source) => Err(OutputError::Create {
                path: p.to_string(),
                source,
            }),
        },
    }
}

/// `cotui decode FILE... --format pcapng`: every frame of every input, in order, one
/// interface description per interface name.
pub fn pcapng(args: &DecodeArgs) -> ExitCode {
    if args.transactions || args.summary || args.events {
        eprintln!(
            "cotui decode: --format pcapng writes frames; it does not go with --transactions, --summary or --events"
        );
        return ExitCode::Usage;
    }
    let out = match open(args.output.as_deref(), true) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let mut w = match PcapngWriter::new(out) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Unavailable;
        }
    };
    let mut status = ExitCode::Ok;
    for path in &args.files {
        let Some(input) = input::open_input(path, "decode") else {
            status = ExitCode::Unavailable;
            continue;
        };
        if let Err(e) = write_stream(path, input, &mut w) {
            if e.kind() == io::ErrorKind::BrokenPipe {
                return status;
            }
            eprintln!("cotui decode: {path}: {e}");
            status = ExitCode::Unavailable;
        }
    }
    match w.flush() {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            eprintln!("cotui decode: {e}");
            ExitCode::Unavailable
        }
        _ => status,
    }
}

/// Writes the frames of one input (parsed on a second thread); reports what was skipped.
fn write_stream(path: &str, input: Box<dyn BufRead + Send>, w: &mut PcapngWriter<impl Write>) -> io::Result<()> {
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
