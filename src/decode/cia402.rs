//! CiA 402 drive profile: controlword, statusword and modes of operation.

/// Drive state decoded from a statusword (CiA 402 table 30).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DriveState {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

impl DriveState {
    /// The state a statusword shows.
    pub fn from_statusword(sw: u16) -> DriveState {
        match (sw & 0x4F, sw & 0x6F) {
            (0x00, _) => DriveState::NotReadyToSwitchOn,
            (0x40, _) => DriveState::SwitchOnDisabled,
            (_, 0x21) => DriveState::ReadyToSwitchOn,
            (_, 0x23) => DriveState::SwitchedOn,
            (_, 0x27) => DriveState::OperationEnabled,
            (_, 0x07) => DriveState::QuickStopActive,
            (0x0F, _) => DriveState::FaultReactionActive,
            (0x08, _) => DriveState::Fault,
            // Any other pattern is not a valid state; the nearest reading is "not ready".
            _ => DriveState::NotReadyToSwitchOn,
        }
    }
    /// Human name as CiA 402 writes it.
    pub fn text(self) -> &'static str {
        match self {
            DriveState::NotReadyToSwitchOn => "Not ready to switch on",
            DriveState::SwitchOnDisabled => "Switch on disabled",
            DriveState::ReadyToSwitchOn => "Ready to switch on",
            DriveState::SwitchedOn => "Switched on",
            DriveState::OperationEnabled => "Operation enabled",
            DriveState::QuickStopActive => "Quick stop active",
            DriveState::FaultReactionActive => "Fault reaction active",
            DriveState::Fault => "Fault",
        }
    }
    /// snake_case name for JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            DriveState::NotReadyToSwitchOn => "not_ready_to_switch_on",
            DriveState::SwitchOnDisabled => "switch_on_disabled",
            DriveState::ReadyToSwitchOn => "ready_to_switch_on",
            DriveState::SwitchedOn => "switched_on",
            DriveState::OperationEnabled => "operation_enabled",
            DriveState::QuickStopActive => "quick_stop_active",
            DriveState::FaultReactionActive => "fault_reaction_active",
            DriveState::Fault => "fault",
        }
    }
}

/// Does a statusword bit pattern match one of the defined states exactly?
pub fn statusword_is_valid(sw: u16) -> bool {
    matches!(sw & 0x4F, 0x00 | 0x40 | 0x0F | 0x08) || matches!(sw & 0x6F, 0x21 | 0x23 | 0x27 | 0x07)
}

/// Statusword bit names 0..=15 (bits 12/13 depend on the mode and are named by [`mode_bits`]).
const STATUS_BITS: [&str; 16] = [
    "ready to switch on",
    "switched on",
    "operation enabled",
    "fault",
    "voltage enabled",
    "quick stop",
    "switch on disabled",
    "warning",
    "manufacturer 8",
    "remote",
    "target reached",
    "internal limit active",
    "mode bit 12",
    "mode bit 13",
    "manufacturer 14",
    "manufacturer 15",
];

/// Names of statusword bits 10, 12 and 13 in a mode of operation.
fn mode_bits(mode: Option<i8>) -> [&'static str; 3] {
    match mode {
        Some(1) => ["target reached", "set-point acknowledge", "following error"],
        Some(3) => ["target reached", "speed is zero", "max slippage error"],
        Some(4) => ["target reached", "mode bit 12", "mode bit 13"],
        Some(6) => ["target reached", "homing attained", "homing error"],
        Some(7) => ["target reached", "ip mode active", "mode bit 13"],
        Some(8) => ["status toggle", "drive follows command value", "following error"],
        Some(9) | Some(10) => ["status toggle", "drive follows command value", "mode bit 13"],
        _ => ["target reached", "mode bit 12", "mode bit 13"],
    }
}

/// Names of the statusword bits that are set, in bit order.
pub fn statusword_bits(sw: u16, mode: Option<i8>) -> Vec<&'static str> {
    let m = mode_bits(mode);
    (0..16)
        .filter(|b| sw & (1 << b) != 0)
        .map(|b| match b {
            10 => m[0],
            12 => m[1],
            13 => m[2],
            _ => STATUS_BITS[b],
        })
        .collect()
}

/// Statusword meaning: `Operation enabled [ready to switch on, ...]`.
pub fn describe_statusword(sw: u16, mode: Option<i8>) -> String {
    let state = DriveState::from_statusword(sw);
    let valid = if statusword_is_valid(sw) {
        ""
    } else {
        " (invalid state bits)"
    };
    format!("{}{valid} [{}]", state.text(), statusword_bits(sw, mode).join(", "))
}

/// The device control command a controlword encodes (CiA 402 table 29).
pub fn controlword_command(cw: u16) -> &'static str {
    if cw & 0x80 != 0 {
        "Fault reset"
    } else if cw & 0x02 == 0 {
        "Disable voltage"
    } else if cw & 0x06 == 0x02 {
        "Quick stop"
    } else if cw & 0x07 == 0x06 {
        "Shutdown"
    } else if cw & 0x0F == 0x07 {
        "Switch on / Disable operation"
    } else {
        "Enable operation"
    }
}

/// Names of controlword bits 4, 5, 6 and 9 in a mode of operation.
fn control_mode_bits(mode: Option<i8>) -> [&'static str; 4] {
    match mode {
        Some(1) => [
            "new set-point",
            "change set immediately",
            "relative",
            "change on set-point",
        ],
        Some(6) => ["homing start", "mode bit 5", "mode bit 6", "mode bit 9"],
        Some(7) => ["enable ip mode", "mode bit 5", "mode bit 6", "mode bit 9"],
        _ => ["mode bit 4", "mode bit 5", "mode bit 6", "mode bit 9"],
    }
}

