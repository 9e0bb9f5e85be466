//! `cotui bench`: decoder throughput and peak memory on a generated log.
//!
//! Each figure comes from a child `cotui decode` or `cotui diagnose` process (so peak RSS
//! is that run's alone), reading a synthetic candump log and writing to /dev/null; the
//! runs are interleaved round by round and the median of the rounds reported, beside
//! can-utils' `log2asc` on the same log (the baseline) and the targets, and, for the
//! diagnosis, `canopen-lens` when installed.

pub mod log;
mod mf4;
mod scratch;
mod tui;

use crate::command::ExitCode;
use clap::Args;
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
    /// With --write-log: write the bench frames in this input format instead of the
    /// candump log (screen, asc, trc, csv, peak-csv, savvycan, mf4, blf), as the per-format rows read them.
    #[arg(long, value_name = "FORMAT", requires = "write_log", value_parser = clap::builder::PossibleValuesParser::new(log::INPUT_FORMATS.map(|(f, _)| f)))]
    pub log_format: Option<String>,
    /// Measure the interactive analyzer instead: first screen, full index, memory per
    /// frame, redraw and key response times (use --frames 10000000 for the target figures).
    #[arg(long)]
    pub tui: bool,
}

/// Interleaved rounds per figure; the median is reported.
const ROUNDS: usize = 5;
/// Runs of the start-up figure (decode of a 10-line log, interleaved with `cat` of it);
/// the median is reported.
const STARTUP_RUNS: usize = 21;
/// Target start-up time as a multiple of `cat`'s wall time on the same 10-line log
/// (process spawn included in both).
const STARTUP_TARGET_VS_CAT: f64 = 2.0;
/// Distinct interface names in the many- and few-interfaces logs (same frames, names
/// round-robin). With 40,000 names each is seen only about six times in the 1/4 log, so
/// the first sight of a name (interned on both threads) weighs; a table searched name by
/// name made this log 100x slower, a hash index keeps it above a quarter of the rate.
const MANY_IFACES: u32 = 40_000;
const FEW_IFACES: u32 = 40;
/// The most bytes the names of the many-interfaces log (`can39999`) add to a line.
const MANY_IFACES_NAME_BYTES: f64 = 4.0;

/// Bytes to ask for logs of about `estimate` bytes: 10 % more, and 1 MB for the small files.
fn need_bytes(estimate: f64) -> u64 {
    let bytes = estimate * 1.1 + 1e6;
    if bytes >= u64::MAX as f64 {
        u64::MAX
    } else {
        bytes as u64
    }
}

/// `scan --probe` on the demo bus: how long it listens and waits for each answer (ms).
const SCAN_LISTEN_MS: u64 = 100;
const SCAN_TIMEOUT_MS: u64 = 300;
/// Target wall time of `decode --format parquet -o DIR` as a multiple of JSONL's.
const PARQUET_TARGET_VS_JSONL: f64 = 1.5;

/// One way of running the decoder, and its measurements.
struct Run {
    /// The program, when not `cotui` itself.
    program: Option<PathBuf>,
    name: &'static str,
    title: &'static str,
    args: Vec<String>,
    frames: u64,
    /// Target throughput as a multiple of log2asc's.
    target: Option<f64>,
    seconds: Vec<f64>,
    peak_rss_kib: u64,
}

impl Run {
    fn new(name: &'static str, title: &'static str, args: &[&str], frames: u64, target: Option<f64>) -> Run {
        Run {
            program: None,
            name,
            title,
            args: args.iter().map(|a| a.to_string()).collect(),
            frames,
            target,
            seconds: Vec::new(),
            peak_rss_kib: 0,
        }
    }
    /// Median wall time of the rounds.
    fn seconds(&self) -> f64 {
        median(&self.seconds)
    }
    fn rate(&self) -> f64 {
        self.frames as f64 / self.seconds()
    }
}

/// The median of `v` (0 when empty).
fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
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
    scratch::set_child(pid);
    let mut status = 0;
    // SAFETY: rusage is plain data; wait4 fills it for the child we just spawned.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: pid is our child; status and usage point to valid memory.
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    if r < 0 {
        return Err(std::io::Error::last_os_error());
    }
    scratch::set_child(0);
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
pub fn run(args: &BenchArgs) -> ExitCode {
    match bench(args) {
        Ok(()) => ExitCode::Ok,
        // Logs larger than the free space: give fewer frames (a usage error).
        Err(e) if e.kind() == std::io::ErrorKind::StorageFull => {
            eprintln!("cotui bench: --frames {}: {e}", args.frames);
            ExitCode::Usage
        }
        Err(e) => {
            eprintln!("cotui bench: {e}");
            ExitCode::Unavailable
        }
    }
}

