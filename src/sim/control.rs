//! The words that make simulated nodes fail, declared once: `cotui sim` reads them as lines
//! on stdin (`fault 2 0x2310`), the demo's palette takes them after `sim`
//! (`:sim fault 2 0x2310`).

use super::Simulation;
use super::spec::number;
use crate::frame::Frame;

/// The control words, for help texts and completion.
pub const USAGE: &str = "fault NODE CODE | silence NODE | resume NODE | reboot NODE | mains NODE on|off | status";

/// One control command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// EMCY with this error code, then Fault.
    Fault { node: u8, code: u16 },
    /// The node sends and answers nothing (its heartbeat stops).
    Silence(u8),
    /// A silenced node sends again.
    Resume(u8),
    /// Power cycle: boot-up, pre-operational, dictionary defaults.
    Reboot(u8),
    /// DC link voltage on or off.
    Mains { node: u8, on: bool },
    /// Every node's NMT and CiA 402 state.
    Status,
}

/// Why a control line does not parse.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ControlError {
    #[error("usage: {USAGE}")]
    Usage,
    #[error("`{0}` is not a node-ID (1..127)")]
    Node(String),
    #[error("fault: `{0}` is not a 16-bit error code")]
    Code(String),
}

impl Control {
    /// Parses a control line (`fault 2 0x2310`).
    pub fn parse(line: &str) -> Result<Control, ControlError> {
        let words: Vec<&str> = line.split_whitespace().collect();
        let node = |w: &str| match number(w) {
            Some(n @ 1..=127) => Ok(n as u8),
            _ => Err(ControlError::Node(w.to_string())),
        };
        Ok(match words[..] {
            ["status"] => Control::Status,
            ["fault", n, code] => Control::Fault {
                node: node(n)?,
                code: number(code)
                    .and_then(|c| u16::try_from(c).ok())
                    .ok_or_else(|| ControlError::Code(code.to_string()))?,
            },
            ["silence", n] => Control::Silence(node(n)?),
            ["resume", n] => Control::Resume(node(n)?),
            ["reboot", n] => Control::Reboot(node(n)?),
            ["mains", n, on @ ("on" | "off")] => Control::Mains {
                node: node(n)?,
                on: on == "on",
            },
            _ => return Err(ControlError::Usage),
        })
    }

    /// Carries the command out at `now_ns`; returns what to tell the user and the frames
    /// the nodes send at once (boot-up after a reboot).
    pub fn apply(self, sim: &mut Simulation, now_ns: u64) -> (String, Vec<Frame>) {
        let node = match self {
            Control::Status => {
                let lines: Vec<String> = sim
                    .drives()
                    .iter()
                    .map(|d| {
                        format!(
                            "node {}: {:?}, {}{}",
                            d.node(),
                            d.nmt(),
                            d.state().text(),
                            if d.is_silent() { ", silenced" } else { "" }
                        )
                    })
                    .collect();
                return (lines.join("\n"), Vec::new());
            }
            Control::Fault { node, .. }
            | Control::Silence(node)
            | Control::Resume(node)
            | Control::Reboot(node)
            | Control::Mains { node, .. } => node,
        };
        let Some(drive) = sim.drive_mut(node) else {
            return (format!("no simulated node {node}"), Vec::new());
        };
        match self {
            Control::Fault { code, .. } => {
                drive.inject_fault(code);
                (
                    format!("node {node}: fault 0x{code:04X} (EMCY, then Fault)"),
                    Vec::new(),
                )
            }
            Control::Silence(_) => {
                drive.set_silent(true);
                (format!("node {node}: silenced (sends and answers nothing)"), Vec::new())
            }
            Control::Resume(_) => {
                drive.set_silent(false);
                (format!("node {node}: sends again"), Vec::new())
            }
            Control::Reboot(_) => {
                drive.set_silent(false);
                (
                    format!("node {node}: rebooted (boot-up, pre-operational)"),
                    drive.power_on(now_ns),
                )
            }
            Control::Mains { on, .. } => {
                drive.set_mains(on);
                let on = if on { "on" } else { "off" };
                (format!("node {node}: mains {on}"), Vec::new())
            }
            Control::Status => (String::new(), Vec::new()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::drive::Drive;
    use crate::sim::profile::DriveProfile;

    fn apply(sim: &mut Simulation, line: &str) -> (String, Vec<Frame>) {
        match Control::parse(line) {
            Ok(c) => c.apply(sim, 0),
            Err(e) => (e.to_string(), Vec::new()),
        }
    }

    #[test]
    fn control_lines_fail_silence_and_reboot_nodes() {
        let mut sim = Simulation::new(vec![Drive::new(2, DriveProfile::aimotor_like())], 0);
        let sim = &mut sim;
        assert_eq!(
            apply(sim, "silence 2").0,
            "node 2: silenced (sends and answers nothing)"
        );
        assert!(sim.drive(2).unwrap().is_silent());
        let (text, frames) = apply(sim, "reboot 2");
        assert_eq!(text, "node 2: rebooted (boot-up, pre-operational)");
        assert_eq!((frames[0].id, frames[0].payload()), (0x702, &[0u8][..]));
        assert_eq!(
            apply(sim, "fault 2 0x2310").0,
            "node 2: fault 0x2310 (EMCY, then Fault)"
        );
        assert_eq!(apply(sim, "fault 9 1").0, "no simulated node 9");
        assert_eq!(
            apply(sim, "fault 2 0x12345").0,
            "fault: `0x12345` is not a 16-bit error code"
        );
        assert_eq!(apply(sim, "reboot 200").0, "`200` is not a node-ID (1..127)");
        assert!(apply(sim, "fault 2").0.starts_with("usage: fault NODE CODE |"));
        assert_eq!(apply(sim, "mains 2 off").0, "node 2: mains off");
        assert!(apply(sim, "status").0.starts_with("node 2: PreOperational"));
    }
}
