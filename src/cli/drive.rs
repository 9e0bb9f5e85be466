//! `cotui drive IFACE NODE enable|disable|quick-stop|fault-reset|status|mode MODE`.

use super::commander::{BusArgs, ms_arg, node_arg, run};
use crate::command::DriveAction;
use crate::command::grammar::DEFAULT_TIMEOUT_MS;
use clap::Args;

/// Arguments of `cotui drive`.
#[derive(Args, Debug)]
pub struct DriveArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Node id 1..127 (decimal or 0x hex).
    #[arg(value_parser = node_arg)]
    pub node: u8,
    /// enable, disable, quick-stop, fault-reset, status, or mode.
    pub action: String,
    /// The mode for `mode`: pp, pv, pt, hm, ip, csp, csv, cst or a number.
    pub mode: Option<String>,
    /// How long to wait for each SDO answer, and half of how long each step may take, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

fn text(v: &serde_json::Value) -> String {
    let mut s = format!(
        "node {}: {} (statusword {})",
        v["node"],
        v["state_text"].as_str().unwrap_or(""),
        v["statusword"].as_str().unwrap_or("")
    );
    if let Some(cws) = v["controlwords"].as_array()
        && !cws.is_empty()
    {
        let list: Vec<&str> = cws.iter().filter_map(|c| c.as_str()).collect();
        s.push_str(&format!(", controlwords {}", list.join(" -> ")));
    }
    if let Some(m) = v["mode_display"].as_i64() {
        s.push_str(&format!(", mode {m} ({})", crate::decode::cia402::mode_name(m as i8)));
    }
    if let Some(e) = v["error_code"].as_str()
        && e != "0x0000"
    {
        s.push_str(&format!(", error code {e}"));
    }
    s
}

/// Runs `cotui drive`; returns the exit status.
pub fn run_drive(args: &DriveArgs) -> i32 {
    let action = DriveAction::parse(&args.action, args.mode.as_deref());
    let (node, timeout) = (args.node, args.timeout);
    run(&args.bus, "drive", text, |bus| async move {
        let action = action.map_err(crate::command::CommandError::Usage)?;
        let r = crate::command::drive::drive(&bus, node, action, timeout).await?;
        Ok(r.to_json())
    })
}
