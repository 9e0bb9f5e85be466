//! EMCY (0x080 + node): error code text, error register bits, manufacturer bytes.

use crate::frame::json::Hex;
use crate::od::Dictionary;
use serde::Serialize;
use std::collections::BTreeMap;

/// An emergency frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Emcy {
    /// Emergency error code (bytes 0-1, little-endian).
    pub code: u16,
    /// Error register 0x1001 (byte 2).
    pub register: u8,
    /// Manufacturer-specific error field (bytes 3-7).
    pub mfr: [u8; 5],
    /// Text of the code: vendor text, else CiA 301/402 exact text, else its class.
    pub text: String,
    /// Manufacturer bytes decoded through the profile's layout, e.g. `M1 alarm=0x12`.
    pub mfr_fields: Vec<(String, String)>,
    /// The profile's "check first" steps for this code (empty when it has none).
    pub check: Vec<String>,
}

/// Names of the error register bits 0..7 (CiA 301 7.5.2.2).
pub(crate) const REGISTER_BITS: [&str; 8] = [
    "generic",
    "current",
    "voltage",
    "temperature",
    "communication",
    "device_profile",
    "reserved",
    "manufacturer",
];

impl Emcy {
    /// Names of the error register bits that are set.
    pub fn register_bits(&self) -> Vec<&'static str> {
        (0..8)
            .filter(|b| self.register & (1 << b) != 0)
            .map(|b| REGISTER_BITS[b])
            .collect()
    }
    /// One-line label for `node`.
    pub fn label(&self, node: u8) -> String {
        let mut s = format!("EMCY node {node}: 0x{:04X} {}", self.code, self.text);
        s.push_str(&format!("; register 0x{:02X}", self.register));
        let bits = self.register_bits();
        if !bits.is_empty() {
            s.push_str(&format!(" [{}]", bits.join(", ")));
        }
        if self.mfr_fields.is_empty() {
            if self.mfr != [0; 5] {
                s.push_str(&format!("; mfr {}", crate::frame::hex::spaced(&self.mfr)));
            }
        } else {
            let fields: Vec<String> = self.mfr_fields.iter().map(|(k, v)| format!("{k}={v}")).collect();
            s.push_str(&format!("; {}", fields.join(", ")));
        }
        s
    }
    /// The kind-specific JSON object.
    pub fn to_json(&self) -> EmcyJson<'_> {
        EmcyJson {
            code: self.code,
            mfr: Hex(&self.mfr),
            // A map, so a name given twice keeps its last value.
            mfr_fields: self.mfr_fields.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect(),
            register: self.register,
            register_bits: self.register_bits(),
            text: &self.text,
        }
    }
}

/// The `emcy` object of a JSONL frame record (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct EmcyJson<'a> {
    pub code: u16,
    /// The manufacturer bytes, upper-case hex.
    pub mfr: Hex<'a>,
    /// The manufacturer bytes decoded through the profile's layout, by name.
    pub mfr_fields: BTreeMap<&'a str, &'a str>,
    pub register: u8,
    pub register_bits: Vec<&'static str>,
    pub text: &'a str,
}

/// Decodes an EMCY payload with the node's dictionary; the second value explains a rule broken.
pub fn decode(payload: &[u8], dict: &Dictionary) -> (Emcy, Option<String>) {
    let mut b = [0u8; 8];
    let n = payload.len().min(8);
    b[..n].copy_from_slice(&payload[..n]);
    let code = u16::from_le_bytes([b[0], b[1]]);
    let mut mfr = [0u8; 5];
    mfr.copy_from_slice(&b[3..8]);
    let text = dict
        .emcy_text(code)
        .map(str::to_string)
        .unwrap_or_else(|| code_text(code).to_string());
    let mfr_fields = crate::od::emcy_fields(dict, &b);
    let emcy = Emcy {
        code,
        register: b[2],
        mfr,
        text,
        mfr_fields,
        check: dict.emcy_check(code).to_vec(),
    };
    let problem = if payload.len() != 8 {
        Some(format!("EMCY frame has {} data bytes, expected 8", payload.len()))
    } else {
        None
    };
    (emcy, problem)
}

/// Text of a standard emergency code: exact CiA 301/402 code first, then its class.
pub(crate) fn code_text(code: u16) -> &'static str {
    if let Ok(i) = EXACT.binary_search_by_key(&code, |(c, _)| *c) {
        return EXACT[i].1;
    }
    // Classes from most to least specific: 0xXXY0, 0xXX00, 0xX000.
    for mask in [0xFFF0u16, 0xFF00, 0xF000] {
        if let Ok(i) = EXACT.binary_search_by_key(&(code & mask), |(c, _)| *c) {
            return EXACT[i].1;
        }
    }
    "unknown error code"
}

