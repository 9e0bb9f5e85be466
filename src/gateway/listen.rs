//! Where a gateway listens (`tcp:ADDR:PORT`, `unix:PATH`), bound before any bus is opened
//! so that a taken address is said at once, and the accept loop that gives each client its
//! own session.

use super::serve::Gateway;
use std::future::Future;
use std::path::PathBuf;

/// A bound listening socket, not yet on a runtime.
pub enum Bound {
    /// TCP on the address it names (port 0 picks a free one).
    Tcp(std::net::TcpListener),
    /// A Unix socket at its path (removed when the loop ends).
    Unix(std::os::unix::net::UnixListener, PathBuf),
}

impl Bound {
    /// Binds TCP `addr` (only that address: `127.0.0.1:5555`, port 0 picks one).
    pub fn tcp(addr: &str) -> Result<Bound, String> {
        let l = std::net::TcpListener::bind(addr).map_err(|e| format!("cannot listen on {addr}: {e}"))?;
        l.set_nonblocking(true).map_err(|e| format!("{addr}: {e}"))?;
        Ok(Bound::Tcp(l))
    }

    /// Binds a Unix socket at `path`, replacing a socket an earlier gateway left there (any
    /// other kind of file is refused).
    pub fn unix(path: PathBuf) -> Result<Bound, String> {
        replace_stale_socket(&path)?;
        let l = std::os::unix::net::UnixListener::bind(&path)
            .map_err(|e| format!("cannot listen on {}: {e}", path.display()))?;
        l.set_nonblocking(true)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(Bound::Unix(l, path))
    }

    /// `tcp:ADDR:PORT` or `unix:PATH` (the TUI's `--gateway`).
    pub fn spec(spec: &str) -> Result<Bound, String> {
        if let Some(addr) = spec.strip_prefix("tcp:") {
            return Bound::tcp(addr);
        }
        if let Some(path) = spec.strip_prefix("unix:").filter(|p| !p.is_empty()) {
            return Bound::unix(PathBuf::from(path));
        }
        Err(format!(
            "--gateway {spec}: give tcp:ADDR:PORT (e.g. tcp:127.0.0.1:5555) or unix:PATH"
        ))
    }

    /// Stops listening without serving (a Unix socket's file is removed).
    pub fn close(self) {
        if let Bound::Unix(_, path) = self {
            let _ = std::fs::remove_file(path);
        }
    }

    /// Where it listens, as the first audit line says it (`tcp 127.0.0.1:5555`).
    pub fn at(&self) -> String {
        match self {
            Bound::Tcp(l) => l.local_addr().map_or_else(|_| "tcp ?".into(), |a| format!("tcp {a}")),
            Bound::Unix(_, p) => format!("unix {}", p.display()),
        }
    }

    /// Accepts clients for `gw` until `stop` resolves; each is served on its own task. A
    /// Unix socket's file is removed at the end. Needs a tokio runtime.
    pub async fn serve(self, gw: &Gateway, stop: impl Future<Output = ()>) -> std::io::Result<()> {
        tokio::pin!(stop);
        match self {
            Bound::Tcp(l) => {
                let l = tokio::net::TcpListener::from_std(l)?;
                loop {
                    tokio::select! {
                        _ = &mut stop => return Ok(()),
                        got = l.accept() => match got {
                            Ok((stream, peer)) => gw.spawn_client(stream, format!("tcp {peer}")),
                            Err(e) => gw.say(&format!("accept failed: {e}")),
                        },
                    }
                }
            }
            Bound::Unix(l, path) => {
                let l = tokio::net::UnixListener::from_std(l)?;
                let mut n = 0u64;
                loop {
                    tokio::select! {
                        _ = &mut stop => break,
                        got = l.accept() => match got {
                            Ok((stream, _)) => {
                                n += 1;
                                gw.spawn_client(stream, format!("unix client {n}"));
                            }
                            Err(e) => gw.say(&format!("accept failed: {e}")),
                        },
                    }
                }
                let _ = std::fs::remove_file(path);
                Ok(())
            }
        }
    }
}

/// Removes a socket left at `path` by an earlier gateway; refuses any other kind of file.
fn replace_stale_socket(path: &std::path::Path) -> Result<(), String> {
    use std::os::unix::fs::FileTypeExt;
    match std::fs::symlink_metadata(path) {
        Err(_) => Ok(()),
        Ok(m) if m.file_type().is_socket() => {
            std::fs::remove_file(path).map_err(|e| format!("cannot replace the socket {}: {e}", path.display()))
        }
        Ok(_) => Err(format!(
            "{} exists and is not a socket: not replaced (give another PATH)",
            path.display()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gateway_spec_names_tcp_or_unix_and_a_taken_address_is_said() {
        let e = Bound::spec("127.0.0.1:5555").err().unwrap();
        assert!(e.contains("give tcp:ADDR:PORT"), "{e}");
        assert!(Bound::spec("unix:").is_err());
        let b = Bound::spec("tcp:127.0.0.1:0").unwrap();
        let at = b.at();
        assert!(at.starts_with("tcp 127.0.0.1:"), "{at}");
        let taken = at.trim_start_matches("tcp ");
        let e = Bound::spec(&format!("tcp:{taken}")).err().unwrap();
        assert!(e.starts_with(&format!("cannot listen on {taken}:")), "{e}");
        let file = std::env::temp_dir().join(format!("cotui-gw-plain-{}", std::process::id()));
        std::fs::write(&file, "x").unwrap();
        let e = Bound::unix(file.clone()).err().unwrap();
        std::fs::remove_file(&file).unwrap();
        assert!(e.ends_with("is not a socket: not replaced (give another PATH)"), "{e}");
    }
}
