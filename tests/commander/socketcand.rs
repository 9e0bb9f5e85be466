//! `cotui serve demo --socketcand 0` (loopback, a free port) against real clients:
//! python-can's `socketcand` interface, cotui's own `socketcand://` client (sdo, lss, nmt,
//! record, CAN FD frames both ways), and a raw TCP client sending garbage, a 1 MB element and
//! 200 connections.
//! Every wait is on a condition (a line on stderr, an answer), never a fixed sleep.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Output, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A running `cotui serve`, killed when dropped; its stderr lines as they come.
pub struct Server {
    child: Child,
    pub port: u16,
    lines: Arc<Mutex<Vec<String>>>,
}

impl Server {
    /// `cotui serve demo --socketcand 0 EXTRA...`, once it listens.
    pub fn demo(extra: &[&str]) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["serve", "demo", "--socketcand", "0"])
            .args(extra)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let lines = Arc::new(Mutex::new(Vec::new()));
        let err = child.stderr.take().unwrap();
        let sink = lines.clone();
        std::thread::spawn(move || {
            for l in BufReader::new(err).lines().map_while(Result::ok) {
                sink.lock().unwrap().push(l);
            }
        });
        let mut s = Server { child, port: 0, lines };
        let first = s.wait_line("the listening line", |l| l.contains("socketcand on 127.0.0.1:"));
        let addr = first.split("socketcand on 127.0.0.1:").nth(1).unwrap();
        s.port = addr.split(',').next().unwrap().parse().unwrap();
        s
    }
    /// `socketcand://127.0.0.1:PORT/demo`
    pub fn url(&self) -> String {
        format!("socketcand://127.0.0.1:{}/demo", self.port)
    }
    /// The stderr lines so far.
    pub fn lines(&self) -> Vec<String> {
        self.lines.lock().unwrap().clone()
    }
    /// Waits (60 s at most) for a stderr line that satisfies `f`.
    pub fn wait_line(&self, what: &str, f: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            if let Some(l) = self.lines().into_iter().find(|l| f(l)) {
                return l;
            }
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "no {what} on the server's stderr:\n{}",
                self.lines().join("\n")
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn cotui(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cotui")).args(args).output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "status {:?}\nstdout: {}\nstderr: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Runs a python-can script with the server's port as argv[1]; its stdout.
fn python(port: u16, script: &str) -> String {
    let o = Command::new("python3")
        .arg("-c")
        .arg(script)
        .arg(port.to_string())
        .output()
        .unwrap();
    assert!(o.status.success(), "python failed:\n{}", text(&o));
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// The python-can client: bus heartbeats, an SDO read of node 2's 0x1017, the answer.
const PY_SDO: &str = r#"
import can, sys, time
bus = can.Bus(interface="socketcand", host="127.0.0.1", port=int(sys.argv[1]), channel="demo")
def wait(pred, secs=30):
    end = time.time() + secs
    while time.time() < end:
        m = bus.recv(0.5)
        if m is not None and pred(m):
            return m
    return None
hb = wait(lambda m: m.arbitration_id == 0x702)
print("heartbeat", hb.data.hex() if hb else None, "ts", hb.timestamp if hb else None)
bus.send(can.Message(arbitration_id=0x602, data=[0x40, 0x17, 0x10, 0, 0, 0, 0, 0], is_extended_id=False))
try:
    ans = wait(lambda m: m.arbitration_id == 0x582, 10)
    print("answer", ans.data.hex() if ans else None)
except can.CanError as e:
    print("error", "send" in str(e))
bus.shutdown()
"#;

#[test]
fn python_can_receives_the_bus_and_reads_an_sdo_with_allow_send() {
    let s = Server::demo(&["--allow-send"]);
    let out = python(s.port, PY_SDO);
    assert!(out.contains("heartbeat 05 ts 1"), "{out}");
    // Expedited upload response of 0x1017:00 = 500 ms.
    assert!(out.contains("answer 4b171000f4010000"), "{out}");
    s.wait_line("the audit of the frame sent", |l| {
        l.ends_with("sent 602#4017100000000000")
    });
    s.wait_line("the disconnect", |l| {
        l.contains("disconnected (closed by the client): 1 frames sent, 0 sends refused")
    });
}

#[test]
fn without_allow_send_nothing_is_sent_and_the_client_is_told() {
    let s = Server::demo(&[]);
    let out = python(s.port, PY_SDO);
    // python-can fails its next read on the server's error; no answer ever came.
    assert!(out.contains("error True") || out.contains("answer None"), "{out}");
    assert!(!out.contains("answer 4b"), "{out}");
    s.wait_line("the refusal", |l| {
        l.ends_with("send refused (no --allow-send): 602#4017100000000000")
    });
    assert!(!s.lines().iter().any(|l| l.contains(" sent 602#")), "{:?}", s.lines());
    // The raw protocol: the refusal is an error element naming the fix.
    let mut c = Raw::open(s.port);
    c.say("< rawmode >");
    c.until("< ok >");
    c.say("< send 602 8 40 17 10 0 0 0 0 0 >");
    c.until("< error send refused: the server was started without --allow-send >");
    // cotui's own client fails at once with the reason, exit status 2 (unavailable).
    let t = Instant::now();
    let o = cotui(&["sdo", "read", &s.url(), "2", "0x1017"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("the server does not let clients send (the server was started without --allow-send)"),
        "{}",
        text(&o)
    );
    assert!(
        text(&o).contains("fix: start the server with --allow-send"),
        "{}",
        text(&o)
    );
    assert!(t.elapsed() < Duration::from_secs(30));
}

#[test]
fn cotuis_client_reads_records_and_keeps_the_demo_between_commands() {
    let s = Server::demo(&["--allow-send"]);
    let url = s.url();
    let o = cotui(&["sdo", "read", &url, "2", "0x1017"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("node 2 0x1017:00 Producer heartbeat time = 500 ms"),
        "{}",
        text(&o)
    );
    // The demo lives as long as the server: a slave switched to configuration state by one
    // command answers the inquiry of the next.
    let o = cotui(&["lss", &url, "switch", "config"]);
    assert!(o.status.success(), "{}", text(&o));
    let o = cotui(&["lss", &url, "inquire"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("node-ID 2"), "{}", text(&o));
    // A listen-only client cannot send: exit 2, and the server saw no frame from it.
    let sent_before = s.lines().iter().filter(|l| l.contains(" sent ")).count();
    let o = cotui(&["nmt", &url, "--listen-only", "stop", "3"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("listen-only"), "{}", text(&o));
    let sent_after = s.lines().iter().filter(|l| l.contains(" sent ")).count();
    assert_eq!(sent_before, sent_after, "{:?}", s.lines());
    // A recording of the remote bus: whole candump lines stamped with the server's times.
    let dir = std::env::temp_dir().join(format!("cotui-socketcand-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("remote.log");
    let _ = std::fs::remove_file(&file);
    let o = cotui(&["record", &url, "-o", file.to_str().unwrap(), "--count", "20"]);
    assert!(o.status.success(), "{}", text(&o));
    let log = std::fs::read_to_string(&file).unwrap();
    assert_eq!(log.lines().count(), 20, "{log}");
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_secs_f64();
    for l in log.lines() {
        let ts: f64 = l[1..l.find(')').unwrap()].parse().unwrap();
        assert!((now - ts).abs() < 600.0, "{l}");
        assert!(l.contains(&format!(" {url} ")), "{l}");
    }
    // Heartbeats of the demo's nodes (pre-operational or operational: the demo starts
    // them on its own schedule, so the state depends on when the 20 frames were taken).
    assert!(
        log.lines()
            .any(|l| l.contains(" 70") && (l.ends_with("#7F") || l.ends_with("#05"))),
        "heartbeats: {log}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A raw TCP client of the server.
struct Raw {
    sock: TcpStream,
    got: String,
}

impl Raw {
    fn open(port: u16) -> Raw {
        let sock = TcpStream::connect(("127.0.0.1", port)).unwrap();
        sock.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
        let mut r = Raw {
            sock,
            got: String::new(),
        };
        r.until("< hi >");
        r.say("< open demo >");
        r.until("< ok >");
        r
    }
    fn say(&mut self, text: &str) {
        self.sock.write_all(text.as_bytes()).unwrap();
    }
    /// Reads until `want` arrived (60 s at most); consumes up to its end and returns it.
    fn until(&mut self, want: &str) -> String {
        let start = Instant::now();
        let mut buf = [0u8; 4096];
        loop {
            if let Some(i) = self.got.find(want) {
                return self.got.drain(..i + want.len()).collect();
            }
            assert!(start.elapsed() < Duration::from_secs(60), "no {want} in {}", self.got);
            match self.sock.read(&mut buf) {
                Ok(0) => panic!("closed before {want}: {}", self.got),
                Ok(n) => self.got.push_str(&String::from_utf8_lossy(&buf[..n])),
                Err(_) => {}
            }
        }
    }
}

#[test]
fn garbage_a_huge_element_and_many_connections_leave_the_server_serving() {
    let s = Server::demo(&["--max-clients", "300"]);
    let mut c = Raw::open(s.port);
    c.say("hello there < frobnicate 1 2 >");
    c.until("< error text outside ? ?, ignored >");
    c.until("< error unknown command frobnicate >");
    c.say("< send 601 9 >< send 999 0 >< send 601 1 zz >< subscribe x >< \u{1}\u{2} >");
    c.until("< error send: length 9 is not 0..8 (a CAN FD frame goes as fdsend ID FLAGS LEN DATA) >");
    c.until("< error identifier 999 does not fit 11 bits");
    c.until("< error send: zz is not a byte in hex >");
    c.until("< error subscribe takes SECS USECS ID >");
    c.until("< error unknown command ??");
    c.say("<\u{ff}\u{fe}>");
    c.until("< error command is not ASCII text, skipped >");
    // A 1 MB element: one error, memory bounded, the next element works.
    let mut big = String::from("< ");
    big.push_str(&"x".repeat(1 << 20));
    big.push_str(" >< echo >");
    c.say(&big);
    c.until("< error command longer than 4096 bytes, skipped >");
    c.until("< echo >");
    // The session goes on: raw mode gives frames.
    c.say("< rawmode >");
    c.until("< ok >");
    c.until("< frame 702 ");
    // 200 connections: 100 at once, then 100 one after the other; each greeted.
    let mut held = Vec::new();
    for _ in 0..100 {
        let mut r = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
        r.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
        let mut hi = [0u8; 6];
        r.read_exact(&mut hi).unwrap();
        assert_eq!(&hi, b"< hi >");
        held.push(r);
    }
    drop(held);
    for _ in 0..100 {
        let r = Raw::open(s.port);
        drop(r);
    }
    // One over --max-clients is refused with an error, the others are still served.
    let mut c2 = Raw::open(s.port);
    c2.say("< echo >");
    c2.until("< echo >");
    c.say("< echo >");
    c.until("< echo >");
    s.wait_line("the 201st connect", |l| l.contains("client 202 ("));
    assert!(
        s.lines().iter().all(|l| !l.contains("accept failed")),
        "{:?}",
        s.lines()
    );
}

#[test]
fn a_client_beyond_max_clients_is_refused_with_an_error() {
    let s = Server::demo(&["--max-clients", "1"]);
    let _first = Raw::open(s.port);
    let mut second = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
    let mut got = String::new();
    second.read_to_string(&mut got).unwrap();
    assert_eq!(got, "< error too many clients (1 connected) >");
    s.wait_line("the refusal", |l| {
        l.contains("refused: 1 clients connected already (--max-clients)")
    });
}

#[test]
fn the_server_refuses_other_addresses_without_bind_and_send_under_listen_only() {
    let o = cotui(&["serve", "demo", "--socketcand", "0.0.0.0:0"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("not a loopback address"), "{}", text(&o));
    assert!(text(&o).contains("--bind 0.0.0.0"), "{}", text(&o));
    let o = cotui(&["serve", "demo", "--socketcand", "0", "--allow-send", "--listen-only"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("a listen-only bus cannot send"), "{}", text(&o));
    let o = cotui(&["serve", "demo", "--socketcand", "0", "--beacon"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("--beacon announces the bus to the network"),
        "{}",
        text(&o)
    );
    let o = cotui(&["sdo", "read", "socketcand://127.0.0.1:1/demo", "2", "0x1017"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("cannot connect to 127.0.0.1:1"), "{}", text(&o));
}

/// A client that opens raw mode and never reads (a small receive buffer), while another
/// client sends 30,000 frames: the frames to the first are dropped and counted, the
/// sender's frames all go out, and the server still answers.
#[test]
fn a_client_that_never_reads_loses_frames_counted_and_the_server_goes_on() {
    let s = Server::demo(&["--allow-send"]);
    let stuck = r#"
import socket, sys, time
s = socket.socket()
s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
s.connect(("127.0.0.1", int(sys.argv[1])))
s.sendall(b"< open demo >< rawmode >")
print("connected", flush=True)
sys.stdin.read()
"#;
    let mut py = Command::new("python3")
        .arg("-c")
        .arg(stuck)
        .arg(s.port.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(py.stdout.take().unwrap()).read_line(&mut line).unwrap();
    assert_eq!(line.trim(), "connected");
    s.wait_line("the stuck client", |l| {
        l.contains("client 1 (") && l.ends_with("connected")
    });
    let mut blaster = Raw::open(s.port);
    let burst: String = (0..30_000)
        .map(|i| format!("< send 123 2 {:x} {:x} >", i % 256, i / 256))
        .collect();
    blaster.say(&burst);
    blaster.say("< echo >");
    blaster.until("< echo >");
    s.wait_line("the first drop", |l| {
        l.contains("client 1 (") && l.contains("does not read fast enough: dropping frames")
    });
    s.wait_line("the last frame sent", |l| l.ends_with("sent 123#2F75"));
    // The stuck client leaves: its line counts what it lost.
    drop(py.stdin.take());
    let _ = py.wait();
    let gone = s.wait_line("the stuck client's disconnect", |l| {
        l.contains("client 1 (") && l.contains("disconnected")
    });
    let dropped: u64 = gone
        .split(" frames received, ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(dropped > 1000, "{gone}");
    let mut late = Raw::open(s.port);
    late.say("< echo >");
    late.until("< echo >");
}

/// A TCP proxy that delays every chunk by argv[2] seconds each way (argv[1]: the server's
/// port); prints the port it listens on.
const DELAY_PROXY: &str = r#"
import asyncio, sys
target, delay = int(sys.argv[1]), float(sys.argv[2])
async def pipe(r, w):
    q = asyncio.Queue()
    async def later():
        while True:
            t, data = await q.get()
            if data is None:
                break
            await asyncio.sleep(max(0, t - asyncio.get_running_loop().time()))
            w.write(data)
            await w.drain()
        w.close()
    task = asyncio.create_task(later())
    while True:
        data = await r.read(65536)
        await q.put((asyncio.get_running_loop().time() + delay, data or None))
        if not data:
            break
    await task
async def handle(cr, cw):
    sr, sw = await asyncio.open_connection("127.0.0.1", target)
    await asyncio.gather(pipe(cr, sw), pipe(sr, cw), return_exceptions=True)
async def main():
    srv = await asyncio.start_server(handle, "127.0.0.1", 0)
    print(srv.sockets[0].getsockname()[1], flush=True)
    async with srv:
        await srv.serve_forever()
asyncio.run(main())
"#;

/// 300 ms each way (a 600 ms round trip) and `--timeout 200`: the answer, 1 ms after the
/// request on the remote bus, is taken; a node that is not there still times out.
#[test]
fn sdo_timeouts_count_on_the_remote_bus_not_across_the_network() {
    let s = Server::demo(&["--allow-send"]);
    let mut proxy = Command::new("python3")
        .arg("-c")
        .arg(DELAY_PROXY)
        .arg(s.port.to_string())
        .arg("0.3")
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(proxy.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = format!("socketcand://127.0.0.1:{}/demo", line.trim());
    let o = cotui(&["sdo", "read", &url, "2", "0x1017", "--timeout", "200"]);
    let missing = cotui(&["sdo", "read", &url, "9", "0x1017", "--timeout", "200"]);
    let _ = proxy.kill();
    let _ = proxy.wait();
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("Producer heartbeat time = 500 ms"), "{}", text(&o));
    assert_eq!(missing.status.code(), Some(4), "{}", text(&missing));
    assert!(
        text(&missing).contains("node 9 did not answer within 200 ms"),
        "{}",
        text(&missing)
    );
}

/// The stdout lines of a child, as they come.
struct Lines(Arc<Mutex<Vec<String>>>);

impl Lines {
    fn of(child: &mut Child) -> Lines {
        let out = child.stdout.take().unwrap();
        let lines = Arc::new(Mutex::new(Vec::new()));
        let sink = lines.clone();
        std::thread::spawn(move || {
            for l in BufReader::new(out).lines().map_while(Result::ok) {
                sink.lock().unwrap().push(l);
            }
        });
        Lines(lines)
    }
    /// Waits (60 s at most) for a line that satisfies `f`.
    fn wait(&self, what: &str, f: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            if let Some(l) = self.0.lock().unwrap().iter().find(|l| f(l)) {
                return l.clone();
            }
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "no {what} in:\n{}",
                self.0.lock().unwrap().join("\n")
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

/// CAN FD through the server, with four clients on the bus at once: cotui's own client
/// sends an FD frame (`< fdsend >`), a raw socketcand client gets it as `< fdframe >` and
/// sends one itself, cotui's own client records both as FD frames (flags kept), and
/// python-can's socketcand interface (classic only) skips the FD frames and goes on
/// receiving; its own FD message (written as a `< send >` with a hex length) is refused
/// with an error and nothing reaches the bus.
#[test]
fn fd_frames_cross_the_server_both_ways_and_python_can_skips_them() {
    let s = Server::demo(&["--allow-send"]);
    let url = s.url();
    let mut py = Command::new("python3")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/commander/socketcand_fd.py"))
        .arg(s.port.to_string())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let py_out = Lines::of(&mut py);
    py_out.wait("the python clients' ready", |l| l == "ready");
    let mut rec = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["record", &url, "-o", "-"])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let recorded = Lines::of(&mut rec);
    recorded.wait("a first recorded frame", |_| true);

    let o = cotui(&["send", &url, "123##1112233445566778899AABBCC"]);
    assert!(o.status.success(), "{}", text(&o));
    s.wait_line("the audit of the FD frame", |l| {
        l.ends_with(" sent 123##1112233445566778899AABBCC")
    });
    let got = py_out.wait("the raw client's fdframe", |l| l.starts_with("raw got"));
    assert!(got.starts_with("raw got < fdframe 123 01 "), "{got}");
    assert!(got.ends_with(" 112233445566778899AABBCC >"), "{got}");
    // The raw client's fdsend: 29-bit, BRS and ESI, 16 bytes.
    s.wait_line("the raw client's FD frame", |l| {
        l.ends_with(" sent 0000ABCD##3000102030405060708090A0B0C0D0E0F")
    });
    recorded.wait("the FD frame of cotui's client", |l| {
        l.ends_with(&format!(" {url} 123##1112233445566778899AABBCC"))
    });
    recorded.wait("the FD frame of the raw client", |l| {
        l.ends_with(&format!(" {url} 0000ABCD##3000102030405060708090A0B0C0D0E0F"))
    });

    let skipped = py_out.wait("python-can's classic frame after the FD ones", |l| {
        l.starts_with("python-can got 125")
    });
    assert!(skipped.starts_with("python-can got 125 aa after "), "{skipped}");
    assert!(skipped.ends_with("fd frames delivered: 0"), "{skipped}");
    py_out.wait("python-can's FD send", |l| {
        l == "python-can fd send: error from the server"
    });
    assert!(py.wait().unwrap().success());
    let _ = rec.kill();
    let _ = rec.wait();
    assert!(!s.lines().iter().any(|l| l.contains(" sent 126")), "{:?}", s.lines());
    s.wait_line("python-can's disconnect", |l| {
        l.contains("client 1 (") && l.contains("0 frames sent, 0 sends refused") && l.ends_with("1 errors answered")
    });
}

#[test]
fn bcm_send_jobs_and_a_content_filter_work_over_the_wire() {
    let s = Server::demo(&["--allow-send"]);
    let mut watcher = Raw::open(s.port);
    watcher.say("< rawmode >");
    watcher.until("< ok >");
    // A send job every 10 ms; updated without touching its timer; deleted.
    let mut c = Raw::open(s.port);
    c.say("< add 0 10000 321 2 11 22 >");
    s.wait_line("the job's audit line", |l| {
        l.contains("send job 321#1122 every 10000 us")
    });
    watcher.until(" 1122 >");
    watcher.until("< frame 321 ");
    c.say("< update 321 1 33 >");
    watcher.until(" 33 >");
    c.say("< delete 321 >< echo >");
    c.until("< echo >");
    s.wait_line("the delete's audit line", |l| l.contains("send job 321 deleted"));
    c.say("< delete 321 >");
    c.until("< error no send job for 321 >");
    // A content filter on node 2's heartbeat: only its changes reach the client, not the
    // heartbeat every 100 ms.
    c.say("< filter 0 0 702 1 FF >");
    let mut got = c.until("< frame 702 ");
    c.say("< send 000 2 80 02 >");
    got.push_str(&c.until(" 7F >"));
    c.say("< send 000 2 01 02 >");
    got.push_str(&c.until(" 05 >"));
    // Whatever came between (the demo's own start of all nodes, if it came after the
    // filter): few frames, each heartbeat forwarded differs from the one before.
    let states: Vec<&str> = got
        .split("< frame 702 ")
        .skip(1)
        .filter_map(|e| e.split_whitespace().nth(1))
        .collect();
    assert!((2..=4).contains(&states.len()), "{states:?} in {got}");
    assert!(states.windows(2).all(|w| w[0] != w[1]), "{states:?} in {got}");
}
