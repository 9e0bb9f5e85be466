//! The commander's command language, declared once. Each command (nmt, sdo read/write, lss,
//! drive, run, scan, record, stop, send, sync, pdo, dcf) is a clap declaration here: its words, flags, help text,
//! checks and completion. The command line parses [`Commander`] with its bus options in
//! front (`cotui sdo read IFACE 2 0x6041`, see `crate::cli`); the TUI palette parses the same
//! declaration with nothing in front ([`parse_command`]: `sdo read 2 0x6041`, split like a
//! shell line). So both accept the same lines and refuse the same ones with the same error:
//! unknown flags, extra words, missing words, bad numbers.

use super::cyclic::Schedule;
use super::dcf::DcfAction;
use super::grammar::parse_assignments;
pub(crate) use super::grammar::parse_type;
use super::grammar::{Command, DEFAULT_TIMEOUT_MS, SCAN_LISTEN_MS, SCAN_TIMEOUT_MS, parse_int, parse_node, run_spec};
use super::lss::{FASTSCAN_TIMEOUT_MS, LSS_TIMEOUT_MS, LSS_WORDS, LssAction, LssFlags};
use super::pdo::MapSpec;
use super::record::{Limits, LogFormat, WriteMode};
use super::spec::{CommandArgs, Declared};
use super::stop::{DEFAULT_LISTEN_MS, DEFAULT_RAMP_MS, StopOptions};
use crate::decode::pdo_config::PdoId;
use crate::frame::Frame;
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;
use clap::{Args, CommandFactory, Parser, Subcommand};
use std::sync::OnceLock;

/// Why a command line is not a command.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseError {
    /// A palette line with an unbalanced quote.
    #[error("unterminated quote")]
    Quote,
    /// An empty palette line.
    #[error("empty command; commands: {}", commander_words().join(", "))]
    Empty,
    /// The declaration refused the words: an unknown flag, an extra or missing word, a bad
    /// value. `message` is clap's error line (with its tips), `usage` the command's usage.
    #[error("{message}")]
    Rejected { message: String, usage: String },
    /// `--help`: the help text.
    #[error("{0}")]
    Help(String),
    /// Words the declaration accepts that do not make a command (e.g. a MODE after
    /// `drive N enable`, a parameter before the procedure).
    #[error("{0}")]
    Invalid(String),
}

impl From<clap::Error> for ParseError {
    fn from(e: clap::Error) -> Self {
        let text = e.render().to_string();
        if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
            return ParseError::Help(text.trim_end().to_string());
        }
        let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
        let first = lines.next().unwrap_or("");
        let mut message = first.strip_prefix("error: ").unwrap_or(first).to_string();
        let mut usage = String::new();
        for l in lines {
            if let Some(u) = l.strip_prefix("Usage: ") {
                usage = u.to_string();
            } else if l.starts_with("For more information") {
                break;
            } else if l.starts_with("tip: to pass") {
                // `-- --flag`: no line of ours takes a value that starts with `-`.
            } else if usage.is_empty() {
                // The arguments missing, the tips: part of the message.
                message.push_str(if l.starts_with("tip: ") { "; " } else { " " });
                message.push_str(l);
            }
        }
        ParseError::Rejected { message, usage }
    }
}

/// Nothing: what a palette line has where the command line has its bus options (IFACE,
/// `--listen-only`, `--json`) and dictionary options (`--profile`, `--eds`). The palette
/// runs on the session's bus with the session's dictionaries.
#[derive(Args, Clone, Debug, Default, PartialEq, Eq)]
#[group(skip)]
pub struct Session {}

/// A command's own arguments `A` after the options `B` every command takes where it is
/// parsed (the command line's IFACE and flags; nothing in the palette).
#[derive(Args, Clone, Debug)]
#[group(skip)]
pub struct On<B: Args, A: Args> {
    #[command(flatten)]
    pub bus: B,
    #[command(flatten)]
    pub args: A,
}

/// The commander commands. `B`: the options in front of every command (see [`Session`]),
/// `D`: the dictionary options of the commands that name objects (`sdo`, `run`).
#[derive(Subcommand, Clone, Debug)]
pub enum Commander<B: Args, D: Args> {
    /// Send an NMT command to a node (0 = all): start, stop, preop, reset-node, reset-comm.
    Nmt(On<B, super::nmt::NmtArgs>),
    /// Read or write an object by SDO.
    #[command(subcommand)]
    Sdo(super::object::SdoCommand<B, D>),
    /// CiA 402 drive: enable, disable, quick-stop, fault-reset, status, or mode MODE.
    Drive(On<B, super::drive::DriveArgs>),
    /// Run a profile's procedure step by step (NAME=VALUE parameters); without PROCEDURE (or
    /// with --list), list the node's procedures.
    Run(On<B, RunArgs<D>>),
    /// List the nodes on the bus with their identity.
    Scan(On<B, ScanArgs>),
    /// Record the bus to a candump -l log (or pcapng).
    Record(On<B, RecordArgs>),
    /// Emergency stop: quick stop, then disable voltage, on every CiA 402 drive found powered
    /// (or the nodes named); reads each statusword back. Exit 0 only when all are confirmed.
    Stop(On<B, StopArgs>),
    /// LSS master (CiA 305): switch, select, set-node, set-bitrate, activate-bitrate, store,
    /// inquire, identify, identify-unconfigured, fastscan, or assign N (fastscan + set-node).
    Lss(On<B, LssArgs>),
    /// Send a raw frame in candump's compact form (`601#4041600000000000`, `123#R`,
    /// `12345678#00`): once, --count N times, or --every MS (until stopped without --count).
    Send(On<B, super::send::SendArgs>),
    /// Produce SYNC every --period MS (COB-ID 0x080), with the CiA 301 counter 1..N when
    /// --counter N is given; until stopped without --count.
    Sync(On<B, super::sync::SyncArgs>),
    /// PDOs: `pdo 2` reads every PDO's configuration; `pdo 2 map tpdo1 0x6041 0x6064 --type
    /// sync:2` remaps one (CiA 301 sequence, read back); `pdo 2 send rpdo1 Controlword=0x0F
    /// "Target velocity=500" --every 10` sends an RPDO (mapped signals not given are sent as 0).
    Pdo(On<B, PdoArgs<D>>),
    /// A node's configuration as a CiA 306 DCF: save it, load it back (the values that
    /// differ, PDOs remapped), or show what differs.
    #[command(subcommand)]
    Dcf(DcfCommand<B, D>),
}

