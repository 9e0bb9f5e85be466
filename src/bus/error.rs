//! Why a bus could not be used, and the commands that fix it.

use std::fmt;

/// Why the bus could not be used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BusError {
    /// The interface is missing, down, not CAN, or not permitted; `fix` names the command that helps.
    Unavailable { iface: String, reason: String, fix: String },
    /// The handle was opened with `--listen-only`; nothing was sent.
    ListenOnly,
    /// Reading or writing failed on an open interface.
    Io { iface: String, reason: String },
    /// Every sender of the bus is gone.
    Closed,
}

impl fmt::Display for BusError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BusError::Unavailable { iface, reason, fix } => write!(f, "{iface}: {reason}; fix: {fix}"),
            BusError::ListenOnly => write!(f, "listen-only: this handle cannot send (drop --listen-only to send)"),
            BusError::Io { iface, reason } => write!(f, "{iface}: {reason}"),
            BusError::Closed => write!(f, "the bus was closed"),
        }
    }
}

impl std::error::Error for BusError {}

/// The commands that bring a CAN interface up, for error messages.
pub(crate) fn up_fix(iface: &str) -> String {
    format!("sudo ip link set {iface} up type can bitrate 500000 (a vcan: sudo ip link set {iface} up)")
}

/// The commands that create a virtual CAN interface, for error messages.
pub(crate) fn missing_fix(iface: &str) -> String {
    format!(
        "plug in the adapter and check `ip link`, or create a virtual one: \
         sudo modprobe vcan && sudo ip link add dev {iface} type vcan && sudo ip link set {iface} up"
    )
}
