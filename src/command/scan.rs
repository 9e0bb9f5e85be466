//! `scan`: which nodes are on the bus (heartbeats and boot-ups heard), then who they
//! are (SDO reads of 0x1000 device type, 0x1018 identity, 0x1008 device name).

use super::error::{CommandError, ParseError};
use super::grammar::{SCAN_LISTEN_MS, SCAN_TIMEOUT_MS};
use super::sdo::upload;
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::words::ms_arg;
use crate::bus::{Bus, BusError};
use crate::decode::heartbeat::NmtState;
use crate::frame::Direction;
use crate::od::Value;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Duration;
use tokio::task::JoinSet;

/// What a scan found out about one node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeInfo {
    pub node: u8,
    /// Last NMT state heard (heartbeat or boot-up), `None` when found only by probing.
    pub nmt: Option<NmtState>,
    /// 0x1000 device type.
    pub device_type: Option<u32>,
    /// 0x1018:1..4 vendor-ID, product code, revision, serial number.
    pub identity: [Option<u32>; 4],
    /// 0x1008 manufacturer device name.
    pub device_name: Option<String>,
    /// 0x100A manufacturer software version.
    pub software_version: Option<String>,
    /// The built-in profile the identity matches (suggested for `--profile NODE=NAME`).
    pub profile: Option<String>,
    /// Why the SDO reads failed, when they did.
    pub sdo_error: Option<String>,
}

impl NodeInfo {
    /// A node known only by its NMT state (nothing read from it yet).
    pub fn heard(node: u8, nmt: Option<NmtState>) -> NodeInfo {
        NodeInfo {
            node,
            nmt,
            device_type: None,
            identity: [None; 4],
            device_name: None,
            software_version: None,
            profile: None,
            sdo_error: None,
        }
    }
    /// The CiA device profile number in the low word of 0x1000 (402 for drives).
    pub fn device_profile(&self) -> Option<u16> {
        self.device_type.map(|t| t as u16)
    }
    /// The node in `scan --json`.
    fn json(&self) -> NodeJson {
        let hex = |v: Option<u32>| v.map(|x| format!("0x{x:08X}"));
        NodeJson {
            node: self.node,
            nmt: self.nmt.map(|s| s.as_str()),
            device_type: hex(self.device_type),
            device_profile: self.device_profile(),
            vendor_id: hex(self.identity[0]),
            product_code: hex(self.identity[1]),
            revision: hex(self.identity[2]),
            serial: hex(self.identity[3]),
            device_name: self.device_name.clone(),
            software_version: self.software_version.clone(),
            profile: self.profile.clone(),
            sdo_error: self.sdo_error.clone(),
        }
    }
}

/// One node of `scan --json`.
#[derive(Debug, Serialize)]
struct NodeJson {
    node: u8,
    nmt: Option<&'static str>,
    device_type: Option<String>,
    device_profile: Option<u16>,
    vendor_id: Option<String>,
    product_code: Option<String>,
    revision: Option<String>,
    serial: Option<String>,
    device_name: Option<String>,
    software_version: Option<String>,
    profile: Option<String>,
    sdo_error: Option<String>,
}

/// `scan --json`.
#[derive(Debug, Serialize)]
struct Scanned {
    ok: bool,
    nodes: Vec<NodeJson>,
}

