//! SDO transfers over a [`Bus`]: the IO around the pure [`SdoClient`].
//!
//! The client's clock is the bus's ([`Bus::now_ns`]), the clock of the frames' receive
//! timestamps, so answers are judged by when they arrived, not by when this task got round
//! to reading them: before declaring a timeout, the loop lets the bus reader pass on what
//! it has and consumes every queued frame. On the virtual bus the clock follows tokio's, so
//! tests with paused time are deterministic.

use super::error::CommandError;
use crate::bus::{Bus, BusError, Subscription};
use crate::frame::{Direction, Frame};
use crate::sdo_client::{ClientConfig, Completion, Mode, SdoClient, SdoError};
use std::time::Duration;

/// How long an SDO transfer may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    /// The longest wait for each answer of the server, in ms.
    pub timeout_ms: u64,
    /// The longest the whole transfer may take, in ms; `None`: the client's default
    /// (see [`ClientConfig::default_deadline_ns`]).
    pub deadline_ms: Option<u64>,
}

impl Timing {
    /// `timeout_ms` for each answer and the default overall deadline.
    pub fn answer(timeout_ms: u64) -> Timing {
        Timing {
            timeout_ms,
            deadline_ms: None,
        }
    }
}

/// Reads (index, sub) of `node`; `timeout_ms` bounds the wait for each response, the default
/// deadline the whole transfer.
pub async fn upload(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    block: bool,
    timeout_ms: u64,
) -> Result<Vec<u8>, CommandError> {
    upload_within(bus, node, index, sub, block, Timing::answer(timeout_ms)).await
}

/// Reads (index, sub) of `node` within `timing`.
pub async fn upload_within(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    block: bool,
    timing: Timing,
) -> Result<Vec<u8>, CommandError> {
    let mut rx = bus.subscribe();
    let mut client = SdoClient::new(config(timing));
    let first = client
        .upload(index, sub, mode(block), bus.now_ns())
        .map_err(|e| CommandError::Usage(e.to_string()))?;
    match run(bus, &mut rx, node, client, first).await? {
        Completion::Uploaded { data, .. } => Ok(data),
        other => Err(unexpected(node, index, sub, other, timing)),
    }
}

/// Writes `data` to (index, sub) of `node`: expedited up to 4 bytes, segmented above, block with `block`.
pub async fn download(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    data: Vec<u8>,
    block: bool,
    timeout_ms: u64,
) -> Result<(), CommandError> {
    download_within(bus, node, index, sub, data, block, Timing::answer(timeout_ms)).await
}

/// Writes `data` to (index, sub) of `node` within `timing`.
pub async fn download_within(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    data: Vec<u8>,
    block: bool,
    timing: Timing,
) -> Result<(), CommandError> {
    let mut rx = bus.subscribe();
    let mut client = SdoClient::new(config(timing));
    let first = client
        .download(index, sub, data, mode(block), bus.now_ns())
        .map_err(|e| CommandError::Usage(e.to_string()))?;
    match run(bus, &mut rx, node, client, first).await? {
        Completion::Downloaded { .. } => Ok(()),
        other => Err(unexpected(node, index, sub, other, timing)),
    }
}

fn config(timing: Timing) -> ClientConfig {
    ClientConfig {
        timeout_ns: timing.timeout_ms.saturating_mul(1_000_000),
        deadline_ns: timing.deadline_ms.map(|ms| ms.saturating_mul(1_000_000)),
        ..ClientConfig::default()
    }
}

fn mode(block: bool) -> Mode {
    if block { Mode::Block } else { Mode::Auto }
}

/// A completion of the wrong kind, or a failure, as a command error.
fn unexpected(node: u8, index: u16, sub: u8, c: Completion, timing: Timing) -> CommandError {
    let Completion::Failed { error, .. } = c else {
        return CommandError::Usage("SDO client finished with the wrong kind of transfer".into());
    };
    let abort = |code, by_server, reason| CommandError::Abort {
        node,
        index,
        sub,
        code,
        by_server,
        reason,
    };
    match error {
        SdoError::Aborted { code, .. } => abort(code, true, None),
        SdoError::Protocol { code, reason } => abort(code, false, Some(reason)),
        SdoError::Cancelled { code } => abort(code, false, None),
        SdoError::Timeout => CommandError::Timeout(format!(
            "SDO {index:04X}:{sub:02X}: node {node} did not answer within {} ms (sent abort 0x05040000)",
            timing.timeout_ms
        )),
        SdoError::Deadline { limit_ns } => CommandError::Timeout(format!(
            "SDO {index:04X}:{sub:02X}: node {node} kept the transfer going past its {} ms deadline \
             (sent abort 0x05040000; --deadline sets it)",
            limit_ns / 1_000_000
        )),
    }
}

async fn send_all(bus: &Bus, node: u8, frames: &[[u8; 8]]) -> Result<(), CommandError> {
    for p in frames {
        bus.send(&Frame::classic(0x600 + node as u32, p)).await?;
    }
    Ok(())
}

/// Sends `first`, then feeds the frames of `rx` to `client` until the transfer ends.
///
/// A timeout is declared only at a moment `now` after every frame received before `now`
/// went to the client: `now` is read first, the bus reader gets a turn (a SocketCAN frame
/// the kernel stamped before `now` is then queued), and the queue is drained.
async fn run(
    bus: &Bus,
    rx: &mut Subscription,
    node: u8,
    mut client: SdoClient,
    first: [u8; 8],
) -> Result<Completion, CommandError> {
    send_all(bus, node, &[first]).await?;
    loop {
        let now = bus.now_ns();
        tokio::task::yield_now().await;
        while let Some(frame) = rx.try_recv() {
            if let Some(done) = feed(bus, node, &mut client, frame).await? {
                return Ok(done);
            }
        }
        let out = client.poll(now);
        send_all(bus, node, &out.frames).await?;
        if let Some(done) = out.done {
            return Ok(done);
        }
        let wait = client.next_deadline().map_or(0, |d| d.saturating_sub(now));
        if let Ok(frame) = tokio::time::timeout(Duration::from_nanos(wait), rx.recv()).await
            && let Some(done) = feed(bus, node, &mut client, frame).await?
        {
            return Ok(done);
        }
    }
}

/// Gives one bus frame to `client`: the server's answers, and the echoes of our own
/// requests (their timestamps say when they reached the bus); returns the result once done.
/// A read error of the interface is passed over (the timeouts still run); a closed bus ends the transfer.
async fn feed(
    bus: &Bus,
    node: u8,
    client: &mut SdoClient,
    frame: Result<Frame, BusError>,
) -> Result<Option<Completion>, CommandError> {
    let f = match frame {
        Ok(f) if !f.is_ext() => f,
        Err(BusError::Closed) => return Err(BusError::Closed.into()),
        _ => return Ok(None),
    };
    let ts = if f.ts_ns == 0 { bus.now_ns() } else { f.ts_ns };
    match f.direction() {
        Direction::Rx if f.id == 0x580 + node as u32 => {
            let out = client.on_frame(f.payload(), ts);
            send_all(bus, node, &out.frames).await?;
            Ok(out.done)
        }
        Direction::Tx if f.id == 0x600 + node as u32 => {
            client.on_sent(ts);
            Ok(None)
        }
        _ => Ok(None),
    }
}
