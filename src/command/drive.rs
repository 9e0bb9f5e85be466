//! CiA 402 drive sequences: the pure plan (which controlwords, which states prove
//! each step), the pure diagnosis of a step that did not happen, and the IO that
//! runs them over SDO, watching heartbeats, EMCY and a statusword TPDO on the way.

use super::error::CommandError;
use super::grammar::{DEFAULT_TIMEOUT_MS, parse_mode};
use super::sdo::{download, upload};
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::{DRIVE_WORDS, ParseError, TypedWords, ms_arg, node_arg};
use crate::bus::{Bus, Subscription};
use crate::cob;
use crate::decode::cia402::{DriveState, mode_name};
use crate::decode::heartbeat::NmtState;
use crate::frame::Direction;
use std::time::Duration;

pub use crate::decode::stall::{Observation, Step, diagnose};

/// A CiA 402 drive command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriveAction {
    Enable,
    Disable,
    QuickStop,
    FaultReset,
    Status,
    /// Set the mode of operation (0x6060) and wait for 0x6061 to show it.
    Mode(i8),
}

impl DriveAction {
    /// Parses an action word: `enable|disable|quick-stop|fault-reset|status`, or `mode`
    /// (its MODE follows).
    pub fn parse_verb(word: &str) -> Result<DriveVerb, ParseError> {
        Ok(DriveVerb::Action(match word {
            "enable" => DriveAction::Enable,
            "disable" => DriveAction::Disable,
            "quick-stop" | "quickstop" => DriveAction::QuickStop,
            "fault-reset" => DriveAction::FaultReset,
            "status" => DriveAction::Status,
            "mode" => return Ok(DriveVerb::Mode),
            _ => {
                return Err(ParseError::Invalid(format!(
                    "unknown drive command `{word}`: use enable, disable, quick-stop, fault-reset, status or mode MODE"
                )));
            }
        }))
    }
    /// The word used on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            DriveAction::Enable => "enable",
            DriveAction::Disable => "disable",
            DriveAction::QuickStop => "quick-stop",
            DriveAction::FaultReset => "fault-reset",
            DriveAction::Status => "status",
            DriveAction::Mode(_) => "mode",
        }
    }
}

/// The ACTION word of `drive`: an action, or `mode` (its MODE follows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriveVerb {
    Action(DriveAction),
    Mode,
}

/// The MODE word of `drive`, with its mode (or why it is none): whether it is one is
/// said with the ACTION (only `mode` takes a MODE).
#[derive(Clone, Debug)]
pub struct ModeArg {
    pub word: String,
    pub mode: Result<i8, ParseError>,
}

/// Reads a MODE word (see [`ModeArg`]).
fn mode_arg(word: &str) -> Result<ModeArg, ParseError> {
    Ok(ModeArg {
        word: word.to_string(),
        mode: parse_mode(word),
    })
}

/// `drive NODE ACTION [MODE] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct DriveArgs {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// enable, disable, quick-stop, fault-reset, status, or mode.
    #[arg(value_parser = TypedWords::new(DRIVE_WORDS, DriveAction::parse_verb))]
    pub action: DriveVerb,
    /// The mode for `mode`: pp, pv, pt, hm, ip, csp, csv, cst or a number.
    #[arg(allow_negative_numbers = true, value_parser = mode_arg)]
    pub mode: Option<ModeArg>,
    /// How long to wait for each SDO answer, and half of how long each step may take (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

/// A CiA 402 drive command to a node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Drive {
    pub node: u8,
    pub action: DriveAction,
    pub timeout_ms: u64,
}

impl<D> CommandArgs<D> for DriveArgs {
    type Spec = Drive;

    const NAME: &'static str = "drive";

    /// The action with its MODE: only `mode` takes one, and needs it.
    fn spec(&self) -> Result<Drive, ParseError> {
        let action = match (self.action, self.mode.clone()) {
            (DriveVerb::Mode, Some(m)) => DriveAction::Mode(m.mode?),
            (DriveVerb::Mode, None) => {
                return Err(ParseError::Invalid("drive mode needs a MODE (e.g. pv, csp, 3)".into()));
            }
            (DriveVerb::Action(a), None) => a,
            (DriveVerb::Action(a), Some(m)) => {
                return Err(ParseError::Invalid(format!(
                    "`drive {}` takes no MODE (got `{}`)",
                    a.as_str(),
                    m.word
                )));
            }
        };
        Ok(Drive {
            node: self.node,
            action,
            timeout_ms: self.timeout,
        })
    }
}

