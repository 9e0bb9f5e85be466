//! Second-master detector (`second_master`): NMT commands that undo each other at once,
//! and (reported by [`super::sdo`]) SDO requests or segments of two clients that overlap.

use super::timeline::{At, Timeline};
use super::two_masters::{TWO_MASTERS_NS, second_master};
use crate::frame::NodeKey;

/// Finds NMT commands of two masters.
#[derive(Clone, Default)]
pub(super) struct Masters {
    /// The last NMT command: when, command specifier, target, interface.
    last_nmt: Option<(At, u8, u8, u16)>,
}

impl Masters {
    /// NMT `command` (specifier `cs`) to `target` (0: all nodes) on the current interface.
    ///
    /// A start undone at once (stop, pre-operational or a reset) for the same node, or for
    /// all nodes: two masters disagree. One master leaving pre-operational right after
    /// entering it is a normal re-configuration, and "start all" then "stop node 3" a
    /// choice of which nodes run: the other orders are not. (Equal times, a log without
    /// timestamps, say nothing.)
    pub(super) fn nmt(&mut self, tl: &mut Timeline, cs: u8, target: u8, command: &str) {
        let (at, iface) = (tl.at, tl.iface);
        if let Some((last, last_cs, last_target, last_iface)) = self.last_nmt.replace((at, cs, target, iface))
            && last_iface == iface
            && at.t > last.t
            && at.t - last.t < TWO_MASTERS_NS
            && (last_target == target || target == 0)
            && last_cs == 0x01
            && cs != 0x01
        {
            let node = [target, last_target]
                .into_iter()
                .find(|t| *t != 0)
                .map(|t| NodeKey::new(iface, t));
            // "reset node" names its target itself: "NMT reset node 2".
            let verb = command.strip_suffix(" node").unwrap_or(command);
            let text = format!(
                "NMT {verb} {} right after NMT start (#{})",
                if target == 0 {
                    "all nodes".to_string()
                } else {
                    format!("node {target}")
                },
                last.frame
            );
            second_master(tl, node, "NMT commands that undo each other", at, text);
        }
    }
}
