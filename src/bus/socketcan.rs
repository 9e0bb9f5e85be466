//! SocketCAN: one raw CAN FD socket per handle (classic and FD frames), kernel
//! receive timestamps (`SO_TIMESTAMPNS`), error frames (all error classes) and our own
//! frames (`CAN_RAW_RECV_OWN_MSGS`, recognised by `MSG_CONFIRM`, marked TX).
//!
//! The receive buffer is enlarged to [`RCVBUF_BYTES`] so that a reader that falls behind
//! for a moment (a burst at full bus load, a busy machine) loses nothing; the kernel's
//! count of frames dropped on a full buffer (`SO_MEMINFO`) is [`Bus::dropped`].
//!
//! The `socketcan` crate opens the socket and sets its options. Frames are read with
//! our own `recvmsg` because the crate does not expose `msg_flags`, which is the only
//! way to tell our own frames from those of other programs.

use super::error::{missing_fix, up_fix};
use super::pace::Pace;
use super::state::{Action, BusState, StateChange, SysLink, decide};
use super::{Bus, BusError, Carried, Item, QUEUE_DEPTH, Sender};
use crate::decode::error_frame::controller_state;
use crate::frame::linux::{CAN_EFF_FLAG, CAN_EFF_MASK, CAN_ERR_FLAG, CAN_RTR_FLAG, CANFD_BRS, CANFD_ESI, CANFD_FDF};
use crate::frame::{Flags, Frame};
use socketcan::{CanFdSocket, Socket as _, SocketOptions};
use std::io;
use std::os::fd::AsRawFd;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, RwLock};
use std::time::Duration;
use tokio::io::Interest;
use tokio::io::unix::AsyncFd;
use tokio::sync::{broadcast, mpsc, oneshot};

/// `CAN_ERR_MASK`: the error class bits of an error frame's identifier.
const CAN_ERR_MASK: u32 = CAN_EFF_MASK;
/// All error classes (`CAN_ERR_MASK`).
const ERR_MASK_ALL: u32 = CAN_ERR_MASK;
/// Size of `struct can_frame`.
pub const CAN_MTU: usize = 16;
/// Size of `struct canfd_frame`.
pub const CANFD_MTU: usize = 72;
/// The receive buffer asked for: with the kernel's doubling about 16 MB, some 20000 frames
/// (a full-rate burst of 20000 frames while a busy machine lets the reader fall seconds behind).
/// Root (`CAP_NET_ADMIN`) gets it through `SO_RCVBUFFORCE`; otherwise `SO_RCVBUF` is capped
/// at `net.core.rmem_max`.
pub const RCVBUF_BYTES: i32 = 8 << 20;
/// `ARPHRD_CAN` in `/sys/class/net/IFACE/type`.
const ARPHRD_CAN: u32 = 280;

/// Checks `/sys/class/net/IFACE`: present, CAN, up.
fn check_interface(iface: &str) -> Result<(), BusError> {
    let unavailable = |reason: &str, fix: String| BusError::Unavailable {
        iface: iface.to_string(),
        reason: reason.to_string(),
        fix,
    };
    if iface.is_empty() || iface.contains('/') || iface.len() > 15 {
        return Err(unavailable("not a valid interface name", missing_fix("can0")));
    }
    let dir = std::path::Path::new("/sys/class/net").join(iface);
    if !dir.exists() {
        return Err(unavailable("no such CAN interface", missing_fix(iface)));
    }
    let read_num = |file: &str, radix: u32| {
        std::fs::read_to_string(dir.join(file))
            .ok()
            .and_then(|s| u32::from_str_radix(s.trim().trim_start_matches("0x"), radix).ok())
    };
    if let Some(t) = read_num("type", 10)
        && t != ARPHRD_CAN
    {
        return Err(unavailable(
            "is not a CAN interface",
            "pick a CAN interface from `ip -details link show type can` (or vcan)".into(),
        ));
    }
    if let Some(flags) = read_num("flags", 16)
        && flags & 1 == 0
    {
        return Err(unavailable("interface is down", up_fix(iface)));
    }
    Ok(())
}

