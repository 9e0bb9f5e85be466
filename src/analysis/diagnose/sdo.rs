//! SDO detector: transfers a node refused (`sdo_refused`, grouped per object; reads of
//! entries the node lacks sent by the capturing host are `not_present`), SDO frames that
//! follow no transfer (`sdo_garbled`), requests left unanswered (`sdo_timeout`, or
//! `missing` when nothing at all came from the node), and SDO requests of two clients
//! that overlap (reported as `second_master`).

use super::detector::Detector;
use super::texts::SdoAborts;
use super::timeline::{At, MS, PerNode, Timeline};
use super::two_masters::{TWO_MASTERS_NS, second_master};
use crate::analysis::incident::{Problem, Status, TIMELINE_KEPT};
use crate::decode::sdo::frame::{Chunk8, SdoFrame};
use crate::frame::NodeKey;
use crate::sdo::abort::{AbortClass, abort_class, abort_text};
use crate::sdo::codec::{SdoCommand, Side};
use crate::sdo::transaction::{Outcome, Transaction};
use std::collections::HashMap;

/// An SDO request still unanswered this long after it went out counts as not answered.
const SDO_TIMEOUT_NS: u64 = 1_000 * MS;
/// Distinct abort codes an SDO incident's cause names (the others are counted).
const CODES_TOLD: usize = 6;
/// Objects refused on the bus that get an incident each; the refusals of further objects
/// of a node group into one incident ("N more refusals of other objects"), so that a
/// capture of a million distinct aborts keeps about this many incidents (~1.7 KB each).
const REFUSED_KEPT: usize = 1_000;
/// The `detail` of a node's incident of the refusals beyond [`REFUSED_KEPT`] objects (no
/// object's `index << 8 | sub` is this large).
const MORE_OBJECTS: u32 = u32::MAX;
/// Distinct abort codes kept per incident (the first ones).
const CODES_KEPT: usize = 64;

/// An SDO request waiting for its answer.
#[derive(Clone, Copy, Debug)]
struct Request {
    at: At,
    /// A new request went out before this one was answered.
    replaced: bool,
    index: u16,
    sub: u8,
}

/// The last segment request of a segmented SDO transfer to a node.
#[derive(Clone, Copy, Debug)]
struct Segment {
    at: At,
    toggle: bool,
    /// The frame's bytes when it is a download segment (which carries data).
    data: Option<Chunk8>,
    /// When the node answered it.
    answered: Option<At>,
}

/// The SDO requests and segments of one node.
#[derive(Clone, Debug, Default)]
struct NodeSdo {
    pending: Option<Request>,
    /// The last SDO request was a write.
    download: bool,
    /// The last SDO request was sent by the capturing host (TX-marked: cotui itself, or
    /// the host that recorded the log).
    ours: bool,
    unanswered: Vec<Request>,
    n_unanswered: u64,
    answered_after: bool,
    /// The last segment of a segmented SDO transfer still going on.
    segmenting: Option<At>,
    /// The last segment request, for its toggle bit.
    segment: Option<Segment>,
}

impl NodeSdo {
    /// Request `r` to the node went unanswered.
    fn unanswered(&mut self, r: Request) {
        self.n_unanswered += 1;
        self.answered_after = false;
        if self.unanswered.len() < TIMELINE_KEPT {
            self.unanswered.push(r);
        }
    }
}

/// Finds SDO incidents.
#[derive(Clone, Default)]
pub(super) struct Sdos {
    /// The earliest time a pending request times out.
    deadline: Option<u64>,
    /// The abort codes and directions of each SDO incident.
    aborts: HashMap<usize, SdoAborts>,
    nodes: PerNode<NodeSdo>,
}

impl Sdos {
    /// The aborts of incident `i`, when it is an SDO incident.
    pub(super) fn aborts(&self, i: usize) -> Option<&SdoAborts> {
        self.aborts.get(&i)
    }

