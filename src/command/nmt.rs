//! NMT commands, optionally confirmed by the heartbeat or boot-up that follows.

use super::error::CommandError;
use super::grammar::NmtAction;
use crate::bus::Bus;
use crate::decode::heartbeat::NmtState;
use crate::frame::{Direction, Frame};
use std::collections::BTreeMap;
use std::time::Duration;

/// What `nmt --wait` saw: node -> state reported after the command.
pub type Confirmed = BTreeMap<u8, NmtState>;

/// The state a node reports when it has carried out `action` (boot-up for resets).
pub fn expected_state(action: NmtAction) -> NmtState {
    match action {
        NmtAction::Start => NmtState::Operational,
        NmtAction::Stop => NmtState::Stopped,
        NmtAction::PreOp => NmtState::PreOperational,
        NmtAction::ResetNode | NmtAction::ResetComm => NmtState::BootUp,
    }
}

/// The NMT frame of `action` to `node` (0 = all).
pub fn frame(action: NmtAction, node: u8) -> Frame {
    Frame::classic(0x000, &[action.cs(), node])
}

/// Sends `action` to `node` (0 = all). With `wait`, waits up to `timeout_ms` for the heartbeat
/// or boot-up that confirms it (node 0: every node that answers in that time).
pub async fn nmt(
    bus: &Bus,
    action: NmtAction,
    node: u8,
    wait: bool,
    timeout_ms: u64,
) -> Result<Confirmed, CommandError> {
    let mut rx = bus.subscribe();
    bus.send(&frame(action, node)).await?;
    let mut seen = Confirmed::new();
    if !wait {
        return Ok(seen);
    }
    let want = expected_state(action);
    let deadline = tokio::time::Instant::now() + Duration::from_millis(timeout_ms);
    loop {
        let left = deadline.saturating_duration_since(tokio::time::Instant::now());
        let f = match tokio::time::timeout(left, rx.recv()).await {
            Err(_) => break,
            Ok(Ok(f)) => f,
            Ok(Err(crate::bus::BusError::Closed)) => break,
            Ok(Err(_)) => continue,
        };
        if f.direction() != Direction::Rx || f.is_ext() || f.is_rtr() || !(0x701..=0x77F).contains(&f.id) {
            continue;
        }
        let from = (f.id - 0x700) as u8;
        let Some(b) = f.payload().first() else { continue };
        let state = NmtState::from_byte(*b);
        if node != 0 && from != node {
            continue;
        }
        // A heartbeat sent before the command arrived may still show the old state.
        if state == want {
            seen.insert(from, state);
            if node != 0 {
                return Ok(seen);
            }
        }
    }
    if node == 0 && !seen.is_empty() {
        return Ok(seen);
    }
    Err(CommandError::Timeout(format!(
        "NMT {}: no {} from {} within {timeout_ms} ms (is the heartbeat 0x1017 enabled?)",
        action.as_str(),
        if want == NmtState::BootUp {
            "boot-up".to_string()
        } else {
            format!("heartbeat showing {}", want.text())
        },
        if node == 0 {
            "any node".to_string()
        } else {
            format!("node {node}")
        }
    )))
}
