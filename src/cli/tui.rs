//! `cotui open FILE` and `cotui replay FILE`: the interactive analyzer on a log.

use super::host::HostArgs;
use crate::analysis::trace::Trace;
use crate::command::ExitCode;
use crate::output::busload::Bitrate;
use crate::tui::app::{App, SourceInfo, SourceKind};
use crate::tui::hosted::Hosted;
use crate::tui::keymap::{self, Keymap, KeymapError};
use crate::tui::source;
use clap::Args;
use std::path::PathBuf;

/// Options shared by every interactive source.
#[derive(Args, Debug, Clone)]
pub struct UiArgs {
    /// Key bindings: `default`, `vim` or a JSON file; the user's keymap.json in the config
    /// directory then overrides key by key.
    #[arg(long, value_name = "NAME|FILE", default_value = "default")]
    pub keymap: String,
    /// Nominal bus bit rate for the bus load figure, in bit/s (500000, 500k, 1M); without
    /// it 500 kbit/s is assumed, and the Stats pane says so.
    #[arg(long, value_parser = bitrate_arg)]
    pub bitrate: Option<u64>,
    /// Initial filter (see the filter language in `?`).
    #[arg(long)]
    pub filter: Option<String>,
    /// Bind a device profile to a node: NODE=NAME (a name in decoders/ or a JSON path).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
    /// The configuration a node's boots should write: NODE=FILE.dcf, compared in the boot
    /// stories (`B`) as `diagnose --expect` compares it (also `:expect` in the palette).
    #[arg(long = "expect", value_name = "NODE=FILE")]
    pub expect: Vec<String>,
}

/// The nominal bit rates `--bitrate` takes: CAN's arbitration rate is at most 1 Mbit/s
/// (ISO 11898-1); below 1 kbit/s no controller runs.
pub const BITRATES: std::ops::RangeInclusive<u64> = 1_000..=1_000_000;

/// Parses `--bitrate` for clap: bit/s, with an optional `k` or `M` (500k, 1M); anything
/// outside [`BITRATES`] (0 included) is a usage error.
pub fn bitrate_arg(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (digits, scale) = match t.strip_suffix(['k', 'K']) {
        Some(d) => (d, 1_000),
        None => t.strip_suffix('M').map_or((t, 1), |d| (d, 1_000_000)),
    };
    let bad = || {
        format!(
            "`{text}` is not a CAN bit rate: give the nominal rate in bit/s, {} to {} (e.g. 500000 or 500k)",
            BITRATES.start(),
            BITRATES.end()
        )
    };
    let n: u64 = digits.parse().map_err(|_| bad())?;
    n.checked_mul(scale).filter(|r| BITRATES.contains(r)).ok_or_else(bad)
}

/// Arguments of `cotui open`.
#[derive(Args, Debug)]
pub struct OpenArgs {
    /// Log files (candump -l/-L, candump screen output, Vector ASC, PEAK TRC, python-can CSV,
    /// BLF). Several are merged by time into one capture; an interface name in several files
    /// is the same bus unless --iface-per-file.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// With several files: each file's interfaces are its own buses, named FILE:IFACE.
    #[arg(long)]
    pub iface_per_file: bool,
    #[command(flatten)]
    pub input: super::input::InputArgs,
    #[command(flatten)]
    pub ui: UiArgs,
}

/// Arguments of `cotui replay`.
#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// Log file (candump -l/-L, candump screen output, Vector ASC, PEAK TRC, python-can CSV).
    pub file: PathBuf,
    #[command(flatten)]
    pub input: super::input::InputArgs,
    /// Speed factor (2 = twice as fast; 0 = as fast as possible).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    #[command(flatten)]
    pub ui: UiArgs,
}

