//! The simulated drives that are not CiA 402: the Dexmart DEV dual-motor controller
//! (Multi-Drive commands per motor M1/M2 in RPDO1/RPDO2, answered by TPDO1/TPDO2) and the
//! AQMD DC motor driver (control command, target speed, direction and position in RPDO1;
//! duty, speed and position counter read back). They act on their dictionaries only, as
//! their manuals describe; where a manual's text was lost by the OCR the simulator's own
//! choice is said below.
//!
//! Pure: the objects and elapsed time in, objects changed.

use super::od::DeviceObjects;

/// How a simulated drive behaves: which objects it acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A CiA 402 drive: state machine, modes of operation (AIMOTOR, Syn-tron, servo).
    Cia402,
    /// The Dexmart DEV dual-motor controller: Multi-Drive RPDO commands per motor (M1/M2).
    Dexmart,
    /// The AQMD DC motor driver: control command, target speed, direction, position.
    Aqmd,
}

/// Dexmart 09-26 CANopen PDO Mapping (mapping set 0 or 1).
const DEX_MAPPING: (u16, u8) = (0x3009, 26);
/// Dexmart motors: (drive mode 01-11/01-27, hall mode 01-12/01-28, Multi-Drive record,
/// Multi-Drive Lite record, Monitor Data record).
const DEX_MOTORS: [(u16, u8, u8, u16, u16, u16); 2] = [
    (0x3001, 11, 12, 0x3051, 0x305B, 0x3046),
    (0x3001, 27, 28, 0x3052, 0x305C, 0x304A),
];
/// Dexmart Multi-Drive commands (0x3051:1 values).
const CMD_HALL_SPEED: i64 = 0x01;
const CMD_ENCODER_SPEED: i64 = 0x0A;
const CMD_ENCODER_POSITION: i64 = 0x0F;
/// Simulated acceleration, rpm/s, and position speed, counts/s (not in the manuals).
const RAMP_RPM_S: f64 = 6000.0;
const POSITION_SPEED: f64 = 1000.0;
/// Bus voltage shown by both: the Dexmart manual's Dynamic Data 10 example reply
/// `581 4B 00 30 0A 6E 09` = 2414 (24.14 V).
const BUS_VOLTAGE_CV: i64 = 2414;

/// One simulated motor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motor {
    speed: f64,
    target_speed: f64,
    position: f64,
    target_position: Option<f64>,
}

impl Motor {
    /// Ramps the speed to its target or moves toward the target position over `dt` s.
    fn step(&mut self, dt: f64) {
        if let Some(t) = self.target_position {
            let step = POSITION_SPEED * dt;
            let d = (t - self.position).clamp(-step, step);
            self.position += d;
            self.speed = if dt > 0.0 { d / dt } else { 0.0 };
            if self.position == t {
                self.target_position = None;
                self.speed = 0.0;
            }
            return;
        }
        let step = RAMP_RPM_S * dt;
        self.speed += (self.target_speed - self.speed).clamp(-step, step);
    }
    /// The simulator's motor state byte: 0 stopped, 1 running (the manual's codes are
    /// not legible in the seed).
    fn state(&self) -> i64 {
        i64::from(self.speed.abs() >= 0.5 || self.target_position.is_some())
    }
}

/// The vendor behaviour of a simulated drive.
#[derive(Clone, Debug, PartialEq)]
pub enum Vendor {
    /// A CiA 402 drive: nothing vendor-specific.
    None,
    /// Dexmart DEV: two motors and the PDO mapping set in force.
    Dexmart { motors: [Motor; 2], mapping_set: i64 },
    /// AQMD: one motor (duty in 0.1 %).
    Aqmd { motor: Motor },
}

/// Sets the values a freshly powered drive of `kind` shows.
pub fn init_objects(kind: Kind, od: &mut DeviceObjects) {
    match kind {
        Kind::Cia402 => {}
        Kind::Dexmart => {
            od.set_int(0x3000, 10, BUS_VOLTAGE_CV);
            od.set_int(0x3046, 8, BUS_VOLTAGE_CV);
            od.set_int(0x304A, 8, BUS_VOLTAGE_CV);
        }
        Kind::Aqmd => od.set_int(0x2100, 0, BUS_VOLTAGE_CV),
    }
}

impl Vendor {
    /// The behaviour of `kind` at power-on.
    pub fn new(kind: Kind) -> Vendor {
        match kind {
            Kind::Cia402 => Vendor::None,
            Kind::Dexmart => Vendor::Dexmart {
                motors: [Motor::default(); 2],
                mapping_set: 0,
            },
            Kind::Aqmd => Vendor::Aqmd {
                motor: Motor::default(),
            },
        }
    }

