//! The incident builder: decoded frames, SDO transactions and bus events in, a short
//! ranked list of [`Incident`]s out. Pure: time only comes from frame timestamps.
//!
//! What it finds: nodes that never answer (missing), heartbeats that stop (for good, or
//! for a while), unexpected reboots, refused SDO transfers (grouped per object), SDO
//! requests left unanswered, CiA 402 faults with their cause (EMCY, 0x603F) and the fault
//! resets that followed, EMCY not tied to a fault, CAN error frames and controller states,
//! duplicate node-IDs (boot-ups close together, conflicting heartbeat states) and NMT
//! commands a node did not follow.

use super::events::{Event, What};
use super::incident::{Incident, Problem, Status};
use super::liveness::EventTracker;
use super::texts::SdoAborts;
use super::timing::{PdoGap, PdoKey, PdoTiming, PeriodFrom, SyncTiming};
use crate::decode::cia402::DriveState;
use crate::decode::emcy::Emcy;
use crate::decode::heartbeat::NmtState;
use crate::decode::sdo::frame::{Chunk8, SdoFrame};
use crate::decode::stall::{self, Observation, Step};
use crate::decode::{Body, Decoded, Decoder, Kind};
use crate::frame::{Flags, Frame, NodeKey};
use crate::od::{Dictionary, PdoMapping};
use crate::sdo::abort::{AbortClass, abort_class, abort_text};
use crate::sdo::codec::{SdoCommand, Side};
use crate::sdo::transaction::{Outcome, Transaction, TransferDirection};
use std::collections::{BTreeMap, HashMap};

const MS: u64 = 1_000_000;
/// An SDO request still unanswered this long after it went out counts as not answered.
const SDO_TIMEOUT_NS: u64 = 1_000 * MS;
/// An EMCY this close before a fault is taken as its cause.
const EMCY_CAUSE_NS: u64 = 100 * MS;
/// Faults on several axes of one node this close together are one incident.
const AXES_TOGETHER_NS: u64 = 50 * MS;
/// Two boot-ups of one node-ID this close together come from two devices.
const DUPLICATE_BOOT_NS: u64 = 100 * MS;
/// A boot-up this soon after an NMT reset was asked for.
const RESET_BOOT_NS: u64 = 5_000 * MS;
/// A node has this long (and two heartbeats) to follow an NMT command.
const NMT_GRACE_NS: u64 = 100 * MS;
/// A fault reset this soon after the fault cleared belongs to it (one SYNC cycle).
const SAME_CYCLE_NS: u64 = 20 * MS;
/// An SDO request this soon after another one to the same node that is still going on,
/// or NMT commands this close that undo each other, come from a second master.
const TWO_MASTERS_NS: u64 = 25 * MS;
/// A drive has this long to show the state its controlword asked for.
const STALL_NS: u64 = 1_000 * MS;
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
/// Axes of a multi-axis drive (objects 0x6000 + 0x800 * (axis - 1)).
const AXES: u16 = 8;

/// A frame seen: its number and time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct At {
    frame: u64,
    t: u64,
}

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

/// An NMT command a node should follow.
#[derive(Clone, Copy, Debug)]
struct Expect {
    at: At,
    target: NmtState,
    command: &'static str,
    wrong: u8,
}

/// A CiA 402 axis.
#[derive(Clone, Debug, Default)]
struct Axis {
    cw: Option<u16>,
    /// The open fault incident.
    fault: Option<usize>,
    /// A cleared fault waiting for "operation enabled".
    cleared: Option<usize>,
    /// The last statusword.
    sw: Option<u16>,
    /// A state change the controlword asked for and the statusword has not shown yet:
    /// when, what, and the statusword then.
    asked: Option<(At, Step, Option<u16>)>,
    /// The open "stuck" incident, until the drive reaches the state asked for.
    stuck: Option<usize>,
}

/// What one node has shown so far.
#[derive(Clone, Debug, Default)]
struct Node {
    heard: bool,
    /// A heartbeat (not a boot-up) came since the last boot-up.
    beating: bool,
    last_hb: Option<At>,
    last_state: Option<(u64, NmtState)>,
    /// The heartbeat state before the last change.
    state_before: Option<NmtState>,
    conflicts: u32,
    last_boot: Option<u64>,
    reset_asked: Option<u64>,
    pending: Option<Request>,
    /// The last SDO request was a write.
    download: bool,
    /// The last SDO request was sent by the capturing host (TX-marked: cotui itself, or
    /// the host that recorded the log).
    ours: bool,
    /// Last frame of any kind sent by the node.
    last_any: Option<At>,
    /// 0x1017 = 0 seen on the bus, and when.
    heartbeat_off: Option<At>,
    guarded: bool,
    unanswered: Vec<Request>,
    n_unanswered: u64,
    answered_after: bool,
    expect: Option<Expect>,
    ignored: Option<(usize, NmtState)>,
    cia402: bool,
    axes: BTreeMap<u8, Axis>,
    /// EMCY not yet given to an incident (a fault may follow at once).
    emcy: Vec<(At, Emcy)>,
    /// The last EMCY error code.
    last_emcy: Option<u16>,
    /// The last segment of a segmented SDO transfer still going on.
    segmenting: Option<At>,
    /// The last segment request, for its toggle bit.
    segment: Option<Segment>,
    silence: Option<(At, u64, f64)>,
}

/// Drive-fault details used for its title.
#[derive(Clone, Debug, Default)]
struct FaultMeta {
    resets: u32,
    emcy: Option<u16>,
}

/// Builds incidents from the frames of one capture, in order. Incremental: frames go in
/// one at a time ([`Diagnoser::frame`], [`Diagnoser::skip`]), the capture clock advances
/// on a quiet bus with [`Diagnoser::tick`], and [`Diagnoser::incidents`] tells what is
/// wrong so far without ending the capture.
#[derive(Clone)]
pub struct Diagnoser {
    tracker: EventTracker,
    at: At,
    /// The capture time reached by [`Diagnoser::tick`] (ns), 0 before any tick.
    now: u64,
    first_ns: Option<u64>,
    nodes: BTreeMap<NodeKey, Node>,
    incidents: Vec<Incident>,
    keyed: HashMap<(Option<NodeKey>, Problem, u32), usize>,
    faults: HashMap<usize, FaultMeta>,
    /// The abort codes and directions of each SDO incident.
    aborts: HashMap<usize, SdoAborts>,
    error_frames: u64,
    bus_state: BTreeMap<String, &'static str>,
    sdo_deadline: Option<u64>,
    /// The last NMT reset addressed to all nodes, per interface.
    reset_all: BTreeMap<u16, u64>,
    /// Longest silence per node that came back (ms).
    silent_max: BTreeMap<NodeKey, f64>,
    sync: SyncTiming,
    pdos: PdoTiming,
    /// The incident of each PDO that stopped, while it is missing.
    pdo_gaps: HashMap<PdoKey, usize>,
    /// The profile's "check first" steps for the EMCY code of an incident.
    device_check: HashMap<usize, Vec<String>>,
    /// The last NMT command: when, command specifier, target, interface.
    last_nmt: Option<(At, u8, u8, u16)>,
    /// The synchronous window length 0x1007 written to each node (ns), and the last SYNC.
    sync_window: BTreeMap<NodeKey, u64>,
    last_sync: Option<At>,
    /// The interface of the frame being read (index into the source's table).
    iface: u16,
    /// Interface names by index, as far as known (to name nodes when there are several).
    iface_names: Vec<String>,
    /// Interfaces seen so far: their nodes got the dictionaries' defaults.
    ifaces_seen: u16,
    /// The dictionaries' sync windows (ns) and TPDO transmission types per node-ID: each
    /// interface's nodes start from them.
    defaults: Vec<NodeDefaults>,
}

/// Index offset of `axis` (1-based) in the CiA 402 range.
fn axis_of(index: u16, base: u16) -> Option<u8> {
    let off = index.checked_sub(base)?;
    (off % 0x800 == 0 && off / 0x800 < AXES).then(|| (off / 0x800 + 1) as u8)
}

/// A dictionary's default sync window (µs) and TPDO transmission types (PDO number, type).
type SyncDefaults = (Option<u64>, Vec<(u16, u8)>);

/// A node-ID's default sync window (ns) and TPDO transmission types, for each interface.
type NodeDefaults = (u8, Option<u64>, Vec<(u16, u8)>);

