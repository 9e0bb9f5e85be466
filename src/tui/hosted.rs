//! The servers the TUI hosts on its first bus (`cotui live|demo --gateway SPEC`,
//! `--socketcand [ADDR:]PORT`): the CiA 309-3 gateway and the socketcand server run on the
//! live task's runtime beside the capture. Their audit lines, and each gateway request with
//! its answer, go to the message log; the frames they send are in the trace as cotui's own
//! (the gateway shares the TUI's handle, so stop-all covers the nodes it commanded).

use crate::audit::Audit;
use crate::bus::Bus;
use crate::bus::virt::VirtualBus;
use crate::gateway::listen::Bound;
use crate::gateway::serve::Gateway;
use crate::gateway::session::Policy;
use crate::serve::Source;
use tokio::sync::mpsc::UnboundedSender;

/// What the TUI hosts; bound before the terminal is taken, so a taken address is said at once.
#[derive(Default)]
pub struct Hosted {
    /// The gateway's socket and what its clients may do.
    pub gateway: Option<(Bound, Policy)>,
    /// The socketcand server's socket and settings.
    pub socketcand: Option<(std::net::TcpListener, crate::serve::Config)>,
}

impl Hosted {
    /// Starts the servers on `bus` (the TUI's handle of its first interface; `vbus` the
    /// demo's virtual bus, where each socketcand client gets its own endpoint); their lines
    /// go to `log`. Needs a tokio runtime.
    pub(crate) fn start(self, bus: &Bus, vbus: Option<&VirtualBus>, log: &UnboundedSender<String>) {
        let sink = |prefix: &'static str| {
            let log = log.clone();
            Audit::to(prefix, true, move |line| {
                let _ = log.send(line);
            })
        };
        if let Some((bound, policy)) = self.gateway {
            let gw = Gateway::start(bus.clone(), policy, sink("gateway"));
            let at = bound.at();
            let mode = policy.mode(bus.is_listen_only());
            gw.say(&format!("{} on {at}{mode}", bus.name()));
            tokio::spawn(async move {
                if let Err(e) = bound.serve(&gw, std::future::pending()).await {
                    gw.say(&format!("{at}: {e}"));
                }
            });
        }
        if let Some((listener, cfg)) = self.socketcand {
            let audit = sink("socketcand");
            let source = match vbus {
                Some(v) => Source::Virtual(v.clone()),
                None => Source::Named(cfg.iface.clone()),
            };
            let watch = bus.clone();
            tokio::spawn(async move {
                let served = match tokio::net::TcpListener::from_std(listener) {
                    Ok(l) => crate::serve::run(l, source, watch, &cfg, audit.clone(), std::future::pending()).await,
                    Err(e) => {
                        audit.say(&format!("cannot listen: {e}"));
                        return;
                    }
                };
                if let Err(e) = served {
                    audit.say(&e.to_string());
                }
            });
        }
    }
}
