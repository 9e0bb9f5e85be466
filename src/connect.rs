//! Picks the bus behind an interface name: `demo` is the in-process virtual bus with the
//! simulated drives ([`crate::sim::demo`]), `socketcand://HOST:PORT/CHANNEL` a bus on another
//! machine through a socketcand server ([`socketcand`]), anything else a SocketCAN
//! interface. The one place that knows them all, so the bus layer does not depend on the simulator.

use crate::bus::{Bus, BusError, bitrate, socketcan, socketcand};

/// The interface name of the in-process simulated bus.
pub const DEMO: &str = crate::sim::demo::BUS_NAME;

/// The interface name of a second, independent simulated bus (the standard demo drives),
/// for trying several interfaces at once without hardware (`cotui live demo demo2`).
pub const DEMO2: &str = "demo2";

/// True for the names of the simulated buses ([`DEMO`], [`DEMO2`]).
pub fn is_demo(iface: &str) -> bool {
    iface == DEMO || iface == DEMO2
}

/// Opens `iface` (see the module doc). Must be called inside a tokio runtime.
pub async fn open(iface: &str, listen_only: bool) -> Result<Bus, BusError> {
    if is_demo(iface) {
        Ok(crate::sim::demo::start(listen_only))
    } else if socketcand::is_url(iface) {
        socketcand::open(iface, listen_only).await
    } else {
        socketcan::open(iface, listen_only)
    }
}

/// The bit rate `iface` is configured with, or why it has none, in words that follow its
/// name (see [`bitrate::configured`]): the simulated buses and socketcand channels have none.
pub fn configured_bitrate(iface: &str) -> Result<u64, String> {
    if is_demo(iface) {
        Err("is simulated: it has no bit rate".to_string())
    } else if socketcand::is_url(iface) {
        Err("is a socketcand channel: socketcand does not tell its bit rate".to_string())
    } else {
        bitrate::configured(iface)
    }
}