/// The state a preview assumes for a drive not seen yet.
pub const ASSUMED_STATE: DriveState = DriveState::SwitchOnDisabled;

impl Spec for Drive {
    /// The controlwords from the drive's last state seen (else [`ASSUMED_STATE`]).
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        let (node, st) = (self.node, (known.drive_state)(self.node));
        let frames = frames(node, self.action, st.unwrap_or(ASSUMED_STATE));
        let from = st
            .map(|s| s.text())
            .unwrap_or("state unknown, assumed Switch on disabled");
        let listed = frames.iter().map(super::spec::candump).collect::<Vec<_>>().join(", ");
        Ok(Preview::sends(match self.action {
            DriveAction::Status => format!("reads 0x6041 of node {node}"),
            DriveAction::Mode(m) => format!("{listed} (0x6060 = {m}), then reads 0x6061"),
            _ if frames.is_empty() => format!("nothing to send (node {node}: {from})"),
            _ => format!("{listed} (from {from})"),
        }))
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let report = drive(ctx.bus, self.node, self.action, self.timeout_ms).await?.report();
        let text = report.text();
        Ok(Outcome::new(report, text))
    }
}

const FAULT_RESET: Step = Step {
    name: "fault reset (0x80)",
    controlword: 0x0080,
    target: DriveState::SwitchOnDisabled,
};
const DISABLE_VOLTAGE: Step = Step {
    name: "disable voltage (0x00)",
    controlword: 0x0000,
    target: DriveState::SwitchOnDisabled,
};
const SHUTDOWN: Step = Step {
    name: "shutdown (0x06)",
    controlword: 0x0006,
    target: DriveState::ReadyToSwitchOn,
};
const SWITCH_ON: Step = Step {
    name: "switch on (0x07)",
    controlword: 0x0007,
    target: DriveState::SwitchedOn,
};
const ENABLE_OPERATION: Step = Step {
    name: "enable operation (0x0F)",
    controlword: 0x000F,
    target: DriveState::OperationEnabled,
};

/// The controlwords of the emergency stop, in order: quick stop, then disable voltage.
pub const STOP_CONTROLWORDS: [u16; 2] = [0x0002, 0x0000];

/// The frame that writes `controlword` to `node` (an expedited SDO download of 0x6040:00),
/// as the SDO client sends it.
pub fn controlword_frame(node: u8, controlword: u16) -> crate::frame::Frame {
    super::sdo::first_download_frame(node, 0x6040, 0, &controlword.to_le_bytes(), false).0
}

/// The frames a drive command on `node` in `state` writes, in order: a controlword per step
/// of [`plan`], or the 0x6060 write of `mode` (then read back; `status` only reads).
pub fn frames(node: u8, action: DriveAction, state: DriveState) -> Vec<crate::frame::Frame> {
    match action {
        DriveAction::Status => Vec::new(),
        DriveAction::Mode(m) => vec![super::sdo::first_download_frame(node, 0x6060, 0, &[m as u8], false).0],
        a => plan(a, state)
            .iter()
            .map(|s| controlword_frame(node, s.controlword))
            .collect(),
    }
}

