//! The state of an interface and its CAN controller as subscriptions report it, with the
//! text and fix shown to the user, and the reader's pure decision of what to do with its
//! socket given what `/sys/class/net/IFACE` says.

use super::error::{BusError, up_fix};
use crate::decode::error_frame::ControllerState;

/// The state of a bus handle's interface and controller.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BusState {
    /// Capturing; the controller is error-active.
    Active,
    /// Capturing; an error counter reached the warning level.
    Warning,
    /// Capturing; the controller is error-passive.
    Passive,
    /// Not capturing: the controller is bus-off.
    BusOff,
    /// Not capturing: the interface is down. Frames resume when it is up again.
    Down,
    /// Not capturing: the interface is gone (unplugged, `ip link del`). It is reopened by
    /// name when it is back.
    Missing,
    /// Not capturing: the connection to a socketcand server is lost. The handle reconnects
    /// every second.
    Disconnected,
}

impl BusState {
    /// The state an error frame's controller state maps to.
    pub fn from_controller(c: ControllerState) -> BusState {
        match c {
            ControllerState::Active => BusState::Active,
            ControllerState::Warning => BusState::Warning,
            ControllerState::Passive => BusState::Passive,
            ControllerState::BusOff => BusState::BusOff,
        }
    }
    /// True while frames on the bus reach the handle.
    pub fn capturing(self) -> bool {
        matches!(self, BusState::Active | BusState::Warning | BusState::Passive)
    }
    /// Short name, as in `"gaps": [{"reason"}]`.
    pub fn name(self) -> &'static str {
        match self {
            BusState::Active => "error-active",
            BusState::Warning => "error-warning",
            BusState::Passive => "error-passive",
            BusState::BusOff => "bus-off",
            BusState::Down => "interface down",
            BusState::Missing => "interface missing",
            BusState::Disconnected => "connection lost",
        }
    }
    /// What the user can do about the state (none when all is well).
    pub fn fix(self, iface: &str) -> Option<String> {
        let wiring = "check wiring, termination, bitrate";
        match self {
            BusState::Active => None,
            BusState::Warning | BusState::Passive => Some(format!(
                "{wiring} (error counters: ip -details -statistics link show {iface})"
            )),
            BusState::BusOff => Some(format!(
                "{wiring}; restart: sudo ip link set {iface} type can restart-ms 100"
            )),
            BusState::Down => Some(up_fix(iface)),
            BusState::Missing => Some(format!(
                "plug it back in (a vcan: sudo ip link add dev {iface} type vcan && sudo ip link set {iface} up)"
            )),
            BusState::Disconnected => {
                Some("check that the server runs and the network reaches it (reconnecting every second)".into())
            }
        }
    }
}

/// A change of a handle's [`BusState`], stamped with the wall-clock time it was seen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateChange {
    /// When: ns since the Unix epoch (the clock of frame timestamps).
    pub ts_ns: u64,
    /// The new state.
    pub state: BusState,
    /// The controller's transmit and receive error counters, when the error frame carried them.
    pub counters: Option<(u8, u8)>,
}

impl StateChange {
    /// One line for the user: the state, the counters, whether frames are captured, the fix.
    pub fn text(&self, iface: &str) -> String {
        let counters = self
            .counters
            .map(|(tx, rx)| format!(" (errors: tx {tx}, rx {rx})"))
            .unwrap_or_default();
        let what = match self.state {
            BusState::Active => format!("{iface}: capturing, controller error-active{counters}"),
            BusState::Warning | BusState::Passive => format!("{iface}: controller {}{counters}", self.state.name()),
            BusState::BusOff => format!("{iface}: bus-off{counters}, not capturing"),
            BusState::Down => format!("{iface}: interface is down, not capturing"),
            BusState::Missing => format!("{iface}: interface is gone, not capturing"),
            BusState::Disconnected => format!("{iface}: connection to the server lost, not capturing"),
        };
        match self.state.fix(iface) {
            Some(fix) => format!("{what}; fix: {fix}"),
            None => what,
        }
    }
    /// The error a frame-only reader ([`super::Subscription::recv`]) gets when capture stops.
    pub fn error(&self, iface: &str) -> Option<BusError> {
        (!self.state.capturing()).then(|| BusError::Unavailable {
            iface: iface.to_string(),
            reason: match self.state {
                BusState::BusOff => "controller is bus-off".to_string(),
                BusState::Down => "interface is down".to_string(),
                BusState::Disconnected => "connection to the server lost".to_string(),
                _ => "interface is gone".to_string(),
            },
            fix: self.state.fix(iface).unwrap_or_default(),
        })
    }
}

