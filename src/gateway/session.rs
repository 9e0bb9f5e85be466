//! One client's session of the gateway: its defaults (`set node`, `set sdo_timeout`, `set
//! sdo_block`), its kept notifications (`log`), and each request run to its answer through
//! the command layer (SDO client, NMT, LSS master) on the bus, one at a time.
//!
//! Read-only by default: `write`, NMT and LSS requests need [`Policy::allow_writes`], else
//! they are answered `ERROR:100` and nothing is sent; on a listen-only bus every request
//! that would send (SDO reads too) is answered `ERROR:102`.

use super::answer::{self, Code};
use super::line::{self, Command, Help, Line, Lss, Request};
use crate::bus::{Bus, BusError};
use crate::command::CommandError;
use crate::command::lss::{LSS_TIMEOUT_MS, exchange, fastscan};
use crate::command::sdo::{Timing, download_within, upload_within};
use crate::lss::master::{Answer, Service};
use crate::lss::{Address, Part};
use std::collections::VecDeque;

/// What the gateway lets its clients do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Policy {
    /// `--allow-writes`: SDO writes, NMT and LSS commands go on the bus.
    pub allow_writes: bool,
    /// `--notify`: notifications are written to the clients as they happen (between
    /// answers), besides being kept for `log`. Off by default, as in canopend: a client like
    /// `cocomm` takes the first line after a request for its answer.
    pub notify: bool,
}

impl Policy {
    /// What the clients may do, for the line that says where the gateway listens.
    pub fn mode(&self, listen_only: bool) -> &'static str {
        match (listen_only, self.allow_writes) {
            (true, _) => " (listen-only: nothing is sent)",
            (false, true) => " (writes, NMT and LSS allowed)",
            (false, false) => " (read-only: --allow-writes for write, NMT and LSS)",
        }
    }
}

/// The default SDO timeout of a session, in ms (canopend's).
pub const SDO_TIMEOUT_MS: u16 = 500;

/// Notifications kept for `log`, per session (the oldest go first).
const LOG_LINES: usize = 100;

/// One client's state.
pub struct Session {
    bus: Bus,
    policy: Policy,
    node: Option<u8>,
    sdo_timeout_ms: u16,
    block: bool,
    log: VecDeque<String>,
}

impl Session {
    /// A session on `bus`: no default node, SDO timeout 500 ms, block transfers off (as canopend starts).
    pub fn new(bus: Bus, policy: Policy) -> Session {
        Session {
            bus,
            policy,
            node: None,
            sdo_timeout_ms: SDO_TIMEOUT_MS,
            block: false,
            log: VecDeque::new(),
        }
    }

    /// The session's policy.
    pub fn policy(&self) -> Policy {
        self.policy
    }

    /// Keeps a notification line for `log`.
    pub fn keep(&mut self, line: &str) {
        if self.log.len() == LOG_LINES {
            self.log.pop_front();
        }
        self.log.push_back(line.trim_end().to_string());
    }

    /// The answer to one line (its text without the line end; bytes that are not UTF-8 are refused).
    pub async fn answer(&mut self, bytes: &[u8]) -> String {
        let Ok(text) = std::str::from_utf8(bytes) else {
            return answer::error(
                seq_of(bytes).unwrap_or(0),
                Code::Syntax,
                "the line is not text (not UTF-8)",
            );
        };
        match line::parse(text) {
            Ok(Line::Empty) => answer::empty(),
            Ok(Line::Request(r)) => self.run(r).await,
            Err(r) => answer::error(r.seq.unwrap_or(0), r.code, &r.why),
        }
    }

    /// Runs a parsed request.
    async fn run(&mut self, r: Request) -> String {
        let seq = r.seq;
        let refuse = |code: Code, why: &str| answer::error(seq, code, why);
        let sends = matches!(
            r.command,
            Command::Read { .. } | Command::Write { .. } | Command::Nmt(_) | Command::Lss(_)
        );
        let writes = sends && !matches!(r.command, Command::Read { .. });
        if writes && !self.policy.allow_writes {
            return refuse(
                Code::NotSupported,
                "the gateway is read-only: start it with --allow-writes for write, NMT and LSS (nothing was sent)",
            );
        }
        if sends && self.bus.is_listen_only() {
            return refuse(
                Code::InternalState,
                "the gateway is listen-only: it cannot send on the bus (nothing was sent)",
            );
        }
        let node = r.node.or(self.node);
        match r.command {
            Command::Read { index, sub, ty } => {
                let Some(node) = sdo_node(node) else {
                    return no_node(seq, node);
                };
                match upload_within(&self.bus, node, index, sub, self.block, self.timing()).await {
                    Ok(data) => answer::value(seq, &ty.print(&data)),
                    Err(e) => failed(seq, e),
                }
            }
            Command::Write { index, sub, data, .. } => {
                let Some(node) = sdo_node(node) else {
                    return no_node(seq, node);
                };
                match download_within(&self.bus, node, index, sub, data, self.block, self.timing()).await {
                    Ok(()) => answer::ok(seq),
                    Err(e) => failed(seq, e),
                }
            }
            Command::Nmt(action) => {
                let Some(node) = node else {
                    return refuse(Code::NoDefaultNode, "give the node (0 = all) or `set node N` first");
                };
                match crate::command::nmt::nmt(&self.bus, action, node, false, 0).await {
                    Ok(_) => answer::ok(seq),
                    Err(e) => failed(seq, e),
                }
            }
            Command::SetNetwork(_) => answer::ok(seq),
            Command::SetNode(n) => {
                self.node = Some(n);
                answer::ok(seq)
            }
            Command::SetSdoTimeout(ms) => {
                self.sdo_timeout_ms = ms;
                answer::ok(seq)
            }
            Command::SetSdoBlock(on) => {
                self.block = on;
                answer::ok(seq)
            }
            Command::Lss(l) => self.lss(seq, l).await,
            Command::Help(topic) => answer::text(help(topic)),
            Command::Log => {
                let lines: Vec<String> = self.log.drain(..).collect();
                answer::text(&lines.join("\n"))
            }
        }
    }

