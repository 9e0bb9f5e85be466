//! A simulated CiA 402 drive: NMT slave with boot-up and heartbeat, SDO server,
//! TPDOs on SYNC and RPDOs from its mapping objects, the CiA 402 state machine
//! (transitions 0..16), profile velocity motion and EMCY on faults, and an LSS slave
//! (a drive made with node-ID 0xFF only answers LSS until it is given one and reset).
//! Drives that are not CiA 402 (Dexmart, AQMD) act through [`super::vendor`] instead of
//! the state machine. PDOs follow their communication parameters (CiA 301, see
//! [`Tpdo`]): RPDOs with a synchronous transmission type (0..240) take effect at the next
//! SYNC, 254/255 at once; TPDOs go out every N-th SYNC (1..240), after a SYNC when their
//! data changed (0), on a remote request (252/253), or on change and on their event timer
//! (254/255), never closer together than their inhibit time.
//!
//! Pure: frames and the current time in, frames out.

use super::od::DeviceObjects;
use super::profile;
use super::vendor::Kind;
use super::vendor::Vendor;
use crate::cob;
use crate::decode::cia402::DriveState;
use crate::frame::Frame;
use crate::lss::{self, Address, UNCONFIGURED};
use crate::sdo::server::{SdoServer, ServerConfig};

/// NMT state of a simulated node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NmtState {
    PreOperational,
    Operational,
    Stopped,
}

impl NmtState {
    /// The heartbeat state byte.
    pub fn byte(self) -> u8 {
        match self {
            NmtState::PreOperational => 0x7F,
            NmtState::Operational => 0x05,
            NmtState::Stopped => 0x04,
        }
    }
}

/// Mode of operation: profile position.
pub const MODE_PP: i8 = 1;
/// Mode of operation: profile velocity.
pub const MODE_PV: i8 = 3;
/// Mode of operation: profile torque.
pub const MODE_PT: i8 = 4;
/// Mode of operation: homing.
pub const MODE_HM: i8 = 6;
/// Mode of operation: cyclic synchronous position.
pub const MODE_CSP: i8 = 8;
/// Mode of operation: cyclic synchronous velocity.
pub const MODE_CSV: i8 = 9;
/// Mode of operation: cyclic synchronous torque.
pub const MODE_CST: i8 = 10;
/// Time a simulated homing run takes (s).
const HOMING_S: f64 = 0.5;

/// One simulated drive.
#[derive(Clone, Debug)]
pub struct Drive {
    node: u8,
    profile: profile::DriveProfile,
    lss: lss::slave::Slave,
    /// Sends nothing at all (a node that died or lost its bus connection).
    silent: bool,
    od: DeviceObjects,
    sdo: SdoServer,
    nmt: NmtState,
    state: DriveState,
    /// Controlword bit 7 as last seen, for the rising edge of fault reset.
    reset_bit: bool,
    /// Controlword bit 4 as last seen (new set-point / homing start).
    setpoint_bit: bool,
    /// Profile position: the position the drive is moving to.
    pp_target: Option<f64>,
    /// Homing: seconds left of the homing run.
    homing_left: Option<f64>,
    /// Homing attained.
    homed: bool,
    /// DC link voltage present (statusword bit 4; needed for Switch on).
    mains: bool,
    /// Velocity in raw 0x606C units (fractional part kept here, 0x606C holds the integer).
    velocity: f64,
    /// Position units one raw velocity unit covers per second.
    position_per_velocity: f64,
    position: f64,
    last_ns: Option<u64>,
    next_heartbeat_ns: Option<u64>,
    pending_fault: Option<u16>,
    /// Vendor behaviour (drives that are not CiA 402).
    vendor: Vendor,
    /// Synchronous RPDOs received since the last SYNC, by PDO number (0-based).
    sync_rpdo: [Option<Vec<u8>>; 4],
    /// The transmission state of each TPDO (0-based).
    tpdo: [Tpdo; 4],
}

/// The transmission state of one TPDO, driven by its communication parameters 0x1800+n
/// (CiA 301 7.2.2): sub 2 transmission type, sub 3 inhibit time (100 µs), sub 5 event
/// timer (ms). Reset when the node leaves operational, so that the first chance after an
/// NMT start sends the current values (nothing has been sent yet).
#[derive(Clone, Debug, Default)]
struct Tpdo {
    /// SYNCs counted toward the next synchronous send (types 1..240).
    syncs: u64,
    /// The data last sent (types 0, 254, 255 send when it changes).
    last_data: Option<Vec<u8>>,
    /// When it was last sent (inhibit time).
    last_sent_ns: Option<u64>,
    /// An event that waits for the inhibit time to pass.
    pending: bool,
    /// When the event timer runs out.
    timer_due_ns: Option<u64>,
    /// Type 252: the data sampled at the last SYNC, sent on the next remote request.
    sampled: Option<Vec<u8>>,
}

/// Transmission types of 0x1800+n sub 2 (CiA 301 table 71).
const ACYCLIC_SYNC: u64 = 0;
const RTR_SYNC: u64 = 252;
const RTR_EVENT: u64 = 253;
const EVENT_MANUFACTURER: u64 = 254;
const EVENT_PROFILE: u64 = 255;