fn bench(args: &BenchArgs) -> std::io::Result<()> {
    if let Some(path) = &args.write_log {
        return match &args.log_format {
            Some(format) => log::write_format_log(path, args.frames, format),
            None => log::write_bench_log(path, args.frames),
        };
    }
    if args.tui {
        return tui::bench(args.frames, args.json);
    }
    let exe = std::env::current_exe()?;
    let dir = std::env::temp_dir().join(format!("cotui-bench-{}", std::process::id()));
    // The full log, three quarter-size ones (two with longer interface names) and a tiny one.
    let per_frame = log::bytes_per_frame();
    let need = args.frames as f64 * (per_frame * 1.75 + 2.0 * 0.25 * MANY_IFACES_NAME_BYTES);
    let scratch = scratch::Scratch::create(dir, need_bytes(need))?;
    let result = measure_all(args, &exe, scratch.path());
    drop(scratch);
    report(args, &result?);
    Ok(())
}

/// Runs every figure `ROUNDS` times, interleaved (so a load change hits all alike).
fn measure_all(args: &BenchArgs, exe: &Path, dir: &Path) -> std::io::Result<Figures> {
    let load_before = load_average();
    let (big, small, tiny, many, few) = (
        dir.join("bench.log"),
        dir.join("bench-quarter.log"),
        dir.join("tiny.log"),
        dir.join("many-ifaces.log"),
        dir.join("few-ifaces.log"),
    );
    log::write_bench_log(&big, args.frames)?;
    log::write_bench_log(&small, args.frames / 4)?;
    log::write_bench_log(&tiny, 10)?;
    log::write_many_iface_log(&many, args.frames / 4, MANY_IFACES)?;
    log::write_many_iface_log(&few, args.frames / 4, FEW_IFACES)?;
    // The same frames as a BLF file, written by cotui itself.
    let blf = dir.join("bench.blf");
    let made = std::process::Command::new(exe)
        .args(["decode", "--format", "blf", "-o"])
        .arg(&blf)
        .arg(&big)
        .status()?;
    if !made.success() {
        return Err(std::io::Error::other("writing the BLF bench log failed"));
    }
    let blf = blf.to_string_lossy();
    let (b, s, t, m, f) = (
        big.to_string_lossy(),
        small.to_string_lossy(),
        tiny.to_string_lossy(),
        many.to_string_lossy(),
        few.to_string_lossy(),
    );
    let n = args.frames;
    let pq = dir.join("pq");
    let pq = pq.to_string_lossy();
    let mut runs = vec![
        Run::new(
            "summary",
            "decode --summary",
            &["decode", "--summary", &b],
            n,
            Some(20.0),
        ),
        Run::new(
            "text",
            "decode --format text",
            &["decode", "--format", "text", &b],
            n,
            Some(8.0),
        ),
        Run::new(
            "transactions",
            "decode --transactions",
            &["decode", "--transactions", &b],
            n,
            Some(12.0),
        ),
        Run::new(
            "jsonl",
            "decode --format jsonl",
            &["decode", "--format", "jsonl", &b],
            n,
            Some(5.0),
        ),
        Run::new(
            "parquet",
            "decode --format parquet -o DIR",
            &["decode", "--format", "parquet", "-o", &pq, &b],
            n,
            None,
        ),
        Run::new(
            "diagnose",
            "diagnose (target: within 2x of --summary)",
            &["diagnose", "--format", "jsonl", &b],
            n,
            None,
        ),
        Run::new(
            "summary-blf",
            "decode --summary, the same frames as BLF",
            &["decode", "--summary", &blf],
            n,
            None,
        ),
        Run::new(
            "summary-many-ifaces",
            "decode --summary, 40,000 ifaces (1/4 log)",
            &["decode", "--summary", &m],
            n / 4,
            None,
        ),
        Run::new(
            "summary-few-ifaces",
            "decode --summary, 40 ifaces (1/4 log)",
            &["decode", "--summary", &f],
            n / 4,
            None,
        ),
        Run::new(
            "text-quarter",
            "decode --format text (1/4 log)",
            &["decode", "--format", "text", &s],
            n / 4,
            None,
        ),
    ];
    // The candump path on the quarter log, to hold each input format's row against.
    runs.push(Run::new(
        "summary-quarter",
        "decode --summary, candump input (1/4 log)",
        &["decode", "--summary", &s],
        n / 4,
        None,
    ));
    // One row per input format, of the same frames as the quarter log.
    let format_logs: Vec<(String, String)> = log::INPUT_FORMATS
        .iter()
        .map(|(format, name)| {
            let path = dir.join(name);
            log::write_format_log(&path, n / 4, format)
                .map(|()| (format.to_string(), path.to_string_lossy().into_owned()))
        })
        .collect::<std::io::Result<_>>()?;
    for (format, path) in &format_logs {
        let (name, title) = match format.as_str() {
            "screen" => ("summary-screen", "decode --summary, screen input (1/4 log)"),
            "asc" => ("summary-asc", "decode --summary, ASC input (1/4 log)"),
            "trc" => ("summary-trc", "decode --summary, TRC input (1/4 log)"),
            "mf4" => ("summary-mf4", "decode --summary, MF4 input (1/4 log)"),
            "blf" => ("summary-blf-quarter", "decode --summary, BLF input (1/4 log)"),
            "peak-csv" => ("summary-peak-csv", "decode --summary, PEAK CSV input (1/4 log)"),
            "savvycan" => ("summary-savvycan", "decode --summary, SavvyCAN CSV input (1/4 log)"),
            _ => ("summary-csv", "decode --summary, CSV input (1/4 log)"),
        };
        runs.push(Run::new(name, title, &["decode", "--summary", path], n / 4, None));
    }
    let log2asc = which("log2asc").map(|p| Run {
        program: Some(p),
        ..Run::new("log2asc", "log2asc", &["-I", &b, "-O", "/dev/null", "can0"], n, None)
    });
    let has_base = log2asc.is_some();
    runs.extend(log2asc);
    for _ in 0..ROUNDS {
        for run in runs.iter_mut() {
            measure_into(exe, run)?;
        }
    }
    let log2asc = if has_base { runs.pop() } else { None };
    // canopen-lens is slow (about 10 k frames/s): the quarter log keeps the run short.
    let lens_rate = which("canopen-lens")
        .and_then(|p| measure(&p, &[&s]).ok())
        .map(|(secs, _)| (n / 4) as f64 / secs);
    let cat = which("cat").unwrap_or_else(|| PathBuf::from("/bin/cat"));
    let (mut startup, mut cat_s) = (Vec::new(), Vec::new());
    for _ in 0..STARTUP_RUNS {
        startup.push(measure(exe, &["decode", &t])?.0);
        cat_s.push(measure(&cat, &[&t])?.0);
    }
    let (listen, timeout) = (SCAN_LISTEN_MS.to_string(), SCAN_TIMEOUT_MS.to_string());
    let scan_args = ["scan", "demo", "--probe", "--listen", &listen, "--timeout", &timeout];
    let (scan_s, _) = measure(exe, &scan_args)?;
    Ok(Figures {
        runs,
        log2asc,
        startup_s: median(&startup),
        cat_s: median(&cat_s),
        scan_s,
        load: [load_before, load_average()],
        lens_rate,
    })
}