/// Maps an error of opening or configuring the socket to a [`BusError`] naming the fix.
fn open_error(iface: &str, e: &io::Error) -> BusError {
    let (reason, fix) = match e.raw_os_error() {
        Some(libc::ENODEV) => ("no such CAN interface".to_string(), missing_fix(iface)),
        Some(libc::ENETDOWN) => ("interface is down".to_string(), up_fix(iface)),
        Some(libc::EPERM) | Some(libc::EACCES) => (
            "no permission to open a raw CAN socket".to_string(),
            "run as root or give the binary CAP_NET_RAW: sudo setcap cap_net_raw+ep $(command -v cotui)".to_string(),
        ),
        Some(libc::EAFNOSUPPORT) | Some(libc::EPROTONOSUPPORT) => (
            "this kernel has no SocketCAN support loaded".to_string(),
            "sudo modprobe can && sudo modprobe can_raw (and sudo modprobe vcan for virtual buses)".to_string(),
        ),
        _ => (e.to_string(), up_fix(iface)),
    };
    BusError::Unavailable {
        iface: iface.to_string(),
        reason,
        fix,
    }
}

/// The text of an errno for read/write errors on an open interface.
pub fn errno_text(errno: i32) -> String {
    match errno {
        libc::ENETDOWN => "interface went down".to_string(),
        libc::ENOBUFS => "transmit queue full (no ACK? check wiring, termination and bitrate)".to_string(),
        libc::ENXIO | libc::ENODEV => "interface disappeared".to_string(),
        _ => io::Error::from_raw_os_error(errno).to_string(),
    }
}

/// Opens a SocketCAN interface. Must be called inside a tokio runtime (a reader task is spawned).
pub fn open(iface: &str, listen_only: bool) -> Result<Bus, BusError> {
    check_interface(iface)?;
    let (sock, index) = open_socket(iface)?;
    let link = Arc::new(Link {
        iface: iface.to_string(),
        sock: RwLock::new(Some(Arc::new(sock))),
        drops_before: AtomicU64::new(0),
    });
    let events = broadcast::channel(QUEUE_DEPTH).0;
    let (catch_up, requests) = mpsc::unbounded_channel();
    let reader = Reader {
        link: link.clone(),
        events: events.clone(),
        requests,
        waiting: Vec::new(),
        bound: Some(index),
        link_state: BusState::Active,
        controller: BusState::Active,
        counters: None,
        reported: BusState::Active,
    };
    let task = tokio::spawn(reader.run());
    let sender = (!listen_only).then(|| Sender::Socket(Arc::new(Writer { link: link.clone() })));
    Ok(Bus {
        name: iface.to_string(),
        endpoint: OWN,
        events,
        sender,
        socket: Some(Arc::new(Shared { task, link, catch_up })),
        clock: super::Clock::Wall,
        turns: Default::default(),
    })
}

type Socket = Arc<AsyncFd<CanFdSocket>>;

/// Opens and configures a socket bound to `iface` by its current index.
fn open_socket(iface: &str) -> Result<(AsyncFd<CanFdSocket>, u32), BusError> {
    let index = sys_link(iface).map(|s| s.index).ok_or_else(|| BusError::Unavailable {
        iface: iface.to_string(),
        reason: "no such CAN interface".into(),
        fix: missing_fix(iface),
    })?;
    let sock = CanFdSocket::open_iface(index).map_err(|e| open_error(iface, &e))?;
    let configure = || -> io::Result<()> {
        sock.set_nonblocking(true)?;
        sock.set_error_filter(ERR_MASK_ALL)?;
        sock.set_recv_own_msgs(true)?;
        sock.set_recv_timestamp(true)?;
        let fd = sock.as_raw_fd();
        if setsockopt_int(fd, libc::SO_RCVBUFFORCE, RCVBUF_BYTES).is_err() {
            setsockopt_int(fd, libc::SO_RCVBUF, RCVBUF_BYTES)?;
        }
        Ok(())
    };
    configure().map_err(|e| open_error(iface, &e))?;
    // SAFETY: the socket owns its descriptor and the AsyncFd owns the socket until it is dropped.
    let fd = unsafe { AsyncFd::register(sock) }.map_err(|e| open_error(iface, &e.into_parts().1))?;
    Ok((fd, index))
}