impl Drive {
    /// A drive at `node` with the object dictionary of `profile` (see [`profile::drive_objects`]).
    /// `node` 0xFF makes a drive without a node-ID that answers only LSS.
    pub fn new(node: u8, profile: profile::DriveProfile) -> Drive {
        let od = profile::drive_objects(node, profile.clone());
        let address = Address {
            vendor: od.uint(0x1018, 1) as u32,
            product: od.uint(0x1018, 2) as u32,
            revision: od.uint(0x1018, 3) as u32,
            serial: od.uint(0x1018, 4) as u32,
        };
        let profile_kind = profile.kind;
        Drive {
            node,
            lss: lss::slave::Slave::new(address, node),
            silent: false,
            position_per_velocity: profile.position_per_velocity,
            profile,
            od,
            sdo: SdoServer::new(ServerConfig::default()),
            nmt: NmtState::PreOperational,
            state: DriveState::SwitchOnDisabled,
            reset_bit: false,
            setpoint_bit: false,
            pp_target: None,
            homing_left: None,
            homed: false,
            mains: true,
            velocity: 0.0,
            position: 0.0,
            last_ns: None,
            next_heartbeat_ns: None,
            pending_fault: None,
            vendor: Vendor::new(profile_kind),
            sync_rpdo: Default::default(),
            tpdo: Default::default(),
        }
    }
    /// The node id.
    pub fn node(&self) -> u8 {
        self.node
    }
    /// The built-in profile the drive's dictionary comes from.
    pub fn dictionary(&self) -> &'static str {
        self.profile.dictionary
    }
    /// The NMT state.
    pub fn nmt(&self) -> NmtState {
        self.nmt
    }
    /// The CiA 402 state.
    pub fn state(&self) -> DriveState {
        self.state
    }
    /// The object dictionary (read-only view).
    pub fn objects(&self) -> &DeviceObjects {
        &self.od
    }
    /// Switches the simulated DC link voltage on or off.
    pub fn set_mains(&mut self, on: bool) {
        self.mains = on;
        if !on && matches!(self.state, DriveState::SwitchedOn | DriveState::OperationEnabled) {
            // Losing the DC link in a powered state is a fault (undervoltage).
            self.pending_fault = Some(0x3220);
        }
        self.update_statusword();
    }
    /// The drive's dictionary as an EDS (the objects it answers, with their defaults), for
    /// tools that need one to talk to it.
    pub fn eds(&self) -> String {
        let o = &self.od;
        let info = crate::od::dcf::DeviceInfo {
            vendor_name: "cotui simulation".into(),
            vendor_number: o.uint(0x1018, 1) as u32,
            product_name: self.profile.device_name.clone(),
            product_number: o.uint(0x1018, 2) as u32,
            revision_number: o.uint(0x1018, 3) as u32,
            node_id: None,
            description: format!("{} as simulated by cotui sim", self.profile.device_name),
            file_name: String::new(),
        };
        crate::od::dcf::write(&info, &o.dcf_entries())
    }
    /// Silences the node (nothing sent, nothing answered) or brings it back.
    pub fn set_silent(&mut self, silent: bool) {
        self.silent = silent;
    }
    /// Is the node silenced?
    pub fn is_silent(&self) -> bool {
        self.silent
    }
    /// Has the node a node-ID (not 0xFF)?
    fn configured(&self) -> bool {
        self.node != UNCONFIGURED
    }
    /// Makes the drive go to Fault at its next step with this EMCY error code.
    pub fn inject_fault(&mut self, code: u16) {
        self.pending_fault = Some(code);
    }

    /// Power-on: boot-up message, pre-operational.
    pub fn power_on(&mut self, now_ns: u64) -> Vec<Frame> {
        self.reset(0x1000..=0xFFFF);
        self.boot(now_ns)
    }

    fn reset(&mut self, range: std::ops::RangeInclusive<u16>) {
        self.od.reset(range.clone());
        self.sdo = SdoServer::new(ServerConfig::default());
        self.sync_rpdo = Default::default();
        self.tpdo = Default::default();
        if range.contains(&0x2000) {
            self.vendor = Vendor::new(self.profile.kind);
            super::vendor::init_objects(self.profile.kind, &mut self.od);
        } else {
            self.vendor
                .on_communication_reset(&mut self.od, self.profile.dictionary);
        }
        if range.contains(&0x6000) {
            // Reset of the application: the power stage starts over.
            self.state = DriveState::SwitchOnDisabled;
            self.velocity = 0.0;
            self.position = 0.0;
            self.reset_bit = false;
            self.setpoint_bit = false;
            self.pp_target = None;
            self.homing_left = None;
            self.homed = false;
        }
        self.od.set_int(0x6061, 0, self.od.int(0x6060, 0));
        self.update_statusword();
    }

    fn boot(&mut self, now_ns: u64) -> Vec<Frame> {
        self.nmt = NmtState::PreOperational;
        if !self.configured() {
            self.next_heartbeat_ns = None;
            return Vec::new();
        }
        self.next_heartbeat_ns = self.heartbeat_period_ns().map(|p| now_ns + p);
        vec![Frame::classic(cob::heartbeat(self.node), &[0])]
    }

    /// NMT reset: a node-ID configured by LSS comes into use, with the communication
    /// objects of the new node-ID.
    fn take_lss_node_id(&mut self) {
        let node = self.lss.reset_communication();
        if node != self.node {
            self.node = node;
            self.od = profile::drive_objects(node, self.profile.clone());
        }
    }

    fn heartbeat_period_ns(&self) -> Option<u64> {
        let ms = self.od.uint(0x1017, 0);
        (ms > 0).then_some(ms * 1_000_000)
    }

    /// Handles one frame from the bus at `now_ns`; returns the frames the drive sends.
    pub fn on_frame(&mut self, f: &Frame, now_ns: u64) -> Vec<Frame> {
        if self.silent || f.is_err() || f.is_ext() || f.is_fd() {
            return Vec::new();
        }
        if f.id == lss::MASTER_ID && !f.is_rtr() {
            return self
                .lss
                .on_request(f.payload())
                .map_or_else(Vec::new, |r| vec![Frame::classic(lss::SLAVE_ID, &r)]);
        }
        if !self.configured() && f.id != 0x000 {
            return Vec::new();
        }
        let node = self.node;
        let mut out = match f.id {
            0x000 => self.on_nmt(f.payload(), now_ns),
            0x080 if self.nmt == NmtState::Operational => {
                let mut out = self.apply_sync_rpdos();
                out.extend(self.on_sync());
                out
            }
            id if self.nmt == NmtState::Operational && f.is_rtr() => self.on_remote_request(id, now_ns),
            id if id == cob::sdo_request(node) && self.nmt != NmtState::Stopped && !f.is_rtr() => {
                let replies = self.sdo.on_frame(f.payload(), now_ns, &mut self.od).frames;
                let mut out: Vec<Frame> = replies
                    .iter()
                    .map(|r| Frame::classic(cob::sdo_response(node), r))
                    .collect();
                if self.profile.kind == Kind::Dexmart && alarm_reset(f.payload(), replies.first()) {
                    out.extend(self.clear_fault());
                }
                let faulted = self.faulted();
                self.vendor.on_sdo(&mut self.od, self.profile.dictionary, faulted);
                out.extend(self.apply_objects());
                out
            }
            id if self.nmt == NmtState::Operational && !f.is_rtr() => self.on_rpdo(id, f.payload()),
            _ => Vec::new(),
        };
        // What the frame changed (an SDO or RPDO write, a state transition) is an event
        // for the event-driven TPDOs.
        out.extend(self.event_tpdos(now_ns));
        out
    }

    fn on_nmt(&mut self, p: &[u8], now_ns: u64) -> Vec<Frame> {
        let [cs, target, ..] = p else { return Vec::new() };
        if *target != 0 && (*target != self.node || !self.configured()) {
            return Vec::new();
        }
        if *cs != 0x01 {
            // Out of operational no PDO goes out; the next start sends afresh.
            self.tpdo = Default::default();
        }
        match cs {
            0x01 => self.nmt = NmtState::Operational,
            0x02 => self.nmt = NmtState::Stopped,
            0x80 => self.nmt = NmtState::PreOperational,
            0x81 => {
                self.take_lss_node_id();
                self.reset(0x1000..=0xFFFF);
                return self.boot(now_ns);
            }
            0x82 => {
                self.take_lss_node_id();
                self.reset(0x1000..=0x1FFF);
                return self.boot(now_ns);
            }
            _ => {}
        }
        Vec::new()
    }

    /// The COB-ID of a PDO communication parameter, when valid (bit 31 clear).
    fn pdo_cob(&self, comm: u16) -> Option<u32> {
        let cob = self.od.uint(comm, 1) as u32;
        (self.od.entry(comm, 1).is_some() && cob & 0x8000_0000 == 0).then_some(cob & 0x7FF)
    }

    /// An RPDO: stored at once (asynchronous types 254/255) or at the next SYNC.
    fn on_rpdo(&mut self, id: u32, p: &[u8]) -> Vec<Frame> {
        let mut out = Vec::new();
        for n in 0..4u16 {
            if self.pdo_cob(0x1400 + n) != Some(id) {
                continue;
            }
            if self.od.uint(0x1400 + n, 2) <= 240 {
                self.sync_rpdo[n as usize] = Some(p.to_vec());
            } else {
                out.extend(self.take_rpdo(n, p));
            }
        }
        out
    }

    /// The synchronous RPDOs received since the last SYNC take effect.
    fn apply_sync_rpdos(&mut self) -> Vec<Frame> {
        let mut out = Vec::new();
        for n in 0..4u16 {
            if let Some(p) = self.sync_rpdo[n as usize].take() {
                out.extend(self.take_rpdo(n, &p));
            }
        }
        out
    }

    /// Writes RPDO `n`'s data into the mapped objects and acts on them.
    fn take_rpdo(&mut self, n: u16, p: &[u8]) -> Vec<Frame> {
        let map = 0x1600 + n;
        let mut bit = 0usize;
        for i in 1..=self.od.uint(map, 0) as u8 {
            let e = self.od.uint(map, i) as u32;
            let (index, sub, bits) = ((e >> 16) as u16, (e >> 8) as u8, (e & 0xFF) as usize);
            let bytes = bits / 8;
            if bit / 8 + bytes > p.len() {
                break;
            }
            self.od.set(index, sub, &p[bit / 8..bit / 8 + bytes]);
            bit += bits;
        }
        let replies = self.vendor.on_rpdo(n, &self.od, self.faulted());
        let mut out = self.apply_objects();
        out.extend(replies.into_iter().filter_map(|t| self.tpdo_frame(t)));
        out
    }

    /// TPDO `n` (0-based) with the current values of its mapped objects, when valid.
    fn tpdo_frame(&self, n: u16) -> Option<Frame> {
        let cob = self.pdo_cob(0x1800 + n)?;
        let map = 0x1A00 + n;
        let mut data = Vec::new();
        for i in 1..=self.od.uint(map, 0) as u8 {
            let e = self.od.uint(map, i) as u32;
            let (index, sub, bits) = ((e >> 16) as u16, (e >> 8) as u8, (e & 0xFF) as usize);
            let mut v = self.od.entry(index, sub).map(|x| x.data.clone()).unwrap_or_default();
            v.resize(bits / 8, 0);
            data.extend_from_slice(&v);
        }
        (data.len() <= 8).then(|| Frame::classic(cob, &data))
    }

    /// The transmission type of TPDO `n` (0x1800+n sub 2).
    fn tpdo_type(&self, n: u16) -> u64 {
        self.od.uint(0x1800 + n, 2)
    }

    /// A SYNC: the synchronous TPDOs that are due (every N-th SYNC for types 1..240; type 0
    /// when its data changed since it was last sent); type 252 samples its data.
    fn on_sync(&mut self) -> Vec<Frame> {
        let mut out = Vec::new();
        for n in 0..4u16 {
            let kind = self.tpdo_type(n);
            let Some(frame) = self.tpdo_frame(n) else {
                continue;
            };
            let data = frame.payload().to_vec();
            let t = &mut self.tpdo[n as usize];
            let send = match kind {
                ACYCLIC_SYNC => t.last_data.as_ref() != Some(&data),
                1..=240 => {
                    t.syncs += 1;
                    let due = t.syncs >= kind;
                    if due {
                        t.syncs = 0;
                    }
                    due
                }
                RTR_SYNC => {
                    t.sampled = Some(data);
                    continue;
                }
                _ => continue,
            };
            if send {
                t.last_data = Some(data);
                out.push(frame);
            }
        }
        out
    }

    /// A remote request for one of the drive's TPDOs: answered when its type is RTR-only
    /// (252 with the data sampled at the last SYNC, 253 with the current data) and its
    /// COB-ID allows remote requests (bit 30 clear).
    fn on_remote_request(&mut self, id: u32, now_ns: u64) -> Vec<Frame> {
        let mut out = Vec::new();
        for n in 0..4u16 {
            let kind = self.tpdo_type(n);
            let rtr_allowed = self.od.uint(0x1800 + n, 1) & 0x4000_0000 == 0;
            if self.pdo_cob(0x1800 + n) != Some(id) || !rtr_allowed || !(RTR_SYNC..=RTR_EVENT).contains(&kind) {
                continue;
            }
            let Some(mut frame) = self.tpdo_frame(n) else {
                continue;
            };
            let t = &mut self.tpdo[n as usize];
            if kind == RTR_SYNC
                && let Some(sampled) = &t.sampled
            {
                frame = Frame::classic(frame.id, sampled);
            }
            t.last_sent_ns = Some(now_ns);
            out.push(frame);
        }
        out
    }

    /// Does a change of TPDO `n`'s data make it go out? Types 255 (device profile
    /// events) and, for CiA 402 drives, 254; the manufacturer events of 254 on the vendor
    /// drives are their own (Dexmart: a TPDO in reply to each RPDO, see [`Vendor::on_rpdo`]).
    fn sends_on_change(&self, kind: u64) -> bool {
        kind == EVENT_PROFILE || (kind == EVENT_MANUFACTURER && self.profile.kind == Kind::Cia402)
    }

    /// The event-driven TPDOs (types 254/255) that go out at `now_ns`: when their data
    /// changed or their event timer ran out, once their inhibit time since the last send
    /// has passed (an event during the inhibit time waits for its end).
    fn event_tpdos(&mut self, now_ns: u64) -> Vec<Frame> {
        let mut out = Vec::new();
        let running = self.nmt == NmtState::Operational && self.configured() && !self.silent;
        for n in 0..4u16 {
            let kind = self.tpdo_type(n);
            let frame = self.tpdo_frame(n);
            let on_change = self.sends_on_change(kind);
            let period_ns = self.od.uint(0x1800 + n, 5) * 1_000_000;
            let inhibit_ns = self.od.uint(0x1800 + n, 3) * 100_000;
            let t = &mut self.tpdo[n as usize];
            let (true, Some(frame)) = (running && kind >= EVENT_MANUFACTURER, frame) else {
                t.pending = false;
                t.timer_due_ns = None;
                continue;
            };
            let data = frame.payload();
            if on_change && t.last_data.as_deref() != Some(data) {
                t.pending = true;
            }
            let mut timed_out = false;
            match t.timer_due_ns {
                _ if period_ns == 0 => t.timer_due_ns = None,
                Some(due) if now_ns >= due => {
                    t.pending = true;
                    timed_out = true;
                }
                Some(_) => {}
                None => t.timer_due_ns = Some(now_ns + period_ns),
            }
            let inhibited = t.last_sent_ns.is_some_and(|last| now_ns < last + inhibit_ns);
            if !t.pending || inhibited {
                continue;
            }
            t.pending = false;
            t.last_data = Some(data.to_vec());
            t.last_sent_ns = Some(now_ns);
            if period_ns > 0 {
                // The event timer restarts with every send; when it ran out, the next one
                // keeps its cycle (late ticks do not add up).
                t.timer_due_ns = Some(match t.timer_due_ns {
                    Some(due) if timed_out => due.max(now_ns.saturating_sub(period_ns)) + period_ns,
                    _ => now_ns + period_ns,
                });
            }
            out.push(frame);
        }
        out
    }

    /// Acts on objects written by SDO or RPDO: controlword and mode of operation.
    fn apply_objects(&mut self) -> Vec<Frame> {
        if self.profile.kind != Kind::Cia402 {
            return Vec::new();
        }
        let mode = self.od.int(0x6060, 0);
        self.od.set_int(0x6061, 0, mode);
        let cw = self.od.uint(0x6040, 0) as u16;
        let out = self.controlword(cw);
        self.update_statusword();
        out
    }

    /// Applies a controlword to the state machine (CiA 402 figure "state machine").
    fn controlword(&mut self, cw: u16) -> Vec<Frame> {
        use DriveState::*;
        let rising_reset = cw & 0x80 != 0 && !self.reset_bit;
        self.reset_bit = cw & 0x80 != 0;
        let shutdown = cw & 0x87 == 0x06;
        let switch_on = cw & 0x8F == 0x07;
        let enable = cw & 0x8F == 0x0F;
        let disable_voltage = cw & 0x82 == 0x00;
        let quick_stop = cw & 0x86 == 0x02;
        let qs_option = self.od.int(0x605A, 0);
        let mut out = Vec::new();
        self.state = match self.state {
            Fault if rising_reset => {
                // Transition 15; the reset EMCY tells the bus the error is gone.
                out = self.clear_fault();
                SwitchOnDisabled
            }
            SwitchOnDisabled if shutdown => ReadyToSwitchOn,
            ReadyToSwitchOn if switch_on && self.mains => SwitchedOn,
            ReadyToSwitchOn if enable && self.mains && self.mode_ok() => OperationEnabled,
            ReadyToSwitchOn if disable_voltage || quick_stop => SwitchOnDisabled,
            SwitchedOn if enable && self.mode_ok() => OperationEnabled,
            SwitchedOn if shutdown => ReadyToSwitchOn,
            SwitchedOn if disable_voltage || quick_stop => SwitchOnDisabled,
            OperationEnabled if switch_on => SwitchedOn,
            OperationEnabled if shutdown => ReadyToSwitchOn,
            OperationEnabled if disable_voltage => SwitchOnDisabled,
            OperationEnabled if quick_stop => QuickStopActive,
            QuickStopActive if disable_voltage => SwitchOnDisabled,
            QuickStopActive if enable && (5..=8).contains(&qs_option) => OperationEnabled,
            s => s,
        };
        if !matches!(self.state, OperationEnabled | QuickStopActive) {
            self.velocity = 0.0;
            self.pp_target = None;
            self.homing_left = None;
        }
        self.setpoint(cw);
        out
    }

    /// Controlword bit 4 in operation enabled: a new set-point (profile position, bit 6 =
    /// relative) or the start of homing.
    fn setpoint(&mut self, cw: u16) {
        let rising = cw & 0x10 != 0 && !self.setpoint_bit;
        self.setpoint_bit = cw & 0x10 != 0;
        if !rising || self.state != DriveState::OperationEnabled {
            return;
        }
        match self.mode() {
            MODE_PP => {
                let target = self.od.int(0x607A, 0) as f64;
                let base = if cw & 0x40 != 0 {
                    self.pp_target.unwrap_or(self.position)
                } else {
                    0.0
                };
                self.pp_target = Some(base + target);
            }
            MODE_HM => {
                self.homed = false;
                self.homing_left = Some(HOMING_S);
            }
            _ => {}
        }
    }

    fn mode(&self) -> i8 {
        self.od.int(0x6061, 0) as i8
    }

    /// A mode of operation the simulator can run (CiA 402 leaves "no mode" refusals to the vendor).
    fn mode_ok(&self) -> bool {
        matches!(
            self.mode(),
            MODE_PP | MODE_PV | MODE_PT | MODE_HM | MODE_CSP | MODE_CSV | MODE_CST
        )
    }

    /// Statusword bits 10 (target reached) and 12 (mode-specific) in operation enabled.
    fn mode_bits(&self) -> u16 {
        const REACHED: u16 = 0x0400;
        const BIT12: u16 = 0x1000;
        match self.mode() {
            MODE_PV | MODE_CSV => {
                let reached = (self.velocity - self.target_velocity()).abs() < 0.5;
                // Bit 12 in profile velocity: speed is zero; cyclic modes: following the target.
                let bit12 = self.mode() == MODE_CSV || self.velocity.abs() < 0.5;
                (u16::from(reached) * REACHED) | (u16::from(bit12) * BIT12)
            }
            MODE_PP => {
                let reached = self.pp_target.is_none_or(|t| (t - self.position).abs() < 0.5);
                (u16::from(reached) * REACHED) | (u16::from(self.setpoint_bit) * BIT12)
            }
            MODE_HM if self.homed => REACHED | BIT12,
            MODE_HM => 0,
            MODE_CSP | MODE_CST => REACHED | BIT12,
            _ => REACHED,
        }
    }

    /// In fault (or its reaction).
    fn faulted(&self) -> bool {
        matches!(self.state, DriveState::Fault | DriveState::FaultReactionActive)
    }

    /// Leaves the fault (CiA 402 transition 15; Dexmart: 300Ah Alarm Reset): error register
    /// and error code cleared, the reset EMCY sent.
    fn clear_fault(&mut self) -> Vec<Frame> {
        if !self.faulted() {
            return Vec::new();
        }
        self.od.set_int(0x603F, 0, 0);
        self.od.set_int(0x1001, 0, 0);
        self.state = DriveState::SwitchOnDisabled;
        vec![self.emcy(0x0000)]
    }

    fn emcy(&self, code: u16) -> Frame {
        let c = code.to_le_bytes();
        let reg = self.od.uint(0x1001, 0) as u8;
        Frame::classic(cob::emcy(self.node), &[c[0], c[1], reg, 0, 0, 0, 0, 0])
    }

    fn update_statusword(&mut self) {
        use DriveState::*;
        let base: u16 = match self.state {
            NotReadyToSwitchOn => 0x0000,
            SwitchOnDisabled => 0x0040,
            ReadyToSwitchOn => 0x0021,
            SwitchedOn => 0x0023,
            OperationEnabled => 0x0027,
            QuickStopActive => 0x0007,
            FaultReactionActive => 0x000F,
            Fault => 0x0008,
        };
        let mut sw = base | 0x0200; // remote
        if self.mains {
            sw |= 0x0010;
        }
        if self.state == OperationEnabled {
            sw |= self.mode_bits();
        }
        self.od.set_int(0x6041, 0, sw as i64);
        // Profile and cyclic torque: the torque follows its target while enabled.
        let torque = match self.mode() {
            MODE_PT | MODE_CST if self.state == OperationEnabled => self.od.int(0x6071, 0),
            _ => 0,
        };
        self.od.set_int(0x6077, 0, torque);
        self.od.set_int(0x606C, 0, self.velocity.round() as i64);
        self.od.set_int(0x6064, 0, self.position.round() as i64);
    }

    /// The velocity the drive is heading for now.
    fn target_velocity(&self) -> f64 {
        let halt = self.od.uint(0x6040, 0) & 0x100 != 0;
        if halt || self.state != DriveState::OperationEnabled {
            return 0.0;
        }
        match self.mode() {
            MODE_PV | MODE_CSV => self.od.int(0x60FF, 0) as f64,
            MODE_PP => match self.pp_target {
                Some(t) if (t - self.position).abs() >= 0.5 => {
                    let speed = (self.od.uint(0x6081, 0) as f64).max(1.0);
                    speed.copysign(t - self.position) / self.position_per_velocity
                }
                _ => 0.0,
            },
            _ => 0.0,
        }
    }

    /// Advances time to `now_ns`: motion, faults and heartbeats; returns the frames sent.
    pub fn tick(&mut self, now_ns: u64) -> Vec<Frame> {
        let mut out = Vec::new();
        let dt = self
            .last_ns
            .map(|t| now_ns.saturating_sub(t) as f64 / 1e9)
            .unwrap_or(0.0);
        self.last_ns = Some(now_ns);
        if let Some(code) = self.pending_fault.take() {
            self.state = DriveState::FaultReactionActive;
            self.od.set_int(0x603F, 0, code as i64);
            self.od.set_int(0x1001, 0, error_register(code) as i64);
            self.od.set_int(0x1003, 1, code as i64);
            self.od.set_int(0x1003, 0, 1);
            if self.nmt != NmtState::Stopped && self.configured() {
                out.push(self.emcy(code));
            }
            if self.profile.kind == Kind::Aqmd && self.nmt == NmtState::Operational {
                // AQMD manual: after an EMCY in operational the driver drops to
                // pre-operational and needs an NMT start.
                self.nmt = NmtState::PreOperational;
            }
        } else if self.state == DriveState::FaultReactionActive {
            // Transition 14: the fault reaction (motor stopped) is done.
            self.velocity = 0.0;
            self.state = DriveState::Fault;
        }
        if self.profile.kind == Kind::Cia402 {
            self.move_axis(dt);
            self.update_statusword();
        } else {
            let faulted = self.faulted();
            self.vendor.tick(dt, &mut self.od, faulted);
        }
        if self.silent {
            return Vec::new();
        }
        if !self.configured() {
            return out;
        }
        out.extend(self.event_tpdos(now_ns));
        if let Some(next) = self.next_heartbeat_ns {
            if now_ns >= next {
                out.push(Frame::classic(cob::heartbeat(self.node), &[self.nmt.byte()]));
                self.next_heartbeat_ns = self.heartbeat_period_ns().map(|p| next.max(now_ns - p) + p);
            }
        } else if let Some(p) = self.heartbeat_period_ns() {
            self.next_heartbeat_ns = Some(now_ns + p);
        }
        out
    }

    /// Ramps the velocity toward its target and integrates the position.
    fn move_axis(&mut self, dt: f64) {
        let (target, ramp) = match self.state {
            DriveState::QuickStopActive => (0.0, self.od.uint(0x6085, 0) as f64),
            _ => {
                let t = self.target_velocity();
                let ramp = if t.abs() > self.velocity.abs() { 0x6083 } else { 0x6084 };
                (t, self.od.uint(ramp, 0) as f64)
            }
        };
        let step = if ramp > 0.0 { ramp * dt } else { f64::INFINITY };
        let dv = (target - self.velocity).clamp(-step, step);
        let v0 = self.velocity;
        self.velocity += dv;
        let before = self.position;
        self.position += (v0 + self.velocity) / 2.0 * dt * self.position_per_velocity;
        if let Some(t) = self.pp_target
            && (before - t).signum() != (self.position - t).signum()
        {
            // Reached the set-point within this step: stop on it.
            self.position = t;
            self.velocity = 0.0;
        }
        if self.mode() == MODE_CSP && self.state == DriveState::OperationEnabled {
            self.position = self.od.int(0x607A, 0) as f64;
        }
        if let Some(left) = self.homing_left {
            if left <= dt {
                self.homing_left = None;
                self.homed = true;
                self.position = self.od.int(0x607C, 0) as f64;
            } else {
                self.homing_left = Some(left - dt);
            }
        }
        if self.state == DriveState::QuickStopActive
            && self.velocity == 0.0
            && (1..=4).contains(&self.od.int(0x605A, 0))
        {
            // Transition 12 after the quick stop ramp for option codes 1..4.
            self.state = DriveState::SwitchOnDisabled;
        }
    }
}

