//! The words of an incident: title, "check first" steps and why it matters, written for a
//! technician at the machine rather than a protocol expert. One row of [`WORDS`] per kind
//! of incident: fixed words as data, the few made from what the incident holds as small
//! functions.

use crate::analysis::incident::{Incident, Problem, Status};
use crate::sdo::abort::{AbortClass, abort_class};
use std::collections::BTreeSet;

/// What the bus showed of an SDO incident's aborts (kept by the diagnosis per incident).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(super) struct SdoAborts {
    /// The distinct abort codes, first seen first.
    pub(super) codes: Vec<u32>,
    /// The entries not present (index, sub-index), of a not-present incident only.
    pub(super) entries: BTreeSet<(u16, u8)>,
    /// Some were reads (uploads).
    pub(super) reads: bool,
    /// Some were writes (downloads).
    pub(super) writes: bool,
}

/// The words of a refused SDO transfer by the class of its abort codes: the title and why
/// for a read, a write, and an object both read and written (in that order), and the steps
/// to check first.
struct AbortWords {
    class: AbortClass,
    title: [&'static str; 3],
    why: [&'static str; 3],
    check: &'static [&'static str],
}

/// One row per class; a class not listed takes the last row's words.
const ABORT_WORDS: &[AbortWords] = &[
    AbortWords {
        class: AbortClass::Protocol,
        title: [
            "The transfer broke: a value was not read",
            "The transfer broke: a setting was not written",
            "The transfer broke: reads and writes of this object failed",
        ],
        why: [
            "The transfer did not finish: the master does not have the value, and a retry may break the same way.",
            "The transfer did not finish: the setting was not written, and a retry may break the same way.",
            "The transfers did not finish: values were neither read nor written, and retries may break the same way.",
        ],
        check: &[
            "Look for a second SDO client on this node's channel (0x600 + node): another tool or master talking to the node at the same time breaks the transfer.",
            "Check the timing: the client's SDO timeout against the time the device takes to answer, and segments or blocks sent no faster than the device takes them.",
            "Check the bus at that moment for error frames and lost frames (wiring, termination, bus load): a lost segment breaks the transfer.",
        ],
    },
    AbortWords {
        class: AbortClass::Refused,
        title: [
            "A value could not be read",
            "A setting was not applied",
            "Reads and writes of this object were refused",
        ],
        why: [
            "The master does not know this value.",
            "The device keeps running with its old or default value.",
            "The master does not know this value, and the device keeps its old or default one.",
        ],
        check: &[
            "Compare index, sub-index, data size and access rights with the device manual or EDS.",
            "Check that the node is in the right state for this object (some are writable only when disabled).",
            "Fix the master's configuration that sends it, then record a new capture.",
        ],
    },
];

/// The words for `aborts`: a transfer that broke when any code is a protocol abort, else
/// a refusal (read, write or both).
fn abort_class_words(aborts: &SdoAborts) -> (&'static AbortWords, usize) {
    let class = if aborts.codes.iter().any(|c| abort_class(*c) == AbortClass::Protocol) {
        AbortClass::Protocol
    } else {
        AbortClass::Refused
    };
    let words = ABORT_WORDS
        .iter()
        .find(|w| w.class == class)
        .unwrap_or(&ABORT_WORDS[ABORT_WORDS.len() - 1]);
    let which = match (aborts.reads, aborts.writes) {
        (true, true) => 2,
        (false, true) => 1,
        _ => 0,
    };
    (words, which)
}

/// What the diagnosis knows of an incident beyond the incident itself.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Facts<'a> {
    /// A drive fault's fault resets.
    pub(super) resets: u32,
    /// A drive fault's EMCY code (its cause).
    pub(super) emcy: Option<u16>,
    /// The capture's CAN error frames.
    pub(super) error_frames: u64,
    /// The aborts of an SDO incident.
    pub(super) sdo: Option<&'a SdoAborts>,
}

