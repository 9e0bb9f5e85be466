//! The palette's built-in commands (those that are not commander lines): their names and
//! why they fail.

use super::palette::commander_words;

/// Names the palette completes.
pub const PALETTE_COMMANDS: &[&str] = &[
    "filter", "search", "goto", "time", "speed", "pause", "resume", "rewind", "loop", "plot", "export", "help",
    "messages", "quit", "jobs", "sim",
];

/// Why a built-in palette command (`goto`, `time`, `speed`, `plot`, `export`, ...) failed;
/// the text is what the status bar shows.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// `goto` without a frame number.
    #[error("goto: `{0}` is not a frame number")]
    NotAFrame(String),
    /// `time` without seconds.
    #[error("time: `{0}` is not seconds")]
    NotSeconds(String),
    /// `speed` without a factor.
    #[error("speed: `{0}` is not a factor from 0.01 to 1000 (0 = as fast as possible)")]
    NotAFactor(String),
    /// A replay command on a source that is not a replay.
    #[error("{0}: only a replay can do that")]
    NoReplay(&'static str),
    /// `speed` on a source that is not a replay.
    #[error("speed: only a replay has a speed")]
    NoSpeed,
    /// `plot` without a node and an object.
    #[error("plot: usage `plot NODE INDEX[:SUB]`, e.g. `plot 1 6064:00`")]
    PlotUsage,
    /// `plot` with a bad node-ID.
    #[error("plot: `{0}` is not a node-ID")]
    NotANode(String),
    /// `plot` with a bad index.
    #[error("plot: bad index `{0}`")]
    BadIndex(String),
    /// `plot` with a bad sub-index.
    #[error("plot: bad sub-index `{0}`")]
    BadSub(String),
    /// `plot` of an object with no numeric value seen.
    #[error("plot: no numeric values of node {node} 0x{index:04X}:{sub:02X} seen")]
    NoSeries { node: u8, index: u16, sub: u8 },
    /// `export --format` without a format.
    #[error("export: --format needs candump, jsonl or pcapng")]
    FormatMissing,
    /// `export --format` with an unknown format.
    #[error("export: {0}")]
    Format(#[from] super::export::UnknownFormat),
    /// `export` with an unknown option.
    #[error("export: unknown option `{0}`")]
    ExportOption(String),
    /// `export` with more than one file.
    #[error("export: one FILE only (`{0}` is extra)")]
    ExtraFile(String),
    /// `export` without a file.
    #[error("export: usage `export FILE [--format candump|jsonl|pcapng] [--force]`")]
    ExportUsage,
    /// The export file could not be written.
    #[error("export: {file}: {source}{hint}", hint = overwrite_hint(source))]
    Export { file: String, source: std::io::Error },
    /// A word that is no command.
    #[error("unknown command `{0}` (commands: {palette} {commander})", palette = PALETTE_COMMANDS.join(" "), commander = commander_words().join(" "))]
    Unknown(String),
}

/// What to add to an export error: how to overwrite an existing file.
fn overwrite_hint(e: &std::io::Error) -> &'static str {
    if e.kind() == std::io::ErrorKind::AlreadyExists {
        " (add --force to overwrite)"
    } else {
        ""
    }
}