/// Is this SDO request, answered by `reply`, a successful expedited download of 0x0000
/// (Alarm Reset) to the Dexmart command object 300Ah?
fn alarm_reset(request: &[u8], reply: Option<&[u8; 8]>) -> bool {
    let [cs, 0x0A, 0x30, 0, data @ ..] = request else {
        return false;
    };
    cs & 0xE2 == 0x22 && data.iter().take(2).all(|b| *b == 0) && reply.is_some_and(|r| r[0] == 0x60)
}

/// The error register (0x1001) bits for an EMCY error code: generic plus the class
/// bit of current (0x2xxx), voltage (0x3xxx), temperature (0x4xxx) or communication (0x81xx).
pub fn error_register(code: u16) -> u8 {
    let class = match code >> 12 {
        0x2 => 0x02,
        0x3 => 0x04,
        0x4 => 0x08,
        0x8 if code & 0xFF00 == 0x8100 => 0x10,
        _ => 0x00,
    };
    0x01 | class
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::profile::DriveProfile;

    fn drive() -> Drive {
        let mut d = Drive::new(2, DriveProfile::servo("test", 1));
        d.power_on(0);
        d
    }

    /// Writes the controlword by expedited SDO and returns the statusword after it.
    fn cw(d: &mut Drive, value: u16) -> u16 {
        let v = value.to_le_bytes();
        let out = d.on_frame(&Frame::classic(0x602, &[0x2B, 0x40, 0x60, 0, v[0], v[1], 0, 0]), 0);
        assert_eq!(out[0].payload()[0], 0x60, "SDO download answered");
        d.objects().uint(0x6041, 0) as u16
    }

    #[test]
    fn an_unconfigured_drive_answers_only_lss_until_given_a_node_id_and_reset() {
        use crate::lss::Request;
        let profile = DriveProfile {
            serial_number: Some(77),
            ..DriveProfile::servo("test", 1)
        };
        let mut d = Drive::new(0xFF, profile);
        assert!(d.power_on(0).is_empty(), "no boot-up without a node-ID");
        assert!(d.tick(2_000_000_000).is_empty(), "no heartbeat without a node-ID");
        let lss = |d: &mut Drive, r: Request| d.on_frame(&Frame::classic(0x7E5, &r.encode()), 0);
        assert!(lss(&mut d, Request::SwitchGlobal(true)).is_empty());
        let serial = lss(&mut d, Request::Inquire(crate::lss::Part::Serial));
        assert_eq!(
            (serial[0].id, serial[0].payload()),
            (0x7E4, &[0x5D, 77, 0, 0, 0, 0, 0, 0][..])
        );
        let ok = lss(&mut d, Request::ConfigureNodeId(9));
        assert_eq!(ok[0].payload()[..2], [0x11, 0]);
        let boot = d.on_frame(&Frame::classic(0x000, &[0x82, 0]), 0);
        assert_eq!(
            (boot[0].id, boot[0].payload()),
            (0x709, &[0u8][..]),
            "boot-up as node 9"
        );
        let sdo = d.on_frame(&Frame::classic(0x609, &[0x40, 0x18, 0x10, 4, 0, 0, 0, 0]), 0);
        assert_eq!(
            (sdo[0].id, sdo[0].payload()[4]),
            (0x589, 77),
            "SDO as node 9, same serial"
        );
        d.set_silent(true);
        assert!(
            d.tick(4_000_000_000).is_empty()
                && d.on_frame(&Frame::classic(0x609, &[0x40, 0x18, 0x10, 4, 0, 0, 0, 0]), 0)
                    .is_empty()
        );
    }

    #[test]
    fn state_machine_transitions_and_statusword_values() {
        let mut d = drive();
        assert_eq!(d.objects().uint(0x6041, 0), 0x0250);
        assert_eq!(cw(&mut d, 0x06), 0x0231); // 2
        assert_eq!(cw(&mut d, 0x07), 0x0233); // 3
        assert_eq!(cw(&mut d, 0x0F) & 0x6F, 0x27); // 4
        assert_eq!(cw(&mut d, 0x07), 0x0233); // 5
        assert_eq!(cw(&mut d, 0x06), 0x0231); // 6
        assert_eq!(cw(&mut d, 0x00), 0x0250); // 7
        cw(&mut d, 0x06);
        cw(&mut d, 0x07);
        cw(&mut d, 0x0F);
        assert_eq!(cw(&mut d, 0x06), 0x0231); // 8
        cw(&mut d, 0x0F);
        assert_eq!(d.state(), DriveState::OperationEnabled); // 3+4 in one step
        assert_eq!(cw(&mut d, 0x00), 0x0250); // 9
        cw(&mut d, 0x06);
        cw(&mut d, 0x07);
        assert_eq!(cw(&mut d, 0x02), 0x0250); // 10
        cw(&mut d, 0x06);
        cw(&mut d, 0x0F);
        assert_eq!(cw(&mut d, 0x02) & 0x6F, 0x07); // 11, option code 6 stays in quick stop
        assert_eq!(cw(&mut d, 0x0F) & 0x6F, 0x27); // 16
        cw(&mut d, 0x02);
        assert_eq!(cw(&mut d, 0x00), 0x0250); // 12
    }

    #[test]
    fn fault_needs_a_rising_edge_of_bit_7() {
        let mut d = drive();
        d.on_frame(&Frame::classic(0x000, &[0x01, 0x02]), 0);
        cw(&mut d, 0x80);
        d.inject_fault(0x4310);
        let emcy = d.tick(1_000_000);
        assert_eq!(emcy[0].id, 0x82);
        assert_eq!(emcy[0].payload(), &[0x10, 0x43, 0x09, 0, 0, 0, 0, 0]);
        assert_eq!(d.state(), DriveState::FaultReactionActive); // 13
        assert_eq!(d.objects().uint(0x6041, 0), 0x021F);
        d.tick(2_000_000);
        assert_eq!(d.objects().uint(0x6041, 0), 0x0218); // 14
        // Bit 7 still set from before the fault: no edge, no reset.
        assert_eq!(cw(&mut d, 0x80), 0x0218);
        cw(&mut d, 0x00);
        let out = d.on_frame(&Frame::classic(0x602, &[0x2B, 0x40, 0x60, 0, 0x80, 0, 0, 0]), 0);
        assert_eq!(d.state(), DriveState::SwitchOnDisabled); // 15
        assert_eq!(out[1].payload(), &[0; 8], "reset EMCY");
        assert_eq!(d.objects().uint(0x603F, 0), 0);
    }

    #[test]
    fn quick_stop_option_2_ramps_down_then_disables() {
        let mut d = drive();
        d.on_frame(&Frame::classic(0x602, &[0x2B, 0x5A, 0x60, 0, 2, 0, 0, 0]), 0);
        d.on_frame(&Frame::classic(0x602, &[0x23, 0xFF, 0x60, 0, 0x10, 0x27, 0, 0]), 0);
        cw(&mut d, 0x06);
        cw(&mut d, 0x0F);
        for t in 0..=100u64 {
            d.tick(t * 10_000_000);
        }
        assert_eq!(d.objects().int(0x606C, 0), 10_000);
        assert!(d.objects().int(0x6064, 0) > 0);
        cw(&mut d, 0x02);
        assert_eq!(d.state(), DriveState::QuickStopActive);
        d.tick(1_010_000_000);
        assert_eq!(d.state(), DriveState::QuickStopActive, "still braking");
        for t in 102..=130u64 {
            d.tick(t * 10_000_000);
        }
        assert_eq!(d.state(), DriveState::SwitchOnDisabled);
        assert_eq!(d.objects().int(0x606C, 0), 0);
    }

    #[test]
    fn nmt_gates_pdos_and_sdo_and_resets_boot() {
        let mut d = drive();
        assert!(
            d.on_frame(&Frame::classic(0x080, &[]), 0).is_empty(),
            "no PDO in pre-operational"
        );
        d.on_frame(&Frame::classic(0x000, &[0x01, 0x00]), 0);
        let pdos = d.on_frame(&Frame::classic(0x080, &[]), 0);
        assert_eq!(pdos.iter().map(|f| f.id).collect::<Vec<_>>(), vec![0x182, 0x282]);
        assert_eq!(pdos[0].payload(), &[0x50, 0x02, 0x03]);
        d.on_frame(&Frame::classic(0x000, &[0x02, 0x02]), 0);
        assert!(
            d.on_frame(&Frame::classic(0x602, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]), 0)
                .is_empty()
        );
        let hb = d.tick(500_000_000);
        assert_eq!((hb[0].id, hb[0].payload()), (0x702, &[0x04][..]));
        let boot = d.on_frame(&Frame::classic(0x000, &[0x81, 0x00]), 0);
        assert_eq!((boot[0].id, boot[0].payload()), (0x702, &[0x00][..]));
        assert_eq!(d.nmt(), NmtState::PreOperational);
        assert!(d.on_frame(&Frame::classic(0x000, &[0x01, 0x03]), 0).is_empty());
        assert_eq!(d.nmt(), NmtState::PreOperational, "command for node 3 ignored");
    }

    #[test]
    fn an_aqmd_fault_stops_the_motor_and_drops_to_pre_operational() {
        let mut d = Drive::new(1, DriveProfile::aqmd_like());
        d.power_on(0);
        d.on_frame(&Frame::classic(0x000, &[0x01, 0x01]), 0);
        // Manual 7.5.4: RPDO1 "201 03 88 13 00 F4 01 00 00" (command 3, speed 5000).
        d.on_frame(&Frame::classic(0x201, &[0x03, 0x88, 0x13, 0x00, 0xF4, 0x01, 0, 0]), 0);
        d.tick(0);
        d.tick(1_000_000_000);
        assert_eq!(d.objects().int(0x2101, 0), 1000, "duty capped at 100 %");
        d.inject_fault(0x2310);
        let emcy = d.tick(1_010_000_000);
        assert_eq!(emcy[0].payload()[..3], [0x10, 0x23, 0x03]);
        assert_eq!(d.nmt(), NmtState::PreOperational);
        d.tick(3_000_000_000);
        assert_eq!(d.objects().int(0x2101, 0), 0, "stopped by the fault");
    }

    #[test]
    fn a_dexmart_fault_is_cleared_by_alarm_reset_300a() {
        let mut d = Drive::new(1, DriveProfile::dexmart_like());
        d.power_on(0);
        d.inject_fault(0x3210);
        d.tick(0);
        d.tick(10_000_000);
        assert_eq!(d.state(), DriveState::Fault);
        let out = d.on_frame(&Frame::classic(0x601, &[0x2B, 0x0A, 0x30, 0, 0, 0, 0, 0]), 0);
        assert_eq!(out[0].payload()[0], 0x60, "download answered");
        assert_eq!((out[1].id, out[1].payload()), (0x81, &[0u8; 8][..]), "reset EMCY");
        assert_eq!(d.objects().uint(0x1001, 0), 0);
        assert_ne!(d.state(), DriveState::Fault);
    }
}

