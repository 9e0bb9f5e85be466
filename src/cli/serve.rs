//! `cotui serve IFACE --socketcand [ADDR:]PORT`: the bus over the socketcand protocol
//! ([`crate::serve`]), with the address and permission rules of the command line.

use crate::command::ExitCode;
use crate::serve::{Config, serve};
use clap::Args;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};

/// Arguments of `cotui serve`.
#[derive(Args, Debug)]
pub struct ServeArgs {
    /// The bus to serve: a SocketCAN interface, `demo` (the simulated bus, alive as long as
    /// the server), or socketcand://HOST:PORT/CHANNEL.
    pub iface: String,
    /// Serve it over the socketcand protocol on [ADDR:]PORT (a loopback ADDR; default
    /// 127.0.0.1; port 0 picks a free one, named on stderr). Clients open IFACE by its name.
    #[arg(long, value_name = "[ADDR:]PORT", required = true)]
    pub socketcand: String,
    /// Listen on ADDR instead (e.g. 0.0.0.0, or the bench PC's address): every machine that
    /// reaches it can then watch the bus. Needed for any address other than loopback.
    #[arg(long, value_name = "ADDR")]
    pub bind: Option<IpAddr>,
    /// Let clients send frames (by default they only receive; each frame sent is an audit
    /// line on stderr).
    #[arg(long)]
    pub allow_send: bool,
    /// Open the bus without a send path (refuses --allow-send).
    #[arg(long)]
    pub listen_only: bool,
    /// The most clients connected at once; more get an error and are closed.
    #[arg(long, value_name = "N", default_value_t = 64)]
    pub max_clients: usize,
    /// Announce the bus by UDP broadcast (port 42000, every 3 s) as socketcand does, for
    /// clients that discover servers (python-can's detect, SavvyCAN). Needs --bind.
    #[arg(long)]
    pub beacon: bool,
}

/// The address to listen on: `spec` is PORT or ADDR:PORT; a non-loopback address only
/// when `bind` names it (or `bind` replaces the address).
pub fn listen_addr(spec: &str, bind: Option<IpAddr>) -> Result<SocketAddr, String> {
    let localhost = |s: &str| s.strip_prefix("localhost:").map(|p| format!("127.0.0.1:{p}"));
    let addr = if let Ok(port) = spec.parse::<u16>() {
        SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), port)
    } else {
        let text = localhost(spec).unwrap_or_else(|| spec.to_string());
        text.parse::<SocketAddr>()
            .map_err(|_| format!("--socketcand {spec}: give PORT or ADDR:PORT (e.g. 29536 or 127.0.0.1:29536)"))?
    };
    match bind {
        Some(ip) if addr.ip().is_loopback() || addr.ip() == ip => Ok(SocketAddr::new(ip, addr.port())),
        Some(ip) => Err(format!(
            "--socketcand {spec} and --bind {ip} name two addresses: give the port in --socketcand and the address in --bind"
        )),
        None if addr.ip().is_loopback() => Ok(addr),
        None => Err(format!(
            "--socketcand {spec}: {} is not a loopback address; every machine that reaches it could watch \
             the bus, so say it explicitly: --bind {}",
            addr.ip(),
            addr.ip()
        )),
    }
}

/// Runs `cotui serve`; returns the exit status.
pub fn run_serve(args: &ServeArgs) -> ExitCode {
    let usage = |e: String| {
        eprintln!("cotui serve: {e}");
        ExitCode::Usage
    };
    if args.allow_send && args.listen_only {
        return usage("--allow-send and --listen-only contradict each other: a listen-only bus cannot send".into());
    }
    let addr = match listen_addr(&args.socketcand, args.bind) {
        Ok(a) => a,
        Err(e) => return usage(e),
    };
    if args.beacon && addr.ip().is_loopback() {
        return usage("--beacon announces the bus to the network: give --bind ADDR too".into());
    }
    let cfg = Config {
        iface: args.iface.clone(),
        addr,
        allow_send: args.allow_send,
        max_clients: args.max_clients,
        beacon: args.beacon,
    };
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => return usage(format!("cannot start the runtime: {e}")),
    };
    match rt.block_on(serve(cfg)) {
        Ok(()) => ExitCode::Ok,
        Err(e) => {
            eprintln!("cotui serve: {e}");
            ExitCode::Unavailable
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_by_default_and_other_addresses_only_when_bound_explicitly() {
        assert_eq!(listen_addr("29536", None), Ok("127.0.0.1:29536".parse().unwrap()));
        assert_eq!(listen_addr("localhost:5", None), Ok("127.0.0.1:5".parse().unwrap()));
        assert_eq!(listen_addr("[::1]:5", None), Ok("[::1]:5".parse().unwrap()));
        let e = listen_addr("0.0.0.0:29536", None).unwrap_err();
        assert!(
            e.contains("not a loopback address") && e.ends_with("--bind 0.0.0.0"),
            "{e}"
        );
        let any: IpAddr = "0.0.0.0".parse().unwrap();
        assert_eq!(listen_addr("29536", Some(any)), Ok("0.0.0.0:29536".parse().unwrap()));
        assert_eq!(listen_addr("0.0.0.0:1", Some(any)), Ok("0.0.0.0:1".parse().unwrap()));
        assert!(listen_addr("10.0.0.1:1", Some(any)).is_err());
        assert!(
            listen_addr("can0", None)
                .unwrap_err()
                .contains("give PORT or ADDR:PORT")
        );
    }
}
