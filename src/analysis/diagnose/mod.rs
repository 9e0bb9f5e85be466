//! The incident builder: decoded frames, SDO transactions and bus events in, a short
//! ranked list of [`Incident`]s out. Pure: time only comes from frame timestamps.
//!
//! What it finds: nodes that never answer (missing), heartbeats that stop (for good, or
//! for a while), unexpected reboots, refused SDO transfers (grouped per object), SDO
//! requests left unanswered, CiA 402 faults with their cause (EMCY, 0x603F) and the fault
//! resets that followed, EMCY not tied to a fault, CAN error frames and controller states,
//! duplicate node-IDs (boot-ups close together, conflicting heartbeat states) and NMT
//! commands a node did not follow; boots whose configuration writes differ from the
//! node's first complete boot or from an expected configuration.
//!
//! [`Diagnoser`] is the facade: it routes each frame, transaction and event to the
//! detectors concerned, one module per kind of incident (`heartbeat`, `boot`, `sdo`,
//! `masters`, `drive`, `emcy`, `pdo`, `sync`, `bus`, `boot_config`), in a fixed order (the incidents'
//! order depends on it). They share the clock, the node table and the incident book
//! (`timeline`); each keeps its own state of each node, and what one detector tells
//! another goes through the facade (no detector imports another). The words of each kind
//! are a table (`texts`), the report's order is `rank`'s.

mod boot;
mod boot_config;
mod bus;
mod detector;
mod drive;
mod emcy;
mod heartbeat;
mod masters;
mod pdo;
mod rank;
mod sdo;
mod sync;
mod texts;
mod timeline;
mod two_masters;

use super::boot_story::{Boot, Expected};
use super::events::{Event, What};
use super::incident::Incident;
use super::liveness::EventTracker;
use crate::decode::heartbeat::NmtState;
use crate::decode::sdo::frame::SdoFrame;
use crate::decode::{Body, Decoded, Decoder, Kind};
use crate::frame::{Flags, Frame, NodeKey};
use crate::od::{Dictionary, PdoMapping};
use crate::sdo::transaction::{Outcome, Transaction, TransferDirection};
use detector::{Detector, value};
use timeline::{At, Timeline};

