//! The pure SDO client against servers that misbehave: every transfer ends, with the
//! abort frame on the bus and the reason, however the server breaks the protocol.

use cotui::sdo::client::{ClientConfig, ClientOutput, Completion, Mode, SdoClient, SdoError};

const MS: u64 = 1_000_000;

/// The abort frame the client sends for (index, sub) with `code`.
fn abort(index: u16, sub: u8, code: u32) -> [u8; 8] {
    let [i0, i1] = index.to_le_bytes();
    let [c0, c1, c2, c3] = code.to_le_bytes();
    [0x80, i0, i1, sub, c0, c1, c2, c3]
}

/// The error of a failed transfer, after checking the output holds exactly the abort frame.
fn failed(out: &ClientOutput, index: u16, sub: u8, code: u32) -> SdoError {
    assert_eq!(out.frames, vec![abort(index, sub, code)], "{out:?}");
    match &out.done {
        Some(Completion::Failed {
            index: i,
            sub: s,
            error,
        }) if (*i, *s) == (index, sub) => error.clone(),
        other => panic!("not a failure of {index:04X}:{sub}: {other:?}"),
    }
}

/// A protocol error with `code` whose reason contains `says`.
fn protocol(out: &ClientOutput, index: u16, sub: u8, code: u32, says: &str) {
    match failed(out, index, sub, code) {
        SdoError::Protocol { code: c, reason } => {
            assert_eq!(c, code);
            assert!(reason.contains(says), "{reason}");
        }
        other => panic!("not a protocol error: {other:?}"),
    }
}

/// A segment of 7 bytes that is not the last, with `toggle`.
fn segment(toggle: bool) -> [u8; 8] {
    [if toggle { 0x10 } else { 0x00 }, 1, 2, 3, 4, 5, 6, 7]
}

#[test]
fn segments_past_the_announced_size_are_aborted_as_too_long() {
    let mut c = SdoClient::new(ClientConfig::default());
    c.upload(0x2000, 1, Mode::Auto, 0).unwrap();
    // Segmented, 10 bytes announced.
    let out = c.on_frame(&[0x41, 0x00, 0x20, 0x01, 10, 0, 0, 0], MS);
    assert_eq!(out.frames, vec![[0x60, 0, 0, 0, 0, 0, 0, 0]]);
    let out = c.on_frame(&segment(false), 2 * MS);
    assert_eq!(out.frames, vec![[0x70, 0, 0, 0, 0, 0, 0, 0]]);
    // 14 bytes of 10, and still not the last segment.
    let out = c.on_frame(&segment(true), 3 * MS);
    protocol(&out, 0x2000, 1, 0x0607_0012, "announced 10 bytes but sent 14");
    assert!(!c.is_busy());
    // A last segment that stops short of the size is too short.
    c.upload(0x2000, 1, Mode::Auto, 4 * MS).unwrap();
    c.on_frame(&[0x41, 0x00, 0x20, 0x01, 10, 0, 0, 0], 5 * MS);
    // 0x07: toggle 0, 3 bytes unused (4 carried), last.
    let out = c.on_frame(&[0x07, 1, 2, 3, 4, 0, 0, 0], 6 * MS);
    protocol(&out, 0x2000, 1, 0x0607_0013, "announced 10 bytes but ended after 4");
}

#[test]
fn unannounced_uploads_stop_at_the_cap_and_bigger_announcements_are_refused() {
    let cfg = ClientConfig {
        max_size: 20,
        ..ClientConfig::default()
    };
    let mut c = SdoClient::new(cfg);
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    // Segmented without a size.
    c.on_frame(&[0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0], MS);
    assert_eq!(c.on_frame(&segment(false), 2 * MS).frames.len(), 1);
    assert_eq!(c.on_frame(&segment(true), 3 * MS).frames.len(), 1);
    let out = c.on_frame(&segment(false), 4 * MS);
    protocol(&out, 0x2000, 0, 0x0504_0005, "sent 21 bytes without announcing a size");
    // An announced size above the cap is refused at once, segmented or block.
    c.upload(0x2000, 0, Mode::Auto, 5 * MS).unwrap();
    let out = c.on_frame(&[0x41, 0x00, 0x20, 0x00, 21, 0, 0, 0], 6 * MS);
    protocol(&out, 0x2000, 0, 0x0504_0005, "announced 21 bytes");
    c.upload(0x2000, 0, Mode::Block, 7 * MS).unwrap();
    let out = c.on_frame(&[0xC6, 0x00, 0x20, 0x00, 0, 1, 0, 0], 8 * MS);
    protocol(&out, 0x2000, 0, 0x0504_0005, "announced 256 bytes");
}