    fn timing(&self) -> Timing {
        Timing {
            timeout_ms: u64::from(self.sdo_timeout_ms),
            deadline_ms: None,
        }
    }

    /// Runs an LSS command on the LSS master.
    async fn lss(&mut self, seq: u32, l: Lss) -> String {
        let service = match l {
            Lss::SwitchGlobal(config) => Service::SwitchGlobal(config),
            Lss::SwitchSelective([vendor, product, revision, serial]) => Service::SwitchSelective(Address {
                vendor,
                product,
                revision,
                serial,
            }),
            Lss::SetNode(n) => Service::ConfigureNodeId(n),
            Lss::ConfBitrate(index) => Service::ConfigureBitTiming { table: 0, index },
            Lss::ActivateBitrate(delay_ms) => Service::ActivateBitTiming { delay_ms },
            Lss::Store => Service::StoreConfiguration,
            Lss::InquireAddress(None) => Service::InquireAddress,
            Lss::InquireAddress(Some(p)) => Service::Inquire(Part::ALL[usize::from(p.min(3))]),
            Lss::GetNode => Service::InquireNodeId,
            Lss::Fastscan(timeout) => {
                let ms = timeout.map_or(crate::command::lss::FASTSCAN_TIMEOUT_MS, u64::from);
                return match fastscan(&self.bus, [None; 4], ms).await {
                    Ok(Some(a)) => answer::value(seq, &address(a)),
                    Ok(None) => answer::error(seq, Code::TimeOut, "no non-configured LSS slave answered the fastscan"),
                    Err(e) => failed(seq, e),
                };
            }
            Lss::AllNodes(a) => return self.all_nodes(seq, a).await,
        };
        match exchange(&self.bus, service, LSS_TIMEOUT_MS).await {
            Ok(Answer::Address(a)) => answer::value(seq, &address(a)),
            Ok(Answer::Value(_, v)) => answer::value(seq, &format!("0x{v:08X}")),
            Ok(Answer::NodeId(n)) => answer::value(seq, &format!("0x{n:02X}")),
            Ok(_) => answer::ok(seq),
            Err(e) => failed(seq, e),
        }
    }
}

impl Session {
    /// `lss_allnodes`, as canopend runs it: fastscan for a non-configured slave, give it the
    /// next node-ID (stored when asked), back to waiting; again until no slave answers or
    /// node-ID 127 was given. Each slave is a `# Node-ID N assigned to: ...` line before the
    /// answer; the count (`# Found N nodes, search finished.`) or `# Not all nodes
    /// scanned!` before the last `OK`. A failure ends it, after the lines of the slaves done.
    async fn all_nodes(&mut self, seq: u32, a: line::AllNodes) -> String {
        let mut out = String::new();
        let (mut node, mut found) = (a.first, 0u32);
        loop {
            let addr = match fastscan(&self.bus, a.known, u64::from(a.timeout_ms)).await {
                Ok(Some(addr)) => addr,
                Ok(None) => {
                    out.push_str(&format!("# Found {found} nodes, search finished.\n"));
                    out.push_str(&answer::ok(seq));
                    return out;
                }
                Err(e) => return out + &failed(seq, e),
            };
            let mut steps = vec![Service::ConfigureNodeId(node)];
            if a.store {
                steps.push(Service::StoreConfiguration);
            }
            steps.push(Service::SwitchGlobal(false));
            for step in steps {
                if let Err(e) = exchange(&self.bus, step, LSS_TIMEOUT_MS).await {
                    return out + &failed(seq, e);
                }
            }
            found += 1;
            out.push_str(&format!("# Node-ID {node} assigned to: {}\n", address(addr)));
            if node == 127 {
                out.push_str("# Not all nodes scanned!\n");
                out.push_str(&answer::ok(seq));
                return out;
            }
            node += 1;
        }
    }
}

/// The four parts of an LSS address as canopend prints them.
fn address(a: Address) -> String {
    format!(
        "0x{:08X} 0x{:08X} 0x{:08X} 0x{:08X}",
        a.vendor, a.product, a.revision, a.serial
    )
}

