//! `cotui demo --gateway tcp:... --socketcand PORT`: the TUI hosts the CiA 309-3 gateway and
//! a socketcand server on its bus. A gateway client's read is answered, the request and its
//! answer are in the message log, its frames in the trace as cotui's own; a write is
//! refused (read-only) with nothing sent; a socketcand client gets the bus, its connect is
//! in the message log.

use cotui::analysis::trace::Trace;
use cotui::decode::Decoder;
use cotui::frame::Direction;
use cotui::gateway::listen::Bound;
use cotui::gateway::session::Policy;
use cotui::tui::app::{App, SourceInfo, SourceKind};
use cotui::tui::hosted::Hosted;
use cotui::tui::keymap::Keymap;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::time::Duration;

fn until(a: &mut App, what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    crate::screen::until_at(a, (160, 40), what, f)
}

fn logged(a: &App, f: impl Fn(&str) -> bool) -> bool {
    a.screen().messages().iter().any(|e| f(&e.text))
}

/// One answer line of the gateway (CR LF cut).
fn answer(r: &mut BufReader<TcpStream>) -> String {
    let mut line = String::new();
    r.read_line(&mut line).unwrap();
    line.trim_end().to_string()
}

#[test]
fn the_tui_hosts_the_gateway_and_a_socketcand_server_and_logs_their_clients() {
    let gateway = Bound::spec("tcp:127.0.0.1:0").unwrap();
    let gw_addr = gateway.at().trim_start_matches("tcp ").to_string();
    let sc = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    sc.set_nonblocking(true).unwrap();
    let sc_addr = sc.local_addr().unwrap();
    let hosted = Hosted {
        gateway: Some((gateway, Policy::default())),
        socketcand: Some((
            sc,
            cotui::serve::Config {
                iface: "demo".into(),
                addr: sc_addr,
                allow_send: false,
                max_clients: 4,
                beacon: false,
            },
        )),
    };
    let bindings = cotui::cli::bind::bindings_on("demo", &[], &[]).unwrap();
    let trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
    let (rx, req) = cotui::tui::live::start(&["demo".into()], false, bindings.clone(), None, hosted);
    let src = SourceInfo::live("demo", SourceKind::Demo { listen_only: false }, rx, req);
    let mut a = App::new(trace, Keymap::default_map(), src);
    a.set_bindings(bindings);
    until(&mut a, "the gateway's first line", |a, _| {
        logged(a, |t| {
            t == format!("gateway: demo on tcp {gw_addr} (read-only: --allow-writes for write, NMT and LSS)")
        })
    });

    // A gateway client reads the heartbeat time of drive 2.
    let stream = TcpStream::connect(&gw_addr).unwrap();
    stream.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let mut w = stream.try_clone().unwrap();
    let mut r = BufReader::new(stream);
    w.write_all(b"[1] 2 read 0x1017 0 u16\r\n").unwrap();
    assert_eq!(answer(&mut r), "[1] 500");
    w.write_all(b"[2] 2 write 0x1017 0 u16 1000\r\n").unwrap();
    assert_eq!(
        answer(&mut r),
        "[2] ERROR:100 #Request not supported. the gateway is read-only: start it with --allow-writes for write, NMT and LSS (nothing was sent)"
    );
    until(&mut a, "both requests in the message log", |a, _| {
        logged(a, |t| {
            t.starts_with("gateway: tcp 127.0.0.1:") && t.ends_with(": [1] 2 read 0x1017 0 u16 -> [1] 500")
        }) && logged(a, |t| {
            t.contains(": [2] 2 write 0x1017 0 u16 1000 -> [2] ERROR:100 #Request not supported.")
        })
    });
    assert!(logged(&a, |t| t.starts_with("gateway: tcp 127.0.0.1:")
        && t.ends_with(" connected")));
    // The read is in the trace as cotui's own frame; the refused write never went out.
    let t = a.trace();
    let ours: Vec<[u8; 4]> = (0..t.len())
        .map(|i| t.store.frame(i))
        .filter(|f| f.id == 0x602 && f.direction() == Direction::Tx)
        .map(|f| [f.data[0], f.data[1], f.data[2], f.data[3]])
        .collect();
    assert!(ours.contains(&[0x40, 0x17, 0x10, 0x00]), "{ours:02X?}");
    assert!(!ours.iter().any(|d| d[0] == 0x2B), "a write went out: {ours:02X?}");
    drop((w, r));

    // A socketcand client opens the demo bus and receives its frames.
    let mut c = TcpStream::connect(sc_addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let mut got = String::new();
    let mut buf = [0u8; 4096];
    let mut read_until = |c: &mut TcpStream, got: &mut String, want: &str| {
        while !got.contains(want) {
            let n = c.read(&mut buf).unwrap();
            assert!(n > 0, "closed before {want}: {got}");
            got.push_str(&String::from_utf8_lossy(&buf[..n]));
        }
    };
    read_until(&mut c, &mut got, "< hi >");
    c.write_all(b"< open demo >").unwrap();
    read_until(&mut c, &mut got, "< ok >");
    c.write_all(b"< rawmode >").unwrap();
    read_until(&mut c, &mut got, "< frame 702 ");
    until(&mut a, "the socketcand client in the message log", |a, _| {
        logged(a, |t| t.starts_with("socketcand: socketcand on 127.0.0.1:"))
            && logged(a, |t| {
                t.starts_with("socketcand: client 1 (127.0.0.1:") && t.ends_with(") connected")
            })
    });
}