#[test]
fn block_upload_past_the_announced_size_is_aborted() {
    let cfg = ClientConfig {
        block_size: 4,
        ..ClientConfig::default()
    };
    let mut c = SdoClient::new(cfg);
    c.upload(0x2000, 0, Mode::Block, 0).unwrap();
    // 10 bytes announced (two segments, the second padded); the server keeps going.
    let out = c.on_frame(&[0xC6, 0x00, 0x20, 0x00, 10, 0, 0, 0], MS);
    assert_eq!(out.frames, vec![[0xA3, 0, 0, 0, 0, 0, 0, 0]]);
    assert!(c.on_frame(&[1, 1, 2, 3, 4, 5, 6, 7], 2 * MS).frames.is_empty());
    assert!(c.on_frame(&[2, 1, 2, 3, 4, 5, 6, 7], 3 * MS).frames.is_empty());
    let out = c.on_frame(&[3, 1, 2, 3, 4, 5, 6, 7], 4 * MS);
    protocol(&out, 0x2000, 0, 0x0607_0012, "announced 10 bytes but sent 21");
}

#[test]
fn block_upload_that_never_ends_meets_the_overall_deadline() {
    let cfg = ClientConfig {
        timeout_ns: 100 * MS,
        deadline_ns: Some(2_000 * MS),
        block_size: 4,
        ..ClientConfig::default()
    };
    let mut c = SdoClient::new(cfg);
    c.upload(0x2000, 0, Mode::Block, 0).unwrap();
    // No size; then sub-blocks of 4 segments every 40 ms, acknowledged, never the last.
    c.on_frame(&[0xC4, 0x00, 0x20, 0x00, 0, 0, 0, 0], 10 * MS);
    let mut t = 10 * MS;
    let mut acks = 0;
    let error = loop {
        for seq in 1..=4u8 {
            t += 10 * MS;
            let out = c.on_frame(&[seq, 0, 0, 0, 0, 0, 0, 0], t);
            if out.done.is_some() {
                let limit_ns = 2_000 * MS;
                assert_eq!(failed(&out, 0x2000, 0, 0x0504_0000), SdoError::Deadline { limit_ns });
                break;
            }
            assert!(out.done.is_none(), "{out:?}");
            acks += out.frames.len();
        }
        if !c.is_busy() {
            break t;
        }
        assert!(c.poll(t).done.is_none());
    };
    // Every frame came 10 ms after the last: only the overall deadline could end it.
    assert_eq!(error, 2_000 * MS);
    assert_eq!(acks, 49, "one ack per sub-block before the deadline");
}

#[test]
fn overall_deadline_holds_while_the_server_answers_in_time() {
    let cfg = ClientConfig {
        timeout_ns: 1_000 * MS,
        deadline_ns: Some(3_000 * MS),
        ..ClientConfig::default()
    };
    let mut c = SdoClient::new(cfg);
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    c.on_frame(&[0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0], 500 * MS);
    assert_eq!(c.next_deadline(), Some(1_500 * MS));
    let mut toggle = false;
    for t in [1_000, 1_500, 2_000, 2_500] {
        assert!(c.poll(t * MS).done.is_none());
        let out = c.on_frame(&segment(toggle), t * MS);
        assert!(out.done.is_none());
        toggle = !toggle;
    }
    assert_eq!(c.next_deadline(), Some(3_000 * MS), "the overall deadline comes first");
    let out = c.poll(3_000 * MS);
    assert_eq!(
        failed(&out, 0x2000, 0, 0x0504_0000),
        SdoError::Deadline { limit_ns: 3_000 * MS }
    );
    assert_eq!(
        SdoError::Deadline { limit_ns: 3_000 * MS }.to_string(),
        "SDO transfer not finished within its overall deadline of 3000 ms (the server kept it going)"
    );
}

