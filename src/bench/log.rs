//! The generated bench log: synthetic commissioning traffic written as candump `-l`.

use crate::frame::{Flags, Frame};
use crate::log::export::{AscWriter, TrcWriter};
use crate::log::writer::LogWriter;
use crate::output::blf::BlfWriter;
use crate::sim::synth::Traffic;
use std::io::Write;
use std::path::Path;

/// When the bench frames begin (ns since the epoch).
const START_NS: u64 = 1_700_000_000_000_000_000;

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
    for (i, frame) in Traffic::new(frames, START_NS).enumerate() {
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
    for frame in Traffic::new(SAMPLE, START_NS) {
        writer.write_line(&mut line, &frame, "can0");
    }
    line.len() as f64 / SAMPLE as f64
}

fn write_frames(path: &Path, frames: u64, garbage_every: Option<u64>) -> std::io::Result<()> {
    let file = std::fs::File::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, file);
    let mut writer = LogWriter::new();
    let mut line = String::with_capacity(1 << 16);
    for (i, frame) in Traffic::new(frames, START_NS).enumerate() {
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

/// The input formats `cotui bench` times besides candump, with their file names.
pub const INPUT_FORMATS: [(&str, &str); 8] = [
    ("screen", "bench-quarter.screen.txt"),
    ("asc", "bench-quarter.asc"),
    ("trc", "bench-quarter.trc"),
    ("csv", "bench-quarter.csv"),
    ("peak-csv", "bench-quarter.peak.csv"),
    ("savvycan", "bench-quarter.savvycan.csv"),
    ("mf4", "bench-quarter.mf4"),
    ("blf", "bench-quarter.blf"),
];

/// Writes the same synthetic frames as [`write_log`] in input format `format` (one of
/// [`INPUT_FORMATS`]): candump screen output (`-ta`), Vector ASC, PEAK TRC 2.1,
/// python-can CSV, PEAK CSV, SavvyCAN CSV, ASAM MDF4 or Vector BLF (by cotui's own BLF
/// writer).
pub fn write_format_log(path: &Path, frames: u64, format: &str) -> std::io::Result<()> {
    match format {
        "mf4" => return super::mf4::write_mf4_log(path, frames),
        "blf" => return write_blf_log(path, frames),
        _ => {}
    }
    let file = std::fs::File::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, file);
    let (mut asc, mut trc) = (AscWriter::new(), TrcWriter::new());
    let mut line = String::with_capacity(1 << 16);
    line.push_str(match format {
        "csv" => "timestamp,arbitration_id,extended,remote,error,dlc,data\n",
        "peak-csv" => PEAK_CSV_HEADER,
        "savvycan" => "Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8\n",
        _ => "",
    });
    for (i, frame) in Traffic::new(frames, START_NS).enumerate() {
        match format {
            "asc" => asc.write_line(&mut line, &frame, "can0"),
            "trc" => trc.write_line(&mut line, &frame, "can0"),
            "csv" => csv_line(&mut line, &frame),
            "peak-csv" => peak_csv_line(&mut line, i as u64 + 1, &frame, START_NS),
            "savvycan" => savvycan_line(&mut line, &frame),
            _ => screen_line(&mut line, &frame),
        }
        if line.len() > 1 << 15 {
            out.write_all(line.as_bytes())?;
            line.clear();
        }
    }
    asc.finish(&mut line);
    out.write_all(line.as_bytes())?;
    out.flush()
}

/// Writes the synthetic frames as a Vector BLF file with cotui's BLF writer, the final
/// header (with the totals) written over the first one.
fn write_blf_log(path: &Path, frames: u64) -> std::io::Result<()> {
    use std::io::{Seek, SeekFrom};
    let mut file = std::fs::File::create(path)?;
    let mut blf = BlfWriter::new(std::io::BufWriter::with_capacity(1 << 20, &file));
    for frame in Traffic::new(frames, START_NS) {
        blf.write_frame("can0", &frame)?;
    }
    let header = blf.finish()?;
    drop(blf);
    file.seek(SeekFrom::Start(0))?;
    file.write_all(&header)
}

