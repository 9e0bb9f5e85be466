//! Meaning of CiA 301 communication parameter values: COB-IDs with their flag
//! bits, PDO transmission types and mapping entries, store/restore signatures, and the
//! identity objects (device type 0x1000 with its profile, 0x1018 and the expected
//! identities 0x1F84..0x1F88), which are identifiers: shown in hex, as manuals write them.
//! [`describe`] is the one place that says how these objects read; every value text
//! (SDO labels, PDO signals, `sdo read`, the Objects pane) goes through it.

use crate::od::Dictionary;

/// A COB-ID value (0x1005, 0x1014, 0x12xx, 0x14xx, 0x18xx) with its flag bits.
pub fn cob_id(raw: u32, bit30: &str) -> String {
    let ext = raw & (1 << 29) != 0;
    let id = if ext {
        format!("0x{:08X}", raw & 0x1FFF_FFFF)
    } else {
        format!("0x{:03X}", raw & 0x7FF)
    };
    let mut flags = Vec::new();
    if raw & (1 << 31) != 0 {
        flags.push("invalid/disabled");
    }
    if raw & (1 << 30) != 0 && !bit30.is_empty() {
        flags.push(bit30);
    }
    if ext {
        flags.push("29-bit");
    }
    let flags = if flags.is_empty() {
        String::new()
    } else {
        format!(", {}", flags.join(", "))
    };
    format!("0x{raw:08X} (COB-ID {id}{flags})")
}

/// A device type (0x1000, 0x1F84 subs, 0x67FF): `0x00020192 (CiA 402, servo drive)`.
/// CiA 301: bits 0-15 the device profile number, bits 16-31 additional information that
/// the profile defines (0xFFFF: a multiple device module). CiA 402: bits 16-23 the type
/// (1 frequency converter, 2 servo drive, 3 stepper motor; +0x40 with the type's PDO
/// mapping; 0xFF multiple device module), bits 24-31 manufacturer-specific mode bits.
pub fn device_type(raw: u32) -> String {
    let (profile, info) = (raw & 0xFFFF, raw >> 16);
    let mut words = vec![match profile {
        0 => "no standard device profile".to_string(),
        400..=499 => format!("CiA {profile}"),
        n => format!("device profile {n}"),
    }];
    if info == 0xFFFF {
        words.push("multiple device module".into());
    } else if profile == 402 {
        let (kind, mode) = (info & 0xFF, info >> 8);
        let name = match kind & 0x3F {
            _ if kind == 0xFF => Some("multiple device module"),
            1 => Some("frequency converter"),
            2 => Some("servo drive"),
            3 => Some("stepper motor"),
            _ => None,
        };
        match name {
            Some(n) => words.push(n.into()),
            None if kind != 0 => words.push(format!("type 0x{kind:02X}")),
            None => {}
        }
        if kind != 0xFF && kind & 0x40 != 0 && name.is_some() {
            words.push("type-specific PDO mapping".into());
        }
        if mode != 0 {
            words.push(format!("mode bits 0x{mode:02X}"));
        }
    } else if info != 0 {
        words.push(format!("additional information 0x{info:04X}"));
    }
    format!("0x{raw:08X} ({})", words.join(", "))
}

/// PDO transmission type text (sub 2 of 0x1400/0x1800 records).
pub fn transmission_type(t: u32) -> String {
    format!("{t} ({})", transmission_words(t))
}

/// A PDO transmission type in words: `synchronous, every 5 SYNCs`, `event-driven (device profile)`.
pub(crate) fn transmission_words(t: u32) -> String {
    match t {
        0 => "synchronous, acyclic".to_string(),
        1 => "synchronous, every SYNC".to_string(),
        2..=240 => format!("synchronous, every {t} SYNCs"),
        241..=251 => "reserved".to_string(),
        252 => "RTR-only, synchronous".to_string(),
        253 => "RTR-only, event-driven".to_string(),
        254 => "event-driven (manufacturer-specific)".to_string(),
        _ => "event-driven (device profile)".to_string(),
    }
}

/// A PDO mapping entry: `0x60410010 (0x6041:00 Statusword, 16 bits)`.
fn mapping_entry(raw: u32, dict: &Dictionary) -> String {
    let (index, sub, bits) = ((raw >> 16) as u16, (raw >> 8) as u8, raw as u8);
    match dict.name(index, sub) {
        Some(name) => format!("0x{raw:08X} (0x{index:04X}:{sub:02X} {name}, {bits} bits)"),
        None => format!("0x{raw:08X} (0x{index:04X}:{sub:02X}, {bits} bits)"),
    }
}