    /// Acts on objects written by SDO: Dexmart 09-26 switches the PDO mapping set at once
    /// (the simulator's choice; the manual does not say when it takes effect). A faulted
    /// drive (`faulted`) starts no motor.
    pub fn on_sdo(&mut self, od: &mut DeviceObjects, dictionary: &str, faulted: bool) {
        self.follow_mapping_set(od, dictionary);
        if let Vendor::Aqmd { motor } = self {
            aqmd_command(motor, od, faulted);
        }
    }

    /// After a reset of the communication objects (the PDO mappings are back to set 0):
    /// Dexmart maps the set 09-26 selects again.
    pub fn on_communication_reset(&mut self, od: &mut DeviceObjects, dictionary: &str) {
        if let Vendor::Dexmart { mapping_set, .. } = self {
            *mapping_set = 0;
        }
        self.follow_mapping_set(od, dictionary);
    }

    /// Dexmart: the PDO mappings of the set 09-26 selects, when it changed.
    fn follow_mapping_set(&mut self, od: &mut DeviceObjects, dictionary: &str) {
        if let Vendor::Dexmart { mapping_set, .. } = self {
            let set = od.int(DEX_MAPPING.0, DEX_MAPPING.1);
            if set != *mapping_set {
                *mapping_set = set;
                select_mapping_set(od, dictionary, set);
            }
        }
    }

    /// RPDO `n` (0-based) was written into `od`: acts on it (a faulted drive takes no
    /// command); returns the TPDOs (0-based) sent in reply (Dexmart: TPDOn on RPDOn, 09-27 = 0).
    pub fn on_rpdo(&mut self, n: u16, od: &DeviceObjects, faulted: bool) -> Vec<u16> {
        match self {
            Vendor::None => Vec::new(),
            Vendor::Aqmd { motor } => {
                aqmd_command(motor, od, faulted);
                Vec::new()
            }
            Vendor::Dexmart { motors, mapping_set } => {
                let Some(motor) = motors.get_mut(n as usize) else {
                    return Vec::new();
                };
                let (page, mode, hall, multi, lite, _) = DEX_MOTORS[n as usize];
                let (drive_mode, hall_mode) = (od.int(page, mode), od.int(page, hall));
                let (cmd, data1, data2) = if *mapping_set == 1 {
                    (od.int(lite, 1), od.int(lite, 2), 0)
                } else {
                    (od.int(multi, 1), od.int(multi, 2), od.int(multi, 3))
                };
                // A command the motor's drive mode does not take is ignored.
                match cmd {
                    _ if faulted => {}
                    CMD_ENCODER_SPEED if drive_mode == 2 => {
                        motor.target_position = None;
                        motor.target_speed = data2 as f64;
                    }
                    CMD_ENCODER_POSITION if drive_mode == 2 => motor.target_position = Some(data1 as f64),
                    CMD_HALL_SPEED if drive_mode == 0 && hall_mode == 4 => {
                        motor.target_position = None;
                        motor.target_speed = data1 as f64;
                    }
                    _ => {}
                }
                vec![n]
            }
        }
    }

    /// Advances the motors by `dt` seconds and shows them in the dictionary; a fault
    /// (`faulted`) stops them.
    pub fn tick(&mut self, dt: f64, od: &mut DeviceObjects, faulted: bool) {
        if faulted {
            self.motors_mut().iter_mut().for_each(|m| {
                m.target_speed = 0.0;
                m.target_position = None;
            });
        }
        match self {
            Vendor::None => {}
            Vendor::Dexmart { motors, .. } => {
                let mut status = 0;
                for (k, m) in motors.iter_mut().enumerate() {
                    m.step(dt);
                    let monitor = DEX_MOTORS[k].5;
                    od.set_int(monitor, 1, m.state());
                    od.set_int(monitor, 5, m.speed.round() as i64);
                    od.set_int(monitor, 23, m.position.round() as i64);
                    status |= m.state() << (8 * k);
                }
                od.set_int(0x1002, 0, status);
            }
            Vendor::Aqmd { motor } => {
                motor.step(dt);
                motor.position += motor.speed * dt;
                let duty = motor.speed.round() as i64;
                od.set_int(0x2101, 0, duty);
                od.set_int(0x2102, 0, duty);
                od.set_int(0x210A, 0, duty.abs());
                od.set_int(0x2105, 0, motor.position.round() as i64);
                od.set_int(0x2111, 0, duty.signum().rem_euclid(3));
            }
        }
    }
}

impl Vendor {
    /// The motors.
    fn motors_mut(&mut self) -> &mut [Motor] {
        match self {
            Vendor::None => &mut [],
            Vendor::Dexmart { motors, .. } => motors,
            Vendor::Aqmd { motor } => std::slice::from_mut(motor),
        }
    }
}

/// AQMD: command 3 runs at the target speed (0x2001, reversed by direction 0x2002 = 1);
/// the simulator stops the motor on every other command (their texts are lost in the seed)
/// and while faulted.
fn aqmd_command(motor: &mut Motor, od: &DeviceObjects, faulted: bool) {
    let sign = if od.int(0x2002, 0) == 1 { -1.0 } else { 1.0 };
    motor.target_speed = match od.int(0x2000, 0) {
        3 if !faulted => (od.int(0x2001, 0) as f64 * sign).clamp(-1000.0, 1000.0),
        _ => 0.0,
    };
}

