//! SDO transfers over a [`Bus`]: the IO around the pure [`SdoClient`].
//!
//! The client's clock is the bus's ([`Bus::now_ns`]), the clock of the frames' receive
//! timestamps, so answers are judged by when they arrived, not by when this task got round
//! to reading them: before declaring a timeout, the loop lets the bus reader pass on what
//! it has and consumes every queued frame. On the virtual bus the clock follows tokio's, so
//! tests with paused time are deterministic.
//!
//! Each transfer waits for its node's turn ([`Bus::sdo_turn`]): the palette, the Watch and
//! Objects panes, the gateway's clients and the commands never run two transfers to one
//! node at once (their answers would cross); a stop's handle does not wait.

use super::error::CommandError;
use crate::bus::{Bus, BusError, Subscription};
use crate::cob;
use crate::frame::{Direction, Frame};
use crate::sdo::client::{ClientConfig, Completion, Mode, SdoClient, SdoError};
use std::time::Duration;

/// How long an SDO transfer may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    /// The longest wait for each answer of the server, in ms.
    pub timeout_ms: u64,
    /// The longest the whole transfer may take, in ms; `None`: the client's default
    /// (see [`ClientConfig::default_deadline_ns`]).
    pub deadline_ms: Option<u64>,
}

impl Timing {
    /// `timeout_ms` for each answer and the default overall deadline.
    pub fn answer(timeout_ms: u64) -> Timing {
        Timing {
            timeout_ms,
            deadline_ms: None,
        }
    }
}

/// Reads (index, sub) of `node`; `timeout_ms` bounds the wait for each response, the default
/// deadline the whole transfer.
pub async fn upload(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    block: bool,
    timeout_ms: u64,
) -> Result<Vec<u8>, CommandError> {
    upload_within(bus, node, index, sub, block, Timing::answer(timeout_ms)).await
}

/// Reads (index, sub) of `node` within `timing`.
pub async fn upload_within(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    block: bool,
    timing: Timing,
) -> Result<Vec<u8>, CommandError> {
    let _turn = bus.sdo_turn(node).await;
    let mut rx = bus.subscribe();
    let mut client = SdoClient::new(config(timing));
    let first = client
        .upload(index, sub, mode(block), bus.now_ns())
        .map_err(|e| CommandError::Usage(e.to_string()))?;
    match run(bus, &mut rx, node, client, first).await? {
        Completion::Uploaded { data, .. } => Ok(data),
        other => Err(unexpected(node, index, sub, other, timing)),
    }
}

/// Writes `data` to (index, sub) of `node`: expedited up to 4 bytes, segmented above, block with `block`.
pub async fn download(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    data: Vec<u8>,
    block: bool,
    timeout_ms: u64,
) -> Result<(), CommandError> {
    download_within(bus, node, index, sub, data, block, Timing::answer(timeout_ms)).await
}

/// Writes `data` to (index, sub) of `node` within `timing`.
pub async fn download_within(
    bus: &Bus,
    node: u8,
    index: u16,
    sub: u8,
    data: Vec<u8>,
    block: bool,
    timing: Timing,
) -> Result<(), CommandError> {
    let _turn = bus.sdo_turn(node).await;
    let mut rx = bus.subscribe();
    let mut client = SdoClient::new(config(timing));
    let first = client
        .download(index, sub, data, mode(block), bus.now_ns())
        .map_err(|e| CommandError::Usage(e.to_string()))?;
    match run(bus, &mut rx, node, client, first).await? {
        Completion::Downloaded { .. } => Ok(()),
        other => Err(unexpected(node, index, sub, other, timing)),
    }
}

/// The first frame an SDO read of (index, sub) of `node` sends: the one the client itself
/// starts the transfer with (initiate upload, or block upload initiate with `block`).
pub fn first_upload_frame(node: u8, index: u16, sub: u8, block: bool) -> Frame {
    let mut client = SdoClient::new(ClientConfig::default());
    let first = client.upload(index, sub, mode(block), 0).unwrap_or_default();
    request_frame(node, &first)
}

