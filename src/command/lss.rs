//! LSS master commands (CiA 305) over a [`Bus`]: the IO around the pure
//! [`crate::lss::master`] exchanges and [`crate::lss::fastscan`].
//!
//! Requests go out on 0x7E5, answers are read from 0x7E4. The clock is the bus's
//! ([`Bus::now_ns`], the clock of the receive timestamps): before a deadline is judged at
//! `now`, the loop gives the bus reader a turn and feeds every frame already queued, so a
//! busy machine does not turn a prompt answer into a timeout. A listen-only bus refuses the
//! first send ([`crate::bus::BusError::ListenOnly`]).

use super::error::{CommandError, ParseError};
use super::grammar::parse_int;
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::{ms_arg, u32_arg};
use crate::bus::{Bus, BusError};
use crate::frame::{Direction, Frame};
use crate::lss::fastscan::{Fastscan, FastscanError, Found};
use crate::lss::master::{Answer, LssError, Service, Step};
use crate::lss::{Address, MASTER_ID, Part, SLAVE_ID, UNCONFIGURED, bit_rate_index, bit_rate_text};
use serde::Serialize;
use std::time::Duration;

/// Default wait for each LSS answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
pub const LSS_TIMEOUT_MS: u64 = 100;
/// Default wait for the answers to each fastscan request, in ms (a scan sends about 130).
pub const FASTSCAN_TIMEOUT_MS: u64 = 30;

/// What `lss inquire` asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inquiry {
    /// One part of the LSS address.
    Part(Part),
    /// The node-ID.
    NodeId,
    /// The whole address and the node-ID.
    All,
}

/// One LSS command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LssAction {
    /// `switch config|wait`: every slave to configuration or waiting state.
    Switch { config: bool },
    /// `select VENDOR PRODUCT REVISION SERIAL`: the slave with that address to configuration state.
    Select(Address),
    /// `set-node N`: configure node-ID (1..127, 255 = unconfigured).
    SetNode(u8),
    /// `set-bitrate KBIT`: configure bit timing, table 0.
    SetBitrate { kbit: u32, index: u8 },
    /// `activate-bitrate DELAY_MS`: activate bit timing (no answer).
    ActivateBitrate { delay_ms: u16 },
    /// `store`: store configuration.
    Store,
    /// `inquire [vendor|product|revision|serial|node|all]`.
    Inquire(Inquiry),
    /// `identify VENDOR PRODUCT REV_LO REV_HI SER_LO SER_HI`: identify remote slave.
    Identify {
        vendor: u32,
        product: u32,
        revision: (u32, u32),
        serial: (u32, u32),
    },
    /// `identify-unconfigured`: identify non-configured remote slave.
    IdentifyUnconfigured,
    /// `fastscan [--vendor V] [--product P]`: find one non-configured slave, leave it in
    /// configuration state.
    Fastscan { vendor: Option<u32>, product: Option<u32> },
    /// `assign N [--store] [--vendor V] [--product P]`: fastscan (narrowed like `fastscan`),
    /// configure node-ID N, (store,) switch global waiting.
    Assign {
        node: u8,
        store: bool,
        vendor: Option<u32>,
        product: Option<u32>,
    },
}

/// A number 0..0xFFFFFFFF (an LSS address part).
fn number(word: &str) -> Result<u32, ParseError> {
    u32_arg(word)
}

/// A node-ID for `set-node`: 1..127, or 255 (unconfigured).
fn set_node_id(word: &str) -> Result<u8, ParseError> {
    parse_int(word)
        .filter(|n| (1..=127).contains(n) || *n == i64::from(UNCONFIGURED))
        .map(|n| n as u8)
        .ok_or_else(|| ParseError::Invalid(format!("node-ID `{word}` must be 1..127 (or 255 = unconfigured)")))
}

/// A node-ID for `assign`: 1..127.
fn assign_node_id(word: &str) -> Result<u8, ParseError> {
    parse_int(word)
        .filter(|n| (1..=127).contains(n))
        .map(|n| n as u8)
        .ok_or_else(|| ParseError::Invalid(format!("node-ID `{word}` must be 1..127")))
}

/// A bit rate of the CiA 305 table, in kbit/s.
fn kbit_arg(word: &str) -> Result<u32, ParseError> {
    let kbit = u32_arg(word)?;
    bit_rate_index(kbit).map(|_| kbit).ok_or_else(|| {
        ParseError::Invalid(format!(
            "bit rate `{kbit}` kbit/s is not in the CiA 305 table: use 1000, 800, 500, 250, 125, 50, 20 or 10"
        ))
    })
}