/// The steps that take a drive in `state` through `action` (empty: nothing to do).
pub fn plan(action: DriveAction, state: DriveState) -> Vec<Step> {
    use DriveState::*;
    let quick_stop = |target| Step {
        name: "quick stop (0x02)",
        controlword: 0x0002,
        target,
    };
    match (action, state) {
        (DriveAction::Enable, Fault | FaultReactionActive) => vec![FAULT_RESET, SHUTDOWN, SWITCH_ON, ENABLE_OPERATION],
        (DriveAction::Enable, QuickStopActive) => vec![DISABLE_VOLTAGE, SHUTDOWN, SWITCH_ON, ENABLE_OPERATION],
        (DriveAction::Enable, NotReadyToSwitchOn | SwitchOnDisabled) => vec![SHUTDOWN, SWITCH_ON, ENABLE_OPERATION],
        (DriveAction::Enable, ReadyToSwitchOn) => vec![SWITCH_ON, ENABLE_OPERATION],
        (DriveAction::Enable, SwitchedOn) => vec![ENABLE_OPERATION],
        (DriveAction::Disable, OperationEnabled | SwitchedOn) => vec![SHUTDOWN],
        (DriveAction::Disable, QuickStopActive) => vec![DISABLE_VOLTAGE],
        (DriveAction::QuickStop, OperationEnabled) => vec![quick_stop(QuickStopActive)],
        (DriveAction::QuickStop, SwitchedOn | ReadyToSwitchOn) => vec![quick_stop(SwitchOnDisabled)],
        (DriveAction::FaultReset, Fault) => vec![FAULT_RESET],
        _ => Vec::new(),
    }
}

/// The outcome of a drive command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DriveReport {
    pub node: u8,
    pub action: DriveAction,
    /// The final statusword and the state it shows.
    pub statusword: u16,
    pub state: DriveState,
    /// Controlwords written, in order.
    pub steps: Vec<Step>,
    /// 0x6061 modes of operation display, when readable.
    pub mode_display: Option<i8>,
    /// 0x603F error code, when readable.
    pub error_code: Option<u16>,
    /// Where the final statusword came from: `sdo` or `tpdo`.
    pub source: &'static str,
}

impl DriveReport {
    /// The `--json` object.
    pub fn report(&self) -> DriveJson {
        DriveJson {
            ok: true,
            node: self.node,
            action: self.action.as_str(),
            statusword: format!("0x{:04X}", self.statusword),
            state: self.state.as_str(),
            state_text: self.state.text(),
            controlwords: self.steps.iter().map(|s| format!("0x{:04X}", s.controlword)).collect(),
            mode_display: self.mode_display,
            error_code: self.error_code.map(|c| format!("0x{c:04X}")),
            source: self.source,
        }
    }
}

/// Bus traffic of one node gathered while a sequence runs.
struct Watch {
    rx: Subscription,
    node: u8,
    obs: Observation,
    /// COB-ID and byte offset of a TPDO that carries the statusword.
    tpdo: Option<(u32, usize)>,
    tpdo_sw: Option<u16>,
}

impl Watch {
    /// Watches `node` on `bus` from now on.
    fn new(bus: &Bus, node: u8) -> Watch {
        Watch {
            rx: bus.subscribe(),
            node,
            obs: Observation::default(),
            tpdo: None,
            tpdo_sw: None,
        }
    }

    fn drain(&mut self) {
        while let Some(got) = self.rx.try_recv() {
            let Ok(f) = got else { continue };
            if f.direction() != Direction::Rx || f.is_ext() || f.is_rtr() {
                continue;
            }
            let p = f.payload();
            let n = self.node;
            if f.id == cob::heartbeat(n) && !p.is_empty() {
                self.obs.nmt = Some(NmtState::from_byte(p[0]));
            } else if f.id == cob::emcy(n) && p.len() >= 2 {
                let code = u16::from_le_bytes([p[0], p[1]]);
                self.obs.emcy = (code != 0).then_some(code);
            } else if let Some((cob, off)) = self.tpdo
                && f.id == cob
                && p.len() >= off + 2
            {
                self.tpdo_sw = Some(u16::from_le_bytes([p[off], p[off + 1]]));
            }
        }
    }
}

fn le_u16(d: &[u8]) -> u16 {
    u16::from_le_bytes([d.first().copied().unwrap_or(0), d.get(1).copied().unwrap_or(0)])
}

fn le_u32(d: &[u8]) -> u32 {
    let mut b = [0u8; 4];
    for (i, x) in d.iter().take(4).enumerate() {
        b[i] = *x;
    }
    u32::from_le_bytes(b)
}

