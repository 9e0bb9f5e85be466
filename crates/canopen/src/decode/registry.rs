//! The decoder registry: routes each frame to its service decoder and keeps the
//! bus state that decoding depends on (moved COB-IDs, PDO mappings, SDO
//! transfers, modes of operation).

use super::cob_id::{CobId, CobTable, Route};
use super::heartbeat::Heartbeat;
use super::kind::Kind;
use super::pdo::{self, Pdo};
use super::pdo_config::{CommParams, PdoId};
use super::sdo::tracker::{labelled, unlabelled};
use super::sdo::{SdoFrame, SdoTracker};
use super::{emcy, error_frame, heartbeat, lss, nmt, sync, time, value_text, vendor_sdo};
use crate::frame::{Frame, NodeKey};
use crate::od::{Dictionary, MappingSource, PdoMapping, resolve_object};
use crate::sdo::tracker::Tracked;
use crate::sdo::{Transaction, TransferDirection};
use std::collections::HashMap;

/// The decoded meaning of one frame.
#[derive(Debug)]
pub struct Decoded {
    pub kind: Kind,
    /// The node the frame belongs to (None for NMT broadcast, SYNC, TIME, LSS, other).
    pub node: Option<u8>,
    /// One-line human label.
    pub label: String,
    /// Kind-specific structured content.
    pub body: Body,
    /// Set when the frame breaks its kind's rules (it is still decoded and shown).
    pub malformed: Option<String>,
}

/// Kind-specific content of a [`Decoded`] frame.
#[derive(Debug)]
pub enum Body {
    None,
    Nmt(nmt::Nmt),
    Heartbeat(Heartbeat),
    Sync(sync::Sync),
    Time(time::Time),
    Emcy(emcy::Emcy),
    Pdo(Pdo),
    /// Boxed: the largest body by far, so that a [`Decoded`] stays small to move.
    Sdo(Box<SdoFrame>),
    Lss(lss::Lss),
    ErrorFrame {
        class: u32,
    },
    /// A vendor SDO command the node's profile describes (e.g. Syn-tron 0xE8/0xE9).
    VendorSdo(vendor_sdo::VendorSdo),
}

/// Identifies one PDO of one node: (node, transmit, number).
type PdoKey = (u8, bool, u16);

/// Mapping entries seen in SDO traffic for one PDO, not yet complete.
#[derive(Clone, Debug, Default)]
struct LearnedMapping {
    count: Option<u8>,
    entries: Vec<Option<u32>>,
}

/// What decoding learns about one bus (interface): its moved COB-IDs, PDO mappings and
/// communication parameters, modes of operation. Each interface has its own: node 5 on
/// can0 and node 5 on can1 are two nodes.
#[derive(Clone, Default)]
struct Bus {
    cobs: CobTable,
    mappings: HashMap<PdoKey, PdoMapping>,
    learning: HashMap<PdoKey, LearnedMapping>,
    /// PDO communication parameters seen in SDO transfers (reads and writes).
    comm: HashMap<PdoKey, CommParams>,
    /// Per node (bit = node-ID): the last SDO request to it was ours (marked TX), so a
    /// mapping it writes is "configured", not "sniffed".
    ours: u128,
    /// Mode of operation per node, from 0x6060/0x6061 traffic (made on the first mode
    /// seen: a bus costs little until it carries drives).
    modes: Option<Box<[Option<i8>; 128]>>,
    /// SDO channels moved by 0x1200 writes: COB-ID -> (node, client_to_server).
    sdo_cobs: HashMap<u32, (u8, bool)>,
}

impl Bus {
    /// The last mode of operation seen of `node`.
    fn mode(&self, node: u8) -> Option<i8> {
        self.modes.as_ref().and_then(|m| m[usize::from(node & 0x7F)])
    }

    /// Records the mode of operation of `node`.
    fn set_mode(&mut self, node: u8, mode: Option<i8>) {
        if mode.is_some() || self.modes.is_some() {
            self.modes.get_or_insert_with(|| Box::new([None; 128]))[usize::from(node & 0x7F)] = mode;
        }
    }

    /// Whether the last SDO request to `node` was ours.
    fn is_ours(&self, node: u8) -> bool {
        self.ours & (1 << (node & 0x7F)) != 0
    }

