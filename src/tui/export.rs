//! Export of the trace view (the rows the filter in force shows) to a file: candump `-l`,
//! JSON lines (decoded, as `cotui decode --format jsonl`) or pcapng for Wireshark.

use crate::analysis::trace::Trace;
use crate::analysis::view::View;
use crate::log::writer::LogWriter;
use crate::output::jsonl;
use crate::output::pcapng::PcapngWriter;
use std::fs::OpenOptions;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// A format name that is not one of the export formats.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown export format `{0}`: use candump, jsonl or pcapng")]
pub struct UnknownFormat(pub String);

/// Why `export` failed; the text is what the status bar shows.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// `export --format` without a format.
    #[error("export: --format needs candump, jsonl or pcapng")]
    FormatMissing,
    /// `export --format` with an unknown format.
    #[error("export: {0}")]
    Format(#[from] UnknownFormat),
    /// `export` with an unknown option.
    #[error("export: unknown option `{0}`")]
    UnknownOption(String),
    /// `export` with more than one file.
    #[error("export: one FILE only (`{0}` is extra)")]
    ExtraFile(String),
    /// `export` without a file.
    #[error("export: usage `export FILE [--format candump|jsonl|pcapng] [--force]`")]
    Usage,
    /// `export plot` without a file.
    #[error("export: usage `export plot FILE.csv [--all] [--force]`")]
    PlotUsage,
    /// `export plot` with no signal in the Plot pane.
    #[error("export plot: no signal is plotted")]
    NothingPlotted,
    /// `export watch` without a file.
    #[error("export: usage `export watch FILE.csv [--force]`")]
    WatchUsage,
    /// `export watch` with nothing watched.
    #[error("export watch: nothing is watched (`watch NODE OBJ...` first)")]
    NothingWatched,
    /// The export file could not be written.
    #[error("export: {file}: {source}{hint}", hint = overwrite_hint(source))]
    Write { file: String, source: std::io::Error },
}

fn overwrite_hint(e: &std::io::Error) -> &'static str {
    if e.kind() == std::io::ErrorKind::AlreadyExists {
        " (add --force to overwrite)"
    } else {
        ""
    }
}

/// The formats the view exports to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportFormat {
    Candump,
    Jsonl,
    Pcapng,
}

impl ExportFormat {
    /// Parses `candump`, `jsonl` or `pcapng`.
    pub fn parse(word: &str) -> Result<ExportFormat, UnknownFormat> {
        match word {
            "candump" | "log" => Ok(ExportFormat::Candump),
            "jsonl" | "json" => Ok(ExportFormat::Jsonl),
            "pcapng" => Ok(ExportFormat::Pcapng),
            _ => Err(UnknownFormat(word.to_string())),
        }
    }
    /// The format a file name suggests: `.pcapng`, `.jsonl`/`.json`, else candump.
    pub fn of_path(path: &Path) -> ExportFormat {
        match path.extension().and_then(|e| e.to_str()) {
            Some("pcapng") => ExportFormat::Pcapng,
            Some("jsonl" | "json") => ExportFormat::Jsonl,
            _ => ExportFormat::Candump,
        }
    }
}

/// Creates the export file `path`: an existing file is refused unless `force` (then replaced).
pub(crate) fn create(path: &Path, force: bool) -> io::Result<std::fs::File> {
    if force {
        OpenOptions::new().write(true).create(true).truncate(true).open(path)
    } else {
        OpenOptions::new().write(true).create_new(true).open(path)
    }
}

/// Frames decoded per step when exporting JSON lines.
const CHUNK: usize = 4096;

/// Writes the rows of `view` to `path` (refusing an existing file unless `force`); returns
/// how many frames were written.
pub fn export(trace: &Trace, view: &View, path: &Path, format: ExportFormat, force: bool) -> io::Result<usize> {
    let file = create(path, force)?;
    let mut out = BufWriter::new(file);
    let rows = view.len(trace);
    let positions = (0..rows).map(|r| view.position(r));
    match format {
        ExportFormat::Candump => {
            let mut w = LogWriter::new();
            for pos in positions {
                let f = trace.store.frame(pos);
                w.write_io(&mut out, &f, trace.ifaces.name(f.iface))?;
            }
        }
        ExportFormat::Pcapng => {
            let mut w = PcapngWriter::new(&mut out)?;
            for pos in positions {
                let f = trace.store.frame(pos);
                w.write_frame(trace.ifaces.name(f.iface), &f)?;
            }
            w.flush()?;
        }
        ExportFormat::Jsonl => {
            let all: Vec<usize> = positions.collect();
            let mut walker = None;
            let mut buf = Vec::new();
            for chunk in all.chunks(CHUNK) {
                for (pos, d) in chunk.iter().zip(trace.decode_with(&mut walker, chunk)) {
                    let f = trace.store.frame(*pos);
                    jsonl::write_frame(&mut buf, *pos as u64 + 1, &f, &trace.ifaces, &d);
                }
                out.write_all(&buf)?;
                buf.clear();
            }
        }
    }
    out.flush()?;
    Ok(rows)
}

