//! Boot configuration detector: builds each node's boot stories (boot-ups and NMT resets,
//! the SDO downloads and NMT commands up to Operational) and, at the end of the capture,
//! compares each boot with the node's first complete one and with the expected
//! configuration; a boot that differs is a `boot_config` incident whose steps are its
//! findings (the comparisons: `crate::analysis::boot_story`).

use super::detector::Detector;
use super::timeline::{At, MS, Timeline};
use crate::analysis::boot_story::{
    Against, Boot, BootStep, Bytes, Expected, FindingKind, Operational, Write, WriteResult, against_expected,
    against_reference,
};
use crate::analysis::incident::{Problem, Status};
use crate::frame::NodeKey;
use crate::sdo::transaction::{Outcome, Transaction, TransferDirection};
use std::collections::{BTreeMap, BTreeSet};

/// A boot-up this soon after an NMT reset answers it (the same boot).
const RESET_BOOT_NS: u64 = 5_000 * MS;
/// Boots kept per node: a node's later boots are not told (memory stays bounded).
const MAX_BOOTS: usize = 200;
/// Steps kept per boot (real boots write a few hundred objects at most).
const MAX_STEPS: usize = 2_000;

/// The boot stories of a capture and the expected configurations.
#[derive(Clone, Default)]
pub(super) struct BootConfigs {
    stories: BTreeMap<NodeKey, Vec<Boot>>,
    /// The last NMT reset to all nodes per interface: when and which.
    reset_all: BTreeMap<u16, (At, &'static str)>,
    /// Expected values by node-ID (any interface).
    expected: BTreeMap<u8, Vec<Expected>>,
    /// Nodes that booted more than [`MAX_BOOTS`] times: nothing more is told of them.
    full: BTreeSet<NodeKey>,
    /// Nodes whose last boot has not reached Operational yet.
    awaiting: BTreeSet<NodeKey>,
}

/// The boot still going on (not Operational yet) with room for one more step, if any.
fn open_boot(boots: &mut [Boot]) -> Option<&mut Boot> {
    boots
        .last_mut()
        .filter(|b| b.operational.is_none() && b.steps.len() < MAX_STEPS)
}

impl BootConfigs {
    /// Node `node` (on any interface) should be configured with `values`.
    pub(super) fn expect(&mut self, node: u8, values: Vec<Expected>) {
        self.expected.insert(node, values);
    }

    /// No node has an expected configuration any more.
    pub(super) fn expect_nothing(&mut self) {
        self.expected.clear();
    }

    /// The nodes with an expected configuration.
    pub(super) fn expected_nodes(&self) -> Vec<u8> {
        self.expected.keys().copied().collect()
    }

    /// A new boot of `n` beginning at `at` with `first`.
    fn begin(&mut self, n: NodeKey, at: At, first: BootStep) {
        let boots = self.stories.entry(n).or_default();
        if boots.len() >= MAX_BOOTS {
            self.full.insert(n);
            self.awaiting.remove(&n);
            return;
        }
        self.awaiting.insert(n);
        boots.push(Boot {
            node: n,
            number: boots.len() as u32 + 1,
            frame: at.frame,
            t_ns: at.t,
            operational: None,
            steps: vec![first],
            reference: None,
            findings: Vec::new(),
        });
    }

    /// The boot-up message of `n` (the frame being read).
    pub(super) fn boot_up(&mut self, tl: &Timeline, n: NodeKey) {
        if self.full.contains(&n) {
            return;
        }
        let at = tl.at;
        let step = BootStep::BootUp {
            frame: at.frame,
            t_ns: at.t,
        };
        // The answer to the NMT reset that began the boot going on.
        if let Some(b) = self.stories.get_mut(&n).and_then(|b| open_boot(b))
            && matches!(b.steps.as_slice(), [BootStep::Nmt { .. }])
            && at.t.saturating_sub(b.t_ns) <= RESET_BOOT_NS
        {
            b.steps.push(step);
            return;
        }
        // A node first heard after a reset of all nodes: its boot began with that reset.
        let since = self.stories.get(&n).and_then(|b| b.last()).map(|b| b.frame);
        if let Some((reset, command)) = self.reset_all.get(&n.iface).copied()
            && since.is_none_or(|f| f < reset.frame)
            && at.t.saturating_sub(reset.t) <= RESET_BOOT_NS
        {
            let nmt = BootStep::Nmt {
                frame: reset.frame,
                t_ns: reset.t,
                command,
                all: true,
            };
            self.begin(n, reset, nmt);
            // (Not when the node has no room for a new boot: nothing more is told of it.)
            if let Some(b) = self
                .stories
                .get_mut(&n)
                .filter(|_| !self.full.contains(&n))
                .and_then(|b| open_boot(b))
            {
                b.steps.push(step);
            }
            return;
        }
        self.begin(n, at, step);
    }

    /// NMT `command` to `target` (0: all nodes) on the current interface; `reset`: it
    /// restarts the node (a new boot).
    pub(super) fn command(&mut self, tl: &Timeline, command: &'static str, target: u8, reset: bool) {
        let (at, iface) = (tl.at, tl.iface);
        let nodes: Vec<NodeKey> = match target {
            0 => self.stories.keys().filter(|k| k.iface == iface).copied().collect(),
            t => vec![NodeKey::new(iface, t)],
        };
        let step = BootStep::Nmt {
            frame: at.frame,
            t_ns: at.t,
            command,
            all: target == 0,
        };
        if reset && target == 0 {
            self.reset_all.insert(iface, (at, command));
        }
        for n in nodes {
            if self.full.contains(&n) {
                continue;
            }
            if reset {
                self.begin(n, at, step.clone());
            } else if let Some(b) = self.stories.get_mut(&n).and_then(|b| open_boot(b)) {
                b.steps.push(step.clone());
            }
        }
    }