/// A line of words: fixed, or made from the incident.
enum Text {
    /// Words as they are; `{node}` stands for the node-ID.
    Fixed(&'static str),
    /// For one occurrence, for more (`{n}` stands for the count).
    Counted(&'static str, &'static str),
    /// Made from the incident and its facts.
    Made(fn(&Incident, &Facts) -> String),
}

/// The "check first" steps: fixed, or made from the incident.
enum Steps {
    /// Steps as they are; `{node}` stands for the node-ID.
    Fixed(&'static [&'static str]),
    /// Made from the incident and its facts.
    Made(fn(&Incident, &Facts) -> Vec<String>),
}

/// The words of one kind of incident.
struct Words {
    problem: Problem,
    /// The row is only for incidents with a cause (a row for any follows).
    with_cause: bool,
    /// None: the detector that found it wrote the title (which PDO, the figures).
    title: Option<Text>,
    check: Steps,
    why: Text,
}

/// The words of every kind of incident, in the order of [`Problem`].
const WORDS: &[Words] = &[
    Words {
        problem: Problem::Missing,
        with_cause: false,
        title: Some(Text::Fixed("No answer: the device seems to be missing")),
        check: Steps::Fixed(&[
            "Check that the device really has node-ID {node} (switches or its configuration tool).",
            "Check the node's power, CAN connector and bit rate.",
            "Nothing at all came from this node (no heartbeat, no answer): it is not on the bus.",
        ]),
        why: Text::Fixed(
            "The node is off or unreachable, and the master cannot know whether its settings took effect.",
        ),
    },
    Words {
        problem: Problem::Silent,
        with_cause: true,
        title: Some(Text::Fixed(
            "Heartbeat stopped for good, while the node still sends other messages",
        )),
        check: Steps::Fixed(&[
            "Check whether the master wrote 0x1017 (heartbeat time) or reset it to 0.",
            "The node's heartbeat task may have hung while the rest runs: check its firmware and error log.",
            "The master's heartbeat consumer will soon report the node as lost.",
        ]),
        why: Text::Fixed(
            "The master judges the node by its heartbeat: it may stop the machine although the node runs.",
        ),
    },
    Words {
        problem: Problem::Silent,
        with_cause: false,
        title: Some(Text::Fixed("Went silent and never came back")),
        check: Steps::Fixed(&[
            "Check the node's power and status LEDs.",
            "Check that the CAN connector and cable are not loose or broken.",
            "If the node was resetting, a boot-up message should follow: record a longer capture.",
        ]),
        why: Text::Fixed("The node looks switched off, hung, or disconnected from the bus."),
    },
    Words {
        problem: Problem::SilentBack,
        with_cause: false,
        title: Some(Text::Counted(
            "Went silent for a while, then came back",
            "Went silent {n} times, came back each time",
        )),
        check: Steps::Fixed(&[
            "Look for CAN error frames at the same time: if there are any, suspect wiring or termination.",
            "Check whether moving the connector reproduces it, and whether the cable runs through moving parts.",
            "Some firmware stops its heartbeat while busy (e.g. writing flash).",
        ]),
        why: Text::Fixed("Even a short silence can make the master think the node is gone and stop the machine."),
    },
    Words {
        problem: Problem::Rebooted,
        with_cause: false,
        title: Some(Text::Counted(
            "Restarted without being told to",
            "Restarted {n} times without being told to",
        )),
        check: Steps::Fixed(&[
            "Check the node's supply voltage for dips (brake release, motor start).",
            "Check the node's watchdog and error log: a firmware crash restarts it.",
            "Check for loose power connectors.",
        ]),
        why: Text::Fixed("A restarted node forgets what the master configured and starts again in pre-operational."),
    },
    Words {
        problem: Problem::SdoRefused,
        with_cause: false,
        title: Some(Text::Made(|inc, f| {
            let (words, which) = abort_words(inc, f);
            let mut title = words.title[which].to_string();
            if inc.status == Status::Recovered {
                title.push_str(" (a later try worked)");
            }
            title
        })),
        check: Steps::Made(|inc, f| strings(abort_words(inc, f).0.check)),
        why: Text::Made(|inc, f| {
            let (words, which) = abort_words(inc, f);
            words.why[which].into()
        }),
    },
    Words {
        problem: Problem::SdoGarbled,
        with_cause: false,
        title: Some(Text::Counted(
            "Sent SDO frames that make no sense (1)",
            "Sent SDO frames that make no sense ({n})",
        )),
        check: Steps::Fixed(&[
            "Update or report the node's firmware: its SDO server answers outside the protocol.",
            "Check that no second device answers on node-ID {node}.",
            "Check the transfer the master was doing at that moment (object, size) against the manual.",
        ]),
        why: Text::Fixed("The transfer fails or, worse, writes wrong data; the master may retry or give up."),
    },
    Words {
        problem: Problem::Unmonitored,
        with_cause: false,
        title: Some(Text::Fixed("Not monitored: heartbeat is off and no node guarding")),
        check: Steps::Fixed(&[
            "Set the heartbeat producer time 0x1017 (e.g. 100 ms) in the master's configuration.",
            "Or enable node guarding (0x100C/0x100D) if the master uses it.",
        ]),
        why: Text::Fixed("If this node fails or is unplugged, nothing on the bus tells the master."),
    },
    Words {
        problem: Problem::SdoTimeout,
        with_cause: false,
        title: Some(Text::Counted(
            "1 SDO request not answered",
            "{n} SDO requests not answered",
        )),
        check: Steps::Fixed(&[
            "Check that the request goes to the right node-ID and SDO channel.",
            "Check the bus load and whether the node is busy (some firmware answers late while writing flash).",
            "Check the master's SDO timeout against the device manual.",
        ]),
        why: Text::Fixed("The master cannot tell whether the setting took effect."),
    },
    Words {
        problem: Problem::DriveFault,
        with_cause: false,
        title: Some(Text::Made(drive_fault_title)),
        check: Steps::Made(drive_fault_check),
        why: Text::Fixed(
            "A faulted drive switches the motor torque off and ignores motion commands until the fault is reset.",
        ),
    },
    Words {
        problem: Problem::Emcy,
        with_cause: false,
        title: Some(Text::Made(|inc, _| {
            let text = inc.cause.clone().unwrap_or_default();
            let mut title = match inc.status {
                Status::Recovered => format!("Reported an error: {text}, later reset"),
                _ => format!("Reported an error: {text}"),
            };
            if inc.count > 1 {
                title.push_str(&format!(" ({} times)", inc.count));
            }
            title
        })),
        check: Steps::Fixed(&[
            "Look up the EMCY code in the device manual's error table.",
            "Read the node's error register 0x1001 and error history 0x1003.",
            "A flood of EMCY from one node can also be a faulty device or a node-ID clash.",
        ]),
        why: Text::Fixed("The node says something is wrong; it may stop or behave differently until it is fixed."),
    },
    Words {
        problem: Problem::BusErrors,
        with_cause: false,
        title: Some(Text::Made(|inc, f| {
            // The worst state the controller reached, not the last: bus off followed by an
            // error counter line back in error passive still went bus off.
            let said = |state: &str| inc.events.iter().any(|e| e.text.contains(state));
            let worst = ["bus off", "error passive"].into_iter().find(|w| said(w));
            match worst {
                Some(w) => format!(
                    "{} (the controller went {w})",
                    plural(f.error_frames, "CAN error frame")
                ),
                None => plural(f.error_frames, "CAN error frame"),
            }
        })),
        check: Steps::Fixed(&[
            "Check for exactly one 120 Ω terminator at each end (about 60 Ω between CAN_H and CAN_L, power off).",
            "Check that every node uses the same bit rate.",
            "Check CAN_GND, cable length and the distance from motor power cables.",
        ]),
        why: Text::Fixed(
            "Bus errors cause retransmissions or lost messages, seen as heartbeat gaps or SDO failures; bus off stops sending altogether.",
        ),
    },
    Words {
        problem: Problem::DuplicateId,
        with_cause: false,
        title: Some(Text::Fixed("Two devices seem to use the same node-ID")),
        check: Steps::Fixed(&[
            "Check the node-ID switches or settings of every device: two have {node}.",
            "Disconnect devices one by one and watch which boot-ups or heartbeats remain.",
        ]),
        why: Text::Fixed("Two devices on one ID answer each other's requests and collide on the bus."),
    },
    Words {
        problem: Problem::NmtIgnored,
        with_cause: false,
        title: Some(Text::Made(|inc, _| {
            match inc.status {
                Status::Open => "Did not follow an NMT command",
                _ => "Followed an NMT command late",
            }
            .into()
        })),
        check: Steps::Fixed(&[
            "Check that the command addresses the right node-ID.",
            "Check the node's error state: some devices refuse to start while they have an error.",
            "Check the device manual for conditions on NMT start (e.g. a required parameter set).",
        ]),
        why: Text::Fixed(
            "The master thinks the node is in one state while it is in another: PDOs may not be sent or used.",
        ),
    },
    Words {
        problem: Problem::DriveStuck,
        with_cause: false,
        title: None,
        check: Steps::Fixed(&[
            "Do what the cause says first: a fault needs a fault reset; \"voltage not enabled\" needs the drive's main power (DC link); a quick stop needs disable voltage (0x00) before 0x06 → 0x07 → 0x0F.",
            "Check the enable sequence the master sends: 0x06 → 0x07 → 0x0F, each only after the statusword shows the state before.",
            "Check the drive's enable inputs (STO, hardware enable) and its display or error log.",
        ]),
        why: Text::Fixed(
            "The master waits for a state the drive does not reach: the axis does not move and motion commands are ignored.",
        ),
    },
    Words {
        problem: Problem::PdoMissing,
        with_cause: false,
        title: None,
        check: Steps::Fixed(&[
            "Check the node's NMT state: PDOs are sent in operational only.",
            "Check the PDO's transmission type and event time (0x1800/0x1400 sub 2 and 5) and, for synchronous PDOs, that SYNC kept coming.",
            "Look for bus errors or a busy bus at the same time: a PDO with a low priority waits behind others.",
        ]),
        why: Text::Fixed(
            "The master or the drive works on stale values while the PDO is missing; a drive may stop on its RPDO timeout.",
        ),
    },
    Words {
        problem: Problem::SyncJitter,
        with_cause: false,
        title: None,
        check: Steps::Fixed(&[
            "Check the SYNC producer: a PC master without real-time scheduling sends SYNC late under load.",
            "Check the bus load: frames in the way delay even the high-priority SYNC.",
            "Check the drives' SYNC-loss and following-error settings if they run cyclic synchronous modes.",
        ]),
        why: Text::Fixed(
            "Drives in cyclic synchronous modes (CSP, CSV) move in steps of one SYNC: an uneven SYNC makes the motion rough or trips a following error.",
        ),
    },
    Words {
        problem: Problem::SecondMaster,
        with_cause: false,
        title: Some(Text::Counted(
            "Commands from two masters at once",
            "Commands from two masters at once ({n} times)",
        )),
        check: Steps::Fixed(&[
            "Look for a second device or tool acting as master: a PLC and a PC tool, a configuration tool left connected, a second controller.",
            "Only one SDO client may use a node's default SDO channel (0x600 + node) at a time: stop the other one or give it its own SDO channel (0x1280).",
            "Only one master should start and stop nodes (NMT): check the NMT start-up settings of each.",
        ]),
        why: Text::Fixed(
            "Two masters undo each other's settings and states: commands seem to be ignored or reversed at random.",
        ),
    },
    Words {
        problem: Problem::PdoLate,
        with_cause: false,
        title: None,
        check: Steps::Fixed(&[
            "Check the node's load and its synchronous window setting 0x1007 against its PDO processing time.",
            "Check the bus load right after SYNC: many synchronous PDOs queue behind each other; spread them or raise the bit rate.",
            "Check that the window (0x1007) fits inside the SYNC period (0x1006).",
        ]),
        why: Text::Fixed(
            "A PDO sent after the window is not taken in this cycle: the master or the drive works on values one cycle old.",
        ),
    },
    Words {
        problem: Problem::BootConfig,
        with_cause: false,
        title: None,
        check: Steps::Fixed(&[
            "Compare the master's configuration for node {node} between the boots: a changed file, a parameter read from another source, or a step skipped after an error.",
            "For a refused or unanswered write, check the object (index, sub-index, size, access) against the device's EDS and the node's state at that moment.",
            "Against a DCF: check that the DCF given is the one the master uses for this node.",
        ]),
        why: Text::Fixed(
            "The node runs with another configuration than before (or than planned): PDOs, heartbeat or limits may differ without any error shown.",
        ),
    },
    Words {
        problem: Problem::NotPresent,
        with_cause: false,
        title: Some(Text::Made(|inc, f| {
            let n = f.sdo.map_or(inc.count, |a| a.entries.len() as u64);
            if n == 1 {
                "1 object not present (read from here)".into()
            } else {
                format!("{n} objects not present (read from here)")
            }
        })),
        check: Steps::Fixed(&[
            "Nothing to fix on the bus: the device does not have these entries, although the dictionary used (EDS or profile) lists them.",
            "If the device should have one of them, compare its firmware version and EDS with the device manual.",
        ]),
        why: Text::Fixed("Only worth knowing: reading an entry the device lacks changes nothing on the device."),
    },
];

