//! `sdo read NODE OBJECT` and `sdo write NODE OBJECT VALUE`: one object by SDO, named by
//! index, index:sub or a name of the node's dictionary (the client is [`super::sdo`]).

use super::error::CommandError;
use super::grammar::DEFAULT_TIMEOUT_MS;
use super::sdo::{Timing, download_within, first_download_frame, first_upload_frame, upload_within};
use super::spec::{Ctx, Declared, Known, Outcome, Preview, Spec};
use super::value::{decode, encode};
use super::words::{On, ParseError, TYPE_WORDS, TypedWords, ms_arg, node_arg, parse_type};
use super::write::write_output;
use crate::od::bind::Bindings;
use crate::od::resolve_object;
use crate::od::{DataType, Dictionary, Value};
use clap::Args;
use serde::Serialize;

/// `sdo read` and `sdo write`.
#[derive(clap::Subcommand, Clone, Debug)]
pub enum SdoCommand<B: Args, D: Args> {
    /// Read an object: `sdo read 2 0x6041`.
    Read(On<B, SdoReadArgs<D>>),
    /// Write an object: `sdo write 2 0x6060 3 --type i8`.
    Write(On<B, SdoWriteArgs<D>>),
}

/// What `sdo read` and `sdo write` share.
#[derive(Args, Clone, Debug)]
pub struct Transfer<D: Args> {
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// Object: 0x6041, 0x1018:1, or an object name from the node's profile.
    pub object: String,
    /// Value type: u8..u64, i8..i64, f32, f64, bool, string, octets (hex), domain (a file).
    #[arg(long = "type", short = 't', value_parser = TypedWords::new(TYPE_WORDS, parse_type))]
    pub data_type: Option<DataType>,
    /// Force a block transfer.
    #[arg(long)]
    pub block: bool,
    /// How long to wait for each server response (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    /// How long the whole transfer may take, in ms [default: the longer of 10 s and 10
    /// timeouts, plus 1 ms per byte of the size written or announced by the server].
    #[arg(long, value_parser = ms_arg)]
    pub deadline: Option<u64>,
    #[command(flatten)]
    pub dict: D,
}

impl<D: Args> Transfer<D> {
    fn options(&self) -> SdoOptions {
        SdoOptions {
            data_type: self.data_type,
            block: self.block,
            timeout_ms: self.timeout,
            deadline_ms: self.deadline,
        }
    }
}

/// `sdo read NODE OBJECT [-o FILE] [transfer options]`.
#[derive(Args, Clone, Debug)]
pub struct SdoReadArgs<D: Args> {
    #[command(flatten)]
    pub t: Transfer<D>,
    /// Write the data read to this file (for domains).
    #[arg(long = "output", short = 'o')]
    pub output: Option<String>,
}

/// `sdo write NODE OBJECT VALUE [transfer options]`.
#[derive(Args, Clone, Debug)]
pub struct SdoWriteArgs<D: Args> {
    #[command(flatten)]
    pub t: Transfer<D>,
    /// The value (a file path for `--type domain`, hex bytes for `--type octets`); negative numbers need no `--`.
    #[arg(allow_negative_numbers = true)]
    pub value: String,
}

/// Options of an SDO transfer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SdoOptions {
    /// `--type`: how to encode/decode the value (else from the dictionary, else raw).
    pub data_type: Option<DataType>,
    /// `--block`: force a block transfer.
    pub block: bool,
    /// `--timeout`: ms to wait for each server response.
    pub timeout_ms: u64,
    /// `--deadline`: ms the whole transfer may take (`None`: the client's default, see
    /// [`crate::sdo::client::ClientConfig::default_deadline_ns`]).
    pub deadline_ms: Option<u64>,
}

impl Default for SdoOptions {
    fn default() -> Self {
        SdoOptions {
            data_type: None,
            block: false,
            timeout_ms: DEFAULT_TIMEOUT_MS,
            deadline_ms: None,
        }
    }
}

impl SdoOptions {
    /// The timeouts of the transfer.
    fn timing(&self) -> Timing {
        Timing {
            timeout_ms: self.timeout_ms,
            deadline_ms: self.deadline_ms,
        }
    }
}

/// `sdo read` or `sdo write`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sdo {
    Read(SdoRead),
    Write(SdoWrite),
}

/// `sdo read NODE OBJECT`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SdoRead {
    pub node: u8,
    pub object: String,
    pub options: SdoOptions,
    /// Also write the data read to this file (domains).
    pub output: Option<String>,
}

/// `sdo write NODE OBJECT VALUE` (a file path for domains).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SdoWrite {
    pub node: u8,
    pub object: String,
    pub value: String,
    pub options: SdoOptions,
}

impl<B: Args, D: Args> Declared<B, D> for SdoCommand<B, D> {
    type Spec = Sdo;

    fn bus(&self) -> &B {
        match self {
            SdoCommand::Read(o) => &o.bus,
            SdoCommand::Write(o) => &o.bus,
        }
    }

    fn dict(&self) -> Option<&D> {
        match self {
            SdoCommand::Read(o) => Some(&o.args.t.dict),
            SdoCommand::Write(o) => Some(&o.args.t.dict),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            SdoCommand::Read(_) => "sdo read",
            SdoCommand::Write(_) => "sdo write",
        }
    }