/// Arguments of `cotui live`.
#[derive(Args, Debug)]
pub struct LiveArgs {
    /// SocketCAN interfaces (e.g. can0, vcan0), captured together in one session: each
    /// bus's load and state on the status line; palette commands go to the first. `demo`
    /// and `demo2` are two independent simulated buses; socketcand://HOST:PORT/CHANNEL a bus
    /// on another machine (`cotui serve`).
    #[arg(required = true, value_name = "IFACE")]
    pub iface: Vec<String>,
    /// Never send: the bus is opened without a send path.
    #[arg(long)]
    pub listen_only: bool,
    /// A transmit list (the JSON of `send --list`) for the Transmit pane (9): its enabled
    /// entries are sent from the start; a bad entry is shown with its line, the rest works.
    #[arg(long, value_name = "FILE")]
    pub transmit: Option<PathBuf>,
    #[command(flatten)]
    pub host: HostArgs,
    #[command(flatten)]
    pub ui: UiArgs,
}

/// Arguments of `cotui demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Never send: watch the simulated drives only.
    #[arg(long)]
    pub listen_only: bool,
    /// A transmit list (the JSON of `send --list`) for the Transmit pane (9): its enabled
    /// entries are sent from the start; a bad entry is shown with its line, the rest works.
    #[arg(long, value_name = "FILE")]
    pub transmit: Option<PathBuf>,
    /// A simulated drive: NODE=MODEL[@SERIAL], MODEL one of aimotor, syntron-ds,
    /// dexmart-dev, aqmd2405, servo; NODE `ff` for a drive without node-ID (LSS only).
    /// Repeatable. Default: 2=aimotor 3=syntron-ds.
    #[arg(long = "node", value_name = "NODE=MODEL[@SERIAL]")]
    pub nodes: Vec<String>,
    #[command(flatten)]
    pub host: HostArgs,
    #[command(flatten)]
    pub ui: UiArgs,
}

/// The user's keymap file: `$XDG_CONFIG_HOME/cotui/keymap.json` or `~/.config/cotui/keymap.json`.
pub fn user_keymap_path() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
    Some(base.join("cotui").join("keymap.json"))
}

/// A keymap file's text, read with the dictionary files' size cap; `None` when there is no
/// such file. The error is the line cotui prints.
fn read_text(path: &std::path::Path) -> Result<Option<String>, String> {
    let name = path.display().to_string();
    if path.is_dir() {
        return Err(format!("keymap: {name}: is a directory, not a keymap file"));
    }
    match crate::files::read_capped(path) {
        Ok(bytes) => keymap::utf8_text(&name, bytes)
            .map(Some)
            .map_err(|e| format!("keymap: {e}")),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("keymap: {name}: {e}")),
    }
}

/// Loads the keymap named by `--keymap` plus the user's overrides (a user keymap that
/// cannot be read is an error, not ignored).
pub fn load_keymap(choice: &str) -> Result<Keymap, String> {
    let file_text;
    let base: (&str, &str) = match choice {
        "default" => ("default", keymap::DEFAULT),
        "vim" => ("vim", keymap::VIM),
        path => {
            file_text = read_text(std::path::Path::new(path))?
                .ok_or_else(|| format!("--keymap {path}: no such file (or use `default`, `vim`)"))?;
            (path, &file_text)
        }
    };
    let user = match user_keymap_path() {
        Some(p) => read_text(&p)?.map(|t| (p.display().to_string(), t)),
        None => None,
    };
    let overrides: Vec<(&str, &str)> = user.iter().map(|(n, t)| (n.as_str(), t.as_str())).collect();
    Keymap::load(base, &overrides).map_err(|e: KeymapError| format!("keymap: {e}"))
}

/// How the app gets its frames.
enum Feeding {
    /// A log task with an optional control line.
    Log(source::Feeds),
    /// Live buses (interfaces, listen-only) that also run commands and the hosted servers
    /// (on the first).
    Live(Vec<String>, bool, Hosted),
    /// The demo bus with these simulated drives (listen-only), hosting these servers.
    Demo(crate::sim::Simulation, bool, Hosted),
}