/// What `cotui bench` measured.
struct Figures {
    runs: Vec<Run>,
    log2asc: Option<Run>,
    /// Median start-up time (decode of a 10-line log).
    startup_s: f64,
    /// Median wall time of `cat` of the same log (the start-up baseline).
    cat_s: f64,
    /// Wall time of `scan demo --probe` (all 127 node-IDs probed at once).
    scan_s: f64,
    /// The 1-minute load average before and after.
    load: [Option<String>; 2],
    /// canopen-lens's rate on the quarter log (frames/s), when it is installed.
    lens_rate: Option<f64>,
}

/// Measures one round of `run` (a `cotui` child unless it names its program).
fn measure_into(exe: &Path, run: &mut Run) -> std::io::Result<()> {
    let args: Vec<&str> = run.args.iter().map(String::as_str).collect();
    let (secs, rss) = measure(run.program.as_deref().unwrap_or(exe), &args)?;
    run.seconds.push(secs);
    run.peak_rss_kib = run.peak_rss_kib.max(rss);
    Ok(())
}

/// The `scan --probe` target: listening, one round of probes and one of identity reads.
fn scan_target_s() -> f64 {
    (SCAN_LISTEN_MS + 3 * SCAN_TIMEOUT_MS) as f64 / 1e3
}

/// The 40,000-names log's `--summary` rate as a fraction of the 40-names log's.
fn many_ifaces_ratio(runs: &[Run]) -> Option<f64> {
    let rate = |name| runs.iter().find(|r| r.name == name).map(Run::rate);
    Some(rate("summary-many-ifaces")? / rate("summary-few-ifaces")?)
}

