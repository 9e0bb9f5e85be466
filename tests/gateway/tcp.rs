//! `cotui gateway demo --tcp 127.0.0.1:0`: several clients at once, each its own session.

use crate::client::{Client, WAIT, lines_of};
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

/// The gateway on a free loopback port; gives the child and the address it printed.
fn start(args: &[&str]) -> (Child, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["gateway", "demo", "--tcp", "127.0.0.1:0"])
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    // `cotui gateway: demo on tcp 127.0.0.1:PORT (read-only: ...)`
    let addr = line
        .split("on tcp ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    assert!(addr.starts_with("127.0.0.1:"), "binds only what is named: {line}");
    // Keep reading the audit lines so the gateway never blocks on a full pipe.
    std::thread::spawn(move || for _ in err.lines() {});
    (child, addr)
}

fn connect(addr: &str) -> Client<TcpStream> {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(WAIT)).unwrap();
    let r = s.try_clone().unwrap();
    Client::new(s, lines_of(r))
}

#[test]
fn two_clients_at_once_each_with_its_own_defaults() {
    let (mut child, addr) = start(&["--allow-writes"]);
    let mut a = connect(&addr);
    let mut b = connect(&addr);
    assert_eq!(a.ask("[1] set node 2"), "[1] OK");
    assert_eq!(b.ask("[1] set node 3"), "[1] OK");
    // Both ask before either reads.
    a.send(b"[2] r 0x1008 0 vs\r\n");
    b.send(b"[2] r 0x1008 0 vs\r\n");
    assert_eq!(b.answer_of(2), "[2] \"cotui simulated Syn-tron-like DS servo\"");
    assert_eq!(a.answer_of(2), "[2] \"cotui simulated AIMOTOR-like servo\"");
    assert_eq!(a.ask("[3] w 0x1017 0 u16 250"), "[3] OK");
    assert_eq!(b.ask("[3] 2 r 0x1017 0 u16"), "[3] 250", "one bus behind both clients");
    // A client that goes away leaves the other served.
    drop(a);
    assert_eq!(b.ask("[4] r 0x1017 0 u16"), "[4] 500");
    let mut c = connect(&addr);
    assert!(
        c.ask("[5] r 0x1017 0").starts_with("[5] ERROR:105"),
        "a new session has no default node"
    );
    let _ = child.kill();
    let _ = child.wait();
}

#[test]
fn read_only_over_tcp_refuses_writes() {
    let (mut child, addr) = start(&[]);
    let mut a = connect(&addr);
    assert!(a.ask("[1] 2 w 0x1017 0 u16 250").starts_with("[1] ERROR:100"));
    assert_eq!(a.ask("[2] 2 r 0x1017 0 u16"), "[2] 500");
    let _ = child.kill();
    let _ = child.wait();
}

#[test]
fn past_the_client_limit_a_connect_is_told_and_closed_and_the_others_go_on() {
    let (mut child, addr) = start(&[]);
    let mut first = connect(&addr);
    assert_eq!(first.ask("[1] 2 r 0x1017 0 u16"), "[1] 500");
    // Fill the gateway: each connection answered once, so it is counted in.
    let mut held = Vec::new();
    for n in 1..cotui::gateway::serve::MAX_CLIENTS {
        let mut c = connect(&addr);
        assert_eq!(c.ask(&format!("[{n}] set node 2")), format!("[{n}] OK"));
        held.push(c);
    }
    let mut extra = connect(&addr);
    let told = extra.next_line();
    assert!(
        told.starts_with("[0] ERROR:102") && told.contains("clients are served already"),
        "{told}"
    );
    assert_eq!(
        first.ask("[2] 2 r 0x1017 0 u16"),
        "[2] 500",
        "the others are still served"
    );
    held.pop().unwrap().to.shutdown(std::net::Shutdown::Both).unwrap();
    // A freed place is taken by the next connect (once the gateway saw the close).
    let served = (0..200).any(|k| {
        let mut c = connect(&addr);
        c.send(format!("[{k}] set node 3\r\n").as_bytes());
        c.next_line() == format!("[{k}] OK")
    });
    assert!(served, "a place freed by a client that left is taken again");
    let _ = child.kill();
    let _ = child.wait();
}
