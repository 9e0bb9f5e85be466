//! The hits of a [`Trigger`] in a stream of frames: each filter atom judges the frames as
//! `decode --filter` does ([`Stream`]), bus events come from the liveness tracker and
//! error frames ([`Views::Events`]) or the live interface ([`Detector::link`]), incidents
//! from a diagnosis of the stream ([`Views::Diagnosis`]). Only what the trigger names is
//! derived. A hit is dated when it is known: the frame that shows it, or the tick that
//! finds a heartbeat overdue.

use super::window::Hit;
use super::{Atom, BusEvent, Trigger};
use crate::analysis::Incident;
use crate::analysis::events::What;
use crate::analysis::filter::Facts;
use crate::analysis::filter::stream::Stream;
use crate::analysis::trace::{Trace, Views};
use crate::decode::Decoder;
use crate::frame::{Frame, Interfaces};

/// How often (stream time) the detector asks the diagnosis for its incidents as if the
/// capture ended then: some detectors open their incident only after a while (an EMCY
/// waits to be grouped with the fault that follows it), so an `incident KIND` hit comes at
/// most this late after the diagnosis would report it.
const SNAPSHOT_NS: u64 = 100_000_000;

/// An incident's identity across looks: kind, interface, node, first occurrence.
type IncidentKey = (crate::analysis::Problem, u16, Option<u8>, u64);

/// A change of the live interface's state (from the bus layer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// The interface went down or away.
    Down,
    /// The controller went bus-off.
    BusOff,
    /// The controller went error-passive.
    Passive,
}

/// A filter atom's pipeline: frames decoded with labels, judged in order.
struct Judged {
    trace: Trace,
    stream: Stream<u64>,
    pos: u64,
}

/// How one atom is watched.
enum Watch {
    Filter(Box<Judged>),
    Event(BusEvent),
    Incident(crate::analysis::Problem),
}

/// Finds the hits of a trigger.
pub struct Detector {
    watches: Vec<(Watch, String)>,
    /// `then B within`: ns.
    within_ns: Option<u64>,
    /// Bus events, when an atom names one a frame can show.
    events: Option<Box<Trace>>,
    /// The diagnosis, when an atom names an incident.
    diagnosis: Option<Box<Trace>>,
    /// The incidents seen so far, by (kind, interface, node, first time), with their counts.
    incidents: Vec<(IncidentKey, u64)>,
    /// Stream time of the last full look at the diagnosis ([`SNAPSHOT_NS`]).
    snapshot_ns: u64,
    /// The time and words of the last hit of A (`A then B`).
    armed: Option<(u64, String)>,
    now_ns: u64,
}

impl Detector {
    /// A detector of `trigger`, decoding with `decoder` (the profiles bound).
    pub fn new(trigger: &Trigger, decoder: &Decoder) -> Detector {
        let mut events = None;
        let mut diagnosis = None;
        let watches = trigger
            .atoms()
            .map(|a| match a {
                Atom::Filter(f) => (
                    Watch::Filter(Box::new(Judged {
                        trace: Trace::headless(decoder.clone(), Views::Frames),
                        stream: Stream::new(f.clone()),
                        pos: 0,
                    })),
                    f.source.clone(),
                ),
                Atom::Event(e) => {
                    if *e != BusEvent::IfaceDown && events.is_none() {
                        events = Some(Box::new(Trace::headless(decoder.clone(), Views::Events)));
                    }
                    (Watch::Event(*e), e.word().to_string())
                }
                Atom::Incident(p) => {
                    if diagnosis.is_none() {
                        diagnosis = Some(Box::new(Trace::headless(decoder.clone(), Views::Diagnosis)));
                    }
                    (Watch::Incident(*p), format!("incident {}", p.as_str()))
                }
            })
            .collect();
        Detector {
            watches,
            within_ns: trigger.then.as_ref().map(|(_, w)| *w),
            events,
            diagnosis,
            incidents: Vec::new(),
            snapshot_ns: 0,
            armed: None,
            now_ns: 0,
        }
    }

    /// Takes note of the frames' interface table (call it before pushing their frames).
    pub fn name_interfaces(&mut self, ifaces: &Interfaces) {
        for t in self.traces() {
            t.name_interfaces(ifaces);
        }
    }

    fn traces(&mut self) -> impl Iterator<Item = &mut Trace> {
        let filters = self.watches.iter_mut().filter_map(|(w, _)| match w {
            Watch::Filter(j) => Some(&mut j.trace),
            _ => None,
        });
        filters
            .chain(self.events.as_deref_mut())
            .chain(self.diagnosis.as_deref_mut())
    }

    /// Judges the next frame; its hits (and those it decided for earlier frames) go to `hits`.
    pub fn frame(&mut self, f: &Frame, hits: &mut Vec<Hit>) {
        self.now_ns = self.now_ns.max(f.ts_ns);
        let mut found: Vec<(usize, String)> = Vec::new();
        for (i, (w, words)) in self.watches.iter_mut().enumerate() {
            if let Watch::Filter(j) = w {
                j.trace.push(f);
                let pos = j.pos;
                j.pos += 1;
                let done = j.trace.take_transactions();
                if let Some(d) = j.trace.take_decoded() {
                    let facts = Facts {
                        ts_ns: f.ts_ns,
                        id: f.id,
                        flags: f.flags.0,
                        kind: d.kind,
                        node: d.node,
                    };
                    j.stream
                        .frame(pos, (facts, j.trace.ifaces.name(f.iface)), d, &done, |_| f.ts_ns);
                }
                found.extend(j.stream.ready().into_iter().map(|_| (i, words.clone())));
            }
        }
        if let Some(t) = &mut self.events {
            t.push(f);
        }
        if let Some(t) = &mut self.diagnosis {
            t.push(f);
        }
        self.derived(&mut found);
        self.fire(found, hits);
    }

