//! SocketCAN error frames (CAN_ERR_FLAG): error class bits and details (linux/can/error.h).

use serde_json::json;

/// Error class names by bit of the error frame's id.
const CLASSES: [(u32, &str); 10] = [
    (0x001, "TX timeout"),
    (0x002, "lost arbitration"),
    (0x004, "controller problem"),
    (0x008, "protocol violation"),
    (0x010, "transceiver status"),
    (0x020, "no ACK on transmission"),
    (0x040, "bus off"),
    (0x080, "bus error"),
    (0x100, "controller restarted"),
    (0x200, "error counters"),
];

const CONTROLLER: [(u8, &str); 7] = [
    (0x01, "RX buffer overflow"),
    (0x02, "TX buffer overflow"),
    (0x04, "RX error warning"),
    (0x08, "TX error warning"),
    (0x10, "RX error passive"),
    (0x20, "TX error passive"),
    (0x40, "recovered to error active"),
];

const PROTOCOL: [(u8, &str); 8] = [
    (0x01, "single bit error"),
    (0x02, "frame format error"),
    (0x04, "bit stuffing error"),
    (0x08, "unable to send dominant bit"),
    (0x10, "unable to send recessive bit"),
    (0x20, "bus overload"),
    (0x40, "active error announcement"),
    (0x80, "error on transmission"),
];

/// The classes set in an error frame's id, with details from its data bytes.
pub fn describe(class: u32, data: &[u8]) -> Vec<String> {
    let byte = |i: usize| data.get(i).copied().unwrap_or(0);
    CLASSES
        .iter()
        .filter(|(m, _)| class & m != 0)
        .map(|(m, name)| {
            let detail = match *m {
                0x002 if byte(0) != 0 => format!(" at bit {}", byte(0)),
                0x004 => paren(&bits(&CONTROLLER, byte(1))),
                0x008 => paren(&bits(&PROTOCOL, byte(2))),
                0x200 => format!(" tx={} rx={}", byte(6), byte(7)),
                _ => String::new(),
            };
            format!("{name}{detail}")
        })
        .collect()
}

fn bits(table: &[(u8, &'static str)], b: u8) -> Vec<&'static str> {
    table.iter().filter(|(m, _)| b & m != 0).map(|(_, t)| *t).collect()
}

fn paren(items: &[&str]) -> String {
    if items.is_empty() {
        String::new()
    } else {
        format!(" ({})", items.join(", "))
    }
}

/// One-line label of an error frame.
pub fn label(class: u32, data: &[u8]) -> String {
    let parts = describe(class, data);
    if parts.is_empty() {
        format!("Error frame 0x{class:08X}")
    } else {
        format!("Error frame: {}", parts.join("; "))
    }
}

/// The kind-specific JSON object.
pub fn to_json(class: u32, data: &[u8]) -> serde_json::Value {
    json!({"class": class, "details": describe(class, data)})
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controller_and_counters() {
        let data = [0, 0x14, 0, 0, 0, 0, 0x60, 0x80];
        assert_eq!(
            label(0x204, &data),
            "Error frame: controller problem (RX error warning, RX error passive); error counters tx=96 rx=128"
        );
        assert_eq!(label(0x040, &[0; 8]), "Error frame: bus off");
        assert_eq!(label(0, &[]), "Error frame 0x00000000");
        assert_eq!(to_json(0x20, &[])["details"], json!(["no ACK on transmission"]));
    }
}