    /// An SDO frame of node `n`; `ours`: the frame is TX-marked (sent by the capturing
    /// host).
    pub(super) fn frame(&mut self, tl: &mut Timeline, n: NodeKey, s: &SdoFrame, ours: bool) {
        let at = tl.at;
        if s.side == Side::Server {
            tl.node(n).heard = true;
            let node = self.nodes.of(tl, n);
            node.pending = None;
            node.answered_after = true;
            if matches!(
                s.command,
                SdoCommand::DownloadSegmentResponse { .. } | SdoCommand::UploadSegmentResponse { .. }
            ) && let Some(seg) = &mut node.segment
            {
                seg.answered.get_or_insert(at);
            }
            if let SdoCommand::Abort { index, sub, code } = s.command {
                node.segmenting = None;
                node.segment = None;
                self.refused(tl, n, index, sub, code);
            } else if s.problems.iter().any(|p| p == "outside any transfer seen") {
                garbled(tl, n, format!("{} frame outside any transfer", s.command.cs_name()));
            }
            return;
        }
        match s.command {
            SdoCommand::DownloadSegment { toggle, .. } => {
                let node = self.nodes.of(tl, n);
                node.segmenting = Some(at);
                segment_request(tl, node, n, toggle, Some(s.raw));
            }
            SdoCommand::UploadSegment { toggle } => {
                let node = self.nodes.of(tl, n);
                node.segmenting = Some(at);
                segment_request(tl, node, n, toggle, None);
            }
            // A new transfer (or its end) starts the toggle bit over.
            _ if s.command.object().is_some() => self.nodes.of(tl, n).segment = None,
            _ => {}
        }
        // Only initiate frames start a request (segments carry no object themselves).
        if let Some((index, sub)) = s.command.object()
            && s.command.cs_name() != "abort"
        {
            // The other client's request may well be answered: not counted as unanswered.
            let node = self.nodes.of(tl, n);
            let overlap = overlapping_request(tl, node, n, index, sub);
            node.download = matches!(s.command.cs_name(), "initiate_download" | "block_download");
            node.ours = ours;
            if let Some(old) = node.pending.take()
                && !overlap
            {
                node.unanswered(Request { replaced: true, ..old });
            }
            node.pending = Some(Request {
                at,
                replaced: false,
                index,
                sub,
            });
            let dl = at.t + SDO_TIMEOUT_NS;
            self.deadline = Some(self.deadline.map_or(dl, |d| d.min(dl)));
        }
    }

    /// Node `n` aborted a transfer of `index:sub` with `code`.
    fn refused(&mut self, tl: &mut Timeline, n: NodeKey, index: u16, sub: u8, code: u32) {
        let at = tl.at;
        let text = abort_text(code);
        let node = self.nodes.of(tl, n);
        let (write, ours) = (node.download, node.ours);
        // A read the capturing host sent (cotui's own, or a TX-marked line of a log) of an
        // entry the node does not have: worth knowing, not a problem of the node.
        let absent = ours && !write && abort_class(code) == AbortClass::NotPresent;
        let (problem, detail) = match absent {
            true => (Problem::NotPresent, 0),
            false => (Problem::SdoRefused, (u32::from(index) << 8) | u32::from(sub)),
        };
        let more = problem == Problem::SdoRefused
            && self.aborts.len() >= REFUSED_KEPT
            && tl.keyed(Some(n), problem, detail).is_none();
        let detail = if more { MORE_OBJECTS } else { detail };
        let more = detail == MORE_OBJECTS;
        let i = tl.grouped(Some(n), problem, detail, at.t);
        let count = tl.incidents[i].count;
        let meta = self.aborts.entry(i).or_default();
        if meta.codes.len() < CODES_KEPT && !meta.codes.contains(&code) {
            meta.codes.push(code);
        }
        if absent {
            meta.entries.insert((index, sub));
        }
        if write {
            meta.writes = true;
        } else {
            meta.reads = true;
        }
        let codes: Vec<String> = meta.codes.iter().map(|c| format!("0x{c:08X}")).collect();
        let cause = match absent {
            true => format!("the node does not have them (abort {})", codes.join(", ")),
            false => {
                // Every distinct code, up to a readable few.
                let mut said: Vec<String> = meta
                    .codes
                    .iter()
                    .take(CODES_TOLD)
                    .map(|c| format!("{} (abort 0x{c:08X})", abort_text(*c)))
                    .collect();
                if meta.codes.len() > CODES_TOLD {
                    said.push(format!("{} more abort codes", meta.codes.len() - CODES_TOLD));
                }
                match more {
                    true => format!(
                        "{count} more refusals of objects beyond the first {REFUSED_KEPT} refused on the bus: {}",
                        said.join("; ")
                    ),
                    false => format!("0x{index:04X}:{sub:02X}: {}", said.join("; ")),
                }
            }
        };
        let inc = &mut tl.incidents[i];
        inc.status = if absent { Status::Info } else { Status::Open };
        inc.cause = Some(cause);
        let what = if write { "Write" } else { "Read" };
        let how = if absent { "not present" } else { "refused" };
        tl.step(
            i,
            at,
            format!("{what} of 0x{index:04X}:{sub:02X} {how}: {text} (0x{code:08X})"),
        );
    }

    /// Requests unanswered for longer than the SDO timeout at `now`.
    pub(super) fn timeouts(&mut self, tl: &mut Timeline, now: u64) {
        let late: Vec<(NodeKey, Request)> = self
            .nodes
            .iter()
            .filter_map(|(n, d)| d.pending.filter(|r| r.at.t + SDO_TIMEOUT_NS < now).map(|r| (*n, r)))
            .collect();
        for (n, r) in late {
            let node = self.nodes.of(tl, n);
            node.pending = None;
            node.unanswered(r);
        }
        self.deadline = self
            .nodes
            .iter()
            .filter_map(|(_, d)| d.pending.map(|r| r.at.t + SDO_TIMEOUT_NS))
            .min();
    }
}

impl Detector for Sdos {
    #[inline]
    fn tick(&mut self, tl: &mut Timeline, now: u64) {
        if self.deadline.is_some_and(|dl| now > dl) {
            self.timeouts(tl, now);
        }
    }