    /// Records whether the last SDO request to `node` was ours.
    fn set_ours(&mut self, node: u8, ours: bool) {
        let bit = 1u128 << (node & 0x7F);
        self.ours = if ours { self.ours | bit } else { self.ours & !bit };
    }

    fn install_default_mappings(&mut self, node: u8, dict: &Dictionary) {
        for layer in dict.layers().iter().rev() {
            for (transmit, maps) in [(false, &layer.rpdo), (true, &layer.tpdo)] {
                for (num, m) in maps {
                    if let Some(cob) = m.cob_id {
                        let kind = if transmit { Kind::Tpdo } else { Kind::Rpdo };
                        self.cobs.assign(
                            cob_key(cob),
                            Route {
                                kind,
                                node: Some(node),
                                pdo: u16::from(*num),
                                reserved: false,
                            },
                        );
                    }
                    self.mappings.insert((node, transmit, u16::from(*num)), m.clone());
                }
            }
        }
    }

    /// Learns COB-IDs, PDO mappings and modes from a completed SDO transfer.
    fn learn(&mut self, t: &Transaction, dict: &Dictionary) {
        if !t.is_ok() || t.data.is_empty() {
            return;
        }
        let node = t.node;
        let mut b = [0u8; 4];
        let len = t.data.len().min(4);
        b[..len].copy_from_slice(&t.data[..len]);
        let v = u32::from_le_bytes(b);
        self.select_pdo_set(node, t.index, t.sub, i64::from(v), dict);
        match (t.index, t.sub) {
            (0x6060 | 0x6061, 0) => self.set_mode(node, Some(t.data[0] as i8)),
            (0x1005, 0) => self.assign_cob(
                v,
                Route {
                    kind: Kind::Sync,
                    node: None,
                    pdo: 0,
                    reserved: false,
                },
            ),
            (0x1014, 0) => self.assign_cob(
                v,
                Route {
                    kind: Kind::Emcy,
                    node: Some(node),
                    pdo: 0,
                    reserved: false,
                },
            ),
            (0x1200, 1 | 2) if v & 0x8000_0000 == 0 => {
                let key = (v & 0x1FFF_FFFF) | if v & (1 << 29) != 0 { 1 << 29 } else { 0 };
                self.sdo_cobs.insert(key, (node, t.sub == 1));
            }
            (0x1400..=0x15FF | 0x1800..=0x19FF, sub) => {
                let transmit = t.index >= 0x1800;
                let num = t.index - if transmit { 0x1800 } else { 0x1400 } + 1;
                let key = (node, transmit, num);
                let mut c = self.comm.get(&key).copied().unwrap_or_default();
                if c.set(sub, v) {
                    self.comm.insert(key, c);
                }
                if sub == 1 {
                    self.pdo_cob(node, transmit, num, v);
                }
            }
            (0x1600..=0x17FF | 0x1A00..=0x1BFF, sub) => {
                let transmit = t.index >= 0x1A00;
                let num = t.index - if transmit { 0x1A00 } else { 0x1600 } + 1;
                let ts_ns = t.end_ns;
                let source = match t.direction {
                    TransferDirection::Upload => MappingSource::ReadFromNode { ts_ns },
                    _ if self.is_ours(node) => MappingSource::Configured { ts_ns },
                    _ => MappingSource::Sniffed { ts_ns },
                };
                self.learn_mapping((node, transmit, num), sub, v, source);
            }
            _ => {}
        }
    }

    /// Switches `node` to the profile's PDO mapping set that (index, sub) = `value`
    /// selects (e.g. Dexmart parameter 09-26), when one does.
    fn select_pdo_set(&mut self, node: u8, index: u16, sub: u8, value: i64, dict: &Dictionary) {
        let chosen = dict.layers().iter().find_map(|layer| {
            layer.pdo_sets.iter().find(|set| {
                set.selected_by
                    .as_ref()
                    .is_some_and(|(object, v)| *v == value && resolve_object(dict, object) == Ok((index, sub)))
            })
        });
        let Some(set) = chosen else { return };
        let source = MappingSource::Profile(dict.profile_name().to_string());
        for transmit in [false, true] {
            let kind = if transmit { Kind::Tpdo } else { Kind::Rpdo };
            for (num, m) in set.mappings(transmit, Some(node), &source) {
                let num = u16::from(num);
                match m.cob_id {
                    Some(cob) => self.cobs.assign(
                        cob_key(cob),
                        Route {
                            kind,
                            node: Some(node),
                            pdo: num,
                            reserved: false,
                        },
                    ),
                    None => self.cobs.unassign(kind, Some(node), num),
                }
                self.mappings.insert((node, transmit, num), m);
            }
        }
    }