/// The PDO communication parameters against the CiA 301 rules: frames and bus times in,
/// the TPDOs that come out.
#[cfg(test)]
mod pdo_tests {
    use super::*;
    use crate::frame::Flags;
    use crate::sim::profile::DriveProfile;

    const MS: u64 = 1_000_000;
    const TPDO1: u32 = cob::tpdo(1, 2);

    /// A servo at node 2 (TPDO1 = statusword + mode display), operational at 0 ms.
    fn running() -> Drive {
        let mut d = Drive::new(2, DriveProfile::servo("test", 1));
        d.power_on(0);
        d
    }

    fn start(d: &mut Drive, now_ns: u64) -> Vec<Frame> {
        d.on_frame(&Frame::classic(0x000, &[0x01, 0x00]), now_ns)
    }

    /// An expedited SDO download of `len` bytes of `value`, as a client would send it.
    fn write(d: &mut Drive, index: u16, sub: u8, value: u32, len: u8, now_ns: u64) -> Vec<Frame> {
        let cs = 0x23 | ((4 - len) << 2);
        let [i0, i1] = index.to_le_bytes();
        let [v0, v1, v2, v3] = value.to_le_bytes();
        let out = d.on_frame(
            &Frame::classic(cob::sdo_request(2), &[cs, i0, i1, sub, v0, v1, v2, v3]),
            now_ns,
        );
        assert_eq!(out[0].payload()[0], 0x60, "download of {index:04X}:{sub:02X} answered");
        out
    }

