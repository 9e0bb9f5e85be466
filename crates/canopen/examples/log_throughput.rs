//! Measures how fast [`canopen::log::LogReader`] reads a typical classic candump log held in
//! memory: `cargo run --release --example log_throughput [lines]`.
//! With a second argument `generate-only` it stops before parsing (to subtract the setup
//! from `perf stat` counts).

use std::time::Instant;

use canopen::frame::{Frame, Interfaces};
use canopen::log::writer::LogWriter;
use canopen::log::{Format, LogReader, Outcome, candump};

fn main() {
    let lines: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2_000_000);
    let mut text = String::with_capacity(lines * 48);
    let mut w = LogWriter::new();
    for i in 0..lines {
        let len = [8, 2, 4, 8, 0, 1][i % 6];
        let bytes: Vec<u8> = (0..len).map(|k| (i as u8).wrapping_mul(31).wrapping_add(k)).collect();
        let mut f = Frame::classic(0x180 + (i % 0x100) as u32, &bytes);
        f.ts_ns = 1_700_000_000_000_000_000 + i as u64 * 137_000;
        w.write_line(&mut text, &f, "can0");
    }
    if std::env::args().nth(2).as_deref() == Some("generate-only") {
        println!("generated {} bytes", text.len());
        return;
    }
    // The parser alone on the same lines, fastest of 5 passes over the first 20 000.
    let sample: Vec<&[u8]> = text.as_bytes().split_inclusive(|&b| b == b'\n').take(20_000).collect();
    let mut parser = candump::Parser::new();
    let mut ifaces = Interfaces::default();
    let mut frame = Frame::default();
    let mut parser_best = f64::MAX;
    for _ in 0..5 {
        let t = Instant::now();
        for line in &sample {
            let skipped = parser.parse_into(line, &mut ifaces, &mut frame).expect("valid line");
            assert!(skipped.is_none());
        }
        parser_best = parser_best.min(t.elapsed().as_nanos() as f64 / sample.len() as f64);
    }
    println!("parser alone: {parser_best:.1} ns/line");
    let cpu_start = cpu_seconds();
    let start = Instant::now();
    let mut reader = LogReader::with_format(text.as_bytes(), Format::Candump);
    let mut checksum = 0u64;
    // On a shared machine the fastest batch is the best estimate of the uncontended cost.
    let batch = 20_000;
    let mut best = f64::MAX;
    let mut batch_start = Instant::now();
    while let Some((n, outcome)) = reader.next_line().expect("in-memory read") {
        if let Outcome::Frame(f) = outcome {
            checksum = checksum.wrapping_add(f.id as u64 + f.data[0] as u64);
        }
        if n % batch == 0 {
            best = best.min(batch_start.elapsed().as_nanos() as f64 / batch as f64);
            batch_start = Instant::now();
        }
    }
    let elapsed = start.elapsed();
    let cpu = cpu_seconds().map(|end| end - cpu_start.unwrap_or(end));
    let c = reader.counts();
    println!(
        "{} lines ({} bytes) in {:.3} s: {:.1} ns/line, {:.1} M lines/s (frames {}, warnings {}, checksum {checksum})",
        lines,
        text.len(),
        elapsed.as_secs_f64(),
        elapsed.as_nanos() as f64 / lines as f64,
        lines as f64 / elapsed.as_secs_f64() / 1e6,
        c.frames,
        c.warnings,
    );
    println!("fastest batch of {batch} lines: {best:.1} ns/line");
    // The machine may be shared: CPU time tells the parser's own cost.
    if let Some(cpu) = cpu {
        println!("CPU time {cpu:.3} s: {:.1} ns/line", cpu * 1e9 / lines as f64);
    }
}

/// User + system CPU seconds of this process from `/proc/self/stat` (Linux, 100 Hz ticks).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let after = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks: u64 = fields.get(11)?.parse::<u64>().ok()? + fields.get(12)?.parse::<u64>().ok()?;
    Some(ticks as f64 / 100.0)
}
