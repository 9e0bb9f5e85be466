//! A bus on another machine through a socketcand server (`socketcand://HOST:PORT/CHANNEL`):
//! `cotui serve`, or linux-can's socketcand daemon.
//!
//! The handle connects, opens CHANNEL in raw mode and then behaves as a SocketCAN handle:
//! frames carry the server's receive timestamps (`< frame ID SECS.USECS DATA >`, CAN FD
//! frames `< fdframe ID FLAGS SECS.USECS DATA >` and sent as `< fdsend >`, see [`wire`]), a
//! frame sent comes back marked TX, and a lost connection is a state change
//! ([`BusState::Disconnected`]), after which the reader reconnects every second and reports
//! [`BusState::Active`] when capture is back.
//!
//! **Time.** [`Bus::now_ns`] on a remote bus is the *server's* clock as seen from here: the
//! local wall clock plus an offset, the largest `server timestamp - local arrival time` of
//! the frames of the last 10 to 20 s (the least-delayed frame; so "now" is the server's
//! clock minus the one-way network delay, and a frame stamped T arrives when "now" is about T).
//! The echo of a frame we send is stamped with "now" plus the measured round trip (an
//! `< echo >` every 2 s, and one at connect): the time it reaches the remote bus. So an SDO
//! timeout counts from when the request is on the remote bus to the answer's own
//! timestamp there: network latency does not eat into `--timeout`, and clocks of the two
//! machines need not agree.
//!
//! Whether the server lets this client send is asked at connect (`< cotui_send_policy >`;
//! another socketcand answers it with an error, taken as yes): a handle on a server that
//! refuses fails every send at once with the server's reason instead of timing out.

pub mod wire;

use super::pace::Pace;
use super::state::{BusState, StateChange};
use super::{Bus, BusError, Carried, Clock, Item, QUEUE_DEPTH, Sender};
use crate::frame::Frame;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;
use tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
use tokio::sync::broadcast;
use wire::{Reply, Splitter, WireError};

/// How a bus name of this kind starts.
pub const SCHEME: &str = "socketcand://";

/// How long connecting and the handshake may take.
const HANDSHAKE: Duration = Duration::from_secs(5);
/// How often the round trip is measured.
const ECHO_EVERY: Duration = Duration::from_secs(2);
/// How long one window of the clock offset's maximum lasts.
const OFFSET_WINDOW_NS: u64 = 10_000_000_000;
/// The endpoint of the frames this handle sent.
const OWN: u32 = 1;

/// True when `name` names a socketcand bus.
pub fn is_url(name: &str) -> bool {
    name.starts_with(SCHEME)
}

/// Where a socketcand bus is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Remote {
    /// Host name or address (an IPv6 address without brackets).
    pub host: String,
    /// TCP port.
    pub port: u16,
    /// The bus on the server (`< open CHANNEL >`).
    pub channel: String,
}

/// Parses `socketcand://HOST:PORT/CHANNEL` (IPv6 hosts in brackets: `[::1]`).
pub fn parse_url(url: &str) -> Result<Remote, BusError> {
    let bad = |why: &str| BusError::Unavailable {
        iface: url.to_string(),
        reason: why.to_string(),
        fix: "write socketcand://HOST:PORT/CHANNEL, e.g. socketcand://192.168.1.20:29536/can0".into(),
    };
    let rest = url
        .strip_prefix(SCHEME)
        .ok_or_else(|| bad("not a socketcand:// address"))?;
    let (authority, channel) = rest.split_once('/').ok_or_else(|| bad("no /CHANNEL"))?;
    if channel.is_empty()
        || channel.len() > 64
        || !channel.bytes().all(|b| b.is_ascii_graphic() && b != b'<' && b != b'>')
    {
        return Err(bad("the channel must be a bus name on the server (e.g. can0)"));
    }
    let (host, port) = authority.rsplit_once(':').ok_or_else(|| bad("no :PORT"))?;
    let host = host.strip_prefix('[').and_then(|h| h.strip_suffix(']')).unwrap_or(host);
    let port = port
        .parse::<u16>()
        .ok()
        .filter(|p| *p != 0)
        .ok_or_else(|| bad("the port must be 1..65535"))?;
    if host.is_empty() {
        return Err(bad("no host"));
    }
    Ok(Remote {
        host: host.to_string(),
        port,
        channel: channel.to_string(),
    })
}

