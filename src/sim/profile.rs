//! The object dictionary of a simulated drive: CiA 301 communication objects, the
//! CiA 402 objects the simulator acts on (for CiA 402 drives) and every object of the
//! built-in profile the drive is modelled after, with its default PDO set.

use super::od::DeviceObjects;
use super::vendor::{Kind, PdoDefault, fill_pdos, init_objects};
use crate::od::{Access, DataType};

/// The drive models `--node NODE=MODEL` accepts (`cotui sim`, `cotui demo`): the built-in
/// device profiles plus `servo`, a plain CiA 402 drive.
pub const MODELS: [&str; 5] = ["aimotor", "syntron-ds", "dexmart-dev", "aqmd2405", "servo"];

/// What makes one simulated drive model different from another.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveProfile {
    /// The behaviour.
    pub kind: Kind,
    /// 0x1000 device type.
    pub device_type: u32,
    /// 0x1008 manufacturer device name.
    pub device_name: String,
    /// 0x1018:1 vendor-ID.
    pub vendor_id: u32,
    /// 0x1018:2 product code.
    pub product_code: u32,
    /// 0x100A manufacturer software version (profiles identify drives by it).
    pub software_version: String,
    /// 0x1017 heartbeat producer time in ms (0 = off).
    pub heartbeat_ms: u16,
    /// Position units (0x6064) a velocity of 1 (0x606C / 0x60FF raw) covers per second.
    pub position_per_velocity: f64,
    /// Vendor parameters (UNSIGNED16, read/write): index, name, value.
    pub vendor_u16: Vec<(u16, &'static str, i64)>,
    /// 0x1018:4 serial number (default: 1000 + node-ID); part of the LSS address.
    pub serial_number: Option<u32>,
    /// The built-in profile whose objects (and those of the profiles it extends, CiA 402)
    /// the drive also has, with their defaults: vendor parameters answer as on the real drive.
    pub dictionary: &'static str,
    /// Accepts writes shorter than an unsigned object (see
    /// [`DeviceObjects::short_writes_extend`]).
    pub short_writes_extend: bool,
}

impl DriveProfile {
    /// A simulated servo drive called `name`; velocity in position units per second.
    pub fn servo(name: &str, product_code: u32) -> DriveProfile {
        DriveProfile {
            kind: Kind::Cia402,
            device_type: 0x0002_0192,
            device_name: name.to_string(),
            vendor_id: 0,
            product_code,
            software_version: "cotui-sim 1".to_string(),
            heartbeat_ms: 500,
            position_per_velocity: 1.0,
            vendor_u16: Vec::new(),
            serial_number: None,
            dictionary: "cia402",
            short_writes_extend: false,
        }
    }
    /// Like the AIMOTOR servo of the seed manuals (profile `aimotor`): identified by a
    /// software version starting with `AIMOTOR`, velocities in pulses/s.
    pub fn aimotor_like() -> DriveProfile {
        DriveProfile {
            software_version: "AIMOTOR (cotui simulation)".to_string(),
            dictionary: "aimotor",
            ..DriveProfile::servo("cotui simulated AIMOTOR-like servo", 0x0402_0002)
        }
    }
    /// Like the Syn-tron DS drive of the seed manuals (profile `syntron-ds`): velocities in
    /// 0.1 rpm, 10000 position increments per revolution.
    pub fn syntron_like() -> DriveProfile {
        DriveProfile {
            position_per_velocity: 10_000.0 / 600.0,
            // F0.1.002 / F1.1.002 control mode: 20 = CANopen (the manual's STEP1).
            vendor_u16: vec![(0x2102, "A control mode", 20), (0x3102, "B control mode", 20)],
            dictionary: "syntron-ds",
            // The manual's PP example writes 6093h sub 1/2 with 2 bytes ("602 2B 93 60 01 01").
            short_writes_extend: true,
            ..DriveProfile::servo("cotui simulated Syn-tron-like DS servo", 0x0402_0003)
        }
    }
}

impl DriveProfile {
    /// The model called `name` (one of [`MODELS`]).
    pub fn model(name: &str) -> Option<DriveProfile> {
        Some(match name {
            "aimotor" => DriveProfile::aimotor_like(),
            "syntron-ds" => DriveProfile::syntron_like(),
            "dexmart-dev" => DriveProfile::dexmart_like(),
            "aqmd2405" => DriveProfile::aqmd_like(),
            "servo" => DriveProfile::servo("cotui simulated servo", 0x0402_0001),
            _ => return None,
        })
    }
    /// Like the Dexmart DEV dual-motor controller (profile `dexmart-dev`, identified by a
    /// device name starting with `DEV`): no CiA 402, mapping set 0 (09-26 = 0) at power-on.
    pub fn dexmart_like() -> DriveProfile {
        DriveProfile {
            kind: Kind::Dexmart,
            device_type: 0,
            dictionary: "dexmart-dev",
            ..DriveProfile::servo("DEV-N050CQ (cotui simulation)", 0x0402_0004)
        }
    }
    /// Like the AQMD2405BLS DC motor driver (profile `aqmd2405`, identified by a device
    /// name starting with `AQMD`): device type 0 (no CiA profile), RPDO1/TPDO1 of the
    /// manual's 7.5.4 examples.
    pub fn aqmd_like() -> DriveProfile {
        DriveProfile {
            kind: Kind::Aqmd,
            device_type: 0,
            dictionary: "aqmd2405",
            ..DriveProfile::servo("AQMD2405BLS-MT-2 (cotui simulation)", 0x0402_0005)
        }
    }
}

