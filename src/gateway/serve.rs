//! The gateway's IO: clients on stdin/stdout, a Unix socket or a TCP address, each with
//! its own [`Session`]; lines read with a bounded length; notifications from one watch of
//! the bus, kept by every session for `log` and, with [`Policy::notify`], written to the
//! client between its answers.
//!
//! Requests of different clients that go on the bus run one after another (one lock):
//! two SDO transfers to the same node at once would take each other's answers.

use super::answer::Notice;
use super::line::MAX_LINE;
use super::session::{Policy, Session, seq_of};
use super::watch::Watch;
use crate::audit::Audit;
use crate::bus::Bus;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use tokio::io::{AsyncBufRead, AsyncBufReadExt, AsyncWrite, AsyncWriteExt, BufReader};
use tokio::sync::{Mutex, broadcast};

/// Clients served at once on a socket; one more is told so and closed.
pub const MAX_CLIENTS: usize = 64;

/// Notifications queued per client while it waits for an answer; past that the oldest are
/// dropped and the client is told how many (a line `... N notifications dropped`).
const NOTICE_QUEUE: usize = 1024;

/// What every client of one gateway shares.
#[derive(Clone)]
pub struct Gateway {
    bus: Bus,
    policy: Policy,
    lock: Arc<Mutex<()>>,
    notices: broadcast::Sender<Notice>,
    clients: Arc<AtomicUsize>,
    audit: Audit,
}

impl Gateway {
    /// A gateway on `bus`, its clients' connects and disconnects (and, when `audit` asks,
    /// every request and answer) told to `audit`; starts the watch that makes the
    /// notifications. Needs a tokio runtime.
    pub fn start(bus: Bus, policy: Policy, audit: Audit) -> Gateway {
        let (notices, _) = broadcast::channel(NOTICE_QUEUE);
        let tx = notices.clone();
        let mut rx = bus.subscribe();
        tokio::spawn(async move {
            let mut watch = Watch::default();
            loop {
                match rx.recv().await {
                    Ok(f) => {
                        if let Some(n) = watch.on_frame(&f) {
                            let _ = tx.send(n);
                        }
                    }
                    Err(crate::bus::BusError::Closed) => break,
                    Err(_) => {}
                }
            }
        });
        Gateway {
            bus,
            policy,
            lock: Arc::new(Mutex::new(())),
            notices,
            clients: Arc::new(AtomicUsize::new(0)),
            audit,
        }
    }

    /// Serves one client (`who`, in request audit lines) until it closes its side (or
    /// writing to it fails).
    pub async fn serve<R, W>(&self, who: &str, reader: R, mut writer: W) -> std::io::Result<()>
    where
        R: tokio::io::AsyncRead + Unpin,
        W: AsyncWrite + Unpin,
    {
        let mut lines = Lines::new(BufReader::new(reader));
        let mut notices = self.notices.subscribe();
        let mut session = Session::new(self.bus.clone(), self.policy);
        loop {
            tokio::select! {
                biased;
                notice = notices.recv() => {
                    let text = match notice {
                        Ok(n) => {
                            let line = n.line(&now_text());
                            session.keep(&line);
                            line
                        }
                        Err(broadcast::error::RecvError::Lagged(k)) => {
                            let line = format!("... {k} notifications dropped (the client read too slowly)\r\n");
                            session.keep(&line);
                            line
                        }
                        Err(broadcast::error::RecvError::Closed) => continue,
                    };
                    if session.policy().notify {
                        writer.write_all(text.as_bytes()).await?;
                        writer.flush().await?;
                    }
                }
                line = lines.next() => {
                    let answer = match line? {
                        None => return Ok(()),
                        Some(Read::Line(bytes)) => {
                            let _turn = self.lock.lock().await;
                            let answer = session.answer(&bytes).await;
                            if self.audit.logs_requests() {
                                let asked = String::from_utf8_lossy(&bytes);
                                self.audit.say(&format!("{who}: {} -> {}", asked.trim(), answer.trim_end()));
                            }
                            answer
                        }
                        Some(Read::TooLong(prefix)) => super::answer::error(
                            seq_of(&prefix).unwrap_or(0),
                            super::answer::Code::Syntax,
                            &format!("the line is longer than {MAX_LINE} bytes (skipped to its end)"),
                        ),
                    };
                    writer.write_all(answer.as_bytes()).await?;
                    writer.flush().await?;
                }
            }
        }
    }

    /// Writes an audit line (where it listens, accept failures).
    pub fn say(&self, line: &str) {
        self.audit.say(line);
    }

