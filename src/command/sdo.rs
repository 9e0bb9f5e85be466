//! SDO transfers over a [`Bus`]: the IO around the pure [`SdoClient`].
//!
//! The client's clock is tokio's (nanoseconds since the transfer started), so
//! tests with paused time are deterministic.

use super::error::CommandError;
use crate::bus::{Bus, BusError};
use crate::frame::{Direction, Frame};
use crate::sdo_client::{ClientConfig, ClientOutput, Completion, Mode, SdoClient, SdoError};
use std::time::Duration;
use tokio::time::Instant;

/// Reads (index, sub) of `node`; `timeout_ms` bounds the wait for each response.
pub async fn upload(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    block: bool,
    timeout_ms: u64,
) -> Result<Vec<u8>, CommandError> {
    let mut client = SdoClient::new(config(timeout_ms));
    let first = client
        .upload(index, sub, mode(block), 0)
        .map_err(|e| CommandError::Usage(e.to_string()))?;
    match run(bus, node, client, first).await? {
        Completion::Uploaded { data, .. } => Ok(data),
        other => Err(unexpected(node, index, sub, other, timeout_ms)),
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
    let mut client = SdoClient::new(config(timeout_ms));
    let first = client
        .download(index, sub, data, mode(block), 0)
        .map_err(|e| CommandError::Usage(e.to_string()))?;
    match run(bus, node, client, first).await? {
        Completion::Downloaded { .. } => Ok(()),
        other => Err(unexpected(node, index, sub, other, timeout_ms)),
    }
}

fn config(timeout_ms: u64) -> ClientConfig {
    ClientConfig {
        timeout_ns: timeout_ms.saturating_mul(1_000_000),
        ..ClientConfig::default()
    }
}

fn mode(block: bool) -> Mode {
    if block { Mode::Block } else { Mode::Auto }
}

/// A completion of the wrong kind, or a failure, as a command error.
fn unexpected(node: u8, index: u16, sub: u8, c: Completion, timeout_ms: u64) -> CommandError {
    let Completion::Failed { error, .. } = c else {
        return CommandError::Usage("SDO client finished with the wrong kind of transfer".into());
    };
    match error {
        SdoError::Aborted { code, .. } => CommandError::Abort {
            node,
            index,
            sub,
            code,
            by_server: true,
        },
        SdoError::Protocol { code, .. } | SdoError::Cancelled { code } => CommandError::Abort {
            node,
            index,
            sub,
            code,
            by_server: false,
        },
        SdoError::Timeout => CommandError::Timeout(format!(
            "SDO {index:04X}:{sub:02X}: node {node} did not answer within {timeout_ms} ms (sent abort 0x05040000)"
        )),
    }
}

async fn send_all(bus: &Bus, node: u8, frames: &[[u8; 8]]) -> Result<(), CommandError> {
    for p in frames {
        bus.send(&Frame::classic(0x600 + node as u32, p)).await?;
    }
    Ok(())
}

/// Sends `first`, then feeds the server's answers to `client` until the transfer ends.
async fn run(bus: &Bus, node: u8, mut client: SdoClient, first: [u8; 8]) -> Result<Completion, CommandError> {
    let start = Instant::now();
    let now = || start.elapsed().as_nanos() as u64;
    let mut rx = bus.subscribe();
    send_all(bus, node, &[first]).await?;
    loop {
        // Wake up at least every 10 ms so the client's own timeout fires on time.
        let out: ClientOutput = match tokio::time::timeout(Duration::from_millis(10), rx.recv()).await {
            Ok(Ok(f)) if f.id == 0x580 + node as u32 && f.direction() == Direction::Rx && !f.is_ext() => {
                client.on_frame(f.payload(), now())
            }
            Ok(Err(BusError::Closed)) => return Err(BusError::Closed.into()),
            _ => client.poll(now()),
        };
        send_all(bus, node, &out.frames).await?;
        if let Some(done) = out.done {
            return Ok(done);
        }
    }
}