impl Scanned {
    /// One line per node found, or what to try when none was.
    fn text(&self) -> String {
        if self.nodes.is_empty() {
            return "no nodes found (no heartbeat or boot-up heard; try --probe)".into();
        }
        let or_dash = |x: &Option<String>| x.clone().unwrap_or_else(|| "-".into());
        self.nodes
            .iter()
            .map(|n| {
                // The node-ID unpadded, as the JSON number was written.
                let mut line = format!(
                    "node {}  {:<16} type {}  vendor {}  product {}  rev {}  serial {}  {}",
                    n.node,
                    n.nmt.unwrap_or("-"),
                    or_dash(&n.device_type),
                    or_dash(&n.vendor_id),
                    or_dash(&n.product_code),
                    or_dash(&n.revision),
                    or_dash(&n.serial),
                    n.device_name.as_ref().map(|d| format!("\"{d}\"")).unwrap_or_default()
                );
                if let Some(p) = &n.profile {
                    line.push_str(&format!("  profile {p} (--profile {}={p})", n.node));
                }
                if let Some(e) = &n.sdo_error {
                    line.push_str(&format!("  ({e})"));
                }
                line
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// `scan [--listen MS] [--probe] [--timeout MS]`.
#[derive(clap::Args, Clone, Debug)]
pub struct ScanArgs {
    /// How long to listen for heartbeats and boot-ups (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = SCAN_LISTEN_MS)]
    pub listen: u64,
    /// Also ask every node 1..127 for 0x1000 (finds nodes without heartbeat).
    #[arg(long)]
    pub probe: bool,
    /// How long to wait for each SDO answer (DUR: a bare number is ms, or 500ms, 2s, 1min).
    #[arg(long, value_parser = ms_arg, default_value_t = SCAN_TIMEOUT_MS)]
    pub timeout: u64,
}

/// A scan of the bus.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scan {
    pub listen_ms: u64,
    pub probe: bool,
    pub timeout_ms: u64,
}

impl<D> CommandArgs<D> for ScanArgs {
    type Spec = Scan;
    const NAME: &'static str = "scan";

    fn spec(&self) -> Result<Scan, ParseError> {
        Ok(Scan {
            listen_ms: self.listen,
            probe: self.probe,
            timeout_ms: self.timeout,
        })
    }
}

impl Spec for Scan {
    /// What it asks depends on who answers.
    fn preview(&self, _known: &Known<'_>) -> Result<Preview, CommandError> {
        Ok(Preview::sends(
            "listens for heartbeats, then reads 0x1018 of each node found",
        ))
    }

    async fn run(&self, ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let nodes = scan(ctx.bus, self.listen_ms, self.probe, self.timeout_ms).await?;
        let report = Scanned {
            ok: true,
            nodes: nodes.iter().map(NodeInfo::json).collect(),
        };
        let text = report.text();
        Ok(Outcome::new(report, text))
    }
}

/// Listens `listen_ms` for heartbeats and boot-ups (and, with `probe`, also asks every silent
/// node-ID 1..127 for 0x1000, all at once), then reads the identification of each node found
/// (all nodes at once; 0x1000 is asked once per node-ID). On a listen-only
/// bus nothing is sent: the nodes heard are returned unidentified (and `probe` is refused).
pub async fn scan(bus: &Bus, listen_ms: u64, probe: bool, timeout_ms: u64) -> Result<Vec<NodeInfo>, CommandError> {
    let mut rx = bus.subscribe();
    let mut heard: BTreeMap<u8, Option<NmtState>> = BTreeMap::new();
    let deadline = tokio::time::Instant::now() + Duration::from_millis(listen_ms);
    loop {
        let left = deadline.saturating_duration_since(tokio::time::Instant::now());
        match tokio::time::timeout(left, rx.recv()).await {
            Err(_) => break,
            Ok(Err(BusError::Closed)) => return Err(BusError::Closed.into()),
            Ok(Err(_)) => {}
            Ok(Ok(f)) => {
                if f.direction() == Direction::Rx
                    && !f.is_ext()
                    && !f.is_rtr()
                    && let Some(node) = crate::cob::heartbeat_node(f.id)
                    && let Some(b) = f.payload().first()
                {
                    heard.insert(node, Some(NmtState::from_byte(*b)));
                }
            }
        }
    }
    if bus.is_listen_only() {
        // Nothing may be sent: the nodes heard are the answer, without SDO identification.
        if probe {
            return Err(BusError::ListenOnly.into());
        }
        return Ok(heard
            .into_iter()
            .map(|(node, nmt)| NodeInfo::heard(node, nmt))
            .collect());
    }
    // Node-IDs answering 0x1000, with the answer (so identification does not ask again).
    let mut probed: BTreeMap<u8, Vec<u8>> = BTreeMap::new();
    if probe {
        // Every silent node-ID at once: the probe takes one timeout, not 127.
        let mut set = JoinSet::new();
        for node in (1..=127u8).filter(|n| !heard.contains_key(n)) {
            let bus = bus.clone();
            set.spawn(async move { (node, upload(&bus, node, 0x1000, 0, false, timeout_ms).await) });
        }
        while let Some(r) = set.join_next().await {
            match r.map_err(|e| CommandError::Usage(format!("a probe task failed: {e}")))? {
                (node, Ok(d)) => {
                    heard.insert(node, None);
                    probed.insert(node, d);
                }
                (_, Err(CommandError::Bus(BusError::Closed))) => return Err(BusError::Closed.into()),
                // No answer, or not a CANopen SDO server: no node there.
                (_, Err(_)) => {}
            }
        }
    }
    // The identification of every node at once.
    let mut set = JoinSet::new();
    for (node, nmt) in heard {
        let bus = bus.clone();
        let device_type = probed.remove(&node);
        set.spawn(async move { identify(&bus, node, nmt, device_type, timeout_ms).await });
    }
    let mut out = BTreeMap::new();
    while let Some(r) = set.join_next().await {
        let info = r.map_err(|e| CommandError::Usage(format!("an identification task failed: {e}")))??;
        out.insert(info.node, info);
    }
    Ok(out.into_values().collect())
}

fn le_u32(d: &[u8]) -> u32 {
    d.iter().take(4).rev().fold(0u32, |a, b| (a << 8) | *b as u32)
}

/// Reads the identification of `node`; `device_type` is its 0x1000 answer when the probe already has it.
async fn identify(
    bus: &Bus,
    node: u8,
    nmt: Option<NmtState>,
    device_type: Option<Vec<u8>>,
    timeout_ms: u64,
) -> Result<NodeInfo, CommandError> {
    let mut info = NodeInfo::heard(node, nmt);
    let note = |e: CommandError, info: &mut NodeInfo| -> Result<(), CommandError> {
        match e {
            CommandError::Bus(b) => Err(CommandError::Bus(b)),
            e => {
                info.sdo_error.get_or_insert(e.to_string());
                Ok(())
            }
        }
    };
    let first = match device_type {
        Some(d) => Ok(d),
        None => upload(bus, node, 0x1000, 0, false, timeout_ms).await,
    };
    match first {
        Ok(d) => info.device_type = Some(le_u32(&d)),
        Err(e) => {
            note(e, &mut info)?;
            // A node that does not answer 0x1000 (stopped, or no SDO) will not answer the rest.
            return Ok(info);
        }
    }
    for sub in 1..=4u8 {
        match upload(bus, node, 0x1018, sub, false, timeout_ms).await {
            Ok(d) => info.identity[sub as usize - 1] = Some(le_u32(&d)),
            Err(e) => note(e, &mut info)?,
        }
    }
    for (index, slot) in [(0x1008, &mut info.device_name), (0x100A, &mut info.software_version)] {
        match upload(bus, node, index, 0, false, timeout_ms).await {
            Ok(d) => *slot = Some(String::from_utf8_lossy(&d).trim_end_matches('\0').to_string()),
            // Optional objects: a device without them aborts.
            Err(CommandError::Abort { .. }) => {}
            Err(CommandError::Bus(b)) => return Err(CommandError::Bus(b)),
            Err(e) => {
                info.sdo_error.get_or_insert(e.to_string());
            }
        }
    }
    info.profile = suggest_profile(&info);
    Ok(info)
}

/// The built-in profile whose identification matches what the node told us. A vendor
/// profile wins over a generic one it extends (AIMOTOR over CiA 402); then more conditions win.
pub fn suggest_profile(info: &NodeInfo) -> Option<String> {
    let read = |index: u16, sub: u8| -> Option<Value> {
        match (index, sub) {
            (0x1000, 0) => info.device_type.map(|v| Value::Unsigned(v as u64)),
            (0x1018, 1..=4) => info.identity[sub as usize - 1].map(|v| Value::Unsigned(v as u64)),
            (0x1008, 0) => info.device_name.clone().map(Value::Text),
            (0x100A, 0) => info.software_version.clone().map(Value::Text),
            _ => None,
        }
    };
    let matching: Vec<_> = crate::od::bind::builtin_names()
        .filter_map(|n| crate::od::bind::shared_builtin(n)?.ok())
        .map(|(p, _)| p)
        .filter(|p| p.identifies(&read))
        .collect();
    let is_base = |p: &crate::od::Profile| matching.iter().any(|q| q.extends.contains(&p.name));
    matching
        .iter()
        .filter(|p| !is_base(p))
        .max_by_key(|p| p.identification.len())
        .map(|p| p.name.clone())
}