fn start(ui: &UiArgs, name: &str, kind: SourceKind, feed: Feeding, transmit: Option<&std::path::Path>) -> ExitCode {
    let keymap = match load_keymap(&ui.keymap) {
        Ok(k) => k,
        Err(e) => {
            eprintln!("cotui: {e}");
            return ExitCode::Usage;
        }
    };
    let bindings = match &feed {
        Feeding::Demo(sim, ..) => super::bind::bindings_for_demo(sim, &ui.profiles, &ui.eds),
        Feeding::Live(ifaces, ..) => super::bind::bindings_on(&ifaces[0], &ui.profiles, &ui.eds),
        Feeding::Log(_) => super::bind::bindings_on(name, &ui.profiles, &ui.eds),
    };
    let bindings = match bindings {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cotui: {e}");
            return ExitCode::Usage;
        }
    };
    let decoder = crate::decode::Decoder::from_bindings(&bindings);
    let open_file = matches!(kind, SourceKind::Open) && std::path::Path::new(name).is_file();
    let bitrate = match &feed {
        Feeding::Log(_) => Bitrate::given_or_assumed(ui.bitrate),
        Feeding::Live(ifaces, ..) => live_bitrate(ui.bitrate, ifaces),
        Feeding::Demo(..) => live_bitrate(ui.bitrate, &[crate::connect::DEMO.to_string()]),
    };
    let mut trace = Trace::new(decoder, bitrate);
    let warnings = match crate::tui::expect::set(&mut trace, &ui.expect) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("cotui: --{e}");
            return ExitCode::Usage;
        }
    };
    let src = match feed {
        Feeding::Log((rx, ctl)) => SourceInfo::new(name, kind, rx, ctl),
        Feeding::Live(ifaces, listen_only, hosted) => {
            let (rx, req) = crate::tui::live::start(&ifaces, listen_only, bindings.clone(), None, hosted);
            SourceInfo::live(name, kind, rx, req)
        }
        Feeding::Demo(sim, listen_only, hosted) => {
            let demo = [crate::connect::DEMO.to_string()];
            let (rx, req) = crate::tui::live::start(&demo, listen_only, bindings.clone(), Some(sim), hosted);
            SourceInfo::live(name, kind, rx, req)
        }
    };
    let mut app = App::new(trace, keymap, src);
    for w in warnings {
        app.screen_mut()
            .log(crate::tui::messages::Level::Warn, &format!("--expect: {w}"));
    }
    app.set_bindings(bindings);
    // `cotui open FILE`: the bookmarks are kept beside the log (README, "Bookmarks").
    if open_file {
        app.screen_mut().keep_bookmarks(std::path::Path::new(name));
    }
    if let Some(path) = transmit
        && let Err(e) = app.load_transmit(path)
    {
        eprintln!("cotui: {e}");
        return ExitCode::Usage;
    }
    if let Some(f) = &ui.filter {
        app.set_filter(f);
        if let Some(m) = app.screen_mut().take_message() {
            eprintln!("cotui: --filter: {m}");
            return ExitCode::Usage;
        }
    }
    match crate::tui::term::run(app) {
        Ok(()) => ExitCode::Ok,
        Err(e) => {
            eprintln!("cotui: {e}");
            ExitCode::Unavailable
        }
    }
}

/// The bit rate of a live session on `ifaces` (see [`Bitrate::of_live`]): each interface is
/// asked for its configured rate.
fn live_bitrate(option: Option<u64>, ifaces: &[String]) -> Bitrate {
    let rates: Vec<(&str, Result<u64, String>)> = ifaces
        .iter()
        .map(|i| (i.as_str(), crate::connect::configured_bitrate(i)))
        .collect();
    Bitrate::of_live(option, &rates)
}

fn check_file(path: &std::path::Path) -> Result<(), ExitCode> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => Ok(()),
        Ok(_) => {
            eprintln!("cotui: {}: not a file", path.display());
            Err(ExitCode::Unavailable)
        }
        Err(e) => {
            eprintln!("cotui: {}: {e}", path.display());
            Err(ExitCode::Unavailable)
        }
    }
}

