//! `run NODE PROCEDURE [NAME=VALUE ...]`: a profile's named procedure, planned into
//! concrete steps (pure: objects resolved, values encoded, frames built) and then run
//! step by step through the same SDO and NMT paths as `sdo write` / `nmt`.

pub mod command;

use super::error::CommandError;
use super::grammar::parse_int;
use super::nmt::NmtAction;
use super::report::Reported;
use super::value::{decode, encode};
use crate::bus::{Bus, BusError};
use crate::decode::value_text::object_text;
use crate::frame::Frame;
use crate::frame::hex;
use crate::od::procedure::{NmtCommand, Procedure, Step, fill_object, frame_bytes};
use crate::od::resolve_object;
use crate::od::{DataType, Dictionary, Value};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Duration;

/// What a planned step does on the bus.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// SDO download of `data` (already encoded) to (index, sub).
    SdoWrite { index: u16, sub: u8, data: Vec<u8> },
    /// SDO upload of (index, sub), decoded as `ty`.
    SdoRead { index: u16, sub: u8, ty: Option<DataType> },
    /// An NMT command to `target` (0 = all), sent like `nmt ACTION NODE`.
    Nmt { action: NmtAction, target: u8 },
    /// A raw frame, sent as-is.
    Frame(Frame),
    /// Read (index, sub) by SDO until `(value & mask) == equals`, at most `timeout_ms`.
    Wait {
        index: u16,
        sub: u8,
        ty: Option<DataType>,
        mask: i64,
        equals: i64,
        timeout_ms: u32,
        /// `(value & mask) == equals` fails the step at once with this text.
        fail_if: Option<(i64, i64, String)>,
    },
    /// Sleep.
    Delay { ms: u32 },
}

/// One step with its values filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedStep {
    /// What it does.
    pub action: Action,
    /// How it reads, e.g. `sdo write 0x6040:00 Controlword = 0x0006 (Shutdown)`.
    pub text: String,
    /// The value written or compared with, if any.
    pub value: Option<i64>,
    /// The (first) frame it sends, candump style (`602#2B40600006000000`), if it sends one.
    pub frame: Option<String>,
}

impl PlannedStep {
    /// The step kind as in the profile: `sdo_write`, `sdo_read`, `nmt`, `frame`, `wait`, `delay`.
    pub fn kind(&self) -> &'static str {
        match self.action {
            Action::SdoWrite { .. } => "sdo_write",
            Action::SdoRead { .. } => "sdo_read",
            Action::Nmt { .. } => "nmt",
            Action::Frame(_) => "frame",
            Action::Wait { .. } => "wait",
            Action::Delay { .. } => "delay",
        }
    }
    /// The object it addresses, `0x6040:00`.
    pub fn object(&self) -> Option<String> {
        match self.action {
            Action::SdoWrite { index, sub, .. }
            | Action::SdoRead { index, sub, .. }
            | Action::Wait { index, sub, .. } => Some(format!("0x{index:04X}:{sub:02X}")),
            _ => None,
        }
    }
    /// The line shown before the step is sent: `step 3/9: TEXT  [FRAME]`.
    pub fn line(&self, number: usize, of: usize) -> String {
        match &self.frame {
            Some(f) => format!("step {number}/{of}: {}  [{f}]", self.text),
            None => format!("step {number}/{of}: {}", self.text),
        }
    }
    /// A short form for the palette preview: the frame, or what the step does.
    pub fn preview(&self) -> String {
        match (&self.action, &self.frame) {
            (Action::Wait { .. } | Action::Delay { .. }, _) | (_, None) => self.text.clone(),
            (Action::SdoWrite { data, .. }, Some(f)) if data.len() > 4 => {
                format!("{f} then {} segments", data.len().div_ceil(7))
            }
            (_, Some(f)) => f.clone(),
        }
    }
}

/// A procedure with its parameters bound, ready to run on one node.
#[derive(Clone, Debug, PartialEq)]
pub struct RunPlan {
    /// The procedure's name.
    pub procedure: String,
    /// The target node.
    pub node: u8,
    /// Every parameter with the value used (given or default).
    pub params: Vec<(String, i64)>,
    /// The steps in order.
    pub steps: Vec<PlannedStep>,
}

