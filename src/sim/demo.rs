//! Runs a [`Simulation`] on an in-process virtual bus (`cotui demo`).

use super::Simulation;
use crate::bus::Bus;
use crate::bus::virt::VirtualBus;
use std::sync::{Arc, Mutex};

/// The name of the demo bus (the IFACE that selects it, see [`crate::connect`]).
pub const BUS_NAME: &str = "demo";

/// A running demo bus: a handle for the user and the simulation behind it.
#[derive(Clone)]
pub struct Demo {
    /// The user's handle (listen-only when asked).
    pub bus: Bus,
    /// The bus itself, to add more endpoints.
    pub vbus: VirtualBus,
    /// The simulation's own endpoint (what the nodes send goes out here).
    pub nodes: Bus,
    /// The simulated nodes; lock briefly to inject faults or inspect state.
    pub sim: Arc<Mutex<Simulation>>,
}

impl Demo {
    /// Starts `sim` on a new virtual bus called `demo`. Must be called inside a tokio runtime.
    pub fn spawn(sim: Simulation, listen_only: bool) -> Demo {
        let vbus = VirtualBus::new(BUS_NAME);
        let node_side = vbus.endpoint(false);
        let sim = Arc::new(Mutex::new(sim));
        // Subscribe before the task starts so no frame sent from now on is missed.
        let rx = node_side.subscribe();
        tokio::spawn(super::serve::serve(sim.clone(), node_side.clone(), rx));
        Demo {
            nodes: node_side,
            bus: vbus.endpoint(listen_only),
            vbus,
            sim,
        }
    }
}

/// Starts the standard demo ([`Simulation::demo`]) and returns the user's handle.
pub fn start(listen_only: bool) -> Bus {
    Demo::spawn(Simulation::demo(), listen_only).bus
}
