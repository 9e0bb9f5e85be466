//! The arguments of `cotui decode` and its output formats.

use clap::{Args, ValueEnum};

/// Output formats of `cotui decode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// candump-like lines with the decoded label.
    Text,
    /// One JSON object per frame (see README, "JSONL contract").
    Jsonl,
    /// A pcapng capture for Wireshark (binary: with -o FILE or a redirected stdout).
    // `run` hands it to `decode_out` before decoding, so the matches below that pair it
    // with `Jsonl` never see it.
    Pcapng,
    /// A Vector BLF log for CANalyzer/CANoe and python-can (binary: with -o FILE or a
    /// redirected stdout; the header's totals are filled in only in a file).
    // `run` hands it to `decode_out` before decoding, as pcapng.
    Blf,
    /// Two Parquet tables, frames and decoded values (with -o DIR or -o NAME.parquet;
    /// see README, "Parquet tables").
    // `run` hands it to `decode_parquet` before decoding.
    Parquet,
    /// A Vector ASC log (frames only).
    // `run` hands it (and Trc) to `decode_out` before decoding.
    Asc,
    /// A PEAK TRC 2.1 log (frames only).
    Trc,
}

/// Arguments of `cotui decode`.
#[derive(Args, Debug)]
pub struct DecodeArgs {
    /// Log files (candump -l/-L, candump screen output, Vector ASC, PEAK TRC, python-can
    /// CSV); `-` reads stdin. Several are merged by time into one capture; an interface
    /// name in several files is the same bus (one bus's log split in parts) unless
    /// --iface-per-file.
    #[arg(required = true)]
    pub files: Vec<String>,
    /// With several files: each file's interfaces are its own buses, named FILE:IFACE
    /// (two buses recorded apart, both as can0, stay apart).
    #[arg(long)]
    pub iface_per_file: bool,
    #[command(flatten)]
    pub input: super::input::InputArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: OutputFormat,
    /// Print reassembled SDO transactions instead of frames.
    #[arg(long)]
    pub transactions: bool,
    /// Print per-node and per-kind totals only.
    #[arg(long, conflicts_with = "transactions")]
    pub summary: bool,
    /// Bus bit rate for the `--summary` bus load, in bit/s (500000, 500k, 1M); without it
    /// 500 kbit/s is assumed, and the summary says so.
    #[arg(long, value_parser = super::tui::bitrate_arg, value_name = "R")]
    pub bitrate: Option<u64>,
    /// Print bus events instead of frames: boot-up, NMT state change, heartbeat lost/back,
    /// heartbeat period (0x1017), EMCY, SDO abort, controller state (error frames).
    #[arg(long, conflicts_with_all = ["transactions", "summary"])]
    pub events: bool,
    /// Print one record per SYNC cycle instead of frames: its synchronous TPDOs with their
    /// time after the SYNC, the window 0x1007 and the TPDOs after it (late); text ends
    /// with a summary (cycles, mean and longest period, the slowest cycle, late TPDOs).
    #[arg(long, conflicts_with_all = ["transactions", "summary", "events", "filter", "trigger"])]
    pub sync_cycles: bool,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
    /// Only frames (or with --transactions, SDO transfers; with --summary, the totals of
    /// frames) matching EXPR, in the TUI's filter language (docs/TUI.md, "Filter and search").
    #[arg(long, value_name = "EXPR")]
    pub filter: Option<String>,
    /// Write to FILE instead of stdout (`-` is stdout); with --trigger, the directory of
    /// the window files.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<String>,
    /// Capture windows around each hit of EXPR (a filter, `hb lost`, `bootup`, `bus-off`,
    /// `error-passive`, `incident KIND`, or `A then B within DUR`): one file per window in
    /// -o DIR (candump -l, or --format pcapng|asc|trc|blf) with a JSON sidecar; with
    /// --format jsonl and no -o, one JSON line per window (README, "Capture triggers").
    #[arg(long, value_name = "EXPR")]
    pub trigger: Option<String>,
    /// With --trigger: keep DUR before each hit (`30s`, `500ms`; a bare number is ms).
    #[arg(long, value_name = "DUR", default_value = "10s", value_parser = crate::command::words::ms_or_zero_arg, requires = "trigger")]
    pub pre: u64,
    /// With --trigger: keep DUR after each hit (hits inside a window extend it).
    #[arg(long, value_name = "DUR", default_value = "10s", value_parser = crate::command::words::ms_or_zero_arg, requires = "trigger")]
    pub post: u64,
}