/// The switch delay of `activate-bitrate`, ms.
fn delay_arg(word: &str) -> Result<u16, ParseError> {
    u32_arg(word)
        .ok()
        .and_then(|v| u16::try_from(v).ok())
        .ok_or_else(|| ParseError::Invalid(format!("DELAY_MS `{word}` must be 0..65535")))
}

/// The words of `lss switch`: `[global] config|wait`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SwitchWord {
    /// Switch state global (the only switch there is without an address).
    Global,
    /// To configuration state.
    #[value(alias = "configuration")]
    Config,
    /// To waiting state.
    #[value(alias = "waiting")]
    Wait,
}

/// What `lss inquire` asks for.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum InquireWord {
    /// The vendor-ID.
    Vendor,
    /// The product code.
    Product,
    /// The revision number.
    Revision,
    /// The serial number.
    Serial,
    /// The node-ID.
    #[value(alias = "node-id")]
    Node,
    /// The whole address and the node-ID.
    All,
}

/// The CiA 305 services of `lss`, each with its own words.
#[derive(clap::Subcommand, Clone, Debug)]
pub enum LssService {
    /// Every slave to configuration or waiting state: `switch [global] config|wait`.
    Switch {
        /// `[global] config|wait`.
        #[arg(value_enum, num_args = 1..=2, required = true, value_name = "[global] config|wait")]
        words: Vec<SwitchWord>,
    },
    /// The slave with this LSS address to configuration state.
    Select {
        /// Vendor-ID (0x1018:1).
        #[arg(value_parser = number)]
        vendor: u32,
        /// Product code (0x1018:2).
        #[arg(value_parser = number)]
        product: u32,
        /// Revision number (0x1018:3).
        #[arg(value_parser = number)]
        revision: u32,
        /// Serial number (0x1018:4).
        #[arg(value_parser = number)]
        serial: u32,
    },
    /// Configure the node-ID of the slave in configuration state (255 = unconfigured).
    SetNode {
        /// The node-ID, 1..127 (255: unconfigured).
        #[arg(value_parser = set_node_id)]
        node: u8,
    },
    /// Configure bit timing (CiA 305 table 0), in kbit/s.
    SetBitrate {
        /// 1000, 800, 500, 250, 125, 50, 20 or 10.
        #[arg(value_parser = kbit_arg)]
        kbit: u32,
    },
    /// Activate the bit timing after a switch delay (no answer).
    ActivateBitrate {
        /// The switch delay, ms (0..65535): each period before and after the switch.
        #[arg(value_parser = delay_arg)]
        delay_ms: u16,
    },
    /// Store the configuration of the slave in configuration state.
    Store,
    /// Ask the slave in configuration state for a part of its address, its node-ID, or all.
    Inquire {
        /// The part asked for.
        #[arg(value_enum, default_value = "all")]
        what: InquireWord,
    },
    /// Identify remote slaves in an address range.
    Identify {
        /// Vendor-ID.
        #[arg(value_parser = number)]
        vendor: u32,
        /// Product code.
        #[arg(value_parser = number)]
        product: u32,
        /// Lowest revision number.
        #[arg(value_parser = number)]
        rev_lo: u32,
        /// Highest revision number.
        #[arg(value_parser = number)]
        rev_hi: u32,
        /// Lowest serial number.
        #[arg(value_parser = number)]
        ser_lo: u32,
        /// Highest serial number.
        #[arg(value_parser = number)]
        ser_hi: u32,
    },
    /// Identify non-configured remote slaves.
    IdentifyUnconfigured,
    /// Find one non-configured slave and leave it in configuration state.
    Fastscan {
        #[command(flatten)]
        narrow: Narrow,
    },
    /// Fastscan (narrowed like `fastscan`), configure node-ID N, (store,) switch global waiting.
    Assign {
        /// The node-ID to give the slave found, 1..127.
        #[arg(value_parser = assign_node_id)]
        node: u8,
        /// Also store the configuration.
        #[arg(long)]
        store: bool,
        #[command(flatten)]
        narrow: Narrow,
    },
}

/// What narrows a fastscan: the parts of the address known.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct Narrow {
    /// Only a slave with this vendor-ID.
    #[arg(long, value_parser = number)]
    pub vendor: Option<u32>,
    /// Only a slave with this product code.
    #[arg(long, value_parser = number)]
    pub product: Option<u32>,
}