/// The first frame an SDO write of `data` to (index, sub) of `node` sends (expedited up to
/// 4 bytes, segmented initiate above, block download initiate with `block`), built by the
/// client itself; with what follows it, when more follows.
pub fn first_download_frame(node: u8, index: u16, sub: u8, data: &[u8], block: bool) -> (Frame, Option<String>) {
    let mut client = SdoClient::new(ClientConfig::default());
    let first = client
        .download(index, sub, data.to_vec(), mode(block), 0)
        .unwrap_or_default();
    let segments = data.len().div_ceil(7).max(1);
    let then = if block {
        Some(format!(
            "then {segments} block segments ({} bytes) and the block end",
            data.len()
        ))
    } else if data.len() > 4 || data.is_empty() {
        Some(format!("then {segments} segments"))
    } else {
        None
    };
    (request_frame(node, &first), then)
}

/// A request of the client to `node`'s server (COB-ID 0x600 + node).
fn request_frame(node: u8, payload: &[u8; 8]) -> Frame {
    Frame::classic(cob::sdo_request(node), payload)
}

fn config(timing: Timing) -> ClientConfig {
    ClientConfig {
        timeout_ns: timing.timeout_ms.saturating_mul(1_000_000),
        deadline_ns: timing.deadline_ms.map(|ms| ms.saturating_mul(1_000_000)),
        ..ClientConfig::default()
    }
}

fn mode(block: bool) -> Mode {
    if block { Mode::Block } else { Mode::Auto }
}

/// A completion of the wrong kind, or a failure, as a command error.
fn unexpected(node: u8, index: u16, sub: u8, c: Completion, timing: Timing) -> CommandError {
    let Completion::Failed { error, .. } = c else {
        return CommandError::Usage("SDO client finished with the wrong kind of transfer".into());
    };
    let abort = |code, by_server, reason| CommandError::Abort {
        node,
        index,
        sub,
        code,
        by_server,
        reason,
    };
    match error {
        SdoError::Aborted { code, .. } => abort(code, true, None),
        SdoError::Protocol { code, reason } => abort(code, false, Some(reason)),
        SdoError::Cancelled { code } => abort(code, false, None),
        SdoError::Timeout => CommandError::Timeout(format!(
            "SDO {index:04X}:{sub:02X}: node {node} did not answer within {} ms (sent abort 0x05040000)",
            timing.timeout_ms
        )),
        SdoError::Deadline { limit_ns } => CommandError::Timeout(format!(
            "SDO {index:04X}:{sub:02X}: node {node} kept the transfer going past its {} ms deadline \
             (sent abort 0x05040000; --deadline sets it)",
            limit_ns / 1_000_000
        )),
    }
}

async fn send_all(bus: &Bus, node: u8, frames: &[[u8; 8]]) -> Result<(), CommandError> {
    for p in frames {
        bus.send(&Frame::classic(cob::sdo_request(node), p)).await?;
    }
    Ok(())
}

/// Sends `first`, then feeds the frames of `rx` to `client` until the transfer ends.
///
/// A timeout is declared only at a moment `now` after every frame received before `now`
/// went to the client: `now` is read first, the bus reader gets a turn (a SocketCAN frame
/// the kernel stamped before `now` is then queued), and the queue is drained.
async fn run(
    bus: &Bus,
    rx: &mut Subscription,
    node: u8,
    mut client: SdoClient,
    first: [u8; 8],
) -> Result<Completion, CommandError> {
    send_all(bus, node, &[first]).await?;
    loop {
        let now = bus.now_ns();
        tokio::task::yield_now().await;
        while let Some(frame) = rx.try_recv() {
            if let Some(done) = feed(bus, node, &mut client, frame).await? {
                return Ok(done);
            }
        }
        let out = client.poll(now);
        send_all(bus, node, &out.frames).await?;
        if let Some(done) = out.done {
            return Ok(done);
        }
        let wait = client.next_deadline().map_or(0, |d| d.saturating_sub(now));
        if let Ok(frame) = tokio::time::timeout(Duration::from_nanos(wait), rx.recv()).await
            && let Some(done) = feed(bus, node, &mut client, frame).await?
        {
            return Ok(done);
        }
    }
}

