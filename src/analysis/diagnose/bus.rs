//! Bus detector (`bus_errors`): CAN error frames and the controller states (error
//! passive, bus off) the source reports.

use super::detector::Detector;
use super::timeline::{At, Timeline};
use crate::analysis::incident::{Problem, Status};
use std::collections::BTreeMap;

/// Finds bus errors.
#[derive(Clone, Default)]
pub(super) struct Bus {
    /// CAN error frames so far.
    pub(super) error_frames: u64,
    /// Each interface's last controller state.
    state: BTreeMap<String, &'static str>,
}

impl Bus {
    /// A CAN error frame (`label`: its decoding).
    pub(super) fn error_frame(&mut self, tl: &mut Timeline, label: &str) {
        self.error_frames += 1;
        let at = tl.at;
        let i = tl.grouped(None, Problem::BusErrors, 0, at.t);
        if tl.incidents[i].count == 1 {
            tl.incidents[i].cause = Some(label.to_string());
            tl.step(i, at, format!("CAN bus errors detected: {label}"));
        }
    }

    /// The controller of `iface` went `to` at `t_ns` (`detail`: what the source says).
    pub(super) fn state(&mut self, tl: &mut Timeline, iface: &str, to: &'static str, detail: &str, t_ns: u64) {
        self.state.insert(iface.to_string(), to);
        let i = tl.grouped(None, Problem::BusErrors, 0, t_ns);
        tl.incidents[i].count -= 1;
        let at = At {
            frame: tl.at.frame,
            t: t_ns,
        };
        tl.step(
            i,
            at,
            format!("{iface}: controller now {} ({detail})", to.replace('_', " ")),
        );
    }
}

impl Detector for Bus {
    fn end(&mut self, tl: &mut Timeline, end: At) {
        if self.error_frames == 0 && self.state.is_empty() {
            return;
        }
        let i = tl.grouped(None, Problem::BusErrors, 0, end.t);
        let inc = &mut tl.incidents[i];
        inc.count = self.error_frames;
        let worst = self
            .state
            .values()
            .copied()
            .find(|s| *s == "bus_off")
            .or_else(|| self.state.values().copied().find(|s| *s == "error_passive"));
        inc.status = if worst.is_some() { Status::Open } else { Status::Warning };
        inc.last_ns = inc.last_ns.min(end.t).max(inc.first_ns);
    }
}
