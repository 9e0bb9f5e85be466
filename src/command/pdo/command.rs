//! `pdo NODE`, `pdo NODE send rpdoK NAME=VALUE ...`, `pdo NODE map PDO OBJECT...` as the
//! commander declares them: the words, the preview (the SDO frames of [`super::plan`], the
//! RPDO of [`crate::command::cyclic::rpdo`]) and the run.

use super::{MapSpec, assumed_cob, dry_run, map, plan, read_all, read_report};
use crate::command::cyclic::{Schedule, Source, rpdo};
use crate::command::error::{CommandError, ParseError};
use crate::command::grammar::{DEFAULT_TIMEOUT_MS, parse_assignments};
use crate::command::sdo::first_upload_frame;
use crate::command::spec::candump;
use crate::command::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use crate::command::words::{
    Repeat, TypedWords, inhibit_arg, ms_arg, node_arg, not_reserved, pdo_arg, pdo_cob_arg, pdo_word, transmission_arg,
    u16_arg,
};
use crate::decode::pdo_config::PdoId;
use crate::od::bind::Bindings;

/// `pdo NODE` (read every PDO), `pdo NODE send rpdoK NAME=VALUE ... [--every MS] [--count N]`,
/// `pdo NODE map PDO OBJECT... [--type T] [--event MS] [--inhibit T] [--cob-id ID] [--dry-run]`.
#[derive(clap::Args, Clone, Debug)]
pub struct PdoArgs<D: clap::Args> {
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
    /// read, map: how long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

impl<D: clap::Args> CommandArgs<D> for PdoArgs<D> {
    type Spec = Pdo;
    const NAME: &'static str = "pdo";

    fn dict(&self) -> Option<&D> {
        Some(&self.dict)
    }

    fn spec(&self) -> Result<Pdo, ParseError> {
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
                Ok(Pdo::Read {
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
                Ok(Pdo::Send(RpdoSend {
                    node: self.node,
                    num: pdo.num,
                    assignments: parse_assignments(&words)?,
                    schedule: self.repeat.schedule(),
                }))
            }
            (Some(_), Some(pdo)) => {
                refuse(&send_flags, "map")?;
                if let Some(id) = self.cob_id
                    && !self.force
                {
                    not_reserved(id, &format!("{} of node {}", pdo.title(), self.node))?;
                }
                Ok(Pdo::Map(MapSpec {
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

/// A `pdo` command.
#[derive(Clone, Debug, PartialEq)]
pub enum Pdo {
    /// `pdo NODE [--timeout MS]`: reads every PDO's communication and mapping parameters.
    Read { node: u8, timeout_ms: u64 },
    /// `pdo NODE send rpdoK NAME=VALUE ... [--every MS] [--count N]`.
    Send(RpdoSend),
    /// `pdo NODE map PDO OBJECT... [--type T] [--event MS] [--inhibit T] [--cob-id ID]
    /// [--dry-run] [--force] [--timeout MS]`: the CiA 301 remapping sequence.
    Map(MapSpec),
}

/// An RPDO encoded through the node's mapping, sent on a schedule.
#[derive(Clone, Debug, PartialEq)]
pub struct RpdoSend {
    pub node: u8,
    /// The RPDO number (1-based).
    pub num: u16,
    pub assignments: Vec<(String, String)>,
    pub schedule: Schedule,
}

/// A list of frames, candump style.
fn listed(frames: &[crate::frame::Frame]) -> String {
    frames.iter().map(candump).collect::<Vec<_>>().join(", ")
}

impl Spec for Pdo {
    /// Read: the first SDO request; send: the RPDO and its schedule; map: every write of the
    /// remapping.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        Ok(Preview::sends(match self {
            Pdo::Read { node, .. } => format!(
                "{} then the other PDO records of node {node} (0x1400-0x1BFF, until one is missing)",
                candump(&first_upload_frame(*node, 0x1400, 0, false))
            ),
            Pdo::Send(_) => return crate::command::spec::cyclic_preview(self, known, ""),
            Pdo::Map(spec) => {
                let dict = known.bindings.dictionary(spec.node);
                let writes = plan(dict, spec, assumed_cob(dict, spec))?;
                let frames: Vec<_> = writes.iter().map(|w| w.frame(spec.node)).collect();
                let read = candump(&first_upload_frame(spec.node, spec.pdo.comm_index(), 1, false));
                if spec.dry_run {
                    format!("nothing (dry run of {read}, {})", listed(&frames))
                } else {
                    format!("{read} (COB-ID), {} then reads back", listed(&frames))
                }
            }
        }))
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let mapped = |(json, text)| Outcome::new(json, text);
        Ok(match self {
            Pdo::Read { node, timeout_ms } => {
                let pdos = read_all(ctx.bus, *node, *timeout_ms).await?;
                let (json, text) = read_report(*node, ctx.bindings.dictionary(*node), &pdos);
                Outcome::new(json, text)
            }
            Pdo::Send(_) => return crate::command::spec::cyclic_run(self, ctx).await,
            Pdo::Map(spec) if spec.dry_run => mapped(dry_run(ctx.bindings.dictionary(spec.node), spec)?),
            Pdo::Map(spec) => mapped(map(ctx.bus, ctx.bindings.dictionary(spec.node), spec).await?),
        })
    }

    /// A dry run needs no bus (not even an interface that exists).
    fn answers_offline(&self) -> bool {
        matches!(self, Pdo::Map(spec) if spec.dry_run)
    }

    fn offline(&self, bindings: &Bindings) -> Option<Result<Outcome, CommandError>> {
        match self {
            Pdo::Map(spec) if spec.dry_run => {
                Some(dry_run(bindings.dictionary(spec.node), spec).map(|(json, text)| Outcome::new(json, text)))
            }
            _ => None,
        }
    }

    fn source(&self, bindings: &Bindings) -> Option<Result<Source, CommandError>> {
        let Pdo::Send(s) = self else { return None };
        Some(rpdo(bindings, s.node, s.num, &s.assignments).map(|r| {
            let f = r.frame;
            Source {
                what: format!("RPDO{} node {} {}", s.num, s.node, candump(&f)),
                next: Box::new(move |_| f),
                defaulted: r.defaulted,
                schedule: s.schedule,
            }
        }))
    }

    fn cyclic(&self) -> bool {
        matches!(self, Pdo::Send(_))
    }
}