/// Wall-clock time in ns since the Unix epoch.
fn wall_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// The connection of a handle, shared by its clones and its reader.
pub(super) struct Link {
    name: String,
    events: broadcast::Sender<Carried>,
    writer: tokio::sync::Mutex<Option<OwnedWriteHalf>>,
    /// Server clock minus local clock minus the one-way delay, ns.
    offset_ns: AtomicI64,
    /// The last measured round trip, ns.
    rtt_ns: AtomicU64,
    /// The timestamp of the last echo of a frame sent.
    last_echo_ns: AtomicU64,
    /// Why the server refuses this client's frames (none: it accepts them).
    refused: Mutex<Option<String>>,
}

impl Link {
    /// The server's clock as seen from here (see the module doc).
    pub(super) fn now_ns(&self) -> u64 {
        wall_ns().saturating_add_signed(self.offset_ns.load(Ordering::Relaxed))
    }

    fn lost(&self) -> BusError {
        BusError::Unavailable {
            iface: self.name.clone(),
            reason: "connection to the server lost".into(),
            fix: BusState::Disconnected.fix(&self.name).unwrap_or_default(),
        }
    }

    /// Sends `frame` as `< send >` (`< fdsend >` for CAN FD); its echo goes to the subscriptions marked TX.
    pub(super) async fn write(&self, frame: &Frame) -> Result<(), BusError> {
        if let Some(why) = self.refused.lock().ok().and_then(|r| r.clone()) {
            return Err(BusError::Unavailable {
                iface: self.name.clone(),
                reason: format!("the server does not let clients send ({why})"),
                fix: "start the server with --allow-send (cotui serve IFACE --socketcand ADDR:PORT --allow-send)"
                    .into(),
            });
        }
        let text = wire::send_element(frame).map_err(|reason| BusError::Io {
            iface: self.name.clone(),
            reason,
        })?;
        let mut w = self.writer.lock().await;
        let Some(stream) = w.as_mut() else {
            return Err(self.lost());
        };
        if stream.write_all(text.as_bytes()).await.is_err() {
            *w = None;
            return Err(self.lost());
        }
        drop(w);
        let mut echo = *frame;
        // Monotonic, although the offset and the round trip change between two sends.
        let at = self.now_ns().saturating_add(self.rtt_ns.load(Ordering::Relaxed));
        let last = self.last_echo_ns.fetch_max(at, Ordering::Relaxed);
        echo.ts_ns = at.max(last);
        let _ = self.events.send(Carried {
            origin: OWN,
            item: Item::Frame(echo),
        });
        Ok(())
    }

    async fn write_text(&self, text: &str) -> bool {
        let mut w = self.writer.lock().await;
        match w.as_mut() {
            Some(s) => s.write_all(text.as_bytes()).await.is_ok(),
            None => false,
        }
    }
}

/// The reader task of a handle; aborted when the last clone of the handle is dropped.
pub(super) struct Shared {
    pub(super) link: Arc<Link>,
    task: tokio::task::JoinHandle<()>,
}

impl Drop for Shared {
    fn drop(&mut self) {
        self.task.abort();
    }
}

/// A connection's read side with the elements split so far.
struct Conn {
    read: OwnedReadHalf,
    splitter: Splitter,
    queued: std::collections::VecDeque<Result<String, WireError>>,
}

impl Conn {
    /// The next element; `None` at the end of the stream or on a read error.
    async fn next(&mut self) -> Option<Result<String, WireError>> {
        let mut buf = [0u8; 8192];
        loop {
            if let Some(e) = self.queued.pop_front() {
                return Some(e);
            }
            let n = self.read.read(&mut buf).await.ok().filter(|n| *n > 0)?;
            let mut out = Vec::new();
            self.splitter.push(&buf[..n], &mut out);
            self.queued.extend(out);
        }
    }
}

/// What a successful handshake gives.
struct Connected {
    conn: Conn,
    write: OwnedWriteHalf,
    refused: Option<String>,
    rtt_ns: u64,
    /// `server time - local arrival` of the frames that came during the handshake.
    offset_ns: Option<i64>,
}

