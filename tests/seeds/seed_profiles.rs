//! The four seed drive profiles load without warnings and carry what their manuals give.

use cotui::od::json::load_profile;
use cotui::od::{Dictionary, Profile, SdoDirection, resolve_object};
use std::sync::Arc;

fn load(name: &str) -> Profile {
    let path = format!("{}/decoders/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let (profile, warnings) = load_profile(&path, &text).unwrap_or_else(|e| panic!("{e}"));
    let listed: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    assert!(listed.is_empty(), "{name} has warnings:\n{}", listed.join("\n"));
    assert_eq!(profile.name, name);
    profile
}

fn dict(p: Profile) -> Dictionary {
    Dictionary::new(vec![Arc::new(p)])
}

#[test]
fn all_seed_profiles_load_cleanly() {
    for name in ["dexmart-dev", "aqmd2405", "syntron-ds", "aimotor"] {
        let p = load(name);
        assert!(!p.objects.is_empty(), "{name} has no objects");
        assert!(!p.procedures.is_empty(), "{name} has no procedures");
    }
}

#[test]
fn syntron_aliases_follow_the_manual_rules() {
    let d = dict(load("syntron-ds"));
    // "F0.1.002 ... 0x2102, F1.3.018 ... 0x3318, Pn5.006 ... 0x4506" (manual 1.4)
    assert_eq!(resolve_object(&d, "F0.1.002"), Ok((0x2102, 0)));
    assert_eq!(resolve_object(&d, "F1.3.018"), Ok((0x3318, 0)));
    assert_eq!(resolve_object(&d, "Pn5.006"), Ok((0x4506, 0)));
    // "Fn1.002 ... 0x2102, Dn002 ... 0x5002"
    assert_eq!(resolve_object(&d, "Fn1.002"), Ok((0x2102, 0)));
    assert_eq!(resolve_object(&d, "Dn002"), Ok((0x5002, 0)));
    // "Dn0.012 0x5012", "Dn1.012 0x5112"; "D0.004 D1.004 ... 0x5004 0x5104"
    assert_eq!(resolve_object(&d, "Dn1.012"), Ok((0x5112, 0)));
    assert_eq!(resolve_object(&d, "D1.04"), Ok((0x5104, 0)));
    let p = &d.layers()[0];
    assert!(p.sdo_command(0xE8, SdoDirection::Request).is_some());
    assert!(p.sdo_command(0xE9, SdoDirection::Request).is_some());
    assert_eq!(p.axis_of(0x3318, 0).map(|a| a.name.as_str()), Some("B"));
    assert_eq!(p.axis_of(0x5004, 0).map(|a| a.name.as_str()), Some("A"));
}

#[test]
fn dexmart_parameters_and_pdo_sets() {
    let p = load("dexmart-dev");
    // "E£809-26 CANOpen PDO Mapping = 0 / = 1": two sets, 0 is the default.
    assert_eq!(p.pdo_sets.len(), 2);
    assert_eq!(p.default_pdo_set().map(|s| s.name.as_str()), Some("mapping-0"));
    let d = dict(p);
    // "03-01 (Index = 3003h - Sub-Index = 01h)"
    assert_eq!(resolve_object(&d, "03-01"), Ok((0x3003, 1)));
    assert_eq!(resolve_object(&d, "09-26"), Ok((0x3009, 26)));
    // "Sub-Index 01h = 01-01 (Modbus Address 0x0100)", "Monitor Data ( Modbus Address 0x4600 )"
    assert_eq!(resolve_object(&d, "MB0100"), Ok((0x3001, 1)));
    assert_eq!(resolve_object(&d, "MB4600"), Ok((0x3046, 1)));
    assert_eq!(d.name(0x3046, 5), Some("M1: Current Speed"));
    assert_eq!(d.name(0x3002, 7), Some("EEP parameter 2-7"));
    let p = &d.layers()[0];
    assert_eq!(p.axis_of(0x304A, 2).map(|a| a.name.as_str()), Some("M2"));
}

#[test]
fn aimotor_h_parameters_follow_the_manual_table() {
    let d = dict(load("aimotor"));
    // 1.4: "H02-00 0x2002 0x01", "H03-09 0x2003 0x0A", "H0B-26 0x200B 0x1B", "H12-20 0x2012 0x15"
    assert_eq!(resolve_object(&d, "H02-00"), Ok((0x2002, 0x01)));
    assert_eq!(resolve_object(&d, "H03-09"), Ok((0x2003, 0x0A)));
    assert_eq!(resolve_object(&d, "H0B-26"), Ok((0x200B, 0x1B)));
    assert_eq!(resolve_object(&d, "H12-20"), Ok((0x2012, 0x15)));
    // 6.2: "H0B-34 ... 200Bh sub 23h" current fault code, with the fault -> 603Fh table as texts
    assert_eq!(resolve_object(&d, "H0B-34"), Ok((0x200B, 0x23)));
    let fault = d.object(0x200B, 0x23).expect("H0B-34");
    assert!(
        fault.values[&0x0D03].contains("0x8130"),
        "{:?}",
        fault.values.get(&0x0D03)
    );
    // Default PDOs: "1600h 0x60400010, 0x60600008, 607A"; "1A00h 0x60410010, 0x60610008, 0x60640020"
    let p = &d.layers()[0];
    let set = p.default_pdo_set().expect("default set");
    let entries = |m: &cotui::od::PdoTemplate| m.entries.iter().map(|e| (e.index, e.bits)).collect::<Vec<_>>();
    assert_eq!(entries(&set.rpdo[&1]), vec![(0x6040, 16), (0x6060, 8), (0x607A, 32)]);
    assert_eq!(entries(&set.tpdo[&1]), vec![(0x6041, 16), (0x6061, 8), (0x6064, 32)]);
}

#[test]
fn aqmd_modbus_registers_map_to_objects() {
    let d = dict(load("aqmd2405"));
    // 7.4: "0x0000~0x0FFF -> 0x4000 + REG_ADDR", "0x7000~0x7FFF -> REG_ADDR - 0x2000"
    assert_eq!(resolve_object(&d, "MB0121"), Ok((0x4121, 0)));
    assert_eq!(resolve_object(&d, "MB7010"), Ok((0x5010, 0)));
    assert!(
        resolve_object(&d, "MB2000").is_err(),
        "0x2000 is not a mirrored Modbus range"
    );
    // 7.6.3: "0x2202 ... 0: 10kbps ... 7: 1Mbps"
    let rate = d.object(0x2202, 0).expect("0x2202");
    assert_eq!(rate.values[&0], "10 kbit/s");
    assert_eq!(rate.values[&7], "1 Mbit/s");
}

#[test]
fn identity_values_suggest_the_profile() {
    use cotui::od::Value;
    use cotui::od::bind::Bindings;
    let mut b = Bindings::new();
    let suggest = |b: &mut Bindings, index: u16, text: &str| {
        let read = |i: u16, s: u8| (i == index && s == 0).then(|| Value::Text(text.to_string()));
        b.identify(&read).map(|p| p.name.clone())
    };
    // AIMOTOR 2.1.1: "100A ... AIMOTOR_CIA402"
    assert_eq!(suggest(&mut b, 0x100A, "AIMOTOR_CIA402").as_deref(), Some("aimotor"));
    // Dexmart device name 1008h "DEV-N050CQ..." (OCR: "DLV-NO050CQ")
    assert_eq!(suggest(&mut b, 0x1008, "DEV-N050CQ").as_deref(), Some("dexmart-dev"));
    assert_eq!(suggest(&mut b, 0x1008, "AQMD2405BLS-MT-2").as_deref(), Some("aqmd2405"));
    assert_eq!(suggest(&mut b, 0x1008, "SOMETHING ELSE"), None);
}

#[test]
fn named_parameters_from_the_second_pass() {
    // AIMOTOR 1.3: "Nodeid=1, 500kbps ... H0C-00 / H0C-08" (Hxx-yy -> 0x2000 + xx, sub yy + 1)
    let d = dict(load("aimotor"));
    assert_eq!(resolve_object(&d, "H0C-00"), Ok((0x200C, 1)));
    assert_eq!(d.name(0x200C, 1), Some("CANopen node-ID"));
    assert_eq!(d.name(0x200C, 9), Some("CAN bit rate"));
    let rate = d.object(0x200C, 9).unwrap().description.clone().unwrap();
    assert!(rate.contains("500 kbps") && rate.contains("1 Mbps 25 m"), "{rate}");
    // Dexmart RPDO3: "303F011 ... M1: Digital Speed 0", "303F111 ... M2: Digital Speed 0"
    let d = dict(load("dexmart-dev"));
    assert_eq!(resolve_object(&d, "RAM03-01"), Ok((0x303F, 1)));
    assert_eq!(d.name(0x303F, 1), Some("M1 digital speed 0 (RAM)"));
    assert_eq!(d.name(0x303F, 0x11), Some("M2 digital speed 0 (RAM)"));
    assert_eq!(d.name(0x303F, 2), Some("RAM parameter 3-2"));
    // Syn-tron 3.6.4: "F0.7.000 ... F0.7.07F" per PDO: count, COB-ID, transmission type,
    // inhibit/event time, SUB1..SUB4; example "F0.7.041 385" (TPDO1 COB-ID), "F0.7.045 24641" (6041h)
    let d = dict(load("syntron-ds"));
    assert_eq!(resolve_object(&d, "F0.7.041"), Ok((0x2741, 0)));
    for (index, name) in [
        (0x2700, "A RPDO1 number of mapped objects"),
        (0x2741, "A TPDO1 COB-ID"),
        (0x2742, "A TPDO1 transmission type"),
        (0x2745, "A TPDO1 mapped object 1 index"),
        (0x277C, "A TPDO4 mapped object 4 sub-index"),
        (0x3731, "B RPDO4 COB-ID"),
    ] {
        assert_eq!(d.name(index, 0), Some(name), "0x{index:04X}");
    }
}

#[test]
fn default_pdo_communication_parameters() {
    use cotui::od::Value;
    let default = |d: &Dictionary, index: u16, sub: u8| d.object(index, sub).and_then(|o| o.default.clone());
    // AIMOTOR 2.1.1: 1401h-1403h sub 2 = 1, 1800h-1803h sub 2 = 1, sub 5 = 0.
    let d = dict(load("aimotor"));
    assert_eq!(default(&d, 0x1402, 2), Some(Value::Unsigned(1)));
    assert_eq!(default(&d, 0x1803, 2), Some(Value::Unsigned(1)));
    assert_eq!(default(&d, 0x1800, 5), Some(Value::Unsigned(0)));
    // Dexmart: "02h ... FEh TransmissionType", "03h ... 0Ah InhibitTime", "05h ... 0Ah EventTime"
    let p = load("dexmart-dev");
    assert!(
        p.pdo_sets
            .iter()
            .all(|s| s.tpdo.values().all(|t| t.transmission_type == Some(0xFE)))
    );
    let d = dict(p);
    for index in [0x1400, 0x1403, 0x1800, 0x1803] {
        assert_eq!(default(&d, index, 2), Some(Value::Unsigned(0xFE)));
        assert_eq!(default(&d, index, 3), Some(Value::Unsigned(0x0A)));
        assert_eq!(default(&d, index, 5), Some(Value::Unsigned(0x0A)));
    }
    assert_eq!(d.name(0x1801, 3), Some("Inhibit time"));
    // AQMD: RPDOx sub 2 = 0xFE; TPDOx sub 2 = 0xFE, sub 3 = 0 (100 us), sub 5 = 0 ms.
    let d = dict(load("aqmd2405"));
    assert_eq!(default(&d, 0x1401, 2), Some(Value::Unsigned(0xFE)));
    assert_eq!(default(&d, 0x1802, 2), Some(Value::Unsigned(0xFE)));
    assert_eq!(default(&d, 0x1802, 3), Some(Value::Unsigned(0)));
    // Syn-tron: the EDS set's TPDOs are event-driven (255).
    let p = load("syntron-ds");
    let eds = p.pdo_sets.iter().find(|s| s.name == "eds").unwrap();
    assert!(eds.tpdo.values().all(|t| t.transmission_type == Some(255)));
}

#[test]
fn procedures_write_only_objects_their_profile_lets_them_write() {
    use cotui::od::Access;
    // A manual's object table and its own worked lists can disagree (AIMOTOR 2.1.1 prints the PDO
    // COB-IDs RO while 5.4 writes them and the drive answers 60h): the profile must follow the frames.
    for name in ["dexmart-dev", "aqmd2405", "syntron-ds", "aimotor"] {
        let path = format!("{}/decoders/{name}.json", env!("CARGO_MANIFEST_DIR"));
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let d = dict(load(name));
        let mut writes = 0;
        for (proc_name, p) in json["procedures"].as_object().unwrap() {
            for step in p["steps"].as_array().unwrap() {
                let Some(object) = step["sdo_write"]["object"].as_str() else {
                    continue;
                };
                if object.contains('{') {
                    continue; // a parameter chooses the object
                }
                let (index, sub) = resolve_object(&d, object).unwrap_or_else(|e| panic!("{name} {proc_name}: {e}"));
                let access = d.object(index, sub).map(|o| o.access);
                assert!(
                    !matches!(access, Some(Access::Ro | Access::Const)),
                    "{name} {proc_name} writes 0x{index:04X}:{sub}, which the profile marks {access:?}"
                );
                writes += 1;
            }
        }
        assert!(writes > 0, "{name}: no procedure writes anything");
    }
}

#[test]
fn syntron_cia402_object_list_of_section_3_4_3() {
    use DataType::*;
    use cotui::od::{Access, DataType};
    let d = dict(load("syntron-ds"));
    // "Mode Index Name Type Attr. unit": every row of the table; units as (unit, scale) of the
    // physical value ("0.1rpm" = rpm x 0.1, "millisecond from 0rpm to 3000rpm" = ms).
    let rw = Access::Rw;
    let ro = Access::Ro;
    type Row = (u16, u8, DataType, Access, Option<&'static str>, Option<f64>);
    let rows: [Row; 35] = [
        (0x603F, 0, U16, ro, None, None),
        (0x6040, 0, U16, rw, None, None),
        (0x6041, 0, U16, ro, None, None),
        (0x6060, 0, I8, rw, None, None),
        (0x6061, 0, I8, ro, None, None),
        (0x6062, 0, I32, ro, Some("pulse"), None),
        (0x6063, 0, I32, rw, Some("inc"), None),
        (0x6064, 0, I32, ro, None, None),
        (0x6065, 0, U32, rw, Some("pulse"), None),
        (0x6066, 0, U16, rw, Some("ms"), None),
        (0x6067, 0, U32, rw, Some("pulse"), None),
        (0x6068, 0, U16, rw, Some("ms"), None),
        (0x6069, 0, I32, ro, Some("rpm"), Some(0.1)),
        (0x606B, 0, I32, ro, Some("rpm"), Some(0.1)),
        // The table leaves 606Ch's unit empty; it is the same 0.1 rpm as 606Bh/6069h.
        (0x606C, 0, I32, ro, Some("rpm"), Some(0.1)),
        (0x606D, 0, U16, rw, Some("rpm"), Some(0.1)),
        (0x606E, 0, U16, rw, Some("ms"), None),
        (0x606F, 0, U16, rw, Some("rpm"), Some(0.1)),
        (0x6070, 0, U16, rw, Some("ms"), None),
        (0x6071, 0, I16, rw, Some("%"), Some(0.1)),
        (0x607A, 0, I32, rw, Some("pulse"), None),
        (0x607C, 0, I32, rw, None, None),
        (0x6081, 0, U32, rw, Some("rpm"), Some(0.1)),
        (0x6083, 0, U32, rw, Some("ms"), None),
        (0x6084, 0, U32, rw, Some("ms"), None),
        // "6087h Torque slope INTEGER32" (CiA 402 says UNSIGNED32; the manual's type is kept).
        (0x6087, 0, I32, rw, None, None),
        // "6093h Position factor UNSIGNED32 RW": CiA 402's numerator/divisor record, as 3.7.2 writes it.
        (0x6093, 1, U32, rw, None, None),
        (0x6098, 0, I8, rw, None, None),
        (0x6099, 1, U32, rw, Some("rpm"), Some(0.1)),
        (0x609A, 0, U32, rw, Some("ms"), None),
        (0x60F4, 0, I32, ro, Some("pulse"), None),
        (0x60FC, 0, I32, ro, Some("pulse"), None),
        (0x60FD, 0, U32, ro, None, None),
        (0x60FE, 0, U32, ro, None, None),
        (0x60FF, 0, I32, rw, Some("rpm"), Some(0.1)),
    ];
    for (index, sub, ty, access, unit, scale) in rows {
        let o = d
            .object(index, sub)
            .unwrap_or_else(|| panic!("0x{index:04X}:{sub} missing"));
        assert_eq!(
            (o.data_type, o.access, o.unit.as_deref(), o.scale),
            (ty, access, unit, scale),
            "0x{index:04X}:{sub} {}",
            o.name
        );
    }
    assert_eq!(d.object(0x6093, 2).map(|o| o.data_type), Some(U32));
    assert_eq!(d.object(0x6099, 2).map(|o| o.unit.as_deref()), Some(Some("rpm")));
}
