//! `run NODE [PROCEDURE] [NAME=VALUE ...] [--list] [--dry-run] [--timeout MS]` as the
//! commander declares it: the words (the parameters checked by the declaration), the
//! preview (every step's frame, from [`super::plan`]) and the run of [`super::run`].

use super::{Action, list, plan};
use crate::command::error::{CommandError, ParseError};
use crate::command::grammar::DEFAULT_TIMEOUT_MS;
use crate::command::nmt::NmtAction;
use crate::command::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use crate::command::words::{ms_arg, node_arg};
use crate::od::bind::Bindings;
use clap::builder::TypedValueParser;
use clap::error::ErrorKind;

/// `run NODE [PROCEDURE] [NAME=VALUE ...] [--list] [--dry-run] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs<D: clap::Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The procedure (e.g. `pv`); none: list the procedures.
    #[arg(value_parser = Word::Procedure)]
    pub procedure: Option<String>,
    /// The procedure's parameters as NAME=VALUE.
    #[arg(value_parser = Word::Param)]
    pub params: Vec<String>,
    /// List the node's procedures with their descriptions and parameters.
    #[arg(long)]
    pub list: bool,
    /// Print the steps and their frames without sending anything.
    #[arg(long)]
    pub dry_run: bool,
    /// How long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// The checks of `run`'s words, refusing with the words' own message (no clap prefix).
#[derive(Clone, Copy)]
enum Word {
    /// A procedure name: not a NAME=VALUE (those come after it).
    Procedure,
    /// NAME=VALUE.
    Param,
}

impl TypedValueParser for Word {
    type Value = String;

    fn parse_ref(
        &self,
        _cmd: &clap::Command,
        _arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        let w = value.to_string_lossy().into_owned();
        let refused = match self {
            Word::Procedure if w.contains('=') => {
                "run: give the PROCEDURE before its NAME=VALUE parameters".to_string()
            }
            Word::Param if w.split_once('=').is_none_or(|(n, _)| n.is_empty()) => {
                format!("`{w}` is not a parameter: write NAME=VALUE, e.g. speed=100")
            }
            _ => return Ok(w),
        };
        Err(clap::Error::raw(ErrorKind::ValueValidation, format!("{refused}\n")))
    }
}

/// What `run` runs: a procedure of a node with its parameters, or (no procedure) the list.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunSpec {
    /// The target node.
    pub node: u8,
    /// `None`: list the node's procedures.
    pub procedure: Option<String>,
    /// Parameters as given, `NAME=VALUE` split at the first `=`.
    pub args: Vec<(String, String)>,
    /// Show the steps and frames without sending anything.
    pub dry_run: bool,
    /// ms to wait for each SDO answer.
    pub timeout_ms: u64,
}

impl<D: clap::Args> CommandArgs<D> for RunArgs<D> {
    type Spec = RunSpec;
    const NAME: &'static str = "run";

    fn dict(&self) -> Option<&D> {
        Some(&self.dict)
    }

    fn spec(&self) -> Result<RunSpec, ParseError> {
        if self.list && self.procedure.is_some() {
            return Err(ParseError::Invalid("run: give a PROCEDURE or --list, not both".into()));
        }
        Ok(RunSpec {
            node: self.node,
            procedure: self.procedure.clone(),
            // The declaration checked each is NAME=VALUE.
            args: self
                .params
                .iter()
                .filter_map(|w| w.split_once('='))
                .map(|(n, v)| (n.to_string(), v.to_string()))
                .collect(),
            dry_run: self.dry_run,
            timeout_ms: self.timeout,
        })
    }
}

impl RunSpec {
    /// What `run` gives without a bus: the listing (no procedure) or the dry run (also made
    /// to check a procedure and its parameters before the bus is opened).
    fn without_bus(&self, bindings: &Bindings) -> Result<Outcome, CommandError> {
        let dict = bindings.dictionary(self.node);
        Ok(match &self.procedure {
            None => {
                let (json, text) = list(dict, self.node);
                Outcome::new(json, text)
            }
            Some(name) => {
                let p = plan(dict, self.node, name, &self.args)?;
                let (json, text) = super::dry_run(&p);
                Outcome::new(if self.dry_run { json } else { json.checked() }, text)
            }
        })
    }
}

impl Spec for RunSpec {
    /// Every step's frame; a step that broadcasts NMT or resets a node needs confirming.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        let Some(name) = &self.procedure else {
            return Ok(Preview::sends(format!(
                "nothing: lists the procedures of node {}",
                self.node
            )));
        };
        let p = plan(known.bindings.dictionary(self.node), self.node, name, &self.args)?;
        let steps: Vec<String> = p.steps.iter().map(|s| s.preview()).collect();
        if self.dry_run {
            return Ok(Preview::sends(format!("nothing (dry run of {})", steps.join(", "))));
        }
        let confirm = p.steps.iter().find_map(|s| match s.action {
            Action::Nmt { action, target }
                if target == 0 || matches!(action, NmtAction::ResetNode | NmtAction::ResetComm) =>
            {
                Some(format!("`{name}` sends {}", s.text))
            }
            _ => None,
        });
        Ok(Preview {
            frames: steps.join(", "),
            confirm,
        })
    }

    /// Lists, dry-runs or runs the procedure. Each step's line goes to `ctx.lines` as it
    /// happens when given (the text is then the summary line), else the text is the summary
    /// line followed by every step line and result.
    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let offline = self.without_bus(ctx.bindings)?;
        let Some(name) = self.procedure.as_deref().filter(|_| !self.dry_run) else {
            return Ok(offline);
        };
        let dict = ctx.bindings.dictionary(self.node);
        let p = plan(dict, self.node, name, &self.args)?;
        let mut lines = Vec::new();
        let json = match ctx.lines {
            Some(say) => super::run(ctx.bus, dict, &p, self.timeout_ms, say).await?,
            None => super::run(ctx.bus, dict, &p, self.timeout_ms, &mut |l| lines.push(l.to_string())).await?,
        };
        // The summary first: the palette's message line shows one line.
        lines.insert(0, json.summary());
        Ok(Outcome::new(json, lines.join("\n")))
    }

    /// The procedure and its parameters are checked before the bus is opened.
    fn answers_offline(&self) -> bool {
        true
    }

    /// The listing and the dry run need no bus; a bad procedure or parameter is refused.
    fn offline(&self, bindings: &Bindings) -> Option<Result<Outcome, CommandError>> {
        match self.without_bus(bindings) {
            Ok(_) if self.procedure.is_some() && !self.dry_run => None,
            result => Some(result),
        }
    }
}
