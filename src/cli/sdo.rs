//! `cotui sdo read|write IFACE NODE OBJECT [VALUE] [--type T] [--block] [--timeout MS]`.

use super::commander::{BusArgs, ms_arg, node_arg, run};
use crate::command::CommandError;
use crate::command::grammar::{DEFAULT_TIMEOUT_MS, parse_type};
use crate::command::value::{decode, encode};
use crate::od::alias::resolve_object;
use crate::od::{DataType, Dictionary};
use clap::{Args, Subcommand};

/// `cotui sdo` subcommands.
#[derive(Subcommand, Debug)]
pub enum SdoCommand {
    /// Read an object: `cotui sdo read can0 2 0x6041`.
    Read(SdoReadArgs),
    /// Write an object: `cotui sdo write can0 2 0x6060 3 --type i8`.
    Write(SdoWriteArgs),
}

/// Options of both directions.
#[derive(Args, Debug)]
pub struct Transfer {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// Object: 0x6041, 0x1018:1, or an object name from the node's profile.
    pub object: String,
    /// Value type: u8..u64, i8..i64, f32, f64, bool, string, octets (hex), domain (a file).
    #[arg(long = "type", short = 't', value_parser = parse_type)]
    pub data_type: Option<DataType>,
    /// Force a block transfer.
    #[arg(long)]
    pub block: bool,
    /// How long to wait for each server response, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    /// Bind a device profile to a node: NODE=NAME (names, aliases and types come from it).
    #[arg(long = "profile", value_name = "NODE=NAME")]
    pub profiles: Vec<String>,
    /// Bind an EDS/DCF file to a node: NODE=FILE.
    #[arg(long = "eds", value_name = "NODE=FILE")]
    pub eds: Vec<String>,
}

/// Arguments of `cotui sdo read`.
#[derive(Args, Debug)]
pub struct SdoReadArgs {
    #[command(flatten)]
    pub t: Transfer,
    /// Write the data read to this file (for domains).
    #[arg(long = "output", short = 'o')]
    pub output: Option<String>,
}

/// Arguments of `cotui sdo write`.
#[derive(Args, Debug)]
pub struct SdoWriteArgs {
    #[command(flatten)]
    pub t: Transfer,
    /// The value (a file path for `--type domain`, hex bytes for `--type octets`).
    pub value: String,
}

fn text(v: &serde_json::Value) -> String {
    let obj = format!(
        "node {} {}:{:02X}",
        v["node"],
        v["index"].as_str().unwrap_or("").trim_start_matches("0x"),
        v["sub"].as_u64().unwrap_or(0)
    );
    let data = v["data"].as_str().unwrap_or("");
    if v["written"].as_bool() == Some(true) {
        format!("{obj} written ({} bytes: {data})", v["len"])
    } else {
        let name = v["name"].as_str().map(|n| format!(" {n}")).unwrap_or_default();
        let shown = match (&v["text"], &v["value"]) {
            (serde_json::Value::String(t), _) => t.clone(),
            (_, serde_json::Value::String(raw)) => raw.clone(),
            (_, other) => other.to_string(),
        };
        format!("{obj}{name} = {shown} [{data}]")
    }
}

/// Runs `cotui sdo`; returns the exit status.
pub fn run_sdo(cmd: &SdoCommand) -> i32 {
    match cmd {
        SdoCommand::Read(a) => read(a),
        SdoCommand::Write(a) => write(a),
    }
}

/// The node's dictionary (from `--profile`/`--eds`, else CiA 402 + CiA 301) and the object.
fn target(t: &Transfer) -> Result<(Dictionary, u16, u8), CommandError> {
    let b = super::bind::bindings(&t.profiles, &t.eds).map_err(CommandError::Usage)?;
    let dict = b.dictionary(t.node).clone();
    let (index, sub) = resolve_object(&dict, &t.object).map_err(CommandError::Usage)?;
    Ok((dict, index, sub))
}

/// The value's type: `--type`, else the dictionary's for a fixed-size or string object.
fn value_type(t: &Transfer, dict: &Dictionary, index: u16, sub: u8) -> Option<DataType> {
    t.data_type.or_else(|| dict.object(index, sub).map(|o| o.data_type))
}

fn read(a: &SdoReadArgs) -> i32 {
    let t = &a.t;
    let (node, block, timeout) = (t.node, t.block, t.timeout);
    let output = a.output.clone();
    let object = target(t).map(|(dict, index, sub)| {
        let ty = value_type(t, &dict, index, sub);
        (dict, index, sub, ty)
    });
    run(&t.bus, "sdo read", text, |bus| async move {
        let (dict, index, sub, ty) = object?;
        let data = crate::command::sdo::upload(&bus, node, index, sub, block, timeout).await?;
        if let Some(path) = &output {
            std::fs::write(path, &data).map_err(|e| CommandError::Usage(format!("cannot write {path}: {e}")))?;
        }
        let value = decode(&data, ty);
        let info = dict.object(index, sub);
        Ok(serde_json::json!({
            "ok": true,
            "node": node,
            "index": format!("0x{index:04X}"),
            "sub": sub,
            "name": dict.name(index, sub),
            "value": value.to_json(),
            "text": value
                .as_i64()
                .and_then(|raw| crate::decode::cia402::describe(index, sub, raw, None))
                .or_else(|| info.map(|i| crate::od::format_value(Some(i), &value))),
            "data": crate::hex::upper(&data),
            "len": data.len(),
        }))
    })
}

fn write(a: &SdoWriteArgs) -> i32 {
    let t = &a.t;
    let (node, block, timeout) = (t.node, t.block, t.timeout);
    let prepared = target(t).and_then(|(dict, index, sub)| {
        let data = match value_type(t, &dict, index, sub) {
            Some(DataType::Domain) => std::fs::read(&a.value)
                .map_err(|e| CommandError::Usage(format!("cannot read {}: {e}", a.value)))?,
            Some(ty) => encode(&a.value, ty).map_err(CommandError::Usage)?,
            None => {
                return Err(CommandError::Usage(format!(
                    "the type of {index:04X}:{sub:02X} is unknown: give --type (u8..u64, i8..i64, f32, f64, bool, string, octets, domain)"
                )));
            }
        };
        Ok((index, sub, data))
    });
    run(&t.bus, "sdo write", text, |bus| async move {
        let (index, sub, data) = prepared?;
        crate::command::sdo::download(&bus, node, index, sub, data.clone(), block, timeout).await?;
        Ok(serde_json::json!({
            "ok": true,
            "written": true,
            "node": node,
            "index": format!("0x{index:04X}"),
            "sub": sub,
            "data": crate::hex::upper(&data),
            "len": data.len(),
        }))
    })
}