/// One PDO's start-up mapping (entries as in 0x1600/0x1A00) and transmission type.
pub(super) type PdoDefault = (Vec<u32>, u8);

/// The templates of a profile's PDO set as start-up mappings (PDOs 1..4).
pub(super) fn fill_pdos(out: &mut [PdoDefault; 4], set: &std::collections::BTreeMap<u8, crate::od::PdoTemplate>) {
    for (n, t) in set {
        if let Some(slot) = (*n as usize).checked_sub(1).and_then(|i| out.get_mut(i)) {
            let entries = t
                .entries
                .iter()
                .map(|e| (e.index as u32) << 16 | (e.sub as u32) << 8 | e.bits as u32)
                .collect();
            *slot = (entries, t.transmission_type.unwrap_or(0xFF));
        }
    }
}

/// Writes the PDO mapping of Dexmart mapping set `set` (09-26) into 0x1600.. and 0x1A00..
fn select_mapping_set(od: &mut DeviceObjects, dictionary: &str, set: i64) {
    let Some(Ok((profile, _))) = crate::od::bind::shared_builtin(dictionary) else {
        return;
    };
    let Some(chosen) = profile
        .pdo_sets
        .iter()
        .find(|s| s.selected_by.as_ref().is_some_and(|(_, v)| *v == set))
    else {
        return;
    };
    for (map, templates) in [(0x1600u16, &chosen.rpdo), (0x1A00, &chosen.tpdo)] {
        let mut pdos: [PdoDefault; 4] = std::array::from_fn(|_| (Vec::new(), 0xFF));
        fill_pdos(&mut pdos, templates);
        for (k, (entries, _)) in pdos.iter().enumerate() {
            let map = map + k as u16;
            od.set_int(map, 0, entries.len() as i64);
            for sub in 1..=8u8 {
                let e = entries.get(sub as usize - 1).copied().unwrap_or(0);
                od.set_int(map, sub, e as i64);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::profile::{DriveProfile, drive_objects};

    #[test]
    fn dexmart_encoder_speed_command_moves_m1_and_mapping_set_1_takes_lite_commands() {
        let mut od = drive_objects(1, DriveProfile::dexmart_like());
        let mut v = Vendor::new(Kind::Dexmart);
        od.set_int(0x3001, 11, 2);
        // RPDO1 of mapping set 0: 201#0A0000B80B (manual: 3000 rpm on M1).
        od.set(0x3051, 1, &[0x0A]);
        od.set(0x3051, 3, &3000i16.to_le_bytes());
        assert_eq!(v.on_rpdo(0, &od, false), vec![0]);
        v.tick(1.0, &mut od, false);
        assert_eq!((od.int(0x3046, 5), od.int(0x3046, 1)), (3000, 1));
        assert_eq!(od.uint(0x1002, 0), 1, "byte 0 = M1 running");
        od.set_int(0x3009, 26, 1);
        v.on_sdo(&mut od, "dexmart-dev", false);
        assert_eq!(od.uint(0x1600, 1), 0x305B_0108, "RPDO1 = Multi-Drive Lite M1");
        od.set_int(0x3001, 27, 0);
        od.set_int(0x3001, 28, 4);
        od.set(0x305C, 1, &[0x01]);
        od.set(0x305C, 2, &(-500i16).to_le_bytes());
        v.on_rpdo(1, &od, false);
        v.tick(1.0, &mut od, false);
        assert_eq!(od.int(0x304A, 5) as i16, -500);
        // A reset of the communication objects keeps the set 09-26 selects.
        od.reset(0x1000..=0x1FFF);
        assert_eq!(od.uint(0x1600, 1), 0x3051_0108);
        v.on_communication_reset(&mut od, "dexmart-dev");
        assert_eq!(od.uint(0x1600, 1), 0x305B_0108);
    }

    #[test]
    fn aqmd_runs_at_target_speed_on_command_3_and_stops_on_others() {
        let mut od = drive_objects(1, DriveProfile::aqmd_like());
        let mut v = Vendor::new(Kind::Aqmd);
        od.set_int(0x2000, 0, 3);
        od.set_int(0x2001, 0, 500);
        v.on_rpdo(0, &od, false);
        v.tick(1.0, &mut od, false);
        assert_eq!((od.int(0x2101, 0), od.int(0x2111, 0)), (500, 1));
        assert!(od.int(0x2105, 0) > 0);
        od.set_int(0x2000, 0, 0);
        v.on_sdo(&mut od, "aqmd2405", false);
        v.tick(1.0, &mut od, false);
        assert_eq!((od.int(0x2101, 0), od.int(0x2111, 0)), (0, 0));
    }
}
