//! The report's order: PDOs that stopped because their node went silent for good dropped
//! (the silence tells it), drive faults of one node and axes with one cause merged,
//! timelines in frame order, open incidents first, then recovered, then warnings, each by
//! time; nodes named with their interface when the capture has several.

use super::timeline::Timeline;
use crate::analysis::incident::{Incident, Problem};
use crate::frame::NodeKey;

/// `incidents` (in the order they were opened) as the report shows them; `tl` tells the
/// nodes and interfaces seen.
pub(super) fn rank(mut incidents: Vec<Incident>, tl: &Timeline) -> Vec<Incident> {
    // A PDO that stops because its node went silent for good is part of that silence.
    let gone: Vec<Option<NodeKey>> = incidents
        .iter()
        .filter(|i| i.problem == Problem::Silent)
        .map(Incident::key)
        .collect();
    incidents.retain(|i| !(i.problem == Problem::PdoMissing && gone.contains(&i.key())));
    let mut out = merge_faults(incidents);
    for inc in &mut out {
        inc.events.sort_by_key(|e| e.frame);
    }
    out.retain(|i| i.count > 0 || !i.events.is_empty());
    out.sort_by_key(|i| (i.status, i.first_ns));
    // Nodes on several interfaces: each node is shown with its interface's name.
    let first = tl.nodes.keys().next().map(|k| k.iface);
    if tl.nodes.keys().any(|k| Some(k.iface) != first) {
        for inc in out.iter_mut().filter(|i| i.node.is_some()) {
            inc.iface_name = tl
                .iface_names
                .get(inc.iface as usize)
                .filter(|n| !n.is_empty())
                .cloned();
        }
    }
    out
}

/// Drive faults of one node and axes with the same cause become one incident with a count.
fn merge_faults(all: Vec<Incident>) -> Vec<Incident> {
    let mut out: Vec<Incident> = Vec::with_capacity(all.len());
    for inc in all {
        if inc.problem == Problem::DriveFault
            && let Some(prev) = out.iter_mut().find(|p| {
                p.problem == Problem::DriveFault && p.key() == inc.key() && p.axes == inc.axes && p.cause == inc.cause
            })
        {
            prev.count += inc.count;
            prev.last_ns = inc.last_ns;
            prev.status = inc.status;
            prev.title = inc.title;
            for s in inc.events {
                prev.step(s.frame, s.t_ns, s.text);
            }
            continue;
        }
        out.push(inc);
    }
    out
}