impl LssService {
    /// The action, with the checks clap cannot make (a range upside down, the switch words).
    fn action(&self) -> Result<LssAction, ParseError> {
        Ok(match *self {
            LssService::Switch { ref words } => match words.as_slice() {
                [SwitchWord::Global, m] | [m] if *m != SwitchWord::Global => LssAction::Switch {
                    config: *m == SwitchWord::Config,
                },
                _ => return Err(ParseError::Invalid("`lss switch` takes [global] config|wait".into())),
            },
            LssService::Select {
                vendor,
                product,
                revision,
                serial,
            } => LssAction::Select(Address {
                vendor,
                product,
                revision,
                serial,
            }),
            LssService::SetNode { node } => LssAction::SetNode(node),
            LssService::SetBitrate { kbit } => LssAction::SetBitrate {
                kbit,
                index: bit_rate_index(kbit).unwrap_or_default(),
            },
            LssService::ActivateBitrate { delay_ms } => LssAction::ActivateBitrate { delay_ms },
            LssService::Store => LssAction::Store,
            LssService::Inquire { what } => LssAction::Inquire(match what {
                InquireWord::Vendor => Inquiry::Part(Part::Vendor),
                InquireWord::Product => Inquiry::Part(Part::Product),
                InquireWord::Revision => Inquiry::Part(Part::Revision),
                InquireWord::Serial => Inquiry::Part(Part::Serial),
                InquireWord::Node => Inquiry::NodeId,
                InquireWord::All => Inquiry::All,
            }),
            LssService::Identify {
                vendor,
                product,
                rev_lo,
                rev_hi,
                ser_lo,
                ser_hi,
            } => LssAction::Identify {
                vendor,
                product,
                revision: range(rev_lo, rev_hi, "REV")?,
                serial: range(ser_lo, ser_hi, "SER")?,
            },
            LssService::IdentifyUnconfigured => LssAction::IdentifyUnconfigured,
            LssService::Fastscan { narrow } => LssAction::Fastscan {
                vendor: narrow.vendor,
                product: narrow.product,
            },
            LssService::Assign { node, store, narrow } => LssAction::Assign {
                node,
                store,
                vendor: narrow.vendor,
                product: narrow.product,
            },
        })
    }
}

/// An `identify` range LO..HI, refused upside down (no slave would answer).
fn range(lo: u32, hi: u32, what: &str) -> Result<(u32, u32), ParseError> {
    if lo > hi {
        return Err(ParseError::Invalid(format!(
            "`lss identify`: {what}_LO 0x{lo:08X} is above {what}_HI 0x{hi:08X}: the range is LO..HI (no slave would answer; nothing sent)"
        )));
    }
    Ok((lo, hi))
}

impl LssAction {
    /// The command's word.
    pub fn as_str(&self) -> &'static str {
        match self {
            LssAction::Switch { .. } => "switch",
            LssAction::Select(_) => "select",
            LssAction::SetNode(_) => "set-node",
            LssAction::SetBitrate { .. } => "set-bitrate",
            LssAction::ActivateBitrate { .. } => "activate-bitrate",
            LssAction::Store => "store",
            LssAction::Inquire(_) => "inquire",
            LssAction::Identify { .. } => "identify",
            LssAction::IdentifyUnconfigured => "identify-unconfigured",
            LssAction::Fastscan { .. } => "fastscan",
            LssAction::Assign { .. } => "assign",
        }
    }

    /// The master service the command runs, when it is one service.
    pub fn service(&self) -> Option<Service> {
        Some(match *self {
            LssAction::Switch { config } => Service::SwitchGlobal(config),
            LssAction::Select(a) => Service::SwitchSelective(a),
            LssAction::SetNode(n) => Service::ConfigureNodeId(n),
            LssAction::SetBitrate { index, .. } => Service::ConfigureBitTiming { table: 0, index },
            LssAction::ActivateBitrate { delay_ms } => Service::ActivateBitTiming { delay_ms },
            LssAction::Store => Service::StoreConfiguration,
            LssAction::Inquire(Inquiry::Part(p)) => Service::Inquire(p),
            LssAction::Inquire(Inquiry::NodeId) => Service::InquireNodeId,
            LssAction::Inquire(Inquiry::All) => Service::InquireAddress,
            LssAction::Identify {
                vendor,
                product,
                revision,
                serial,
            } => Service::IdentifyRemote {
                vendor,
                product,
                revision,
                serial,
            },
            LssAction::IdentifyUnconfigured => Service::IdentifyNonConfigured,
            LssAction::Fastscan { .. } | LssAction::Assign { .. } => return None,
        })
    }

    /// What the command sends, for previews: the frames of its service, or a description
    /// when they depend on the answers.
    pub fn preview(&self) -> String {
        match self {
            LssAction::Fastscan { .. } => {
                "fastscan: about 130 frames 7E5#51.. (one per bit of the unknown address parts), the found slave \
                 left in configuration state"
                    .into()
            }
            LssAction::Assign { node, store, .. } => format!(
                "fastscan (about 130 frames 7E5#51..), then 7E5#11{node:02X}000000000000{}, then 7E5#0400000000000000",
                if *store { ", 7E5#1700000000000000" } else { "" }
            ),
            LssAction::Inquire(Inquiry::All) => {
                let mut frames = self.frames();
                frames.push(Frame::classic(MASTER_ID, &crate::lss::Request::InquireNodeId.encode()));
                frames.iter().map(super::spec::candump).collect::<Vec<_>>().join(", ")
            }
            _ => self
                .frames()
                .iter()
                .map(super::spec::candump)
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    /// The frames of the command's service, as the protocol layer encodes them.
    fn frames(&self) -> Vec<Frame> {
        self.service()
            .map(|s| s.requests())
            .unwrap_or_default()
            .iter()
            .map(|r| Frame::classic(MASTER_ID, &r.encode()))
            .collect()
    }
}

/// `lss SERVICE [WORDS...] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
#[command(
    subcommand_value_name = "SERVICE",
    subcommand_help_heading = "Services",
    disable_help_subcommand = true
)]
pub struct LssArgs {
    /// The LSS service and its words.
    #[command(subcommand)]
    pub service: LssService,
    /// How long to wait for each answer, in ms [default: 100; fastscan and assign: 30 per
    /// fastscan request].
    #[arg(long, global = true, value_parser = ms_arg)]
    pub timeout: Option<u64>,
}