    fn sync(d: &mut Drive, now_ns: u64) -> Vec<Frame> {
        d.on_frame(&Frame::classic(cob::SYNC, &[]), now_ns)
    }

    fn tpdo1s(frames: &[Frame]) -> usize {
        frames.iter().filter(|f| f.id == TPDO1).count()
    }

    /// Which of the next `count` SYNCs (1-based, 100 ms apart from the drive's last tick,
    /// the drive ticking in between) TPDO1 followed.
    fn syncs_answered(d: &mut Drive, count: u64) -> Vec<u64> {
        let base = d.last_ns.unwrap_or(0) + 50 * MS;
        (1..=count)
            .filter(|k| {
                let t = base + k * 100 * MS;
                let mut out = d.tick(t - 50 * MS);
                out.extend(sync(d, t));
                tpdo1s(&out) > 0
            })
            .collect()
    }

    #[test]
    fn type_1_sends_on_every_sync_and_type_2_on_every_second() {
        let mut d = running();
        start(&mut d, 0);
        assert_eq!(syncs_answered(&mut d, 4), [1, 2, 3, 4]);
        write(&mut d, 0x1800, 2, 2, 1, 450 * MS);
        assert_eq!(syncs_answered(&mut d, 6), [2, 4, 6]);
        write(&mut d, 0x1800, 2, 5, 1, 1_060 * MS);
        assert_eq!(syncs_answered(&mut d, 10), [5, 10]);
    }

