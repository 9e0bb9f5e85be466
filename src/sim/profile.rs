//! The object dictionary of a simulated CiA 402 drive (CiA 301 communication
//! objects plus the CiA 402 objects the simulator acts on).

use super::od::DeviceObjects;
use crate::od::{Access, DataType};

/// What makes one simulated drive model different from another.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveProfile {
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
}

impl DriveProfile {
    /// A simulated servo drive called `name`; velocity in position units per second.
    pub fn servo(name: &str, product_code: u32) -> DriveProfile {
        DriveProfile {
            device_name: name.to_string(),
            vendor_id: 0,
            product_code,
            software_version: "cotui-sim 1".to_string(),
            heartbeat_ms: 500,
            position_per_velocity: 1.0,
            vendor_u16: Vec::new(),
            serial_number: None,
        }
    }
    /// Like the AIMOTOR servo of the seed manuals (profile `aimotor`): identified by a
    /// software version starting with `AIMOTOR`, velocities in pulses/s.
    pub fn aimotor_like() -> DriveProfile {
        DriveProfile {
            software_version: "AIMOTOR (cotui simulation)".to_string(),
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
            ..DriveProfile::servo("cotui simulated Syn-tron-like DS servo", 0x0402_0003)
        }
    }
}

/// The objects of a drive at `node` (COB-IDs follow the pre-defined connection set).
pub fn drive_objects(node: u8, p: DriveProfile) -> DeviceObjects {
    use Access::*;
    use DataType::*;
    let n = node as i64;
    let mut s = DeviceObjects::default();
    s.add(0x1000, 0, "Device type", U32, Ro, 0x0002_0192);
    s.add(0x1001, 0, "Error register", U8, Ro, 0);
    s.add(0x1003, 0, "Number of errors", U8, Rw, 0);
    s.add(0x1003, 1, "Standard error field", U32, Ro, 0);
    s.add(0x1005, 0, "COB-ID SYNC", U32, Rw, 0x80);
    s.add_bytes(
        0x1008,
        0,
        "Manufacturer device name",
        VisibleString,
        Const,
        p.device_name.into_bytes(),
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
        p.software_version.into_bytes(),
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
    // RPDO1: controlword + target velocity.
    s.add(0x1400, 0, "Highest sub-index supported", U8, Const, 2);
    s.add(0x1400, 1, "COB-ID used by RPDO", U32, Rw, 0x200 + n);
    s.add(0x1400, 2, "Transmission type", U8, Rw, 0xFF);
    s.add(0x1600, 0, "Number of mapped objects", U8, Rw, 2);
    s.add(0x1600, 1, "Mapping entry 1", U32, Rw, 0x6040_0010);
    s.add(0x1600, 2, "Mapping entry 2", U32, Rw, 0x60FF_0020);
    // TPDO1: statusword + mode display; TPDO2: position + velocity; both on every SYNC.
    for (k, cob, entries) in [
        (0u16, 0x180, [0x6041_0010u32, 0x6061_0008]),
        (1, 0x280, [0x6064_0020, 0x606C_0020]),
    ] {
        s.add(0x1800 + k, 0, "Highest sub-index supported", U8, Const, 2);
        s.add(0x1800 + k, 1, "COB-ID used by TPDO", U32, Rw, cob + n);
        s.add(0x1800 + k, 2, "Transmission type", U8, Rw, 1);
        s.add(0x1A00 + k, 0, "Number of mapped objects", U8, Rw, 2);
        s.add(0x1A00 + k, 1, "Mapping entry 1", U32, Rw, entries[0] as i64);
        s.add(0x1A00 + k, 2, "Mapping entry 2", U32, Rw, entries[1] as i64);
    }
    let block: Vec<u8> = (0..200u32).map(|i| (i * 7 + n as u32) as u8).collect();
    s.add_bytes(0x2000, 0, "Parameter block", Domain, Rw, block);
    for (index, name, value) in &p.vendor_u16 {
        s.add(*index, 0, name, U16, Rw, *value);
    }
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
    s.add(0x6502, 0, "Supported drive modes", U32, Ro, (1 << 2) | (1 << 8));
    s
}