    fn transaction(&mut self, tl: &mut Timeline, t: &Transaction) {
        self.nodes.of(tl, t.key()).segmenting = None;
        if t.outcome != Outcome::Ok || t.data.is_empty() {
            return;
        }
        let detail = (u32::from(t.index) << 8) | u32::from(t.sub);
        if let Some(i) = tl.keyed(Some(t.key()), Problem::SdoRefused, detail)
            && tl.incidents[i].status == Status::Open
        {
            tl.incidents[i].status = Status::Recovered;
            let at = tl.at;
            tl.step(i, at, "A later transfer of the same object worked");
        }
    }

    fn end(&mut self, tl: &mut Timeline, end: At) {
        self.timeouts(tl, end.t);
    }

    fn end_node(&mut self, tl: &mut Timeline, n: NodeKey, end: At) {
        let Some(node) = self.nodes.get(n).filter(|d| d.n_unanswered > 0) else {
            return;
        };
        let heard = tl.nodes[&n].heard;
        let (answered_after, count) = (node.answered_after, node.n_unanswered);
        let requests = node.unanswered.clone();
        let problem = if heard { Problem::SdoTimeout } else { Problem::Missing };
        let i = tl.grouped(Some(n), problem, 0, requests[0].at.t);
        tl.incidents[i].count = count;
        tl.incidents[i].status = if heard && answered_after {
            Status::Warning
        } else {
            Status::Open
        };
        for r in &requests {
            let how = if r.replaced {
                "no answer before the next request"
            } else {
                "no answer within 1 s"
            };
            tl.step(i, r.at, format!("Request for 0x{:04X}:{:02X}: {how}", r.index, r.sub));
        }
        tl.incidents[i].last_ns = requests.last().map_or(end.t, |r| r.at.t);
    }
}

/// Node `n` sent an SDO frame that fits no transfer (`what`).
fn garbled(tl: &mut Timeline, n: NodeKey, what: String) {
    let at = tl.at;
    let i = tl.grouped(Some(n), Problem::SdoGarbled, 0, at.t);
    tl.incidents[i].status = Status::Open;
    if tl.incidents[i].cause.is_none() {
        tl.incidents[i].cause = Some(what.clone());
    }
    tl.step(i, at, format!("Node sent an SDO {what}"));
}

/// An SDO request for `index:sub` to node `n` while another one is going on (sent just
/// before and not answered, or a segmented transfer in mid-flow): two clients. True when
/// it is one. `node` is `n`'s state.
fn overlapping_request(tl: &mut Timeline, node: &mut NodeSdo, n: NodeKey, index: u16, sub: u8) -> bool {
    let at = tl.at;
    let young = |a: At| at.t.saturating_sub(a.t) < TWO_MASTERS_NS;
    let what = match (node.pending, node.segmenting) {
        (Some(r), _) if young(r.at) && (r.index, r.sub) != (index, sub) => format!(
            "Request for 0x{index:04X}:{sub:02X} while the request for 0x{:04X}:{:02X} (#{}) still waits for its answer",
            r.index, r.sub, r.at.frame
        ),
        (_, Some(s)) if young(s) => {
            format!(
                "Request for 0x{index:04X}:{sub:02X} in the middle of a segmented transfer (#{})",
                s.frame
            )
        }
        _ => return false,
    };
    node.segmenting = None;
    second_master(tl, Some(n), "SDO requests to the node overlap", at, what);
    true
}

/// A segment request with toggle bit `toggle` to node `n`. One client alternates the bit
/// and waits for each answer; the same bit again within [`TWO_MASTERS_NS`] of
/// the request before (still unanswered) or of its answer is a second client's transfer
/// interleaving. A retry after a timeout repeats the bit too, but much later; the same
/// download segment again (same bytes) is a retransmission or a frame captured twice; and
/// equal times (a log without timestamps) say nothing. `node` is `n`'s state.
fn segment_request(tl: &mut Timeline, node: &mut NodeSdo, n: NodeKey, toggle: bool, data: Option<Chunk8>) {
    let at = tl.at;
    let young = |a: At| at.t > a.t && at.t - a.t < TWO_MASTERS_NS;
    let Some(prev) = node.segment.replace(Segment {
        at,
        toggle,
        data,
        answered: None,
    }) else {
        return;
    };
    if prev.toggle != toggle || (data.is_some() && prev.data == data) {
        return;
    }
    let bit = u8::from(toggle);
    let what = match prev.answered {
        Some(a) if young(a) => format!(
            "Segment request with toggle bit {bit} again, right after the node answered the one with toggle bit {bit} (#{}): segments of another client's transfer",
            prev.at.frame
        ),
        None if young(prev.at) => format!(
            "Segment request with toggle bit {bit} while the one with the same toggle bit (#{}) still waits for its answer",
            prev.at.frame
        ),
        _ => return,
    };
    second_master(tl, Some(n), "SDO segments of two clients interleave", at, what);
}
