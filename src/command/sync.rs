//! `sync --period MS [--counter N] [--count N] [--cob-id ID] [--listen DUR] [--force]`: the
//! SYNC producer, with the CiA 301 counter when asked (see [`super::cyclic`] for the timing
//! and its report), after listening for another SYNC producer ([`super::listen_first`]).

use super::cyclic::{Schedule, Source, sync_frame};
use super::error::CommandError;
use super::listen_first::{LISTEN_MS, Listen, OtherProducer};
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::{ParseError, cob_arg, count_arg, counter_arg, ms_arg, ms_or_zero_arg, not_reserved};
use crate::cob;
use crate::od::bind::Bindings;
use serde::Serialize;

/// `sync --period MS [--counter N] [--count N] [--cob-id ID] [--listen DUR] [--force]`.
#[derive(clap::Args, Clone, Debug)]
pub struct SyncArgs {
    /// The SYNC period in ms.
    #[arg(long, value_parser = ms_arg)]
    pub period: u64,
    /// Send the CiA 301 SYNC counter, counting 1..N (N = 2..240).
    #[arg(long, value_parser = counter_arg)]
    pub counter: Option<u8>,
    /// Stop after this many SYNCs.
    #[arg(long, value_parser = count_arg)]
    pub count: Option<u64>,
    /// The SYNC COB-ID (11-bit).
    #[arg(long, value_parser = cob_arg, default_value = "0x080")]
    pub cob_id: u32,
    /// How long to listen for another SYNC producer before sending (DUR; 0: do not listen).
    #[arg(long, value_parser = ms_or_zero_arg, default_value_t = LISTEN_MS)]
    pub listen: u64,
    /// Use a --cob-id that another service owns (an SDO, EMCY or heartbeat id...), and send
    /// even when another SYNC producer is heard.
    #[arg(long)]
    pub force: bool,
}

/// The SYNC producer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sync {
    pub cob_id: u32,
    /// The CiA 301 counter's overflow value (2..=240), if the counter is sent.
    pub counter: Option<u8>,
    pub schedule: Schedule,
    /// Listening for another SYNC producer first.
    pub listen: Listen,
}

/// `sync --json`: the cyclic report and the other SYNC producer heard (sent with --force).
#[derive(Debug, Serialize)]
struct SyncReport {
    #[serde(flatten)]
    sent: super::cyclic::Report,
    other_producer: Option<OtherProducer>,
}

impl<D> CommandArgs<D> for SyncArgs {
    type Spec = Sync;

    const NAME: &'static str = "sync";

    fn spec(&self) -> Result<Sync, ParseError> {
        Ok(Sync {
            cob_id: match self.cob_id {
                // SYNC's own COB-ID; any other service's needs --force.
                cob::SYNC => cob::SYNC,
                id if self.force => id,
                id => not_reserved(id, "the SYNC producer").map(|()| id)?,
            },
            counter: self.counter,
            schedule: Schedule {
                every_ms: Some(self.period),
                count: self.count,
            },
            listen: Listen {
                ms: self.listen,
                force: self.force,
            },
        })
    }
}

impl Spec for Sync {
    /// The first SYNC, the period and the counter's range.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        let counter = self.counter.map(|n| format!(", counter 1..{n}")).unwrap_or_default();
        super::spec::cyclic_preview(self, known, &counter)
    }

    /// Listens for another SYNC producer, then sends the SYNCs.
    async fn run(&self, mut ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let other =
            super::listen_first::before_sending(ctx.bus, self.cob_id, "SYNC producer", self.listen, &mut ctx.stop)
                .await?;
        let sent = super::cyclic::transmit(ctx.bus, self.frames(), ctx.progress, ctx.stop).await?;
        let mut text = sent.text();
        if let Some(o) = &other {
            text.push_str(&format!("\nsent anyway (--force): {}", o.text()));
        }
        Ok(Outcome::new(
            SyncReport {
                sent,
                other_producer: other,
            },
            text,
        ))
    }

    fn cyclic(&self) -> bool {
        true
    }

    fn source(&self, _bindings: &Bindings) -> Option<Result<Source, CommandError>> {
        Some(Ok(self.frames()))
    }
}

impl Sync {
    /// The SYNC frames on their schedule.
    fn frames(&self) -> Source {
        let (cob, counter) = (self.cob_id, self.counter);
        Source {
            what: format!("SYNC {cob:03X}"),
            next: Box::new(move |i| sync_frame(cob, counter, i)),
            defaulted: Vec::new(),
            schedule: self.schedule,
        }
    }
}