/// Gives one bus frame to `client`: the server's answers, and the echoes of our own
/// requests (their timestamps say when they reached the bus); returns the result once done.
/// A read error of the interface is passed over (the timeouts still run); a closed bus ends the transfer.
async fn feed(
    bus: &Bus,
    node: u8,
    client: &mut SdoClient,
    frame: Result<Frame, BusError>,
) -> Result<Option<Completion>, CommandError> {
    let f = match frame {
        Ok(f) if !f.is_ext() => f,
        Err(BusError::Closed) => return Err(BusError::Closed.into()),
        _ => return Ok(None),
    };
    let ts = if f.ts_ns == 0 { bus.now_ns() } else { f.ts_ns };
    match f.direction() {
        Direction::Rx if f.id == cob::sdo_response(node) => {
            let out = client.on_frame(f.payload(), ts);
            send_all(bus, node, &out.frames).await?;
            Ok(out.done)
        }
        Direction::Tx if f.id == cob::sdo_request(node) => {
            client.on_sent(ts);
            Ok(None)
        }
        _ => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    //! The IO loop on the virtual bus with paused time, against scripted servers.

    use super::*;
    use crate::bus::virt::VirtualBus;
    use std::sync::{Arc, Mutex};
    use tokio::time::Instant;

    const NODE: u8 = 9;
    const MS: u64 = 1_000_000;

    /// What a scripted server answers to one request: (delay, payload) pairs, sent in order.
    type Script = Box<dyn FnMut(&[u8]) -> Vec<(u64, Vec<u8>)> + Send>;

    /// Runs `script` as node 9's server on its own endpoint; returns the log of the client's
    /// requests it saw.
    fn serve(vbus: &VirtualBus, mut script: Script) -> Arc<Mutex<Vec<Vec<u8>>>> {
        let log = Arc::new(Mutex::new(Vec::new()));
        let server = vbus.endpoint(false);
        let mut rx = server.subscribe();
        let seen = log.clone();
        tokio::spawn(async move {
            while let Ok(f) = rx.recv().await {
                if f.id != cob::sdo_request(NODE) || f.direction() == Direction::Tx {
                    continue;
                }
                seen.lock().unwrap().push(f.payload().to_vec());
                for (delay_ms, p) in script(f.payload()) {
                    tokio::time::sleep(Duration::from_millis(delay_ms)).await;
                    let _ = server.send(&Frame::classic(cob::sdo_response(NODE), &p)).await;
                }
            }
        });
        log
    }

    fn timing(timeout_ms: u64, deadline_ms: Option<u64>) -> Timing {
        Timing {
            timeout_ms,
            deadline_ms,
        }
    }

    /// The abort the client sent: the last request the server saw, once the server task
    /// had its turns to read it.
    async fn last_abort(log: &Arc<Mutex<Vec<Vec<u8>>>>) -> Vec<u8> {
        let last = || log.lock().unwrap().last().cloned().unwrap_or_default();
        for _ in 0..100 {
            if last().first() == Some(&0x80) {
                break;
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        last()
    }

    #[tokio::test(start_paused = true)]
    async fn two_clients_reading_one_node_take_turns_and_both_get_their_value() {
        let vbus = VirtualBus::new("vbus");
        // A 14-byte segmented upload: initiate, then two segments (toggle 0, then 1 and last).
        let log = serve(
            &vbus,
            Box::new(|req| match req[0] {
                0x40 => vec![(2, vec![0x41, 0x00, 0x20, 0x00, 14, 0, 0, 0])],
                0x60 => vec![(2, [&[0x00][..], b"cotui s"].concat())],
                0x70 => vec![(2, [&[0x11][..], b"egments"].concat())],
                _ => vec![],
            }),
        );
        // Two tools on the bus (a palette read and a gateway client, say), at once.
        let (a, b) = (vbus.endpoint(false), vbus.endpoint(false));
        let (ra, rb) = tokio::join!(
            upload_within(&a, NODE, 0x2000, 0, false, timing(1000, None)),
            upload_within(&b, NODE, 0x2000, 0, false, timing(1000, None)),
        );
        assert_eq!(ra.unwrap(), b"cotui segments");
        assert_eq!(rb.unwrap(), b"cotui segments");
        let firsts: Vec<u8> = log.lock().unwrap().iter().map(|r| r[0]).collect();
        assert_eq!(
            firsts,
            [0x40, 0x60, 0x70, 0x40, 0x60, 0x70],
            "one transfer after the other"
        );
    }

    #[tokio::test(start_paused = true)]
    async fn truncated_answer_is_a_client_abort_with_exit_3() {
        let vbus = VirtualBus::new("vbus");
        // `599#4B002000`: an expedited answer cut after the index.
        let log = serve(&vbus, Box::new(|_| vec![(4, vec![0x4B, 0x00, 0x20, 0x00])]));
        let bus = vbus.endpoint(false);
        let e = upload_within(&bus, NODE, 0x2000, 0, false, timing(1000, None))
            .await
            .unwrap_err();
        assert_eq!(e.exit_code(), 3);
        let j = e.to_json();
        assert_eq!(j["error"], "sdo_abort");
        assert_eq!(j["abort_code"], 0x0504_0001);
        assert_eq!(j["aborted_by"], "client");
        assert!(j["reason"].as_str().unwrap().contains("4-byte answer"), "{j}");
        assert!(e.to_string().contains("SDO frames have 8 bytes"), "{e}");
        assert_eq!(last_abort(&log).await, [0x80, 0x00, 0x20, 0x00, 0x01, 0x00, 0x04, 0x05]);
    }

    #[tokio::test(start_paused = true)]
    async fn endless_segments_past_the_announced_size_are_aborted() {
        let vbus = VirtualBus::new("vbus");
        let mut toggle = 0;
        let log = serve(
            &vbus,
            Box::new(move |req| match req[0] {
                // 8 bytes announced, then 7-byte segments that never end.
                0x40 => vec![(1, vec![0x41, 0x00, 0x20, 0x00, 8, 0, 0, 0])],
                0x80 => vec![],
                _ => {
                    toggle ^= 0x10;
                    vec![(1, vec![toggle ^ 0x10, 1, 2, 3, 4, 5, 6, 7])]
                }
            }),
        );
        let bus = vbus.endpoint(false);
        let e = upload_within(&bus, NODE, 0x2000, 0, false, timing(1000, None))
            .await
            .unwrap_err();
        assert_eq!(e.exit_code(), 3);
        assert_eq!(e.to_json()["abort_code"], 0x0607_0012);
        assert!(e.to_string().contains("announced 8 bytes but sent 14"), "{e}");
        assert_eq!(last_abort(&log).await, [0x80, 0x00, 0x20, 0x00, 0x12, 0x00, 0x07, 0x06]);
    }

    #[tokio::test(start_paused = true)]
    async fn block_upload_that_never_ends_stops_at_the_deadline_with_exit_4() {
        let vbus = VirtualBus::new("vbus");
        let log = serve(
            &vbus,
            Box::new(|req| match req[0] {
                // No size announced; every sub-block is full and none is the last.
                0xA4 => vec![(1, vec![0xC4, 0x00, 0x20, 0x00, 0, 0, 0, 0])],
                0xA3 | 0xA2 => (1..=127u8)
                    .map(|s| (if s == 1 { 50 } else { 0 }, vec![s, 0, 0, 0, 0, 0, 0, 0]))
                    .collect(),
                _ => vec![],
            }),
        );
        let bus = vbus.endpoint(false);
        let start = Instant::now();
        let e = upload_within(&bus, NODE, 0x2000, 0, true, timing(1000, Some(2000)))
            .await
            .unwrap_err();
        assert_eq!(start.elapsed(), Duration::from_millis(2000));
        assert_eq!(e.exit_code(), 4);
        assert!(e.to_string().contains("past its 2000 ms deadline"), "{e}");
        assert_eq!(last_abort(&log).await, [0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x04, 0x05]);
        assert!(log.lock().unwrap().len() > 30, "the server was answering all along");
    }

    #[tokio::test(start_paused = true)]
    async fn overall_deadline_holds_while_every_answer_comes_in_time() {
        let vbus = VirtualBus::new("vbus");
        let mut toggle = 0x10;
        let log = serve(
            &vbus,
            Box::new(move |req| match req[0] {
                // Segmented without a size; each answer after 500 ms (the timeout is 1 s).
                0x40 => vec![(500, vec![0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0])],
                0x80 => vec![],
                _ => {
                    toggle ^= 0x10;
                    vec![(500, vec![toggle, 1, 2, 3, 4, 5, 6, 7])]
                }
            }),
        );
        let bus = vbus.endpoint(false);
        let start = Instant::now();
        let e = upload_within(&bus, NODE, 0x2000, 0, false, timing(1000, Some(3000)))
            .await
            .unwrap_err();
        assert_eq!(start.elapsed(), Duration::from_millis(3000));
        assert!(matches!(e, CommandError::Timeout(_)), "{e:?}");
        assert_eq!(last_abort(&log).await, [0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x04, 0x05]);
    }

    #[tokio::test(start_paused = true)]
    async fn silent_server_times_out_after_the_answer_timeout() {
        let vbus = VirtualBus::new("vbus");
        let log = serve(&vbus, Box::new(|_| vec![]));
        let bus = vbus.endpoint(false);
        let start = Instant::now();
        let e = download_within(&bus, NODE, 0x6040, 0, vec![6, 0], false, timing(700, None))
            .await
            .unwrap_err();
        assert_eq!(start.elapsed(), Duration::from_millis(700));
        assert_eq!(e.exit_code(), 4);
        assert!(e.to_string().contains("did not answer within 700 ms"), "{e}");
        assert_eq!(last_abort(&log).await, [0x80, 0x40, 0x60, 0x00, 0x00, 0x00, 0x04, 0x05]);
    }

    /// A SocketCAN reader that gets its turn only at the very moment the answer is due passes
    /// on an answer the kernel stamped 4 ms after the request: it is taken, not timed out.
    #[tokio::test(start_paused = true)]
    async fn queued_answer_stamped_in_time_is_taken_at_the_deadline() {
        let vbus = VirtualBus::new("vbus");
        let bus = vbus.endpoint(false);
        let reader = bus.clone();
        let mut rx = vbus.endpoint(false).subscribe();
        tokio::spawn(async move {
            let request = loop {
                match rx.recv().await {
                    Ok(f) if f.id == cob::sdo_request(NODE) => break f,
                    Ok(_) => {}
                    Err(_) => return,
                }
            };
            tokio::time::sleep(Duration::from_millis(1000)).await;
            let mut answer = Frame::classic(cob::sdo_response(NODE), &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]);
            answer.ts_ns = request.ts_ns + 4 * MS;
            reader.inject(answer);
        });
        let start = Instant::now();
        let data = upload_within(&bus, NODE, 0x6041, 0, false, timing(1000, None))
            .await
            .unwrap();
        assert_eq!(data, [0x37, 0x02]);
        assert_eq!(start.elapsed(), Duration::from_millis(1000));
    }

    #[test]
    fn palette_and_cli_take_a_deadline() {
        use crate::command::object::Sdo;
        let Ok(crate::command::Command::Sdo(Sdo::Read(crate::command::object::SdoRead { options, .. }))) =
            crate::command::parse_command("sdo read 2 0x1F50:1 --block --timeout 500 --deadline 60000")
        else {
            panic!("not an sdo read")
        };
        assert_eq!((options.timeout_ms, options.deadline_ms), (500, Some(60_000)));
        assert!(crate::command::parse_command("sdo read 2 0x1F50:1 --deadline 0").is_err());
    }

    /// The same answer stamped after the deadline is late: a timeout.
    #[tokio::test(start_paused = true)]
    async fn answer_stamped_after_the_deadline_is_a_timeout() {
        let vbus = VirtualBus::new("vbus");
        let bus = vbus.endpoint(false);
        let reader = bus.clone();
        let before = vbus.now_ns();
        reader.inject({
            let mut f = Frame::classic(cob::sdo_response(NODE), &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]);
            f.ts_ns = before + 1500 * MS;
            f
        });
        let e = upload_within(&bus, NODE, 0x6041, 0, false, timing(1000, None))
            .await
            .unwrap_err();
        assert_eq!(e.exit_code(), 4, "{e}");
    }
}