/// `dcf save`, `dcf load` and `dcf diff`.
#[derive(Subcommand, Clone, Debug)]
pub enum DcfCommand<B: Args, D: Args> {
    /// Read every readable object the node's dictionary knows and write a DCF: `dcf save 5 -o node5.dcf`.
    Save(On<B, DcfSaveArgs<D>>),
    /// Write the file's writable values that differ from the node's, PDO mappings by the CiA
    /// 301 sequence, communication objects last; read them back: `dcf load 5 node5.dcf --store`.
    Load(On<B, DcfLoadArgs<D>>),
    /// Show the objects whose values differ between the file and the node (exit status 6
    /// when any writable one does): `dcf diff 5 node5.dcf`.
    Diff(On<B, DcfDiffArgs<D>>),
}

/// `dcf save NODE -o FILE [--force] [--timeout MS]`.
#[derive(Args, Clone, Debug)]
pub struct DcfSaveArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The DCF to write. An existing file is refused unless --force.
    #[arg(short = 'o', long)]
    pub output: String,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// `dcf load NODE FILE [--store] [--dry-run] [--timeout MS]`.
#[derive(Args, Clone, Debug)]
pub struct DcfLoadArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The DCF to load.
    pub file: String,
    /// Then write "save" (0x65766173) to 0x1010:01 to store the configuration.
    #[arg(long)]
    pub store: bool,
    /// Read the node and print what would be written; write nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// `dcf diff NODE FILE [--timeout MS]`.
#[derive(Args, Clone, Debug)]
pub struct DcfDiffArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The DCF to compare with.
    pub file: String,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// `run NODE [PROCEDURE] [NAME=VALUE ...] [--list] [--dry-run] [--timeout MS]`.
#[derive(Args, Clone, Debug)]
pub struct RunArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The procedure (e.g. `pv`), then its parameters as NAME=VALUE; none: list the procedures.
    pub words: Vec<String>,
    /// List the node's procedures with their descriptions and parameters.
    #[arg(long)]
    pub list: bool,
    /// Print the steps and their frames without sending anything.
    #[arg(long)]
    pub dry_run: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// `scan [--listen MS] [--probe] [--timeout MS]`.
#[derive(Args, Clone, Debug)]
pub struct ScanArgs {
    /// How long to listen for heartbeats and boot-ups, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = SCAN_LISTEN_MS)]
    pub listen: u64,
    /// Also ask every node 1..127 for 0x1000 (finds nodes without heartbeat).
    #[arg(long)]
    pub probe: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = SCAN_TIMEOUT_MS)]
    pub timeout: u64,
}

/// `record -o FILE [--count N] [--duration MS] [--force | --append] [--format F]`.
#[derive(Args, Clone, Debug)]
pub struct RecordArgs {
    /// The log file to write (candump -l format; `-` for stdout). An existing file is
    /// refused unless --force or --append.
    #[arg(short = 'o', long)]
    pub output: String,
    /// Stop after this many frames.
    #[arg(long, value_parser = count_arg)]
    pub count: Option<u64>,
    /// Stop after this many ms (else at Ctrl-C, SIGTERM, SIGHUP or SIGQUIT).
    #[arg(long, value_parser = ms_arg)]
    pub duration: Option<u64>,
    /// Overwrite an existing output file.
    #[arg(long, conflicts_with = "append")]
    pub force: bool,
    /// Append to an existing output file.
    #[arg(long)]
    pub append: bool,
    /// The file format: candump (-l lines), pcapng (for Wireshark) or blf (Vector BLF, for
    /// CANalyzer/CANoe and python-can); the binary ones not to a terminal.
    #[arg(long, default_value = "candump", value_parser = TypedWords::new(&["candump", "pcapng", "blf"], LogFormat::parse))]
    pub format: LogFormat,
}

