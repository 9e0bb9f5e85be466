//! `cotui serve IFACE --socketcand ADDR:PORT`: any cotui bus (SocketCAN, `demo`, another
//! socketcand bus) served over the socketcand protocol, for python-can, SavvyCAN, cotui's
//! own `socketcand://` client and other tools on other machines.
//!
//! Each client is its own session ([`session::Session`]) on its own bus handle, as
//! socketcand gives each client its own raw socket: a client gets every frame on the bus
//! except the ones it sent itself. The `demo` bus lives as long as the server, so
//! consecutive commands of one client, or several clients, act on the same simulated nodes.
//!
//! Safe by default: clients receive only (`< send >` is answered with an error and nothing
//! is sent) unless `--allow-send`, which `--listen-only` refuses; the caller binds loopback
//! unless told otherwise. Every connect, disconnect, frame sent and send refused is an
//! audit line ([`Audit`]: stderr, or the TUI's message log when the TUI hosts the server). A client that does not read loses frames, never the server's
//! memory: each client has a queue of [`CLIENT_QUEUE`] elements, frames that do not fit
//! are dropped and counted (an audit line at the first, the total at disconnect).

mod jobs;
pub mod session;

use crate::audit::Audit;
use crate::bus::socketcand::wire::{self, Splitter};
use crate::bus::virt::VirtualBus;
use crate::bus::{Bus, BusError, Event};
use crate::frame::Flags;
use session::{Action, Session};
use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::mpsc;

/// Elements queued per client before frames to it are dropped.
pub const CLIENT_QUEUE: usize = 4096;

/// The kernel send buffer of a client's socket (the kernel doubles it): bounds what a
/// client that does not read pins in the kernel, and is ample for a CAN bus at 1 Mbit/s
/// (under 400 KB/s of `< frame >` text) over a LAN.
const CLIENT_SNDBUF: i32 = 128 * 1024;

/// How long frames wait after the `< ok >` of `< rawmode >`, unless the client says more
/// before: python-can's client reads that answer with one `recv` and compares it whole, so
/// a frame in the same read would fail its handshake.
const RAW_GRACE: Duration = Duration::from_millis(300);

/// How the server runs.
#[derive(Clone, Debug)]
pub struct Config {
    /// The bus served (`demo`, a SocketCAN interface, a `socketcand://` address).
    pub iface: String,
    /// Where to listen.
    pub addr: SocketAddr,
    /// Clients may send frames.
    pub allow_send: bool,
    /// The most clients connected at once; more are refused with an error.
    pub max_clients: usize,
    /// Announce the bus by UDP broadcast on port 42000 every 3 s, as socketcand does.
    pub beacon: bool,
}

/// Why the server could not run.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The bus could not be opened.
    #[error(transparent)]
    Bus(#[from] BusError),
    /// The address could not be bound.
    #[error("cannot listen on {addr}: {source}")]
    Bind { addr: SocketAddr, source: std::io::Error },
    /// The signal handlers could not be installed.
    #[error("cannot watch for SIGINT/SIGTERM: {0}")]
    Signal(std::io::Error),
}

/// Where each client's bus handle comes from.
pub enum Source {
    /// The demo's virtual bus, one endpoint per client; lives as long as the server.
    Virtual(VirtualBus),
    /// A bus opened by name, one handle per client.
    Named(String),
}

impl Source {
    async fn open(&self, listen_only: bool) -> Result<Bus, BusError> {
        match self {
            Source::Virtual(v) => Ok(v.endpoint(listen_only)),
            Source::Named(n) => crate::connect::open(n, listen_only).await,
        }
    }
}

/// What the server shares with every client task.
struct Shared {
    source: Source,
    audit: Audit,
    bus: String,
    refused: Option<String>,
    connected: AtomicUsize,
    max_clients: usize,
}