/// The words of a refused SDO transfer (`inc`): by its aborts, or (none kept) by whether
/// its first step was a write.
fn abort_words(inc: &Incident, f: &Facts) -> (&'static AbortWords, usize) {
    match f.sdo {
        Some(a) => abort_class_words(a),
        None => abort_class_words(&SdoAborts {
            writes: inc.events.first().is_some_and(|e| e.text.starts_with("Write")),
            ..SdoAborts::default()
        }),
    }
}

fn drive_fault_title(inc: &Incident, f: &Facts) -> String {
    let cause = match (&inc.cause, f.emcy) {
        (Some(c), Some(_)) => lower_first(c.split(" (EMCY").next().unwrap_or(c)),
        (Some(c), None) => lower_first(c),
        (None, _) if inc.axes.len() > 1 => "all axes stopped together (no cause reported)".into(),
        (None, _) => "a fault (no cause reported)".into(),
    };
    let resets = f.resets;
    let failed = resets.saturating_sub(1);
    match inc.status {
        Status::Recovered if resets > 1 => format!(
            "Stopped: {cause} → recovered on reset #{resets} ({})",
            plural(u64::from(failed), "failed reset")
        ),
        Status::Recovered if resets == 1 => format!("Stopped: {cause} → recovered after a reset"),
        Status::Recovered => format!("Stopped: {cause} → recovered"),
        _ if resets > 0 => format!(
            "Stopped: {cause}; still in fault at the end ({} did not work)",
            plural(u64::from(resets), "fault reset")
        ),
        _ => format!("Stopped: {cause}; still in fault at the end"),
    }
}