/// `stop [NODE ...] [--node N]... [--listen MS] [--ramp MS] [--timeout MS]`.
#[derive(Args, Clone, Debug)]
pub struct StopArgs {
    /// Stop these nodes. Without any, every CiA 402 drive found powered is stopped.
    #[arg(value_parser = node_arg)]
    pub nodes: Vec<u8>,
    /// Stop this node too (repeatable; the same as naming it).
    #[arg(long = "node", value_name = "N", value_parser = node_arg)]
    pub node_flags: Vec<u8>,
    /// How long to listen for nodes before reading their statuswords, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_LISTEN_MS)]
    pub listen: u64,
    /// How long a drive may take to finish its quick stop ramp before voltage is disabled, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_RAMP_MS)]
    pub ramp: u64,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

/// `lss ACTION [WORDS...] [--timeout MS] [--vendor V] [--product P] [--store]`.
#[derive(Args, Clone, Debug)]
pub struct LssArgs {
    /// The LSS service (its words follow).
    #[arg(value_parser = TypedWords::new(LSS_WORDS, LssAction::verb))]
    pub action: String,
    /// The action's words: `switch [global] config|wait`, `select VENDOR PRODUCT REVISION
    /// SERIAL`, `set-node N`, `set-bitrate KBIT`, `activate-bitrate DELAY_MS`, `inquire
    /// [vendor|product|revision|serial|node|all]`, `identify VENDOR PRODUCT REV_LO REV_HI
    /// SER_LO SER_HI`, `assign N`.
    pub words: Vec<String>,
    /// fastscan, assign: only a slave with this vendor-ID.
    #[arg(long, value_parser = u32_arg)]
    pub vendor: Option<u32>,
    /// fastscan, assign: only a slave with this product code.
    #[arg(long, value_parser = u32_arg)]
    pub product: Option<u32>,
    /// assign: also store the configuration.
    #[arg(long)]
    pub store: bool,
    /// How long to wait for each answer, in ms [default: 100; fastscan and assign: 30 per
    /// fastscan request].
    #[arg(long, value_parser = ms_arg)]
    pub timeout: Option<u64>,
}

impl LssArgs {
    fn command(&self) -> Result<Command, ParseError> {
        let flags = LssFlags {
            vendor: self.vendor,
            product: self.product,
            store: self.store,
        };
        let action = LssAction::parse(&self.action, &self.words, flags)?;
        let default = match action {
            LssAction::Fastscan { .. } | LssAction::Assign { .. } => FASTSCAN_TIMEOUT_MS,
            _ => LSS_TIMEOUT_MS,
        };
        Ok(Command::Lss {
            action,
            timeout_ms: self.timeout.unwrap_or(default),
        })
    }
}

/// Parses a 32-bit number (decimal or 0x hex).
fn u32_arg(text: &str) -> Result<u32, ParseError> {
    parse_int(text)
        .filter(|v| (0..=i64::from(u32::MAX)).contains(v))
        .map(|v| v as u32)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a number 0..0xFFFFFFFF")))
}

/// How often `send`, `sync` and `pdo` send.
#[derive(Args, Clone, Debug)]
pub struct Repeat {
    /// Send every MS ms (until stopped: Ctrl-C, or stop-all / `jobs stop ID` in the TUI).
    #[arg(long, value_parser = ms_arg)]
    pub every: Option<u64>,
    /// Send this many frames (with --every: then stop).
    #[arg(long, value_parser = count_arg)]
    pub count: Option<u64>,
}

impl Repeat {
    pub(crate) fn schedule(&self) -> Schedule {
        Schedule {
            every_ms: self.every,
            count: self.count,
        }
    }
}

/// `pdo NODE` (read every PDO), `pdo NODE send rpdoK NAME=VALUE ... [--every MS] [--count N]`,
/// `pdo NODE map PDO OBJECT... [--type T] [--event MS] [--inhibit T] [--cob-id ID] [--dry-run]`.
#[derive(Args, Clone, Debug)]
pub struct PdoArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// send (an RPDO) or map (remap a PDO); none: read every PDO's configuration.
    #[arg(value_parser = TypedWords::new(&["send", "map"], pdo_word))]
    pub action: Option<String>,
    /// The PDO: rpdo1, rpdo2, ... (send), tpdo1, rpdo1, ... (map).
    #[arg(value_parser = pdo_arg)]
    pub pdo: Option<PdoId>,
    /// send: the signals as NAME=VALUE; map: the objects to map, in order (object name,
    /// alias or index:sub; OBJECT/BITS for one the dictionary does not size).
    #[arg(allow_negative_numbers = true)]
    pub signals: Vec<String>,
    #[command(flatten)]
    pub repeat: Repeat,
    /// map: the transmission type: acyclic (0), sync (1), sync:N (every N SYNCs), rtr-sync
    /// (252), rtr (253), event-mfr (254), event (255), or a number.
    #[arg(long = "type", value_parser = transmission_arg)]
    pub transmission: Option<u8>,
    /// map: the event timer in ms (0 = off).
    #[arg(long, value_parser = u16_arg)]
    pub event: Option<u16>,
    /// map: the inhibit time, in 100 us units (`25` = 2.5 ms), or with a unit: `2.5ms`, `500us`.
    #[arg(long, value_parser = inhibit_arg)]
    pub inhibit: Option<u16>,
    /// map: the COB-ID the PDO gets (29-bit above 0x7FF) [default: the PDO's own].
    #[arg(long, value_parser = pdo_cob_arg)]
    pub cob_id: Option<u32>,
    /// map: print the frames without sending anything.
    #[arg(long)]
    pub dry_run: bool,
    /// map: map objects the node's dictionary says are not mappable, or use a --cob-id
    /// another service owns.
    #[arg(long)]
    pub force: bool,
    /// read, map: how long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

impl<D: Args> PdoArgs<D> {
    fn command(&self) -> Result<Command, ParseError> {
        let map_flags = [
            ("--type", self.transmission.is_some()),
            ("--event", self.event.is_some()),
            ("--inhibit", self.inhibit.is_some()),
            ("--cob-id", self.cob_id.is_some()),
            ("--dry-run", self.dry_run),
            ("--force", self.force),
        ];
        let send_flags = [
            ("--every", self.repeat.every.is_some()),
            ("--count", self.repeat.count.is_some()),
        ];
        let refuse = |flags: &[(&str, bool)], action: &str| match flags.iter().find(|(_, on)| *on) {
            Some((flag, _)) => Err(ParseError::Invalid(format!("{flag} does not go with `pdo {action}`"))),
            None => Ok(()),
        };
        match (self.action.as_deref(), self.pdo) {
            (None, _) => {
                refuse(&map_flags, "NODE")?;
                refuse(&send_flags, "NODE")?;
                Ok(Command::PdoRead {
                    node: self.node,
                    timeout_ms: self.timeout,
                })
            }
            (Some(action), None) => Err(ParseError::Invalid(format!(
                "`pdo NODE {action}` needs the PDO (rpdo1, tpdo1, ...)"
            ))),
            (Some("send"), Some(pdo)) => {
                refuse(&map_flags, "send")?;
                if pdo.transmit {
                    return Err(ParseError::Invalid(format!(
                        "`{}` is not an RPDO: use rpdo1, rpdo2, ... (TPDOs are the node's to send)",
                        pdo.name()
                    )));
                }
                let words: Vec<&str> = self.signals.iter().map(String::as_str).collect();
                Ok(Command::Pdo {
                    node: self.node,
                    num: pdo.num,
                    assignments: parse_assignments(&words)?,
                    schedule: self.repeat.schedule(),
                })
            }
            (Some(_), Some(pdo)) => {
                refuse(&send_flags, "map")?;
                if let Some(id) = self.cob_id
                    && !self.force
                {
                    not_reserved(id, &format!("{} of node {}", pdo.title(), self.node))?;
                }
                Ok(Command::PdoMap(MapSpec {
                    node: self.node,
                    pdo,
                    objects: self.signals.clone(),
                    transmission: self.transmission,
                    event_ms: self.event,
                    inhibit_100us: self.inhibit,
                    cob_id: self.cob_id,
                    dry_run: self.dry_run,
                    force: self.force,
                    timeout_ms: self.timeout,
                }))
            }
        }
    }
}

impl<B: Args, D: Args> Commander<B, D> {
    /// The options in front of the command (the command line's bus options).
    pub fn bus(&self) -> &B {
        match self {
            Commander::Nmt(o) => &o.bus,
            Commander::Sdo(g) => g.bus(),
            Commander::Drive(o) => &o.bus,
            Commander::Run(o) => &o.bus,
            Commander::Scan(o) => &o.bus,
            Commander::Record(o) => &o.bus,
            Commander::Stop(o) => &o.bus,
            Commander::Lss(o) => &o.bus,
            Commander::Send(o) => &o.bus,
            Commander::Sync(o) => &o.bus,
            Commander::Pdo(o) => &o.bus,
            Commander::Dcf(DcfCommand::Save(o)) => &o.bus,
            Commander::Dcf(DcfCommand::Load(o)) => &o.bus,
            Commander::Dcf(DcfCommand::Diff(o)) => &o.bus,
        }
    }