/// The objects of a drive at `node` (COB-IDs follow the pre-defined connection set).
pub fn drive_objects(node: u8, p: DriveProfile) -> DeviceObjects {
    use Access::*;
    use DataType::*;
    let n = node as i64;
    let mut s = DeviceObjects::default();
    s.short_writes_extend = p.short_writes_extend;
    s.add(0x1000, 0, "Device type", U32, Ro, p.device_type as i64);
    s.add(0x1001, 0, "Error register", U8, Ro, 0);
    s.add(0x1003, 0, "Number of errors", U8, Rw, 0);
    s.add(0x1003, 1, "Standard error field", U32, Ro, 0);
    s.add(0x1005, 0, "COB-ID SYNC", U32, Rw, 0x80);
    s.add(0x1006, 0, "Communication cycle period", U32, Rw, 0);
    s.add_bytes(
        0x1008,
        0,
        "Manufacturer device name",
        VisibleString,
        Const,
        p.device_name.clone().into_bytes(),
    );
    s.add_bytes(
        0x1009,
        0,
        "Manufacturer hardware version",
        VisibleString,
        Const,
        b"1.0".to_vec(),
    );
    s.add_bytes(
        0x100A,
        0,
        "Manufacturer software version",
        VisibleString,
        Const,
        p.software_version.clone().into_bytes(),
    );
    s.add(0x1017, 0, "Producer heartbeat time", U16, Rw, p.heartbeat_ms as i64);
    s.add(0x1018, 0, "Highest sub-index supported", U8, Const, 4);
    s.add(0x1018, 1, "Vendor-ID", U32, Ro, p.vendor_id as i64);
    s.add(0x1018, 2, "Product code", U32, Ro, p.product_code as i64);
    s.add(0x1018, 3, "Revision number", U32, Ro, 0x0001_0000);
    s.add(
        0x1018,
        4,
        "Serial number",
        U32,
        Ro,
        p.serial_number.map_or(1000 + n, i64::from),
    );
    // Four RPDOs and TPDOs with every communication and mapping sub-index, the unused
    // ones with an invalid COB-ID and nothing mapped.
    let (rpdo, tpdo) = default_pdos(&p);
    for (comm, map, base, maps) in [(0x1400u16, 0x1600u16, 0x200, rpdo), (0x1800, 0x1A00, 0x180, tpdo)] {
        let what = if comm == 0x1400 { "RPDO" } else { "TPDO" };
        for (k, (entries, kind)) in maps.iter().enumerate() {
            let (comm, map) = (comm + k as u16, map + k as u16);
            let cob = base + 0x100 * k as i64 + n;
            let cob = if entries.is_empty() { cob | 0x8000_0000 } else { cob };
            s.add(comm, 0, "Highest sub-index supported", U8, Const, 5);
            s.add(comm, 1, &format!("COB-ID used by {what}"), U32, Rw, cob);
            s.add(comm, 2, "Transmission type", U8, Rw, *kind as i64);
            s.add(comm, 3, "Inhibit time", U16, Rw, 0);
            s.add(comm, 5, "Event timer", U16, Rw, 0);
            s.add(map, 0, "Number of mapped objects", U8, Rw, entries.len() as i64);
            for sub in 1..=8u8 {
                let e = entries.get(sub as usize - 1).copied().unwrap_or(0);
                s.add(map, sub, &format!("Mapping entry {sub}"), U32, Rw, e as i64);
            }
        }
    }
    for (index, name, value) in &p.vendor_u16 {
        s.add(*index, 0, name, U16, Rw, *value);
    }
    if p.kind == Kind::Cia402 {
        let block: Vec<u8> = (0..200u32).map(|i| (i * 7 + n as u32) as u8).collect();
        s.add_bytes(0x2000, 0, "Parameter block", Domain, Rw, block);
        add_cia402_objects(&mut s);
    }
    add_profile_objects(&mut s, p.dictionary);
    // Store/restore, unless the profile describes them (AQMD: subs 1 and 2).
    if !s.has_index(0x1010) {
        s.add(0x1010, 0, "Highest sub-index supported", U8, Const, 1);
        s.add(0x1010, 1, "Save all parameters", U32, Rw, 1);
    }
    if !s.has_index(0x1011) {
        s.add(0x1011, 0, "Highest sub-index supported", U8, Const, 1);
        s.add(0x1011, 1, "Restore all default parameters", U32, Rw, 1);
    }
    init_objects(p.kind, &mut s);
    s
}

