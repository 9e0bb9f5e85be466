//! `cotui nmt IFACE start|stop|preop|reset-node|reset-comm NODE [--wait]`.

use super::commander::{BusArgs, ms_arg, node_or_all_arg, run};
use crate::command::NmtAction;
use crate::command::grammar::DEFAULT_TIMEOUT_MS;
use clap::Args;

/// Arguments of `cotui nmt`.
#[derive(Args, Debug)]
pub struct NmtArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// start, stop, preop, reset-node or reset-comm.
    #[arg(value_parser = NmtAction::parse)]
    pub action: NmtAction,
    /// Node id 1..127, or 0 for all nodes.
    #[arg(value_parser = node_or_all_arg)]
    pub node: u8,
    /// Wait for the heartbeat (or boot-up after a reset) that confirms the command.
    #[arg(long)]
    pub wait: bool,
    /// How long --wait waits, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = 2 * DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
}

fn text(v: &serde_json::Value) -> String {
    let mut s = format!(
        "NMT {} sent to {}",
        v["action"].as_str().unwrap_or(""),
        v["target"].as_str().unwrap_or("")
    );
    if let Some(m) = v["confirmed"].as_object() {
        for (node, state) in m {
            s.push_str(&format!("\nnode {node}: {}", state.as_str().unwrap_or("")));
        }
    }
    s
}

/// Runs `cotui nmt`; returns the exit status.
pub fn run_nmt(args: &NmtArgs) -> i32 {
    let (action, node, wait, timeout) = (args.action, args.node, args.wait, args.timeout);
    run(&args.bus, "nmt", text, |bus| async move {
        let seen = crate::command::nmt::nmt(&bus, action, node, wait, timeout).await?;
        let confirmed: serde_json::Map<String, serde_json::Value> =
            seen.iter().map(|(n, s)| (n.to_string(), s.as_str().into())).collect();
        Ok(serde_json::json!({
            "ok": true,
            "action": action.as_str(),
            "node": node,
            "target": if node == 0 { "all nodes".to_string() } else { format!("node {node}") },
            "confirmed": if wait { serde_json::Value::Object(confirmed) } else { serde_json::Value::Null },
        }))
    })
}