/// Serves `cfg` until SIGINT/SIGTERM, audit lines on stderr. The first audit line names
/// the address bound (port 0 picks one).
pub async fn serve(cfg: Config) -> Result<(), ServeError> {
    use tokio::signal::unix::{SignalKind, signal};
    let mut int = signal(SignalKind::interrupt()).map_err(ServeError::Signal)?;
    let mut term = signal(SignalKind::terminate()).map_err(ServeError::Signal)?;
    // The server's own handle: proves the bus opens, keeps the demo running, reports its state.
    let (source, watch) = if crate::connect::is_demo(&cfg.iface) {
        let demo = crate::sim::demo::Demo::spawn(crate::sim::Simulation::demo(), true);
        (Source::Virtual(demo.vbus.clone()), demo.bus)
    } else {
        let bus = crate::connect::open(&cfg.iface, true).await?;
        (Source::Named(cfg.iface.clone()), bus)
    };
    let listener = listen(cfg.addr).await?;
    let stop = async {
        tokio::select! {
            _ = int.recv() => {}
            _ = term.recv() => {}
        }
    };
    run(listener, source, watch, &cfg, Audit::stderr("serve"), stop).await
}

/// Binds `addr` for [`run`].
pub async fn listen(addr: SocketAddr) -> Result<TcpListener, ServeError> {
    TcpListener::bind(addr)
        .await
        .map_err(|source| ServeError::Bind { addr, source })
}

/// Serves clients of `listener` on buses from `source` until `stop` resolves or the bus
/// `watch` (a listen-only handle of the same bus) closes; its state changes are audit lines.
pub async fn run(
    listener: TcpListener,
    source: Source,
    watch: Bus,
    cfg: &Config,
    audit: Audit,
    stop: impl Future<Output = ()>,
) -> Result<(), ServeError> {
    let local = listener
        .local_addr()
        .map_err(|source| ServeError::Bind { addr: cfg.addr, source })?;
    let refused = (!cfg.allow_send).then(|| "the server was started without --allow-send".to_string());
    audit.say(&format!(
        "socketcand on {local}, bus {} ({}); clients connect to socketcand://{local}/{}",
        cfg.iface,
        if cfg.allow_send {
            "clients may send"
        } else {
            "clients receive only; --allow-send lets them send"
        },
        cfg.iface
    ));
    let shared = Arc::new(Shared {
        source,
        audit: audit.clone(),
        bus: cfg.iface.clone(),
        refused,
        connected: AtomicUsize::new(0),
        max_clients: cfg.max_clients,
    });
    if cfg.beacon {
        tokio::spawn(beacon(local, cfg.iface.clone(), audit.clone()));
    }
    let mut states = watch.subscribe();
    let mut next_id = 0u64;
    tokio::pin!(stop);
    loop {
        tokio::select! {
            got = listener.accept() => match got {
                Ok((stream, peer)) => {
                    next_id += 1;
                    tokio::spawn(client(next_id, stream, peer, shared.clone()));
                }
                Err(e) => {
                    // Out of descriptors and the like: say so, wait a little, go on.
                    audit.say(&format!("accept failed: {e}"));
                    tokio::time::sleep(Duration::from_millis(100)).await;
                }
            },
            ev = states.next() => match ev {
                Ok(Event::State(s)) => audit.say(&format!("bus {}", s.text(&cfg.iface))),
                Ok(Event::Frame(_)) | Err(BusError::Io { .. } | BusError::Unavailable { .. } | BusError::ListenOnly) => {}
                Err(BusError::Closed) => {
                    audit.say("the bus was closed");
                    return Ok(());
                }
            },
            _ = &mut stop => break,
        }
    }
    audit.say("stopped");
    Ok(())
}

/// Counts a client while its task runs.
struct Seat<'a>(&'a AtomicUsize);

impl Drop for Seat<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

/// What one client did, for its last audit line.
#[derive(Default)]
struct Tally {
    sent: u64,
    refused: u64,
    forwarded: u64,
    /// Frames dropped because the client's queue was full.
    dropped: u64,
    /// Frames the session itself missed (it fell behind the bus).
    lagged: u64,
    /// Errors answered (garbled, unknown or refused commands).
    errors: u64,
}

