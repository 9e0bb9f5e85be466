//! `send FRAME [--every MS] [--count N]`: a raw frame in candump's compact form, once, N
//! times or every MS ms (see [`super::cyclic`] for the timing and its report).

use super::cyclic::{Schedule, Source};
use super::error::CommandError;
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::{ParseError, Repeat, frame_arg};
use crate::frame::Frame;
use crate::od::bind::Bindings;

/// `send FRAME [--every MS] [--count N]`.
#[derive(clap::Args, Clone, Debug)]
pub struct SendArgs {
    /// The frame, as cansend takes it: `123#DEADBEEF`, `123#R`, 29-bit `12345678#00`.
    #[arg(value_parser = frame_arg)]
    pub frame: Frame,
    #[command(flatten)]
    pub repeat: Repeat,
}

/// A raw frame to send on a schedule.
#[derive(Clone, Debug, PartialEq)]
pub struct Send {
    pub frame: Frame,
    pub schedule: Schedule,
}

impl<D> CommandArgs<D> for SendArgs {
    type Spec = Send;

    const NAME: &'static str = "send";

    fn spec(&self) -> Result<Send, ParseError> {
        Ok(Send {
            frame: self.frame,
            schedule: self.repeat.schedule(),
        })
    }
}

impl Spec for Send {
    /// The frame and how often.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        super::spec::cyclic_preview(self, known, "")
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        super::spec::cyclic_run(self, ctx).await
    }

    fn cyclic(&self) -> bool {
        true
    }

    fn source(&self, _bindings: &Bindings) -> Option<Result<Source, CommandError>> {
        let f = self.frame;
        Some(Ok(Source {
            what: super::candump(&f),
            next: Box::new(move |_| f),
            defaulted: Vec::new(),
            schedule: self.schedule,
        }))
    }
}