    /// The dictionary options, for the commands that take them.
    pub fn dict(&self) -> Option<&D> {
        match self {
            Commander::Sdo(g) => g.dict(),
            Commander::Run(o) => Some(&o.args.dict),
            Commander::Pdo(o) => Some(&o.args.dict),
            Commander::Dcf(DcfCommand::Save(o)) => Some(&o.args.dict),
            Commander::Dcf(DcfCommand::Load(o)) => Some(&o.args.dict),
            Commander::Dcf(DcfCommand::Diff(o)) => Some(&o.args.dict),
            _ => None,
        }
    }

    /// The command the words make, or why they make none.
    pub fn command(&self) -> Result<Command, ParseError> {
        Ok(match self {
            Commander::Nmt(o) => Command::Nmt(Declared::<B, D>::spec(o)?),
            Commander::Sdo(g) => Command::Sdo(Declared::<B, D>::spec(g)?),
            Commander::Drive(o) => Command::Drive(Declared::<B, D>::spec(o)?),
            Commander::Run(On { args: a, .. }) => {
                let words: Vec<&str> = a.words.iter().map(String::as_str).collect();
                Command::Run(run_spec(a.node, &words, a.list, a.dry_run, a.timeout)?)
            }
            Commander::Scan(On { args: a, .. }) => Command::Scan {
                listen_ms: a.listen,
                probe: a.probe,
                timeout_ms: a.timeout,
            },
            Commander::Record(On { args: a, .. }) => Command::Record {
                output: a.output.clone(),
                limits: Limits {
                    count: a.count,
                    duration_ms: a.duration,
                },
                mode: match (a.force, a.append) {
                    (true, _) => WriteMode::Overwrite,
                    (_, true) => WriteMode::Append,
                    _ => WriteMode::New,
                },
                format: a.format,
            },
            Commander::Stop(On { args: a, .. }) => {
                let mut nodes = a.nodes.clone();
                nodes.extend(a.node_flags.iter().filter(|n| !a.nodes.contains(n)));
                Command::Stop {
                    nodes,
                    listen_ms: a.listen,
                    options: StopOptions {
                        timeout_ms: a.timeout,
                        ramp_ms: a.ramp,
                    },
                }
            }
            Commander::Lss(On { args: a, .. }) => a.command()?,
            Commander::Send(o) => Command::Send(Declared::<B, D>::spec(o)?),
            Commander::Sync(o) => Command::Sync(Declared::<B, D>::spec(o)?),
            Commander::Pdo(On { args: a, .. }) => a.command()?,
            Commander::Dcf(DcfCommand::Save(On { args: a, .. })) => dcf(
                a.node,
                DcfAction::Save {
                    output: a.output.clone(),
                    force: a.force,
                },
                a.timeout,
            ),
            Commander::Dcf(DcfCommand::Load(On { args: a, .. })) => dcf(
                a.node,
                DcfAction::Load {
                    file: a.file.clone(),
                    store: a.store,
                    dry_run: a.dry_run,
                },
                a.timeout,
            ),
            Commander::Dcf(DcfCommand::Diff(On { args: a, .. })) => {
                dcf(a.node, DcfAction::Diff { file: a.file.clone() }, a.timeout)
            }
        })
    }
}

/// A command's words after the options in front.
impl<B: Args, D, A: CommandArgs<D>> Declared<B, D> for On<B, A> {
    type Spec = A::Spec;

    fn bus(&self) -> &B {
        &self.bus
    }

    fn dict(&self) -> Option<&D> {
        self.args.dict()
    }

    fn name(&self) -> &'static str {
        self.args.name()
    }

    fn spec(&self) -> Result<A::Spec, ParseError> {
        self.args.spec()
    }
}

/// A `dcf` command.
fn dcf(node: u8, action: DcfAction, timeout_ms: u64) -> Command {
    Command::Dcf(super::dcf::DcfCommand {
        node,
        action,
        timeout_ms,
    })
}

/// The palette's parser: the commander declaration with nothing in front.
#[derive(Parser, Debug)]
#[command(
    name = ":",
    no_binary_name = true,
    disable_help_subcommand = true,
    disable_version_flag = true
)]
struct Palette {
    #[command(subcommand)]
    command: Commander<Session, Session>,
}

/// The palette's clap command, built once.
fn palette() -> &'static clap::Command {
    static CMD: OnceLock<clap::Command> = OnceLock::new();
    CMD.get_or_init(|| {
        let mut c = Palette::command();
        c.build();
        c
    })
}