/// The sync window (0x1007, µs) and the transmission types of the TPDOs (0x1800.. sub 2)
/// that `dict` gives as default values (EDS `DefaultValue`, profile `default`).
fn sync_defaults(dict: &Dictionary) -> SyncDefaults {
    let default = |index: u16, sub: u8| dict.object(index, sub)?.default.as_ref()?.as_i64();
    let window = default(0x1007, 0)
        .and_then(|v| u64::try_from(v).ok())
        .filter(|v| *v > 0);
    // Only indexes some layer names (objects or index ranges) can have a default.
    let mut indexes: Vec<u16> = Vec::new();
    for layer in dict.layers() {
        indexes.extend(
            layer
                .objects
                .range((0x1800, 2)..=(0x19FF, 2))
                .filter(|(k, _)| k.1 == 2)
                .map(|(k, _)| k.0),
        );
        for r in layer
            .ranges
            .iter()
            .filter(|r| r.subs.get(&2).is_some_and(|o| o.default.is_some()))
        {
            indexes.extend(r.first.max(0x1800)..=r.last.min(0x19FF));
        }
    }
    indexes.sort_unstable();
    indexes.dedup();
    let types = indexes
        .into_iter()
        .filter_map(|i| Some((i - 0x1800 + 1, u8::try_from(default(i, 2)?).ok()?)))
        .collect();
    (window, types)
}

/// One frame of interface `iface` into the diagnosis, decoded only as far as it can tell
/// the diagnosis something (SDO frames tracked without labels, SYNC, TIME, LSS, unknown
/// COB-IDs and PDOs that [`Diagnoser::wants_pdo`] declines only routed). Returns the
/// frame's full decoding when it made one. The SDO transactions the frame completed stay
/// in the decoder: the caller takes them ([`Decoder::take_transactions`]) and hands them
/// to [`Diagnoser::transaction`]. `peeked` is what [`Decoder::peek`] says of the frame.
pub fn feed(
    decoder: &mut Decoder,
    diag: &mut Diagnoser,
    frame: &Frame,
    peeked: (Kind, Option<u8>, u16),
    iface: &str,
) -> Option<Decoded> {
    let (kind, node, pdo) = peeked;
    diag.name_interface(frame.iface, iface);
    let skip = match kind {
        Kind::Sync | Kind::Time | Kind::Lss | Kind::Other => true,
        Kind::SdoRx | Kind::SdoTx => {
            let s = decoder.sdo_frame(frame);
            diag.sdo(frame, node.unwrap_or(0), kind == Kind::SdoRx, s.as_ref());
            return None;
        }
        Kind::Tpdo | Kind::Rpdo => {
            let n = NodeKey::of(frame, node.unwrap_or(0));
            !diag.wants_pdo(n, pdo, decoder.mapping(n, kind == Kind::Tpdo, pdo))
        }
        _ => false,
    };
    if skip {
        diag.skip(frame, kind, node, pdo);
        return None;
    }
    let d = decoder.decode(frame);
    diag.frame(frame, iface, &d);
    Some(d)
}