/// An LSS master service (CiA 305), addressed to every slave in configuration state.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Lss {
    pub action: LssAction,
    pub timeout_ms: u64,
}

impl<D> CommandArgs<D> for LssArgs {
    type Spec = Lss;
    const NAME: &'static str = "lss";

    fn spec(&self) -> Result<Lss, ParseError> {
        let action = self.service.action()?;
        let default = match action {
            LssAction::Fastscan { .. } | LssAction::Assign { .. } => FASTSCAN_TIMEOUT_MS,
            _ => LSS_TIMEOUT_MS,
        };
        Ok(Lss {
            action,
            timeout_ms: self.timeout.unwrap_or(default),
        })
    }
}

impl Spec for Lss {
    /// The first request; inquire and identify only ask, the others change the state of every
    /// slave they reach and need confirming.
    fn preview(&self, _known: &Known<'_>) -> Result<Preview, CommandError> {
        let asks = matches!(
            self.action,
            LssAction::Inquire(_) | LssAction::Identify { .. } | LssAction::IdentifyUnconfigured
        );
        Ok(Preview {
            frames: self.action.preview(),
            confirm: (!asks).then(|| {
                format!(
                    "LSS {} addresses every LSS slave (in configuration state, or not yet configured)",
                    self.action.as_str()
                )
            }),
        })
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let report = lss(ctx.bus, self.action, self.timeout_ms).await?;
        let text = report.text.clone();
        Ok(Outcome::new(report, text))
    }
}

/// The result of an LSS command (`--json`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct LssReport {
    /// Always true (failures are [`CommandError`]s).
    pub ok: bool,
    /// The command word (`fastscan`, `set-node`...).
    pub command: &'static str,
    /// The master services run, in order (`configure_node_id`...).
    pub services: Vec<&'static str>,
    /// The LSS address answered (inquire all / fastscan / assign) or selected.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub address: Option<Address>,
    /// A value inquired: `vendor`, `product`, `revision` or `serial` and its value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub part: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<u32>,
    /// The node-ID inquired or configured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub node_id: Option<u8>,
    /// The bit rate configured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bit_rate: Option<&'static str>,
    /// Identify: how many slaves answered.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identified: Option<usize>,
    /// Fastscan: whether a non-configured slave was found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub found: Option<bool>,
    /// Assign: whether the configuration was stored.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stored: Option<bool>,
    /// What happened, in words.
    pub text: String,
}

impl From<LssError> for CommandError {
    fn from(e: LssError) -> Self {
        match e {
            LssError::NoAnswer { .. } => CommandError::Timeout(format!("LSS {e}")),
            LssError::Refused {
                service,
                error,
                spec,
                text,
            } => CommandError::LssRefused {
                service,
                error,
                spec,
                text,
            },
        }
    }
}

