//! `cotui explain FRAME...`: each frame's identifier split, CANopen meaning, data bits by
//! field and the frame on the wire with its figures (see `src/output/explain.rs`).

use crate::command::ExitCode;
use crate::frame::json::write_line;
use crate::log::candump::parse_compact;
use clap::{Args, ValueEnum};
use std::io::Write;

/// Output formats of `cotui explain`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ExplainFormat {
    /// A report per frame.
    Text,
    /// One JSON object per frame.
    Jsonl,
}

/// Arguments of `cotui explain`.
#[derive(Args, Debug)]
pub struct ExplainArgs {
    /// Frames as cansend takes them: `185#2500EA00`, `705#R`, `12345678#11`, `185##1AABB`.
    #[arg(required = true, value_name = "FRAME")]
    pub frames: Vec<String>,
    /// Bus bit rate for the time on the wire, in bit/s (500000, 500k, 1M); without it
    /// 500 kbit/s is assumed, and said so.
    #[arg(long, value_parser = super::tui::bitrate_arg, value_name = "R")]
    pub bitrate: Option<u64>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: ExplainFormat,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
}

/// Runs `cotui explain`: 1 when a frame is malformed (after explaining the others).
pub fn run(args: &ExplainArgs) -> ExitCode {
    let mut decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui explain: {e}");
            return ExitCode::Usage;
        }
    };
    let bitrate = args.bitrate.unwrap_or(500_000);
    let mut out = Vec::new();
    let mut status = ExitCode::Ok;
    for text in &args.frames {
        let frame = match parse_compact(text.trim().as_bytes()) {
            Ok(Some(f)) => f,
            Ok(None) => {
                eprintln!("cotui explain: {text}: a CAN XL frame, which cotui does not model");
                status = ExitCode::Usage;
                continue;
            }
            Err(e) => {
                eprintln!("cotui explain: {text}: {e}");
                status = ExitCode::Usage;
                continue;
            }
        };
        if let Err(e) = crate::wire::figures(&frame)
            && !frame.is_err()
        {
            eprintln!("cotui explain: {text}: {e}");
            status = ExitCode::Usage;
            continue;
        }
        let decoded = decoder.decode(&frame);
        let e = crate::output::explain::Explained {
            text,
            frame: &frame,
            decoded: &decoded,
            bitrate,
            assumed: args.bitrate.is_none(),
        };
        match args.format {
            ExplainFormat::Text => out.extend_from_slice(e.to_text().as_bytes()),
            ExplainFormat::Jsonl => write_line(&mut out, &e.to_json()),
        }
    }
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout.write_all(&out).and_then(|_| stdout.flush())
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        eprintln!("cotui explain: {e}");
        return ExitCode::Unavailable;
    }
    status
}
