//! SocketCAN against a real kernel: needs a CAN FD capable `vcan0` (MTU 72). Run in the
//! vbus guest: `VBUS_IFACES=vcan0:fd tests/vbus/run.sh $PWD/target/debug/deps/socketcan_live-HASH --ignored`
//! (build it first with `cargo test --test socketcan_live --no-run`).

use cotui::bus::socketcan::open;
use cotui::frame::{Flags, Frame};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

async fn next(rx: &mut cotui::bus::Subscription) -> Frame {
    tokio::time::timeout(Duration::from_secs(2), rx.recv())
        .await
        .unwrap()
        .unwrap()
}

#[tokio::test]
#[ignore = "needs vcan0 (run through tests/vbus/run.sh)"]
async fn own_frames_are_tx_with_kernel_timestamps_and_others_rx() {
    let a = open("vcan0", false).unwrap();
    let b = open("vcan0", false).unwrap();
    let (mut ra, mut rb) = (a.subscribe(), b.subscribe());
    a.send(&Frame::classic(0x602, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]))
        .await
        .unwrap();
    let (fa, fb) = (next(&mut ra).await, next(&mut rb).await);
    assert!(fa.flags.has(Flags::TX), "sender sees its frame as TX");
    assert!(!fb.flags.has(Flags::TX), "another socket sees it as RX");
    assert_eq!(fb.payload(), &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]);
    let now = SystemTime::now().duration_since(UNIX_EPOCH).unwrap().as_nanos() as u64;
    assert!(now - fb.ts_ns < 2_000_000_000, "kernel timestamp is wall-clock time");
    let mut fd = Frame::classic(0x123, &[]);
    fd.flags.set(Flags::FD, true);
    fd.flags.set(Flags::BRS, true);
    fd.len = 12;
    fd.data[..12].copy_from_slice(&[9; 12]);
    b.send(&fd).await.unwrap();
    let got = next(&mut ra).await;
    assert!(got.is_fd() && got.flags.has(Flags::BRS));
    assert_eq!(got.payload(), &[9; 12]);
    let own = next(&mut rb).await;
    assert!(own.is_fd() && own.flags.has(Flags::TX), "b sees its own FD frame as TX");
    let mut ext = Frame::classic(0x1ABC_DEF0, &[1, 2]);
    ext.flags.set(Flags::EXT, true);
    a.send(&ext).await.unwrap();
    let got = next(&mut rb).await;
    assert_eq!((got.id, got.is_ext()), (0x1ABC_DEF0, true));
}

#[tokio::test]
#[ignore = "needs vcan0 (run through tests/vbus/run.sh)"]
async fn listen_only_socket_never_writes() {
    let quiet = open("vcan0", true).unwrap();
    let watch = open("vcan0", false).unwrap();
    let mut rx = watch.subscribe();
    assert_eq!(
        quiet.send(&Frame::classic(0x000, &[1, 0])).await,
        Err(cotui::bus::BusError::ListenOnly)
    );
    // Other tests may talk on vcan0 meanwhile: only the NMT frame we tried to send matters.
    let end = tokio::time::Instant::now() + Duration::from_millis(300);
    while let Ok(Ok(f)) = tokio::time::timeout_at(end, rx.recv()).await {
        assert!(
            !(f.id == 0 && f.payload() == [1, 0]),
            "listen-only frame reached the bus"
        );
    }
}

#[tokio::test]
#[ignore = "needs vcan0 and can-utils' cangen (run through tests/vbus/run.sh)"]
async fn a_reader_that_falls_behind_counts_what_the_kernel_dropped() {
    let bus = open("vcan0", true).unwrap();
    let mut rx = bus.subscribe();
    // cangen runs while this (current-thread) runtime is blocked: nothing reads the socket,
    // so the burst overflows even the enlarged receive buffer.
    let sent = 60_000u64;
    let status = std::process::Command::new("cangen")
        .args([
            "vcan0",
            "-g",
            "0",
            "-n",
            &sent.to_string(),
            "-I",
            "7E0",
            "-L",
            "8",
            "-D",
            "i",
        ])
        .status()
        .expect("cangen runs");
    assert!(status.success());
    let mut got = 0u64;
    let mut last = None;
    while let Ok(Ok(f)) = tokio::time::timeout(Duration::from_millis(500), rx.recv()).await {
        let counter = u64::from_le_bytes(f.payload().try_into().unwrap());
        assert!(
            last.is_none_or(|l| counter > l),
            "frames out of order: {counter} after {last:?}"
        );
        last = Some(counter);
        got += 1;
    }
    assert_eq!(rx.lost(), 0, "the subscription kept up");
    assert!(got > 1000, "the buffer held a good part of the burst: {got}");
    assert!(
        bus.dropped() > 0,
        "{got} frames of {sent} read, none counted as dropped"
    );
    assert_eq!(
        got + bus.dropped(),
        sent,
        "every frame is either read or counted as dropped"
    );
}

#[tokio::test]
#[ignore = "needs vcan0 and can-utils' cangen (run through tests/vbus/run.sh)"]
async fn catch_up_reads_everything_the_kernel_queued() {
    let bus = open("vcan0", true).unwrap();
    let mut rx = bus.subscribe();
    // As above the runtime is blocked while cangen runs, so the frames wait in the socket;
    // 3000 fit the enlarged buffer. catch_up must bring all of them, with no waiting on time.
    let sent = 3000u64;
    let status = std::process::Command::new("cangen")
        .args([
            "vcan0",
            "-g",
            "0",
            "-n",
            &sent.to_string(),
            "-I",
            "7E1",
            "-L",
            "8",
            "-D",
            "i",
        ])
        .status()
        .expect("cangen runs");
    assert!(status.success());
    let mut got = 0u64;
    let mut count = |e: cotui::bus::Event| {
        if let cotui::bus::Event::Frame(f) = e
            && f.id == 0x7E1
        {
            assert_eq!(u64::from_le_bytes(f.payload().try_into().unwrap()), got, "in order");
            got += 1;
        }
    };
    let caught = bus.catch_up();
    tokio::pin!(caught);
    loop {
        tokio::select! {
            biased;
            e = rx.next() => count(e.unwrap()),
            _ = &mut caught => break,
        }
    }
    while let Some(e) = rx.try_next() {
        count(e.unwrap());
    }
    assert_eq!((got, bus.dropped(), rx.lost()), (sent, 0, 0));
}
