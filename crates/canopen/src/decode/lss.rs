//! LSS (CiA 305, 0x7E5 master -> slave, 0x7E4 slave -> master).

use serde::Serialize;

/// An LSS frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lss {
    /// Command specifier (byte 0).
    pub cs: u8,
    /// From the LSS master (0x7E5)?
    pub from_master: bool,
    /// Bytes 1..8.
    pub args: [u8; 7],
}

impl Lss {
    fn u32_at1(&self) -> u32 {
        u32::from_le_bytes([self.args[0], self.args[1], self.args[2], self.args[3]])
    }

    /// The service name (snake_case), used in JSON.
    pub fn service(&self) -> &'static str {
        match (self.cs, self.from_master) {
            (0x04, true) => "switch_state_global",
            (0x40..=0x43, true) => "switch_state_selective",
            (0x44, false) => "switch_state_selective_response",
            (0x11, _) => "configure_node_id",
            (0x13, _) => "configure_bit_timing",
            (0x15, true) => "activate_bit_timing",
            (0x17, _) => "store_configuration",
            (0x46..=0x4B, true) => "identify_remote_slave",
            (0x4C, true) => "identify_non_configured_remote_slave",
            (0x4F, false) => "identify_slave",
            (0x50, false) => "identify_non_configured_slave",
            (0x51, true) => "fastscan",
            (0x5A..=0x5D, _) => "inquire_identity",
            (0x5E, _) => "inquire_node_id",
            _ => "unknown",
        }
    }

    /// One-line label.
    pub fn label(&self) -> String {
        let dir = if self.from_master { "LSS master" } else { "LSS slave" };
        let field = |cs: u8| match cs {
            0x40 | 0x46 | 0x5A => "vendor-id",
            0x41 | 0x47 | 0x5B => "product code",
            0x42 | 0x48 | 0x49 | 0x5C => "revision",
            0x43 | 0x4A | 0x4B | 0x5D => "serial number",
            _ => "node-id",
        };
        let bound = |cs: u8| match cs {
            0x48 | 0x4A => " low",
            0x49 | 0x4B => " high",
            _ => "",
        };
        let detail = match (self.cs, self.from_master) {
            (0x04, true) => match self.args[0] {
                0 => "Switch state global: waiting".to_string(),
                1 => "Switch state global: configuration".to_string(),
                m => format!("Switch state global: invalid mode {m}"),
            },
            (0x40..=0x43, true) => format!("Switch state selective {} = 0x{:08X}", field(self.cs), self.u32_at1()),
            (0x44, false) => "Switch state selective response".to_string(),
            (0x11, true) => format!("Configure node-id {}", self.args[0]),
            (0x13, true) => match crate::lss::bit_rate_text(self.args[0], self.args[1]) {
                Some(r) => format!("Configure bit timing: {r}"),
                None => format!("Configure bit timing: table {} index {}", self.args[0], self.args[1]),
            },
            (0x11 | 0x13 | 0x17, false) => {
                let what = match self.cs {
                    0x11 => "Configure node-id",
                    0x13 => "Configure bit timing",
                    _ => "Store configuration",
                };
                let text = crate::lss::configure_error_text(self.cs, self.args[0], self.args[1]);
                format!("{what} response: {text}")
            }
            (0x15, true) => format!(
                "Activate bit timing, switch delay {} ms",
                u16::from_le_bytes([self.args[0], self.args[1]])
            ),
            (0x17, true) => "Store configuration".to_string(),
            (0x46..=0x4B, true) => {
                format!(
                    "Identify remote slave {}{} = 0x{:08X}",
                    field(self.cs),
                    bound(self.cs),
                    self.u32_at1()
                )
            }
            (0x4C, true) => "Identify non-configured remote slave".to_string(),
            (0x4F, false) => "Identify slave response (identify remote slave, fastscan)".to_string(),
            (0x50, false) => "Identify non-configured slave response".to_string(),
            (0x51, true) if self.args[4] == crate::lss::FASTSCAN_RESET => {
                "Fastscan reset (every non-configured slave answers)".to_string()
            }
            (0x51, true) => format!(
                "Fastscan id 0x{:08X} bitcheck {} sub {} next {}",
                self.u32_at1(),
                self.args[4],
                self.args[5],
                self.args[6]
            ),
            (0x5A..=0x5D, true) => format!("Inquire {}", field(self.cs)),
            (0x5E, true) => "Inquire node-id".to_string(),
            (0x5A..=0x5D, false) => format!("Inquire {} response 0x{:08X}", field(self.cs), self.u32_at1()),
            (0x5E, false) => format!("Inquire node-id response {}", self.args[0]),
            _ => format!("unknown command 0x{:02X}", self.cs),
        };
        format!("{dir}: {detail}")
    }

    /// The kind-specific JSON object.
    pub fn to_json(&self) -> LssJson {
        LssJson {
            cs: self.cs,
            from_master: self.from_master,
            service: self.service(),
        }
    }
}

