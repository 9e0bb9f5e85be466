//! `cotui sim IFACE`: the simulated drives of `cotui demo` on a real interface, so other
//! tools (the python `canopen` library, a PLC, CANopen Magic) can talk to them. Each
//! node answers SDO from its dictionary, follows the CiA 402 state machine, sends boot-up,
//! heartbeats, EMCY and TPDOs, takes RPDOs and SYNC, and answers LSS. Lines on stdin
//! make nodes fail: `fault NODE CODE`, `silence NODE`, `resume NODE`, `reboot NODE`,
//! `mains NODE on|off`, `status`.

use crate::bus::Bus;
use crate::command::ExitCode;
use crate::sim::Simulation;
use crate::sim::drive::Drive;
use crate::sim::profile::DriveProfile;
use clap::Args;
use std::sync::{Arc, Mutex};
use tokio::signal::unix::{SignalKind, signal};

/// Arguments of `cotui sim`.
#[derive(Args, Debug)]
pub struct SimArgs {
    /// SocketCAN interface.
    pub iface: String,
    /// A simulated drive: NODE=MODEL[@SERIAL], MODEL one of aimotor, syntron-ds, servo;
    /// NODE `ff` (or 255) for a drive without node-ID that only answers LSS until one is
    /// configured and the node reset. Default: 2=aimotor 3=syntron-ds.
    #[arg(long = "node", value_name = "NODE=MODEL[@SERIAL]")]
    pub nodes: Vec<String>,
    /// Also produce SYNC every MS milliseconds (off by default: the master's job).
    #[arg(long, value_name = "MS", default_value_t = 0)]
    pub sync: u64,
    /// Write each node's EDS to DIR/node<N>.eds (node ff: DIR/lss-<SERIAL>.eds) first, for
    /// the tools that talk to the simulation.
    #[arg(long, value_name = "DIR")]
    pub write_eds: Option<std::path::PathBuf>,
}

/// The models `--node` accepts.
const MODELS: &str = "aimotor, syntron-ds, servo";

fn model(name: &str) -> Option<DriveProfile> {
    Some(match name {
        "aimotor" => DriveProfile::aimotor_like(),
        "syntron-ds" => DriveProfile::syntron_like(),
        "servo" => DriveProfile::servo("cotui simulated servo", 0x0402_0001),
        _ => return None,
    })
}

fn number(s: &str) -> Option<u32> {
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16).ok(),
        None => s.parse().ok(),
    }
}

/// Why a `--node` does not parse.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NodeSpecError {
    #[error("--node {0}: expected NODE=MODEL[@SERIAL], e.g. 2=aimotor")]
    Form(String),
    #[error("--node {spec}: node-ID `{node}` is not 1..127 or ff")]
    NodeId { spec: String, node: String },
    #[error("--node {spec}: serial `{serial}` is not a number")]
    Serial { spec: String, serial: String },
    #[error("--node {spec}: unknown model `{model}` (use {MODELS})")]
    Model { spec: String, model: String },
}