/// Finds a TPDO mapping the statusword: (COB-ID, byte offset), reading 0x1A00.. and 0x1800.. by SDO.
async fn statusword_tpdo(bus: &Bus, node: u8, timeout_ms: u64) -> Option<(u32, usize)> {
    for n in 0..4u16 {
        let count = upload(bus, node, 0x1A00 + n, 0, false, timeout_ms).await.ok()?;
        let mut bits = 0usize;
        for i in 1..=count.first().copied().unwrap_or(0) {
            let e = le_u32(&upload(bus, node, 0x1A00 + n, i, false, timeout_ms).await.ok()?);
            if e >> 16 == 0x6041 && (e >> 8) & 0xFF == 0 && bits.is_multiple_of(8) {
                let cob = le_u32(&upload(bus, node, 0x1800 + n, 1, false, timeout_ms).await.ok()?);
                return (cob & 0x8000_0000 == 0).then_some((cob & 0x7FF, bits / 8));
            }
            bits += (e & 0xFF) as usize;
        }
    }
    None
}

async fn read_u16(bus: &Bus, node: u8, index: u16, timeout_ms: u64) -> Result<u16, CommandError> {
    upload(bus, node, index, 0, false, timeout_ms).await.map(|d| le_u16(&d))
}

/// Fills in what the drive shows now and explains why `step` failed.
async fn failure(bus: &Bus, w: &mut Watch, step: &Step, timeout_ms: u64) -> CommandError {
    w.drain();
    let node = w.node;
    if !w.obs.sdo_silent {
        w.obs.error_code = read_u16(bus, node, 0x603F, timeout_ms).await.ok();
        w.obs.controlword = read_u16(bus, node, 0x6040, timeout_ms).await.ok();
        w.obs.mode_display = upload(bus, node, 0x6061, 0, false, timeout_ms)
            .await
            .ok()
            .and_then(|d| d.first().map(|b| *b as i8));
    }
    w.drain();
    CommandError::Drive {
        node,
        step: step.name.to_string(),
        reason: diagnose(node, step, &w.obs),
    }
}

/// Reads the statusword (a fresh TPDO value wins over an SDO read).
async fn statusword(bus: &Bus, w: &mut Watch, timeout_ms: u64) -> Result<(u16, &'static str), CommandError> {
    w.drain();
    if let Some(sw) = w.tpdo_sw.take() {
        return Ok((sw, "tpdo"));
    }
    match read_u16(bus, w.node, 0x6041, timeout_ms).await {
        Ok(sw) => Ok((sw, "sdo")),
        Err(CommandError::Timeout(_)) => {
            w.obs.sdo_silent = true;
            Err(CommandError::Timeout(String::new()))
        }
        Err(e) => Err(e),
    }
}

