//! `cotui gateway IFACE --stdio | --unix PATH | --tcp ADDR:PORT`: the CiA 309-3 ASCII
//! gateway ([`crate::gateway`]) on a bus, for scripts in any language.

use crate::command::ExitCode;
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
    #[error("{0}")]
    Refused(String),
}

/// Runs the gateway until its input ends (`--stdio`) or Ctrl-C; returns the exit status.
pub fn run_gateway(args: &GatewayArgs) -> ExitCode {
    let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("cotui gateway: cannot start the runtime: {e}");
            return ExitCode::Usage;
        }
    };
    match rt.block_on(serve(args)) {
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

async fn serve(args: &GatewayArgs) -> Result<(), GatewayError> {
    let bus = crate::connect::open(&args.iface, args.listen_only).await?;
    let policy = Policy {
        allow_writes: args.allow_writes,
        notify: args.notify,
    };
    let gw = Gateway::start(bus, policy);
    let io = |what: String| move |source| GatewayError::Io { what, source };
    if args.stdio {
        return gw
            .serve(tokio::io::stdin(), tokio::io::stdout())
            .await
            .map_err(io("stdio".into()));
    }
    let ctrl_c = async {
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    };
    tokio::pin!(ctrl_c);
    if let Some(addr) = &args.tcp {
        let listener = tokio::net::TcpListener::bind(addr.as_str())
            .await
            .map_err(io(format!("cannot listen on {addr}")))?;
        let at = listener.local_addr().map_err(io(addr.clone()))?;
        eprintln!("cotui gateway: {} on tcp {at}{}", args.iface, mode(args));
        loop {
            tokio::select! {
                _ = &mut ctrl_c => return Ok(()),
                got = listener.accept() => match got {
                    Ok((stream, peer)) => gw.spawn_client(stream, format!("tcp {peer}")),
                    Err(e) => eprintln!("cotui gateway: accept failed: {e}"),
                },
            }
        }
    }
    let Some(path) = &args.unix else {
        return Err(GatewayError::Refused(
            "give --stdio, --unix PATH or --tcp ADDR:PORT".into(),
        ));
    };
    replace_stale_socket(path)?;
    let listener = tokio::net::UnixListener::bind(path).map_err(io(format!("cannot listen on {}", path.display())))?;
    eprintln!("cotui gateway: {} on unix {}{}", args.iface, path.display(), mode(args));
    let mut n = 0u64;
    let end = loop {
        tokio::select! {
            _ = &mut ctrl_c => break Ok(()),
            got = listener.accept() => match got {
                Ok((stream, _)) => {
                    n += 1;
                    gw.spawn_client(stream, format!("unix client {n}"));
                }
                Err(e) => eprintln!("cotui gateway: accept failed: {e}"),
            },
        }
    };
    let _ = std::fs::remove_file(path);
    end
}

/// What the clients may do, for the line that says where the gateway listens.
fn mode(args: &GatewayArgs) -> &'static str {
    match (args.listen_only, args.allow_writes) {
        (true, _) => " (listen-only: nothing is sent)",
        (false, true) => " (writes, NMT and LSS allowed)",
        (false, false) => " (read-only: --allow-writes for write, NMT and LSS)",
    }
}

/// Removes a socket left at `path` by an earlier gateway; refuses any other kind of file.
fn replace_stale_socket(path: &std::path::Path) -> Result<(), GatewayError> {
    use std::os::unix::fs::FileTypeExt;
    match std::fs::symlink_metadata(path) {
        Err(_) => Ok(()),
        Ok(m) if m.file_type().is_socket() => std::fs::remove_file(path).map_err(|source| GatewayError::Io {
            what: format!("cannot replace the socket {}", path.display()),
            source,
        }),
        Ok(_) => Err(GatewayError::Refused(format!(
            "{} exists and is not a socket: not replaced (give another PATH)",
            path.display()
        ))),
    }
}