    #[test]
    fn type_0_sends_after_a_sync_only_when_the_data_changed() {
        let mut d = running();
        write(&mut d, 0x1800, 2, 0, 1, 0);
        start(&mut d, 0);
        // The first SYNC after the start sends the values (none sent yet), then silence.
        assert_eq!(syncs_answered(&mut d, 5), [1]);
        // Shutdown: the statusword changes; nothing until the next SYNC, then once.
        let out = write(&mut d, 0x6040, 0, 0x06, 2, 510 * MS);
        assert_eq!(tpdo1s(&out), 0, "acyclic synchronous waits for the SYNC");
        assert_eq!(tpdo1s(&d.tick(550 * MS)), 0);
        let sent: Vec<Frame> = sync(&mut d, 600 * MS).into_iter().filter(|f| f.id == TPDO1).collect();
        assert_eq!(sent.len(), 1);
        assert_eq!(sent[0].payload(), &[0x31, 0x02, 0x03], "ready to switch on");
        assert_eq!(syncs_answered(&mut d, 5), Vec::<u64>::new());
    }

    #[test]
    fn type_254_follows_its_event_timer_and_changes_never_closer_than_the_inhibit_time() {
        let mut d = running();
        write(&mut d, 0x1800, 2, 254, 1, 0);
        write(&mut d, 0x1800, 5, 100, 2, 0); // event timer 100 ms
        write(&mut d, 0x1800, 3, 300, 2, 0); // inhibit time 30 ms
        assert!(sync(&mut d, 0).is_empty(), "pre-operational");
        let mut sent = Vec::new();
        let mut record = |frames: Vec<Frame>, t: u64| {
            sent.extend(
                frames
                    .iter()
                    .filter(|f| f.id == TPDO1)
                    .map(|f| (t / MS, f.payload()[0])),
            );
        };
        record(start(&mut d, 0), 0);
        for k in 1..=100u64 {
            let t = k * 10 * MS;
            record(d.tick(t), t);
            record(sync(&mut d, t), t); // SYNCs do not trigger an event-driven TPDO
            if k == 34 {
                // Two changes 10 ms apart: the first goes out at once, the second when
                // the 30 ms inhibit time since the first has passed (the tick at 380 ms).
                record(write(&mut d, 0x6040, 0, 0x06, 2, 345 * MS), 345 * MS);
            }
            if k == 35 {
                record(write(&mut d, 0x6040, 0, 0x07, 2, 355 * MS), 355 * MS);
            }
        }
        let times: Vec<u64> = sent.iter().map(|(t, _)| *t).collect();
        assert_eq!(times, [0, 100, 200, 300, 345, 380, 480, 580, 680, 780, 880, 980]);
        assert_eq!(sent[4].1, 0x31, "ready to switch on");
        assert_eq!(sent[5].1, 0x33, "switched on");
        assert!(times.windows(2).all(|w| w[1] - w[0] >= 30), "{times:?}");
    }