impl Diagnoser {
    /// A builder for nodes that use `dict(node)`: their default heartbeat periods (0x1017),
    /// sync windows (0x1007) and TPDO transmission types (0x1800.. sub 2) hold until the
    /// bus shows other values.
    pub fn new<'a>(dict: impl Fn(u8) -> &'a Dictionary) -> Diagnoser {
        let mut d = Diagnoser::with_tracker(EventTracker::new(&dict));
        // Unbound nodes share one dictionary: each distinct one is read once.
        let mut seen: Vec<(Vec<*const crate::od::Profile>, SyncDefaults)> = Vec::new();
        for n in 1..128u8 {
            let dict = dict(n);
            let layers: Vec<_> = dict.layers().iter().map(std::sync::Arc::as_ptr).collect();
            let known = match seen.iter().position(|(l, _)| *l == layers) {
                Some(i) => i,
                None => {
                    seen.push((layers, sync_defaults(dict)));
                    seen.len() - 1
                }
            };
            let (window, types) = &seen[known].1;
            if window.is_some() || !types.is_empty() {
                d.defaults.push((n, window.map(|us| us * 1000), types.clone()));
            }
        }
        d.apply_defaults(0);
        d.ifaces_seen = 1;
        d
    }

    /// The nodes of interface `iface` start from the dictionaries' defaults.
    fn apply_defaults(&mut self, iface: u16) {
        for (n, window, types) in &self.defaults {
            let key = NodeKey::new(iface, *n);
            if let Some(ns) = window {
                self.sync_window.insert(key, *ns);
            }
            for (num, t) in types {
                self.pdos.transmission_type((key, true, *num), *t);
            }
        }
    }

    /// Names interface `iface` (as the frames of the source call it); a node of a capture
    /// with several interfaces is then shown with its interface's name.
    pub fn name_interface(&mut self, iface: u16, name: &str) {
        let i = iface as usize;
        if i >= self.iface_names.len() {
            self.iface_names.resize(i + 1, String::new());
        }
        if self.iface_names[i].is_empty() {
            self.iface_names[i] = name.to_string();
        }
    }

    fn with_tracker(tracker: EventTracker) -> Diagnoser {
        Diagnoser {
            tracker,
            at: At::default(),
            now: 0,
            first_ns: None,
            nodes: BTreeMap::new(),
            incidents: Vec::new(),
            keyed: HashMap::new(),
            faults: HashMap::new(),
            aborts: HashMap::new(),
            error_frames: 0,
            bus_state: BTreeMap::new(),
            sdo_deadline: None,
            silent_max: BTreeMap::new(),
            reset_all: BTreeMap::new(),
            sync: SyncTiming::default(),
            pdos: PdoTiming::default(),
            pdo_gaps: HashMap::new(),
            device_check: HashMap::new(),
            last_nmt: None,
            sync_window: BTreeMap::new(),
            last_sync: None,
            iface: 0,
            iface_names: Vec::new(),
            ifaces_seen: 0,
            defaults: Vec::new(),
        }
    }

    /// Time of the first frame (ns): the origin of the times in the report.
    pub fn origin_ns(&self) -> u64 {
        self.first_ns.unwrap_or(0)
    }

    /// Frames seen so far.
    pub fn frames(&self) -> u64 {
        self.at.frame
    }

    fn node(&mut self, n: NodeKey) -> &mut Node {
        self.nodes.entry(n).or_default()
    }

    fn open(&mut self, node: Option<NodeKey>, problem: Problem, t: u64) -> usize {
        self.incidents.push(Incident {
            node: node.map(|k| k.node),
            iface: node.map_or(0, |k| k.iface),
            iface_name: None,
            axes: Vec::new(),
            problem,
            status: Status::Open,
            title: String::new(),
            cause: None,
            events: Vec::new(),
            check: Vec::new(),
            why: String::new(),
            count: 0,
            first_ns: t,
            last_ns: t,
        });
        self.incidents.len() - 1
    }

    /// The incident for `key`, made on first use; counts one more occurrence at `t`.
    fn grouped(&mut self, node: Option<NodeKey>, problem: Problem, detail: u32, t: u64) -> usize {
        let i = match self.keyed.get(&(node, problem, detail)) {
            Some(i) => *i,
            None => {
                let i = self.open(node, problem, t);
                self.keyed.insert((node, problem, detail), i);
                i
            }
        };
        let inc = &mut self.incidents[i];
        inc.count += 1;
        inc.last_ns = inc.last_ns.max(t);
        i
    }

    fn step(&mut self, i: usize, at: At, text: impl Into<String>) {
        self.incidents[i].step(at.frame, at.t, text);
    }

    /// The tracker's events, if any (checked per frame: most frames make none).
    #[inline]
    fn take_events(&mut self) {
        if self.tracker.pending() > 0 {
            for e in self.tracker.take_events() {
                self.event(&e);
            }
        }
    }

    /// Frame number and time advance to `frame`'s.
    #[inline]
    fn advance(&mut self, frame: &Frame) {
        self.iface = frame.iface;
        if frame.iface >= self.ifaces_seen {
            self.new_interfaces(frame.iface);
        }
        self.at = At {
            frame: self.at.frame + 1,
            t: frame.ts_ns,
        };
        self.first_ns.get_or_insert(frame.ts_ns);
        if self.sdo_deadline.is_some_and(|dl| frame.ts_ns > dl) {
            self.sdo_timeouts(frame.ts_ns);
        }
        self.pdos_due(frame.ts_ns);
    }

    /// Interfaces up to `iface` are seen: their nodes get the dictionaries' defaults.
    #[cold]
    fn new_interfaces(&mut self, iface: u16) {
        for i in self.ifaces_seen..=iface {
            self.apply_defaults(i);
        }
        self.ifaces_seen = iface.saturating_add(1);
    }

    /// PDOs overdue at `now` become (or add to) incidents.
    #[inline]
    fn pdos_due(&mut self, now: u64) {
        for gap in self.pdos.due(now) {
            self.pdo_gap(gap);
        }
    }

    fn pdo_name((_, transmit, num): PdoKey) -> String {
        format!("{}PDO{num}", if transmit { "T" } else { "R" })
    }

    fn pdo_gap(&mut self, gap: PdoGap) {
        match gap {
            PdoGap::Missing {
                key,
                last_frame,
                last_ns,
                period_ns,
                from,
            } => {
                let n = key.0;
                let node = self.node(n);
                // PDOs flow in "operational" only; a silent node is its own incident.
                if node.last_state.is_some_and(|(_, s)| s != NmtState::Operational) || node.silence.is_some() {
                    return;
                }
                let name = Self::pdo_name(key);
                let detail = (u32::from(key.1) << 16) | u32::from(key.2);
                let i = self.grouped(Some(n), Problem::PdoMissing, detail, last_ns);
                let every = match from {
                    PeriodFrom::EventTimer => format!("at least every {:.1} ms (event time)", period_ns as f64 / 1e6),
                    PeriodFrom::Measured => format!("every {:.1} ms (measured)", period_ns as f64 / 1e6),
                };
                let inc = &mut self.incidents[i];
                inc.status = Status::Open;
                inc.title = format!("{name} stopped arriving");
                if inc.cause.is_none() {
                    inc.cause = Some(format!("{name} expected {every}"));
                }
                let at = At {
                    frame: last_frame,
                    t: last_ns,
                };
                self.step(i, at, format!("Last {name} before the gap"));
                self.pdo_gaps.insert(key, i);
            }
            PdoGap::Back { key, gap_ns } => {
                let Some(i) = self.pdo_gaps.remove(&key) else { return };
                let name = Self::pdo_name(key);
                let at = self.at;
                let inc = &mut self.incidents[i];
                inc.status = Status::Warning;
                inc.last_ns = at.t;
                inc.title = if inc.count == 1 {
                    format!("{name} stopped for a while, then came again")
                } else {
                    format!("{name} stopped {} times, came again each time", inc.count)
                };
                self.step(i, at, format!("{name} again after {:.3} s", gap_ns as f64 / 1e9));
            }
        }
    }

    /// A PDO of `node` arrived (number `num`, TPDO when `transmit`).
    fn pdo_arrived(&mut self, node: NodeKey, transmit: bool, num: u16) {
        let at = self.at;
        if transmit
            && let (Some(&window), Some(sync)) = (self.sync_window.get(&node), self.last_sync)
            && at.t.saturating_sub(sync.t) > window
            && self.pdos.synchronous((node, transmit, num))
        {
            let name = Self::pdo_name((node, transmit, num));
            let i = self.grouped(Some(node), Problem::PdoLate, u32::from(num), at.t);
            let inc = &mut self.incidents[i];
            inc.status = Status::Warning;
            inc.title = match inc.count {
                1 => format!("{name} sent after the SYNC window closed"),
                n => format!("{name} sent after the SYNC window closed ({n} times)"),
            };
            inc.cause = Some(format!("synchronous window 0x1007 = {} µs", window / 1000));
            let late = at.t.saturating_sub(sync.t) as f64 / 1e6;
            self.step(i, at, format!("{name} {late:.3} ms after the SYNC (#{})", sync.frame));
        }
        if num > 0
            && let Some(gap) = self.pdos.pdo((node, transmit, num), at.frame, at.t)
        {
            self.pdo_gap(gap);
        }
    }

    /// True when a PDO of `node` can tell the diagnosis something: its `mapping` holds a
    /// CiA 402 controlword, statusword or error code, or (mapping unknown) it is the
    /// predefined TPDO1/RPDO1 of a CiA 402 device. Other PDOs need no decoding.
    pub fn wants_pdo(&self, node: NodeKey, num: u16, mapping: Option<&PdoMapping>) -> bool {
        match mapping {
            Some(m) => m
                .entries
                .iter()
                .any(|e| [0x6040, 0x6041, 0x603F].iter().any(|b| axis_of(e.index, *b).is_some())),
            None => num == 1 && self.nodes.get(&node).is_some_and(|d| d.cia402),
        }
    }

    /// A frame left undecoded (SYNC, TIME, LSS, unknown COB-IDs, PDOs that
    /// [`Diagnoser::wants_pdo`] declines): time and frame number advance, and a TPDO
    /// still shows that its node is there.
    /// `pdo` is the PDO number (from [`crate::decode::Decoder::peek`]), 0 for other frames.
    pub fn skip(&mut self, frame: &Frame, kind: Kind, node: Option<u8>, pdo: u16) {
        self.advance(frame);
        self.tracker.tick(frame.ts_ns);
        self.take_events();
        let node = node.map(|n| NodeKey::of(frame, n));
        match (kind, node) {
            (Kind::Sync, _) => {
                self.sync.sync(self.at.frame, frame.ts_ns);
                self.last_sync = Some(self.at);
            }
            (Kind::Tpdo | Kind::Rpdo, Some(n)) => self.pdo_arrived(n, kind == Kind::Tpdo, pdo),
            _ => {}
        }
        if let (Kind::Tpdo, Some(n)) = (kind, node) {
            let at = self.at;
            let node = self.node(n);
            node.heard = true;
            node.last_any = Some(at);
        }
    }

    /// One frame, in capture order, with its decoding; `iface` names its interface.
    pub fn frame(&mut self, frame: &Frame, iface: &str, d: &Decoded) {
        self.name_interface(frame.iface, iface);
        self.advance(frame);
        self.tracker.frame(frame, iface, d);
        self.take_events();
        let Some(n) = d.node else {
            if d.kind == Kind::Sync {
                self.sync.sync(self.at.frame, frame.ts_ns);
                self.last_sync = Some(self.at);
            }
            if let Body::Nmt(nmt) = &d.body {
                self.nmt(nmt.cs, nmt.target);
            }
            if d.kind == Kind::ErrorFrame {
                self.error_frame(&d.label);
            }
            return;
        };
        let n = NodeKey::of(frame, n);
        let at = self.at;
        if matches!(d.kind, Kind::Tpdo | Kind::SdoTx | Kind::Emcy)
            || matches!(&d.body, Body::Heartbeat(h) if !h.request)
        {
            self.node(n).last_any = Some(at);
        }
        if matches!(&d.body, Body::Heartbeat(h) if h.request) {
            self.node(n).guarded = true;
        }
        match &d.body {
            Body::Heartbeat(h) if !h.request => {
                self.node(n).heard = true;
                if let Some(s) = h.state {
                    self.heartbeat(n, s);
                }
            }
            Body::Emcy(e) => {
                self.node(n).heard = true;
                self.emcy(n, e);
            }
            Body::Sdo(s) => self.sdo_body(n, s, frame.flags.has(Flags::TX)),
            Body::Pdo(p) => {
                if p.transmit {
                    self.node(n).heard = true;
                }
                self.pdo_arrived(n, p.transmit, p.num);
                let mut words = Vec::new();
                for s in &p.signals {
                    let Some(v) = s.value.as_i64() else { continue };
                    words.push((s.index, v as u16));
                }
                if p.signals.is_empty() && p.num == 1 && self.node(n).cia402 && frame.payload().len() >= 2 {
                    // CiA 402 predefined mapping: TPDO1 starts with the statusword, RPDO1
                    // with the controlword.
                    let w = u16::from_le_bytes([frame.payload()[0], frame.payload()[1]]);
                    words.push((if p.transmit { 0x6041 } else { 0x6040 }, w));
                }
                for (index, w) in words {
                    self.drive_word(n, index, w);
                }
            }
            _ => {
                if matches!(d.kind, Kind::Tpdo | Kind::SdoTx) {
                    self.node(n).heard = true;
                }
            }
        }
    }

    /// An SDO frame of node `n` read by [`crate::decode::Decoder::sdo_frame`] (None: a
    /// vendor command of the node's profile): the cheap twin of [`Diagnoser::frame`] for
    /// SDO frames, which needs no label. `to_node` tells a client request.
    pub fn sdo(&mut self, frame: &Frame, n: u8, to_node: bool, s: Option<&SdoFrame>) {
        let n = NodeKey::of(frame, n);
        self.advance(frame);
        self.tracker.tick(frame.ts_ns);
        self.take_events();
        if !to_node {
            let at = self.at;
            let node = self.node(n);
            node.last_any = Some(at);
            node.heard = true;
        }
        if let Some(s) = s {
            self.sdo_body(n, s, frame.flags.has(Flags::TX));
        }
    }

    /// `ours`: the frame is TX-marked (sent by the capturing host).
    fn sdo_body(&mut self, n: NodeKey, s: &SdoFrame, ours: bool) {
        let at = self.at;
        if s.side == Side::Server {
            let node = self.node(n);
            node.heard = true;
            node.pending = None;
            node.answered_after = true;
            if matches!(
                s.command,
                SdoCommand::DownloadSegmentResponse { .. } | SdoCommand::UploadSegmentResponse { .. }
            ) && let Some(seg) = &mut self.node(n).segment
            {
                seg.answered.get_or_insert(at);
            }
            if let SdoCommand::Abort { index, sub, code } = s.command {
                let node = self.node(n);
                node.segmenting = None;
                node.segment = None;
                self.refused(n, index, sub, code);
            } else if s.problems.iter().any(|p| p == "outside any transfer seen") {
                self.garbled(n, format!("{} frame outside any transfer", s.command.cs_name()));
            }
        } else {
            match s.command {
                SdoCommand::DownloadSegment { toggle, .. } => {
                    self.node(n).segmenting = Some(at);
                    self.segment_request(n, toggle, Some(s.raw));
                }
                SdoCommand::UploadSegment { toggle } => {
                    self.node(n).segmenting = Some(at);
                    self.segment_request(n, toggle, None);
                }
                // A new transfer (or its end) starts the toggle bit over.
                _ if s.command.object().is_some() => self.node(n).segment = None,
                _ => {}
            }
            // Only initiate frames start a request (segments carry no object themselves).
            if let Some((index, sub)) = s.command.object()
                && s.command.cs_name() != "abort"
            {
                // The other client's request may well be answered: not counted as unanswered.
                let overlap = self.overlapping_request(n, index, sub);
                self.node(n).download = matches!(s.command.cs_name(), "initiate_download" | "block_download");
                self.node(n).ours = ours;
                if let Some(old) = self.node(n).pending.take()
                    && !overlap
                {
                    self.unanswered(n, Request { replaced: true, ..old });
                }
                self.node(n).pending = Some(Request {
                    at,
                    replaced: false,
                    index,
                    sub,
                });
                let dl = at.t + SDO_TIMEOUT_NS;
                self.sdo_deadline = Some(self.sdo_deadline.map_or(dl, |d| d.min(dl)));
            }
        }
    }

    /// A statusword `sw` of an axis asked to change state: reached (a stuck incident
    /// recovers), a fault (the fault incident tells it), or still not there after
    /// [`STALL_NS`]: the drive is stuck, with the reason the bus shows.
    fn stall(&mut self, n: NodeKey, axis: u8, sw: u16, state: DriveState) {
        let at = self.at;
        let nmt = self.nodes.get(&n).and_then(|d| d.last_state.map(|(_, s)| s));
        let emcy = self.nodes.get(&n).and_then(|d| d.last_emcy);
        let a = self.node(n).axes.entry(axis).or_default();
        a.sw = Some(sw);
        let stuck = a.stuck;
        let cw = a.cw;
        let Some((asked, step, before)) = a.asked else {
            return;
        };
        let faulted = matches!(state, DriveState::Fault | DriveState::FaultReactionActive);
        if stall::reached(&step, state) || faulted {
            a.asked = None;
            a.stuck = None;
            if let Some(i) = stuck.filter(|_| !faulted) {
                self.incidents[i].status = Status::Recovered;
                self.incidents[i].last_ns = at.t;
                let waited = (at.t - asked.t) as f64 / 1e9;
                let inc = &mut self.incidents[i];
                inc.title = format!("{}; reached {} after {waited:.2} s", inc.title, state.text());
                self.step(i, at, format!("Reached {} after {waited:.2} s", state.text()));
            }
            return;
        }
        if stuck.is_some() || at.t.saturating_sub(asked.t) < STALL_NS {
            return;
        }
        let obs = Observation {
            nmt,
            before,
            statusword: Some(sw),
            controlword: cw,
            emcy,
            ..Observation::default()
        };
        let reason = stall::diagnose(n.node, &step, &obs);
        let detail = (u32::from(axis) << 8) | u32::from(step.controlword as u8);
        let i = self.grouped(Some(n), Problem::DriveStuck, detail, asked.t);
        let inc = &mut self.incidents[i];
        if !inc.axes.contains(&axis) {
            inc.axes.push(axis);
        }
        inc.status = Status::Open;
        inc.last_ns = at.t;
        inc.title = format!(
            "Stuck in {}: {} (controlword 0x{:04X}) not followed",
            state.text(),
            step.name,
            step.controlword
        );
        inc.cause = Some(reason);
        self.step(
            i,
            asked,
            format!(
                "Controlword 0x{:04X} ({}) asks for {}",
                step.controlword,
                step.name,
                step.target.text()
            ),
        );
        let waited = (at.t - asked.t) as f64 / 1e9;
        self.step(
            i,
            at,
            format!("Still {} (statusword 0x{sw:04X}) after {waited:.2} s", state.text()),
        );
        self.node(n).axes.entry(axis).or_default().stuck = Some(i);
    }

    /// An SDO request for `index:sub` to node `n` while another one is going on (sent
    /// just before and not answered, or a segmented transfer in mid-flow): two clients.
    /// True when it is one.
    fn overlapping_request(&mut self, n: NodeKey, index: u16, sub: u8) -> bool {
        let at = self.at;
        let node = self.node(n);
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
        self.second_master(Some(n), "SDO requests to the node overlap", at, what);
        true
    }

    /// A segment request with toggle bit `toggle` to node `n`. One client alternates the
    /// bit and waits for each answer; the same bit again within [`TWO_MASTERS_NS`] of the
    /// request before (still unanswered) or of its answer is a second client's transfer
    /// interleaving. A retry after a timeout repeats the bit too, but much later; the same
    /// download segment again (same bytes) is a retransmission or a frame captured twice;
    /// and equal times (a log without timestamps) say nothing.
    fn segment_request(&mut self, n: NodeKey, toggle: bool, data: Option<Chunk8>) {
        let at = self.at;
        let young = |a: At| at.t > a.t && at.t - a.t < TWO_MASTERS_NS;
        let Some(prev) = self.node(n).segment.replace(Segment {
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
        self.second_master(Some(n), "SDO segments of two clients interleave", at, what);
    }

    fn second_master(&mut self, node: Option<NodeKey>, cause: &str, at: At, what: String) {
        let i = self.grouped(node, Problem::SecondMaster, 0, at.t);
        let inc = &mut self.incidents[i];
        inc.status = Status::Warning;
        inc.cause = match inc.cause.take() {
            Some(c) if c.contains(cause) => Some(c),
            Some(c) => Some(format!("{c}; {cause}")),
            None => Some(cause.to_string()),
        };
        self.step(i, at, what);
    }

    /// A CiA 402 object value of `node` (from a PDO or an SDO transfer).
    fn drive_word(&mut self, n: NodeKey, index: u16, w: u16) {
        if let Some(axis) = axis_of(index, 0x6041) {
            self.statusword(n, axis, w);
        } else if let Some(axis) = axis_of(index, 0x6040) {
            self.controlword(n, axis, w);
        } else if let Some(axis) = axis_of(index, 0x603F) {
            let fault = self.node(n).axes.get(&axis).and_then(|a| a.fault);
            if let Some(i) = fault
                && w != 0
            {
                let text = format!("drive error code 0x{w:04X} (0x{index:04X})");
                let inc = &mut self.incidents[i];
                if !inc.cause.as_deref().is_some_and(|c| c.contains(&text)) {
                    inc.cause = Some(match inc.cause.take() {
                        Some(c) => format!("{c}; {text}"),
                        None => text.clone(),
                    });
                    let at = self.at;
                    self.step(i, at, format!("Drive reports {text}"));
                }
            }
        }
    }

    fn statusword(&mut self, n: NodeKey, axis: u8, sw: u16) {
        let at = self.at;
        let state = DriveState::from_statusword(sw);
        self.stall(n, axis, sw, state);
        let faulted = matches!(state, DriveState::Fault | DriveState::FaultReactionActive);
        let a = self.node(n).axes.entry(axis).or_default().clone();
        match (a.fault, faulted) {
            (None, true) => {
                // Another axis of the node faulted just now: one incident.
                let together = self.nodes[&n].axes.values().filter_map(|x| x.fault).find(|i| {
                    at.t.saturating_sub(self.incidents[*i].first_ns) <= AXES_TOGETHER_NS
                        && self.incidents[*i].status == Status::Open
                });
                let i = match together {
                    Some(i) => {
                        self.incidents[i].axes.push(axis);
                        self.step(i, at, format!("Axis {axis} faulted too (statusword 0x{sw:04X})"));
                        i
                    }
                    None => {
                        let i = self.open(Some(n), Problem::DriveFault, at.t);
                        self.incidents[i].count = 1;
                        self.incidents[i].axes.push(axis);
                        self.faults.insert(i, FaultMeta::default());
                        self.step(
                            i,
                            at,
                            format!("Fault: the drive switched the motor torque off (statusword 0x{sw:04X})"),
                        );
                        self.absorb_emcy(n, i);
                        i
                    }
                };
                let ax = self.node(n).axes.entry(axis).or_default();
                ax.fault = Some(i);
                ax.cleared = None;
            }
            (Some(i), false) => {
                let ax = self.node(n).axes.entry(axis).or_default();
                ax.fault = None;
                ax.cleared = Some(i);
                // The incident is recovered once every faulted axis is clear.
                let still = self.nodes[&n].axes.values().any(|x| x.fault == Some(i));
                if !still {
                    self.incidents[i].status = Status::Recovered;
                    self.incidents[i].last_ns = at.t;
                    self.step(
                        i,
                        at,
                        format!("Fault cleared (statusword 0x{sw:04X}, {})", state.text()),
                    );
                }
            }
            _ => {}
        }
        if state == DriveState::OperationEnabled
            && let Some(i) = self.node(n).axes.get_mut(&axis).and_then(|a| a.cleared.take())
        {
            let others_running = self.nodes[&n].axes.values().any(|x| x.cleared == Some(i));
            if !others_running {
                self.step(i, at, "Running again (operation enabled)");
            }
        }
    }

    fn controlword(&mut self, n: NodeKey, axis: u8, cw: u16) {
        let at = self.at;
        let ax = self.node(n).axes.entry(axis).or_default().clone();
        if ax.cw != Some(cw)
            && let Some(step) = stall::requested(cw)
        {
            let a = self.node(n).axes.entry(axis).or_default();
            let done =
                a.sw.is_some_and(|sw| stall::reached(&step, DriveState::from_statusword(sw)));
            a.asked = (!done).then_some((at, step, a.sw));
        }
        let rising = cw & 0x80 != 0 && ax.cw.is_none_or(|p| p & 0x80 == 0);
        self.node(n).axes.entry(axis).or_default().cw = Some(cw);
        // A reset in the same cycle as the clear (the statusword went out first) counts too.
        let just_cleared = ax
            .cleared
            .filter(|i| at.t.saturating_sub(self.incidents[*i].last_ns) <= SAME_CYCLE_NS);
        let Some(i) = ax.fault.or(just_cleared).filter(|_| rising) else {
            return;
        };
        let meta = self.faults.entry(i).or_default();
        meta.resets += 1;
        let r = meta.resets;
        let text = if ax.fault.is_none() {
            format!("Fault reset #{r} sent, in the same cycle as the clear")
        } else if r > 1 {
            format!(
                "Fault reset #{r} sent; reset #{} did not work, the fault was still there",
                r - 1
            )
        } else {
            "Fault reset #1 sent (controlword bit 7)".to_string()
        };
        self.step(i, at, text);
    }

    fn emcy(&mut self, n: NodeKey, e: &Emcy) {
        let at = self.at;
        self.node(n).last_emcy = Some(e.code);
        self.flush_emcy(n, at.t.saturating_sub(EMCY_CAUSE_NS));
        if e.code == 0 {
            // "Error reset or no error": the node's EMCY incidents are over.
            self.flush_emcy(n, u64::MAX);
            let mine: Vec<usize> = (0..self.incidents.len())
                .filter(|i| {
                    let inc = &self.incidents[*i];
                    inc.key() == Some(n) && inc.problem == Problem::Emcy && inc.status == Status::Open
                })
                .collect();
            for i in mine {
                self.incidents[i].status = Status::Recovered;
                self.step(i, at, "Error reset: the node reports no error any more (EMCY 0x0000)");
            }
            return;
        }
        let fault = self.nodes[&n]
            .axes
            .values()
            .filter_map(|a| a.fault)
            .find(|i| self.incidents[*i].cause.is_none());
        match fault {
            Some(i) => self.give_cause(i, at, e),
            None => self.node(n).emcy.push((at, e.clone())),
        }
    }

    fn emcy_text(e: &Emcy) -> String {
        let mut s = format!("{} (EMCY 0x{:04X})", e.text, e.code);
        for (k, v) in &e.mfr_fields {
            s.push_str(&format!(", {k}={v}"));
        }
        s
    }

    fn give_cause(&mut self, i: usize, at: At, e: &Emcy) {
        if !e.check.is_empty() {
            self.device_check.insert(i, e.check.clone());
        }
        self.incidents[i].cause = Some(Self::emcy_text(e));
        self.faults.entry(i).or_default().emcy = Some(e.code);
        self.step(i, at, format!("Cause reported: {}", Self::emcy_text(e)));
    }

    /// A fault just started: a recent EMCY of the node is its cause.
    fn absorb_emcy(&mut self, n: NodeKey, i: usize) {
        let t = self.at.t;
        self.flush_emcy(n, t.saturating_sub(EMCY_CAUSE_NS));
        if let Some((at, e)) = self.node(n).emcy.pop() {
            self.give_cause(i, at, &e);
        }
        self.flush_emcy(n, u64::MAX);
    }

    /// EMCY of `n` older than `before` become EMCY incidents (grouped per code).
    fn flush_emcy(&mut self, n: NodeKey, before: u64) {
        let node = self.node(n);
        let keep = node
            .emcy
            .iter()
            .position(|(at, _)| at.t >= before)
            .unwrap_or(node.emcy.len());
        let old: Vec<(At, Emcy)> = node.emcy.drain(..keep).collect();
        for (at, e) in old {
            let i = self.grouped(Some(n), Problem::Emcy, u32::from(e.code), at.t);
            if !e.check.is_empty() {
                self.device_check.insert(i, e.check.clone());
            }
            let inc = &mut self.incidents[i];
            inc.status = Status::Open;
            inc.cause = Some(Self::emcy_text(&e));
            self.step(i, at, format!("EMCY {}", Self::emcy_text(&e)));
        }
    }

    fn heartbeat(&mut self, n: NodeKey, s: NmtState) {
        let at = self.at;
        let node = self.node(n);
        node.last_hb = Some(at);
        node.beating = s != NmtState::BootUp;
        if s != NmtState::BootUp {
            // Two devices with one node-ID: heartbeat states that flip back and forth
            // (A, B, A, B...), which one node changing state never does.
            if let (Some((_, s1)), Some(s2)) = (node.last_state, node.state_before)
                && s != s1
                && s == s2
            {
                node.conflicts += 1;
                if node.conflicts == 3 {
                    let i = self.grouped(Some(n), Problem::DuplicateId, 0, at.t);
                    self.step(
                        i,
                        at,
                        format!("Heartbeats keep flipping between {} and {}", s1.text(), s.text()),
                    );
                }
            }
            let node = self.node(n);
            if node.last_state.is_some_and(|(_, s1)| s1 != s) {
                node.state_before = node.last_state.map(|(_, s1)| s1);
            }
            self.node(n).last_state = Some((at.t, s));
        }
        let node = self.node(n);
        if let Some((i, target)) = node.ignored
            && target == s
        {
            node.ignored = None;
            self.incidents[i].status = Status::Warning;
            self.step(i, at, format!("Reached {} later", s.text()));
        }
        let node = self.node(n);
        let Some(mut ex) = node.expect else { return };
        if ex.target == s {
            node.expect = None;
            return;
        }
        if s == NmtState::BootUp {
            return;
        }
        ex.wrong += 1;
        node.expect = Some(ex);
        if ex.wrong >= 2 && at.t.saturating_sub(ex.at.t) >= NMT_GRACE_NS {
            node.expect = None;
            let i = self.grouped(
                Some(n),
                Problem::NmtIgnored,
                u32::from(ex.target.as_str().len() as u8),
                at.t,
            );
            self.incidents[i].status = Status::Open;
            self.incidents[i].cause = Some(format!("NMT {} sent, node stays {}", ex.command, s.text()));
            self.step(i, ex.at, format!("NMT {} sent", ex.command));
            self.step(i, at, format!("Node still says {}", s.text()));
            self.node(n).ignored = Some((i, ex.target));
        }
    }

    fn nmt(&mut self, cs: u8, target: u8) {
        let (command, state) = match cs {
            0x01 => ("start", NmtState::Operational),
            0x02 => ("stop", NmtState::Stopped),
            0x80 => ("enter pre-operational", NmtState::PreOperational),
            0x81 => ("reset node", NmtState::BootUp),
            0x82 => ("reset communication", NmtState::BootUp),
            _ => return,
        };
        let iface = self.iface;
        if cs != 0x01 {
            self.pdos.pause(iface, (target != 0).then_some(target));
        }
        let at = self.at;
        // A start undone at once (stop, pre-operational or a reset) for the same node, or
        // for all nodes: two masters disagree. One master leaving pre-operational right
        // after entering it is a normal re-configuration, and "start all" then "stop node
        // 3" a choice of which nodes run: the other orders are not. (Equal times, a log
        // without timestamps, say nothing.)
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
            self.second_master(node, "NMT commands that undo each other", at, text);
        }
        let known: Vec<NodeKey> = self
            .nodes
            .iter()
            .filter(|(n, d)| n.iface == iface && (target == 0 || n.node == target) && d.last_state.is_some())
            .map(|(n, _)| *n)
            .collect();
        if state == NmtState::BootUp {
            if target == 0 {
                self.reset_all.insert(iface, at.t);
            } else {
                self.node(NodeKey::new(iface, target)).reset_asked = Some(at.t);
            }
        }
        for n in known {
            self.node(n).expect = Some(Expect {
                at,
                target: state,
                command,
                wrong: 0,
            });
        }
    }

    fn event(&mut self, e: &Event) {
        let Some(n) = e.key() else {
            if let What::BusState { iface, to, detail, .. } = &e.what {
                self.bus_state.insert(iface.clone(), to);
                let i = self.grouped(None, Problem::BusErrors, 0, e.t_ns);
                self.incidents[i].count -= 1;
                let at = At {
                    frame: self.at.frame,
                    t: e.t_ns,
                };
                self.step(
                    i,
                    at,
                    format!("{iface}: controller now {} ({detail})", to.replace('_', " ")),
                );
            }
            return;
        };
        let at = At {
            frame: self.at.frame,
            t: e.t_ns,
        };
        match &e.what {
            // A heartbeat that has not started since the boot-up did not stop.
            What::HeartbeatLost { .. } if !self.node(n).beating => {}
            What::HeartbeatLost { silent_ms, .. } => {
                let last = self.node(n).last_hb.unwrap_or(at);
                self.node(n).silence = Some((last, e.t_ns, *silent_ms));
            }
            What::HeartbeatBack { silent_ms } => self.back(n, at, *silent_ms),
            What::BootUp { rebooted, .. } => {
                self.pdos.pause(n.iface, Some(n.node));
                let reset_all = self.reset_all.get(&n.iface).copied();
                let node = self.node(n);
                // (Equal times say nothing: logs without timestamps.)
                let close = node
                    .last_boot
                    .is_some_and(|t| at.t > t && at.t - t <= DUPLICATE_BOOT_NS);
                let asked = node
                    .reset_asked
                    .max(reset_all)
                    .is_some_and(|t| at.t.saturating_sub(t) <= RESET_BOOT_NS);
                node.last_boot = Some(at.t);
                node.expect = None;
                node.last_state = None;
                node.state_before = None;
                // A silence that ends in a boot-up is part of the restart (expected when
                // a reset was asked for).
                let silence = node.silence.take();
                if asked {
                    node.reset_asked = None;
                }
                if close {
                    let i = self.grouped(Some(n), Problem::DuplicateId, 0, at.t);
                    self.step(i, at, "A second boot-up with the same node-ID right after the first");
                } else if *rebooted && !asked {
                    let i = self.grouped(Some(n), Problem::Rebooted, 0, at.t);
                    self.incidents[i].status = Status::Warning;
                    if let Some((last, _, _)) = silence {
                        self.step(i, last, "Last heartbeat before the restart");
                    }
                    self.step(i, at, "Boot-up: the node restarted, no NMT reset was sent before");
                }
            }
            _ => {}
        }
    }

    fn back(&mut self, n: NodeKey, at: At, silent_ms: f64) {
        let Some((last, lost, _)) = self.node(n).silence.take() else {
            return;
        };
        let i = self.grouped(Some(n), Problem::SilentBack, 0, lost);
        let longest = self.silent_max.entry(n).or_insert(0.0);
        *longest = longest.max(silent_ms);
        let inc = &mut self.incidents[i];
        inc.status = Status::Warning;
        inc.cause = Some(format!("no heartbeat for up to {:.2} s", *longest / 1000.0));
        self.step(
            i,
            at,
            format!(
                "No heartbeat for {:.2} s (last #{}), then it came back",
                silent_ms / 1000.0,
                last.frame
            ),
        );
    }

    fn refused(&mut self, n: NodeKey, index: u16, sub: u8, code: u32) {
        let at = self.at;
        let text = abort_text(code);
        let (write, ours) = (self.node(n).download, self.node(n).ours);
        // A read the capturing host sent (cotui's own, or a TX-marked line of a log) of an
        // entry the node does not have: worth knowing, not a problem of the node.
        let absent = ours && !write && abort_class(code) == AbortClass::NotPresent;
        let (problem, detail) = match absent {
            true => (Problem::NotPresent, 0),
            false => (Problem::SdoRefused, (u32::from(index) << 8) | u32::from(sub)),
        };
        let more = problem == Problem::SdoRefused
            && self.aborts.len() >= REFUSED_KEPT
            && !self.keyed.contains_key(&(Some(n), problem, detail));
        let detail = if more { MORE_OBJECTS } else { detail };
        let more = detail == MORE_OBJECTS;
        let i = self.grouped(Some(n), problem, detail, at.t);
        let count = self.incidents[i].count;
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
        let inc = &mut self.incidents[i];
        inc.status = if absent { Status::Info } else { Status::Open };
        inc.cause = Some(cause);
        let what = if write { "Write" } else { "Read" };
        let how = if absent { "not present" } else { "refused" };
        self.step(
            i,
            at,
            format!("{what} of 0x{index:04X}:{sub:02X} {how}: {text} (0x{code:08X})"),
        );
    }

    fn garbled(&mut self, n: NodeKey, what: String) {
        let at = self.at;
        let i = self.grouped(Some(n), Problem::SdoGarbled, 0, at.t);
        self.incidents[i].status = Status::Open;
        if self.incidents[i].cause.is_none() {
            self.incidents[i].cause = Some(what.clone());
        }
        self.step(i, at, format!("Node sent an SDO {what}"));
    }

    fn error_frame(&mut self, label: &str) {
        self.error_frames += 1;
        let at = self.at;
        let i = self.grouped(None, Problem::BusErrors, 0, at.t);
        if self.incidents[i].count == 1 {
            self.incidents[i].cause = Some(label.to_string());
            self.step(i, at, format!("CAN bus errors detected: {label}"));
        }
    }

    /// Requests unanswered for longer than the SDO timeout at `now`.
    fn sdo_timeouts(&mut self, now: u64) {
        let late: Vec<(NodeKey, Request)> = self
            .nodes
            .iter()
            .filter_map(|(n, d)| d.pending.filter(|r| r.at.t + SDO_TIMEOUT_NS < now).map(|r| (*n, r)))
            .collect();
        for (n, r) in late {
            self.node(n).pending = None;
            self.unanswered(n, r);
        }
        self.sdo_deadline = self
            .nodes
            .values()
            .filter_map(|d| d.pending.map(|r| r.at.t + SDO_TIMEOUT_NS))
            .min();
    }

    fn unanswered(&mut self, n: NodeKey, r: Request) {
        let node = self.node(n);
        node.n_unanswered += 1;
        node.answered_after = false;
        if node.unanswered.len() < super::incident::TIMELINE_KEPT {
            node.unanswered.push(r);
        }
    }

    /// A completed SDO transfer (in order, right after the frame that ended it).
    pub fn transaction(&mut self, t: &Transaction) {
        self.node(t.key()).segmenting = None;
        self.tracker.transaction(t);
        self.take_events();
        if t.outcome != Outcome::Ok || t.data.is_empty() {
            return;
        }
        let le = |d: &[u8]| d.iter().take(4).rev().fold(0u32, |a, b| a << 8 | u32::from(*b));
        let v = le(&t.data);
        if (t.index, t.sub, t.direction) == (0x1000, 0, TransferDirection::Upload) {
            self.node(t.key()).cia402 = v & 0xFFFF == 402;
        }
        if t.sub == 0 {
            self.drive_word(t.key(), t.index, v as u16);
        }
        match (t.index, t.sub) {
            (0x1800..=0x19FF, 5) => self
                .pdos
                .event_timer((t.key(), true, t.index - 0x1800 + 1), u64::from(v & 0xFFFF)),
            (0x1800..=0x19FF, 2) => self
                .pdos
                .transmission_type((t.key(), true, t.index - 0x1800 + 1), v as u8),
            (0x1007, 0) if v > 0 => {
                self.sync_window.insert(t.key(), u64::from(v) * 1000);
            }
            (0x1007, 0) => {
                self.sync_window.remove(&t.key());
            }
            (0x1400..=0x15FF, 5) => self
                .pdos
                .event_timer((t.key(), false, t.index - 0x1400 + 1), u64::from(v & 0xFFFF)),
            _ => {}
        }
        if (t.index, t.sub) == (0x1017, 0) {
            let at = self.at;
            self.node(t.key()).heartbeat_off = (v & 0xFFFF == 0).then_some(at);
        }
        let key = (
            Some(t.key()),
            Problem::SdoRefused,
            (u32::from(t.index) << 8) | u32::from(t.sub),
        );
        if let Some(&i) = self.keyed.get(&key)
            && self.incidents[i].status == Status::Open
        {
            self.incidents[i].status = Status::Recovered;
            let at = self.at;
            self.step(i, at, "A later transfer of the same object worked");
        }
    }

    /// The capture clock reached `now_ns` with no frame since the last one (a quiet bus in
    /// a live capture or a running replay): heartbeats and SDO answers overdue by then are
    /// missed.
    pub fn tick(&mut self, now_ns: u64) {
        if now_ns <= self.now.max(self.at.t) {
            return;
        }
        self.now = now_ns;
        self.tracker.tick(now_ns);
        self.take_events();
        if self.sdo_deadline.is_some_and(|dl| now_ns > dl) {
            self.sdo_timeouts(now_ns);
        }
        self.pdos_due(now_ns);
    }

    /// The incidents so far, ranked as [`Diagnoser::finish`] ranks them, as if the capture
    /// ended now (the builder goes on).
    pub fn incidents(&self) -> Vec<Incident> {
        self.clone().finish()
    }

    /// SYNC intervals off the period become one warning with the jitter figures.
    fn sync_jitter(&mut self) {
        let Some(sum) = self.sync.summary().filter(|s| s.off > 0) else {
            return;
        };
        let ms = |ns: u64| ns as f64 / 1e6;
        let first = self.sync.kept.first().map_or(0, |o| o.t_ns);
        let i = self.grouped(None, Problem::SyncJitter, 0, first);
        let inc = &mut self.incidents[i];
        inc.count = sum.off;
        inc.status = Status::Warning;
        inc.title = format!(
            "SYNC timing uneven: {} of {} cycles more than 10 % off the {:.3} ms period",
            sum.off,
            sum.intervals,
            ms(sum.period_ns)
        );
        inc.cause = Some(format!(
            "period {:.3} ms; intervals {:.3} to {:.3} ms; standard deviation {:.3} ms",
            ms(sum.period_ns),
            ms(sum.min_ns),
            ms(sum.max_ns),
            sum.std_ns / 1e6
        ));
        if let Some(last) = self.sync.kept.last() {
            inc.last_ns = last.t_ns;
        }
        for o in self.sync.kept.clone() {
            let at = At {
                frame: o.frame,
                t: o.t_ns,
            };
            self.step(i, at, format!("SYNC {:.3} ms after the one before", ms(o.interval_ns)));
        }
    }

    /// The end of the capture: what is still wrong is open. Returns the incidents ranked,
    /// open first, then recovered, then warnings; each by time.
    pub fn finish(mut self) -> Vec<Incident> {
        let end = At {
            t: self.at.t.max(self.now),
            ..self.at
        };
        self.tracker.tick(end.t);
        self.take_events();
        self.sdo_timeouts(end.t);
        self.pdos_due(end.t);
        for (key, i) in std::mem::take(&mut self.pdo_gaps) {
            let name = Self::pdo_name(key);
            self.step(i, end, format!("No {name} after that, until the end of the capture"));
            self.incidents[i].last_ns = end.t;
        }
        self.sync_jitter();
        let nodes: Vec<NodeKey> = self.nodes.keys().copied().collect();
        for n in nodes {
            self.flush_emcy(n, u64::MAX);
            if let Some((last, lost, _)) = self.node(n).silence.take() {
                let i = self.grouped(Some(n), Problem::Silent, 0, lost);
                self.step(i, last, "Last heartbeat");
                if let Some(other) = self.nodes[&n].last_any.filter(|a| a.t > lost) {
                    self.incidents[i].cause = Some("the heartbeat stopped, other messages of the node go on".into());
                    self.step(i, other, "The node still sends other messages (PDO, SDO or EMCY)");
                }
                self.step(i, end, "Nothing after that, until the end of the capture");
                self.incidents[i].last_ns = end.t;
            }
            let node = self.nodes[&n].clone();
            for a in node.axes.values() {
                if let (Some(i), Some(sw)) = (a.stuck, a.sw) {
                    let state = DriveState::from_statusword(sw).text();
                    self.step(i, end, format!("Still {state} at the end of the capture"));
                    self.incidents[i].last_ns = end.t;
                }
            }
            if let Some(at) = node.heartbeat_off.filter(|_| !node.guarded) {
                let i = self.grouped(Some(n), Problem::Unmonitored, 0, at.t);
                self.incidents[i].status = Status::Warning;
                self.step(i, at, "Heartbeat producer time 0x1017 = 0: heartbeat off");
            }
            if node.n_unanswered > 0 {
                let problem = if node.heard {
                    Problem::SdoTimeout
                } else {
                    Problem::Missing
                };
                let i = self.grouped(Some(n), problem, 0, node.unanswered[0].at.t);
                self.incidents[i].count = node.n_unanswered;
                self.incidents[i].status = if node.heard && node.answered_after {
                    Status::Warning
                } else {
                    Status::Open
                };
                for r in &node.unanswered {
                    let how = if r.replaced {
                        "no answer before the next request"
                    } else {
                        "no answer within 1 s"
                    };
                    self.step(i, r.at, format!("Request for 0x{:04X}:{:02X}: {how}", r.index, r.sub));
                }
                self.incidents[i].last_ns = node.unanswered.last().map_or(end.t, |r| r.at.t);
            }
        }
        if self.error_frames > 0 || !self.bus_state.is_empty() {
            let i = self.grouped(None, Problem::BusErrors, 0, end.t);
            let inc = &mut self.incidents[i];
            inc.count = self.error_frames;
            let worst = self
                .bus_state
                .values()
                .copied()
                .find(|s| *s == "bus_off")
                .or_else(|| self.bus_state.values().copied().find(|s| *s == "error_passive"));
            inc.status = if worst.is_some() { Status::Open } else { Status::Warning };
            inc.last_ns = inc.last_ns.min(end.t).max(inc.first_ns);
        }
        for (i, inc) in self.incidents.iter_mut().enumerate() {
            let meta = self.faults.get(&i).cloned().unwrap_or_default();
            super::texts::fill(inc, meta.resets, meta.emcy, self.error_frames, self.aborts.get(&i));
            // The device's own steps for its EMCY code come first.
            if let Some(steps) = self.device_check.get(&i) {
                inc.check.splice(0..0, steps.iter().cloned());
            }
        }
        // A PDO that stops because its node went silent for good is part of that silence.
        let gone: Vec<Option<NodeKey>> = self
            .incidents
            .iter()
            .filter(|i| i.problem == Problem::Silent)
            .map(Incident::key)
            .collect();
        self.incidents
            .retain(|i| !(i.problem == Problem::PdoMissing && gone.contains(&i.key())));
        let mut out = merge_faults(self.incidents);
        for inc in &mut out {
            inc.events.sort_by_key(|e| e.frame);
        }
        out.retain(|i| i.count > 0 || !i.events.is_empty());
        out.sort_by_key(|i| (i.status, i.first_ns));
        // Nodes on several interfaces: each node is shown with its interface's name.
        let first = self.nodes.keys().next().map(|k| k.iface);
        if self.nodes.keys().any(|k| Some(k.iface) != first) {
            for inc in out.iter_mut().filter(|i| i.node.is_some()) {
                inc.iface_name = self
                    .iface_names
                    .get(inc.iface as usize)
                    .filter(|n| !n.is_empty())
                    .cloned();
            }
        }
        out
    }
}

