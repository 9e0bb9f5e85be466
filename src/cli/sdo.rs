//! `cotui sdo read|write IFACE NODE OBJECT [VALUE] [--type T] [--block] [--timeout MS]`.

use super::commander::{BusArgs, ms_arg, node_arg, run};
use crate::command::CommandError;
use crate::command::grammar::{DEFAULT_TIMEOUT_MS, parse_type};
use crate::command::value::{decode, encode, resolve};
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
}

/// Arguments of `cotui sdo read`.
#[derive(Args, Debug)]
pub struct SdoReadArgs {
    #[command(flatten)]
    pub t: Transfer,
    /// Write the data read to this file (for domains).
    #[arg(long, short = 'o')]
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
        format!("{obj} = {} [{data}]", v["value"])
    }
}

/// Runs `cotui sdo`; returns the exit status.
pub fn run_sdo(cmd: &SdoCommand) -> i32 {
    match cmd {
        SdoCommand::Read(a) => read(a),
        SdoCommand::Write(a) => write(a),
    }
}

fn target(t: &Transfer) -> Result<(u16, u8), CommandError> {
    resolve(&Dictionary::default(), &t.object).map_err(CommandError::Usage)
}

fn read(a: &SdoReadArgs) -> i32 {
    let t = &a.t;
    let (node, block, timeout, ty) = (t.node, t.block, t.timeout, t.data_type);
    let output = a.output.clone();
    let object = target(t);
    run(&t.bus, "sdo read", text, |bus| async move {
        let (index, sub) = object?;
        let data = crate::command::sdo::upload(&bus, node, index, sub, block, timeout).await?;
        if let Some(path) = &output {
            std::fs::write(path, &data).map_err(|e| CommandError::Usage(format!("cannot write {path}: {e}")))?;
        }
        let value = decode(&data, ty);
        Ok(serde_json::json!({
            "ok": true,
            "node": node,
            "index": format!("0x{index:04X}"),
            "sub": sub,
            "value": value.to_json(),
            "data": crate::hex::upper(&data),
            "len": data.len(),
        }))
    })
}

fn write(a: &SdoWriteArgs) -> i32 {
    let t = &a.t;
    let (node, block, timeout) = (t.node, t.block, t.timeout);
    let object = target(t);
    let data = match t.data_type {
        Some(DataType::Domain) => {
            std::fs::read(&a.value).map_err(|e| CommandError::Usage(format!("cannot read {}: {e}", a.value)))
        }
        Some(ty) => encode(&a.value, ty).map_err(CommandError::Usage),
        None => Err(CommandError::Usage(
            "give the value's --type (u8..u64, i8..i64, f32, f64, bool, string, octets, domain)".into(),
        )),
    };
    run(&t.bus, "sdo write", text, |bus| async move {
        let (index, sub) = object?;
        let data = data?;
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