/// Parses one palette line (the command line's words without IFACE and its flags), e.g.
/// `sdo read 2 0x6041`, `nmt start 0 --wait`, `sdo write 2 0x6060 3 --type i8`,
/// `drive 2 mode pv`, `run 2 pv speed=100`, `stop 2 3`. Split like a shell line (quotes
/// keep words together: `sdo write 2 0x1008 "my drive" --type string`).
pub fn parse_command(line: &str) -> Result<Command, ParseError> {
    let words = shlex::split(line).ok_or(ParseError::Quote)?;
    if words.is_empty() {
        return Err(ParseError::Empty);
    }
    let matches = palette().clone().try_get_matches_from(words)?;
    let parsed = <Palette as clap::FromArgMatches>::from_arg_matches(&matches)?;
    parsed.command.command()
}

/// The first words of the commander commands, from the declaration.
pub fn commander_words() -> Vec<&'static str> {
    palette().get_subcommands().map(clap::Command::get_name).collect()
}

/// The syntax of every commander command as the palette takes it, one line each, from the
/// declaration: `(usage, about)`, e.g. `("sdo read [OPTIONS] <NODE> <OBJECT>", "Read ...")`.
pub fn usages() -> Vec<(String, String)> {
    fn walk(cmd: &clap::Command, path: &str, out: &mut Vec<(String, String)>) {
        for sub in cmd.get_subcommands() {
            let name = format!("{path}{}", sub.get_name()).trim_start().to_string();
            if sub.has_subcommands() {
                walk(sub, &format!("{name} "), out);
                continue;
            }
            let usage = sub.clone().render_usage().to_string();
            // clap says "Usage: : sdo read ..." (the palette's name is `:`).
            let args = usage.split_once(sub.get_name()).map_or("", |(_, rest)| rest.trim());
            let about = sub.get_about().map(ToString::to_string).unwrap_or_default();
            out.push((format!("{name} {args}").trim_end().to_string(), about));
        }
    }
    let mut out = Vec::new();
    walk(palette(), "", &mut out);
    out
}

/// The words that may complete the last (partial) word of `before`, a palette line up to
/// the cursor: subcommands, flags (when the word starts with `-`), the values of the flag
/// before it or of the positional argument it stands for (NMT and drive actions, types),
/// and what `known` offers for nodes, objects, procedures and their parameters
/// ([`super::complete::values`]).
pub fn completions(before: &str, known: &dyn super::complete::Known) -> Vec<String> {
    let split = shlex::split(before).unwrap_or_else(|| before.split_whitespace().map(String::from).collect());
    let mut words: Vec<&str> = split.iter().map(String::as_str).collect();
    let partial = if before.ends_with(char::is_whitespace) || words.is_empty() {
        ""
    } else {
        words.pop().unwrap_or("")
    };
    let mut cmd = palette();
    let mut positional = 0;
    let mut expecting: Option<&clap::Arg> = None;
    let mut node: Option<u8> = None;
    let mut given: Vec<(String, String)> = Vec::new();
    // The positional argument at `i`; past the last, the last when it takes many values.
    let at = |cmd: &'static clap::Command, i: usize| -> Option<&'static clap::Arg> {
        let all: Vec<&clap::Arg> = cmd.get_positionals().collect();
        all.get(i)
            .or(all.last().filter(|a| matches!(a.get_action(), clap::ArgAction::Append)))
            .copied()
    };
    for w in &words {
        if expecting.take().is_some() {
            continue;
        }
        if let Some(sub) = cmd.find_subcommand(w) {
            cmd = sub;
            positional = 0;
        } else if let Some(long) = w.strip_prefix("--") {
            expecting = cmd
                .get_arguments()
                .find(|a| a.get_long() == Some(long))
                .filter(|a| a.get_action().takes_values());
        } else if w.starts_with('-') && w.len() == 2 && parse_int(w).is_none() {
            let short = w.chars().nth(1);
            expecting = cmd
                .get_arguments()
                .find(|a| a.get_short() == short)
                .filter(|a| a.get_action().takes_values());
        } else {
            if let Some(a) = at(cmd, positional) {
                if a.get_id() == "node" {
                    node = parse_int(w).and_then(|n| u8::try_from(n).ok());
                }
                given.push((a.get_id().to_string(), w.to_string()));
            }
            positional += 1;
        }
    }
    if std::ptr::eq(cmd, palette()) && !words.is_empty() {
        return Vec::new();
    }
    let values = |a: &clap::Arg| -> Vec<String> {
        a.get_possible_values()
            .iter()
            .map(|v| v.get_name().to_string())
            .collect()
    };
    if let Some(arg) = expecting {
        return values(arg);
    }
    if partial.starts_with('-') {
        return cmd
            .get_arguments()
            .filter_map(|a| a.get_long())
            .filter(|l| *l != "help")
            .map(|l| format!("--{l}"))
            .collect();
    }
    if cmd.has_subcommands() {
        return cmd.get_subcommands().map(|s| s.get_name().to_string()).collect();
    }
    let Some(arg) = at(cmd, positional) else {
        return Vec::new();
    };
    let listed = values(arg);
    if !listed.is_empty() {
        return listed;
    }
    let id = arg.get_id().as_str();
    let before_values: Vec<String> = given.into_iter().filter(|(a, _)| a == id).map(|(_, v)| v).collect();
    super::complete::values(id, node, &before_values, known).unwrap_or_default()
}

/// A value parser that checks a word with `parse` and offers `words` for help and completion.
#[derive(Clone)]
pub(crate) struct TypedWords<T> {
    words: &'static [&'static str],
    parse: fn(&str) -> Result<T, ParseError>,
}

impl<T> TypedWords<T> {
    pub(crate) fn new(words: &'static [&'static str], parse: fn(&str) -> Result<T, ParseError>) -> TypedWords<T> {
        TypedWords { words, parse }
    }
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for TypedWords<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        self.parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.words.iter().map(|w| PossibleValue::new(*w))))
    }
}

pub(crate) const NMT_WORDS: &[&str] = &["start", "stop", "preop", "reset-node", "reset-comm"];
pub(crate) const DRIVE_WORDS: &[&str] = &["enable", "disable", "quick-stop", "fault-reset", "status", "mode"];
pub(crate) const TYPE_WORDS: &[&str] = &[
    "u8", "u16", "u32", "u64", "i8", "i16", "i32", "i64", "f32", "f64", "bool", "string", "octets", "domain",
];