    /// The stream's clock reached `now_ns` with no frame (a quiet live bus).
    pub fn tick(&mut self, now_ns: u64, hits: &mut Vec<Hit>) {
        self.now_ns = self.now_ns.max(now_ns);
        if let Some(t) = &mut self.events {
            t.tick(now_ns);
        }
        if let Some(t) = &mut self.diagnosis {
            t.tick(now_ns);
        }
        let mut found = Vec::new();
        self.derived(&mut found);
        self.fire(found, hits);
    }

    /// The live interface changed state at `t_ns`.
    pub fn link(&mut self, t_ns: u64, link: Link, hits: &mut Vec<Hit>) {
        self.now_ns = self.now_ns.max(t_ns);
        let want = match link {
            Link::Down => BusEvent::IfaceDown,
            Link::BusOff => BusEvent::BusOff,
            Link::Passive => BusEvent::ErrorPassive,
        };
        let found = self
            .watches
            .iter()
            .enumerate()
            .filter(|(_, (w, _))| matches!(w, Watch::Event(e) if *e == want))
            .map(|(i, (_, words))| (i, words.clone()))
            .collect();
        self.fire(found, hits);
    }

    /// The stream ended: frames still waiting for their transfer are judged as in none.
    pub fn finish(&mut self, hits: &mut Vec<Hit>) {
        let mut found = Vec::new();
        for (i, (w, words)) in self.watches.iter_mut().enumerate() {
            if let Watch::Filter(j) = w {
                found.extend(j.stream.finish().into_iter().map(|_| (i, words.clone())));
            }
        }
        self.fire(found, hits);
    }

    /// Hits of the event and incident atoms since the last call.
    fn derived(&mut self, found: &mut Vec<(usize, String)>) {
        if let Some(t) = &mut self.events {
            for e in t.events.take_events() {
                let seen = match &e.what {
                    What::HeartbeatLost { .. } => BusEvent::HeartbeatLost,
                    What::BootUp { .. } => BusEvent::BootUp,
                    What::BusState { to: "bus_off", .. } => BusEvent::BusOff,
                    What::BusState {
                        to: "error_passive", ..
                    } => BusEvent::ErrorPassive,
                    _ => continue,
                };
                for (i, (w, _)) in self.watches.iter().enumerate() {
                    if matches!(w, Watch::Event(x) if *x == seen) {
                        found.push((i, with_node(seen.word(), e.node)));
                    }
                }
            }
        }
        let Some(t) = &self.diagnosis else { return };
        let look = self.now_ns >= self.snapshot_ns.saturating_add(SNAPSHOT_NS);
        let snapshot;
        let book: &[Incident] = if look {
            self.snapshot_ns = self.now_ns;
            snapshot = t.diagnosis.incidents();
            &snapshot
        } else {
            t.diagnosis.opened()
        };
        for inc in book {
            let key = (inc.problem, inc.iface, inc.node, inc.first_ns);
            let seen = self.incidents.iter_mut().find(|(k, _)| *k == key);
            let before = seen.as_ref().map_or(0, |(_, c)| *c);
            if inc.count <= before {
                continue;
            }
            match seen {
                Some((_, c)) => *c = inc.count,
                None => self.incidents.push((key, inc.count)),
            }
            for (i, (w, _)) in self.watches.iter().enumerate() {
                if matches!(w, Watch::Incident(p) if *p == inc.problem) {
                    found.push((i, with_node(&format!("incident {}", inc.problem.as_str()), inc.node)));
                }
            }
        }
    }

    /// Turns atom hits into trigger hits: atom 0 fires alone, or arms `then`, which atom 1
    /// fires within its time (a B of the same moment as the A that arms it does not count).
    fn fire(&mut self, found: Vec<(usize, String)>, hits: &mut Vec<Hit>) {
        let t = self.now_ns;
        let Some(within) = self.within_ns else {
            hits.extend(found.into_iter().map(|(_, what)| Hit { t_ns: t, what }));
            return;
        };
        for (_, b) in found.iter().filter(|(i, _)| *i == 1) {
            if let Some((at, a)) = &self.armed
                && *at < t
                && t - at <= within
            {
                hits.push(Hit {
                    t_ns: t,
                    what: format!("{a} then {b}"),
                });
                self.armed = None;
            }
        }
        if let Some((_, a)) = found.iter().rev().find(|(i, _)| *i == 0) {
            self.armed = Some((t, a.clone()));
        }
    }
}

/// `hb lost node 3`, or the words alone for the bus.
fn with_node(words: &str, node: Option<u8>) -> String {
    match node {
        Some(n) => format!("{words} node {n}"),
        None => words.to_string(),
    }
}
