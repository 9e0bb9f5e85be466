//! Simulated CANopen devices for `cotui demo` and the tests: CiA 402 drives,
//! a SYNC producer and a minimal NMT master, all pure (frames and time in, frames
//! out). [`serve`] runs them on a bus on a tokio interval: [`demo`] on an in-process
//! virtual bus, `cotui sim` on a SocketCAN interface.

pub mod control;
pub mod demo;
pub mod drive;
pub mod od;
pub mod profile;
pub mod serve;
pub mod spec;
pub mod synth;
pub mod vendor;

use crate::decode::pdo::entry_from_u32;
use crate::frame::Frame;
use crate::od::{MappingSource, PdoMapping, Profile};
use drive::Drive;
use std::collections::BTreeMap;

/// A set of simulated nodes plus a SYNC producer.
#[derive(Clone, Debug)]
pub struct Simulation {
    drives: Vec<Drive>,
    /// SYNC period in ns (0 = no SYNC producer).
    sync_period_ns: u64,
    next_sync_ns: Option<u64>,
    /// When the built-in NMT master sends "start all nodes" (once), if at all.
    start_all_at_ns: Option<u64>,
}

/// The drives of the demo when `--node` is not given (`NODE=MODEL`, see [`spec`]).
pub const DEMO_NODES: [&str; 2] = ["2=aimotor", "3=syntron-ds"];

impl Simulation {
    /// Drives at the given nodes, SYNC every `sync_ms` (0 = none), no NMT master.
    pub fn new(drives: Vec<Drive>, sync_ms: u64) -> Simulation {
        Simulation {
            drives,
            sync_period_ns: sync_ms * 1_000_000,
            next_sync_ns: None,
            start_all_at_ns: None,
        }
    }
    /// The standard demo bus: an AIMOTOR-like drive at node 2 and a Syn-tron-like one at
    /// node 3 ([`DEMO_NODES`]), see [`Simulation::demo_with`].
    pub fn demo() -> Simulation {
        let drives = DEMO_NODES
            .iter()
            .filter_map(|s| spec::parse_node(s).ok())
            .map(|(node, p)| Drive::new(node, p))
            .collect();
        Simulation::demo_with(drives)
    }
    /// A demo bus with these drives, SYNC every 100 ms, and an NMT master that starts all
    /// nodes 0.8 s after power-on.
    pub fn demo_with(drives: Vec<Drive>) -> Simulation {
        let mut s = Simulation::new(drives, 100);
        s.start_all_at_ns = Some(800_000_000);
        s
    }
    /// The built-in profile each configured drive is modelled after: (node, profile name).
    pub fn profiles(&self) -> Vec<(u8, &'static str)> {
        self.drives
            .iter()
            .filter(|d| d.node() != crate::lss::UNCONFIGURED)
            .map(|d| (d.node(), d.dictionary()))
            .collect()
    }
    /// The PDO mappings each drive starts with, as a dictionary layer per node, so that
    /// the demo decodes PDOs from the first frame. The source reads "demo simulator".
    pub fn pdo_layers(&self) -> Vec<(u8, Profile)> {
        self.drives
            .iter()
            .filter(|d| d.node() != crate::lss::UNCONFIGURED)
            .map(|d| {
                let od = d.objects();
                let source = MappingSource::Profile("demo simulator".into());
                let read = |comm: u16, map: u16| -> BTreeMap<u8, PdoMapping> {
                    (0..4u16)
                        .filter(|n| od.has_index(map + n) && od.uint(map + n, 0) > 0)
                        .map(|n| {
                            let count = od.uint(map + n, 0) as u8;
                            let entries = (1..=count)
                                .map(|s| entry_from_u32(od.uint(map + n, s) as u32))
                                .collect();
                            let cob_id = Some(od.uint(comm + n, 1) as u32);
                            (
                                n as u8 + 1,
                                PdoMapping {
                                    cob_id,
                                    entries,
                                    source: source.clone(),
                                },
                            )
                        })
                        .collect()
                };
                // The device's own heartbeat default (as its EDS would give it), so the
                // Nodes pane knows the period before anyone reads 0x1017.
                let heartbeat = crate::od::ObjectInfo {
                    name: "Producer heartbeat time".into(),
                    data_type: crate::od::DataType::U16,
                    access: crate::od::Access::Rw,
                    unit: Some("ms".into()),
                    default: Some(crate::od::Value::Unsigned(od.uint(0x1017, 0))),
                    ..Default::default()
                };
                let layer = Profile {
                    // Named after the profile the drive is modelled on (the Nodes pane
                    // shows it); `cli::bind::bindings_on` renames it to the bound one.
                    name: d.dictionary().into(),
                    rpdo: read(0x1400, 0x1600),
                    tpdo: read(0x1800, 0x1A00),
                    objects: BTreeMap::from([((0x1017, 0), heartbeat)]),
                    ..Profile::default()
                };
                (d.node(), layer)
            })
            .collect()
    }

