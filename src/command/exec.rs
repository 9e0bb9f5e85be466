//! Runs a parsed [`Command`] on a bus: the one entry point the command line and the
//! TUI palette share. Each result comes as one typed report (its JSON object) plus its text.

use super::cyclic::Progress;
use super::error::CommandError;
use super::registry::Command;
use super::spec::{Ctx, Outcome, Spec};
use crate::bus::Bus;
use crate::od::bind::Bindings;
use std::future::Future;

/// Runs `cmd` on `bus`; `bindings` give node dictionaries (object names, aliases, types).
/// A `record` without limits runs until its future is dropped (the log is flushed then).
pub async fn execute(bus: &Bus, cmd: &Command, bindings: &Bindings) -> Result<Outcome, CommandError> {
    execute_until(bus, cmd, bindings, Progress::default(), std::future::pending()).await
}

/// [`execute`], where a cyclic command (`send`, `sync`, `pdo`) notes its timing in
/// `progress` and stops (and reports) when `stop` completes.
pub async fn execute_until(
    bus: &Bus,
    cmd: &Command,
    bindings: &Bindings,
    progress: Progress,
    stop: impl Future<Output = ()> + Send,
) -> Result<Outcome, CommandError> {
    execute_saying(bus, cmd, bindings, progress, stop, None).await
}

/// [`execute_until`], where a command that runs in steps (`run`) says each step to `lines`
/// as it happens (its text is then the summary alone).
pub async fn execute_saying(
    bus: &Bus,
    cmd: &Command,
    bindings: &Bindings,
    progress: Progress,
    stop: impl Future<Output = ()> + Send,
    lines: Option<&mut (dyn FnMut(&str) + Send)>,
) -> Result<Outcome, CommandError> {
    let mut lines = lines;
    let stop = std::pin::pin!(stop);
    let ctx = Ctx {
        bus,
        bindings,
        progress,
        stop,
        lines: lines.as_mut().map(|l| &mut **l as &mut (dyn FnMut(&str) + Send)),
    };
    cmd.run(ctx).await
}