/// Parses NODE 1..127 (decimal or 0x hex).
pub fn node_arg(text: &str) -> Result<u8, ParseError> {
    parse_node(text, false)
}

/// Parses NODE allowing 0 (all nodes).
pub fn node_or_all_arg(text: &str) -> Result<u8, ParseError> {
    parse_node(text, true)
}

/// Parses a positive number of ms.
pub fn ms_arg(text: &str) -> Result<u64, ParseError> {
    parse_int(text)
        .filter(|v| *v > 0)
        .map(|v| v as u64)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a positive number of ms")))
}

/// Parses a frame in candump's compact form with the log reader's parser.
///
/// Blanks around the frame (a quoting artifact) are ignored; a `0x` before the id is
/// refused with the cansend form to write instead (cansend's grammar is hex already); an FD
/// flags digit must be 0..7 (1 BRS, 2 ESI, 4 FDF: bit 3 is no flag, and would be dropped).
pub(crate) fn frame_arg(text: &str) -> Result<Frame, ParseError> {
    let text = text.trim();
    if let Some(rest) = text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        return Err(ParseError::Invalid(format!(
            "`{text}`: the CAN id is hex without 0x, as cansend takes it: `{rest}`"
        )));
    }
    if let Some((_, after)) = text.split_once("##")
        && let Some(digit) = after.chars().next()
        && digit.to_digit(16).is_some_and(|d| d > 7)
    {
        return Err(ParseError::Invalid(format!(
            "`{text}`: CAN FD flags digit `{digit}` is not 0..7 (1 = bit rate switch, 2 = error state \
             indicator, 4 = FD format; add them): e.g. `##1` for BRS"
        )));
    }
    match crate::log::candump::parse_compact(text.as_bytes()) {
        Ok(Some(f)) => Ok(f),
        Ok(None) => Err(ParseError::Invalid(format!("`{text}`: CAN XL frames cannot be sent"))),
        Err(e) => Err(ParseError::Invalid(format!(
            "`{text}` is not a frame ({e}); write ID#DATA, e.g. 601#4041600000000000, 123#R, 12345678#00"
        ))),
    }
}

/// The `pdo` action word: `send` (an RPDO; TPDOs are the nodes' to send) or `map`.
fn pdo_word(word: &str) -> Result<String, ParseError> {
    match word {
        "send" | "map" => Ok(word.to_string()),
        _ => Err(ParseError::Invalid(format!(
            "unknown pdo command `{word}`: use send or map (or nothing, to read the PDOs)"
        ))),
    }
}

/// Parses `rpdo1`..`rpdo512`, `tpdo1`..`tpdo512`.
fn pdo_arg(text: &str) -> Result<PdoId, ParseError> {
    let lower = text.to_ascii_lowercase();
    let (transmit, n) = match (lower.strip_prefix("rpdo"), lower.strip_prefix("tpdo")) {
        (Some(n), _) => (false, n),
        (_, Some(n)) => (true, n),
        _ => (false, ""),
    };
    n.parse::<u16>()
        .ok()
        .filter(|n| (1..=512).contains(n))
        .map(|num| PdoId { transmit, num })
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` is not a PDO: use rpdo1, tpdo1, ... (1..512)")))
}

/// Parses a transmission type: a number 0..255 or its word.
fn transmission_arg(text: &str) -> Result<u8, ParseError> {
    let t = text.to_ascii_lowercase();
    let bad = || {
        ParseError::Invalid(format!(
            "`{text}` is not a transmission type: use acyclic, sync, sync:N (1..240), rtr-sync, rtr, event-mfr, \
             event or a number 0..255"
        ))
    };
    Ok(match t.as_str() {
        "acyclic" => 0,
        "sync" => 1,
        "rtr-sync" => 252,
        "rtr" => 253,
        "event-mfr" => 254,
        "event" => 255,
        _ => match t.strip_prefix("sync:") {
            Some(n) => parse_int(n).filter(|n| (1..=240).contains(n)).ok_or_else(bad)? as u8,
            None => parse_int(&t).filter(|n| (0..=255).contains(n)).ok_or_else(bad)? as u8,
        },
    })
}

/// Parses a 16-bit number (ms of an event timer).
fn u16_arg(text: &str) -> Result<u16, ParseError> {
    parse_int(text)
        .filter(|v| (0..=0xFFFF).contains(v))
        .map(|v| v as u16)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a number 0..65535")))
}

/// Parses an inhibit time: 100 us units, or `2.5ms` / `500us`.
fn inhibit_arg(text: &str) -> Result<u16, ParseError> {
    let t = text.trim().to_ascii_lowercase();
    let units = if let Some(ms) = t.strip_suffix("ms") {
        ms.trim().parse::<f64>().ok().map(|v| v * 10.0)
    } else if let Some(us) = t.strip_suffix("us") {
        us.trim().parse::<f64>().ok().map(|v| v / 100.0)
    } else {
        parse_int(&t).map(|v| v as f64)
    };
    units
        .filter(|u| (0.0..=65535.0).contains(u) && u.fract() == 0.0)
        .map(|u| u as u16)
        .ok_or_else(|| {
            ParseError::Invalid(format!(
                "`{text}`: the inhibit time is 0..65535 units of 100 us (`25`), or `2.5ms`, `500us` (multiples of 0.1 ms)"
            ))
        })
}

/// Parses a PDO COB-ID: 11-bit, or 29-bit above 0x7FF.
fn pdo_cob_arg(text: &str) -> Result<u32, ParseError> {
    parse_int(text)
        .filter(|v| (1..=0x1FFF_FFFF).contains(v))
        .map(|v| v as u32)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a COB-ID 0x001..0x1FFFFFFF")))
}

/// Refuses a COB-ID another service owns ([`crate::decode::cob_id::reserved_for`]) for `user`.
pub(crate) fn not_reserved(id: u32, user: &str) -> Result<(), ParseError> {
    match crate::decode::cob_id::reserved_for(id) {
        Some(owner) => Err(ParseError::Invalid(format!(
            "--cob-id 0x{id:03X} is {owner}: {user} would collide with it; nothing sent (--force uses it anyway)"
        ))),
        None => Ok(()),
    }
}

/// Parses the SYNC counter's overflow value 2..=240.
pub(crate) fn counter_arg(text: &str) -> Result<u8, ParseError> {
    parse_int(text)
        .filter(|v| (2..=240).contains(v))
        .map(|v| v as u8)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}`: the SYNC counter counts to 2..240")))
}