/// candump `-ta` screen output: ` (1700000000.000100)  can0  181   [2]  11 22`.
fn screen_line(out: &mut String, f: &Frame) {
    use std::fmt::Write as _;
    let (s, us) = (f.ts_ns / 1_000_000_000, f.ts_ns / 1000 % 1_000_000);
    let id = if f.flags.has(Flags::EXT) {
        format!("{:08X}", f.id)
    } else {
        format!("{:03X}", f.id)
    };
    let _ = write!(out, " ({s}.{us:06})  can0  {id}   [{}] ", f.len);
    if f.flags.has(Flags::RTR) {
        out.push_str(" remote request");
    } else {
        for b in f.payload() {
            let _ = write!(out, " {b:02X}");
        }
    }
    out.push('\n');
}

/// The header of the bench's PEAK CSV: the start time [`START_NS`] as PEAK writes it (days
/// since 1899-12-30, 12 decimals) and the column names.
const PEAK_CSV_HEADER: &str = ";$FILEVERSION=2.1\n;$STARTTIME=45244.925925925926\nNumber,Time,Bus,Direction,Type,ID,Reserved,Length,D0,D1,D2,D3,D4,D5,D6,D7\n";

/// A PEAK CSV row of a classic data frame, its time in milliseconds after `start_ns`:
/// `2,0.100,1,Rx,DT,0181,-,3,37,02,03,,,,,`.
fn peak_csv_line(out: &mut String, number: u64, f: &Frame, start_ns: u64) {
    use std::fmt::Write as _;
    let since = f.ts_ns - start_ns;
    let (ms, ns) = (since / 1_000_000, since % 1_000_000);
    let _ = write!(out, "{number},{ms}.{:03},1,Rx,DT,{:04X},-,{}", ns / 1000, f.id, f.len);
    for k in 0..8 {
        match f.payload().get(k) {
            Some(b) => write!(out, ",{b:02X}"),
            None => write!(out, ","),
        }
        .ok();
    }
    out.push('\n');
}

/// A SavvyCAN CSV row: `1700000000000100,00000181,false,Rx,0,3,37,02,03,`.
fn savvycan_line(out: &mut String, f: &Frame) {
    use std::fmt::Write as _;
    let _ = write!(out, "{},{:08X},false,Rx,0,{},", f.ts_ns / 1000, f.id, f.len);
    for b in f.payload() {
        let _ = write!(out, "{b:02X},");
    }
    out.push('\n');
}

/// A python-can CSV row: `1700000000.0001,0x181,0,0,0,2,ESI=`.
fn csv_line(out: &mut String, f: &Frame) {
    use std::fmt::Write as _;
    const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let (s, us) = (f.ts_ns / 1_000_000_000, f.ts_ns / 1000 % 1_000_000);
    let flag = |b: u8| if f.flags.has(b) { '1' } else { '0' };
    let _ = write!(
        out,
        "{s}.{us:06},{:#x},{},{},{},{},",
        f.id,
        flag(Flags::EXT),
        flag(Flags::RTR),
        flag(Flags::ERR),
        f.len
    );
    let data = if f.flags.has(Flags::RTR) { &[][..] } else { f.payload() };
    for chunk in data.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (k, &b)| n | u32::from(b) << (16 - 8 * k));
        for k in 0..4 {
            out.push(if k <= chunk.len() {
                B64[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::Outcome;
    use crate::logio::reader::Reader;

    /// Each input format's bench log reads back to the frames of the candump one.
    #[test]
    fn every_input_format_holds_the_same_frames() {
        let dir = std::env::temp_dir().join(format!("cotui-bench-formats-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let read = |path: &Path| -> Vec<(u64, u32, Vec<u8>)> {
            let file = std::fs::File::open(path).unwrap();
            let r = Reader::open_file(file, None, std::io::BufReader::new).unwrap();
            r.filter_map(|item| match item.unwrap() {
                (_, Outcome::Frame(f)) => Some((f.ts_ns / 1000, f.id, f.payload().to_vec())),
                (n, Outcome::Warning(w)) => panic!("{}:{n}: {w}", path.display()),
                _ => None,
            })
            .collect()
        };
        let candump = dir.join("bench.log");
        write_log(&candump, 500).unwrap();
        let want = read(&candump);
        assert_eq!(want.len(), 500);
        for (format, name) in INPUT_FORMATS {
            let path = dir.join(name);
            write_format_log(&path, 500, format).unwrap();
            // ASC times are absolute too: offsets from its `date` line.
            let got = read(&path);
            // TRC's $STARTTIME holds days to 12 decimals (86 ns): times agree within 1 µs.
            assert_eq!(got.len(), want.len(), "{format}");
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    g.0.abs_diff(w.0) <= 1 && (g.1, &g.2) == (w.1, &w.2),
                    "{format}: {g:?} vs {w:?}"
                );
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
