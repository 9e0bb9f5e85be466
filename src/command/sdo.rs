//! SDO transfers over a [`Bus`]: the IO around [`sdo_client::Transfer`].

use super::error::CommandError;
use super::sdo_client::{Progress, Protocol, Transfer};
use crate::bus::{Bus, Subscription};
use crate::frame::{Direction, Frame};
use std::time::Duration;
use tokio::time::timeout;

/// Reads (index, sub) of `node`; `timeout_ms` bounds the wait for each response.
pub async fn upload(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    block: bool,
    timeout_ms: u64,
) -> Result<Vec<u8>, CommandError> {
    let protocol = if block { Protocol::Block } else { Protocol::Auto };
    let (t, req) = Transfer::upload(index, sub, protocol);
    run(bus, node, index, sub, t, req, timeout_ms).await
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
    let protocol = if block { Protocol::Block } else { Protocol::Auto };
    let (t, req) = Transfer::download(index, sub, data, protocol);
    run(bus, node, index, sub, t, req, timeout_ms).await.map(|_| ())
}

async fn send(bus: &Bus, node: u8, payload: &[u8; 8]) -> Result<(), CommandError> {
    Ok(bus.send(&Frame::classic(0x600 + node as u32, payload)).await?)
}

/// The next response of `node`'s SDO server, or `None` after `wait`.
async fn next_response(rx: &mut Subscription, node: u8, wait: Duration) -> Result<Option<Frame>, CommandError> {
    let deadline = tokio::time::Instant::now() + wait;
    loop {
        match timeout(
            deadline.saturating_duration_since(tokio::time::Instant::now()),
            rx.recv(),
        )
        .await
        {
            Err(_) => return Ok(None),
            Ok(Ok(f)) if f.id == 0x580 + node as u32 && f.direction() == Direction::Rx && !f.is_ext() => {
                return Ok(Some(f));
            }
            Ok(Ok(_)) => {}
            Ok(Err(crate::bus::BusError::Closed)) => return Err(crate::bus::BusError::Closed.into()),
            // A read error of the interface: keep waiting, the timeout will tell.
            Ok(Err(_)) => {}
        }
    }
}

async fn run(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    mut t: Transfer,
    req: [u8; 8],
    timeout_ms: u64,
) -> Result<Vec<u8>, CommandError> {
    let wait = Duration::from_millis(timeout_ms);
    let mut rx = bus.subscribe();
    send(bus, node, &req).await?;
    loop {
        let Some(f) = next_response(&mut rx, node, wait).await? else {
            send(bus, node, &t.timeout_abort()).await?;
            return Err(CommandError::Timeout(format!(
                "SDO {index:04X}:{sub:02X}: node {node} did not answer within {timeout_ms} ms"
            )));
        };
        match t.on_response(f.payload()) {
            Progress::Wait => {}
            Progress::Send(frames) => {
                for p in &frames {
                    send(bus, node, p).await?;
                }
            }
            Progress::Done { data, reply } => {
                if let Some(p) = reply {
                    send(bus, node, &p).await?;
                }
                return Ok(data);
            }
            Progress::Aborted { code, by_server, reply } => {
                if let Some(p) = reply {
                    send(bus, node, &p).await?;
                }
                return Err(CommandError::Abort {
                    node,
                    index,
                    sub,
                    code,
                    by_server,
                });
            }
        }
    }
}