impl Tally {
    /// The audit line at the first frame this client loses.
    fn first_drop(&self, who: &str, audit: &Audit) {
        if self.dropped + self.lagged == 0 {
            audit.say(&format!(
                "{who} does not read fast enough: dropping frames to it (its queue of {CLIENT_QUEUE} is full)"
            ));
        }
    }
}

/// One client's connection, from greeting to close.
async fn client(id: u64, stream: TcpStream, peer: SocketAddr, shared: Arc<Shared>) {
    let who = format!("client {id} ({peer})");
    let n = shared.connected.fetch_add(1, Ordering::Relaxed) + 1;
    let _seat = Seat(&shared.connected);
    let _ = stream.set_nodelay(true);
    {
        use std::os::fd::AsRawFd;
        let _ = crate::bus::socketcan::setsockopt_int(stream.as_raw_fd(), libc::SO_SNDBUF, CLIENT_SNDBUF);
    }
    let (mut rd, mut wr) = stream.into_split();
    if n > shared.max_clients {
        shared.audit.say(&format!(
            "{who} refused: {} clients connected already (--max-clients)",
            n - 1
        ));
        let text = wire::error_element(&format!("too many clients ({} connected)", n - 1));
        let _ = wr.write_all(text.as_bytes()).await;
        return;
    }
    let bus = match shared.source.open(shared.refused.is_some()).await {
        Ok(b) => b,
        Err(e) => {
            shared.audit.say(&format!("{who}: bus unavailable: {e}"));
            let _ = wr
                .write_all(wire::error_element(&format!("could not open bus: {e}")).as_bytes())
                .await;
            return;
        }
    };
    shared.audit.say(&format!("{who} connected"));
    let (tx, mut rx) = mpsc::channel::<String>(CLIENT_QUEUE);
    let writer = tokio::spawn(async move {
        while let Some(text) = rx.recv().await {
            if wr.write_all(text.as_bytes()).await.is_err() {
                break;
            }
        }
    });
    let mut tally = Tally::default();
    let end = session(&who, &bus, &shared, &tx, &mut rd, &mut tally).await;
    drop(tx);
    // Let the last replies (an error before a close) reach the client, but never wait on
    // a client that does not read.
    let _ = tokio::time::timeout(Duration::from_secs(1), writer).await;
    shared.audit.say(&format!(
        "{who} disconnected ({end}): {} frames sent, {} sends refused, {} frames received, {} dropped (queue full), {} errors answered",
        tally.sent,
        tally.refused,
        tally.forwarded,
        tally.dropped + tally.lagged,
        tally.errors
    ));
}

