//! The options of `cotui live` and `cotui demo` that host servers on the TUI's bus
//! (`--gateway`, `--socketcand`; [`crate::tui::hosted`]), checked and bound before the
//! terminal is taken.

use crate::gateway::listen::Bound;
use crate::gateway::session::Policy;
use crate::tui::hosted::Hosted;
use clap::Args;

/// Servers the TUI runs on its (first) bus while it shows it.
#[derive(Args, Debug)]
pub struct HostArgs {
    /// Host the CiA 309-3 gateway (`cotui gateway`) on the bus: tcp:ADDR:PORT (only that
    /// address, e.g. tcp:127.0.0.1:5555) or unix:PATH. Each request and answer is in the
    /// message log (m), its frames in the trace; read-only unless --allow-writes.
    #[arg(long, value_name = "tcp:ADDR:PORT|unix:PATH")]
    pub gateway: Option<String>,
    /// Let the gateway's clients write objects, send NMT commands and LSS services.
    #[arg(long, requires = "gateway")]
    pub allow_writes: bool,
    /// Write the gateway's notifications (EMCY, NMT state changes) to its clients as they
    /// happen (as `cotui gateway --notify`).
    #[arg(long, requires = "gateway")]
    pub notify: bool,
    /// Serve the bus over the socketcand protocol (`cotui serve`) on [ADDR:]PORT, a loopback
    /// address (default 127.0.0.1); connects, disconnects and sends are in the message log.
    #[arg(long, value_name = "[ADDR:]PORT")]
    pub socketcand: Option<String>,
    /// Let socketcand clients send frames (they only receive without it).
    #[arg(long, requires = "socketcand")]
    pub allow_send: bool,
}

impl HostArgs {
    /// The servers to host on `iface` (the TUI's first bus), their sockets bound; the
    /// error is the line cotui prints.
    pub fn bind(&self, iface: &str, listen_only: bool) -> Result<Hosted, String> {
        if listen_only && (self.allow_writes || self.allow_send) {
            let what = if self.allow_writes {
                "--allow-writes"
            } else {
                "--allow-send"
            };
            return Err(format!(
                "{what} and --listen-only contradict each other: a listen-only bus cannot send"
            ));
        }
        let gateway = match &self.gateway {
            Some(spec) => Some((
                Bound::spec(spec)?,
                Policy {
                    allow_writes: self.allow_writes,
                    notify: self.notify,
                },
            )),
            None => None,
        };
        let socketcand = match &self.socketcand {
            Some(spec) => {
                let addr = super::serve::listen_addr(spec, None)?;
                let listener = std::net::TcpListener::bind(addr)
                    .map_err(|e| format!("--socketcand {spec}: cannot listen on {addr}: {e}"))?;
                listener
                    .set_nonblocking(true)
                    .map_err(|e| format!("--socketcand {spec}: {e}"))?;
                let cfg = crate::serve::Config {
                    iface: iface.to_string(),
                    addr,
                    allow_send: self.allow_send,
                    max_clients: 64,
                    beacon: false,
                };
                Some((listener, cfg))
            }
            None => None,
        };
        Ok(Hosted { gateway, socketcand })
    }
}