/// Why `cotui sim` stopped.
#[derive(Debug, thiserror::Error)]
enum SimError {
    #[error("{path}: {source}")]
    Eds { path: String, source: std::io::Error },
    #[error("cannot install a signal handler: {0}")]
    Signal(std::io::Error),
    #[error(transparent)]
    Bus(#[from] crate::bus::BusError),
}

/// Parses `NODE=MODEL[@SERIAL]`.
pub fn parse_node(spec: &str) -> Result<(u8, DriveProfile), NodeSpecError> {
    let (node, rest) = spec.split_once('=').ok_or_else(|| NodeSpecError::Form(spec.into()))?;
    let node = match node.to_ascii_lowercase().as_str() {
        "ff" | "0xff" => 0xFF,
        n => match n.parse::<u8>() {
            Ok(v @ (1..=127 | 255)) => v,
            _ => {
                return Err(NodeSpecError::NodeId {
                    spec: spec.into(),
                    node: node.into(),
                });
            }
        },
    };
    let (name, serial) = match rest.split_once('@') {
        Some((m, s)) => {
            let serial = number(s).ok_or_else(|| NodeSpecError::Serial {
                spec: spec.into(),
                serial: s.into(),
            })?;
            (m, Some(serial))
        }
        None => (rest, None),
    };
    let mut profile = model(name).ok_or_else(|| NodeSpecError::Model {
        spec: spec.into(),
        model: name.into(),
    })?;
    profile.serial_number = serial;
    Ok((node, profile))
}

/// Runs `cotui sim`; returns the exit status.
pub fn run_sim(args: &SimArgs) -> ExitCode {
    let specs: Vec<String> = if args.nodes.is_empty() {
        vec!["2=aimotor".into(), "3=syntron-ds".into()]
    } else {
        args.nodes.clone()
    };
    let mut drives = Vec::new();
    for spec in &specs {
        match parse_node(spec) {
            Ok((node, profile)) => {
                if node != 0xFF && drives.iter().any(|d: &Drive| d.node() == node) {
                    eprintln!("cotui sim: node {node} given twice");
                    return ExitCode::Usage;
                }
                drives.push(Drive::new(node, profile));
            }
            Err(e) => {
                eprintln!("cotui sim: {e}");
                return ExitCode::Usage;
            }
        }
    }
    if let Some(dir) = &args.write_eds
        && let Err(e) = write_eds(dir, &drives)
    {
        eprintln!("cotui sim: {e}");
        return ExitCode::Unavailable;
    }
    if args.iface == crate::connect::DEMO {
        eprintln!("cotui sim: give a SocketCAN interface (`cotui demo` runs the simulation on its own bus)");
        return ExitCode::Usage;
    }
    let sim = Arc::new(Mutex::new(Simulation::new(drives, args.sync)));
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("cotui sim: cannot start the runtime: {e}");
            return ExitCode::Usage;
        }
    };
    match rt.block_on(serve(&args.iface, sim)) {
        Ok(()) => ExitCode::Ok,
        Err(e) => {
            eprintln!("cotui sim: {e}");
            ExitCode::Unavailable
        }
    }
}

/// Writes every drive's EDS into `dir`.
fn write_eds(dir: &std::path::Path, drives: &[Drive]) -> Result<(), SimError> {
    let failed = |path: &std::path::Path| {
        let path = path.display().to_string();
        move |source| SimError::Eds { path, source }
    };
    std::fs::create_dir_all(dir).map_err(failed(dir))?;
    for d in drives {
        let name = match d.node() {
            0xFF => format!("lss-{}.eds", d.objects().uint(0x1018, 4)),
            n => format!("node{n}.eds"),
        };
        let path = dir.join(name);
        std::fs::write(&path, d.eds()).map_err(failed(&path))?;
    }
    Ok(())
}

/// Serves the simulation on `iface` until SIGINT/SIGTERM or a bus failure.
async fn serve(iface: &str, sim: Arc<Mutex<Simulation>>) -> Result<(), SimError> {
    let mut int = signal(SignalKind::interrupt()).map_err(SimError::Signal)?;
    let mut term = signal(SignalKind::terminate()).map_err(SimError::Signal)?;
    let bus = crate::connect::open(iface, false).await?;
    let rx = bus.subscribe();
    if let Ok(s) = sim.lock() {
        for d in s.drives() {
            let o = d.objects();
            let node = if d.node() == 0xFF {
                "ff (no node-ID: LSS only)".to_string()
            } else {
                d.node().to_string()
            };
            println!(
                "cotui sim: node {node} on {iface}: vendor 0x{:08X} product 0x{:08X} revision 0x{:08X} serial 0x{:08X}",
                o.uint(0x1018, 1),
                o.uint(0x1018, 2),
                o.uint(0x1018, 3),
                o.uint(0x1018, 4)
            );
        }
    }
    println!(
        "cotui sim: commands on stdin: fault NODE CODE | silence NODE | resume NODE | reboot NODE | mains NODE on|off | status"
    );
    let (lines_tx, mut lines) = tokio::sync::mpsc::unbounded_channel();
    std::thread::spawn(move || {
        for line in std::io::stdin().lines().map_while(Result::ok) {
            if lines_tx.send(line).is_err() {
                break;
            }
        }
    });
    let serving = crate::sim::serve::serve(sim.clone(), bus.clone(), rx);
    tokio::pin!(serving);
    loop {
        tokio::select! {
            r = &mut serving => return Ok(r?),
            Some(line) = lines.recv() => {
                let (text, frames) = control(&sim, &line, bus.now_ns());
                println!("{text}");
                send_all(&bus, &frames).await?;
            }
            _ = int.recv() => return Ok(()),
            _ = term.recv() => return Ok(()),
        }
    }
}