impl From<FastscanError> for CommandError {
    fn from(e: FastscanError) -> Self {
        CommandError::Timeout(format!("LSS {e}"))
    }
}

/// Runs `action`; `timeout_ms` is the wait for each answer (each fastscan request).
pub async fn lss(bus: &Bus, action: LssAction, timeout_ms: u64) -> Result<LssReport, CommandError> {
    let mut r = LssReport {
        ok: true,
        command: action.as_str(),
        ..LssReport::default()
    };
    match action {
        LssAction::Fastscan { vendor, product } => {
            r.services.push("fastscan");
            let found = fastscan(bus, [vendor, product, None, None], timeout_ms).await?;
            r.found = Some(found.is_some());
            r.address = found;
            r.text = match found {
                Some(a) => format!("found a non-configured slave, now in configuration state: {a}"),
                None => "no non-configured LSS slave answered the fastscan".into(),
            };
        }
        LssAction::Assign {
            node,
            store,
            vendor,
            product,
        } => {
            r.services.push("fastscan");
            let a = fastscan(bus, [vendor, product, None, None], timeout_ms)
                .await?
                .ok_or_else(|| {
                    CommandError::Timeout(
                        "LSS assign: no non-configured LSS slave answered the fastscan (every slave has a node-ID?)"
                            .into(),
                    )
                })?;
            r.address = Some(a);
            let mut services = vec![Service::ConfigureNodeId(node)];
            if store {
                services.push(Service::StoreConfiguration);
            }
            services.push(Service::SwitchGlobal(false));
            for s in services {
                r.services.push(s.name());
                exchange(bus, s, timeout_ms).await?;
            }
            r.node_id = Some(node);
            r.stored = Some(store);
            r.text = format!(
                "node-ID {node} configured{} on the slave with {a}; all slaves back to waiting state \
                 (the node-ID is in use after an NMT reset communication or a power cycle)",
                if store { " and stored" } else { "" }
            );
        }
        LssAction::Inquire(Inquiry::All) => {
            r.services.push(Service::InquireAddress.name());
            if let Answer::Address(a) = exchange(bus, Service::InquireAddress, timeout_ms).await? {
                r.address = Some(a);
            }
            r.services.push(Service::InquireNodeId.name());
            if let Answer::NodeId(n) = exchange(bus, Service::InquireNodeId, timeout_ms).await? {
                r.node_id = Some(n);
            }
            r.text = format!(
                "{}, node-ID {}",
                r.address.map(|a| a.to_string()).unwrap_or_default(),
                node_text(r.node_id.unwrap_or(UNCONFIGURED))
            );
        }
        _ => {
            let Some(service) = action.service() else {
                return Err(CommandError::Usage(format!(
                    "lss {}: not a single service",
                    action.as_str()
                )));
            };
            r.services.push(service.name());
            let answer = exchange(bus, service, timeout_ms).await?;
            r.text = single_text(&mut r, action, answer);
        }
    }
    Ok(r)
}

fn node_text(n: u8) -> String {
    if n == UNCONFIGURED {
        "255 (not configured)".into()
    } else {
        n.to_string()
    }
}

/// Fills `r` from a single service's answer; gives its text.
fn single_text(r: &mut LssReport, action: LssAction, answer: Answer) -> String {
    match (action, answer) {
        (_, Answer::Value(p, v)) => {
            r.part = Some(p.name());
            r.value = Some(v);
            format!("{} 0x{v:08X} ({v})", p.name())
        }
        (_, Answer::NodeId(n)) => {
            r.node_id = Some(n);
            format!("node-ID {}", node_text(n))
        }
        (_, Answer::Identified(n)) => {
            r.identified = Some(n);
            match n {
                0 => "no slave answered".to_string(),
                1 => "1 slave answered".to_string(),
                n => format!("{n} slaves answered"),
            }
        }
        (LssAction::Switch { config }, _) => format!(
            "switch state global sent: every slave to {} state",
            if config { "configuration" } else { "waiting" }
        ),
        (LssAction::Select(a), _) => {
            r.address = Some(a);
            format!("the slave with {a} is in configuration state")
        }
        (LssAction::SetNode(n), _) => {
            r.node_id = Some(n);
            format!(
                "node-ID {} configured (in use after an NMT reset communication; `lss store` keeps it)",
                node_text(n)
            )
        }
        (LssAction::SetBitrate { index, .. }, _) => {
            r.bit_rate = bit_rate_text(0, index);
            format!(
                "bit rate {} configured (`lss activate-bitrate DELAY_MS` switches, `lss store` keeps it)",
                r.bit_rate.unwrap_or("?")
            )
        }
        (LssAction::ActivateBitrate { delay_ms }, _) => {
            format!("activate bit timing sent: slaves switch after {delay_ms} ms, then wait {delay_ms} ms")
        }
        (LssAction::Store, _) => "configuration stored".into(),
        _ => "done".into(),
    }
}