/// `/sys/class/net/IFACE/{ifindex,flags}`; none when there is no such interface.
fn sys_link(iface: &str) -> Option<SysLink> {
    let dir = std::path::Path::new("/sys/class/net").join(iface);
    let read = |file: &str| std::fs::read_to_string(dir.join(file)).ok();
    let index = read("ifindex")?.trim().parse().ok()?;
    let flags = read("flags")
        .and_then(|f| u32::from_str_radix(f.trim().trim_start_matches("0x"), 16).ok())
        .unwrap_or(0);
    Some(SysLink {
        index,
        up: flags & libc::IFF_UP as u32 != 0,
    })
}

/// What the reader task and the send path share: the socket in use (none while the
/// interface is missing) and the drops of the sockets it replaced.
pub(super) struct Link {
    iface: String,
    sock: RwLock<Option<Socket>>,
    drops_before: AtomicU64,
}

impl Link {
    fn current(&self) -> Option<Socket> {
        self.sock.read().ok().and_then(|s| s.clone())
    }
    /// Puts `new` in place of the socket, keeping the old one's drop count.
    fn replace(&self, new: Option<Socket>) {
        if let Ok(mut s) = self.sock.write() {
            if let Some(old) = s.as_ref() {
                self.drops_before.fetch_add(drops_of(old), Ordering::Relaxed);
            }
            *s = new;
        }
    }
}

/// The reader task, its socket, and its catch-up line (SocketCAN handles).
pub(super) struct Shared {
    task: tokio::task::JoinHandle<()>,
    link: Arc<Link>,
    catch_up: mpsc::UnboundedSender<oneshot::Sender<()>>,
}

impl Shared {
    /// Frames the kernel dropped on full receive buffers, over every socket of the handle.
    pub(super) fn dropped(&self) -> u64 {
        self.link.drops_before.load(Ordering::Relaxed) + self.link.current().map_or(0, |s| drops_of(&s))
    }
    /// Asks the reader to answer on `done` once the socket's queue is read; false if it is gone.
    pub(super) fn catch_up(&self, done: oneshot::Sender<()>) -> bool {
        self.catch_up.send(done).is_ok()
    }
}

impl Drop for Shared {
    fn drop(&mut self) {
        self.task.abort();
    }
}

/// `SK_MEMINFO_DROPS` of `SO_MEMINFO`: frames the kernel dropped on the socket's full buffer (0 if it does not tell).
fn drops_of(sock: &Socket) -> u64 {
    let mut info = [0u32; libc::SK_MEMINFO_DROPS as usize + 1];
    let mut len = std::mem::size_of_val(&info) as libc::socklen_t;
    // SAFETY: `info` is a writable buffer of `len` bytes for the duration of the call.
    let r = unsafe {
        libc::getsockopt(
            sock.as_raw_fd(),
            libc::SOL_SOCKET,
            libc::SO_MEMINFO,
            info.as_mut_ptr().cast(),
            &mut len,
        )
    };
    let at = libc::SK_MEMINFO_DROPS as usize;
    if r == 0 && (len as usize) >= (at + 1) * 4 {
        info[at] as u64
    } else {
        0
    }
}

/// Sets an integer `SOL_SOCKET` option.
/// Sets the `SOL_SOCKET` option `opt` of `fd` to `value`.
pub(crate) fn setsockopt_int(fd: i32, opt: i32, value: i32) -> io::Result<()> {
    // SAFETY: `value` is a valid c_int for the duration of the call.
    let r = unsafe {
        libc::setsockopt(
            fd,
            libc::SOL_SOCKET,
            opt,
            (&value as *const i32).cast(),
            std::mem::size_of::<i32>() as libc::socklen_t,
        )
    };
    if r < 0 { Err(io::Error::last_os_error()) } else { Ok(()) }
}

/// The endpoint number of frames this socket sent.
const OWN: u32 = 1;
/// How often the reader compares its socket with `/sys/class/net/IFACE` while not capturing.
const CHECK_TROUBLED: Duration = Duration::from_millis(100);
/// How often it does while capturing (an interface deleted and re-created under a quiet
/// socket reports no error on it).
const CHECK_HEALTHY: Duration = Duration::from_secs(1);

