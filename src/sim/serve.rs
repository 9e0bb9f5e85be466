//! Runs a [`Simulation`] on a bus (the demo's virtual bus or a SocketCAN interface):
//! frames are delivered as they arrive and time advances on a 10 ms tokio interval, on
//! the bus's clock (the frames' timestamp clock).

use super::Simulation;
use crate::bus::{Bus, BusError, Subscription};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Step of the simulation clock.
pub const TICK: Duration = Duration::from_millis(10);

/// Powers the simulation on and serves it until the bus closes or refuses a frame.
/// `rx` must be subscribed before the call so no frame is missed.
pub async fn serve(sim: Arc<Mutex<Simulation>>, bus: Bus, mut rx: Subscription) -> Result<(), BusError> {
    let boot = sim.lock().map(|mut s| s.power_on(bus.now_ns())).unwrap_or_default();
    for f in boot {
        bus.send(&f).await?;
    }
    let mut tick = tokio::time::interval(TICK);
    loop {
        let out = tokio::select! {
            got = rx.recv() => match got {
                Ok(f) => sim.lock().map(|mut s| s.on_frame(&f, bus.now_ns())).unwrap_or_default(),
                Err(BusError::Closed) => return Ok(()),
                Err(_) => Vec::new(),
            },
            _ = tick.tick() => sim.lock().map(|mut s| s.tick(bus.now_ns())).unwrap_or_default(),
        };
        for f in out {
            bus.send(&f).await?;
        }
    }
}