/// Drive faults of one node and axes with the same title become one incident with a count.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;

    /// Runs `frames` (ms, COB-ID, hex data) through a decoder and a diagnoser; returns
    /// `node kind status count` per incident.
    fn run(frames: &[(u64, u32, &str)]) -> Vec<String> {
        let mut dec = Decoder::new(Dictionary::default(), Vec::new());
        let mut diag = Diagnoser::new(|n| dec.dictionary(n));
        for (ms, id, data) in frames {
            let bytes: Vec<u8> = (0..data.len() / 2)
                .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).unwrap())
                .collect();
            let mut f = Frame::classic(*id, &bytes);
            f.ts_ns = ms * MS;
            let d = dec.decode(&f);
            diag.frame(&f, "can0", &d);
            for t in dec.take_transactions() {
                diag.transaction(&t);
            }
        }
        diag.finish()
            .iter()
            .map(|i| {
                let node = i.node.map_or("-".into(), |n| n.to_string());
                format!("{node} {} {} {}", i.problem.as_str(), i.status.as_str(), i.count)
            })
            .collect()
    }

    fn heartbeats(node: u32, from_ms: u64, to_ms: u64, state: &'static str) -> Vec<(u64, u32, &'static str)> {
        (from_ms..to_ms)
            .step_by(100)
            .map(|t| (t, 0x700 + node, state))
            .collect()
    }

    #[test]
    fn a_heartbeat_that_has_not_started_since_boot_up_did_not_stop() {
        // 0x1017 = 100 ms is written right after the boot-up; heartbeats start 500 ms later.
        let mut f = vec![
            (0, 0x701, "00"),
            (10, 0x601, "2B17100064000000"),
            (11, 0x581, "6017100000000000"),
        ];
        f.extend(heartbeats(1, 500, 1500, "05"));
        assert!(run(&f).is_empty(), "{:?}", run(&f));
        // Once it beats, a gap is a silence.
        f.extend(heartbeats(1, 2500, 3000, "05"));
        assert_eq!(run(&f), ["1 silent_back warning 1"]);
    }

    #[test]
    fn emcy_right_before_a_fault_is_its_cause_not_a_separate_incident() {
        // Node 2 reads as a CiA 402 device (0x1000 = 0x00020192): TPDO1 starts with the statusword.
        let f = [
            (0, 0x602, "4000100000000000"),
            (1, 0x582, "4300100092010200"),
            (100, 0x182, "3702"),
            (200, 0x082, "2171010000000000"),
            (201, 0x182, "0800"),
            (300, 0x202, "8000"),
            (301, 0x182, "4002"),
            (400, 0x182, "3702"),
        ];
        assert_eq!(run(&f), ["2 drive_fault recovered 1"]);
    }

    /// Like [`run`], with capture-clock ticks: `(ms, 0xFFFF_FFFF, "")` is a tick at `ms`.
    fn run_ticked(frames: &[(u64, u32, &str)]) -> Vec<String> {
        let mut dec = Decoder::new(Dictionary::default(), Vec::new());
        let mut diag = Diagnoser::new(|n| dec.dictionary(n));
        for (ms, id, data) in frames {
            if *id == u32::MAX {
                diag.tick(ms * MS);
                continue;
            }
            let bytes: Vec<u8> = (0..data.len() / 2)
                .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).unwrap())
                .collect();
            let mut f = Frame::classic(*id, &bytes);
            f.ts_ns = ms * MS;
            let d = dec.decode(&f);
            diag.frame(&f, "can0", &d);
        }
        diag.incidents()
            .iter()
            .map(|i| {
                let node = i.node.map_or("-".into(), |n| n.to_string());
                format!("{node} {} {} {}", i.problem.as_str(), i.status.as_str(), i.count)
            })
            .collect()
    }

    #[test]
    fn ticks_on_a_quiet_bus_find_a_silent_node_and_later_frames_undo_it() {
        let mut f = heartbeats(5, 0, 1000, "05");
        // The clock passes the deadline with no frame: silent so far.
        f.push((1500, u32::MAX, ""));
        assert_eq!(run_ticked(&f), ["5 silent open 1"]);
        // It beats again: it was a silence that ended.
        f.extend(heartbeats(5, 1600, 2000, "05"));
        assert_eq!(run_ticked(&f), ["5 silent_back warning 1"]);
        // A tick that runs ahead of the frames (a late delivery) is undone by them.
        let mut f = heartbeats(5, 0, 500, "05");
        f.push((560, u32::MAX, ""));
        f.extend(heartbeats(5, 500, 1000, "05"));
        let got = run_ticked(&f);
        assert!(got.iter().all(|g| !g.contains("silent open")), "{got:?}");
    }

    #[test]
    fn boot_ups_with_equal_times_are_not_a_duplicate_id() {
        // Logs without timestamps give every frame time 0: two boot-ups say nothing there.
        let f = [(0, 0x000, "8100"), (0, 0x705, "00"), (0, 0x705, "00")];
        assert!(run(&f).is_empty(), "{:?}", run(&f));
        let f = [(0, 0x000, "8100"), (10, 0x705, "00"), (30, 0x705, "00")];
        assert_eq!(run(&f), ["5 duplicate_id open 1"]);
    }

    /// `run` of `frames`, only the second-master incidents.
    fn masters(frames: &[(u64, u32, &str)]) -> Vec<String> {
        run(frames)
            .into_iter()
            .filter(|i| i.contains("second_master"))
            .collect()
    }

    /// A segmented upload of 0x1008 from node 2: initiate, answer, segment t0, answer t0.
    const UPLOAD: [(u64, u32, &str); 4] = [
        (0, 0x602, "4008100000000000"),
        (1, 0x582, "4108100010000000"),
        (2, 0x602, "6000000000000000"),
        (3, 0x582, "00434F5455492044"),
    ];

    #[test]
    fn a_segment_toggle_bit_repeated_at_once_is_a_second_client() {
        // Right after the node answered the segment with toggle bit 0, another one with
        // toggle bit 0: only a second client's transfer explains it.
        let mut f = UPLOAD.to_vec();
        f.extend([(5, 0x602, "6000000000000000"), (6, 0x582, "8008100000000305")]);
        assert_eq!(masters(&f), ["2 second_master warning 1"]);
        // Two segment requests with one toggle bit before any answer, 4 ms apart.
        let mut f = UPLOAD[..3].to_vec();
        f.extend([(6, 0x602, "6000000000000000"), (7, 0x582, "00434F5455492044")]);
        assert_eq!(masters(&f), ["2 second_master warning 1"]);
    }

    #[test]
    fn a_segment_retried_after_a_timeout_or_alternating_bits_are_one_client() {
        // The toggle bit alternates: t0, answer, t1, answer (last).
        let mut f = UPLOAD.to_vec();
        f.extend([(4, 0x602, "7000000000000000"), (5, 0x582, "1D55492D31000000")]);
        assert!(masters(&f).is_empty(), "{:?}", run(&f));
        // The segment request is repeated 300 ms later, unanswered: a retry, not a second client.
        let mut f = UPLOAD[..3].to_vec();
        f.extend([
            (300, 0x602, "6000000000000000"),
            (301, 0x582, "00434F5455492044"),
            (302, 0x602, "7000000000000000"),
            (303, 0x582, "1D55492D31000000"),
        ]);
        assert!(masters(&f).is_empty(), "{:?}", run(&f));
        // A new transfer starts the toggle bit over.
        let mut f = UPLOAD.to_vec();
        f.extend([(4, 0x602, "8008100000000000"), (5, 0x602, "4008100000000000")]);
        f.extend([(6, 0x582, "4108100010000000"), (7, 0x602, "6000000000000000")]);
        assert!(masters(&f).is_empty(), "{:?}", run(&f));
    }

    #[test]
    fn nmt_start_undone_at_once_is_a_second_master_a_selection_is_not() {
        // Start node 3, reset node 3 10 ms later: two masters disagree.
        let f = [(0, 0x000, "0103"), (10, 0x000, "8103")];
        assert_eq!(masters(&f), ["3 second_master warning 1"]);
        // Start node 3, then pre-operational for all nodes 5 ms later.
        let f = [(0, 0x000, "0103"), (5, 0x000, "8000")];
        assert_eq!(masters(&f), ["3 second_master warning 1"]);
        // Start all, then keep node 3 stopped: one master choosing which nodes run.
        let f = [(0, 0x000, "0100"), (5, 0x000, "0203")];
        assert!(masters(&f).is_empty());
        // Pre-operational then start (re-configuration), and a stop 30 ms after the start.
        let f = [(0, 0x000, "8003"), (2, 0x000, "0103"), (32, 0x000, "0203")];
        assert!(masters(&f).is_empty());
    }

    #[test]
    fn a_reset_asked_for_is_not_an_unexpected_reboot() {
        let mut f = heartbeats(3, 0, 500, "05");
        f.push((550, 0x000, "8203"));
        f.push((560, 0x703, "00"));
        assert!(run(&f).is_empty(), "{:?}", run(&f));
        let mut f = heartbeats(3, 0, 500, "05");
        f.push((560, 0x703, "00"));
        assert_eq!(run(&f), ["3 rebooted warning 1"]);
    }
}