/// The `lss` object of a JSONL frame record (fields in key order).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct LssJson {
    pub cs: u8,
    pub from_master: bool,
    pub service: &'static str,
}

/// Decodes an LSS payload; the second value explains a rule broken.
pub fn decode(payload: &[u8], from_master: bool) -> (Lss, Option<String>) {
    let mut args = [0u8; 7];
    let n = payload.len().saturating_sub(1).min(7);
    if n > 0 {
        args[..n].copy_from_slice(&payload[1..1 + n]);
    }
    let lss = Lss {
        cs: payload.first().copied().unwrap_or(0),
        from_master,
        args,
    };
    let problem = if payload.len() != 8 {
        Some(format!("LSS frame has {} data bytes, expected 8", payload.len()))
    } else if lss.service() == "unknown" {
        Some(format!("unknown LSS command specifier 0x{:02X}", lss.cs))
    } else {
        None
    };
    (lss, problem)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn master_services() {
        assert_eq!(
            decode(&[0x04, 1, 0, 0, 0, 0, 0, 0], true).0.label(),
            "LSS master: Switch state global: configuration"
        );
        assert_eq!(
            decode(&[0x11, 5, 0, 0, 0, 0, 0, 0], true).0.label(),
            "LSS master: Configure node-id 5"
        );
        assert_eq!(
            decode(&[0x13, 0, 3, 0, 0, 0, 0, 0], true).0.label(),
            "LSS master: Configure bit timing: 250 kbit/s"
        );
        assert_eq!(
            decode(&[0x40, 0x78, 0x56, 0x34, 0x12, 0, 0, 0], true).0.label(),
            "LSS master: Switch state selective vendor-id = 0x12345678"
        );
        assert_eq!(
            decode(&[0x5E, 0, 0, 0, 0, 0, 0, 0], true).0.label(),
            "LSS master: Inquire node-id"
        );
        assert_eq!(
            decode(&[0x51, 0, 0, 0, 0, 0x80, 0, 0], true).0.label(),
            "LSS master: Fastscan reset (every non-configured slave answers)"
        );
        assert_eq!(
            decode(&[0x51, 0, 0, 0, 0x80, 31, 0, 0], true).0.label(),
            "LSS master: Fastscan id 0x80000000 bitcheck 31 sub 0 next 0"
        );
    }

    #[test]
    fn slave_responses() {
        assert_eq!(
            decode(&[0x11, 0, 0, 0, 0, 0, 0, 0], false).0.label(),
            "LSS slave: Configure node-id response: success"
        );
        assert_eq!(
            decode(&[0x11, 1, 0, 0, 0, 0, 0, 0], false).0.label(),
            "LSS slave: Configure node-id response: node-ID out of range (1..127 or 255)"
        );
        assert_eq!(
            decode(&[0x17, 0xFF, 0x21, 0, 0, 0, 0, 0], false).0.label(),
            "LSS slave: Store configuration response: manufacturer-specific error 0x21"
        );
        assert_eq!(
            decode(&[0x5E, 7, 0, 0, 0, 0, 0, 0], false).0.service(),
            "inquire_node_id"
        );
        assert_eq!(
            decode(&[0x5E, 7, 0, 0, 0, 0, 0, 0], false).0.label(),
            "LSS slave: Inquire node-id response 7"
        );
        assert_eq!(
            decode(&[0x4F, 0, 0, 0, 0, 0, 0, 0], false).0.service(),
            "identify_slave"
        );
        let (l, p) = decode(&[0x99, 0, 0, 0, 0, 0, 0, 0], false);
        assert_eq!(l.service(), "unknown");
        assert!(p.unwrap().contains("0x99"));
    }
}
