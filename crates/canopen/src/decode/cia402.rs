//! CiA 402 drive profile: controlword, statusword and modes of operation.

use crate::od::ObjectInfo;

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
pub(crate) fn statusword_is_valid(sw: u16) -> bool {
    matches!(sw & 0x4F, 0x00 | 0x40 | 0x0F | 0x08) || matches!(sw & 0x6F, 0x21 | 0x23 | 0x27 | 0x07)
}

/// Statusword bit names 0..=15 (bits 10, 12 and 13 depend on the mode and are named by [`status_mode_bits`]).
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

/// The profile's texts for a controlword or statusword (`values` for whole words,
/// `bits` for single bits); `None` when the dictionary has no entry.
pub(crate) type WordTexts<'a> = Option<&'a ObjectInfo>;

/// Names of statusword bits 10, 12 and 13 in a mode of operation (CiA 402-2), `None`
/// when the mode is unknown.
fn status_mode_bits(mode: Option<i8>) -> Option<[&'static str; 3]> {
    Some(match mode? {
        1 => ["target reached", "set-point acknowledge", "following error"],
        3 => ["target reached", "speed is zero", "max slippage error"],
        4 => [
            "target reached",
            "mode bit 12 (reserved in PT)",
            "mode bit 13 (reserved in PT)",
        ],
        6 => ["target reached", "homing attained", "homing error"],
        7 => ["target reached", "ip mode active", "mode bit 13 (reserved in IP)"],
        8 => [
            "bit 10 (reserved in CSP)",
            "drive follows the command value",
            "following error",
        ],
        9 => [
            "bit 10 (reserved in CSV)",
            "drive follows the command value",
            "mode bit 13 (reserved in CSV)",
        ],
        10 => [
            "bit 10 (reserved in CST)",
            "drive follows the command value",
            "mode bit 13 (reserved in CST)",
        ],
        _ => return None,
    })
}

/// The name of a bit from the profile's `bits`, else `fallback`.
fn profile_bit<'a>(texts: WordTexts<'a>, bit: u8, fallback: &'a str) -> &'a str {
    texts.and_then(|i| i.bits.get(&bit)).map_or(fallback, String::as_str)
}

/// Pushes `items` onto `out` joined by `, `.
fn push_joined<'a>(out: &mut String, items: impl Iterator<Item = &'a str>) {
    for (i, item) in items.enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        out.push_str(item);
    }
}

/// Names of the statusword bits that are set, in bit order: bits 10/12/13 per the mode in
/// force, else the profile's bit names, else `mode bit N`. In the cyclic synchronous modes an
/// enabled drive with bit 12 clear also shows `target ignored`.
fn statusword_bits<'a>(sw: u16, mode: Option<i8>, texts: WordTexts<'a>) -> impl Iterator<Item = &'a str> {
    let m = status_mode_bits(mode);
    let ignored = matches!(mode, Some(8..=10))
        && sw & (1 << 12) == 0
        && DriveState::from_statusword(sw) == DriveState::OperationEnabled;
    (0..16u8)
        .filter(move |b| sw & (1 << b) != 0)
        .map(move |b| match (b, m) {
            (10, Some(m)) => m[0],
            (12, Some(m)) => m[1],
            (13, Some(m)) => m[2],
            (12 | 13, None) => profile_bit(texts, b, STATUS_BITS[b as usize]),
            _ => STATUS_BITS[b as usize],
        })
        .chain(ignored.then_some("target ignored"))
}

/// Statusword meaning: `Operation enabled [ready to switch on, ...]`.
pub fn describe_statusword(sw: u16, mode: Option<i8>, texts: WordTexts<'_>) -> String {
    let mut out = String::new();
    write_statusword(&mut out, sw, mode, texts);
    out
}

/// [`describe_statusword`] appended to `out`.
fn write_statusword(out: &mut String, sw: u16, mode: Option<i8>, texts: WordTexts<'_>) {
    out.push_str(DriveState::from_statusword(sw).text());
    if !statusword_is_valid(sw) {
        out.push_str(" (invalid state bits)");
    }
    out.push_str(" [");
    push_joined(out, statusword_bits(sw, mode, texts));
    out.push(']');
}

/// The device control command a controlword encodes (CiA 402 table 29).
pub(crate) fn controlword_command(cw: u16) -> &'static str {
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

