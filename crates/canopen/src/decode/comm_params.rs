//! Meaning of CiA 301 communication parameter values: COB-IDs with their flag
//! bits, PDO transmission types and mapping entries, store/restore signatures.

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

/// PDO transmission type text (sub 2 of 0x1400/0x1800 records).
pub fn transmission_type(t: u32) -> String {
    format!("{t} ({})", transmission_words(t))
}

/// A PDO transmission type in words: `synchronous, every 5 SYNCs`, `event-driven (device profile)`.
pub fn transmission_words(t: u32) -> String {
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