    #[test]
    fn type_255_without_event_timer_sends_only_on_change() {
        let mut d = running();
        write(&mut d, 0x1800, 2, 255, 1, 0);
        assert_eq!(tpdo1s(&start(&mut d, 0)), 1, "the values once at the start");
        let quiet: usize = (1..=50u64).map(|k| tpdo1s(&d.tick(k * 10 * MS))).sum();
        assert_eq!(quiet, 0);
        assert_eq!(tpdo1s(&write(&mut d, 0x6040, 0, 0x06, 2, 505 * MS)), 1);
        assert_eq!(tpdo1s(&d.tick(510 * MS)), 0);
    }

    #[test]
    fn an_invalid_cob_id_sends_nothing_whatever_the_type() {
        for kind in [1u32, 0, 253, 254, 255] {
            let mut d = running();
            write(&mut d, 0x1800, 1, 0x8000_0000 | TPDO1, 4, 0);
            write(&mut d, 0x1800, 2, kind, 1, 0);
            write(&mut d, 0x1800, 5, 100, 2, 0);
            let mut out = start(&mut d, 0);
            for k in 1..=20u64 {
                out.extend(d.tick(k * 50 * MS));
                out.extend(sync(&mut d, k * 50 * MS));
            }
            out.extend(write(&mut d, 0x6040, 0, 0x06, 2, 1_010 * MS));
            let mut rtr = Frame::classic(TPDO1, &[]);
            rtr.flags.set(Flags::RTR, true);
            out.extend(d.on_frame(&rtr, 1_020 * MS));
            assert_eq!(tpdo1s(&out), 0, "type {kind}");
            assert!(out.iter().any(|f| f.id == cob::tpdo(2, 2)), "TPDO2 still goes out");
        }
    }

