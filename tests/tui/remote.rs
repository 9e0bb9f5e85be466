//! `cotui live socketcand://127.0.0.1:PORT/demo`: the analyzer on a bus served by `cotui
//! serve demo` in another process, with the full palette (an SDO read answered over the
//! network), a lost server shown as the bus state and capture resuming when it is back.

use cotui::analysis::trace::Trace;
use cotui::decode::Decoder;
use cotui::frame::NodeKey;
use cotui::tui::app::{App, SourceInfo, SourceKind};
use cotui::tui::keymap::Keymap;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// `cotui serve demo --socketcand PORT --allow-send`; the port it listens on once it does.
fn serve(port: u16) -> (Child, u16) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["serve", "demo", "--socketcand", &port.to_string(), "--allow-send"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let err = child.stderr.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for l in BufReader::new(err).lines().map_while(Result::ok) {
            let _ = tx.send(l);
        }
    });
    let first = rx.recv_timeout(Duration::from_secs(60)).unwrap();
    let port = first.split("socketcand on 127.0.0.1:").nth(1).unwrap();
    (child, port.split(',').next().unwrap().parse().unwrap())
}

fn until(a: &mut App, what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    crate::screen::until_at(a, (200, 40), what, f)
}

#[test]
fn the_tui_attaches_to_a_remote_bus_with_the_palette_and_follows_the_server() {
    let (mut server, port) = serve(0);
    let url = format!("socketcand://127.0.0.1:{port}/demo");
    let bindings = cotui::cli::bind::bindings_on(&url, &[], &[]).unwrap();
    let trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
    let (rx, req) = cotui::tui::live::start(
        std::slice::from_ref(&url),
        false,
        bindings.clone(),
        None,
        Default::default(),
    );
    let src = SourceInfo::live(&url, SourceKind::Live { listen_only: false }, rx, req);
    let mut a = App::new(trace, Keymap::default_map(), src);
    a.set_bindings(bindings);
    until(&mut a, "node 2 and 3 from the remote bus", |a, _| {
        let n = &a.trace().nodes;
        [2, 3]
            .iter()
            .all(|&node| n.iter().any(|(k, _)| *k == NodeKey::new(0, node)))
    });
    a.run_command("sdo read 2 0x1017");
    until(&mut a, "the SDO answer in the message line", |a, _| {
        a.message().is_some_and(|m| m.contains("500 ms"))
    });
    // The server goes away: the bus state says so; it comes back on the same port: capture resumes.
    let _ = server.kill();
    let _ = server.wait();
    until(&mut a, "the lost connection", |_, s| {
        s.contains("connection to the server lost")
    });
    let (mut again, _) = serve(port);
    let before = a.trace().len();
    until(&mut a, "frames again", |a, s| {
        a.trace().len() > before + 20 && !s.contains("connection to the server lost")
    });
    let _ = again.kill();
    let _ = again.wait();
}

/// A socketcand server that sends `n` frames (`18N#` with a counter) as fast as TCP takes
/// them, then keeps the connection open; its port.
fn flood_server(n: u32) -> u16 {
    use std::io::{Read, Write};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    std::thread::spawn(move || {
        let (mut c, _) = listener.accept().unwrap();
        c.write_all(b"< hi >").unwrap();
        let mut seen = Vec::new();
        let mut buf = [0u8; 256];
        // Answer `open`, `rawmode`, then cotui's send-policy question and its echo.
        for (word, reply) in [
            ("open", "< ok >"),
            ("rawmode", "< ok >"),
            ("echo", "< cotui_send_policy refused read-only >< echo >"),
        ] {
            while !String::from_utf8_lossy(&seen).contains(word) {
                let k = c.read(&mut buf).unwrap();
                assert!(k > 0, "the client left during the handshake");
                seen.extend_from_slice(&buf[..k]);
            }
            seen.clear();
            c.write_all(reply.as_bytes()).unwrap();
        }
        let mut out = String::new();
        for i in 0..n {
            let us = u64::from(i) * 10;
            out.push_str(&format!(
                "< frame {:X} {}.{:06} {:08X} >",
                0x181 + i % 4,
                1_700_000_000 + us / 1_000_000,
                us % 1_000_000,
                i
            ));
            if out.len() > 64 * 1024 {
                c.write_all(out.as_bytes()).unwrap();
                out.clear();
            }
        }
        c.write_all(out.as_bytes()).unwrap();
        // Keep the connection (the client would report it lost), reading its echoes.
        while c.read(&mut buf).is_ok_and(|k| k > 0) {}
    });
    port
}

#[test]
fn a_flood_from_a_remote_bus_reaches_the_trace_whole_however_slowly_the_ui_takes_it() {
    // More frames than the feed channel holds (256 batches of 1024), sent far faster than
    // this test's UI loop (a render between 20 ms slices) takes them.
    const N: u32 = 400_000;
    let url = format!("socketcand://127.0.0.1:{}/can0", flood_server(N));
    let bindings = cotui::cli::bind::bindings_on(&url, &[], &[]).unwrap();
    let trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
    let (rx, req) = cotui::tui::live::start(
        std::slice::from_ref(&url),
        true,
        bindings.clone(),
        None,
        Default::default(),
    );
    let src = SourceInfo::live(&url, SourceKind::Live { listen_only: true }, rx, req);
    let mut a = App::new(trace, Keymap::default_map(), src);
    let s = until(&mut a, "every frame", |a, _| a.trace().len() >= N as usize);
    assert_eq!(a.trace().len(), N as usize, "{s}");
    assert_eq!(a.source().drops, 0, "{s}");
    assert!(s.contains(&format!("{N} frames | ")) && s.contains("drops 0"), "{s}");
    // In order, none twice: the counter in the data goes 0, 1, 2, ...
    let store = &a.trace().store;
    let bad = (0..store.len()).find(|&i| {
        let f = store.frame(i);
        u32::from_be_bytes([f.data[0], f.data[1], f.data[2], f.data[3]]) != i as u32
    });
    assert_eq!(bad, None, "frame out of order");
}