/// Runs the session until the client leaves or must go; returns why it ended.
async fn session(
    who: &str,
    bus: &Bus,
    shared: &Shared,
    tx: &mpsc::Sender<String>,
    rd: &mut tokio::net::tcp::OwnedReadHalf,
    tally: &mut Tally,
) -> &'static str {
    let mut sub = bus.subscribe();
    let mut s = Session::new(&shared.bus, shared.refused.clone());
    let mut splitter = Splitter::new();
    let mut buf = vec![0u8; 8192];
    let mut elements = Vec::new();
    // Frames wait until then after `< rawmode >` (see RAW_GRACE).
    let mut hold: Option<tokio::time::Instant> = None;
    let mut streaming = false;
    // The client's send jobs: they end with the session.
    let mut jobs = jobs::Jobs::default();
    if tx.send(Session::greeting().to_string()).await.is_err() {
        return "write failed";
    }
    loop {
        let held = hold.unwrap_or_else(tokio::time::Instant::now);
        tokio::select! {
            got = rd.read(&mut buf) => {
                let n = match got {
                    Ok(0) => return "closed by the client",
                    Ok(n) => n,
                    Err(_) => return "read failed",
                };
                splitter.push(&buf[..n], &mut elements);
                // The client speaks again after `< rawmode >`: it read the `< ok >` (cotui's
                // own client asks its send policy at once), so frames need not wait.
                if s.raw() && !elements.is_empty() {
                    hold = None;
                }
                for e in elements.drain(..) {
                    let was_raw = s.raw();
                    for action in s.on_element(e) {
                        match action {
                            Action::Reply(text) => {
                                // Every garbled, unknown or refused command is answered with an error.
                                if text.starts_with("< error") {
                                    tally.errors += 1;
                                }
                                if tx.send(text).await.is_err() {
                                    return "write failed";
                                }
                            }
                            Action::Send(f) => match bus.send(&f).await {
                                Ok(()) => {
                                    tally.sent += 1;
                                    shared.audit.say(&format!("{who} sent {}", crate::command::candump(&f)));
                                    // A burst of sends must not starve the other clients' sessions.
                                    tokio::task::yield_now().await;
                                }
                                Err(e) => {
                                    shared.audit.say(&format!("{who}: sending {} failed: {e}", crate::command::candump(&f)));
                                    let _ = tx.send(wire::error_element(&format!("send failed: {e}"))).await;
                                }
                            },
                            Action::Refused(f) => {
                                tally.refused += 1;
                                shared.audit.say(&format!("{who} send refused (no --allow-send): {}", crate::command::candump(&f)));
                            }
                            Action::Close => return "wrong bus",
                            Action::Cyclic { frame, interval_ns } => {
                                let every = if interval_ns == 0 {
                                    "once".to_string()
                                } else {
                                    format!("every {} us", interval_ns / 1000)
                                };
                                shared.audit.say(&format!("{who} send job {} {every}", crate::command::candump(&frame)));
                                jobs.add(bus, frame, interval_ns, who.to_string(), shared.audit.clone());
                            }
                            Action::Update(frame) => {
                                shared.audit.say(&format!("{who} send job updated: {}", crate::command::candump(&frame)));
                                jobs.update(frame);
                            }
                            Action::Delete(id, ext) => {
                                shared.audit.say(&format!("{who} send job {id:X} deleted"));
                                jobs.delete(id, ext);
                            }
                        }
                    }
                    if s.raw() && !was_raw {
                        hold = Some(tokio::time::Instant::now() + RAW_GRACE);
                    }
                    streaming = s.opened();
                }
            }
            _ = tokio::time::sleep_until(held), if hold.is_some() => hold = None,
            ev = sub.next(), if streaming && hold.is_none() => match ev {
                Ok(Event::Frame(f)) if !f.flags.has(Flags::TX) => {
                    let Some(text) = s.forward(&f) else { continue };
                    match tx.try_send(text) {
                        Ok(()) => tally.forwarded += 1,
                        Err(mpsc::error::TrySendError::Full(_)) => {
                            tally.first_drop(who, &shared.audit);
                            tally.dropped += 1;
                        }
                        Err(mpsc::error::TrySendError::Closed(_)) => return "write failed",
                    }
                }
                Ok(_) => {}
                Err(BusError::Closed) => return "the bus was closed",
                Err(_) => {}
            },
        }
        if sub.lost() > tally.lagged {
            tally.first_drop(who, &shared.audit);
            tally.lagged = sub.lost();
        }
    }
}

/// Announces the bus as socketcand does: a UDP broadcast on port 42000 every 3 s.
async fn beacon(local: SocketAddr, bus: String, audit: Audit) {
    let Ok(sock) = tokio::net::UdpSocket::bind("0.0.0.0:0").await else {
        audit.say("beacon: cannot open a UDP socket");
        return;
    };
    if sock.set_broadcast(true).is_err() {
        audit.say("beacon: broadcast not permitted");
        return;
    }
    let text = format!(
        "<CANBeacon name=\"cotui\" type=\"SocketCAN\" description=\"cotui serve\">\n<URL>can://{local}</URL><Bus name=\"{}\"/></CANBeacon>",
        wire::printable(&bus, 64)
    );
    audit.say(&format!("beacon: announcing {bus} on UDP port 42000 every 3 s"));
    loop {
        let _ = sock.send_to(text.as_bytes(), "255.255.255.255:42000").await;
        tokio::time::sleep(Duration::from_secs(3)).await;
    }
}