/// Runs `cotui open`.
pub fn run_open(args: &OpenArgs) -> ExitCode {
    for f in &args.files {
        if let Err(code) = check_file(f) {
            return code;
        }
    }
    if let Some(twice) = super::input::repeated(&args.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>())
    {
        eprintln!("cotui open: {twice} is given twice");
        return ExitCode::Usage;
    }
    let (name, rx) = match args.files.as_slice() {
        [one] => (
            one.display().to_string(),
            source::open(one.clone(), args.input.format()),
        ),
        several => match super::open_logs::open(several, args.iface_per_file, args.input.format()) {
            Some(feed) => feed,
            None => return ExitCode::Unavailable,
        },
    };
    start(&args.ui, &name, SourceKind::Open, Feeding::Log((rx, None)), None)
}

/// `x` as typed when it is short, else in scientific notation (`1e-300`, not 300 digits).
fn short_number(x: f64) -> String {
    let plain = x.to_string();
    if plain.len() <= 12 { plain } else { format!("{x:e}") }
}

/// Runs `cotui replay`.
pub fn run_replay(args: &ReplayArgs) -> ExitCode {
    if let Err(code) = check_file(&args.file) {
        return code;
    }
    if !source::valid_speed(args.speed) {
        eprintln!(
            "cotui replay: --speed {} is out of range: 0 (as fast as possible) or 0.01 to 1000",
            short_number(args.speed)
        );
        return ExitCode::Usage;
    }
    let name = args.file.display().to_string();
    let (rx, ctl) = source::replay(args.file.clone(), args.speed, args.input.format());
    start(
        &args.ui,
        &name,
        SourceKind::Replay { speed: args.speed },
        Feeding::Log((rx, Some(ctl))),
        None,
    )
}

/// Runs `cotui live IFACE...`.
pub fn run_live(args: &LiveArgs) -> ExitCode {
    if let Some(twice) = super::input::repeated(&args.iface) {
        eprintln!("cotui live: {twice} is given twice: name each interface once");
        return ExitCode::Usage;
    }
    let kind = SourceKind::Live {
        listen_only: args.listen_only,
    };
    let hosted = match args.host.bind(&args.iface[0], args.listen_only) {
        Ok(h) => h,
        Err(e) => {
            eprintln!("cotui live: {e}");
            return ExitCode::Usage;
        }
    };
    let feed = Feeding::Live(args.iface.clone(), args.listen_only, hosted);
    start(&args.ui, &args.iface.join(" "), kind, feed, args.transmit.as_deref())
}

/// Runs `cotui demo`.
pub fn run_demo(args: &DemoArgs) -> ExitCode {
    let kind = SourceKind::Demo {
        listen_only: args.listen_only,
    };
    let drives = match crate::sim::spec::drives(&args.nodes, &crate::sim::DEMO_NODES) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui demo: {e}");
            return ExitCode::Usage;
        }
    };
    let hosted = match args.host.bind(crate::connect::DEMO, args.listen_only) {
        Ok(h) => h,
        Err(e) => {
            eprintln!("cotui demo: {e}");
            return ExitCode::Usage;
        }
    };
    let feed = Feeding::Demo(crate::sim::Simulation::demo_with(drives), args.listen_only, hosted);
    start(&args.ui, crate::connect::DEMO, kind, feed, args.transmit.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bitrate_takes_bits_per_second_with_k_and_m() {
        assert_eq!(bitrate_arg("500000"), Ok(500_000));
        assert_eq!(bitrate_arg("125k"), Ok(125_000));
        assert_eq!(bitrate_arg("1M"), Ok(1_000_000));
        assert_eq!(bitrate_arg("1000"), Ok(1_000));
    }

    #[test]
    fn bitrate_zero_negative_and_absurd_are_usage_errors() {
        for bad in [
            "0",
            "-500000",
            "999",
            "2M",
            "1000001",
            "fast",
            "",
            "18446744073709551615k",
        ] {
            let e = bitrate_arg(bad).unwrap_err();
            assert!(
                e.contains("is not a CAN bit rate") && e.contains("1000 to 1000000"),
                "{bad}: {e}"
            );
        }
    }
}
