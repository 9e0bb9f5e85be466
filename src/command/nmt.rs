//! NMT commands, optionally confirmed by the heartbeat or boot-up that follows.

use super::error::CommandError;
use super::grammar::NMT_WAIT_MS;
use super::listen_first::{LISTEN_MS, Listen, OtherProducer};
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::{NMT_WORDS, ParseError, TypedWords, ms_arg, ms_or_zero_arg, node_or_all_arg};
use crate::bus::Bus;
use crate::cob;
use crate::decode::heartbeat::NmtState;
use crate::frame::{Direction, Frame};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Duration;

/// `nmt ACTION NODE [--wait] [--timeout MS] [--listen DUR] [--force]`.
#[derive(clap::Args, Clone, Debug)]
pub struct NmtArgs {
    /// start, stop, preop, reset-node or reset-comm.
    #[arg(value_parser = TypedWords::new(NMT_WORDS, NmtAction::parse))]
    pub action: NmtAction,
    /// Node id 1..127, or 0 for all nodes.
    #[arg(value_parser = node_or_all_arg)]
    pub node: u8,
    /// Wait for the heartbeat (or boot-up after a reset) that confirms the command.
    #[arg(long)]
    pub wait: bool,
    /// How long --wait waits (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = NMT_WAIT_MS)]
    pub timeout: u64,
    /// How long to listen for another NMT master before sending (DUR; 0: do not listen).
    #[arg(long, value_parser = ms_or_zero_arg, default_value_t = LISTEN_MS)]
    pub listen: u64,
    /// Send even when another NMT master is heard.
    #[arg(long)]
    pub force: bool,
}

/// An NMT command to a node (0 = all), optionally confirmed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Nmt {
    pub action: NmtAction,
    pub node: u8,
    /// Wait for the heartbeat or boot-up that confirms it.
    pub wait: bool,
    pub timeout_ms: u64,
    /// Listening for another NMT master first.
    pub listen: Listen,
}

impl<D> CommandArgs<D> for NmtArgs {
    type Spec = Nmt;

    const NAME: &'static str = "nmt";

    fn spec(&self) -> Result<Nmt, ParseError> {
        Ok(Nmt {
            action: self.action,
            node: self.node,
            wait: self.wait,
            timeout_ms: self.timeout,
            listen: Listen {
                ms: self.listen,
                force: self.force,
            },
        })
    }
}

/// `nmt --json`.
#[derive(Debug, Serialize)]
pub struct NmtSent {
    ok: bool,
    action: &'static str,
    node: u8,
    /// With `--wait`: node -> the state that confirmed the command; else null.
    confirmed: Option<BTreeMap<String, &'static str>>,
    /// The other NMT master heard before sending (sent with --force); else null.
    other_producer: Option<OtherProducer>,
}

impl NmtSent {
    /// `NMT start sent to node 2`, then the confirming state of each node.
    fn text(&self) -> String {
        let target = if self.node == 0 {
            "all nodes".to_string()
        } else {
            format!("node {}", self.node)
        };
        let mut t = format!("NMT {} sent to {target}", self.action);
        for (n, state) in self.confirmed.iter().flatten() {
            t.push_str(&format!("\nnode {n}: {state}"));
        }
        if let Some(o) = &self.other_producer {
            t.push_str(&format!("\nsent anyway (--force): {}", o.text()));
        }
        t
    }
}

impl Spec for Nmt {
    /// The NMT frame; a broadcast or a reset needs confirming.
    fn preview(&self, _known: &Known<'_>) -> Result<Preview, CommandError> {
        let reset = matches!(self.action, NmtAction::ResetNode | NmtAction::ResetComm);
        let confirm = match (self.node, reset) {
            (0, _) => Some(format!("broadcast NMT {} to every node", self.action.as_str())),
            (n, true) => Some(format!("NMT {} of node {n}", self.action.as_str())),
            _ => None,
        };
        Ok(Preview {
            frames: super::spec::candump(&frame(self.action, self.node)),
            confirm,
        })
    }

    /// Listens for another NMT master, then sends (and waits for the confirmation).
    async fn run(&self, mut ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let other =
            super::listen_first::before_sending(ctx.bus, cob::NMT, "NMT master", self.listen, &mut ctx.stop).await?;
        let seen = nmt(ctx.bus, self.action, self.node, self.wait, self.timeout_ms).await?;
        let sent = NmtSent {
            ok: true,
            action: self.action.as_str(),
            node: self.node,
            confirmed: self
                .wait
                .then(|| seen.iter().map(|(n, s)| (n.to_string(), s.as_str())).collect()),
            other_producer: other,
        };
        let text = sent.text();
        Ok(Outcome::new(sent, text))
    }
}