/// Connects and opens the channel in raw mode, within [`HANDSHAKE`].
async fn handshake(name: &str, remote: &Remote) -> Result<Connected, BusError> {
    let unavailable = |reason: String| BusError::Unavailable {
        iface: name.to_string(),
        reason,
        fix: format!(
            "start the server on {}: cotui serve IFACE --socketcand {}:{} --bind ADDR (or socketcand -i IFACE -p {})",
            remote.host, remote.host, remote.port, remote.port
        ),
    };
    let steps = async {
        let stream = TcpStream::connect((remote.host.as_str(), remote.port))
            .await
            .map_err(|e| unavailable(format!("cannot connect to {}:{}: {e}", remote.host, remote.port)))?;
        let _ = stream.set_nodelay(true);
        let (read, mut write) = stream.into_split();
        let mut conn = Conn {
            read,
            splitter: Splitter::new(),
            queued: Default::default(),
        };
        let expect = async |conn: &mut Conn, what: &str| -> Result<(), BusError> {
            match conn.next().await {
                Some(Ok(t)) => match wire::parse_reply(&t) {
                    Ok(Reply::Hi) if what == "hi" => Ok(()),
                    Ok(Reply::Ok) if what == "ok" => Ok(()),
                    Ok(Reply::Error(e)) => Err(unavailable(format!("the server refused: {e}"))),
                    _ => Err(unavailable(format!(
                        "the server answered < {} > instead of < {what} >: is this a socketcand server?",
                        wire::printable(&t, 40)
                    ))),
                },
                Some(Err(e)) => Err(unavailable(format!(
                    "the server sent garbage ({e}): is this a socketcand server?"
                ))),
                None => Err(unavailable("the server closed the connection".into())),
            }
        };
        let send = async |write: &mut OwnedWriteHalf, text: String| {
            write
                .write_all(text.as_bytes())
                .await
                .map_err(|e| unavailable(format!("lost the connection: {e}")))
        };
        expect(&mut conn, "hi").await?;
        send(&mut write, format!("< open {} >", remote.channel)).await?;
        expect(&mut conn, "ok").await?;
        send(&mut write, "< rawmode >".into()).await?;
        expect(&mut conn, "ok").await?;
        let t0 = wall_ns();
        send(&mut write, "< cotui_send_policy >< echo >".into()).await?;
        let mut refused = None;
        let mut offset_ns = None::<i64>;
        loop {
            match conn.next().await {
                Some(Ok(t)) => match wire::parse_reply(&t) {
                    Ok(Reply::Echo) => break,
                    Ok(Reply::SendPolicy(p)) => refused = p,
                    Ok(Reply::Frame(f)) => {
                        let s = f.ts_ns as i64 - wall_ns() as i64;
                        offset_ns = Some(offset_ns.map_or(s, |o| o.max(s)));
                    }
                    _ => {}
                },
                Some(Err(_)) => {}
                None => return Err(unavailable("the server closed the connection".into())),
            }
        }
        Ok(Connected {
            conn,
            write,
            refused,
            rtt_ns: wall_ns().saturating_sub(t0),
            offset_ns,
        })
    };
    match tokio::time::timeout(HANDSHAKE, steps).await {
        Ok(r) => r,
        Err(_) => Err(unavailable(format!(
            "no answer from {}:{} within {} s",
            remote.host,
            remote.port,
            HANDSHAKE.as_secs()
        ))),
    }
}

/// Opens `url` (`socketcand://HOST:PORT/CHANNEL`). Must be called inside a tokio runtime.
pub async fn open(url: &str, listen_only: bool) -> Result<Bus, BusError> {
    let remote = parse_url(url)?;
    let c = handshake(url, &remote).await?;
    let events = broadcast::channel(QUEUE_DEPTH).0;
    let link = Arc::new(Link {
        name: url.to_string(),
        events: events.clone(),
        writer: tokio::sync::Mutex::new(Some(c.write)),
        offset_ns: AtomicI64::new(c.offset_ns.unwrap_or(0)),
        rtt_ns: AtomicU64::new(c.rtt_ns),
        last_echo_ns: AtomicU64::new(0),
        refused: Mutex::new(c.refused),
    });
    let reader = Reader {
        link: link.clone(),
        remote,
        offset: Offset::new(c.offset_ns),
        echo_sent: None,
    };
    let task = tokio::spawn(reader.run(c.conn));
    let sender = (!listen_only).then(|| Sender::Remote(link.clone()));
    Ok(Bus {
        name: url.to_string(),
        endpoint: OWN,
        events,
        sender,
        socket: None,
        clock: Clock::Remote(Arc::new(Shared { link, task })),
        turns: Default::default(),
    })
}

/// The largest clock sample over a sliding window of two [`OFFSET_WINDOW_NS`] halves.
struct Offset {
    current: Option<i64>,
    previous: Option<i64>,
    since_ns: u64,
}