/// Standard error codes of CiA 301 (table 21) and CiA 402 (annex), sorted by code.
const EXACT: &[(u16, &str)] = &[
    (0x0000, "Error reset or no error"),
    (0x1000, "Generic error"),
    (0x2000, "Current"),
    (0x2100, "Current, device input side"),
    (0x2110, "Short circuit/earth leakage (input)"),
    (0x2120, "Earth leakage (input)"),
    (0x2200, "Current inside the device"),
    (0x2210, "Continuous over current (device internal)"),
    (0x2220, "Short circuit/earth leakage (device internal)"),
    (0x2300, "Current, device output side"),
    (0x2310, "Continuous over current"),
    (0x2320, "Short circuit/earth leakage (motor-side)"),
    (0x2330, "Earth leakage (motor-side)"),
    (0x3000, "Voltage"),
    (0x3100, "Mains voltage"),
    (0x3110, "Mains over-voltage"),
    (0x3120, "Mains under-voltage"),
    (0x3130, "Phase failure"),
    (0x3200, "Voltage inside the device"),
    (0x3210, "DC link over-voltage"),
    (0x3220, "DC link under-voltage"),
    (0x3300, "Output voltage"),
    (0x3310, "Output over-voltage"),
    (0x4000, "Temperature"),
    (0x4100, "Ambient temperature"),
    (0x4200, "Device temperature"),
    (0x4210, "Excess temperature device"),
    (0x4300, "Drive temperature"),
    (0x4310, "Excess temperature drive"),
    (0x4400, "Supply temperature"),
    (0x5000, "Device hardware"),
    (0x5100, "Supply"),
    (0x5110, "Supply low voltage"),
    (0x5200, "Control"),
    (0x5300, "Operating unit"),
    (0x5400, "Power section"),
    (0x5410, "Output stages"),
    (0x5500, "Data storage"),
    (0x5530, "EEPROM"),
    (0x6000, "Device software"),
    (0x6100, "Internal software"),
    (0x6200, "User software"),
    (0x6300, "Data set"),
    (0x6310, "Loss of parameters"),
    (0x6320, "Parameter error"),
    (0x7000, "Additional modules"),
    (0x7100, "Power"),
    (0x7110, "Brake chopper"),
    (0x7120, "Motor"),
    (0x7121, "Motor blocked"),
    (0x7122, "Motor error or commutation malfunction"),
    (0x7300, "Sensor"),
    (0x7305, "Incremental sensor 1 fault"),
    (0x7306, "Incremental sensor 2 fault"),
    (0x7310, "Speed"),
    (0x7320, "Position"),
    (0x7400, "Computation circuit"),
    (0x7500, "Communication"),
    (0x7600, "Data storage"),
    (0x8000, "Monitoring"),
    (0x8100, "Communication"),
    (0x8110, "CAN overrun (objects lost)"),
    (0x8120, "CAN in error passive mode"),
    (0x8130, "Life guard error or heartbeat error"),
    (0x8140, "Recovered from bus off"),
    (0x8150, "CAN-ID collision"),
    (0x8200, "Protocol error"),
    (0x8210, "PDO not processed due to length error"),
    (0x8220, "PDO length exceeded"),
    (0x8230, "DAM MPDO not processed, destination object not available"),
    (0x8240, "Unexpected SYNC data length"),
    (0x8250, "RPDO timeout"),
    (0x8300, "Torque control"),
    (0x8311, "Excess torque"),
    (0x8400, "Velocity speed controller"),
    (0x8500, "Position controller"),
    (0x8600, "Positioning controller"),
    (0x8611, "Following error"),
    (0x8612, "Reference limit"),
    (0x8700, "Sync controller"),
    (0x8800, "Winding controller"),
    (0x9000, "External error"),
    (0xF000, "Additional functions"),
    (0xFF00, "Device specific"),
];

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn exact_then_class_text() {
        assert_eq!(code_text(0x8130), "Life guard error or heartbeat error");
        assert_eq!(code_text(0x8131), "Life guard error or heartbeat error");
        assert_eq!(code_text(0x3399), "Output voltage");
        assert_eq!(code_text(0x9ABC), "External error");
        assert_eq!(code_text(0xFF42), "Device specific");
        assert!(EXACT.windows(2).all(|w| w[0].0 < w[1].0), "table must be sorted");
    }

    #[test]
    fn register_bits_and_label() {
        let dict = Dictionary::default();
        let (e, p) = decode(&[0x30, 0x81, 0x11, 0, 0, 0, 0, 0], &dict);
        assert_eq!(p, None);
        assert_eq!(e.code, 0x8130);
        assert_eq!(e.register_bits(), vec!["generic", "communication"]);
        assert_eq!(
            e.label(3),
            "EMCY node 3: 0x8130 Life guard error or heartbeat error; register 0x11 [generic, communication]"
        );
        let j = serde_json::to_value(e.to_json()).unwrap();
        assert_eq!(j["code"], 0x8130);
        assert_eq!(j["register_bits"], json!(["generic", "communication"]));
    }

    #[test]
    fn error_reset_and_short_frames() {
        let dict = Dictionary::default();
        let (e, p) = decode(&[0, 0, 0, 0, 0, 0, 0, 0], &dict);
        assert_eq!(e.label(1), "EMCY node 1: 0x0000 Error reset or no error; register 0x00");
        assert_eq!(p, None);
        let (e, p) = decode(&[0x10], &dict);
        assert_eq!(e.code, 0x0010);
        assert!(p.unwrap().contains("1 data bytes"));
    }
}
