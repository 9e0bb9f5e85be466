//! `cotui sim IFACE`: the simulated drives of `cotui demo` on a real interface, so other
//! tools (the python `canopen` library, a PLC, CANopen Magic) can talk to them. Each
//! node answers SDO from its dictionary, follows the CiA 402 state machine, sends boot-up,
//! heartbeats, EMCY and TPDOs, takes RPDOs and SYNC, and answers LSS. Lines on stdin
//! make nodes fail: `fault NODE CODE`, `silence NODE`, `resume NODE`, `reboot NODE`,
//! `mains NODE on|off`, `status`.

use crate::bus::Bus;
use crate::command::ExitCode;
use crate::sim::Simulation;
use crate::sim::control::{self, Control};
use crate::sim::drive::Drive;
use clap::Args;
use std::sync::{Arc, Mutex};
use tokio::signal::unix::{SignalKind, signal};

/// Arguments of `cotui sim`.
#[derive(Args, Debug)]
pub struct SimArgs {
    /// SocketCAN interface (or socketcand://HOST:PORT/CHANNEL, served with --allow-send).
    pub iface: String,
    /// A simulated drive: NODE=MODEL[@SERIAL], MODEL one of aimotor, syntron-ds,
    /// dexmart-dev, aqmd2405, servo; NODE `ff` (or 255) for a drive without node-ID that only
    /// answers LSS until one is configured and the node reset. Default: 2=aimotor 3=syntron-ds.
    #[arg(long = "node", value_name = "NODE=MODEL[@SERIAL]")]
    pub nodes: Vec<String>,
    /// Also produce SYNC every DUR (a bare number is ms, or `10ms`, `1s`; 0, the default,
    /// is off: the master's job).
    #[arg(long, value_name = "DUR", default_value_t = 0, value_parser = crate::command::words::ms_or_zero_arg)]
    pub sync: u64,
    /// Write each node's EDS to DIR/node<N>.eds (node ff: DIR/lss-<SERIAL>.eds) first, for
    /// the tools that talk to the simulation.
    #[arg(long, value_name = "DIR")]
    pub write_eds: Option<std::path::PathBuf>,
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

/// Runs `cotui sim`; returns the exit status.
pub fn run_sim(args: &SimArgs) -> ExitCode {
    let drives = match crate::sim::spec::drives(&args.nodes, &crate::sim::DEMO_NODES) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui sim: {e}");
            return ExitCode::Usage;
        }
    };
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
    println!("cotui sim: commands on stdin: {}", control::USAGE);
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
                let (text, frames) = match (Control::parse(&line), sim.lock()) {
                    (Ok(c), Ok(mut s)) => c.apply(&mut s, bus.now_ns()),
                    (Err(e), _) => (e.to_string(), Vec::new()),
                    (_, Err(_)) => ("simulation unavailable".into(), Vec::new()),
                };
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