impl Offset {
    fn new(first: Option<i64>) -> Offset {
        Offset {
            current: first,
            previous: None,
            since_ns: wall_ns(),
        }
    }
    /// Takes one sample at local time `now`; returns the offset in force.
    fn sample(&mut self, s: i64, now: u64) -> i64 {
        if now.saturating_sub(self.since_ns) > OFFSET_WINDOW_NS {
            self.previous = self.current.take();
            self.since_ns = now;
        }
        self.current = Some(self.current.map_or(s, |c| c.max(s)));
        self.current.max(self.previous).unwrap_or(s)
    }
}

/// Reads the server's elements onto the subscriptions, measures the round trip, reconnects.
struct Reader {
    link: Arc<Link>,
    remote: Remote,
    offset: Offset,
    echo_sent: Option<u64>,
}

impl Reader {
    fn state(&self, state: BusState) {
        let _ = self.link.events.send(Carried {
            origin: 0,
            item: Item::State(StateChange {
                ts_ns: self.link.now_ns(),
                state,
                counters: None,
            }),
        });
    }

    async fn run(mut self, mut conn: Conn) {
        let mut echo = tokio::time::interval(ECHO_EVERY);
        echo.tick().await;
        let mut pace = Pace::default();
        loop {
            tokio::select! {
                got = conn.next() => match got {
                    Some(Ok(text)) => {
                        self.element(&text);
                        pace.published(&self.link.events).await;
                    }
                    Some(Err(_)) => {}
                    None => conn = self.reconnect().await,
                },
                _ = echo.tick() => {
                    if self.echo_sent.is_none() && self.link.write_text("< echo >").await {
                        self.echo_sent = Some(wall_ns());
                    }
                }
            }
        }
    }

    fn element(&mut self, text: &str) {
        match wire::parse_reply(text) {
            Ok(Reply::Frame(f)) => {
                let now = wall_ns();
                let o = self.offset.sample(f.ts_ns as i64 - now as i64, now);
                self.link.offset_ns.store(o, Ordering::Relaxed);
                let _ = self.link.events.send(Carried {
                    origin: 0,
                    item: Item::Frame(f),
                });
            }
            Ok(Reply::Echo) => {
                if let Some(t0) = self.echo_sent.take() {
                    self.link.rtt_ns.store(wall_ns().saturating_sub(t0), Ordering::Relaxed);
                }
            }
            _ => {}
        }
    }

    /// Reports the loss, then tries again every second until the server answers.
    async fn reconnect(&mut self) -> Conn {
        *self.link.writer.lock().await = None;
        self.echo_sent = None;
        self.state(BusState::Disconnected);
        loop {
            tokio::time::sleep(Duration::from_secs(1)).await;
            if let Ok(c) = handshake(&self.link.name, &self.remote).await {
                *self.link.writer.lock().await = Some(c.write);
                if let Ok(mut r) = self.link.refused.lock() {
                    *r = c.refused;
                }
                self.link.rtt_ns.store(c.rtt_ns, Ordering::Relaxed);
                self.offset = Offset::new(c.offset_ns);
                if let Some(o) = c.offset_ns {
                    self.link.offset_ns.store(o, Ordering::Relaxed);
                }
                self.state(BusState::Active);
                return c.conn;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_name_host_port_and_channel() {
        assert_eq!(
            parse_url("socketcand://192.168.1.20:29536/can0"),
            Ok(Remote {
                host: "192.168.1.20".into(),
                port: 29536,
                channel: "can0".into()
            })
        );
        assert_eq!(parse_url("socketcand://[::1]:5/demo").map(|r| r.host), Ok("::1".into()));
        for bad in [
            "socketcand://host/can0",
            "socketcand://host:0/can0",
            "socketcand://host:99999/can0",
            "socketcand://host:1/",
            "socketcand://:1/can0",
            "socketcand://host:1",
        ] {
            let e = parse_url(bad).unwrap_err().to_string();
            assert!(e.contains("fix: write socketcand://HOST:PORT/CHANNEL"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_offset_is_the_least_delayed_sample_of_the_window() {
        let mut o = Offset::new(None);
        let t = o.since_ns;
        assert_eq!(o.sample(-5_000, t), -5_000);
        assert_eq!(o.sample(-2_000, t + 1), -2_000);
        assert_eq!(o.sample(-9_000, t + 2), -2_000);
        // After a window the old maximum still counts, after two it is gone.
        assert_eq!(o.sample(-7_000, t + OFFSET_WINDOW_NS + 3), -2_000);
        assert_eq!(o.sample(-8_000, t + 2 * OFFSET_WINDOW_NS + 10), -7_000);
    }
}