    fn spec(&self) -> Result<Sdo, ParseError> {
        Ok(match self {
            SdoCommand::Read(On { args: a, .. }) => Sdo::Read(SdoRead {
                node: a.t.node,
                object: a.t.object.clone(),
                options: a.t.options(),
                output: a.output.clone(),
            }),
            SdoCommand::Write(On { args: a, .. }) => Sdo::Write(SdoWrite {
                node: a.t.node,
                object: a.t.object.clone(),
                value: a.value.clone(),
                options: a.t.options(),
            }),
        })
    }
}

/// The object `object` names in `node`'s dictionary.
fn object(bindings: &Bindings, node: u8, object: &str) -> Result<(u16, u8), CommandError> {
    resolve_object(bindings.dictionary(node), object).map_err(|e| CommandError::Usage(e.to_string()))
}

/// `node 2 0x6041:00 Statusword`, as the texts name an object.
fn object_title(node: u8, index: u16, sub: u8, name: Option<&str>) -> String {
    let name = name.map(|n| format!(" {n}")).unwrap_or_default();
    format!("node {node} 0x{index:04X}:{sub:02X}{name}")
}

/// `sdo read --json`.
#[derive(Debug, Serialize)]
pub struct ObjectRead {
    ok: bool,
    node: u8,
    index: u16,
    sub: u8,
    name: Option<String>,
    value: Value,
    text: String,
    data: String,
    len: usize,
}

/// `sdo write --json`.
#[derive(Debug, Serialize)]
pub struct ObjectWritten {
    ok: bool,
    written: bool,
    node: u8,
    index: u16,
    sub: u8,
    name: Option<String>,
    data: String,
    len: usize,
}

impl Spec for Sdo {
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        match self {
            Sdo::Read(c) => c.preview(known),
            Sdo::Write(c) => c.preview(known),
        }
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        match self {
            Sdo::Read(c) => c.run(ctx).await,
            Sdo::Write(c) => c.run(ctx).await,
        }
    }

    fn data_to_stdout(&self) -> bool {
        matches!(self, Sdo::Read(c) if c.output.as_deref() == Some("-"))
    }
}

impl Spec for SdoRead {
    /// The client's first frame (and that block segments follow).
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        let (i, s) = object(known.bindings, self.node, &self.object)?;
        let first = super::spec::candump(&first_upload_frame(self.node, i, s, self.options.block));
        Ok(Preview::sends(if self.options.block {
            format!("{first} then the server's block segments")
        } else {
            first
        }))
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let (node, options) = (self.node, &self.options);
        let dict = ctx.bindings.dictionary(node);
        let (index, sub) = object(ctx.bindings, node, &self.object)?;
        let data = upload_within(ctx.bus, node, index, sub, options.block, options.timing()).await?;
        if let Some(path) = &self.output {
            write_output(path, &data)?;
        }
        let ty = options
            .data_type
            .or_else(|| dict.object(index, sub).map(|o| o.data_type));
        let value = decode(&data, ty);
        let read = ObjectRead {
            ok: true,
            node,
            index,
            sub,
            name: dict.name(index, sub).map(str::to_string),
            text: crate::decode::value_text::object_text(dict, index, sub, &value, None),
            value,
            data: crate::frame::hex::upper(&data),
            len: data.len(),
        };
        let text = format!(
            "{} = {} (data {})",
            object_title(node, index, sub, read.name.as_deref()),
            read.text,
            read.data
        );
        Ok(Outcome::new(read, text))
    }
}

impl Spec for SdoWrite {
    /// The client's first frame (and the segments that follow).
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        let dict = known.bindings.dictionary(self.node);
        let (i, s) = object(known.bindings, self.node, &self.object)?;
        let data = write_data(dict, i, s, &self.value, self.options.data_type)?;
        let (first, then) = first_download_frame(self.node, i, s, &data, self.options.block);
        Ok(Preview::sends(match then {
            Some(t) => format!("{} {t}", super::spec::candump(&first)),
            None => super::spec::candump(&first),
        }))
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let (node, options) = (self.node, &self.options);
        let dict = ctx.bindings.dictionary(node);
        let (index, sub) = object(ctx.bindings, node, &self.object)?;
        let data = write_data(dict, index, sub, &self.value, options.data_type)?;
        download_within(ctx.bus, node, index, sub, data.clone(), options.block, options.timing()).await?;
        let written = ObjectWritten {
            ok: true,
            written: true,
            node,
            index,
            sub,
            name: dict.name(index, sub).map(str::to_string),
            data: crate::frame::hex::upper(&data),
            len: data.len(),
        };
        let text = format!(
            "{} written ({} bytes: {})",
            object_title(node, index, sub, written.name.as_deref()),
            written.len,
            written.data
        );
        Ok(Outcome::new(written, text))
    }
}

/// The bytes an SDO write of `value` sends: typed by `ty`, else by the dictionary; a
/// domain value names the file to send.
pub fn write_data(
    dict: &Dictionary,
    index: u16,
    sub: u8,
    value: &str,
    ty: Option<DataType>,
) -> Result<Vec<u8>, CommandError> {
    match ty.or_else(|| dict.object(index, sub).map(|o| o.data_type)) {
        Some(DataType::Domain) => {
            let why = "the most a domain write sends";
            crate::files::read_at_most(std::path::Path::new(value), crate::files::MAX_DOMAIN, why)
                .map_err(|e| CommandError::Usage(format!("cannot read {value}: {e}")))
        }
        Some(t) => Ok(encode(value, t)?),
        None => Err(CommandError::Usage(format!(
            "the type of {index:04X}:{sub:02X} is unknown: give --type (u8..u64, i8..i64, f32, f64, bool, string, octets, domain)"
        ))),
    }
}