#[test]
fn default_deadline_grows_with_the_size_written_or_announced() {
    let cfg = ClientConfig::default();
    // 10 s (10 timeouts of 1 s are no longer), plus 1 ms a byte.
    assert_eq!(cfg.default_deadline_ns(0), 10_000 * MS);
    assert_eq!(cfg.default_deadline_ns(5_000), 15_000 * MS);
    let slow = ClientConfig {
        timeout_ns: 3_000 * MS,
        ..cfg
    };
    assert_eq!(slow.default_deadline_ns(0), 30_000 * MS);
    let mut c = SdoClient::new(cfg);
    // Writing 5000 bytes segmented, each segment confirmed 30 ms after the last answer:
    // 715 segments would take 21 s; the deadline is 10 s + 5 s.
    c.download(0x1F50, 1, vec![0; 5_000], Mode::Segmented, 0).unwrap();
    let (mut t, mut toggle) = (MS, false);
    let out = c.on_frame(&[0x60, 0x50, 0x1F, 0x01, 0, 0, 0, 0], t);
    assert_eq!(out.frames.len(), 1);
    let out = loop {
        t += 30 * MS;
        let out = c.on_frame(&[if toggle { 0x30 } else { 0x20 }, 0, 0, 0, 0, 0, 0, 0], t);
        if out.done.is_some() {
            break out;
        }
        toggle = !toggle;
    };
    assert_eq!(t, 15_001 * MS);
    assert_eq!(
        failed(&out, 0x1F50, 1, 0x0504_0000),
        SdoError::Deadline { limit_ns: 15_000 * MS }
    );
    // An upload gets the size-based share once the server announces the size.
    c.upload(0x1F50, 1, Mode::Auto, 0).unwrap();
    c.on_frame(&[0x41, 0x50, 0x1F, 0x01, 0x20, 0x4E, 0, 0], MS); // 20000 bytes
    let mut t = MS;
    let mut toggle = false;
    while t < 29_000 * MS {
        t += 500 * MS;
        assert!(c.on_frame(&segment(toggle), t).done.is_none(), "at {t}");
        toggle = !toggle;
    }
    let out = c.poll(30_000 * MS);
    assert_eq!(
        failed(&out, 0x1F50, 1, 0x0504_0000),
        SdoError::Deadline { limit_ns: 30_000 * MS }
    );
}

#[test]
fn truncated_answers_are_protocol_errors() {
    let mut c = SdoClient::new(ClientConfig::default());
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    // `593#4B002000`: an expedited answer cut after the index.
    let out = c.on_frame(&[0x4B, 0x00, 0x20, 0x00], MS);
    protocol(&out, 0x2000, 0, 0x0504_0001, "4-byte answer (4B 00 20 00)");
    // Mid-transfer too: a short segment, and an empty frame.
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    c.on_frame(&[0x41, 0x00, 0x20, 0x00, 10, 0, 0, 0], MS);
    let out = c.on_frame(&[0x00, 1, 2], 2 * MS);
    protocol(&out, 0x2000, 0, 0x0504_0001, "3-byte answer");
    c.download(0x2000, 0, vec![1, 2], Mode::Auto, 0).unwrap();
    let out = c.on_frame(&[], MS);
    protocol(&out, 0x2000, 0, 0x0504_0001, "0-byte answer");
}

#[test]
fn wrong_command_specifiers_are_protocol_errors() {
    let mut c = SdoClient::new(ClientConfig::default());
    // An upload answered with a download response.
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    let out = c.on_frame(&[0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0], MS);
    protocol(&out, 0x2000, 0, 0x0504_0001, "unexpected initiate_download frame");
    // A command specifier CiA 301 does not define (scs 7).
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    let out = c.on_frame(&[0xE0, 0x00, 0x20, 0x00, 0, 0, 0, 0], MS);
    protocol(&out, 0x2000, 0, 0x0504_0001, "unexpected unknown frame");
    // A segmented upload answered with an initiate response again.
    c.upload(0x2000, 0, Mode::Auto, 0).unwrap();
    c.on_frame(&[0x41, 0x00, 0x20, 0x00, 10, 0, 0, 0], MS);
    let out = c.on_frame(&[0x41, 0x00, 0x20, 0x00, 10, 0, 0, 0], 2 * MS);
    protocol(&out, 0x2000, 0, 0x0504_0001, "unexpected initiate_upload frame");
}

#[test]
fn answers_are_judged_by_their_receive_time() {
    let cfg = ClientConfig {
        timeout_ns: 1_000 * MS,
        ..ClientConfig::default()
    };
    let mut c = SdoClient::new(cfg);
    // Received 4 ms after the request, handled much later (the caller was descheduled):
    // in time, because the client is given the receive time.
    c.upload(0x6041, 0, Mode::Auto, 0).unwrap();
    let out = c.on_frame(&[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0], 4 * MS);
    assert_eq!(
        out.done,
        Some(Completion::Uploaded {
            index: 0x6041,
            sub: 0,
            protocol: cotui::sdo::Protocol::Expedited,
            data: vec![0x37, 0x02],
        })
    );
    // Received after the answer was due: a timeout, and the late answer is not taken.
    c.upload(0x6041, 0, Mode::Auto, 0).unwrap();
    let out = c.on_frame(&[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0], 1_000 * MS);
    assert_eq!(failed(&out, 0x6041, 0, 0x0504_0000), SdoError::Timeout);
    // The request reached the bus late (its echo says when): the answer is due a timeout after that.
    c.upload(0x6041, 0, Mode::Auto, 0).unwrap();
    c.on_sent(300 * MS);
    assert_eq!(c.next_deadline(), Some(1_300 * MS));
    assert!(c.poll(1_200 * MS).done.is_none());
    assert_eq!(failed(&c.poll(1_300 * MS), 0x6041, 0, 0x0504_0000), SdoError::Timeout);
    assert_eq!(c.next_deadline(), None);
}