/// The reader task: reads the socket into the broadcast channel, follows the interface
/// (down, deleted, re-created: reopened by name) and the controller state from error frames.
struct Reader {
    link: Arc<Link>,
    events: broadcast::Sender<Carried>,
    requests: mpsc::UnboundedReceiver<oneshot::Sender<()>>,
    /// Catch-up requests: when asked (ns) and where to answer.
    waiting: Vec<(u64, oneshot::Sender<()>)>,
    /// The interface index the socket is bound to (none: no socket).
    bound: Option<u32>,
    /// `Active` (up), `Down` or `Missing`.
    link_state: BusState,
    /// From error frames: `Active`, `Warning`, `Passive` or `BusOff`.
    controller: BusState,
    counters: Option<(u8, u8)>,
    reported: BusState,
}

impl Reader {
    async fn run(mut self) {
        let mut tick = tokio::time::interval(CHECK_TROUBLED);
        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        let mut checked = tokio::time::Instant::now();
        loop {
            let sock = self.link.current();
            if let Some(s) = &sock {
                self.read_queued(s).await;
            }
            // The queue is empty: everyone who asked has every frame queued before they asked.
            for (_, w) in self.waiting.drain(..) {
                let _ = w.send(());
            }
            tokio::select! {
                r = readable(sock.as_ref()) => {
                    if let Err(e) = r {
                        self.on_error(e).await;
                    }
                }
                req = self.requests.recv() => match req {
                    Some(w) => self.waiting.push((now_ns(), w)),
                    None => return,
                },
                _ = tick.tick() => {
                    if self.link_state != BusState::Active || checked.elapsed() >= CHECK_HEALTHY {
                        checked = tokio::time::Instant::now();
                        self.reconcile();
                    }
                }
            }
        }
    }

    /// Reads until the socket's queue is empty (or fails), letting the subscribers run between runs.
    async fn read_queued(&mut self, sock: &Socket) {
        let mut pace = Pace::default();
        loop {
            match recv(sock.as_raw_fd()) {
                Ok((frame, own)) => {
                    self.on_frame(frame, own);
                    pace.published(&self.events).await;
                }
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return self.on_error(e).await,
            }
        }
    }

    fn on_frame(&mut self, frame: Frame, own: bool) {
        if self.link_state != BusState::Active {
            // A frame came in: the interface is up again.
            self.link_state = BusState::Active;
            self.controller = BusState::Active;
            self.report(frame.ts_ns);
        }
        let _ = self.events.send(Carried {
            origin: if own { OWN } else { 0 },
            item: Item::Frame(frame),
        });
        if frame.is_err() {
            let (state, counters) = controller_state(frame.id, frame.payload());
            if counters.is_some() {
                self.counters = counters;
            }
            if let Some(c) = state {
                self.controller = BusState::from_controller(c);
                self.report(frame.ts_ns);
            }
        }
        // A frame stamped after a request proves that everything queued before it was read
        // (this ends a catch-up even on a bus that never falls quiet).
        if self.waiting.iter().any(|(asked, _)| *asked < frame.ts_ns) {
            let (done, wait): (Vec<_>, Vec<_>) = self.waiting.drain(..).partition(|(asked, _)| *asked < frame.ts_ns);
            self.waiting = wait;
            for (_, w) in done {
                let _ = w.send(());
            }
        }
    }

    async fn on_error(&mut self, e: io::Error) {
        match e.raw_os_error() {
            Some(libc::ENETDOWN) => {
                self.link_state = BusState::Down;
                self.report(now_ns());
                self.reconcile();
            }
            Some(libc::ENODEV) | Some(libc::ENXIO) => {
                self.link_state = BusState::Missing;
                self.report(now_ns());
                self.reconcile();
            }
            errno => {
                let _ = self.events.send(Carried {
                    origin: 0,
                    item: Item::Fault(errno.unwrap_or(libc::EIO)),
                });
                // Not a change of state: do not spin on an error that repeats.
                tokio::time::sleep(CHECK_TROUBLED).await;
            }
        }
    }