/// A node an SDO can go to (1..127).
fn sdo_node(node: Option<u8>) -> Option<u8> {
    node.filter(|n| (1..=127).contains(n))
}

fn no_node(seq: u32, node: Option<u8>) -> String {
    match node {
        None => answer::error(seq, Code::NoDefaultNode, "give the node or `set node N` first"),
        Some(_) => answer::error(seq, Code::UnsupportedNode, "an SDO goes to one node 1..127"),
    }
}

/// The answer to a command that failed.
fn failed(seq: u32, e: CommandError) -> String {
    match e {
        CommandError::Abort { code, .. } => answer::abort(seq, code),
        // The client gave up and sent abort 0x05040000 (SDO protocol timed out).
        CommandError::Timeout(why) if why.starts_with("SDO") => answer::abort(seq, 0x0504_0000),
        CommandError::Timeout(why) => answer::error(seq, Code::TimeOut, &why),
        CommandError::LssRefused { service, error, .. } => {
            let code = match (service, error) {
                (_, 0xFF) => Code::LssManufacturer,
                ("configure_node_id", _) => Code::LssNodeId,
                ("configure_bit_timing", _) => Code::LssBitRate,
                ("store_configuration", _) => Code::LssStore,
                _ => Code::InternalState,
            };
            answer::error(seq, code, &format!("{service} refused with error {error}"))
        }
        CommandError::Bus(BusError::ListenOnly) => {
            answer::error(seq, Code::InternalState, "the bus is listen-only (nothing was sent)")
        }
        CommandError::Bus(b) => answer::error(seq, Code::InternalState, &b.to_string()),
        other => answer::error(seq, Code::InternalState, &other.to_string()),
    }
}

/// The sequence number at the start of a line that is not text, for its refusal.
pub fn seq_of(bytes: &[u8]) -> Option<u32> {
    let s = bytes.strip_prefix(b"[")?;
    let end = s.iter().position(|&b| b == b']')?;
    let digits = std::str::from_utf8(&s[..end]).ok()?;
    super::types::c_number(digits).and_then(|n| u32::try_from(n).ok())
}

/// The help texts (`help`, `help datatype`, `help lss`).
fn help(topic: Help) -> &'static str {
    match topic {
        Help::Commands => HELP,
        Help::Datatype => HELP_TYPES,
        Help::Lss => HELP_LSS,
    }
}

const HELP: &str = "
cotui gateway: CiA 309-3 ASCII requests, canopend's command set. Each line:
[SEQ] [[NET] NODE] COMMAND ...      answers: [SEQ] OK | [SEQ] VALUE | [SEQ] ERROR:CODE #why
  r[ead] INDEX SUB [TYPE]           SDO upload (no TYPE: hex bytes)
  w[rite] INDEX SUB TYPE VALUE      SDO download (needs --allow-writes)
  start | stop | preop[erational]   NMT to NODE, 0 = all (needs --allow-writes)
  reset node | reset comm[unication]
  set network N | set node N        defaults for the lines without them
  set sdo_timeout MS | set sdo_block 0|1
  help [datatype|lss] | log         this text, types, LSS commands; kept notifications
Comments start with #. One network: NET is accepted and not used. Notifications (EMCY,
NMT state changes from heartbeats and boot-ups) are kept for `log` (with --notify: written
as lines between answers too).";

const HELP_TYPES: &str = "
Data types:
  b                      boolean (printed as 0 or 1)
  i8 i16 i32 i64         signed integers
  u8 u16 u32 u64         unsigned integers (0x hex, leading 0 octal, else decimal)
  x8 x16 x32 x64         unsigned integers printed as hex
  r32 r64                real numbers
  vs                     visible string (\"in double quotes\" for several words, \"\" for a quote)
  os us d                octet string, unicode string, domain: one line of base64
  hex                    bytes as hex pairs, blanks allowed";

const HELP_LSS: &str = "
LSS commands (need --allow-writes):
  lss_switch_glob 0|1                      switch state global: 0 waiting, 1 configuration
  lss_switch_sel VENDOR PRODUCT REV SERIAL switch state selective
  lss_set_node NODE                        configure node-ID (255 = unconfigured)
  lss_conf_bitrate 0 INDEX                 configure bit timing: 0=1000 1=800 2=500 3=250
                                           4=125 6=50 7=20 8=10 kbit/s, 9=auto
  lss_activate_bitrate DELAY_MS            activate bit timing
  lss_store                                store configuration
  lss_inquire_addr [0..3]                  vendor, product, revision, serial (all four without)
  lss_get_node                             inquire node-ID
  _lss_fastscan [TIMEOUT_MS]               find one non-configured slave
  lss_allnodes [TIMEOUT_MS [FIRST STORE    node-IDs FIRST, FIRST+1, ... (2, stored) to every
    [S0 VENDOR S1 PRODUCT S2 REV S3 SERIAL]]] non-configured slave found; S: 0 scan, 1 ignore,
                                           2 match the value";