/// What `/sys/class/net/IFACE` says about an interface that exists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SysLink {
    /// `ifindex`: a new one after the interface was deleted and created again.
    pub index: u32,
    /// `IFF_UP` of `flags`.
    pub up: bool,
}

/// What the reader does with its socket.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Keep the socket; the interface is up or down as told.
    Keep { up: bool },
    /// Open a new socket by name (the interface is back, or is another one now); then up or down as told.
    Reopen { up: bool },
    /// Close the socket: the interface is gone.
    Close,
}

/// Decides from the interface index the socket is bound to (none: no socket) and what
/// `/sys/class/net/IFACE` says (none: no such interface). A socket bound to an index
/// that is no longer the interface's receives nothing and reports no error: it is replaced.
pub fn decide(bound: Option<u32>, sys: Option<SysLink>) -> Action {
    match (bound, sys) {
        (_, None) => Action::Close,
        (Some(b), Some(s)) if b == s.index => Action::Keep { up: s.up },
        (_, Some(s)) => Action::Reopen { up: s.up },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn socket_follows_the_interface_through_down_delete_and_add() {
        let up = |index| Some(SysLink { index, up: true });
        let down = |index| Some(SysLink { index, up: false });
        assert_eq!(decide(Some(4), up(4)), Action::Keep { up: true });
        assert_eq!(decide(Some(4), down(4)), Action::Keep { up: false });
        assert_eq!(decide(Some(4), None), Action::Close);
        assert_eq!(decide(None, None), Action::Close);
        // Deleted and added again: a new index, down until `ip link set up`.
        assert_eq!(decide(None, down(9)), Action::Reopen { up: false });
        assert_eq!(decide(Some(4), up(9)), Action::Reopen { up: true });
    }

    #[test]
    fn texts_name_the_state_and_the_fix() {
        let at = |state, counters| StateChange {
            ts_ns: 0,
            state,
            counters,
        };
        let down = at(BusState::Down, None).text("can0");
        assert!(
            down.starts_with("can0: interface is down, not capturing; fix: "),
            "{down}"
        );
        assert!(down.contains("sudo ip link set can0 up"), "{down}");
        let gone = at(BusState::Missing, None).text("vcan0");
        assert!(gone.contains("sudo ip link add dev vcan0 type vcan"), "{gone}");
        // The status bar of a 160-column terminal shows every state with its fix in full.
        for s in [BusState::Down, BusState::Missing, BusState::BusOff] {
            let t = at(s, Some((255, 255))).text("vcan0");
            assert!(t.len() <= 160, "{} chars: {t}", t.len());
        }
        let off = at(BusState::BusOff, Some((248, 0))).text("can0");
        assert!(
            off.starts_with("can0: bus-off (errors: tx 248, rx 0), not capturing; fix: check wiring"),
            "{off}"
        );
        assert!(
            off.ends_with("restart: sudo ip link set can0 type can restart-ms 100"),
            "{off}"
        );
        let passive = at(BusState::Passive, Some((128, 3))).text("can0");
        assert!(passive.starts_with("can0: controller error-passive (errors: tx 128, rx 3); fix:"));
        assert_eq!(
            at(BusState::Active, None).text("can0"),
            "can0: capturing, controller error-active"
        );
        assert_eq!(at(BusState::Passive, None).error("can0"), None);
        let e = at(BusState::Down, None).error("can0").unwrap().to_string();
        assert!(
            e.starts_with("can0: interface is down; fix: sudo ip link set can0 up"),
            "{e}"
        );
    }
}