    /// Brings the socket in line with what `/sys/class/net/IFACE` says.
    fn reconcile(&mut self) {
        let sys = sys_link(&self.link.iface);
        let up = match decide(self.bound, sys) {
            Action::Keep { up } => up,
            Action::Close => {
                self.link.replace(None);
                self.bound = None;
                self.link_state = BusState::Missing;
                return self.report(now_ns());
            }
            Action::Reopen { up } => match open_socket(&self.link.iface) {
                Ok((sock, index)) => {
                    self.link.replace(Some(Arc::new(sock)));
                    self.bound = Some(index);
                    up
                }
                // Not there yet (or gone again): tried again on the next tick.
                Err(_) => {
                    self.link.replace(None);
                    self.bound = None;
                    self.link_state = BusState::Missing;
                    return self.report(now_ns());
                }
            },
        };
        let state = if up { BusState::Active } else { BusState::Down };
        if state != self.link_state {
            self.link_state = state;
            // A controller that was down starts over error-active.
            self.controller = BusState::Active;
            self.counters = None;
        }
        self.report(now_ns());
    }

    /// Sends the state in force if it differs from the last one sent.
    fn report(&mut self, ts_ns: u64) {
        let state = if self.link_state == BusState::Active {
            self.controller
        } else {
            self.link_state
        };
        if state != self.reported {
            self.reported = state;
            let _ = self.events.send(Carried {
                origin: 0,
                item: Item::State(StateChange {
                    ts_ns,
                    state,
                    counters: self.counters.filter(|_| self.link_state == BusState::Active),
                }),
            });
        }
    }
}

/// Waits until `sock` is readable (forever without a socket) and clears its readiness:
/// the caller reads until the queue is empty, and data arriving meanwhile sets it again.
async fn readable(sock: Option<&Socket>) -> io::Result<()> {
    match sock {
        Some(s) => {
            s.readable().await?.clear_ready();
            Ok(())
        }
        None => std::future::pending().await,
    }
}

/// Wall-clock time in ns since the Unix epoch (the clock of kernel frame timestamps).
fn now_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// The send path of a SocketCAN handle (absent on listen-only handles).
pub(super) struct Writer {
    link: Arc<Link>,
}

impl Writer {
    /// Writes one frame, retrying briefly while the transmit queue is full.
    pub(super) async fn write(&self, frame: &Frame) -> Result<(), BusError> {
        let iface = &self.link.iface;
        let raw = to_raw(frame).map_err(|e| BusError::Io {
            iface: iface.clone(),
            reason: e.to_string(),
        })?;
        let unavailable = |errno| {
            let state = if errno == libc::ENETDOWN {
                BusState::Down
            } else {
                BusState::Missing
            };
            StateChange {
                ts_ns: 0,
                state,
                counters: None,
            }
            .error(iface)
            .unwrap_or(BusError::Closed)
        };
        let Some(sock) = self.link.current() else {
            return Err(unavailable(libc::ENODEV));
        };
        let mut tries = 0;
        loop {
            let r = sock
                .async_io(Interest::WRITABLE, |s| {
                    // SAFETY: `raw` is a valid buffer of `raw.len()` bytes for the whole call.
                    let n = unsafe { libc::write(s.as_raw_fd(), raw.as_ptr().cast(), raw.len()) };
                    if n < 0 {
                        Err(io::Error::last_os_error())
                    } else {
                        Ok(n as usize)
                    }
                })
                .await;
            match r {
                Ok(n) if n == raw.len() => return Ok(()),
                Ok(n) => {
                    return Err(BusError::Io {
                        iface: iface.clone(),
                        reason: format!("short write: {n} of {} bytes", raw.len()),
                    });
                }
                Err(e) if e.raw_os_error() == Some(libc::ENOBUFS) && tries < 20 => {
                    tries += 1;
                    tokio::time::sleep(std::time::Duration::from_millis(5)).await;
                }
                Err(e) => {
                    return Err(match e.raw_os_error() {
                        Some(errno @ (libc::ENETDOWN | libc::ENODEV | libc::ENXIO)) => unavailable(errno),
                        errno => BusError::Io {
                            iface: iface.clone(),
                            reason: errno_text(errno.unwrap_or(libc::EIO)),
                        },
                    });
                }
            }
        }
    }
}