/// Sends LSS master frames.
async fn send_all(bus: &Bus, frames: &[[u8; 8]]) -> Result<(), CommandError> {
    for p in frames {
        bus.send(&Frame::classic(MASTER_ID, p)).await?;
    }
    Ok(())
}

/// The data and receive time of an LSS slave answer; `None` for other frames. A closed bus
/// ends the command.
fn answer(bus: &Bus, frame: Result<Frame, BusError>) -> Result<Option<([u8; 8], u64)>, CommandError> {
    let f = match frame {
        Ok(f) => f,
        Err(BusError::Closed) => return Err(BusError::Closed.into()),
        Err(_) => return Ok(None),
    };
    if f.direction() != Direction::Rx || f.is_ext() || f.is_rtr() || f.id != SLAVE_ID {
        return Ok(None);
    }
    let Ok(data) = <[u8; 8]>::try_from(f.payload()) else {
        return Ok(None);
    };
    Ok(Some((data, if f.ts_ns == 0 { bus.now_ns() } else { f.ts_ns })))
}

/// Runs one master service to its end.
pub async fn exchange(bus: &Bus, service: Service, timeout_ms: u64) -> Result<Answer, CommandError> {
    let mut rx = bus.subscribe();
    let (mut x, first) = service.start(bus.now_ns(), timeout_ms.saturating_mul(1_000_000));
    if let Some(done) = apply(bus, first).await? {
        return Ok(done?);
    }
    loop {
        let now = bus.now_ns();
        tokio::task::yield_now().await;
        while let Some(frame) = rx.try_recv() {
            if let Some(done) = feed(bus, &mut x, frame).await? {
                return Ok(done?);
            }
        }
        if let Some(done) = apply(bus, x.on_time(now)).await? {
            return Ok(done?);
        }
        let wait = x.deadline_ns().map_or(0, |d| d.saturating_sub(now));
        if let Ok(frame) = tokio::time::timeout(Duration::from_nanos(wait), rx.recv()).await
            && let Some(done) = feed(bus, &mut x, frame).await?
        {
            return Ok(done?);
        }
    }
}

type Done = Option<Result<Answer, LssError>>;

/// Sends a step's frames; gives its result when it ends the exchange.
async fn apply(bus: &Bus, step: Step) -> Result<Done, CommandError> {
    send_all(bus, &step.send).await?;
    Ok(step.done)
}

async fn feed(
    bus: &Bus,
    x: &mut crate::lss::master::Exchange,
    frame: Result<Frame, BusError>,
) -> Result<Done, CommandError> {
    match answer(bus, frame)? {
        Some((data, ts)) => apply(bus, x.on_frame(&data, ts)).await,
        None => Ok(None),
    }
}

/// Fastscan with the parts in `known` given; the slave found is left in configuration state.
/// `None` when no non-configured slave answers (or none with the parts given).
pub async fn fastscan(bus: &Bus, known: [Option<u32>; 4], timeout_ms: u64) -> Result<Option<Address>, CommandError> {
    let mut rx = bus.subscribe();
    let (mut f, first) = Fastscan::start(known, bus.now_ns(), timeout_ms.saturating_mul(1_000_000));
    send_all(bus, &first).await?;
    loop {
        let now = bus.now_ns();
        tokio::task::yield_now().await;
        while let Some(frame) = rx.try_recv() {
            if let Some((data, _)) = answer(bus, frame)? {
                f.on_frame(&data);
            }
        }
        let step = match f.on_time(now) {
            Ok(step) => step,
            // A part given that no slave confirms: no slave with that vendor/product.
            Err(FastscanError::Lost(part))
                if Part::ALL
                    .iter()
                    .zip(known)
                    .any(|(p, k)| p.name() == part && k.is_some()) =>
            {
                return Ok(None);
            }
            Err(e) => return Err(e.into()),
        };
        send_all(bus, &step.send).await?;
        match step.done {
            Some(Found::Slave(a)) => return Ok(Some(a)),
            Some(Found::Nobody) => return Ok(None),
            None => {}
        }
        let wait = f.deadline_ns().saturating_sub(now);
        if let Ok(frame) = tokio::time::timeout(Duration::from_nanos(wait), rx.recv()).await
            && let Some((data, _)) = answer(bus, frame)?
        {
            f.on_frame(&data);
        }
    }
}

