//! NMT error control (0x700 + node): heartbeat, boot-up and node guarding.

use serde::Serialize;

/// NMT state as carried by heartbeat and guarding frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NmtState {
    BootUp,
    Stopped,
    Operational,
    PreOperational,
    Unknown(u8),
}

impl NmtState {
    /// The state for the 7-bit state value.
    pub fn from_byte(b: u8) -> NmtState {
        match b & 0x7F {
            0x00 => NmtState::BootUp,
            0x04 => NmtState::Stopped,
            0x05 => NmtState::Operational,
            0x7F => NmtState::PreOperational,
            other => NmtState::Unknown(other),
        }
    }
    /// JSONL name.
    pub fn as_str(self) -> &'static str {
        match self {
            NmtState::BootUp => "boot_up",
            NmtState::Stopped => "stopped",
            NmtState::Operational => "operational",
            NmtState::PreOperational => "pre_operational",
            NmtState::Unknown(_) => "unknown",
        }
    }
    /// Human name.
    pub fn text(self) -> String {
        match self {
            NmtState::BootUp => "Boot-up".into(),
            NmtState::Stopped => "Stopped".into(),
            NmtState::Operational => "Operational".into(),
            NmtState::PreOperational => "Pre-operational".into(),
            NmtState::Unknown(v) => format!("unknown state 0x{v:02X}"),
        }
    }
}

/// A heartbeat, boot-up, guarding request (RTR) or guarding response.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Heartbeat {
    /// `None` for a guarding request (RTR carries no state).
    pub state: Option<NmtState>,
    /// Toggle bit (bit 7), meaningful in guarding responses.
    pub toggle: bool,
    /// A node guarding request (remote frame from the NMT master).
    pub request: bool,
}

impl Heartbeat {
    /// One-line label for `node`.
    pub fn label(&self, node: u8) -> String {
        match self.state {
            None => format!("Node guarding request node {node}"),
            Some(NmtState::BootUp) => format!("Boot-up node {node}"),
            Some(s) if self.toggle => format!("Guarding response node {node}: {} (toggle 1)", s.text()),
            Some(s) => format!("Heartbeat node {node}: {}", s.text()),
        }
    }
    /// The kind-specific JSON object.
    pub fn to_json(&self) -> HeartbeatJson {
        HeartbeatJson {
            request: self.request,
            state: self.state.map(NmtState::as_str),
            toggle: self.toggle,
        }
    }
}

/// The `heartbeat` object of a JSONL frame record (fields in key order).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct HeartbeatJson {
    pub request: bool,
    /// `null` for a guarding request.
    pub state: Option<&'static str>,
    pub toggle: bool,
}

/// Decodes an error-control frame; the second value explains a rule broken.
pub fn decode(payload: &[u8], rtr: bool) -> (Heartbeat, Option<String>) {
    if rtr {
        return (
            Heartbeat {
                state: None,
                toggle: false,
                request: true,
            },
            None,
        );
    }
    let Some(&b) = payload.first() else {
        return (
            Heartbeat {
                state: None,
                toggle: false,
                request: false,
            },
            Some("heartbeat frame without data".into()),
        );
    };
    let hb = Heartbeat {
        state: Some(NmtState::from_byte(b)),
        toggle: b & 0x80 != 0,
        request: false,
    };
    let problem = if payload.len() != 1 {
        Some(format!("heartbeat frame has {} data bytes, expected 1", payload.len()))
    } else if let Some(NmtState::Unknown(v)) = hb.state {
        Some(format!("unknown NMT state 0x{v:02X}"))
    } else if hb.state == Some(NmtState::BootUp) && hb.toggle {
        Some("boot-up message with toggle bit set".into())
    } else {
        None
    };
    (hb, problem)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn states() {
        assert_eq!(decode(&[0x05], false).0.label(5), "Heartbeat node 5: Operational");
        assert_eq!(decode(&[0x7F], false).0.label(5), "Heartbeat node 5: Pre-operational");
        assert_eq!(decode(&[0x04], false).0.label(5), "Heartbeat node 5: Stopped");
        assert_eq!(decode(&[0x00], false).0.label(5), "Boot-up node 5");
        assert_eq!(
            serde_json::to_value(decode(&[0x00], false).0.to_json()).unwrap(),
            json!({"state": "boot_up", "toggle": false, "request": false})
        );
    }

    #[test]
    fn guarding() {
        // Syn-tron manual: "702 85" is a guarding response, toggle 1, operational.
        let (hb, p) = decode(&[0x85], false);
        assert_eq!(hb.label(2), "Guarding response node 2: Operational (toggle 1)");
        assert!(hb.toggle);
        assert_eq!(p, None);
        let (req, _) = decode(&[], true);
        assert_eq!(req.label(2), "Node guarding request node 2");
        assert_eq!(
            serde_json::to_value(req.to_json()).unwrap(),
            json!({"state": null, "toggle": false, "request": true})
        );
    }

    #[test]
    fn rule_breaks_are_marked() {
        assert!(decode(&[0x05, 0], false).1.unwrap().contains("2 data bytes"));
        assert!(decode(&[0x33], false).1.unwrap().contains("0x33"));
        assert!(decode(&[], false).1.is_some());
    }
}
