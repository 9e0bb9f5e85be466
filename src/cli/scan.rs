//! `cotui scan IFACE [--listen MS] [--probe]`.

use super::commander::{BusArgs, ms_arg, run};
use clap::Args;

/// Arguments of `cotui scan`.
#[derive(Args, Debug)]
pub struct ScanArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// How long to listen for heartbeats and boot-ups, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = 1500)]
    pub listen: u64,
    /// Also ask every node 1..127 for 0x1000 (finds nodes without heartbeat).
    #[arg(long)]
    pub probe: bool,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = 300)]
    pub timeout: u64,
}

fn text(v: &serde_json::Value) -> String {
    let nodes = v["nodes"].as_array().cloned().unwrap_or_default();
    if nodes.is_empty() {
        return "no nodes found (no heartbeat or boot-up heard; try --probe)".into();
    }
    let s = |x: &serde_json::Value| x.as_str().unwrap_or("-").to_string();
    nodes
        .iter()
        .map(|n| {
            let mut line = format!(
                "node {:>3}  {:<16} type {}  vendor {}  product {}  rev {}  serial {}  {}",
                n["node"],
                s(&n["nmt"]),
                s(&n["device_type"]),
                s(&n["vendor_id"]),
                s(&n["product_code"]),
                s(&n["revision"]),
                s(&n["serial"]),
                n["device_name"]
                    .as_str()
                    .map(|d| format!("\"{d}\""))
                    .unwrap_or_default()
            );
            if let Some(p) = n["profile"].as_str() {
                line.push_str(&format!("  profile {p} (--profile {}={p})", n["node"]));
            }
            if let Some(e) = n["sdo_error"].as_str() {
                line.push_str(&format!("  ({e})"));
            }
            line
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs `cotui scan`; returns the exit status.
pub fn run_scan(args: &ScanArgs) -> i32 {
    let (listen, probe, timeout) = (args.listen, args.probe, args.timeout);
    run(&args.bus, "scan", text, |bus| async move {
        let nodes = crate::command::scan::scan(&bus, listen, probe, timeout).await?;
        Ok(serde_json::json!({
            "ok": true,
            "nodes": nodes.iter().map(|n| n.to_json()).collect::<Vec<_>>(),
        }))
    })
}