/// `export FILE [--format candump|jsonl|pcapng] [--force]` (the words after `export`):
/// writes the rows `view` shows; the text says what was written.
pub(crate) fn command(rest: &str, trace: &Trace, view: &View) -> Result<String, ExportError> {
    let (mut file, mut format, mut force) = (None, None, false);
    let mut words = rest.split_whitespace();
    while let Some(w) = words.next() {
        match w {
            "--force" => force = true,
            "--format" => {
                let f = words.next().ok_or(ExportError::FormatMissing)?;
                format = Some(ExportFormat::parse(f)?);
            }
            w if w.starts_with("--") => return Err(ExportError::UnknownOption(w.to_string())),
            w if file.is_none() => file = Some(w.to_string()),
            w => return Err(ExportError::ExtraFile(w.to_string())),
        }
    }
    let file = file.ok_or(ExportError::Usage)?;
    let path = Path::new(&file);
    let format = format.unwrap_or_else(|| ExportFormat::of_path(path));
    let scanned = view.progress(trace);
    let n = export(trace, view, path, format, force).map_err(|source| ExportError::Write {
        file: file.clone(),
        source,
    })?;
    Ok(format!(
        "exported {n} frames to {file} ({format:?}){}",
        if scanned < 100 {
            format!("; the filter had scanned {scanned}% of the trace")
        } else {
            String::new()
        }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::filter::Filter;
    use crate::log::{LogReader, Outcome};
    use crate::tui::panes::testutil::{app, frames};
    use std::time::Duration;

    #[test]
    fn the_filtered_view_goes_out_in_each_format() {
        let a = app();
        let dir = std::env::temp_dir().join(format!("cotui-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // All frames as candump: read back, they are the frames.
        let log = dir.join("all.log");
        assert_eq!(
            export(a.trace(), a.screen().view(), &log, ExportFormat::Candump, false).unwrap(),
            frames().len()
        );
        let back: Vec<_> = LogReader::new(io::BufReader::new(std::fs::File::open(&log).unwrap()))
            .unwrap()
            .filter_map(|r| match r.unwrap().1 {
                Outcome::Frame(f) => Some((f.id, f.payload().to_vec(), f.ts_ns / 1000)),
                _ => None,
            })
            .collect();
        let want: Vec<_> = frames()
            .iter()
            .map(|f| (f.id, f.payload().to_vec(), f.ts_ns / 1000))
            .collect();
        assert_eq!(back, want);
        // An existing file is refused unless forced.
        assert!(export(a.trace(), a.screen().view(), &log, ExportFormat::Candump, false).is_err());
        assert!(export(a.trace(), a.screen().view(), &log, ExportFormat::Candump, true).is_ok());
        // The heartbeats of node 2 only, decoded, as JSON lines.
        let mut view = View::new(Filter::parse("node 2 kind hb").unwrap());
        view.advance(a.trace(), Duration::from_secs(5));
        let jsonl = dir.join("hb.jsonl");
        let n = export(a.trace(), &view, &jsonl, ExportFormat::of_path(&jsonl), false).unwrap();
        let text = std::fs::read_to_string(&jsonl).unwrap();
        assert_eq!((n, text.lines().count()), (7, 7));
        for l in text.lines() {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            assert_eq!((v["kind"].as_str(), v["node"].as_u64()), (Some("heartbeat"), Some(2)));
        }
        // pcapng: a section header, one interface, one packet block per frame.
        let cap = dir.join("hb.pcapng");
        export(a.trace(), &view, &cap, ExportFormat::of_path(&cap), false).unwrap();
        let bytes = std::fs::read(&cap).unwrap();
        assert_eq!(&bytes[..4], &[0x0A, 0x0D, 0x0D, 0x0A]);
        std::fs::remove_dir_all(&dir).ok();
    }
}
