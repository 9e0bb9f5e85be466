//! Runs a [`Simulation`] on a virtual bus: frames are delivered as they arrive and
//! time advances on a 10 ms tokio interval.

use super::Simulation;
use crate::bus::Bus;
use crate::bus::virt::VirtualBus;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Step of the simulation clock.
pub const TICK: Duration = Duration::from_millis(10);

/// A running demo bus: a handle for the user and the simulation behind it.
#[derive(Clone)]
pub struct Demo {
    /// The user's handle (listen-only when asked).
    pub bus: Bus,
    /// The bus itself, to add more endpoints.
    pub vbus: VirtualBus,
    /// The simulated nodes; lock briefly to inject faults or inspect state.
    pub sim: Arc<Mutex<Simulation>>,
}

impl Demo {
    /// Starts `sim` on a new virtual bus called `demo`. Must be called inside a tokio runtime.
    pub fn spawn(sim: Simulation, listen_only: bool) -> Demo {
        let vbus = VirtualBus::new(crate::connect::DEMO);
        let node_side = vbus.endpoint(false);
        let sim = Arc::new(Mutex::new(sim));
        // Subscribe before the task starts so no frame sent from now on is missed.
        let rx = node_side.subscribe();
        tokio::spawn(run(sim.clone(), node_side, rx, vbus.clone()));
        Demo {
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

async fn run(sim: Arc<Mutex<Simulation>>, bus: Bus, mut rx: crate::bus::Subscription, vbus: VirtualBus) {
    let boot = sim.lock().map(|mut s| s.power_on(vbus.now_ns())).unwrap_or_default();
    for f in boot {
        if bus.send(&f).await.is_err() {
            return;
        }
    }
    let mut tick = tokio::time::interval(TICK);
    loop {
        let out = tokio::select! {
            got = rx.recv() => match got {
                Ok(f) => sim.lock().map(|mut s| s.on_frame(&f, vbus.now_ns())).unwrap_or_default(),
                Err(crate::bus::BusError::Closed) => return,
                Err(_) => Vec::new(),
            },
            _ = tick.tick() => sim.lock().map(|mut s| s.tick(vbus.now_ns())).unwrap_or_default(),
        };
        for f in out {
            if bus.send(&f).await.is_err() {
                return;
            }
        }
    }
}