/// Parquet's wall time as a multiple of JSONL's on the same log.
fn parquet_vs_jsonl(runs: &[Run]) -> Option<f64> {
    let secs = |name| runs.iter().find(|r| r.name == name).map(Run::seconds);
    Some(secs("parquet")? / secs("jsonl")?)
}

/// The 1-minute load average (from /proc/loadavg), when known.
fn load_average() -> Option<String> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    text.split_whitespace().next().map(str::to_string)
}

fn report(args: &BenchArgs, f: &Figures) {
    let (runs, base) = (&f.runs, f.log2asc.as_ref().map(Run::rate));
    let (startup_ms, cat_ms) = (f.startup_s * 1e3, f.cat_s * 1e3);
    let startup_vs_cat = f.startup_s / f.cat_s.max(1e-9);
    let [before, after] = f.load.clone().map(|l| l.unwrap_or_else(|| "unknown".into()));
    if args.json {
        let figures: Vec<serde_json::Value> = runs
            .iter()
            .map(|r| {
                serde_json::json!({
                    "name": r.name, "frames": r.frames, "seconds": r.seconds(),
                    "frames_per_s": r.rate(), "peak_rss_kib": r.peak_rss_kib,
                    "vs_log2asc": base.map(|b| r.rate() / b), "target_vs_log2asc": r.target,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({
                "frames": args.frames, "rounds": ROUNDS, "runs": figures,
                "log2asc_frames_per_s": base, "load_average": [before, after],
                "startup_ms": startup_ms, "startup_cat_ms": cat_ms,
                "startup_vs_cat": startup_vs_cat, "startup_target_vs_cat": STARTUP_TARGET_VS_CAT,
                "canopen_lens_frames_per_s": f.lens_rate,
                "scan_probe_s": f.scan_s, "scan_probe_target_s": scan_target_s(),
                "many_ifaces_vs_few": many_ifaces_ratio(runs),
                "parquet_vs_jsonl": parquet_vs_jsonl(runs), "parquet_vs_jsonl_target": PARQUET_TARGET_VS_JSONL,
            })
        );
        return;
    }
    println!(
        "cotui bench: {} generated frames (candump -l log, ~12 % SDO), median of {ROUNDS} \
         interleaved runs; load average {before} before, {after} after",
        args.frames
    );
    for r in runs {
        let vs = match (base, r.target) {
            (Some(b), Some(t)) => format!("  {:5.1}x log2asc (target >= {t}x)", r.rate() / b),
            (Some(b), None) => format!("  {:5.1}x log2asc", r.rate() / b),
            (None, _) => String::new(),
        };
        println!(
            "  {:<32} {:>12.0} frames/s  {:>7.3} s  peak RSS {:>7} KiB{vs}",
            r.title,
            r.rate(),
            r.seconds(),
            r.peak_rss_kib
        );
    }
    if let Some(r) = parquet_vs_jsonl(runs) {
        println!(
            "  {:<32} {r:>12.2}x JSONL's wall time (target <= {PARQUET_TARGET_VS_JSONL}x)",
            "parquet vs jsonl"
        );
    }
    match base {
        Some(b) => println!(
            "  {:<32} {b:>12.0} frames/s (can-utils, same log, to /dev/null)",
            "log2asc"
        ),
        None => println!("  log2asc not found (install can-utils) - no baseline"),
    }
    println!(
        "  {:<32} {startup_ms:>12.2} ms, {startup_vs_cat:.2}x `cat` of it ({cat_ms:.2} ms; target <= \
         {STARTUP_TARGET_VS_CAT}x)",
        "start-up (decode of a 10-line log)"
    );
    println!(
        "  {:<32} {:>12.3} s  (target < {:.1} s: {SCAN_LISTEN_MS} ms listening + one {SCAN_TIMEOUT_MS} ms \
         probe round; one node-ID at a time would take {:.1} s)",
        "scan demo --probe (127 node-IDs)",
        f.scan_s,
        scan_target_s(),
        (SCAN_LISTEN_MS + 127 * SCAN_TIMEOUT_MS) as f64 / 1e3,
    );
    if let Some(r) = many_ifaces_ratio(runs) {
        println!(
            "  {:<32} {r:>12.2}x the rate with 40 names (target >= 0.25x: interning stays linear)",
            "40,000 interface names"
        );
    }
    match f.lens_rate {
        Some(r) => println!(
            "  {:<32} {r:>12.0} frames/s (the diagnose peer, 1/4 log)",
            "canopen-lens"
        ),
        None => println!("  canopen-lens not found (scripts/install-test-deps.sh) - no diagnose peer figure"),
    }
}