/// Why a procedure cannot be planned (a usage error: nothing was sent).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PlanError {
    /// The node's dictionary has no procedure of that name (`known`: the ones it has).
    #[error(
        "node {node} has no procedure `{name}`{}",
        if known.is_empty() {
            format!(": its dictionary has no procedures (bind a profile: --profile {node}=NAME)")
        } else {
            format!("; its procedures: {}", known.join(", "))
        }
    )]
    NoProcedure { node: u8, name: String, known: Vec<String> },
    /// A parameter the procedure does not take (`params`: the ones it takes).
    #[error("`{procedure}` has no parameter `{name}`; {params}")]
    UnknownParam {
        procedure: String,
        name: String,
        params: String,
    },
    /// A parameter value that is not a number.
    #[error("{name}=`{text}` is not a number (decimal or 0x hex)")]
    NotANumber { name: String, text: String },
    /// A parameter without default not given.
    #[error("`{procedure}` needs {name}=VALUE; {params}")]
    MissingParam {
        procedure: String,
        name: String,
        params: String,
    },
    /// A step that cannot be built (object, expression, value, frame).
    #[error("`{procedure}` step {step}/{of}: {reason}")]
    Step {
        procedure: String,
        step: usize,
        of: usize,
        reason: StepError,
    },
}