/// One `recvmsg`: the frame with its kernel timestamp, and whether this socket sent it.
fn recv(fd: i32) -> io::Result<(Frame, bool)> {
    let mut buf = [0u8; CANFD_MTU];
    let mut ctrl = [0u64; 16];
    let mut iov = libc::iovec {
        iov_base: buf.as_mut_ptr().cast(),
        iov_len: buf.len(),
    };
    // SAFETY: msghdr is plain data; every pointer set below outlives the recvmsg call.
    let mut msg: libc::msghdr = unsafe { std::mem::zeroed() };
    msg.msg_iov = &mut iov;
    msg.msg_iovlen = 1;
    msg.msg_control = ctrl.as_mut_ptr().cast();
    msg.msg_controllen = std::mem::size_of_val(&ctrl) as _;
    // SAFETY: `msg` points at live buffers of the stated sizes.
    let n = unsafe { libc::recvmsg(fd, &mut msg, 0) };
    if n < 0 {
        return Err(io::Error::last_os_error());
    }
    let mut ts_ns = 0u64;
    // SAFETY: the CMSG macros walk the control buffer the kernel filled within msg_controllen.
    unsafe {
        let mut c = libc::CMSG_FIRSTHDR(&msg);
        while !c.is_null() {
            if (*c).cmsg_level == libc::SOL_SOCKET && (*c).cmsg_type == libc::SCM_TIMESTAMPNS {
                let t: libc::timespec = std::ptr::read_unaligned(libc::CMSG_DATA(c).cast());
                ts_ns = t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64;
            }
            c = libc::CMSG_NXTHDR(&msg, c);
        }
    }
    let own = msg.msg_flags & libc::MSG_CONFIRM != 0;
    let mut frame = from_raw(&buf[..n as usize]).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
    frame.ts_ns = ts_ns;
    Ok((frame, own))
}

/// Why bytes are not a kernel CAN frame, or a frame cannot become one.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RawFrameError {
    #[error("read {0} bytes, expected {CAN_MTU} (CAN) or {CANFD_MTU} (CAN FD)")]
    Size(usize),
    #[error("error frames cannot be sent")]
    ErrorFrame,
    #[error("id 0x{0:X} does not fit 11 bits; mark the frame extended")]
    IdTooLarge(u32),
    #[error("{0} bytes is not a CAN FD length")]
    FdLength(usize),
    #[error("{0} bytes do not fit a classic CAN frame")]
    ClassicLength(usize),
}

/// Parses a kernel `can_frame` (16 bytes) or `canfd_frame` (72 bytes).
pub fn from_raw(raw: &[u8]) -> Result<Frame, RawFrameError> {
    if raw.len() != CAN_MTU && raw.len() != CANFD_MTU {
        return Err(RawFrameError::Size(raw.len()));
    }
    let can_id = u32::from_ne_bytes([raw[0], raw[1], raw[2], raw[3]]);
    let mut f = Frame::default();
    let fd = raw.len() == CANFD_MTU;
    let max = if fd { 64 } else { 8 };
    let len = (raw[4] as usize).min(max);
    f.len = len as u8;
    if can_id & CAN_ERR_FLAG != 0 {
        f.flags.set(Flags::ERR, true);
        f.id = can_id & CAN_ERR_MASK;
    } else if can_id & CAN_EFF_FLAG != 0 {
        f.flags.set(Flags::EXT, true);
        f.id = can_id & CAN_EFF_MASK;
    } else {
        f.id = can_id & 0x7FF;
    }
    if fd {
        f.flags.set(Flags::FD, true);
        f.flags.set(Flags::BRS, raw[5] & CANFD_BRS != 0);
        f.flags.set(Flags::ESI, raw[5] & CANFD_ESI != 0);
        f.flags.set(Flags::FDF, raw[5] & CANFD_FDF != 0);
    } else {
        f.flags
            .set(Flags::RTR, can_id & CAN_RTR_FLAG != 0 && can_id & CAN_ERR_FLAG == 0);
        if len == 8 && (9..=15).contains(&raw[7]) {
            f.raw_dlc = raw[7];
        }
    }
    if !f.is_rtr() {
        f.data[..len].copy_from_slice(&raw[8..8 + len]);
    }
    Ok(f)
}