/// Controlword meaning: `Enable operation [new set-point, halt]`.
pub fn describe_controlword(cw: u16, mode: Option<i8>) -> String {
    let m = control_mode_bits(mode);
    let extra: Vec<&str> = [(4, m[0]), (5, m[1]), (6, m[2]), (8, "halt"), (9, m[3])]
        .iter()
        .filter(|(b, _)| cw & (1 << b) != 0)
        .map(|(_, n)| *n)
        .collect();
    if extra.is_empty() {
        controlword_command(cw).to_string()
    } else {
        format!("{} [{}]", controlword_command(cw), extra.join(", "))
    }
}

/// Name of a mode of operation (0x6060 / 0x6061).
pub fn mode_name(mode: i8) -> &'static str {
    match mode {
        0 => "No mode",
        1 => "Profile position",
        2 => "Velocity",
        3 => "Profile velocity",
        4 => "Profile torque",
        6 => "Homing",
        7 => "Interpolated position",
        8 => "Cyclic synchronous position",
        9 => "Cyclic synchronous velocity",
        10 => "Cyclic synchronous torque",
        m if m < 0 => "Manufacturer-specific mode",
        _ => "Reserved mode",
    }
}

/// CiA 402 meaning of a value of a known object, when it has one.
pub fn describe(index: u16, sub: u8, raw: i64, mode: Option<i8>) -> Option<String> {
    if sub != 0 {
        return None;
    }
    match index {
        0x6040 => Some(describe_controlword(raw as u16, mode)),
        0x6041 => Some(describe_statusword(raw as u16, mode)),
        0x6060 | 0x6061 => Some(mode_name(raw as i8).to_string()),
        _ => None,
    }
}

/// A value of a CiA 402 word as labels show it: `0x0237 (Operation enabled [...])`,
/// `3 (Profile velocity)`; `None` for other objects.
pub fn value_text(index: u16, sub: u8, raw: i64, mode: Option<i8>) -> Option<String> {
    let meaning = describe(index, sub, raw, mode)?;
    Some(match index {
        0x6060 | 0x6061 => format!("{} ({meaning})", raw as i8),
        _ => format!("0x{:04X} ({meaning})", raw as u16),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statusword_states_from_the_seed_manuals() {
        // Syn-tron and AIMOTOR manuals: 0x0250, 0x0231, 0x0233, 0x0237, and fault 0x0088/0x0218.
        assert_eq!(DriveState::from_statusword(0x0250), DriveState::SwitchOnDisabled);
        assert_eq!(DriveState::from_statusword(0x0231), DriveState::ReadyToSwitchOn);
        assert_eq!(DriveState::from_statusword(0x0233), DriveState::SwitchedOn);
        assert_eq!(DriveState::from_statusword(0x0237), DriveState::OperationEnabled);
        assert_eq!(DriveState::from_statusword(0x0217), DriveState::QuickStopActive);
        assert_eq!(DriveState::from_statusword(0x0218), DriveState::Fault);
        assert_eq!(DriveState::from_statusword(0x021F), DriveState::FaultReactionActive);
        assert_eq!(DriveState::from_statusword(0x0000), DriveState::NotReadyToSwitchOn);
        // EPOS trace from machinekit#589.
        assert_eq!(DriveState::from_statusword(0x0740), DriveState::SwitchOnDisabled);
        assert_eq!(DriveState::from_statusword(0x0721), DriveState::ReadyToSwitchOn);
    }

    #[test]
    fn statusword_text() {
        assert_eq!(
            describe_statusword(0x0237, None),
            "Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote]"
        );
        assert_eq!(
            describe_statusword(0x1637, Some(1)),
            "Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote, target reached, set-point acknowledge]"
        );
        assert_eq!(describe_statusword(0x0088, None), "Fault [fault, warning]");
        assert_eq!(
            describe_statusword(0x0001, None),
            "Not ready to switch on (invalid state bits) [ready to switch on]"
        );
    }

    #[test]
    fn controlword_commands() {
        assert_eq!(describe_controlword(0x06, None), "Shutdown");
        assert_eq!(describe_controlword(0x07, None), "Switch on / Disable operation");
        assert_eq!(describe_controlword(0x0F, None), "Enable operation");
        assert_eq!(describe_controlword(0x1F, Some(1)), "Enable operation [new set-point]");
        assert_eq!(
            describe_controlword(0x5F, Some(1)),
            "Enable operation [new set-point, relative]"
        );
        assert_eq!(describe_controlword(0x1F, Some(6)), "Enable operation [homing start]");
        assert_eq!(describe_controlword(0x80, None), "Fault reset");
        assert_eq!(describe_controlword(0x02, None), "Quick stop");
        assert_eq!(describe_controlword(0x00, None), "Disable voltage");
        assert_eq!(describe_controlword(0x010F, None), "Enable operation [halt]");
    }

    #[test]
    fn modes() {
        assert_eq!(mode_name(3), "Profile velocity");
        assert_eq!(mode_name(-1), "Manufacturer-specific mode");
        assert_eq!(describe(0x6060, 0, 8, None).unwrap(), "Cyclic synchronous position");
        assert_eq!(describe(0x6041, 1, 8, None), None);
    }
}