/// An NMT command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NmtAction {
    Start,
    Stop,
    PreOp,
    ResetNode,
    ResetComm,
}

impl NmtAction {
    /// The NMT command specifier.
    pub fn cs(self) -> u8 {
        match self {
            NmtAction::Start => 0x01,
            NmtAction::Stop => 0x02,
            NmtAction::PreOp => 0x80,
            NmtAction::ResetNode => 0x81,
            NmtAction::ResetComm => 0x82,
        }
    }
    /// The word used on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            NmtAction::Start => "start",
            NmtAction::Stop => "stop",
            NmtAction::PreOp => "preop",
            NmtAction::ResetNode => "reset-node",
            NmtAction::ResetComm => "reset-comm",
        }
    }
    /// Parses `start|stop|preop|reset-node|reset-comm`.
    pub fn parse(word: &str) -> Result<NmtAction, ParseError> {
        Ok(match word {
            "start" => NmtAction::Start,
            "stop" => NmtAction::Stop,
            "preop" | "pre-op" | "preoperational" => NmtAction::PreOp,
            "reset-node" => NmtAction::ResetNode,
            "reset-comm" => NmtAction::ResetComm,
            _ => {
                return Err(ParseError::Invalid(format!(
                    "unknown NMT command `{word}`: use start, stop, preop, reset-node or reset-comm"
                )));
            }
        })
    }
}

/// What `nmt --wait` saw: node -> state reported after the command.
pub type Confirmed = BTreeMap<u8, NmtState>;

/// The state a node reports when it has carried out `action` (boot-up for resets).
pub fn expected_state(action: NmtAction) -> NmtState {
    match action {
        NmtAction::Start => NmtState::Operational,
        NmtAction::Stop => NmtState::Stopped,
        NmtAction::PreOp => NmtState::PreOperational,
        NmtAction::ResetNode | NmtAction::ResetComm => NmtState::BootUp,
    }
}

/// The NMT frame of `action` to `node` (0 = all).
pub fn frame(action: NmtAction, node: u8) -> Frame {
    Frame::classic(cob::NMT, &[action.cs(), node])
}

/// Sends `action` to `node` (0 = all). With `wait`, waits up to `timeout_ms` for the heartbeat
/// or boot-up that confirms it (node 0: every node that answers in that time).
pub async fn nmt(
    bus: &Bus,
    action: NmtAction,
    node: u8,
    wait: bool,
    timeout_ms: u64,
) -> Result<Confirmed, CommandError> {
    let mut rx = bus.subscribe();
    bus.send(&frame(action, node)).await?;
    let mut seen = Confirmed::new();
    if !wait {
        return Ok(seen);
    }
    let want = expected_state(action);
    let deadline = tokio::time::Instant::now() + Duration::from_millis(timeout_ms);
    loop {
        let left = deadline.saturating_duration_since(tokio::time::Instant::now());
        let f = match tokio::time::timeout(left, rx.recv()).await {
            Err(_) => break,
            Ok(Ok(f)) => f,
            Ok(Err(crate::bus::BusError::Closed)) => break,
            Ok(Err(_)) => continue,
        };
        if f.direction() != Direction::Rx || f.is_ext() || f.is_rtr() {
            continue;
        }
        let Some(from) = cob::heartbeat_node(f.id) else {
            continue;
        };
        let Some(b) = f.payload().first() else { continue };
        let state = NmtState::from_byte(*b);
        if node != 0 && from != node {
            continue;
        }
        // A heartbeat sent before the command arrived may still show the old state.
        if state == want {
            seen.insert(from, state);
            if node != 0 {
                return Ok(seen);
            }
        }
    }
    if node == 0 && !seen.is_empty() {
        return Ok(seen);
    }
    Err(CommandError::Timeout(format!(
        "NMT {}: no {} from {} within {timeout_ms} ms (is the heartbeat 0x1017 enabled?)",
        action.as_str(),
        if want == NmtState::BootUp {
            "boot-up".to_string()
        } else {
            format!("heartbeat showing {}", want.text())
        },
        if node == 0 {
            "any node".to_string()
        } else {
            format!("node {node}")
        }
    )))
}