/// Names of controlword bits 4, 5, 6 and 9 in a mode of operation (CiA 402-2), `None`
/// when the mode is unknown.
fn control_mode_bits(mode: Option<i8>) -> Option<[&'static str; 4]> {
    Some(match mode? {
        1 => [
            "new set-point",
            "change set immediately",
            "relative",
            "change on set-point",
        ],
        3 => [
            "mode bit 4 (reserved in PV)",
            "mode bit 5 (reserved in PV)",
            "mode bit 6 (reserved in PV)",
            "mode bit 9 (reserved in PV)",
        ],
        4 => [
            "mode bit 4 (reserved in PT)",
            "mode bit 5 (reserved in PT)",
            "mode bit 6 (reserved in PT)",
            "mode bit 9 (reserved in PT)",
        ],
        6 => [
            "start homing",
            "mode bit 5 (reserved in HM)",
            "mode bit 6 (reserved in HM)",
            "mode bit 9 (reserved in HM)",
        ],
        7 => ["enable ip mode", "mode bit 5", "mode bit 6", "mode bit 9"],
        8..=10 => [
            "mode bit 4 (reserved in CSP/CSV/CST)",
            "mode bit 5 (reserved in CSP/CSV/CST)",
            "mode bit 6 (reserved in CSP/CSV/CST)",
            "mode bit 9 (reserved in CSP/CSV/CST)",
        ],
        _ => return None,
    })
}

/// Controlword meaning: `Enable operation [new set-point, halt]`. The command is the
/// profile's text for this exact value when it has one (Syn-tron 0x005F `Enable operation,
/// start relative (bits 4, 6)`), else the CiA 402 command. Bits 4/5/6/9 are named per the
/// mode in force; with the mode unknown, a profile text for the value already says what
/// they do, else the profile's bit names (else `mode bit N`) are shown.
pub fn describe_controlword(cw: u16, mode: Option<i8>, texts: WordTexts<'_>) -> String {
    let mut out = String::new();
    write_controlword(&mut out, cw, mode, texts);
    out
}

/// [`describe_controlword`] appended to `out`.
fn write_controlword(out: &mut String, cw: u16, mode: Option<i8>, texts: WordTexts<'_>) {
    let value_text = texts.and_then(|i| i.values.get(&i64::from(cw)));
    let m = control_mode_bits(mode);
    let extra = [4u8, 5, 6, 8, 9]
        .into_iter()
        .filter(|b| cw & (1 << *b) != 0)
        .filter_map(|b| {
            let k = match b {
                4 => 0,
                5 => 1,
                6 => 2,
                9 => 3,
                _ => return Some("halt"),
            };
            match m {
                Some(m) => Some(m[k]),
                None if value_text.is_some() => None,
                None => Some(profile_bit(texts, b, MODE_BITS[k])),
            }
        });
    out.push_str(value_text.map_or(controlword_command(cw), String::as_str));
    let mut extra = extra.peekable();
    if extra.peek().is_some() {
        out.push_str(" [");
        push_joined(out, extra);
        out.push(']');
    }
}

/// `mode bit N` for controlword bits 4, 5, 6 and 9, when neither the mode nor the profile
/// names them.
const MODE_BITS: [&str; 4] = ["mode bit 4", "mode bit 5", "mode bit 6", "mode bit 9"];

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

/// CiA 402 meaning of a value of a known object, when it has one; `texts` are the
/// dictionary's entry for the object (profile value and bit texts).
pub fn describe(index: u16, sub: u8, raw: i64, mode: Option<i8>, texts: WordTexts<'_>) -> Option<String> {
    let mut out = String::new();
    write_description(&mut out, index, sub, raw, mode, texts).then_some(out)
}

/// Whether [`describe`] has a meaning for the object (sub-index 0 of 0x6040, 0x6041,
/// 0x6060 or 0x6061).
fn described(index: u16, sub: u8) -> bool {
    sub == 0 && matches!(index, 0x6040 | 0x6041 | 0x6060 | 0x6061)
}

/// [`describe`] appended to `out`; false (nothing written) when the object has none.
fn write_description(out: &mut String, index: u16, sub: u8, raw: i64, mode: Option<i8>, texts: WordTexts<'_>) -> bool {
    if !described(index, sub) {
        return false;
    }
    match index {
        0x6040 => write_controlword(out, raw as u16, mode, texts),
        0x6041 => write_statusword(out, raw as u16, mode, texts),
        _ => out.push_str(
            texts
                .and_then(|i| i.values.get(&i64::from(raw as i8)))
                .map_or(mode_name(raw as i8), String::as_str),
        ),
    }
    true
}