#[cfg(test)]
mod tests {
    //! The runners on the virtual bus with paused time, against LSS slaves of the protocol
    //! layer on their own endpoint.

    use super::*;
    use crate::bus::virt::VirtualBus;
    use crate::command::ExitCode;
    use crate::lss::slave::Slave;
    use std::sync::{Arc, Mutex};

    type Slaves = Arc<Mutex<Vec<Slave>>>;

    fn addr(serial: u32) -> Address {
        Address {
            vendor: 0x3A,
            product: 0x1234,
            revision: 2,
            serial,
        }
    }

    /// Runs `slaves` on their own endpoint of `vbus`: each master frame goes to every slave,
    /// their answers go out on 0x7E4.
    fn serve(vbus: &VirtualBus, slaves: Vec<Slave>) -> Slaves {
        let shared = Arc::new(Mutex::new(slaves));
        let bus = vbus.endpoint(false);
        let mut rx = bus.subscribe();
        let s = shared.clone();
        tokio::spawn(async move {
            while let Ok(f) = rx.recv().await {
                if f.id != MASTER_ID || f.direction() == Direction::Tx {
                    continue;
                }
                let answers: Vec<[u8; 8]> = s
                    .lock()
                    .unwrap()
                    .iter_mut()
                    .filter_map(|sl| sl.on_request(f.payload()))
                    .collect();
                for a in answers {
                    let _ = bus.send(&Frame::classic(SLAVE_ID, &a)).await;
                }
            }
        });
        shared
    }

    #[tokio::test(start_paused = true)]
    async fn assign_gives_fresh_slaves_node_ids_one_by_one() {
        let vbus = VirtualBus::new("vbus");
        let slaves = serve(
            &vbus,
            vec![
                Slave::new(addr(0x99), 0xFF),
                Slave::new(addr(0x1234), 0xFF),
                Slave::new(addr(7), 5),
            ],
        );
        let bus = vbus.endpoint(false);
        let first = lss(
            &bus,
            LssAction::Assign {
                node: 10,
                store: true,
                vendor: None,
                product: None,
            },
            30,
        )
        .await
        .unwrap();
        let second = lss(
            &bus,
            LssAction::Assign {
                node: 11,
                store: false,
                vendor: Some(0x3A),
                product: None,
            },
            30,
        )
        .await
        .unwrap();
        let none = lss(
            &bus,
            LssAction::Fastscan {
                vendor: None,
                product: None,
            },
            30,
        )
        .await
        .unwrap();
        let pending: Vec<u8> = slaves.lock().unwrap().iter().map(Slave::pending_node_id).collect();
        let serial_of = |n: u8| addr(if pending[0] == n { 0x99 } else { 0x1234 });
        assert_eq!(first.address, Some(serial_of(10)));
        assert_eq!(second.address, Some(serial_of(11)));
        let mut given = pending[..2].to_vec();
        given.sort();
        assert_eq!(given, [10, 11]);
        assert_eq!(pending[2], 5);
        assert_eq!(
            first.services,
            [
                "fastscan",
                "configure_node_id",
                "store_configuration",
                "switch_state_global"
            ]
        );
        assert!(
            first.text.starts_with("node-ID 10 configured and stored"),
            "{}",
            first.text
        );
        assert!(slaves.lock().unwrap().iter().all(|s| !s.in_configuration()));
        assert_eq!(none.found, Some(false));
        assert_eq!(none.text, "no non-configured LSS slave answered the fastscan");
    }

    #[tokio::test(start_paused = true)]
    async fn fastscan_with_known_vendor_and_product_then_inquire_all() {
        let vbus = VirtualBus::new("vbus");
        serve(&vbus, vec![Slave::new(addr(0x99), 0xFF)]);
        let bus = vbus.endpoint(false);
        let found = lss(
            &bus,
            LssAction::Fastscan {
                vendor: Some(0x3A),
                product: Some(0x1234),
            },
            30,
        )
        .await
        .unwrap();
        assert_eq!(found.address, Some(addr(0x99)));
        let all = lss(&bus, LssAction::Inquire(Inquiry::All), 100).await.unwrap();
        assert_eq!(all.address, Some(addr(0x99)));
        assert_eq!(all.node_id, Some(0xFF));
        assert!(all.text.ends_with("node-ID 255 (not configured)"), "{}", all.text);
        let serial = lss(&bus, LssAction::Inquire(Inquiry::Part(Part::Serial)), 100)
            .await
            .unwrap();
        assert_eq!((serial.part, serial.value), (Some("serial"), Some(0x99)));
        // A wrong vendor finds nobody.
        lss(&bus, LssAction::Switch { config: false }, 100).await.unwrap();
        let other = LssAction::Fastscan {
            vendor: Some(0x3B),
            product: None,
        };
        assert_eq!(lss(&bus, other, 30).await.unwrap().found, Some(false));
    }