/// Runs a drive command on `node`. `timeout_ms` bounds each SDO response and each step.
pub async fn drive(bus: &Bus, node: u8, action: DriveAction, timeout_ms: u64) -> Result<DriveReport, CommandError> {
    let mut w = Watch::new(bus, node);
    let probe = Step {
        name: "read statusword",
        controlword: 0,
        target: DriveState::SwitchOnDisabled,
    };
    let (mut sw, mut source) = match statusword(bus, &mut w, timeout_ms).await {
        Ok(v) => v,
        Err(CommandError::Timeout(_)) => {
            // Give heartbeats a moment to tell whether the node is there at all.
            tokio::time::sleep(Duration::from_millis(timeout_ms.min(1500))).await;
            let e = failure(bus, &mut w, &probe, timeout_ms).await;
            // Neither SDO nor heartbeat: no such node, a timeout as for `sdo read` (exit 4).
            return Err(match w.obs.nmt {
                None => CommandError::Timeout(e.to_string()),
                Some(_) => e,
            });
        }
        Err(e) => return Err(e),
    };
    if let DriveAction::Mode(mode) = action {
        return set_mode(bus, &mut w, mode, sw, timeout_ms).await;
    }
    let steps = plan(action, DriveState::from_statusword(sw));
    if !steps.is_empty() {
        w.tpdo = statusword_tpdo(bus, node, timeout_ms).await;
    }
    for step in &steps {
        w.obs.before = Some(sw);
        w.tpdo_sw = None;
        if let Err(e) = download(
            bus,
            node,
            0x6040,
            0,
            step.controlword.to_le_bytes().to_vec(),
            false,
            timeout_ms,
        )
        .await
        {
            return Err(match e {
                CommandError::Abort { code, .. } => CommandError::Drive {
                    node,
                    step: step.name.to_string(),
                    reason: format!(
                        "the drive refused controlword 0x{:04X}: SDO abort 0x{code:08X} {}",
                        step.controlword,
                        crate::sdo::abort_text(code)
                    ),
                },
                CommandError::Timeout(_) => {
                    w.obs.sdo_silent = true;
                    failure(bus, &mut w, step, timeout_ms).await
                }
                e => e,
            });
        }
        let deadline = tokio::time::Instant::now() + Duration::from_millis(timeout_ms.max(200) * 2);
        loop {
            match statusword(bus, &mut w, timeout_ms).await {
                Ok((s, src)) => {
                    (sw, source) = (s, src);
                    w.obs.statusword = Some(s);
                }
                Err(CommandError::Timeout(_)) => return Err(failure(bus, &mut w, step, timeout_ms).await),
                Err(e) => return Err(e),
            }
            if DriveState::from_statusword(sw) == step.target {
                break;
            }
            if tokio::time::Instant::now() >= deadline {
                return Err(failure(bus, &mut w, step, timeout_ms).await);
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    }
    let mode_display = upload(bus, node, 0x6061, 0, false, timeout_ms)
        .await
        .ok()
        .and_then(|d| d.first().map(|b| *b as i8));
    let error_code = read_u16(bus, node, 0x603F, timeout_ms).await.ok();
    Ok(DriveReport {
        node,
        action,
        statusword: sw,
        state: DriveState::from_statusword(sw),
        steps,
        mode_display,
        error_code,
        source,
    })
}

async fn set_mode(bus: &Bus, w: &mut Watch, mode: i8, sw: u16, timeout_ms: u64) -> Result<DriveReport, CommandError> {
    let node = w.node;
    download(bus, node, 0x6060, 0, vec![mode as u8], false, timeout_ms).await?;
    let deadline = tokio::time::Instant::now() + Duration::from_millis(timeout_ms.max(200) * 2);
    loop {
        let shown = upload(bus, node, 0x6061, 0, false, timeout_ms).await?;
        let shown = shown.first().map(|b| *b as i8);
        if shown == Some(mode) {
            return Ok(DriveReport {
                node,
                action: DriveAction::Mode(mode),
                statusword: sw,
                state: DriveState::from_statusword(sw),
                steps: Vec::new(),
                mode_display: shown,
                error_code: None,
                source: "sdo",
            });
        }
        if tokio::time::Instant::now() >= deadline {
            return Err(CommandError::Drive {
                node,
                step: format!("mode {mode}"),
                reason: format!(
                    "mode not set: 0x6061 shows {} after writing {mode} ({}) to 0x6060; check 0x6502 supported modes",
                    shown.map(|m| m.to_string()).unwrap_or("nothing".into()),
                    mode_name(mode)
                ),
            });
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
}

/// How the stop of one drive ended (see [`stop`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeStop {
    pub node: u8,
    /// True when the statusword read back shows the power stage off (Switch on disabled or
    /// Not ready to switch on) after our controlwords.
    pub stopped: bool,
    /// The last statusword read, and the state it shows.
    pub statusword: Option<u16>,
    pub state: Option<DriveState>,
    /// Controlwords written, in order.
    pub sent: Vec<u16>,
    /// Why the stop is not confirmed (no answer, refused, fault, state).
    pub reason: Option<String>,
}

/// The JSON object of one node in a stop report.
impl serde::Serialize for NodeStop {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        NodeStopJson {
            node: self.node,
            stopped: self.stopped,
            statusword: self.statusword.map(|s| format!("0x{s:04X}")),
            state: self.state.map(|s| s.as_str()),
            controlwords: self.sent.iter().map(|c| format!("0x{c:04X}")).collect(),
            reason: self.reason.as_deref(),
        }
        .serialize(s)
    }
}

impl NodeStop {
    /// One line: `node 2: stopped, Switch on disabled (0x0250) after 0x0002, 0x0000`.
    pub fn text(&self) -> String {
        let sent = self
            .sent
            .iter()
            .map(|c| format!("0x{c:04X}"))
            .collect::<Vec<_>>()
            .join(", ");
        let shown = match (self.state, self.statusword) {
            (Some(s), Some(sw)) => format!("{} (statusword 0x{sw:04X})", s.text()),
            _ => "no statusword".into(),
        };
        match &self.reason {
            None => format!("node {}: stopped, {shown} after controlwords {sent}", self.node),
            Some(r) => format!("node {}: NOT confirmed stopped: {r}", self.node),
        }
    }
}

/// `drive --json`: the outcome of a drive command.
#[derive(Debug, serde::Serialize)]
pub struct DriveJson {
    ok: bool,
    node: u8,
    action: &'static str,
    pub statusword: String,
    state: &'static str,
    state_text: &'static str,
    controlwords: Vec<String>,
    mode_display: Option<i8>,
    error_code: Option<String>,
    source: &'static str,
}

impl DriveJson {
    /// `node 2: Operation enabled (statusword 0x0237), controlwords ..., mode ..., error code ...`.
    fn text(&self) -> String {
        let mut t = format!(
            "node {}: {} (statusword {})",
            self.node, self.state_text, self.statusword
        );
        if !self.controlwords.is_empty() {
            t.push_str(&format!(", controlwords {}", self.controlwords.join(" -> ")));
        }
        if let Some(m) = self.mode_display {
            t.push_str(&format!(", mode {m} ({})", mode_name(m)));
        }
        if let Some(e) = self.error_code.as_deref().filter(|e| *e != "0x0000") {
            t.push_str(&format!(", error code {e}"));
        }
        t
    }
}

/// One node of a stop report.
#[derive(serde::Serialize)]
struct NodeStopJson<'a> {
    node: u8,
    stopped: bool,
    statusword: Option<String>,
    state: Option<&'static str>,
    controlwords: Vec<String>,
    reason: Option<&'a str>,
}

/// Quick stop, then disable voltage: the emergency stop of one drive.
///
/// Writes controlword 0x0002 at once, waits up to `ramp_ms` for the drive to finish its
/// quick stop (it leaves Quick stop active by itself, or shows target reached, bit 10),
/// writes 0x0000 (disable voltage) and reads the statusword back until it shows the power
/// stage off. Never fails: every problem is in the returned [`NodeStop`].
pub async fn stop(bus: &Bus, node: u8, timeout_ms: u64, ramp_ms: u64) -> NodeStop {
    let mut w = Watch::new(bus, node);
    let mut out = NodeStop {
        node,
        stopped: false,
        statusword: None,
        state: None,
        sent: Vec::new(),
        reason: None,
    };
    let [quick_stop, disable_voltage] = STOP_CONTROLWORDS;
    for (cw, wait_ms) in [(quick_stop, ramp_ms), (disable_voltage, timeout_ms.max(200) * 2)] {
        if let Err(e) = download(bus, node, 0x6040, 0, cw.to_le_bytes().to_vec(), false, timeout_ms).await {
            out.reason = Some(stop_failure(&mut w, cw, e));
            return out;
        }
        out.sent.push(cw);
        let deadline = tokio::time::Instant::now() + Duration::from_millis(wait_ms);
        loop {
            let sw = match statusword(bus, &mut w, timeout_ms).await {
                Ok((sw, _)) => sw,
                Err(e) => {
                    out.reason = Some(format!("statusword not readable after controlword 0x{cw:04X}: {e}"));
                    return out;
                }
            };
            let state = DriveState::from_statusword(sw);
            (out.statusword, out.state) = (Some(sw), Some(state));
            let off = matches!(state, DriveState::SwitchOnDisabled | DriveState::NotReadyToSwitchOn);
            let faulted = matches!(state, DriveState::Fault | DriveState::FaultReactionActive);
            let standstill = state == DriveState::QuickStopActive && sw & 0x0400 != 0;
            if off || faulted || (cw == quick_stop && standstill) || tokio::time::Instant::now() >= deadline {
                break;
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    }
    let (Some(sw), Some(state)) = (out.statusword, out.state) else {
        return out;
    };
    out.stopped = matches!(state, DriveState::SwitchOnDisabled | DriveState::NotReadyToSwitchOn);
    if !out.stopped {
        out.reason = Some(
            if matches!(state, DriveState::Fault | DriveState::FaultReactionActive) {
                let code = read_u16(bus, node, 0x603F, timeout_ms).await.ok();
                format!(
                    "in {} (statusword 0x{sw:04X}{}): the fault reaction decides what the motor does;                  check the drive, then `drive {node} fault-reset`",
                    state.text(),
                    code.map(|c| format!(", error code 0x{c:04X}")).unwrap_or_default()
                )
            } else {
                format!(
                    "statusword 0x{sw:04X} still shows {} after disable voltage (0x0000)",
                    state.text()
                )
            },
        );
    }
    out
}

/// Why writing controlword `cw` during a stop failed, in words.
fn stop_failure(w: &mut Watch, cw: u16, e: CommandError) -> String {
    w.drain();
    match e {
        CommandError::Abort { code, .. } => format!(
            "the node refused controlword 0x{cw:04X}: SDO abort 0x{code:08X} {} (not a CiA 402 drive?)",
            crate::sdo::abort_text(code)
        ),
        CommandError::Timeout(_) => match w.obs.nmt {
            Some(s) => format!("no SDO answer to controlword 0x{cw:04X} (heartbeat says {})", s.text()),
            None => format!("no SDO answer to controlword 0x{cw:04X} and no heartbeat: check power, wiring, node-ID"),
        },
        e => format!("controlword 0x{cw:04X} not written: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obs(sw: u16) -> Observation {
        Observation {
            nmt: Some(NmtState::Operational),
            before: Some(0x0250),
            statusword: Some(sw),
            ..Observation::default()
        }
    }

    #[test]
    fn plans_follow_the_state_machine() {
        let cws = |a, s| plan(a, s).iter().map(|st| st.controlword).collect::<Vec<_>>();
        assert_eq!(
            cws(DriveAction::Enable, DriveState::Fault),
            vec![0x80, 0x06, 0x07, 0x0F]
        );
        assert_eq!(cws(DriveAction::Enable, DriveState::SwitchedOn), vec![0x0F]);
        assert_eq!(
            cws(DriveAction::Enable, DriveState::OperationEnabled),
            Vec::<u16>::new()
        );
        assert_eq!(cws(DriveAction::QuickStop, DriveState::OperationEnabled), vec![0x02]);
        assert_eq!(
            cws(DriveAction::FaultReset, DriveState::SwitchOnDisabled),
            Vec::<u16>::new()
        );
    }

    #[test]
    fn reasons_from_what_the_bus_shows() {
        let stopped = Observation {
            nmt: Some(NmtState::Stopped),
            ..obs(0x0250)
        };
        assert!(diagnose(2, &SHUTDOWN, &stopped).starts_with("NMT not operational: node 2 is NMT stopped"));
        let fault = Observation {
            error_code: Some(0x2310),
            ..obs(0x0218)
        };
        assert_eq!(
            diagnose(2, &SHUTDOWN, &fault),
            "fault bit set: statusword 0x0218 shows Fault (error code 0x2310); run `drive 2 fault-reset`"
        );
        assert!(diagnose(2, &SWITCH_ON, &obs(0x0221)).starts_with("voltage not enabled"));
        let halt = Observation {
            controlword: Some(0x010F),
            ..obs(0x0233)
        };
        assert!(diagnose(2, &ENABLE_OPERATION, &halt).starts_with("halt bit set"));
        let no_mode = Observation {
            mode_display: Some(0),
            ..obs(0x0233)
        };
        assert!(
            diagnose(2, &ENABLE_OPERATION, &no_mode).starts_with("mode not set: modes of operation display 0x6061 = 0")
        );
        let stale = Observation {
            nmt: Some(NmtState::PreOperational),
            ..obs(0x0250)
        };
        assert_eq!(
            diagnose(2, &SHUTDOWN, &stale),
            "statusword stale: still 0x0250 (Switch on disabled) after controlword 0x0006; node is NMT Pre-operational \
             and some drives take the controlword only when operational: run `cotui nmt IFACE start 2`"
        );
        assert!(diagnose(2, &ENABLE_OPERATION, &obs(0x0217)).starts_with("quick stop active"));
        let silent = Observation {
            nmt: None,
            sdo_silent: true,
            ..Observation::default()
        };
        assert!(diagnose(7, &SHUTDOWN, &silent).starts_with("no SDO answer and no heartbeat from node 7"));
    }
}