    /// `n` showed it is Operational (`by`: heartbeat or TPDO): its boot is complete.
    pub(super) fn operational(&mut self, tl: &Timeline, n: NodeKey, by: &'static str) {
        // Every heartbeat and TPDO comes here: once all boots are complete, nothing to do.
        if self.awaiting.is_empty() || !self.awaiting.remove(&n) {
            return;
        }
        if let Some(b) = self
            .stories
            .get_mut(&n)
            .and_then(|b| b.last_mut())
            .filter(|b| b.operational.is_none())
        {
            b.operational = Some(Operational {
                frame: tl.at.frame,
                t_ns: tl.at.t,
                by,
            });
        }
    }

    /// Compares every boot, keeps the findings in the stories and opens one incident per
    /// boot with findings.
    fn compare(&mut self, tl: &mut Timeline) {
        for (n, boots) in &mut self.stories {
            let reference = boots.iter().find(|b| b.operational.is_some()).cloned();
            let expected = self.expected.get(&n.node);
            for b in boots.iter_mut() {
                let mut findings = Vec::new();
                if let Some(r) = reference.as_ref().filter(|r| r.number != b.number) {
                    b.reference = Some(r.number);
                    findings = against_reference(b, r);
                }
                if let Some(e) = expected {
                    findings.extend(against_expected(b, e));
                }
                b.findings = findings;
                if !b.findings.is_empty() {
                    incident(tl, b);
                }
            }
        }
    }

    /// The stories with their findings, by node and boot (after [`Detector::end`]).
    pub(super) fn stories(&self) -> Vec<Boot> {
        self.stories.values().flatten().cloned().collect()
    }
}

impl Detector for BootConfigs {
    /// A download to a node during one of its boots is a configuration write.
    fn transaction(&mut self, tl: &mut Timeline, t: &Transaction) {
        if t.direction != TransferDirection::Download || self.full.contains(&t.key()) {
            return;
        }
        let Some(b) = self.stories.get_mut(&t.key()).and_then(|b| b.last_mut()) else {
            return;
        };
        if b.steps.len() >= MAX_STEPS {
            return;
        }
        // A transfer that ended later (left unanswered) belongs to the boot it began in.
        if t.start_ns < b.t_ns || b.operational.is_some_and(|op| t.start_ns > op.t_ns) {
            return;
        }
        let result = match &t.outcome {
            Outcome::Ok => WriteResult::Ok,
            Outcome::Aborted { text, .. } => WriteResult::Refused(text.to_string()),
            Outcome::Incomplete => WriteResult::Unanswered,
            Outcome::ProtocolError(e) if e.contains("new request") => WriteResult::Unanswered,
            Outcome::ProtocolError(e) => WriteResult::Refused(e.clone()),
        };
        // The request's frame (an unanswered one ends at the end of the capture).
        let frame = t.frames.first().copied().unwrap_or(tl.at.frame);
        let at = b.steps.iter().position(|s| s.frame() > frame).unwrap_or(b.steps.len());
        b.steps.insert(
            at,
            BootStep::Write(Write {
                frame,
                t_ns: t.start_ns,
                index: t.index,
                sub: t.sub,
                data: Bytes::of(&t.data),
                result,
            }),
        );
    }

    fn end(&mut self, tl: &mut Timeline, _end: At) {
        self.compare(tl);
    }
}

/// The `boot_config` incident of boot `b`: its findings as steps.
fn incident(tl: &mut Timeline, b: &Boot) {
    let i = tl.open(Some(b.node), Problem::BootConfig, b.t_ns);
    tl.incidents[i].count = 1;
    tl.incidents[i].status = Status::Open;
    tl.incidents[i].title = title(b);
    tl.step(
        i,
        At {
            frame: b.frame,
            t: b.t_ns,
        },
        format!("Boot {} began", b.number),
    );
    let at_end = b.operational.map_or(
        At {
            frame: b.frame,
            t: b.t_ns,
        },
        |op| At {
            frame: op.frame,
            t: op.t_ns,
        },
    );
    for f in &b.findings {
        let at = f.at.map_or(at_end, |(frame, t)| At { frame, t });
        tl.step(i, at, f.text());
    }
    tl.incidents[i].findings = b.findings.clone();
}

/// `Boot 2 configured otherwise than boot 1 (1 different, 1 missing)`.
fn title(b: &Boot) -> String {
    let reference = b.findings.iter().find_map(|f| match f.against {
        Against::Reference(n) => Some(n),
        Against::Expected => None,
    });
    let dcf = b.findings.iter().any(|f| f.against == Against::Expected);
    let than = match (reference, dcf) {
        (Some(n), true) => format!("boot {n} and the DCF"),
        (Some(n), false) => format!("boot {n}"),
        _ => "the DCF".to_string(),
    };
    let kinds = [
        FindingKind::Different,
        FindingKind::Missing,
        FindingKind::Extra,
        FindingKind::Refused,
        FindingKind::Unanswered,
    ];
    let counts: Vec<String> = kinds
        .iter()
        .filter_map(|k| {
            let n = b.findings.iter().filter(|f| f.kind == *k).count();
            (n > 0).then(|| format!("{n} {}", k.as_str()))
        })
        .collect();
    format!(
        "Boot {} configured otherwise than {than} ({})",
        b.number,
        counts.join(", ")
    )
}