    #[tokio::test(start_paused = true)]
    async fn select_then_set_node_refused_and_bit_rate() {
        let vbus = VirtualBus::new("vbus");
        let slaves = serve(&vbus, vec![Slave::new(addr(1), 4), Slave::new(addr(2), 5)]);
        let bus = vbus.endpoint(false);
        lss(&bus, LssAction::Select(addr(2)), 100).await.unwrap();
        let e = lss(&bus, LssAction::SetNode(200), 100).await.unwrap_err();
        assert_eq!(e.exit_code(), ExitCode::Abort);
        assert_eq!(
            e.to_string(),
            "LSS configure_node_id: the slave refused: node-ID out of range (1..127 or 255) (error code 1)"
        );
        let j = e.to_json();
        assert_eq!(
            (j["error"].as_str(), j["error_code"].as_u64()),
            (Some("lss_refused"), Some(1))
        );
        let r = lss(&bus, LssAction::SetBitrate { kbit: 250, index: 3 }, 100)
            .await
            .unwrap();
        assert_eq!(r.bit_rate, Some("250 kbit/s"));
        assert_eq!(slaves.lock().unwrap()[1].bit_timing, Some(3));
        assert_eq!(slaves.lock().unwrap()[0].bit_timing, None);
        let id = lss(&bus, LssAction::Inquire(Inquiry::NodeId), 100).await.unwrap();
        assert_eq!(id.node_id, Some(5));
    }

    #[tokio::test(start_paused = true)]
    async fn no_slave_in_configuration_is_a_timeout_with_a_hint() {
        let vbus = VirtualBus::new("vbus");
        serve(&vbus, vec![Slave::new(addr(1), 4)]);
        let bus = vbus.endpoint(false);
        let e = lss(&bus, LssAction::Inquire(Inquiry::NodeId), 100).await.unwrap_err();
        assert_eq!(e.exit_code(), ExitCode::Timeout);
        assert!(
            e.to_string().starts_with(
                "LSS inquire_node_id: no answer from an LSS slave within 100 ms (is a slave in configuration state?"
            ),
            "{e}"
        );
        let e = lss(&bus, LssAction::Select(addr(9)), 100).await.unwrap_err();
        assert!(e.to_string().contains("(no slave has that address)"), "{e}");
    }

    #[tokio::test(start_paused = true)]
    async fn listen_only_sends_nothing() {
        let vbus = VirtualBus::new("vbus");
        let spy = vbus.endpoint(false);
        let mut seen = spy.subscribe();
        let bus = vbus.endpoint(true);
        let e = lss(&bus, LssAction::Switch { config: true }, 100).await.unwrap_err();
        assert_eq!(e.exit_code(), ExitCode::Unavailable);
        assert!(matches!(e, CommandError::Bus(BusError::ListenOnly)), "{e:?}");
        assert!(seen.try_recv().is_none());
    }

    #[test]
    fn words_parse_and_previews_come_from_the_protocol_layer() {
        let p = |line: &str| match crate::command::parse_command(line) {
            Ok(crate::command::Command::Lss(l)) => Ok(l.action),
            Ok(other) => panic!("{line}: {other:?}"),
            Err(e) => Err(e.to_string()),
        };
        assert_eq!(p("lss switch global config"), Ok(LssAction::Switch { config: true }));
        assert_eq!(p("lss switch wait"), Ok(LssAction::Switch { config: false }));
        assert!(p("lss switch global").unwrap_err().contains("[global] config|wait"));
        assert_eq!(
            p("lss set-bitrate 250"),
            Ok(LssAction::SetBitrate { kbit: 250, index: 3 })
        );
        assert!(
            p("lss set-bitrate 300")
                .unwrap_err()
                .contains("not in the CiA 305 table")
        );
        assert!(p("lss set-node 0").unwrap_err().contains("must be 1..127"));
        assert!(p("lss store --store").is_err());
        assert_eq!(p("lss set-node 10").unwrap().preview(), "7E5#110A000000000000");
        assert_eq!(
            p("lss select 0x3A 0x1234 2 0x99").unwrap().preview(),
            "7E5#403A000000000000, 7E5#4134120000000000, 7E5#4202000000000000, 7E5#4399000000000000"
        );
    }
}