/// The kernel `can_frame` / `canfd_frame` bytes of a frame to send.
pub fn to_raw(f: &Frame) -> Result<Vec<u8>, RawFrameError> {
    if f.is_err() {
        return Err(RawFrameError::ErrorFrame);
    }
    let mut can_id = if f.is_ext() {
        (f.id & CAN_EFF_MASK) | CAN_EFF_FLAG
    } else if f.id <= 0x7FF {
        f.id
    } else {
        return Err(RawFrameError::IdTooLarge(f.id));
    };
    let len = f.len as usize;
    if f.is_fd() {
        if len > 64 || !matches!(len, 0..=8 | 12 | 16 | 20 | 24 | 32 | 48 | 64) {
            return Err(RawFrameError::FdLength(len));
        }
        let mut raw = vec![0u8; CANFD_MTU];
        raw[..4].copy_from_slice(&can_id.to_ne_bytes());
        raw[4] = len as u8;
        let mut flags = 0;
        if f.flags.has(Flags::BRS) {
            flags |= CANFD_BRS;
        }
        if f.flags.has(Flags::ESI) {
            flags |= CANFD_ESI;
        }
        raw[5] = flags;
        raw[8..8 + len].copy_from_slice(&f.data[..len]);
        Ok(raw)
    } else {
        if len > 8 {
            return Err(RawFrameError::ClassicLength(len));
        }
        if f.is_rtr() {
            can_id |= CAN_RTR_FLAG;
        }
        let mut raw = vec![0u8; CAN_MTU];
        raw[..4].copy_from_slice(&can_id.to_ne_bytes());
        raw[4] = len as u8;
        if len == 8 && (9..=15).contains(&f.raw_dlc) {
            raw[7] = f.raw_dlc;
        }
        if !f.is_rtr() {
            raw[8..8 + len].copy_from_slice(&f.data[..len]);
        }
        Ok(raw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classic_frames_round_trip_through_kernel_layout() {
        let f = Frame::classic(0x602, &[0x40, 0x41, 0x60, 0]);
        let raw = to_raw(&f).unwrap();
        assert_eq!(raw.len(), CAN_MTU);
        assert_eq!(&raw[..5], &[0x02, 0x06, 0, 0, 4]);
        assert_eq!(from_raw(&raw).unwrap(), f);
        let mut ext = Frame::classic(0x1234_5678, &[1, 2, 3, 4, 5, 6, 7, 8]);
        ext.raw_dlc = 0xC;
        let back = from_raw(&to_raw(&ext).unwrap()).unwrap();
        assert_eq!((back.id, back.is_ext(), back.raw_dlc), (0x1234_5678, true, 0xC));
        let mut rtr = Frame::classic(0x702, &[]);
        rtr.flags.set(Flags::RTR, true);
        rtr.len = 1;
        let back = from_raw(&to_raw(&rtr).unwrap()).unwrap();
        assert!(back.is_rtr());
        assert_eq!(back.len, 1);
    }

    #[test]
    fn fd_and_error_frames() {
        let mut raw = vec![0u8; CANFD_MTU];
        raw[..4].copy_from_slice(&0x123u32.to_ne_bytes());
        raw[4] = 12;
        raw[5] = CANFD_BRS | CANFD_FDF;
        raw[8..20].copy_from_slice(&[7; 12]);
        let f = from_raw(&raw).unwrap();
        assert!(f.is_fd() && f.flags.has(Flags::BRS) && !f.flags.has(Flags::ESI));
        assert_eq!(f.payload(), &[7; 12]);
        let mut err = vec![0u8; CAN_MTU];
        err[..4].copy_from_slice(&(CAN_ERR_FLAG | 0x04).to_ne_bytes());
        err[4] = 8;
        err[9] = 0x0C;
        let e = from_raw(&err).unwrap();
        assert!(e.is_err());
        assert_eq!((e.id, e.payload()[1]), (4, 0x0C));
        assert_eq!(
            to_raw(&e).map_err(|e| e.to_string()),
            Err("error frames cannot be sent".into())
        );
        assert!(from_raw(&[0; 10]).unwrap_err().to_string().contains("read 10 bytes"));
    }

    #[test]
    fn missing_interface_names_the_fix() {
        let e = check_interface("cotuinosuch0").unwrap_err();
        let text = e.to_string();
        assert!(text.contains("no such CAN interface"), "{text}");
        assert!(text.contains("sudo modprobe vcan"), "{text}");
        assert!(up_fix("can0").contains("sudo ip link set can0 up type can bitrate 500000"));
    }
}