    #[test]
    fn rtr_only_types_answer_a_remote_request_and_nothing_else() {
        let mut rtr = Frame::classic(TPDO1, &[]);
        rtr.flags.set(Flags::RTR, true);
        rtr.len = 3;
        for kind in [252u32, 253] {
            let mut d = running();
            write(&mut d, 0x1800, 2, kind, 1, 0);
            write(&mut d, 0x1800, 5, 100, 2, 0);
            start(&mut d, 0);
            assert_eq!(syncs_answered(&mut d, 5), Vec::<u64>::new(), "type {kind}");
            // Shutdown after the last SYNC: 252 answers with what it sampled at the SYNC,
            // 253 with the value now.
            write(&mut d, 0x6040, 0, 0x06, 2, 510 * MS);
            let answer = d.on_frame(&rtr, 520 * MS);
            assert_eq!(answer.len(), 1, "type {kind}");
            assert_eq!(answer[0].id, TPDO1);
            assert!(!answer[0].is_rtr());
            let expect: &[u8] = if kind == 252 {
                &[0x50, 0x02, 0x03]
            } else {
                &[0x31, 0x02, 0x03]
            };
            assert_eq!(answer[0].payload(), expect, "type {kind}");
        }
        // A synchronous TPDO does not answer remote requests.
        let mut d = running();
        start(&mut d, 0);
        assert!(d.on_frame(&rtr, 10 * MS).is_empty());
    }

    #[test]
    fn a_synchronous_rpdo_takes_effect_at_the_next_sync_an_asynchronous_one_at_once() {
        let rpdo1 = |cw: u8| Frame::classic(cob::rpdo(1, 2), &[cw, 0, 0, 0, 0, 0]);
        let mut d = running();
        start(&mut d, 0);
        write(&mut d, 0x1400, 2, 1, 1, 0);
        d.on_frame(&rpdo1(0x06), 10 * MS);
        assert_eq!(d.state(), DriveState::SwitchOnDisabled, "waits for the SYNC");
        let out = sync(&mut d, 100 * MS);
        assert_eq!(d.state(), DriveState::ReadyToSwitchOn);
        let tpdo = out.iter().find(|f| f.id == TPDO1).unwrap();
        assert_eq!(tpdo.payload()[0], 0x31, "the TPDO of that SYNC shows the new state");
        write(&mut d, 0x1400, 2, 255, 1, 110 * MS);
        d.on_frame(&rpdo1(0x07), 120 * MS);
        assert_eq!(d.state(), DriveState::SwitchedOn, "event-driven: at once");
        write(&mut d, 0x1400, 1, 0x8000_0000 | cob::rpdo(1, 2), 4, 130 * MS);
        d.on_frame(&rpdo1(0x06), 140 * MS);
        sync(&mut d, 200 * MS);
        assert_eq!(d.state(), DriveState::SwitchedOn, "an invalid RPDO is ignored");
    }
}