    /// Every simulated drive.
    pub fn drives(&self) -> &[Drive] {
        &self.drives
    }
    /// The drive at `node`.
    pub fn drive(&self, node: u8) -> Option<&Drive> {
        self.drives.iter().find(|d| d.node() == node)
    }
    /// The drive at `node`, to inject faults or switch its mains.
    pub fn drive_mut(&mut self, node: u8) -> Option<&mut Drive> {
        self.drives.iter_mut().find(|d| d.node() == node)
    }
    /// Powers every node on at `now_ns`: boot-ups. Timers of the master start here.
    pub fn power_on(&mut self, now_ns: u64) -> Vec<Frame> {
        if self.sync_period_ns > 0 {
            self.next_sync_ns = Some(now_ns + self.sync_period_ns);
        }
        if let Some(t) = self.start_all_at_ns.as_mut() {
            *t += now_ns;
        }
        self.drives.iter_mut().flat_map(|d| d.power_on(now_ns)).collect()
    }
    /// One frame seen on the bus (from anyone, including the simulation itself).
    pub fn on_frame(&mut self, f: &Frame, now_ns: u64) -> Vec<Frame> {
        self.drives.iter_mut().flat_map(|d| d.on_frame(f, now_ns)).collect()
    }
    /// Advances time: SYNC, the master's start command, drive motion and heartbeats.
    pub fn tick(&mut self, now_ns: u64) -> Vec<Frame> {
        let mut out = Vec::new();
        if let Some(t) = self.start_all_at_ns
            && now_ns >= t
        {
            self.start_all_at_ns = None;
            out.push(Frame::classic(0x000, &[0x01, 0x00]));
        }
        if let Some(next) = self.next_sync_ns
            && now_ns >= next
        {
            out.push(Frame::classic(0x080, &[]));
            self.next_sync_ns = Some(next + self.sync_period_ns * ((now_ns - next) / self.sync_period_ns + 1));
        }
        for d in &mut self.drives {
            out.extend(d.tick(now_ns));
        }
        out
    }
    /// Delivers frames to the simulation until it is quiet, as the bus would echo them;
    /// returns everything that went on the bus in order (test and replay helper).
    pub fn settle(&mut self, mut pending: Vec<Frame>, now_ns: u64) -> Vec<Frame> {
        let mut all = Vec::new();
        let mut i = 0;
        while i < pending.len() {
            let f = pending[i];
            pending.extend(self.on_frame(&f, now_ns));
            all.push(f);
            i += 1;
        }
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_boots_starts_and_syncs_without_a_bus() {
        let mut sim = Simulation::demo();
        let boot = sim.power_on(0);
        let on_bus = sim.settle(boot, 0);
        assert_eq!(on_bus.iter().map(|f| f.id).collect::<Vec<_>>(), vec![0x702, 0x703]);
        let mut ids = Vec::new();
        for t in 1..=100u64 {
            let now = t * 10_000_000;
            let out = sim.tick(now);
            ids.extend(sim.settle(out, now).iter().map(|f| (now / 1_000_000, f.id)));
        }
        // SYNC every 100 ms; PDOs answer it only after the master's start at 800 ms.
        let syncs: Vec<u64> = ids.iter().filter(|(_, id)| *id == 0x080).map(|(t, _)| *t).collect();
        assert_eq!(syncs, (1..=10).map(|k| k * 100).collect::<Vec<_>>());
        assert!(ids.contains(&(800, 0x000)));
        let tpdo_times: Vec<u64> = ids.iter().filter(|(_, id)| *id == 0x182).map(|(t, _)| *t).collect();
        assert_eq!(tpdo_times, vec![800, 900, 1000]);
        assert_eq!(sim.drive(3).map(|d| d.nmt()), Some(drive::NmtState::Operational));
    }
}

#[cfg(test)]
mod pdo_layer_tests {
    use super::Simulation;
    use crate::decode::Decoder;
    use crate::od::bind::Bindings;

    #[test]
    fn demo_pdos_decode_from_the_first_frame() {
        let sim = Simulation::demo();
        let mut bindings = Bindings::new();
        for (node, layer) in sim.pdo_layers() {
            bindings.bind_config(node, layer);
        }
        let mut decoder = Decoder::from_bindings(&bindings);
        let d = decoder.decode(&crate::frame::Frame::classic(0x182, &[0x50, 0x02, 0x03]));
        assert!(
            d.label
                .starts_with("TPDO1 node 2: Statusword=0x0250 (Switch on disabled"),
            "{}",
            d.label
        );
        assert!(
            d.label.ends_with("Modes of operation display=3 (Profile velocity)"),
            "{}",
            d.label
        );
        let d = decoder.decode(&crate::frame::Frame::classic(0x203, &[0x0F, 0x00, 0xE8, 0x03, 0, 0]));
        assert_eq!(
            d.label,
            "RPDO1 node 3: Controlword=0x000F (Enable operation), Target velocity=1000"
        );
    }
}
