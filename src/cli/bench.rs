//! `cotui bench`: decoder throughput and peak memory on a generated log.
//!
//! Each figure comes from a child `cotui decode` or `cotui diagnose` process (so peak RSS
//! is that run's alone), reading a synthetic candump log and writing to /dev/null. The
//! peers run on the same log: can-utils' `log2asc` (the baseline) and, for the diagnosis,
//! `canopen-lens` when installed.

use super::{EXIT_OK, EXIT_UNAVAILABLE};
use crate::log::writer::LogWriter;
use crate::synth::Traffic;
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// Arguments of `cotui bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Frames in the generated log.
    #[arg(long, default_value_t = 1_000_000)]
    pub frames: u64,
    /// Print the figures as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Only write the generated log to this file (for profiling or tests) and exit.
    #[arg(long, value_name = "FILE")]
    pub write_log: Option<PathBuf>,
    /// Measure the interactive analyzer instead: first screen, full index, memory per
    /// frame, redraw and key response times (use --frames 10000000 for the target figures).
    #[arg(long)]
    pub tui: bool,
}

/// One measured run.
struct Figure {
    name: String,
    frames: u64,
    seconds: f64,
    peak_rss_kib: u64,
}

impl Figure {
    fn rate(&self) -> f64 {
        self.frames as f64 / self.seconds
    }
}

/// Writes a candump `-l` log of `frames` synthetic frames to `path`.
pub fn write_log(path: &Path, frames: u64) -> std::io::Result<()> {
    let file = std::fs::File::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, file);
    let mut writer = LogWriter::new();
    let mut line = String::with_capacity(1 << 16);
    for frame in Traffic::new(frames, 1_700_000_000_000_000_000) {
        writer.write_line(&mut line, &frame, "can0");
        if line.len() > 1 << 15 {
            out.write_all(line.as_bytes())?;
            line.clear();
        }
    }
    out.write_all(line.as_bytes())?;
    out.flush()
}

/// Runs `program args`, discarding output; returns wall seconds and peak RSS (KiB).
fn measure(program: &Path, args: &[&str]) -> std::io::Result<(f64, u64)> {
    let start = Instant::now();
    let child = Command::new(program)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()?;
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: rusage is plain data; wait4 fills it for the child we just spawned.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: pid is our child; status and usage point to valid memory.
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    if r < 0 {
        return Err(std::io::Error::last_os_error());
    }
    let secs = start.elapsed().as_secs_f64();
    if !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) != 0 {
        return Err(std::io::Error::other(format!(
            "{} {:?} failed (status {status})",
            program.display(),
            args
        )));
    }
    Ok((secs, usage.ru_maxrss as u64))
}

/// Finds `name` on PATH.
fn which(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|d| Path::new(d).join(name))
        .find(|p| p.is_file())
}

/// Runs `cotui bench`; returns the exit status.
pub fn run(args: &BenchArgs) -> i32 {
    match bench(args) {
        Ok(()) => EXIT_OK,
        Err(e) => {
            eprintln!("cotui bench: {e}");
            EXIT_UNAVAILABLE
        }
    }
}

fn bench(args: &BenchArgs) -> std::io::Result<()> {
    if let Some(path) = &args.write_log {
        return write_log(path, args.frames);
    }
    if args.tui {
        return super::bench_tui::bench(args.frames, args.json);
    }
    let exe = std::env::current_exe()?;
    let dir = std::env::temp_dir().join(format!("cotui-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let big = dir.join("bench.log");
    let small = dir.join("bench-quarter.log");
    write_log(&big, args.frames)?;
    write_log(&small, args.frames / 4)?;
    let (b, s) = (big.to_string_lossy().to_string(), small.to_string_lossy().to_string());
    let mut figures = Vec::new();
    let runs: [(&str, Vec<&str>, &str, u64); 5] = [
        (
            "text",
            vec!["decode", "--format", "text", &b],
            "decode --format text",
            args.frames,
        ),
        (
            "jsonl",
            vec!["decode", "--format", "jsonl", &b],
            "decode --format jsonl",
            args.frames,
        ),
        (
            "summary",
            vec!["decode", "--summary", &b],
            "decode --summary",
            args.frames,
        ),
        (
            "diagnose",
            vec!["diagnose", "--format", "jsonl", &b],
            "diagnose",
            args.frames,
        ),
        (
            "text-quarter",
            vec!["decode", "--format", "text", &s],
            "decode --format text (1/4 log)",
            args.frames / 4,
        ),
    ];
    for (name, argv, _, frames) in &runs {
        let (seconds, peak_rss_kib) = measure(&exe, argv)?;
        figures.push(Figure {
            name: name.to_string(),
            frames: *frames,
            seconds,
            peak_rss_kib,
        });
    }
    let log2asc = which("log2asc").and_then(|p| {
        let out = dir.join("bench.asc");
        let o = out.to_string_lossy().to_string();
        measure(&p, &["-I", &b, "-O", &o, "can0"]).ok()
    });
    // canopen-lens is slow (about 10 k frames/s): the quarter log keeps the run short.
    let lens = which("canopen-lens").and_then(|p| measure(&p, &[&s]).ok());
    let _ = std::fs::remove_dir_all(&dir);
    let lens_rate = lens.map(|(secs, _)| (args.frames / 4) as f64 / secs);
    report(args, &runs.map(|r| r.2), &figures, log2asc, lens_rate);
    Ok(())
}

/// Prints the figures; `lens` is canopen-lens's rate on the quarter log (frames/s).
fn report(args: &BenchArgs, titles: &[&str; 5], figures: &[Figure], log2asc: Option<(f64, u64)>, lens: Option<f64>) {
    let base = log2asc.map(|(secs, _)| args.frames as f64 / secs);
    if args.json {
        let runs: Vec<serde_json::Value> = figures
            .iter()
            .map(|f| {
                serde_json::json!({
                    "name": f.name, "frames": f.frames, "seconds": f.seconds,
                    "frames_per_s": f.rate(), "peak_rss_kib": f.peak_rss_kib,
                    "vs_log2asc": base.map(|b| f.rate() / b),
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({"frames": args.frames, "runs": runs, "log2asc_frames_per_s": base,
                               "canopen_lens_frames_per_s": lens})
        );
        return;
    }
    println!("cotui bench: {} generated frames (candump -l log)", args.frames);
    for (f, title) in figures.iter().zip(titles) {
        let vs = base
            .map(|b| format!("  {:5.1}x log2asc", f.rate() / b))
            .unwrap_or_default();
        println!(
            "  {title:<32} {:>12.0} frames/s  {:>7.3} s  peak RSS {:>7} KiB{vs}",
            f.rate(),
            f.seconds,
            f.peak_rss_kib
        );
    }
    match base {
        Some(b) => println!("  {:<32} {b:>12.0} frames/s (can-utils, same log)", "log2asc"),
        None => println!("  log2asc not found (install can-utils) - no baseline"),
    }
    match lens {
        Some(r) => println!(
            "  {:<32} {r:>12.0} frames/s (the diagnose peer, 1/4 log)",
            "canopen-lens"
        ),
        None => println!("  canopen-lens not found (scripts/install-test-deps.sh) - no diagnose peer figure"),
    }
}
