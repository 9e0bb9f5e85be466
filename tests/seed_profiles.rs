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