    fn assign_cob(&mut self, v: u32, route: Route) {
        if v & 0x8000_0000 == 0 || route.kind == Kind::Sync {
            self.cobs.assign(cob_key(v), route);
        }
    }

    fn pdo_cob(&mut self, node: u8, transmit: bool, num: u16, v: u32) {
        let kind = if transmit { Kind::Tpdo } else { Kind::Rpdo };
        if v & 0x8000_0000 != 0 {
            self.cobs.unassign(kind, Some(node), num);
            return;
        }
        let route = Route {
            kind,
            node: Some(node),
            pdo: num,
            reserved: false,
        };
        let predefined = super::cob_id::predefined(v & 0x7FF);
        let is_default = v & (1 << 29) == 0 && predefined == route;
        if is_default {
            self.cobs.unassign(kind, Some(node), num);
        } else {
            self.cobs.assign(cob_key(v), route);
        }
    }

    fn learn_mapping(&mut self, key: PdoKey, sub: u8, v: u32, source: MappingSource) {
        let l = self.learning.entry(key).or_default();
        if sub == 0 {
            l.count = Some(v as u8);
            if v as u8 == 0 {
                self.mappings.remove(&key);
                return;
            }
        } else if sub <= 64 {
            let i = sub as usize - 1;
            if l.entries.len() <= i {
                l.entries.resize(i + 1, None);
            }
            l.entries[i] = Some(v);
        }
        let Some(count) = l.count.filter(|c| *c > 0 && *c <= 64) else {
            return;
        };
        let entries: Option<Vec<u32>> = (0..count as usize)
            .map(|i| l.entries.get(i).copied().flatten())
            .collect();
        if let Some(entries) = entries {
            let entries: Vec<_> = entries.into_iter().map(pdo::entry_from_u32).collect();
            // The same mapping seen again (read back after a write) keeps where it came from.
            if self.mappings.get(&key).is_some_and(|m| m.entries == entries) {
                return;
            }
            let cob_id = self.mappings.get(&key).and_then(|m| m.cob_id);
            let mapping = PdoMapping {
                cob_id,
                entries,
                source,
            };
            self.mappings.insert(key, mapping);
        }
    }
}

/// Decodes frames one after another, keeping the state of the bus.
///
/// `Clone` lets a viewer keep checkpoints of the state and decode any stretch of a
/// long trace again from the nearest one.
#[derive(Clone)]
pub struct Decoder {
    /// Per-node dictionaries, index = node id (0 unused).
    dicts: Vec<Dictionary>,
    /// The state of each interface, index = `Frame::iface` (made when something is learnt
    /// of it; boxed, so that a capture of 40,000 interface names grows a table of pointers).
    buses: Vec<Option<Box<Bus>>>,
    /// The state of an interface before its first frame (the bound nodes' defaults).
    fresh: Bus,
    /// SDO transfers of every interface (channels are per interface).
    sdo: SdoTracker,
    completed: Vec<Transaction>,
    seq: u64,
    /// A label buffer handed back by [`Decoder::recycle`], reused for the next PDO or SDO label.
    spare: String,
    /// An SDO body's box handed back by [`Decoder::recycle`], reused for the next SDO frame.
    spare_sdo: Option<Box<SdoFrame>>,
}

impl Decoder {
    /// A decoder where node `n` uses `dict_for(n)`. Nodes listed in `bound`
    /// (explicit `--profile`/`--eds` bindings) also get their default PDO
    /// mappings and COB-IDs from their dictionary.
    pub fn new(default: Dictionary, bound: Vec<(u8, Dictionary)>) -> Decoder {
        let mut dicts = vec![default; 128];
        let mut fresh = Bus::default();
        for (node, dict) in bound {
            if (1..128).contains(&node) {
                fresh.install_default_mappings(node, &dict);
                dicts[node as usize] = dict;
            }
        }
        Decoder {
            dicts,
            buses: vec![Some(Box::new(fresh.clone()))],
            fresh,
            sdo: SdoTracker::new(),
            completed: Vec::new(),
            seq: 0,
            spare: String::new(),
            spare_sdo: None,
        }
    }