fn drive_fault_check(inc: &Incident, f: &Facts) -> Vec<String> {
    let mut check = Vec::new();
    match f.emcy {
        Some(c) => check.push(format!("Look up EMCY 0x{c:04X} in the drive manual's error table.")),
        None if inc.axes.len() > 1 => {
            check.push("Check what stops the whole device: E-stop, STO (safe torque off), power.".into())
        }
        None => check.push("The drive sent no EMCY: check its display or error log.".into()),
    }
    let axis = inc.axes.first().copied().unwrap_or(1);
    check.push(format!(
        "Read the drive's error code 0x{:04X} for the exact cause.",
        0x603F + 0x800 * (u16::from(axis) - 1)
    ));
    check.push("Remove the cause, then reset the fault: controlword 0x80, then 0x06 → 0x07 → 0x0F.".into());
    check
}

fn plural(n: u64, one: &str) -> String {
    if n == 1 {
        format!("1 {one}")
    } else {
        format!("{n} {one}s")
    }
}

fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_lowercase().chain(c).collect(),
        None => String::new(),
    }
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

impl Text {
    fn say(&self, inc: &Incident, f: &Facts, node: &str) -> String {
        match self {
            Text::Fixed(s) => s.replace("{node}", node),
            Text::Counted(one, _) if inc.count == 1 => one.to_string(),
            Text::Counted(_, many) => many.replace("{n}", &inc.count.to_string()),
            Text::Made(make) => make(inc, f),
        }
    }
}