/// The meaning of a communication parameter value, when (index, sub) is one.
pub fn describe(index: u16, sub: u8, raw: u64, dict: &Dictionary) -> Option<String> {
    let v = raw as u32;
    Some(match (index, sub) {
        (0x1000 | 0x67FF, 0) | (0x1F84, 1..) => device_type(v),
        // Vendor-ID, product code, revision and serial number, as the node has them and as
        // a master expects them: identifiers, in hex.
        (0x1018, 1..) | (0x1F85..=0x1F88, 1..) => format!("0x{v:08X}"),
        (0x1005, 0) => cob_id(v, "generates SYNC"),
        (0x1012, 0) => cob_id(v, "produces TIME"),
        (0x1014, 0) => cob_id(v, ""),
        (0x1010 | 0x1011, 1..) => match &v.to_le_bytes() {
            b"save" => format!("0x{v:08X} (\"save\" signature)"),
            b"load" => format!("0x{v:08X} (\"load\" signature)"),
            _ => return None,
        },
        (0x1200..=0x12FF, 1 | 2) => cob_id(v, "dynamic"),
        (0x1400..=0x15FF | 0x1800..=0x19FF, 1) => cob_id(v, "no RTR allowed"),
        (0x1400..=0x15FF | 0x1800..=0x19FF, 2) => transmission_type(v),
        (0x1600..=0x17FF | 0x1A00..=0x1BFF, 1..=64) => mapping_entry(v, dict),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cob_ids_and_flags() {
        let d = Dictionary::default();
        assert_eq!(
            describe(0x1800, 1, 0x8000_0182, &d).unwrap(),
            "0x80000182 (COB-ID 0x182, invalid/disabled)"
        );
        assert_eq!(
            describe(0x1400, 1, 0x0000_0202, &d).unwrap(),
            "0x00000202 (COB-ID 0x202)"
        );
        assert_eq!(
            describe(0x1800, 1, 0x6000_1234, &d).unwrap(),
            "0x60001234 (COB-ID 0x00001234, no RTR allowed, 29-bit)"
        );
        assert_eq!(
            describe(0x1005, 0, 0x4000_0080, &d).unwrap(),
            "0x40000080 (COB-ID 0x080, generates SYNC)"
        );
    }

    #[test]
    fn identity_objects_in_hex_and_the_device_type_with_its_profile() {
        let d = Dictionary::default();
        let t = |i, s, v| describe(i, s, v, &d).unwrap();
        assert_eq!(t(0x1000, 0, 0x0002_0192), "0x00020192 (CiA 402, servo drive)");
        assert_eq!(
            t(0x1000, 0, 0x0042_0192),
            "0x00420192 (CiA 402, servo drive, type-specific PDO mapping)"
        );
        assert_eq!(
            t(0x1000, 0, 0x00FF_0192),
            "0x00FF0192 (CiA 402, multiple device module)"
        );
        assert_eq!(
            t(0x1000, 0, 0x3003_0192),
            "0x30030192 (CiA 402, stepper motor, mode bits 0x30)"
        );
        assert_eq!(t(0x1000, 0, 0x0000_0192), "0x00000192 (CiA 402)");
        assert_eq!(
            t(0x1000, 0, 0x000F_0191),
            "0x000F0191 (CiA 401, additional information 0x000F)"
        );
        assert_eq!(t(0x1000, 0, 0), "0x00000000 (no standard device profile)");
        assert_eq!(t(0x1000, 0, 1022), "0x000003FE (device profile 1022)");
        assert_eq!(t(0x1F84, 2, 0x0002_0192), "0x00020192 (CiA 402, servo drive)");
        assert_eq!(t(0x1018, 1, 768), "0x00000300");
        assert_eq!(t(0x1018, 4, 0x1234_5678), "0x12345678");
        assert_eq!(t(0x1F85, 3, 864), "0x00000360");
        // Sub 0 is a count, not an identifier.
        assert_eq!(describe(0x1018, 0, 4, &d), None);
        assert_eq!(describe(0x1F84, 0, 4, &d), None);
    }

    #[test]
    fn transmission_types_mapping_and_signatures() {
        let d = Dictionary::default();
        assert_eq!(
            describe(0x1800, 2, 254, &d).unwrap(),
            "254 (event-driven (manufacturer-specific))"
        );
        assert_eq!(describe(0x1401, 2, 5, &d).unwrap(), "5 (synchronous, every 5 SYNCs)");
        assert_eq!(
            describe(0x1A00, 1, 0x6041_0010, &d).unwrap(),
            "0x60410010 (0x6041:00, 16 bits)"
        );
        assert_eq!(
            describe(0x1010, 1, 0x6576_6173, &d).unwrap(),
            "0x65766173 (\"save\" signature)"
        );
        assert_eq!(
            describe(0x1011, 1, 0x6461_6F6C, &d).unwrap(),
            "0x64616F6C (\"load\" signature)"
        );
        assert_eq!(describe(0x1A00, 0, 2, &d), None);
        assert_eq!(describe(0x6041, 0, 2, &d), None);
    }
}