/// Why one step of a procedure cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StepError {
    #[error(transparent)]
    Expr(#[from] crate::od::expr::ExprError),
    #[error(transparent)]
    Object(#[from] crate::od::alias::ObjectError),
    #[error(transparent)]
    Procedure(#[from] crate::od::procedure::ProcedureError),
    #[error(transparent)]
    Value(#[from] super::value::ValueError),
    #[error("the type of {index:04X}:{sub:02X} is unknown (give `type` in the profile)")]
    UnknownType { index: u16, sub: u8 },
    #[error("NMT node {0} is not 0..127")]
    NmtNode(i64),
    #[error("frame id {0} is not a CAN id")]
    FrameId(i64),
}

impl From<PlanError> for CommandError {
    fn from(e: PlanError) -> Self {
        CommandError::Usage(e.to_string())
    }
}

/// The procedure `name` of `dict`, or an error naming the ones there are.
pub fn find<'a>(dict: &'a Dictionary, node: u8, name: &str) -> Result<&'a Procedure, PlanError> {
    dict.procedure(name).ok_or_else(|| PlanError::NoProcedure {
        node,
        name: name.to_string(),
        known: dict.procedures().iter().map(|p| p.name.clone()).collect(),
    })
}

fn param_list(p: &Procedure) -> String {
    if p.params.is_empty() {
        return "it takes none".into();
    }
    let each: Vec<String> = p
        .params
        .iter()
        .map(|q| match q.default {
            Some(d) => format!("{}={d}", q.name),
            None => format!("{}=(required)", q.name),
        })
        .collect();
    format!("its parameters: {}", each.join(", "))
}

/// Binds `args` to the parameters of `p` (defaults for the rest): unknown, unparsable or
/// missing parameters are errors naming the valid ones.
pub fn bind_params(p: &Procedure, args: &[(String, String)]) -> Result<Vec<(String, i64)>, PlanError> {
    for (name, _) in args {
        if !p.params.iter().any(|q| &q.name == name) {
            return Err(PlanError::UnknownParam {
                procedure: p.name.clone(),
                name: name.clone(),
                params: param_list(p),
            });
        }
    }
    p.params
        .iter()
        .map(|q| {
            let given = args.iter().rev().find(|(n, _)| n == &q.name);
            let v = match (given, q.default) {
                (Some((_, text)), _) => parse_int(text).ok_or_else(|| PlanError::NotANumber {
                    name: q.name.clone(),
                    text: text.clone(),
                })?,
                (None, Some(d)) => d,
                (None, None) => {
                    return Err(PlanError::MissingParam {
                        procedure: p.name.clone(),
                        name: q.name.clone(),
                        params: param_list(p),
                    });
                }
            };
            Ok((q.name.clone(), v))
        })
        .collect()
}

/// Plans procedure `name` of node `node` with dictionary `dict` and parameters `args`:
/// resolves every object, evaluates every expression and builds every frame, without IO.
pub fn plan(dict: &Dictionary, node: u8, name: &str, args: &[(String, String)]) -> Result<RunPlan, PlanError> {
    let p = find(dict, node, name)?;
    let params = bind_params(p, args)?;
    let vars = |v: &str| {
        if v == "node" {
            return Some(i64::from(node));
        }
        params.iter().find(|(n, _)| n == v).map(|(_, x)| *x)
    };
    let n = p.steps.len();
    let mut steps = Vec::with_capacity(n);
    for (i, step) in p.steps.iter().enumerate() {
        let at = |reason: StepError| PlanError::Step {
            procedure: name.to_string(),
            step: i + 1,
            of: n,
            reason,
        };
        steps.push(plan_step(dict, node, step, &vars).map_err(at)?);
    }
    Ok(RunPlan {
        procedure: p.name.clone(),
        node,
        params,
        steps,
    })
}

fn object_name(dict: &Dictionary, index: u16, sub: u8) -> String {
    match dict.name(index, sub) {
        Some(n) => format!("0x{index:04X}:{sub:02X} {n}"),
        None => format!("0x{index:04X}:{sub:02X}"),
    }
}

fn plan_step(
    dict: &Dictionary,
    node: u8,
    step: &Step,
    vars: &dyn Fn(&str) -> Option<i64>,
) -> Result<PlannedStep, StepError> {
    let typed = |index: u16, sub: u8| dict.object(index, sub).map(|o| o.data_type);
    Ok(match step {
        Step::SdoWrite {
            object,
            value,
            data_type,
        } => {
            let (index, sub) = resolve_object(dict, &fill_object(object, vars)?)?;
            let v = value.eval(vars)?;
            let ty = data_type
                .or_else(|| typed(index, sub))
                .ok_or(StepError::UnknownType { index, sub })?;
            let data = encode(&v.to_string(), ty)?;
            let shown = object_text(dict, index, sub, &ty.decode(&data), None);
            let text = format!("sdo write {} = {shown}", object_name(dict, index, sub));
            let frame = super::spec::candump(&super::sdo::first_download_frame(node, index, sub, &data, false).0);
            PlannedStep {
                action: Action::SdoWrite { index, sub, data },
                text,
                value: Some(v),
                frame: Some(frame),
            }
        }
        Step::SdoRead { object } => {
            let (index, sub) = resolve_object(dict, &fill_object(object, vars)?)?;
            PlannedStep {
                action: Action::SdoRead {
                    index,
                    sub,
                    ty: typed(index, sub),
                },
                text: format!("sdo read {}", object_name(dict, index, sub)),
                value: None,
                frame: Some(super::spec::candump(&super::sdo::first_upload_frame(
                    node, index, sub, false,
                ))),
            }
        }
        Step::Nmt { command, node: to } => {
            let target = match to {
                Some(e) => {
                    let t = e.eval(vars)?;
                    u8::try_from(t)
                        .ok()
                        .filter(|t| *t <= 127)
                        .ok_or(StepError::NmtNode(t))?
                }
                None => node,
            };
            let action = nmt_action(*command);
            let f = super::nmt::frame(action, target);
            let whom = if target == 0 {
                "all nodes".to_string()
            } else {
                format!("node {target}")
            };
            PlannedStep {
                action: Action::Nmt { action, target },
                text: format!("nmt {} to {whom}", nmt_word(*command)),
                value: None,
                frame: Some(super::spec::candump(&f)),
            }
        }
        Step::Frame { id, data } => {
            let id = id.eval(vars)?;
            let id = u32::try_from(id)
                .ok()
                .filter(|i| *i <= 0x1FFF_FFFF)
                .ok_or(StepError::FrameId(id))?;
            let f = Frame::classic(id, &frame_bytes(data, vars)?);
            let c = super::spec::candump(&f);
            PlannedStep {
                action: Action::Frame(f),
                text: format!("frame {c}"),
                value: None,
                frame: Some(c),
            }
        }
        Step::Wait {
            object,
            mask,
            equals,
            timeout_ms,
            fail_if,
        } => {
            let (index, sub) = resolve_object(dict, &fill_object(object, vars)?)?;
            let (mask, equals) = (mask.eval(vars)?, equals.eval(vars)?);
            let fail_if = match fail_if {
                Some(f) => Some((f.mask.eval(vars)?, f.equals.eval(vars)?, f.text.clone())),
                None => None,
            };
            let fails_on = fail_if
                .as_ref()
                .map(|f| format!(", fails on {}", f.2))
                .unwrap_or_default();
            let shown_mask = if mask == -1 {
                String::new()
            } else {
                format!(" & 0x{mask:04X}")
            };
            PlannedStep {
                action: Action::Wait {
                    index,
                    sub,
                    ty: typed(index, sub),
                    mask,
                    equals,
                    timeout_ms: *timeout_ms,
                    fail_if,
                },
                text: format!(
                    "wait until {}{shown_mask} == 0x{equals:04X} (at most {timeout_ms} ms{})",
                    object_name(dict, index, sub),
                    fails_on
                ),
                value: Some(equals),
                frame: Some(super::spec::candump(&super::sdo::first_upload_frame(
                    node, index, sub, false,
                ))),
            }
        }
        Step::Delay { ms } => PlannedStep {
            action: Action::Delay { ms: *ms },
            text: format!("delay {ms} ms"),
            value: None,
            frame: None,
        },
    })
}

/// What a step did, its `result` in the JSON of a run.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum StepResult {
    /// `"written"`, `"sent"`, `"done"`, `"not sent"`.
    Word(&'static str),
    /// An SDO read: the value, its meaning, the bytes.
    Read { value: Value, text: String, data: String },
    /// A wait reached: the value read, its meaning, after how long.
    Reached { value: i64, text: String, after_ms: u64 },
    /// The step that failed.
    Failed { error: String },
}

/// One step in the JSON of a run.
#[derive(Debug, Serialize)]
struct StepJson {
    step: usize,
    kind: &'static str,
    object: Option<String>,
    value: Option<i64>,
    frame: Option<String>,
    text: String,
    result: StepResult,
}

fn step_json(s: &PlannedStep, number: usize, result: StepResult) -> StepJson {
    StepJson {
        step: number,
        kind: s.kind(),
        object: s.object(),
        value: s.value,
        frame: s.frame.clone(),
        text: s.text.clone(),
        result,
    }
}

/// The JSON of a run (or dry run) of a procedure.
#[derive(Debug, Serialize)]
pub struct RunJson {
    ok: bool,
    procedure: String,
    node: u8,
    /// Every parameter with the value used.
    params: BTreeMap<String, i64>,
    steps: Vec<StepJson>,
    #[serde(skip_serializing_if = "Option::is_none")]
    dry_run: Option<bool>,
}

impl RunJson {
    /// The last line of a successful run.
    pub fn summary(&self) -> String {
        format!(
            "`{}` on node {}: {} steps done",
            self.procedure,
            self.node,
            self.steps.len()
        )
    }

    /// A dry run made to check a procedure before running it says so.
    pub(crate) fn checked(mut self) -> RunJson {
        self.dry_run = Some(false);
        self
    }
}

fn plan_json(plan: &RunPlan, steps: Vec<StepJson>, ok: bool) -> RunJson {
    RunJson {
        ok,
        procedure: plan.procedure.clone(),
        node: plan.node,
        params: plan.params.iter().map(|(n, v)| (n.clone(), *v)).collect(),
        steps,
        dry_run: None,
    }
}

/// `run --list --json`.
#[derive(Debug, Serialize)]
pub struct ListJson {
    ok: bool,
    node: u8,
    procedures: Vec<ProcedureJson>,
}

/// One procedure of a listing.
#[derive(Debug, Serialize)]
struct ProcedureJson {
    name: String,
    description: Option<String>,
    steps: usize,
    params: Vec<ParamJson>,
}

/// One parameter of a procedure.
#[derive(Debug, Serialize)]
struct ParamJson {
    name: String,
    unit: Option<String>,
    description: Option<String>,
    default: Option<i64>,
}

/// The outcome of `--dry-run`: every step with its frame, `result` "not sent"; the text's
/// first line is the summary (the palette shows one line).
pub fn dry_run(plan: &RunPlan) -> (RunJson, String) {
    let n = plan.steps.len();
    let steps = (1..)
        .zip(&plan.steps)
        .map(|(k, s)| step_json(s, k, StepResult::Word("not sent")))
        .collect();
    let v = RunJson {
        dry_run: Some(true),
        ..plan_json(plan, steps, true)
    };
    let mut lines = vec![format!(
        "dry run of `{}` on node {}: {n} steps, nothing sent",
        plan.procedure, plan.node
    )];
    lines.extend((1..).zip(&plan.steps).map(|(k, s)| s.line(k, n)));
    (v, lines.join("\n"))
}

/// The procedures of `dict` with their descriptions and parameters (JSON and text; the
/// text's first line names them all).
pub fn list(dict: &Dictionary, node: u8) -> (ListJson, String) {
    let procs = dict.procedures();
    let items: Vec<ProcedureJson> = procs
        .iter()
        .map(|p| ProcedureJson {
            name: p.name.clone(),
            description: p.description.clone(),
            steps: p.steps.len(),
            params: p
                .params
                .iter()
                .map(|q| ParamJson {
                    name: q.name.clone(),
                    unit: q.unit.clone(),
                    description: q.description.clone(),
                    default: q.default,
                })
                .collect(),
        })
        .collect();
    let text = if procs.is_empty() {
        format!("node {node} has no procedures (bind a profile: --profile {node}=NAME)")
    } else {
        let names: Vec<&str> = procs.iter().map(|p| p.name.as_str()).collect();
        let header = format!("node {node} procedures: {}", names.join(", "));
        std::iter::once(header)
            .chain(procs.iter().map(|p| {
                let mut t = format!("{}  {}", p.name, p.description.as_deref().unwrap_or(""));
                for q in &p.params {
                    let default = q.default.map_or("required".to_string(), |d| format!("default {d}"));
                    let unit = q.unit.as_deref().map(|u| format!(" {u}")).unwrap_or_default();
                    let about = q.description.as_deref().map(|d| format!(": {d}")).unwrap_or_default();
                    t.push_str(&format!("\n    {}=VALUE ({default}{unit}){about}", q.name));
                }
                t
            }))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let json = ListJson {
        ok: true,
        node,
        procedures: items,
    };
    (json, text)
}

/// Runs `plan` on `bus` step by step (`dict` gives the meaning of values read): `progress`
/// gets each step's line before it is sent and its result after. SDO steps wait for the
/// answer (`timeout_ms` each); the first failure stops the run and comes back as
/// [`CommandError::Step`], with the steps done so far. A listen-only bus fails before step 1.
pub async fn run(
    bus: &Bus,
    dict: &Dictionary,
    plan: &RunPlan,
    timeout_ms: u64,
    progress: &mut (dyn FnMut(&str) + Send),
) -> Result<RunJson, CommandError> {
    if bus.is_listen_only() {
        return Err(BusError::ListenOnly.into());
    }
    let n = plan.steps.len();
    let mut done = Vec::with_capacity(n);
    // The mode of operation the run set (6060h), so that statusword bits read back are named for it.
    let mut mode: Option<i8> = None;
    for (k, s) in (1..).zip(&plan.steps) {
        progress(&s.line(k, n));
        if let Action::SdoWrite {
            index: 0x6060,
            sub: 0,
            data,
        } = &s.action
        {
            mode = data.first().map(|m| *m as i8);
        }
        match run_step(bus, dict, plan.node, s, (k, n), timeout_ms, mode).await {
            Ok((result, text)) => {
                progress(&format!("  -> {text}"));
                done.push(step_json(s, k, result));
            }
            Err(e) => {
                progress(&format!("  -> failed: {e}"));
                done.push(step_json(s, k, StepResult::Failed { error: e.to_string() }));
                return Err(CommandError::Step {
                    procedure: plan.procedure.clone(),
                    step: k,
                    of: n,
                    report: Reported::new(plan_json(plan, done, false)),
                    cause: Box::new(e),
                });
            }
        }
    }
    Ok(plan_json(plan, done, true))
}

/// Runs one step; gives its `result` JSON and text.
async fn run_step(
    bus: &Bus,
    dict: &Dictionary,
    node: u8,
    s: &PlannedStep,
    (k, n): (usize, usize),
    timeout_ms: u64,
    mode: Option<i8>,
) -> Result<(StepResult, String), CommandError> {
    Ok(match &s.action {
        Action::SdoWrite { index, sub, data } => {
            super::sdo::download(bus, node, *index, *sub, data.clone(), false, timeout_ms).await?;
            (StepResult::Word("written"), format!("written ({})", hex::upper(data)))
        }
        Action::SdoRead { index, sub, ty } => {
            let data = super::sdo::upload(bus, node, *index, *sub, false, timeout_ms).await?;
            let text = read_text(dict, *index, *sub, *ty, &data, mode);
            (
                StepResult::Read {
                    value: decode(&data, *ty),
                    text: text.clone(),
                    data: hex::upper(&data),
                },
                text,
            )
        }
        Action::Nmt { action, target } => {
            super::nmt::nmt(bus, *action, *target, false, 0).await?;
            (StepResult::Word("sent"), "sent".into())
        }
        Action::Frame(f) => {
            bus.send(f).await?;
            (StepResult::Word("sent"), "sent".into())
        }
        Action::Delay { ms } => {
            tokio::time::sleep(Duration::from_millis(u64::from(*ms))).await;
            (StepResult::Word("done"), format!("waited {ms} ms"))
        }
        Action::Wait {
            index,
            sub,
            ty,
            mask,
            equals,
            timeout_ms: limit,
            fail_if,
        } => {
            let start = tokio::time::Instant::now();
            let limit_d = Duration::from_millis(u64::from(*limit));
            loop {
                let data = super::sdo::upload(bus, node, *index, *sub, false, timeout_ms).await?;
                let v = decode(&data, *ty).as_i64().unwrap_or(0);
                let text = read_text(dict, *index, *sub, *ty, &data, mode);
                if let Some((fail_mask, fail_equals, what)) = fail_if
                    && v & fail_mask == *fail_equals
                {
                    return Err(CommandError::Drive {
                        node,
                        step: format!("step {k}/{n} ({})", s.text),
                        reason: format!("{what}; read {text}"),
                    });
                }
                if v & mask == *equals {
                    let ms = u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX);
                    return Ok((
                        StepResult::Reached {
                            value: v,
                            text: text.clone(),
                            after_ms: ms,
                        },
                        format!("{text} after {ms} ms"),
                    ));
                }
                if start.elapsed() >= limit_d {
                    return Err(CommandError::Drive {
                        node,
                        step: format!("step {k}/{n} ({})", s.text),
                        reason: format!("not reached in {limit} ms; last read {text}"),
                    });
                }
                tokio::time::sleep(Duration::from_millis(20)).await;
            }
        }
    })
}

fn read_text(dict: &Dictionary, index: u16, sub: u8, ty: Option<DataType>, data: &[u8], mode: Option<i8>) -> String {
    let shown = object_text(dict, index, sub, &decode(data, ty), mode);
    format!("0x{index:04X}:{sub:02X} = {shown}")
}

fn nmt_action(c: NmtCommand) -> NmtAction {
    match c {
        NmtCommand::Start => NmtAction::Start,
        NmtCommand::Stop => NmtAction::Stop,
        NmtCommand::PreOperational => NmtAction::PreOp,
        NmtCommand::Reset => NmtAction::ResetNode,
        NmtCommand::ResetCommunication => NmtAction::ResetComm,
    }
}

fn nmt_word(c: NmtCommand) -> &'static str {
    match c {
        NmtCommand::Start => "start",
        NmtCommand::Stop => "stop",
        NmtCommand::PreOperational => "pre-operational",
        NmtCommand::Reset => "reset",
        NmtCommand::ResetCommunication => "reset-communication",
    }
}
