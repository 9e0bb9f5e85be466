//! Two masters on one bus: the time window that tells them apart and the `second_master`
//! warning, which the NMT ([`super::masters`]) and SDO ([`super::sdo`]) detectors both
//! write.

use super::timeline::{At, MS, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::frame::NodeKey;

/// An SDO request this soon after another one to the same node that is still going on,
/// or NMT commands this close that undo each other, come from a second master.
pub(super) const TWO_MASTERS_NS: u64 = 25 * MS;

/// Commands from two masters at `at` (`what`), for `cause`: one warning per node.
pub(super) fn second_master(tl: &mut Timeline, node: Option<NodeKey>, cause: &str, at: At, what: String) {
    let i = tl.grouped(node, Problem::SecondMaster, 0, at.t);
    let inc = &mut tl.incidents[i];
    inc.status = Status::Warning;
    inc.cause = match inc.cause.take() {
        Some(c) if c.contains(cause) => Some(c),
        Some(c) => Some(format!("{c}; {cause}")),
        None => Some(cause.to_string()),
    };
    tl.step(i, at, what);
}