/// The CiA 402 objects the simulator acts on.
fn add_cia402_objects(s: &mut DeviceObjects) {
    use Access::*;
    use DataType::*;
    s.add(0x603F, 0, "Error code", U16, Ro, 0);
    s.add(0x6040, 0, "Controlword", U16, Rww, 0);
    s.add(0x6041, 0, "Statusword", U16, Ro, 0x0250);
    s.add(0x605A, 0, "Quick stop option code", I16, Rw, 6);
    s.add(0x6060, 0, "Modes of operation", I8, Rww, 3);
    s.add(0x6061, 0, "Modes of operation display", I8, Ro, 3);
    s.add(0x6064, 0, "Position actual value", I32, Ro, 0);
    s.add(0x606C, 0, "Velocity actual value", I32, Ro, 0);
    s.add(0x6083, 0, "Profile acceleration", U32, Rw, 20_000);
    s.add(0x6084, 0, "Profile deceleration", U32, Rw, 20_000);
    s.add(0x6085, 0, "Quick stop deceleration", U32, Rw, 100_000);
    s.add(0x60FF, 0, "Target velocity", I32, Rww, 0);
    // PP, PV, PT, HM, CSP, CSV, CST.
    s.add(0x6502, 0, "Supported drive modes", U32, Ro, 0b11_1010_1101);
}

/// The PDOs a drive starts with (RPDO1..4, TPDO1..4). CiA 402 drives: RPDO1 controlword +
/// target velocity, TPDO1 statusword + mode display, TPDO2 position + velocity, both on
/// every SYNC. The others: the default PDO set of their profile.
fn default_pdos(p: &DriveProfile) -> ([PdoDefault; 4], [PdoDefault; 4]) {
    let none = || std::array::from_fn(|_| (Vec::new(), 0xFF));
    let (mut rpdo, mut tpdo): ([PdoDefault; 4], [PdoDefault; 4]) = (none(), none());
    if p.kind == Kind::Cia402 {
        rpdo[0] = (vec![0x6040_0010, 0x60FF_0020], 0xFF);
        tpdo[0] = (vec![0x6041_0010, 0x6061_0008], 1);
        tpdo[1] = (vec![0x6064_0020, 0x606C_0020], 1);
        return (rpdo, tpdo);
    }
    let Some(Ok((profile, _))) = crate::od::bind::shared_builtin(p.dictionary) else {
        return (rpdo, tpdo);
    };
    if let Some(set) = profile.pdo_sets.iter().find(|s| s.default) {
        fill_pdos(&mut rpdo, &set.rpdo);
        fill_pdos(&mut tpdo, &set.tpdo);
    }
    (rpdo, tpdo)
}

/// Adds the objects of built-in profile `name` and of the profiles it extends (not CiA 301:
/// its generic entries would say nothing about the device) that `s` lacks, with the
/// profile's default or 0, plus sub-index 0 of records that have none.
fn add_profile_objects(s: &mut DeviceObjects, name: &str) {
    let mut names = vec![name.to_string()];
    let mut i = 0;
    while let Some(name) = names.get(i).cloned() {
        i += 1;
        let Some(Ok((profile, _))) = crate::od::bind::shared_builtin(&name) else {
            continue;
        };
        for e in &profile.extends {
            if e != "cia301" && !names.contains(e) {
                names.push(e.clone());
            }
        }
        for ((index, sub), info) in profile.entries() {
            // PDO parameters are the simulator's own (above), as are the objects it has.
            if (0x1400..=0x1BFF).contains(&index) || s.entry(index, sub).is_some() {
                continue;
            }
            match info.data_type.size() {
                Some(_) => {
                    let v = info.default.as_ref().and_then(|v| v.as_i64()).unwrap_or(0);
                    s.add(index, sub, &info.name, info.data_type, info.access, v);
                }
                None => s.add_bytes(index, sub, &info.name, info.data_type, info.access, Vec::new()),
            }
        }
    }
    let records: Vec<(u16, u8)> = s
        .highest_subs()
        .into_iter()
        .filter(|(i, max)| *max > 0 && s.entry(*i, 0).is_none())
        .collect();
    for (index, max) in records {
        s.add(
            index,
            0,
            "Highest sub-index supported",
            DataType::U8,
            Access::Const,
            max as i64,
        );
    }
}
