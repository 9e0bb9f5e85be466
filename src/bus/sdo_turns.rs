//! One SDO transfer per node at a time, for every client of one bus in this process.
//!
//! A node's SDO server answers on one COB-ID: two transfers to it at once (a palette read
//! and a Watch poll, a gateway client and the Objects pane) would take each other's answers.
//! Every [`crate::bus::Bus`] handle of one opened bus shares one [`SdoTurns`]; each transfer
//! ([`crate::command::sdo`]) waits for its node's turn. A stop does not wait: its handle
//! ([`crate::bus::Bus::ahead_of_turns`]) goes first, even into a transfer under way.

use std::sync::Arc;
use tokio::sync::{Mutex, MutexGuard};

/// The turns of the 128 node-IDs (0 is never a server; it keeps the indexing plain).
#[derive(Clone)]
pub(super) struct SdoTurns {
    nodes: Arc<[Mutex<()>]>,
    /// False on a stop's handle: its transfers never wait.
    wait: bool,
}

impl Default for SdoTurns {
    fn default() -> SdoTurns {
        SdoTurns {
            nodes: (0..128).map(|_| Mutex::new(())).collect(),
            wait: true,
        }
    }
}

impl SdoTurns {
    /// `node`'s turn, held until the guard is dropped; `None` (at once) for a stop's handle.
    pub(super) async fn take(&self, node: u8) -> Option<MutexGuard<'_, ()>> {
        if !self.wait {
            return None;
        }
        Some(self.nodes[usize::from(node & 0x7F)].lock().await)
    }

    /// The same turns, not waited for.
    pub(super) fn ahead(&self) -> SdoTurns {
        SdoTurns {
            nodes: self.nodes.clone(),
            wait: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn a_node_has_one_turn_at_a_time_and_a_stop_does_not_wait() {
        let turns = SdoTurns::default();
        let held = turns.take(5).await;
        assert!(held.is_some());
        // Another node is free; node 5 is not, until the turn is given back.
        assert!(turns.take(6).await.is_some());
        let waiting = tokio::time::timeout(std::time::Duration::from_millis(20), turns.take(5)).await;
        assert!(waiting.is_err(), "node 5's second transfer must wait");
        assert!(turns.ahead().take(5).await.is_none(), "a stop goes first");
        drop(held);
        assert!(turns.take(5).await.is_some());
    }
}
