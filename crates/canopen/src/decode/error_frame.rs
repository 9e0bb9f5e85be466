//! SocketCAN error frames (CAN_ERR_FLAG): error class bits and details (linux/can/error.h).

use serde::Serialize;

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

/// The state of a CAN controller as its error frames tell it (ISO 11898 fault confinement).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControllerState {
    /// Error-active: normal operation (also after a restart).
    Active,
    /// An error counter reached the warning level (96).
    Warning,
    /// An error counter passed 127: the controller may only send passive error flags.
    Passive,
    /// The transmit error counter passed 255: the controller is off the bus until restarted.
    BusOff,
}

/// What an error frame says about the controller: the state it entered (if it tells) and
/// the transmit/receive error counters (if the frame carries them, class 0x200, bytes 6 and 7).
pub fn controller_state(class: u32, data: &[u8]) -> (Option<ControllerState>, Option<(u8, u8)>) {
    let byte = |i: usize| data.get(i).copied().unwrap_or(0);
    let counters = (class & 0x200 != 0).then(|| (byte(6), byte(7)));
    let ctrl = if class & 0x004 != 0 { byte(1) } else { 0 };
    let state = if class & 0x040 != 0 {
        Some(ControllerState::BusOff)
    } else if ctrl & 0x30 != 0 {
        Some(ControllerState::Passive)
    } else if ctrl & 0x0C != 0 {
        Some(ControllerState::Warning)
    } else if class & 0x100 != 0 || ctrl & 0x40 != 0 {
        Some(ControllerState::Active)
    } else {
        None
    };
    (state, counters)
}

/// The kind-specific JSON object.
pub fn to_json(class: u32, data: &[u8]) -> ErrorFrameJson {
    ErrorFrameJson {
        class,
        details: describe(class, data),
    }
}

/// The `error` object of a JSONL frame record (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct ErrorFrameJson {
    /// The CAN_ERR class bits.
    pub class: u32,
    /// One text per class bit set, with the details the data bytes give.
    pub details: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn controller_and_counters() {
        let data = [0, 0x14, 0, 0, 0, 0, 0x60, 0x80];
        assert_eq!(
            label(0x204, &data),
            "Error frame: controller problem (RX error warning, RX error passive); error counters tx=96 rx=128"
        );
        assert_eq!(label(0x040, &[0; 8]), "Error frame: bus off");
        assert_eq!(label(0, &[]), "Error frame 0x00000000");
        assert_eq!(
            serde_json::to_value(to_json(0x20, &[])).unwrap()["details"],
            json!(["no ACK on transmission"])
        );
    }

    #[test]
    fn controller_states_and_counters() {
        use ControllerState::*;
        // Bus-off (class 0x040), with counters: tx 255 (well, 0xF8 as drivers cap it), rx 0.
        assert_eq!(
            controller_state(0x240, &[0, 0, 0, 0, 0, 0, 0xF8, 0]),
            (Some(BusOff), Some((0xF8, 0)))
        );
        assert_eq!(
            controller_state(0x004, &[0, 0x20, 0, 0, 0, 0, 0, 0]),
            (Some(Passive), None)
        );
        assert_eq!(
            controller_state(0x204, &[0, 0x04, 0, 0, 0, 0, 3, 97]),
            (Some(Warning), Some((3, 97)))
        );
        assert_eq!(
            controller_state(0x004, &[0, 0x40, 0, 0, 0, 0, 0, 0]),
            (Some(Active), None)
        );
        assert_eq!(controller_state(0x100, &[0; 8]), (Some(Active), None));
        // A protocol violation or a lost arbitration says nothing about the state.
        assert_eq!(controller_state(0x00A, &[3, 0, 0x04, 0, 0, 0, 0, 0]), (None, None));
        // Controller bits without the controller class are not read; short frames are fine.
        assert_eq!(controller_state(0x008, &[0, 0x30]), (None, None));
        assert_eq!(controller_state(0x204, &[0, 0x10]), (Some(Passive), Some((0, 0))));
    }
}