    /// Counts a client in; `None` (and nothing counted) when [`MAX_CLIENTS`] are served.
    fn admit(&self) -> Option<Admitted> {
        let n = self.clients.fetch_add(1, Ordering::SeqCst);
        if n >= MAX_CLIENTS {
            self.clients.fetch_sub(1, Ordering::SeqCst);
            return None;
        }
        Some(Admitted(self.clients.clone()))
    }

    /// Serves a socket's client on its own task, with audit lines on stderr.
    pub fn spawn_client<S>(&self, stream: S, who: String)
    where
        S: tokio::io::AsyncRead + AsyncWrite + Send + Unpin + 'static,
    {
        let Some(admitted) = self.admit() else {
            self.audit.say(&format!("{who} refused: {MAX_CLIENTS} clients already"));
            tokio::spawn(async move {
                let mut stream = stream;
                let text = super::answer::error(
                    0,
                    super::answer::Code::InternalState,
                    &format!("{MAX_CLIENTS} clients are served already: try again later"),
                );
                let _ = stream.write_all(text.as_bytes()).await;
                let _ = stream.shutdown().await;
            });
            return;
        };
        self.audit.say(&format!("{who} connected"));
        let gw = self.clone();
        tokio::spawn(async move {
            let (r, w) = tokio::io::split(stream);
            let end = gw.serve(&who, r, w).await;
            drop(admitted);
            match end {
                Ok(()) => gw.audit.say(&format!("{who} disconnected")),
                Err(e) => gw.audit.say(&format!("{who} disconnected: {e}")),
            }
        });
    }
}

/// A client counted in [`Gateway::admit`]; counted out when dropped.
struct Admitted(Arc<AtomicUsize>);

impl Drop for Admitted {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The wall clock as canopend stamps its log lines (`YYYY-MM-DD HH:MM:SS`; here UTC).
fn now_text() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    crate::calendar::utc_text(secs)
}

/// What [`Lines::next`] read.
enum Read {
    /// A line without its end (LF, and a CR before it).
    Line(Vec<u8>),
    /// A line longer than [`MAX_LINE`]: its first bytes (the rest was skipped).
    TooLong(Vec<u8>),
}

/// Lines of at most [`MAX_LINE`] bytes. Cancel-safe: the only wait is `fill_buf`, and the
/// line so far is kept in `self`.
struct Lines<R> {
    reader: R,
    line: Vec<u8>,
    too_long: bool,
}

impl<R: AsyncBufRead + Unpin> Lines<R> {
    fn new(reader: R) -> Lines<R> {
        Lines {
            reader,
            line: Vec::new(),
            too_long: false,
        }
    }

    /// The next line; `None` at the end of the input (a last line without LF counts).
    async fn next(&mut self) -> std::io::Result<Option<Read>> {
        loop {
            let buf = self.reader.fill_buf().await?;
            if buf.is_empty() {
                if self.line.is_empty() && !self.too_long {
                    return Ok(None);
                }
                return Ok(Some(self.take()));
            }
            let (part, found) = match memchr::memchr(b'\n', buf) {
                Some(i) => (&buf[..i], Some(i + 1)),
                None => (buf, None),
            };
            if !self.too_long {
                let room = MAX_LINE.saturating_sub(self.line.len());
                if part.len() > room {
                    self.line.extend_from_slice(&part[..room]);
                    self.too_long = true;
                } else {
                    self.line.extend_from_slice(part);
                }
            }
            let used = found.unwrap_or(buf.len());
            self.reader.consume(used);
            if found.is_some() {
                return Ok(Some(self.take()));
            }
        }
    }

    fn take(&mut self) -> Read {
        let mut line = std::mem::take(&mut self.line);
        if std::mem::take(&mut self.too_long) {
            line.truncate(64);
            return Read::TooLong(line);
        }
        if line.last() == Some(&b'\r') {
            line.pop();
        }
        Read::Line(line)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn lines_are_bounded_and_a_long_one_is_skipped_to_its_end() {
        let mut input = b"[1] help\r\n".to_vec();
        input.extend(std::iter::repeat_n(b'x', MAX_LINE + 10));
        input.extend(b"\n[2] log\nlast");
        let mut lines = Lines::new(BufReader::with_capacity(1000, &input[..]));
        let mut got = Vec::new();
        while let Some(r) = lines.next().await.unwrap() {
            got.push(match r {
                Read::Line(l) => String::from_utf8(l).unwrap(),
                Read::TooLong(p) => format!("too long: {}", p.len()),
            });
        }
        assert_eq!(got, ["[1] help", "too long: 64", "[2] log", "last"]);
    }
}