/// Builds incidents from the frames of one capture, in order. Incremental: frames go in
/// one at a time ([`Diagnoser::frame`], [`Diagnoser::skip`]), the capture clock advances
/// on a quiet bus with [`Diagnoser::tick`], and [`Diagnoser::incidents`] tells what is
/// wrong so far without ending the capture.
#[derive(Clone)]
pub struct Diagnoser {
    tracker: EventTracker,
    tl: Timeline,
    /// Interfaces seen so far: their nodes got the dictionaries' defaults.
    ifaces_seen: u16,
    heartbeats: heartbeat::Heartbeats,
    boots: boot::Boots,
    sdos: sdo::Sdos,
    masters: masters::Masters,
    drives: drive::Drives,
    emcys: emcy::Emcys,
    pdos: pdo::Pdos,
    syncs: sync::Syncs,
    bus: bus::Bus,
    boot_configs: boot_config::BootConfigs,
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
        let mut d = Diagnoser {
            tracker: EventTracker::new(&dict),
            tl: Timeline::default(),
            ifaces_seen: 0,
            heartbeats: Default::default(),
            boots: Default::default(),
            sdos: Default::default(),
            masters: Default::default(),
            drives: Default::default(),
            emcys: Default::default(),
            pdos: Default::default(),
            syncs: Default::default(),
            bus: Default::default(),
            boot_configs: Default::default(),
        };
        // Unbound nodes share one dictionary: each distinct one is read once.
        let mut seen: Vec<(
            Vec<*const crate::od::Profile>,
            crate::analysis::sync_cycles::SyncDefaults,
        )> = Vec::new();
        for n in 1..128u8 {
            let dict = dict(n);
            let layers: Vec<_> = dict.layers().iter().map(std::sync::Arc::as_ptr).collect();
            let known = match seen.iter().position(|(l, _)| *l == layers) {
                Some(i) => i,
                None => {
                    seen.push((layers, crate::analysis::sync_cycles::sync_defaults(dict)));
                    seen.len() - 1
                }
            };
            d.pdos.add_defaults(n, &seen[known].1);
        }
        d.pdos.apply_defaults(0);
        d.ifaces_seen = 1;
        d
    }

    /// Node `node` (on any interface) should be configured with `values` (a DCF's, typed):
    /// every boot is compared with them too.
    pub fn expect(&mut self, node: u8, values: Vec<Expected>) {
        self.boot_configs.expect(node, values);
    }

    /// Forgets every expected configuration ([`Diagnoser::expect`]).
    pub fn expect_nothing(&mut self) {
        self.boot_configs.expect_nothing();
    }

    /// The nodes with an expected configuration, in order.
    pub fn expected_nodes(&self) -> Vec<u8> {
        self.boot_configs.expected_nodes()
    }

    /// Names interface `iface` (as the frames of the source call it); a node of a capture
    /// with several interfaces is then shown with its interface's name.
    pub fn name_interface(&mut self, iface: u16, name: &str) {
        let names = &mut self.tl.iface_names;
        let i = iface as usize;
        if i >= names.len() {
            names.resize(i + 1, String::new());
        }
        if names[i].is_empty() {
            names[i] = name.to_string();
        }
    }

    /// Time of the first frame (ns): the origin of the times in the report.
    pub fn origin_ns(&self) -> u64 {
        self.tl.first_ns.unwrap_or(0)
    }

    /// Frames seen so far.
    pub fn frames(&self) -> u64 {
        self.tl.at.frame
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
        self.tl.iface = frame.iface;
        if frame.iface >= self.ifaces_seen {
            self.new_interfaces(frame.iface);
        }
        self.tl.at = At {
            frame: self.tl.at.frame + 1,
            t: frame.ts_ns,
        };
        self.tl.first_ns.get_or_insert(frame.ts_ns);
        self.clock(frame.ts_ns);
    }

    /// The detectors that watch the clock learn it reached `now`.
    #[inline]
    fn clock(&mut self, now: u64) {
        self.sdos.tick(&mut self.tl, now);
        self.pdos.tick(&mut self.tl, now);
    }

    /// Interfaces up to `iface` are seen: their nodes get the dictionaries' defaults.
    #[cold]
    fn new_interfaces(&mut self, iface: u16) {
        for i in self.ifaces_seen..=iface {
            self.pdos.apply_defaults(i);
        }
        self.ifaces_seen = iface.saturating_add(1);
    }

    /// True when a PDO of `node` can tell the diagnosis something: its `mapping` holds a
    /// CiA 402 controlword, statusword or error code, or (mapping unknown) it is the
    /// predefined TPDO1/RPDO1 of a CiA 402 device. Other PDOs need no decoding.
    pub fn wants_pdo(&self, node: NodeKey, num: u16, mapping: Option<&PdoMapping>) -> bool {
        match mapping {
            Some(m) => drive::maps_drive_words(m),
            None => num == 1 && self.tl.nodes.get(&node).is_some_and(|d| d.cia402),
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
            (Kind::Sync, _) => self.syncs.sync(&self.tl),
            (Kind::Tpdo | Kind::Rpdo, Some(n)) => {
                self.pdos
                    .arrived(&mut self.tl, n, kind == Kind::Tpdo, pdo, self.syncs.last)
            }
            _ => {}
        }
        if let (Kind::Tpdo, Some(n)) = (kind, node) {
            self.boot_configs.operational(&self.tl, n, "TPDO");
            let at = self.tl.at;
            let node = self.tl.node(n);
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
                self.syncs.sync(&self.tl);
            }
            if let Body::Nmt(nmt) = &d.body {
                self.nmt(nmt.cs, nmt.target);
            }
            if d.kind == Kind::ErrorFrame {
                self.bus.error_frame(&mut self.tl, &d.label);
            }
            return;
        };
        let n = NodeKey::of(frame, n);
        let at = self.tl.at;
        let tl = &mut self.tl;
        if matches!(d.kind, Kind::Tpdo | Kind::SdoTx | Kind::Emcy)
            || matches!(&d.body, Body::Heartbeat(h) if !h.request)
        {
            tl.node(n).last_any = Some(at);
        }
        if matches!(&d.body, Body::Heartbeat(h) if h.request) {
            self.heartbeats.guarded(tl, n);
        }
        match &d.body {
            Body::Heartbeat(h) if !h.request => {
                tl.node(n).heard = true;
                if let Some(s) = h.state {
                    self.heartbeats.heartbeat(tl, n, s);
                    self.boots.heartbeat(tl, n, s);
                    match s {
                        NmtState::BootUp => self.boot_configs.boot_up(tl, n),
                        NmtState::Operational => self.boot_configs.operational(tl, n, "heartbeat"),
                        _ => {}
                    }
                }
            }
            Body::Emcy(e) => {
                tl.node(n).heard = true;
                self.emcys.emcy(tl, n, e, self.drives.faults(n));
            }
            Body::Sdo(s) => self.sdos.frame(tl, n, s, frame.flags.has(Flags::TX)),
            Body::Pdo(p) => {
                if p.transmit {
                    tl.node(n).heard = true;
                    self.boot_configs.operational(tl, n, "TPDO");
                }
                self.pdos.arrived(tl, n, p.transmit, p.num, self.syncs.last);
                if p.signals.is_empty() && p.num == 1 && tl.node(n).cia402 && frame.payload().len() >= 2 {
                    // CiA 402 predefined mapping: TPDO1 starts with the statusword, RPDO1
                    // with the controlword.
                    let w = u16::from_le_bytes([frame.payload()[0], frame.payload()[1]]);
                    self.drive_word(n, if p.transmit { 0x6041 } else { 0x6040 }, w);
                }
                for s in &p.signals {
                    if let Some(v) = s.value.as_i64() {
                        self.drive_word(n, s.index, v as u16);
                    }
                }
            }
            _ => {
                if matches!(d.kind, Kind::Tpdo | Kind::SdoTx) {
                    tl.node(n).heard = true;
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
            let at = self.tl.at;
            let node = self.tl.node(n);
            node.last_any = Some(at);
            node.heard = true;
        }
        if let Some(s) = s {
            self.sdos.frame(&mut self.tl, n, s, frame.flags.has(Flags::TX));
        }
    }

    /// A CiA 402 object value `w` of `n` at `index`: a fault it starts gets its cause from
    /// a recent EMCY of the node.
    fn drive_word(&mut self, n: NodeKey, index: u16, w: u16) {
        if let Some(i) = self.drives.word(&mut self.tl, n, index, w) {
            self.emcys.absorb(&mut self.tl, n, i);
        }
    }

    /// An NMT command (specifier `cs`) to `target` (0: all nodes).
    fn nmt(&mut self, cs: u8, target: u8) {
        let Some((command, state)) = boot::nmt_command(cs) else {
            return;
        };
        if cs != 0x01 {
            self.pdos.pause(self.tl.iface, (target != 0).then_some(target));
        }
        self.masters.nmt(&mut self.tl, cs, target, command);
        self.boots.command(&mut self.tl, command, state, target);
        self.boot_configs
            .command(&self.tl, command, target, state == NmtState::BootUp);
    }

    /// A bus event of the liveness tracker.
    fn event(&mut self, e: &Event) {
        let tl = &mut self.tl;
        let Some(n) = e.key() else {
            if let What::BusState { iface, to, detail, .. } = &e.what {
                self.bus.state(tl, iface, to, detail, e.t_ns);
            }
            return;
        };
        let at = At {
            frame: tl.at.frame,
            t: e.t_ns,
        };
        match &e.what {
            What::HeartbeatLost { silent_ms, .. } => self.heartbeats.lost(tl, n, at, *silent_ms),
            What::HeartbeatBack { silent_ms } => self.heartbeats.back(tl, n, at, *silent_ms),
            What::BootUp { rebooted, .. } => {
                self.pdos.pause(n.iface, Some(n.node));
                self.boots.boot_up(tl, n, at, *rebooted);
                self.heartbeats.boot_up(tl, n);
            }
            _ => {}
        }
    }

    /// A completed SDO transfer (in order, right after the frame that ended it).
    pub fn transaction(&mut self, t: &Transaction) {
        self.tracker.transaction(t);
        self.take_events();
        if t.outcome == Outcome::Ok && !t.data.is_empty() {
            let v = value(t);
            if (t.index, t.sub, t.direction) == (0x1000, 0, TransferDirection::Upload) {
                self.tl.node(t.key()).cia402 = v & 0xFFFF == 402;
            }
            if t.sub == 0 {
                self.drive_word(t.key(), t.index, v as u16);
            }
        }
        let tl = &mut self.tl;
        let detectors: [&mut dyn Detector; 4] = [
            &mut self.pdos,
            &mut self.heartbeats,
            &mut self.sdos,
            &mut self.boot_configs,
        ];
        for d in detectors {
            d.transaction(tl, t);
        }
    }

    /// The capture clock reached `now_ns` with no frame since the last one (a quiet bus in
    /// a live capture or a running replay): heartbeats and SDO answers overdue by then are
    /// missed.
    pub fn tick(&mut self, now_ns: u64) {
        if now_ns <= self.tl.now.max(self.tl.at.t) {
            return;
        }
        self.tl.now = now_ns;
        self.tracker.tick(now_ns);
        self.take_events();
        self.clock(now_ns);
    }

    /// The incidents opened so far as they stand, in the order they were opened (no
    /// ranking, no end-of-capture pass): cheap enough to look at after every frame (a
    /// trigger on `incident KIND`).
    pub fn opened(&self) -> &[Incident] {
        &self.tl.incidents
    }

    /// The incidents so far, ranked as [`Diagnoser::finish`] ranks them, as if the capture
    /// ended now (the builder goes on).
    pub fn incidents(&self) -> Vec<Incident> {
        self.clone().finish()
    }

    /// The end of the capture: what is still wrong is open. Returns the incidents ranked,
    /// open first, then recovered, then warnings; each by time.
    pub fn finish(self) -> Vec<Incident> {
        self.finish_with_boots().0
    }

    /// [`Diagnoser::finish`], and the boot stories of every node (by node, then boot)
    /// with what each differs in from its reference and the expected configuration.
    pub fn finish_with_boots(mut self) -> (Vec<Incident>, Vec<Boot>) {
        let end = At {
            t: self.tl.at.t.max(self.tl.now),
            ..self.tl.at
        };
        self.tracker.tick(end.t);
        self.take_events();
        let tl = &mut self.tl;
        let bus: [&mut dyn Detector; 5] = [
            &mut self.sdos,
            &mut self.pdos,
            &mut self.syncs,
            &mut self.bus,
            &mut self.boot_configs,
        ];
        for d in bus {
            d.end(tl, end);
        }
        let nodes: Vec<NodeKey> = tl.nodes.keys().copied().collect();
        for n in nodes {
            let per_node: [&mut dyn Detector; 4] =
                [&mut self.emcys, &mut self.heartbeats, &mut self.drives, &mut self.sdos];
            for d in per_node {
                d.end_node(tl, n, end);
            }
        }
        for (i, inc) in tl.incidents.iter_mut().enumerate() {
            let facts = texts::Facts {
                resets: self.drives.resets(i),
                emcy: self.emcys.fault_code(i),
                error_frames: self.bus.error_frames,
                sdo: self.sdos.aborts(i),
            };
            texts::fill(inc, &facts);
            // The device's own steps for its EMCY code come first.
            if let Some(steps) = self.emcys.device_check(i) {
                inc.check.splice(0..0, steps.iter().cloned());
            }
        }
        (
            rank::rank(std::mem::take(&mut tl.incidents), tl),
            self.boot_configs.stories(),
        )
    }
}

#[cfg(test)]
mod tests;
