//! Sessions in process on the demo bus (tokio time paused: deterministic): what reaches the
//! bus for each request, and the node table of a trace fed from the same bus.

use cotui::analysis::trace::Trace;
use cotui::bus::Subscription;
use cotui::decode::Decoder;
use cotui::decode::heartbeat::NmtState;
use cotui::frame::{Direction, Frame, NodeKey};
use cotui::gateway::session::{Policy, Session};
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use std::time::Duration;

/// The frames this handle sent that are on `rx` now.
fn sent(rx: &mut Subscription) -> Vec<Frame> {
    let mut out = Vec::new();
    while let Some(f) = rx.try_recv() {
        let f = f.unwrap();
        if f.direction() == Direction::Tx {
            out.push(f);
        }
    }
    out
}

fn writes(allow_writes: bool) -> Policy {
    Policy {
        allow_writes,
        notify: false,
    }
}

#[tokio::test(start_paused = true)]
async fn refused_requests_send_nothing() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut rx = d.bus.subscribe();
    let mut s = Session::new(d.bus.clone(), writes(false));
    for line in [
        "[1] 2 w 0x1017 0 u16 1000",
        "[2] 0 start",
        "[3] 2 reset comm",
        "[4] lss_switch_glob 1",
        "[5] lss_set_node 5",
        "[6] 2 w 0x1017 0 u99 1",
        "[7] 2 frob",
    ] {
        let a = s.answer(line.as_bytes()).await;
        assert!(a.contains("ERROR:10"), "{line}: {a}");
    }
    assert_eq!(sent(&mut rx), [], "a refused request sends nothing");
    assert_eq!(s.answer(b"[8] 2 r 0x1017 0 u16").await, "[8] 500\r\n");
    let frames = sent(&mut rx);
    assert_eq!(frames.len(), 1, "one expedited upload: {frames:?}");
    assert_eq!(frames[0].id, 0x602);
    assert_eq!(frames[0].payload()[..4], [0x40, 0x17, 0x10, 0x00]);
}

#[tokio::test(start_paused = true)]
async fn sdo_block_1_reads_by_block_transfer() {
    let d = Demo::spawn(Simulation::demo(), false);
    let mut rx = d.bus.subscribe();
    let mut s = Session::new(d.bus.clone(), writes(false));
    assert_eq!(s.answer(b"[1] set sdo_block 1").await, "[1] OK\r\n");
    let a = s.answer(b"[2] 2 r 0x1008 0 vs").await;
    assert_eq!(a, "[2] \"cotui simulated AIMOTOR-like servo\"\r\n");
    let frames = sent(&mut rx);
    assert_eq!(
        frames[0].payload()[0] & 0xE3,
        0xA0,
        "block upload initiate: {:?}",
        frames[0]
    );
}

#[tokio::test(start_paused = true)]
async fn listen_only_answers_102_for_a_read() {
    let d = Demo::spawn(Simulation::demo(), true);
    let mut s = Session::new(d.bus.clone(), writes(true));
    let a = s.answer(b"[1] 2 r 0x1017 0 u16").await;
    assert!(a.starts_with("[1] ERROR:102"), "{a}");
}

/// Feeds `rx`'s frames to `trace` until node 2 shows `want` (the demo's time runs meanwhile).
async fn until_state(rx: &mut Subscription, trace: &mut Trace, want: NmtState) {
    for _ in 0..100 {
        while let Some(f) = rx.try_recv() {
            trace.push(&f.unwrap());
        }
        let state = trace.nodes.liveness(NodeKey::new(0, 2)).and_then(|l| l.state);
        if state == Some(want) {
            return;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!("node 2 never showed {want:?} in the node table");
}

#[tokio::test(start_paused = true)]
async fn nmt_through_the_gateway_shows_in_the_node_table() {
    let d = Demo::spawn(Simulation::demo(), false);
    let bindings = cotui::cli::bind::bindings_on("demo", &[], &[]).unwrap();
    let mut trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
    let mut rx = d.bus.subscribe();
    let mut s = Session::new(d.bus.clone(), writes(true));
    until_state(&mut rx, &mut trace, NmtState::Operational).await;
    assert_eq!(s.answer(b"[1] 2 preop").await, "[1] OK\r\n");
    until_state(&mut rx, &mut trace, NmtState::PreOperational).await;
    assert_eq!(s.answer(b"[2] 2 start").await, "[2] OK\r\n");
    until_state(&mut rx, &mut trace, NmtState::Operational).await;
    assert_eq!(s.answer(b"[3] lss_switch_glob 1").await, "[3] OK\r\n");
    assert_eq!(s.answer(b"[4] lss_switch_glob 0").await, "[4] OK\r\n");
    let lss: Vec<Vec<u8>> = sent(&mut rx)
        .iter()
        .filter(|f| f.id == 0x7E5)
        .map(|f| f.payload().to_vec())
        .collect();
    assert_eq!(lss, [vec![4, 1, 0, 0, 0, 0, 0, 0], vec![4, 0, 0, 0, 0, 0, 0, 0]]);
}

#[tokio::test(start_paused = true)]
async fn lss_allnodes_gives_every_fresh_drive_a_node_id_as_canopend_does() {
    use cotui::sim::drive::Drive;
    use cotui::sim::spec::parse_node;
    let drives = ["ff=servo@0x99", "ff=servo@0x1234"]
        .iter()
        .map(|s| {
            let (node, profile) = parse_node(s).unwrap();
            Drive::new(node, profile)
        })
        .collect();
    let d = Demo::spawn(Simulation::new(drives, 0), false);
    let mut s = Session::new(d.bus.clone(), writes(true));
    let a = s.answer(b"[1] lss_allnodes 100 10 1").await;
    let lines: Vec<&str> = a.lines().collect();
    assert_eq!(lines.len(), 4, "{a}");
    // The fastscan finds the lower serial first (its bits are walked from the top down).
    assert!(lines[0].starts_with("# Node-ID 10 assigned to: 0x"), "{a}");
    assert!(lines[0].ends_with(" 0x00000099"), "{a}");
    assert!(
        lines[1].starts_with("# Node-ID 11 assigned to: ") && lines[1].ends_with(" 0x00001234"),
        "{a}"
    );
    assert_eq!(lines[2..], ["# Found 2 nodes, search finished.", "[1] OK"]);
    assert!(a.ends_with("[1] OK\r\n"));
    // Both took their node-ID at the reset: they answer SDO there.
    assert_eq!(s.answer(b"[2] 0 reset comm").await, "[2] OK\r\n");
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert_eq!(s.answer(b"[3] 10 r 0x1018 4 u32").await, "[3] 153\r\n");
    assert_eq!(s.answer(b"[4] 11 r 0x1018 4 u32").await, "[4] 4660\r\n");
    // None left: found 0.
    assert_eq!(
        s.answer(b"[5] lss_allnodes").await,
        "# Found 0 nodes, search finished.\n[5] OK\r\n"
    );
}
