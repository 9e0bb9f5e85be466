//! NMT module control (COB-ID 0x000): start, stop, pre-operational, resets.

use serde::Serialize;

/// An NMT command frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Nmt {
    /// Command specifier byte.
    pub cs: u8,
    /// Addressed node, 0 = all nodes.
    pub target: u8,
}

impl Nmt {
    /// JSONL name of the command.
    pub fn command(&self) -> &'static str {
        match self.cs {
            0x01 => "start",
            0x02 => "stop",
            0x80 => "pre_operational",
            0x81 => "reset_node",
            0x82 => "reset_communication",
            _ => "unknown",
        }
    }

    /// Human name of the command, as CiA 301 words it.
    pub fn text(&self) -> &'static str {
        match self.cs {
            0x01 => "Start remote node",
            0x02 => "Stop remote node",
            0x80 => "Enter pre-operational",
            0x81 => "Reset node",
            0x82 => "Reset communication",
            _ => "unknown command",
        }
    }

    /// One-line label.
    pub fn label(&self) -> String {
        let target = if self.target == 0 {
            "all nodes".to_string()
        } else {
            format!("node {}", self.target)
        };
        if self.command() == "unknown" {
            format!("NMT unknown command 0x{:02X} -> {target}", self.cs)
        } else {
            format!("NMT {} -> {target}", self.text())
        }
    }

    /// The kind-specific JSON object.
    pub fn to_json(&self) -> NmtJson {
        NmtJson {
            command: self.command(),
            target: self.target,
        }
    }
}

/// The `nmt` object of a JSONL frame record (fields in key order).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct NmtJson {
    pub command: &'static str,
    pub target: u8,
}

/// Decodes an NMT payload; the second value explains a rule broken (DLC, command byte).
pub fn decode(payload: &[u8]) -> (Nmt, Option<String>) {
    let nmt = Nmt {
        cs: payload.first().copied().unwrap_or(0),
        target: payload.get(1).copied().unwrap_or(0),
    };
    let problem = if payload.len() != 2 {
        Some(format!("NMT frame has {} data bytes, expected 2", payload.len()))
    } else if nmt.command() == "unknown" {
        Some(format!("unknown NMT command specifier 0x{:02X}", nmt.cs))
    } else if nmt.target > 127 {
        Some(format!("NMT target node {} is outside 0..127", nmt.target))
    } else {
        None
    };
    (nmt, problem)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn all_five_commands() {
        let cases = [
            (0x01, "start", "NMT Start remote node -> node 2"),
            (0x02, "stop", "NMT Stop remote node -> node 2"),
            (0x80, "pre_operational", "NMT Enter pre-operational -> node 2"),
            (0x81, "reset_node", "NMT Reset node -> node 2"),
            (0x82, "reset_communication", "NMT Reset communication -> node 2"),
        ];
        for (cs, name, label) in cases {
            let (n, p) = decode(&[cs, 2]);
            assert_eq!(n.command(), name);
            assert_eq!(n.label(), label);
            assert_eq!(p, None);
        }
    }

    #[test]
    fn broadcast_and_rule_breaks() {
        let (n, _) = decode(&[0x01, 0]);
        assert_eq!(n.label(), "NMT Start remote node -> all nodes");
        assert_eq!(
            serde_json::to_value(n.to_json()).unwrap(),
            json!({"command": "start", "target": 0})
        );
        assert!(decode(&[0x01]).1.unwrap().contains("1 data bytes"));
        let (n, p) = decode(&[0x33, 1]);
        assert_eq!(n.command(), "unknown");
        assert!(p.unwrap().contains("0x33"));
        assert!(decode(&[]).1.is_some());
    }
}