/// Sets `inc`'s title (unless its detector wrote it), check steps and why, from its row
/// of [`WORDS`].
pub(super) fn fill(inc: &mut Incident, facts: &Facts) {
    let Some(words) = WORDS
        .iter()
        .find(|w| w.problem == inc.problem && (!w.with_cause || inc.cause.is_some()))
    else {
        return;
    };
    let node = inc.node.map_or(String::new(), |n| n.to_string());
    if let Some(title) = &words.title {
        inc.title = title.say(inc, facts, &node);
    }
    inc.check = match &words.check {
        Steps::Fixed(steps) => steps.iter().map(|s| s.replace("{node}", &node)).collect(),
        Steps::Made(make) => make(inc, facts),
    };
    inc.why = words.why.say(inc, facts, &node);
}

#[cfg(test)]
mod tests {
    use super::super::timeline::Timeline;
    use super::*;
    use crate::frame::NodeKey;

    #[test]
    fn every_kind_has_its_words_with_the_node_and_count_filled_in() {
        for p in Problem::ALL {
            let mut tl = Timeline::default();
            let i = tl.open(Some(NodeKey::new(0, 5)), p, 0);
            let mut inc = tl.incidents[i].clone();
            inc.count = 3;
            fill(&mut inc, &Facts::default());
            assert!(!inc.check.is_empty() && !inc.why.is_empty(), "{p:?}: {inc:?}");
            let words = [inc.title.as_str(), inc.why.as_str()]
                .into_iter()
                .chain(inc.check.iter().map(String::as_str));
            for w in words {
                assert!(!w.contains('{'), "{p:?}: placeholder left in {w:?}");
            }
            let builder = [
                Problem::DriveStuck,
                Problem::PdoMissing,
                Problem::SyncJitter,
                Problem::PdoLate,
                Problem::BootConfig,
            ];
            assert_eq!(
                inc.title.is_empty(),
                builder.contains(&p),
                "{p:?}: title {:?}",
                inc.title
            );
        }
        let mut tl = Timeline::default();
        let i = tl.open(Some(NodeKey::new(0, 5)), Problem::DuplicateId, 0);
        fill(&mut tl.incidents[i], &Facts::default());
        assert_eq!(
            tl.incidents[i].check[0],
            "Check the node-ID switches or settings of every device: two have 5."
        );
        let i = tl.open(Some(NodeKey::new(0, 5)), Problem::SecondMaster, 0);
        tl.incidents[i].count = 4;
        fill(&mut tl.incidents[i], &Facts::default());
        assert_eq!(tl.incidents[i].title, "Commands from two masters at once (4 times)");
    }
}