    /// A decoder for the nodes bound in `bindings` (others use CiA 402 + 301).
    pub fn from_bindings(bindings: &crate::od::bind::Bindings) -> Decoder {
        let bound = bindings
            .bound_nodes()
            .map(|n| (n, bindings.dictionary(n).clone()))
            .collect();
        Decoder::new(bindings.default_dictionary().clone(), bound)
    }

    /// The state of interface `iface` (a fresh one before its first frame).
    #[inline]
    fn bus(&self, iface: u16) -> &Bus {
        self.buses
            .get(iface as usize)
            .and_then(Option::as_deref)
            .unwrap_or(&self.fresh)
    }

    /// The state of interface `iface`, made on first use.
    #[inline]
    fn bus_mut(&mut self, iface: u16) -> &mut Bus {
        Self::bus_in(&mut self.buses, &self.fresh, iface)
    }

    /// The state of interface `iface` in `buses`, made from `fresh` on first use.
    fn bus_in<'b>(buses: &'b mut Vec<Option<Box<Bus>>>, fresh: &Bus, iface: u16) -> &'b mut Bus {
        let i = iface as usize;
        if i >= buses.len() {
            buses.resize_with(i + 1, || None);
        }
        buses[i].get_or_insert_with(|| Box::new(fresh.clone()))
    }

    /// Numbers the frames that follow from `seq + 1` on (the numbers SDO transactions list in
    /// `frames`). A caller that skips frames (e.g. classifies only some) keeps them equal to
    /// frame positions this way.
    pub fn set_seq(&mut self, seq: u64) {
        self.seq = seq;
    }

    /// The dictionary used for `node`.
    pub fn dictionary(&self, node: u8) -> &Dictionary {
        &self.dicts[(node & 0x7F) as usize]
    }

    /// The mapping in force for a PDO of a node, if known.
    pub fn mapping(&self, node: NodeKey, transmit: bool, num: u16) -> Option<&PdoMapping> {
        self.bus(node.iface).mappings.get(&(node.node, transmit, num))
    }

    /// Where a frame goes: kind, node and PDO number (0 when not a PDO), without decoding
    /// it or changing any state (for callers that decode only some frames).
    pub fn peek(&self, frame: &Frame) -> (Kind, Option<u8>, u16) {
        let r = self.route(frame);
        (r.kind, r.node, r.pdo)
    }

    /// The last mode of operation seen for `node`.
    pub fn mode(&self, node: NodeKey) -> Option<i8> {
        self.bus(node.iface).mode(node.node)
    }

    /// Where a frame goes, without building its label (the cheap path for `--summary`).
    /// SDO frames are still tracked so that COB-ID and mapping changes are learned.
    pub fn classify(&mut self, frame: &Frame) -> (Kind, Option<u8>) {
        let route = self.route(frame);
        if matches!(route.kind, Kind::SdoRx | Kind::SdoTx) {
            self.seq += 1;
            self.track_sdo(frame, route);
        }
        (route.kind, route.node)
    }

    /// An SDO frame (per [`Decoder::peek`]) tracked as [`Decoder::decode`] tracks it, without
    /// building its label: the frame as the tracker read it, or None for a vendor SDO
    /// command of the node's profile (which `decode` shows as [`Body::VendorSdo`]).
    /// For callers that only need the command and the tracker's notes (the diagnosis).
    pub fn sdo_frame(&mut self, frame: &Frame) -> Option<SdoFrame> {
        let route = self.route(frame);
        debug_assert!(matches!(route.kind, Kind::SdoRx | Kind::SdoTx));
        self.seq += 1;
        let s = self.track_sdo(frame, route);
        let n = route.node.unwrap_or(0) as usize & 0x7F;
        let c2s = route.kind == Kind::SdoRx;
        vendor_sdo::decode(&self.dicts[n], c2s, frame.payload())
            .is_none()
            .then(|| unlabelled(s, frame.payload()))
    }

    fn route(&self, frame: &Frame) -> Route {
        if frame.is_err() {
            return Route {
                kind: Kind::ErrorFrame,
                node: None,
                pdo: 0,
                reserved: false,
            };
        }
        let bus = self.bus(frame.iface);
        // Most buses move no SDO channel: skip hashing the id then.
        if !bus.sdo_cobs.is_empty()
            && let Some(&(node, c2s)) = bus.sdo_cobs.get(&(frame.id | if frame.is_ext() { 1 << 29 } else { 0 }))
        {
            let kind = if c2s { Kind::SdoRx } else { Kind::SdoTx };
            return Route {
                kind,
                node: Some(node),
                pdo: 0,
                reserved: false,
            };
        }
        bus.cobs.route(frame.id, frame.is_ext())
    }

    /// Hands a decoded frame back once it is written, so that its label buffer (and an SDO
    /// body's box) serves the next frame (saves allocations per frame on the hot paths).
    #[inline]
    pub fn recycle(&mut self, decoded: Decoded) {
        let mut label = decoded.label;
        label.clear();
        self.spare = label;
        if let Body::Sdo(sdo) = decoded.body {
            self.spare_sdo = Some(sdo);
        }
    }

    /// `sdo` in a box, the one [`Decoder::recycle`] handed back when there is one.
    fn boxed_sdo(&mut self, sdo: SdoFrame) -> Box<SdoFrame> {
        match self.spare_sdo.take() {
            Some(mut spare) => {
                *spare = sdo;
                spare
            }
            None => Box::new(sdo),
        }
    }

    /// Decodes one frame, updating the bus state.
    pub fn decode(&mut self, frame: &Frame) -> Decoded {
        let route = self.route(frame);
        self.decode_routed(frame, route)
    }

    fn decode_routed(&mut self, frame: &Frame, route: Route) -> Decoded {
        self.seq += 1;
        let payload = frame.payload();
        let node = route.node;
        let n = node.unwrap_or(0);
        let mut rtr_problem = None;
        if frame.is_rtr() && !matches!(route.kind, Kind::Heartbeat | Kind::Tpdo | Kind::Other) {
            rtr_problem = Some(format!("remote frame on a {} COB-ID", route.kind.as_str()));
        }
        let (label, body, problem) = match route.kind {
            Kind::ErrorFrame => (
                error_frame::label(frame.id, payload),
                Body::ErrorFrame { class: frame.id },
                None,
            ),
            Kind::Nmt => {
                let (m, p) = nmt::decode(payload);
                (m.label(), Body::Nmt(m), p)
            }
            Kind::Sync => {
                let (s, p) = sync::decode(payload);
                (s.label(), Body::Sync(s), p)
            }
            Kind::Time => {
                let (t, p) = time::decode(payload);
                (t.label(), Body::Time(t), p)
            }
            Kind::Emcy => {
                let (e, p) = emcy::decode(payload, &self.dicts[n as usize]);
                (e.label(n), Body::Emcy(e), p)
            }
            Kind::Heartbeat => {
                let (h, p) = heartbeat::decode(payload, frame.is_rtr());
                (h.label(n), Body::Heartbeat(h), p)
            }
            Kind::Lss => {
                let (l, p) = lss::decode(payload, frame.id == 0x7E5);
                (l.label(), Body::Lss(l), p)
            }
            Kind::Tpdo | Kind::Rpdo => self.decode_pdo(frame, route),
            Kind::SdoRx | Kind::SdoTx => {
                let c2s = route.kind == Kind::SdoRx;
                let tracked = self.track_sdo(frame, route);
                let mut s = labelled(tracked, payload, &self.dicts[n as usize]);
                // Controlword and statusword bits are named per the node's mode in force.
                if let (Some(mode), Some((index @ (0x6040 | 0x6041), 0)), Some(v)) =
                    (self.bus(frame.iface).mode(n), s.object, s.value.as_mut())
                    && let Some(typed) = &v.typed
                {
                    v.text = value_text::object_text(&self.dicts[n as usize], index, 0, typed, Some(mode));
                }
                // The tracker sees vendor commands too (as unknown commands), so that
                // their standard replies do not disturb a running transfer.
                match vendor_sdo::decode(&self.dicts[n as usize], c2s, payload) {
                    Some(v) => (v.label(), Body::VendorSdo(v), None),
                    None => {
                        let p = s.malformed();
                        let mut label = std::mem::take(&mut self.spare);
                        s.write_label(&mut label);
                        (label, Body::Sdo(self.boxed_sdo(s)), p)
                    }
                }
            }
            Kind::Other => {
                let label = if route.reserved {
                    format!("Reserved COB-ID 0x{:03X}", frame.id)
                } else if frame.is_ext() {
                    format!("29-bit frame 0x{:08X}", frame.id)
                } else {
                    format!("Not a predefined CANopen COB-ID (0x{:03X})", frame.id)
                };
                let p = route
                    .reserved
                    .then(|| format!("COB-ID 0x{:03X} is reserved by CiA 301", frame.id));
                (label, Body::None, p)
            }
        };
        let malformed = match (rtr_problem, problem) {
            (Some(a), Some(b)) => Some(format!("{a}; {b}")),
            (a, b) => a.or(b),
        };
        Decoded {
            kind: route.kind,
            node,
            label,
            body,
            malformed,
        }
    }

    /// Feeds a frame into the bus state without building its label or body: SDO transfers
    /// (and what their completion teaches) and modes of operation mapped into PDOs. The
    /// cheap path for `--transactions`: the transactions and the state afterwards are those
    /// [`Decoder::decode`] gives.
    pub fn track(&mut self, frame: &Frame) {
        let route = self.route(frame);
        match route.kind {
            Kind::SdoRx | Kind::SdoTx => {
                self.seq += 1;
                self.track_sdo(frame, route);
            }
            Kind::Tpdo | Kind::Rpdo if self.maps_mode(frame.iface, route) => {
                self.decode_routed(frame, route);
            }
            _ => self.seq += 1,
        }
    }

    /// Whether the mapping in force for the PDO of `route` carries the mode of operation
    /// (0x6060/0x6061), which decoding the PDO records.
    fn maps_mode(&self, iface: u16, route: Route) -> bool {
        let key = (route.node.unwrap_or(0), route.kind == Kind::Tpdo, route.pdo);
        self.bus(iface).mappings.get(&key).is_some_and(|m| {
            m.entries
                .iter()
                .any(|e| matches!((e.index, e.sub), (0x6060 | 0x6061, 0)))
        })
    }

    /// Feeds an SDO frame to the transfer tracker and learns from the transfers it
    /// completes (COB-IDs, PDO mappings, modes); returns the frame as the tracker read it.
    fn track_sdo(&mut self, frame: &Frame, route: Route) -> Tracked {
        let n = route.node.unwrap_or(0);
        let c2s = route.kind == Kind::SdoRx;
        let key = NodeKey::of(frame, n);
        if c2s {
            let ours = frame.direction() == crate::frame::Direction::Tx;
            self.bus_mut(frame.iface).set_ours(n, ours);
        }
        let dict = &self.dicts[n as usize & 0x7F];
        let s = self.sdo.track(self.seq, frame.ts_ns, key, c2s, frame.payload(), dict);
        for mut t in self.sdo.drain_completed() {
            let dict = &self.dicts[t.node as usize & 0x7F];
            let bus = Self::bus_in(&mut self.buses, &self.fresh, t.iface);
            t.mode = bus.mode(t.node);
            bus.learn(&t, dict);
            self.completed.push(t);
        }
        s
    }

    /// A PDO frame (per [`Decoder::peek`]) decoded as [`Decoder::decode`] decodes it, bus
    /// state included (modes of operation), but with no label, `malformed` or mapping source
    /// and its signals without names or texts: for callers that keep values (the TUI's index).
    /// `peeked` is what [`Decoder::peek`] says of the frame (not routed again).
    pub fn pdo_values(&mut self, frame: &Frame, peeked: (Kind, Option<u8>, u16)) -> Decoded {
        let (kind, node, num) = peeked;
        debug_assert!(matches!(kind, Kind::Tpdo | Kind::Rpdo));
        self.seq += 1;
        let n = node.unwrap_or(0);
        let transmit = kind == Kind::Tpdo;
        let signals = match self.bus(frame.iface).mappings.get(&(n, transmit, num)) {
            Some(m) if !frame.is_rtr() => pdo::decode_values(frame.payload(), m, &self.dicts[n as usize & 0x7F]),
            _ => Vec::new(),
        };
        self.note_mode(NodeKey::of(frame, n), &signals);
        Decoded {
            kind,
            node,
            label: String::new(),
            body: Body::Pdo(Pdo {
                num,
                transmit,
                signals,
                source: None,
            }),
            malformed: None,
        }
    }

    /// Records a mode of operation carried by PDO `signals` of node `n`.
    fn note_mode(&mut self, n: NodeKey, signals: &[pdo::Signal]) {
        for s in signals {
            if matches!((s.index, s.sub), (0x6060 | 0x6061, 0)) {
                let mode = s.value.as_i64().map(|m| m as i8);
                if self.bus(n.iface).mode(n.node) != mode {
                    self.bus_mut(n.iface).set_mode(n.node, mode);
                }
            }
        }
    }

    fn decode_pdo(&mut self, frame: &Frame, route: Route) -> (String, Body, Option<String>) {
        let n = route.node.unwrap_or(0);
        let transmit = route.kind == Kind::Tpdo;
        let payload = frame.payload();
        if frame.is_rtr() {
            let name = if transmit { "TPDO" } else { "RPDO" };
            let pdo = Pdo {
                num: route.pdo,
                transmit,
                signals: Vec::new(),
                source: None,
            };
            return (
                format!("{name}{} node {n}: remote request", route.pdo),
                Body::Pdo(pdo),
                None,
            );
        }
        let bus = self.bus(frame.iface);
        let (signals, source, problem) = match bus.mappings.get(&(n, transmit, route.pdo)) {
            Some(m) => {
                let mode = bus.mode(n);
                let (s, p) = pdo::decode_signals(payload, m, &self.dicts[n as usize & 0x7F], mode);
                (s, Some(m.source.clone()), p)
            }
            None => (Vec::new(), None, None),
        };
        self.note_mode(NodeKey::of(frame, n), &signals);
        let pdo = Pdo {
            num: route.pdo,
            transmit,
            signals,
            source,
        };
        let mut label = std::mem::take(&mut self.spare);
        pdo.write_label(&mut label, n, payload);
        (label, Body::Pdo(pdo), problem)
    }

    /// The communication parameters of a PDO seen in SDO transfers (else the COB-ID of
    /// its mapping in force, when that names one).
    pub fn pdo_comm(&self, node: NodeKey, transmit: bool, num: u16) -> Option<CommParams> {
        let bus = self.bus(node.iface);
        let key = (node.node, transmit, num);
        let seen = bus.comm.get(&key).copied();
        let cob = bus.mappings.get(&key).and_then(|m| m.cob_id);
        match (seen, cob) {
            (Some(mut c), Some(cob)) => {
                c.cob_id = c.cob_id.or(Some(cob));
                Some(c)
            }
            (Some(c), None) => Some(c),
            (None, cob @ Some(_)) => Some(CommParams {
                cob_id: cob,
                ..CommParams::default()
            }),
            (None, None) => None,
        }
    }

    /// Every PDO the decoder knows something about (a mapping or communication
    /// parameters), in order of interface, node, RPDO before TPDO, number.
    pub fn known_pdos(&self) -> Vec<(NodeKey, PdoId)> {
        let mut out = Vec::new();
        let buses = self.buses.iter().enumerate();
        for (iface, bus) in buses.filter_map(|(i, b)| Some((i, b.as_deref()?))) {
            let mut keys: Vec<PdoKey> = bus.mappings.keys().chain(bus.comm.keys()).copied().collect();
            keys.sort_unstable();
            keys.dedup();
            let iface = u16::try_from(iface).unwrap_or(u16::MAX);
            out.extend(
                keys.into_iter()
                    .map(|(node, transmit, num)| (NodeKey::new(iface, node), PdoId { transmit, num })),
            );
        }
        out
    }

    /// Forgets the SDO transactions completed since the last take: a decoder that only
    /// replays frames for their labels calls it after each frame, so a long replay (a search
    /// through the whole trace) does not pile up transfers nobody takes.
    pub fn forget_transactions(&mut self) {
        self.completed.clear();
    }

    /// SDO transactions completed since the last call.
    pub fn take_transactions(&mut self) -> Vec<Transaction> {
        std::mem::take(&mut self.completed)
    }

    /// Ends the input: returns completed transactions plus those left incomplete.
    pub fn finish(&mut self) -> Vec<Transaction> {
        let mut all = std::mem::take(&mut self.completed);
        all.extend(self.sdo.finish().into_iter().map(|mut t| {
            t.mode = self.bus(t.iface).mode(t.node);
            t
        }));
        all
    }
}

/// COB-ID value of a communication object (bit 29 = 29-bit frame) as a table key.
fn cob_key(v: u32) -> CobId {
    let ext = v & (1 << 29) != 0;
    CobId {
        id: if ext { v & 0x1FFF_FFFF } else { v & 0x7FF },
        ext,
    }
}
