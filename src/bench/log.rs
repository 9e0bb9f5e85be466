//! The generated bench log: synthetic commissioning traffic written as candump `-l`.

use crate::log::writer::LogWriter;
use crate::sim::synth::Traffic;
use std::io::Write;
use std::path::Path;

/// One garbage line (tool chatter the decoder must skip) every this many frames.
const GARBAGE_EVERY: u64 = 5_000;

/// Writes a candump `-l` log of `frames` synthetic frames to `path`.
pub fn write_log(path: &Path, frames: u64) -> std::io::Result<()> {
    write_frames(path, frames, None)
}

/// Writes the bench log: `frames` synthetic frames with a garbage line (a tool's
/// message, as in logs captured by hand) every [`GARBAGE_EVERY`] frames.
pub fn write_bench_log(path: &Path, frames: u64) -> std::io::Result<()> {
    write_frames(path, frames, Some(GARBAGE_EVERY))
}

/// Writes `frames` synthetic frames spread round-robin over `ifaces` distinct interface
/// names (`can0`, `can1`, ...): the interning of names must stay linear.
pub fn write_many_iface_log(path: &Path, frames: u64, ifaces: u32) -> std::io::Result<()> {
    let file = std::fs::File::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, file);
    let mut writer = LogWriter::new();
    let mut line = String::with_capacity(1 << 16);
    for (i, frame) in Traffic::new(frames, 1_700_000_000_000_000_000).enumerate() {
        writer.write_line(&mut line, &frame, &format!("can{}", i as u32 % ifaces.max(1)));
        if line.len() > 1 << 15 {
            out.write_all(line.as_bytes())?;
            line.clear();
        }
    }
    out.write_all(line.as_bytes())?;
    out.flush()
}

/// About how many bytes the logs of `frames` frames take per frame (a sample of the
/// synthetic traffic as written, on interface `can0`; a longer name adds its length).
pub fn bytes_per_frame() -> f64 {
    const SAMPLE: u64 = 10_000;
    let mut writer = LogWriter::new();
    let mut line = String::new();
    for frame in Traffic::new(SAMPLE, 1_700_000_000_000_000_000) {
        writer.write_line(&mut line, &frame, "can0");
    }
    line.len() as f64 / SAMPLE as f64
}

fn write_frames(path: &Path, frames: u64, garbage_every: Option<u64>) -> std::io::Result<()> {
    let file = std::fs::File::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, file);
    let mut writer = LogWriter::new();
    let mut line = String::with_capacity(1 << 16);
    for (i, frame) in Traffic::new(frames, 1_700_000_000_000_000_000).enumerate() {
        if garbage_every.is_some_and(|g| i as u64 % g == g - 1) {
            line.push_str(GARBAGE[i / 5_000 % GARBAGE.len()]);
        }
        writer.write_line(&mut line, &frame, "can0");
        if line.len() > 1 << 15 {
            out.write_all(line.as_bytes())?;
            line.clear();
        }
    }
    out.write_all(line.as_bytes())?;
    out.flush()
}

/// Lines found in hand-captured logs that are not frames (log2asc skips them too).
const GARBAGE: [&str; 3] = [
    "candump: interface can0 down\n",
    "# restarted capture after bus-off\n",
    "read: Network is down\n",
];