async fn send_all(bus: &Bus, frames: &[crate::frame::Frame]) -> Result<(), crate::bus::BusError> {
    for f in frames {
        bus.send(f).await?;
    }
    Ok(())
}

/// Carries out one control line; returns what to print and the frames to send.
pub fn control(sim: &Mutex<Simulation>, line: &str, now_ns: u64) -> (String, Vec<crate::frame::Frame>) {
    let words: Vec<&str> = line.split_whitespace().collect();
    let Ok(mut sim) = sim.lock() else {
        return ("simulation unavailable".into(), Vec::new());
    };
    if words.first() == Some(&"status") {
        let lines: Vec<String> = sim
            .drives()
            .iter()
            .map(|d| {
                format!(
                    "node {}: {:?}, {}{}",
                    d.node(),
                    d.nmt(),
                    d.state().text(),
                    if d.is_silent() { ", silenced" } else { "" }
                )
            })
            .collect();
        return (lines.join("\n"), Vec::new());
    }
    let usage = "usage: fault NODE CODE | silence NODE | resume NODE | reboot NODE | mains NODE on|off | status";
    let (Some(cmd), Some(node)) = (words.first(), words.get(1).and_then(|n| number(n))) else {
        return (usage.into(), Vec::new());
    };
    let node = node.min(255) as u8;
    let Some(drive) = sim.drive_mut(node) else {
        return (format!("no simulated node {node}"), Vec::new());
    };
    match (*cmd, words.get(2).copied(), words.len()) {
        ("fault", Some(code), 3) => match number(code).and_then(|c| u16::try_from(c).ok()) {
            Some(c) => {
                drive.inject_fault(c);
                (format!("node {node}: fault 0x{c:04X} (EMCY, then Fault)"), Vec::new())
            }
            None => (format!("fault: `{code}` is not a 16-bit error code"), Vec::new()),
        },
        ("silence", None, 2) => {
            drive.set_silent(true);
            (format!("node {node}: silenced (sends and answers nothing)"), Vec::new())
        }
        ("resume", None, 2) => {
            drive.set_silent(false);
            (format!("node {node}: sends again"), Vec::new())
        }
        ("reboot", None, 2) => {
            drive.set_silent(false);
            (
                format!("node {node}: rebooted (boot-up, pre-operational)"),
                drive.power_on(now_ns),
            )
        }
        ("mains", Some(on @ ("on" | "off")), 3) => {
            drive.set_mains(on == "on");
            (format!("node {node}: mains {on}"), Vec::new())
        }
        _ => (usage.into(), Vec::new()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_specs_parse_or_say_what_is_wrong() {
        let (n, p) = parse_node("ff=servo@0x1234").unwrap();
        assert_eq!((n, p.serial_number), (0xFF, Some(0x1234)));
        assert_eq!(parse_node("3=syntron-ds").unwrap().0, 3);
        assert_eq!(
            parse_node("200=aimotor").unwrap_err().to_string(),
            "--node 200=aimotor: node-ID `200` is not 1..127 or ff"
        );
        assert!(
            parse_node("2=plc")
                .unwrap_err()
                .to_string()
                .contains("unknown model `plc`")
        );
        assert!(parse_node("2").unwrap_err().to_string().contains("expected NODE=MODEL"));
    }

    #[test]
    fn control_lines_fail_silence_and_reboot_nodes() {
        let sim = Mutex::new(Simulation::new(vec![Drive::new(2, DriveProfile::aimotor_like())], 0));
        assert_eq!(
            control(&sim, "silence 2", 0).0,
            "node 2: silenced (sends and answers nothing)"
        );
        assert!(sim.lock().unwrap().drive(2).unwrap().is_silent());
        let (text, frames) = control(&sim, "reboot 2", 0);
        assert_eq!(text, "node 2: rebooted (boot-up, pre-operational)");
        assert_eq!((frames[0].id, frames[0].payload()), (0x702, &[0u8][..]));
        assert_eq!(
            control(&sim, "fault 2 0x2310", 0).0,
            "node 2: fault 0x2310 (EMCY, then Fault)"
        );
        assert_eq!(control(&sim, "fault 9 1", 0).0, "no simulated node 9");
        assert!(control(&sim, "fault 2", 0).0.starts_with("usage:"));
        assert!(control(&sim, "status", 0).0.starts_with("node 2: PreOperational"));
    }
}