/// Parses an 11-bit COB-ID.
pub(crate) fn cob_arg(text: &str) -> Result<u32, ParseError> {
    parse_int(text)
        .filter(|v| (1..=0x7FF).contains(v))
        .map(|v| v as u32)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be an 11-bit COB-ID 0x001..0x7FF")))
}

/// Parses a positive count.
pub(crate) fn count_arg(text: &str) -> Result<u64, ParseError> {
    parse_int(text)
        .filter(|v| *v > 0)
        .map(|v| v as u64)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a positive number")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::DriveAction;
    use crate::command::object::{Sdo, SdoOptions, SdoRead, SdoWrite};
    use crate::od::DataType;

    /// Completions with nothing known of the bus.
    fn completions_of(before: &str) -> Vec<String> {
        completions(before, &crate::command::complete::Nothing::new())
    }

    #[test]
    fn palette_lines() {
        assert_eq!(
            parse_command("sdo read 2 0x6041").unwrap(),
            Command::Sdo(Sdo::Read(SdoRead {
                node: 2,
                object: "0x6041".into(),
                options: SdoOptions::default(),
                output: None,
            }))
        );
        assert_eq!(
            parse_command("sdo write 0x02 0x1008 \"my drive\" --type string --block --timeout 300").unwrap(),
            Command::Sdo(Sdo::Write(SdoWrite {
                node: 2,
                object: "0x1008".into(),
                value: "my drive".into(),
                options: SdoOptions {
                    data_type: Some(DataType::VisibleString),
                    block: true,
                    timeout_ms: 300,
                    deadline_ms: None
                }
            }))
        );
        assert_eq!(
            parse_command("nmt reset-node 0 --wait").unwrap(),
            Command::Nmt(crate::command::nmt::Nmt {
                action: crate::command::NmtAction::ResetNode,
                node: 0,
                wait: true,
                timeout_ms: crate::command::grammar::NMT_WAIT_MS,
            })
        );
        assert_eq!(
            parse_command("drive 3 mode csv").unwrap(),
            Command::Drive(crate::command::drive::Drive {
                node: 3,
                action: DriveAction::Mode(9),
                timeout_ms: DEFAULT_TIMEOUT_MS
            })
        );
        assert_eq!(
            parse_command("sdo write 2 0x60FF -100 --type i32")
                .map(|c| matches!(c, Command::Sdo(Sdo::Write(w)) if w.value == "-100")),
            Ok(true)
        );
        assert_eq!(
            parse_command("scan --probe --listen 500").unwrap(),
            Command::Scan {
                listen_ms: 500,
                probe: true,
                timeout_ms: SCAN_TIMEOUT_MS
            }
        );
        assert_eq!(
            parse_command("record -o out.log").unwrap(),
            Command::Record {
                output: "out.log".into(),
                limits: Limits::default(),
                mode: WriteMode::New,
                format: LogFormat::Candump,
            }
        );
        assert_eq!(
            parse_command("record -o out.log --append --count 5").unwrap(),
            Command::Record {
                output: "out.log".into(),
                limits: Limits {
                    count: Some(5),
                    duration_ms: None
                },
                mode: WriteMode::Append,
                format: LogFormat::Candump,
            }
        );
        assert!(matches!(
            parse_command("record --force -o out.log"),
            Ok(Command::Record {
                mode: WriteMode::Overwrite,
                ..
            })
        ));
        assert!(
            parse_command("record -o x --force --append")
                .unwrap_err()
                .to_string()
                .contains("cannot be used with")
        );
        assert_eq!(
            parse_command("stop 2 --node 3 --ramp 300").unwrap(),
            Command::Stop {
                nodes: vec![2, 3],
                listen_ms: DEFAULT_LISTEN_MS,
                options: StopOptions {
                    timeout_ms: DEFAULT_TIMEOUT_MS,
                    ramp_ms: 300
                }
            }
        );
    }

    #[test]
    fn errors_say_what_is_wrong() {
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(
            err("sdo read 0 0x6041").contains("node `0` must be a number 1..127 (decimal or 0x hex)"),
            "{}",
            err("sdo read 0 0x6041")
        );
        assert!(err("nmt go 2").contains("unknown NMT command `go`"));
        assert!(err("sdo read 2 0x6041 --type u7").contains("unknown type `u7`"));
        assert!(err("drive 2 fly").contains("unknown drive command"));
        assert!(err("record").contains("--output <OUTPUT>"));
        assert!(err("").starts_with("empty command"));
        assert_eq!(err("nmt start 2 --block"), "unexpected argument '--block' found");
        assert_eq!(
            err("drive 2 enable extra"),
            "`drive enable` takes no MODE (got `extra`)"
        );
        assert!(err("drive 2 mode fly").contains("unknown mode `fly`"));
        assert_eq!(err("drive 2 mode"), "drive mode needs a MODE (e.g. pv, csp, 3)");
        assert_eq!(err("scan extra"), "unexpected argument 'extra' found");
        assert_eq!(parse_command("sdo read 2 \"0x6041"), Err(ParseError::Quote));
        assert!(err("lss fly").contains("unknown LSS command `fly`"));
        assert_eq!(
            err("lss set-node"),
            "`lss set-node` takes a node-ID N (1..127, 255 = unconfigured) (got 0 words)"
        );
        assert_eq!(err("lss inquire node --store"), "--store goes with `lss assign`");
    }

    #[test]
    fn lss_lines() {
        use crate::command::lss::{FASTSCAN_TIMEOUT_MS, Inquiry, LssAction};
        assert_eq!(
            parse_command("lss assign 10 --store").unwrap(),
            Command::Lss {
                action: LssAction::Assign {
                    node: 10,
                    store: true,
                    vendor: None,
                    product: None
                },
                timeout_ms: FASTSCAN_TIMEOUT_MS
            }
        );
        assert_eq!(
            parse_command("lss inquire serial --timeout 50").unwrap(),
            Command::Lss {
                action: LssAction::Inquire(Inquiry::Part(crate::lss::Part::Serial)),
                timeout_ms: 50
            }
        );
        assert!(completions_of("lss ").contains(&"fastscan".to_string()));
    }

    #[test]
    fn run_lines() {
        assert_eq!(
            parse_command("run 2 pv speed=100 accel=0x10 --dry-run").unwrap(),
            Command::Run(super::super::RunSpec {
                node: 2,
                procedure: Some("pv".into()),
                args: vec![("speed".into(), "100".into()), ("accel".into(), "0x10".into())],
                dry_run: true,
                timeout_ms: DEFAULT_TIMEOUT_MS,
            })
        );
        assert!(matches!(
            parse_command("run 3 --list").unwrap(),
            Command::Run(super::super::RunSpec {
                node: 3,
                procedure: None,
                ..
            })
        ));
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(err("run 2 pv speed").contains("NAME=VALUE"));
        assert!(err("run 2 speed=1").contains("PROCEDURE before"));
        assert!(err("run 2 pv --list").contains("not both"));
    }

    #[test]
    fn cyclic_lines() {
        let every = |every_ms, count| Schedule { every_ms, count };
        assert!(matches!(
            parse_command("send 12345678#DEAD --every 5").unwrap(),
            Command::Send(s) if s.frame.id == 0x1234_5678 && s.frame.is_ext()
                && s.schedule == every(Some(5), None)
        ));
        assert_eq!(
            parse_command("sync --period 10 --counter 240 --count 3").unwrap(),
            Command::Sync(crate::command::sync::Sync {
                cob_id: 0x080,
                counter: Some(240),
                schedule: every(Some(10), Some(3))
            })
        );
        assert_eq!(
            parse_command("pdo 2 send rpdo1 Controlword=0x0F \"Target velocity=-5\" --count 2").unwrap(),
            Command::Pdo {
                node: 2,
                num: 1,
                assignments: vec![
                    ("Controlword".into(), "0x0F".into()),
                    ("Target velocity".into(), "-5".into())
                ],
                schedule: every(None, Some(2))
            }
        );
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(err("sync --period 10 --counter 1").contains("counts to 2..240"));
        assert!(
            err("send 601#4G").contains("is not a frame (column"),
            "{}",
            err("send 601#4G")
        );
        assert!(err("pdo 2 send tpdo1").contains("use rpdo1"));
        assert!(err("pdo 2 read rpdo1").contains("use send or map"));
        assert!(err("sync").contains("--period"));
    }

    #[test]
    fn pdo_lines() {
        assert_eq!(
            parse_command("pdo 2 --timeout 300").unwrap(),
            Command::PdoRead {
                node: 2,
                timeout_ms: 300
            }
        );
        let Command::PdoMap(m) = parse_command(
            "pdo 2 map TPDO3 Statusword 0x6064 --type sync:4 --event 100 --inhibit 2.5ms --cob-id 0x12345",
        )
        .unwrap() else {
            panic!("not a map");
        };
        assert_eq!(m.pdo, PdoId { transmit: true, num: 3 });
        assert_eq!(m.objects, ["Statusword", "0x6064"]);
        assert_eq!(
            (m.transmission, m.event_ms, m.inhibit_100us, m.cob_id),
            (Some(4), Some(100), Some(25), Some(0x12345))
        );
        let kind = |t: &str| match parse_command(&format!("pdo 2 map rpdo1 0x6040 --type {t}")) {
            Ok(Command::PdoMap(m)) => m.transmission,
            _ => None,
        };
        assert_eq!(
            ["acyclic", "sync", "rtr-sync", "rtr", "event-mfr", "event", "0xFE"].map(kind),
            [0, 1, 252, 253, 254, 255, 254].map(Some)
        );
        let inhibit = |t: &str| match parse_command(&format!("pdo 2 map rpdo1 0x6040 --inhibit {t}")) {
            Ok(Command::PdoMap(m)) => m.inhibit_100us,
            _ => None,
        };
        assert_eq!(["25", "500us", "1ms", "0"].map(inhibit), [25, 5, 10, 0].map(Some));
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(err("pdo 2 map rpdo1 0x6040 --type sync:241").contains("not a transmission type"));
        assert!(err("pdo 2 map rpdo1 0x6040 --inhibit 0.05ms").contains("multiples of 0.1 ms"));
        assert!(err("pdo 2 map").contains("needs the PDO"));
        assert!(err("pdo 2 map xpdo1 0x6040").contains("is not a PDO"));
        assert!(err("pdo 2 send rpdo1 Controlword=1 --dry-run").contains("--dry-run does not go with `pdo send`"));
        assert!(err("pdo 2 --event 5").contains("--event does not go with `pdo NODE`"));
        assert!(completions_of("pdo 2 ").contains(&"map".to_string()));
    }

    #[test]
    fn completion_comes_from_the_declaration() {
        assert_eq!(
            commander_words(),
            [
                "nmt", "sdo", "drive", "run", "scan", "record", "stop", "lss", "send", "sync", "pdo", "dcf"
            ]
        );
        assert_eq!(completions_of("sdo "), ["read", "write"]);
        assert_eq!(completions_of("nmt re"), NMT_WORDS);
        assert_eq!(completions_of("drive 2 "), DRIVE_WORDS);
        assert!(completions_of("sdo write 2 0x6060 3 --t").contains(&"--type".to_string()));
        assert!(completions_of("sdo write 2 0x6060 3 --type ").contains(&"i8".to_string()));
        assert!(!completions_of("nmt start 2 --").contains(&"--block".to_string()));
        assert!(completions_of("filter x").is_empty());
    }
}
