//! Why a CiA 402 drive did not reach the state a controlword asked for, from what the bus
//! shows: used by the commander when a step of `drive` times out, and by the diagnosis
//! for a drive stuck in a state in a capture. Pure.

use super::cia402::{DriveState, mode_name};
use super::heartbeat::NmtState;

/// One step of a sequence: write `controlword`, then wait for a statusword showing `target`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    pub name: &'static str,
    pub controlword: u16,
    pub target: DriveState,
}

/// What the bus showed about a drive when a step did not happen.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Observation {
    /// Last NMT state from a heartbeat or boot-up, if any was seen.
    pub nmt: Option<NmtState>,
    /// The statusword before the step's controlword was written.
    pub before: Option<u16>,
    /// The last statusword read (SDO or TPDO).
    pub statusword: Option<u16>,
    /// 0x6061 modes of operation display, if readable.
    pub mode_display: Option<i8>,
    /// 0x603F error code, if readable.
    pub error_code: Option<u16>,
    /// The controlword read back from 0x6040, if readable.
    pub controlword: Option<u16>,
    /// The last EMCY error code the node sent.
    pub emcy: Option<u16>,
    /// True when the node's SDO server stopped answering.
    pub sdo_silent: bool,
}

/// Why `step` did not reach its state, from what the bus shows; `node` names the fix commands.
pub fn diagnose(node: u8, step: &Step, o: &Observation) -> String {
    let nmt_hint = format!("run `cotui nmt IFACE start {node}`");
    if o.nmt == Some(NmtState::Stopped) {
        return format!(
            "NMT not operational: node {node} is NMT stopped (heartbeat) and serves no SDO or PDO; {nmt_hint}"
        );
    }
    if o.sdo_silent {
        return match o.nmt {
            None => {
                format!("no SDO answer and no heartbeat from node {node}: check the node id, bitrate, wiring and power")
            }
            Some(s) => format!("node {node} stopped answering SDO (heartbeat says {})", s.text()),
        };
    }
    let Some(sw) = o.statusword else {
        return "no statusword could be read".into();
    };
    let state = DriveState::from_statusword(sw);
    if sw & 0x0008 != 0 {
        let code = o
            .error_code
            .or(o.emcy)
            .map(|c| format!(" (error code 0x{c:04X})"))
            .unwrap_or_default();
        return format!(
            "fault bit set: statusword 0x{sw:04X} shows {}{code}; run `drive {node} fault-reset`",
            state.text()
        );
    }
    if state == DriveState::QuickStopActive {
        return format!(
            "quick stop active (statusword 0x{sw:04X}); `drive {node} enable` leaves it via disable voltage"
        );
    }
    if matches!(step.target, DriveState::SwitchedOn | DriveState::OperationEnabled) && sw & 0x0010 == 0 {
        return format!(
            "voltage not enabled: statusword 0x{sw:04X} bit 4 is clear; switch on the drive's DC link / main power"
        );
    }
    if let Some(cw) = o.controlword
        && cw & 0x0100 != 0
    {
        return format!("halt bit set: controlword 0x{cw:04X} has bit 8 (halt) set");
    }
    if step.target == DriveState::OperationEnabled
        && let Some(m) = o.mode_display
        && !(1..=10).contains(&m)
    {
        return format!(
            "mode not set: modes of operation display 0x6061 = {m} ({}); run `drive {node} mode pv` (or the mode you use)",
            mode_name(m)
        );
    }
    if o.before == Some(sw) {
        let nmt = match o.nmt {
            Some(NmtState::Operational) => String::new(),
            Some(s) => format!(
                "; node is NMT {} and some drives take the controlword only when operational: {nmt_hint}",
                s.text()
            ),
            None => "; no heartbeat seen".into(),
        };
        return format!(
            "statusword stale: still 0x{sw:04X} ({}) after controlword 0x{:04X}{nmt}",
            state.text(),
            step.controlword
        );
    }
    format!(
        "statusword 0x{sw:04X} shows {} instead of {}",
        state.text(),
        step.target.text()
    )
}

/// The state change a controlword asks for (CiA 402 table 29), as a [`Step`]; None for a
/// fault reset (bit 7), which is judged with the fault it resets.
pub fn requested(cw: u16) -> Option<Step> {
    let (name, target) = match super::cia402::controlword_command(cw) {
        "Fault reset" => return None,
        "Disable voltage" => ("disable voltage", DriveState::SwitchOnDisabled),
        "Quick stop" => ("quick stop", DriveState::QuickStopActive),
        "Shutdown" => ("shutdown", DriveState::ReadyToSwitchOn),
        "Switch on / Disable operation" => ("switch on", DriveState::SwitchedOn),
        _ => ("enable operation", DriveState::OperationEnabled),
    };
    Some(Step {
        name,
        controlword: cw,
        target,
    })
}

/// True when `state` is what `step` asked for, or a state the drive may rightly show
/// instead (a quick stop ends in "switch on disabled" when it was not running).
pub fn reached(step: &Step, state: DriveState) -> bool {
    state == step.target
        || (step.target == DriveState::QuickStopActive && state == DriveState::SwitchOnDisabled)
        || (step.target == DriveState::SwitchOnDisabled && state == DriveState::NotReadyToSwitchOn)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controlwords_name_the_state_they_ask_for() {
        assert_eq!(requested(0x0F).map(|s| s.target), Some(DriveState::OperationEnabled));
        assert_eq!(requested(0x1F).map(|s| s.target), Some(DriveState::OperationEnabled));
        assert_eq!(requested(0x06).map(|s| s.target), Some(DriveState::ReadyToSwitchOn));
        assert_eq!(requested(0x07).map(|s| s.target), Some(DriveState::SwitchedOn));
        assert_eq!(requested(0x02).map(|s| s.target), Some(DriveState::QuickStopActive));
        assert_eq!(requested(0x00).map(|s| s.target), Some(DriveState::SwitchOnDisabled));
        assert_eq!(requested(0x80), None);
        let qs = requested(0x02).unwrap();
        assert!(reached(&qs, DriveState::SwitchOnDisabled));
        assert!(!reached(&requested(0x0F).unwrap(), DriveState::SwitchedOn));
    }
}
