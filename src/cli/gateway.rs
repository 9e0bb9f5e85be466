//! `cotui gateway IFACE --stdio | --unix PATH | --tcp ADDR:PORT`: the CiA 309-3 ASCII
//! gateway ([`crate::gateway`]) on a bus, for scripts in any language.

use crate::audit::Audit;
use crate::command::ExitCode;
use crate::gateway::listen::Bound;
use crate::gateway::serve::Gateway;
use crate::gateway::session::Policy;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `cotui gateway`.
#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("listen").required(true).args(["stdio", "unix", "tcp"])))]
pub struct GatewayArgs {
    /// SocketCAN interface (e.g. can0, vcan0), or `demo` for the built-in simulated bus.
    pub iface: String,
    /// Serve one client on stdin (requests) and stdout (answers and notifications).
    #[arg(long)]
    pub stdio: bool,
    /// Serve clients on a Unix socket at PATH (a socket left there is replaced, another file refused).
    #[arg(long, value_name = "PATH")]
    pub unix: Option<PathBuf>,
    /// Serve clients on TCP at ADDR:PORT, binding only that address (e.g. 127.0.0.1:5555;
    /// port 0 picks a free one, printed on stderr).
    #[arg(long, value_name = "ADDR:PORT")]
    pub tcp: Option<String>,
    /// Let clients write objects (`write`), send NMT commands and LSS services; without it the
    /// gateway only reads (`read`), answering the others ERROR:100 and sending nothing.
    #[arg(long)]
    pub allow_writes: bool,
    /// Write notifications (EMCY, NMT state changes) to the clients as they happen, between
    /// answers; without it they are kept for the `log` request, as canopend keeps them.
    #[arg(long)]
    pub notify: bool,
    /// Open the bus without a send path: every request that would send is answered ERROR:102.
    #[arg(long)]
    pub listen_only: bool,
}

/// Why the gateway could not serve.
#[derive(Debug, thiserror::Error)]
enum GatewayError {
    #[error("{0}")]
    Bus(#[from] crate::bus::BusError),
    #[error("{what}: {source}")]
    Io { what: String, source: std::io::Error },
}

/// Runs the gateway until its input ends (`--stdio`) or Ctrl-C; returns the exit status.
pub fn run_gateway(args: &GatewayArgs) -> ExitCode {
    // The socket first: a taken address is said before the bus is opened.
    let bound = match (&args.tcp, &args.unix) {
        (Some(addr), _) => Some(Bound::tcp(addr)),
        (None, Some(path)) => Some(Bound::unix(path.clone())),
        (None, None) => None,
    }
    .transpose();
    let bound = match bound {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cotui gateway: {e}");
            return ExitCode::Usage;
        }
    };
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("cotui gateway: cannot start the runtime: {e}");
            return ExitCode::Usage;
        }
    };
    match rt.block_on(serve(args, bound)) {
        Ok(()) => ExitCode::Ok,
        Err(e) => {
            eprintln!("cotui gateway: {e}");
            match e {
                GatewayError::Bus(_) => ExitCode::Unavailable,
                _ => ExitCode::Usage,
            }
        }
    }
}

async fn serve(args: &GatewayArgs, bound: Option<Bound>) -> Result<(), GatewayError> {
    let bus = match crate::connect::open(&args.iface, args.listen_only).await {
        Ok(b) => b,
        Err(e) => {
            if let Some(b) = bound {
                b.close();
            }
            return Err(e.into());
        }
    };
    let policy = Policy {
        allow_writes: args.allow_writes,
        notify: args.notify,
    };
    let gw = Gateway::start(bus, policy, Audit::stderr("gateway"));
    let Some(bound) = bound else {
        return gw
            .serve("stdio", tokio::io::stdin(), tokio::io::stdout())
            .await
            .map_err(|source| GatewayError::Io {
                what: "stdio".into(),
                source,
            });
    };
    let at = bound.at();
    gw.say(&format!("{} on {at}{}", args.iface, policy.mode(args.listen_only)));
    let ctrl_c = async {
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    };
    bound
        .serve(&gw, ctrl_c)
        .await
        .map_err(|source| GatewayError::Io { what: at, source })
}
