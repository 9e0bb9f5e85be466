//! `dcf save|load|diff NODE ...` as the commander declares them: the words, the preview and
//! the run of [`super::execute`].

use super::{Dcf, DcfAction};
use crate::command::error::{CommandError, ParseError};
use crate::command::grammar::DEFAULT_TIMEOUT_MS;
use crate::command::spec::{Ctx, Declared, Known, Outcome, Preview, Spec};
use crate::command::words::{On, ms_arg, node_arg};
use clap::Args;

/// `dcf save`, `dcf load` and `dcf diff`.
#[derive(clap::Subcommand, Clone, Debug)]
pub enum DcfCommand<B: Args, D: Args> {
    /// Read every readable object the node's dictionary knows and write a DCF: `dcf save 5 -o node5.dcf`.
    Save(On<B, DcfSaveArgs<D>>),
    /// Write the file's writable values that differ from the node's, PDO mappings by the CiA
    /// 301 sequence, communication objects last; read them back: `dcf load 5 node5.dcf --store`.
    Load(On<B, DcfLoadArgs<D>>),
    /// Show the objects whose values differ between the file and the node (exit status 6
    /// when any writable one does): `dcf diff 5 node5.dcf`.
    Diff(On<B, DcfDiffArgs<D>>),
}

/// `dcf save NODE -o FILE [--force] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct DcfSaveArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The DCF to write. An existing file is refused unless --force.
    #[arg(short = 'o', long)]
    pub output: String,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
    /// How long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// `dcf load NODE FILE [--store] [--dry-run] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct DcfLoadArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The DCF to load.
    pub file: String,
    /// Then write "save" (0x65766173) to 0x1010:01 to store the configuration.
    #[arg(long)]
    pub store: bool,
    /// Read the node and print what would be written; write nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// How long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// `dcf diff NODE FILE [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct DcfDiffArgs<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// The DCF to compare with.
    pub file: String,
    /// How long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

impl<B: Args, D: Args> Declared<B, D> for DcfCommand<B, D> {
    type Spec = Dcf;

    fn bus(&self) -> &B {
        match self {
            DcfCommand::Save(o) => &o.bus,
            DcfCommand::Load(o) => &o.bus,
            DcfCommand::Diff(o) => &o.bus,
        }
    }

    fn dict(&self) -> Option<&D> {
        match self {
            DcfCommand::Save(o) => Some(&o.args.dict),
            DcfCommand::Load(o) => Some(&o.args.dict),
            DcfCommand::Diff(o) => Some(&o.args.dict),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            DcfCommand::Save(_) => "dcf save",
            DcfCommand::Load(_) => "dcf load",
            DcfCommand::Diff(_) => "dcf diff",
        }
    }

    fn spec(&self) -> Result<Dcf, ParseError> {
        let dcf = |node, action, timeout_ms| Dcf {
            node,
            action,
            timeout_ms,
        };
        Ok(match self {
            DcfCommand::Save(On { args: a, .. }) => dcf(
                a.node,
                DcfAction::Save {
                    output: a.output.clone(),
                    force: a.force,
                },
                a.timeout,
            ),
            DcfCommand::Load(On { args: a, .. }) => dcf(
                a.node,
                DcfAction::Load {
                    file: a.file.clone(),
                    store: a.store,
                    dry_run: a.dry_run,
                },
                a.timeout,
            ),
            DcfCommand::Diff(On { args: a, .. }) => dcf(a.node, DcfAction::Diff { file: a.file.clone() }, a.timeout),
        })
    }
}

impl Spec for Dcf {
    /// What it reads and writes (the frames depend on the dictionary and the file); a load
    /// that writes needs confirming.
    fn preview(&self, _known: &Known<'_>) -> Result<Preview, CommandError> {
        let n = self.node;
        Ok(match &self.action {
            DcfAction::Save { output, .. } => Preview::sends(format!(
                "reads every object node {n}'s dictionary knows by SDO, writes {output}"
            )),
            DcfAction::Diff { file } => Preview::sends(format!("reads node {n} by SDO, compares with {file}")),
            DcfAction::Load {
                file, dry_run: true, ..
            } => Preview::sends(format!(
                "reads node {n} by SDO, lists what {file} would write (writes nothing)"
            )),
            DcfAction::Load { file, store, .. } => Preview {
                frames: format!(
                    "reads node {n}, writes the values of {file} that differ (PDOs remapped), reads them back{}",
                    if *store { ", stores (0x1010:01)" } else { "" }
                ),
                confirm: Some(format!("dcf load writes node {n}'s configuration from {file}")),
            },
        })
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        super::execute(ctx.bus, ctx.bindings.dictionary(self.node), self).await
    }

    fn data_to_stdout(&self) -> bool {
        matches!(&self.action, DcfAction::Save { output, .. } if output == "-")
    }

    /// `--eds FILE` without `NODE=`: the EDS of the one node the command is about.
    fn node(&self) -> Option<u8> {
        Some(self.node)
    }
}