/// A value of a CiA 402 word as labels show it: `0x0237 (Operation enabled [...])`,
/// `3 (Profile velocity)`; `None` for other objects.
pub fn value_text(index: u16, sub: u8, raw: i64, mode: Option<i8>, texts: WordTexts<'_>) -> Option<String> {
    if !described(index, sub) {
        return None;
    }
    use std::fmt::Write;
    let mut out = String::with_capacity(128);
    let _ = match index {
        0x6060 | 0x6061 => write!(out, "{} (", raw as i8),
        _ => write!(out, "0x{:04X} (", raw as u16),
    };
    write_description(&mut out, index, sub, raw, mode, texts);
    out.push(')');
    Some(out)
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
            describe_statusword(0x0237, None, None),
            "Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote]"
        );
        assert_eq!(
            describe_statusword(0x1637, Some(1), None),
            "Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote, target reached, set-point acknowledge]"
        );
        assert_eq!(describe_statusword(0x0088, None, None), "Fault [fault, warning]");
        assert_eq!(
            describe_statusword(0x0001, None, None),
            "Not ready to switch on (invalid state bits) [ready to switch on]"
        );
    }

    #[test]
    fn controlword_commands() {
        assert_eq!(describe_controlword(0x06, None, None), "Shutdown");
        assert_eq!(describe_controlword(0x07, None, None), "Switch on / Disable operation");
        assert_eq!(describe_controlword(0x0F, None, None), "Enable operation");
        assert_eq!(
            describe_controlword(0x1F, Some(1), None),
            "Enable operation [new set-point]"
        );
        assert_eq!(
            describe_controlword(0x5F, Some(1), None),
            "Enable operation [new set-point, relative]"
        );
        assert_eq!(
            describe_controlword(0x1F, Some(6), None),
            "Enable operation [start homing]"
        );
        assert_eq!(describe_controlword(0x80, None, None), "Fault reset");
        assert_eq!(describe_controlword(0x02, None, None), "Quick stop");
        assert_eq!(describe_controlword(0x00, None, None), "Disable voltage");
        assert_eq!(describe_controlword(0x010F, None, None), "Enable operation [halt]");
    }

    #[test]
    fn profile_texts_stand_in_when_the_mode_is_unknown() {
        let mut info = ObjectInfo::default();
        info.bits
            .insert(4, "Operation mode specific (new set-point / homing start)".into());
        info.bits.insert(
            12,
            "Operation mode specific (set-point acknowledge / homing attained)".into(),
        );
        info.values
            .insert(0x5F, "Enable operation, start relative (bits 4, 6)".into());
        let texts = Some(&info);
        assert_eq!(
            describe_controlword(0x1F, None, texts),
            "Enable operation [Operation mode specific (new set-point / homing start)]"
        );
        assert_eq!(
            describe_controlword(0x5F, None, texts),
            "Enable operation, start relative (bits 4, 6)"
        );
        assert_eq!(
            describe_controlword(0x5F, Some(1), texts),
            "Enable operation, start relative (bits 4, 6) [new set-point, relative]"
        );
        assert_eq!(
            describe_statusword(0x1237, None, texts),
            "Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote, Operation mode specific (set-point acknowledge / homing attained)]"
        );
        // Without profile texts: `mode bit N`.
        assert_eq!(describe_controlword(0x1F, None, None), "Enable operation [mode bit 4]");
        // Cyclic modes: bit 12 clear while enabled means the target is ignored.
        assert!(describe_statusword(0x0237, Some(9), None).ends_with("remote, target ignored]"));
        assert_eq!(describe(0x6061, 0, 6, None, Some(&info)).unwrap(), "Homing");
    }

    #[test]
    fn modes() {
        assert_eq!(mode_name(3), "Profile velocity");
        assert_eq!(mode_name(-1), "Manufacturer-specific mode");
        assert_eq!(
            describe(0x6060, 0, 8, None, None).unwrap(),
            "Cyclic synchronous position"
        );
        assert_eq!(describe(0x6041, 1, 8, None, None), None);
    }
}
