//! Unit tests of the diagnosis: frames in, `node kind status count` out.

use super::Diagnoser;
use super::timeline::MS;
use crate::decode::Decoder;
use crate::frame::Frame;
use crate::od::Dictionary;

/// Runs `frames` (ms, COB-ID, hex data) through a decoder and a diagnoser; returns
/// `node kind status count` per incident.
fn run(frames: &[(u64, u32, &str)]) -> Vec<String> {
    let mut dec = Decoder::new(Dictionary::default(), Vec::new());
    let mut diag = Diagnoser::new(|n| dec.dictionary(n));
    for (ms, id, data) in frames {
        let bytes: Vec<u8> = (0..data.len() / 2)
            .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).unwrap())
            .collect();
        let mut f = Frame::classic(*id, &bytes);
        f.ts_ns = ms * MS;
        let d = dec.decode(&f);
        diag.frame(&f, "can0", &d);
        for t in dec.take_transactions() {
            diag.transaction(&t);
        }
    }
    diag.finish()
        .iter()
        .map(|i| {
            let node = i.node.map_or("-".into(), |n| n.to_string());
            format!("{node} {} {} {}", i.problem.as_str(), i.status.as_str(), i.count)
        })
        .collect()
}

fn heartbeats(node: u32, from_ms: u64, to_ms: u64, state: &'static str) -> Vec<(u64, u32, &'static str)> {
    (from_ms..to_ms)
        .step_by(100)
        .map(|t| (t, 0x700 + node, state))
        .collect()
}

#[test]
fn a_heartbeat_that_has_not_started_since_boot_up_did_not_stop() {
    // 0x1017 = 100 ms is written right after the boot-up; heartbeats start 500 ms later.
    let mut f = vec![
        (0, 0x701, "00"),
        (10, 0x601, "2B17100064000000"),
        (11, 0x581, "6017100000000000"),
    ];
    f.extend(heartbeats(1, 500, 1500, "05"));
    assert!(run(&f).is_empty(), "{:?}", run(&f));
    // Once it beats, a gap is a silence.
    f.extend(heartbeats(1, 2500, 3000, "05"));
    assert_eq!(run(&f), ["1 silent_back warning 1"]);
}

#[test]
fn emcy_right_before_a_fault_is_its_cause_not_a_separate_incident() {
    // Node 2 reads as a CiA 402 device (0x1000 = 0x00020192): TPDO1 starts with the statusword.
    let f = [
        (0, 0x602, "4000100000000000"),
        (1, 0x582, "4300100092010200"),
        (100, 0x182, "3702"),
        (200, 0x082, "2171010000000000"),
        (201, 0x182, "0800"),
        (300, 0x202, "8000"),
        (301, 0x182, "4002"),
        (400, 0x182, "3702"),
    ];
    assert_eq!(run(&f), ["2 drive_fault recovered 1"]);
}

/// Like [`run`], with capture-clock ticks: `(ms, 0xFFFF_FFFF, "")` is a tick at `ms`.
fn run_ticked(frames: &[(u64, u32, &str)]) -> Vec<String> {
    let mut dec = Decoder::new(Dictionary::default(), Vec::new());
    let mut diag = Diagnoser::new(|n| dec.dictionary(n));
    for (ms, id, data) in frames {
        if *id == u32::MAX {
            diag.tick(ms * MS);
            continue;
        }
        let bytes: Vec<u8> = (0..data.len() / 2)
            .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).unwrap())
            .collect();
        let mut f = Frame::classic(*id, &bytes);
        f.ts_ns = ms * MS;
        let d = dec.decode(&f);
        diag.frame(&f, "can0", &d);
    }
    diag.incidents()
        .iter()
        .map(|i| {
            let node = i.node.map_or("-".into(), |n| n.to_string());
            format!("{node} {} {} {}", i.problem.as_str(), i.status.as_str(), i.count)
        })
        .collect()
}

#[test]
fn ticks_on_a_quiet_bus_find_a_silent_node_and_later_frames_undo_it() {
    let mut f = heartbeats(5, 0, 1000, "05");
    // The clock passes the deadline with no frame: silent so far.
    f.push((1500, u32::MAX, ""));
    assert_eq!(run_ticked(&f), ["5 silent open 1"]);
    // It beats again: it was a silence that ended.
    f.extend(heartbeats(5, 1600, 2000, "05"));
    assert_eq!(run_ticked(&f), ["5 silent_back warning 1"]);
    // A tick that runs ahead of the frames (a late delivery) is undone by them.
    let mut f = heartbeats(5, 0, 500, "05");
    f.push((560, u32::MAX, ""));
    f.extend(heartbeats(5, 500, 1000, "05"));
    let got = run_ticked(&f);
    assert!(got.iter().all(|g| !g.contains("silent open")), "{got:?}");
}

#[test]
fn boot_ups_with_equal_times_are_not_a_duplicate_id() {
    // Logs without timestamps give every frame time 0: two boot-ups say nothing there.
    let f = [(0, 0x000, "8100"), (0, 0x705, "00"), (0, 0x705, "00")];
    assert!(run(&f).is_empty(), "{:?}", run(&f));
    let f = [(0, 0x000, "8100"), (10, 0x705, "00"), (30, 0x705, "00")];
    assert_eq!(run(&f), ["5 duplicate_id open 1"]);
}

/// `run` of `frames`, only the second-master incidents.
fn masters(frames: &[(u64, u32, &str)]) -> Vec<String> {
    run(frames)
        .into_iter()
        .filter(|i| i.contains("second_master"))
        .collect()
}

/// A segmented upload of 0x1008 from node 2: initiate, answer, segment t0, answer t0.
const UPLOAD: [(u64, u32, &str); 4] = [
    (0, 0x602, "4008100000000000"),
    (1, 0x582, "4108100010000000"),
    (2, 0x602, "6000000000000000"),
    (3, 0x582, "00434F5455492044"),
];

#[test]
fn a_segment_toggle_bit_repeated_at_once_is_a_second_client() {
    // Right after the node answered the segment with toggle bit 0, another one with
    // toggle bit 0: only a second client's transfer explains it.
    let mut f = UPLOAD.to_vec();
    f.extend([(5, 0x602, "6000000000000000"), (6, 0x582, "8008100000000305")]);
    assert_eq!(masters(&f), ["2 second_master warning 1"]);
    // Two segment requests with one toggle bit before any answer, 4 ms apart.
    let mut f = UPLOAD[..3].to_vec();
    f.extend([(6, 0x602, "6000000000000000"), (7, 0x582, "00434F5455492044")]);
    assert_eq!(masters(&f), ["2 second_master warning 1"]);
}

#[test]
fn a_segment_retried_after_a_timeout_or_alternating_bits_are_one_client() {
    // The toggle bit alternates: t0, answer, t1, answer (last).
    let mut f = UPLOAD.to_vec();
    f.extend([(4, 0x602, "7000000000000000"), (5, 0x582, "1D55492D31000000")]);
    assert!(masters(&f).is_empty(), "{:?}", run(&f));
    // The segment request is repeated 300 ms later, unanswered: a retry, not a second client.
    let mut f = UPLOAD[..3].to_vec();
    f.extend([
        (300, 0x602, "6000000000000000"),
        (301, 0x582, "00434F5455492044"),
        (302, 0x602, "7000000000000000"),
        (303, 0x582, "1D55492D31000000"),
    ]);
    assert!(masters(&f).is_empty(), "{:?}", run(&f));
    // A new transfer starts the toggle bit over.
    let mut f = UPLOAD.to_vec();
    f.extend([(4, 0x602, "8008100000000000"), (5, 0x602, "4008100000000000")]);
    f.extend([(6, 0x582, "4108100010000000"), (7, 0x602, "6000000000000000")]);
    assert!(masters(&f).is_empty(), "{:?}", run(&f));
}

#[test]
fn nmt_start_undone_at_once_is_a_second_master_a_selection_is_not() {
    // Start node 3, reset node 3 10 ms later: two masters disagree.
    let f = [(0, 0x000, "0103"), (10, 0x000, "8103")];
    assert_eq!(masters(&f), ["3 second_master warning 1"]);
    // Start node 3, then pre-operational for all nodes 5 ms later.
    let f = [(0, 0x000, "0103"), (5, 0x000, "8000")];
    assert_eq!(masters(&f), ["3 second_master warning 1"]);
    // Start all, then keep node 3 stopped: one master choosing which nodes run.
    let f = [(0, 0x000, "0100"), (5, 0x000, "0203")];
    assert!(masters(&f).is_empty());
    // Pre-operational then start (re-configuration), and a stop 30 ms after the start.
    let f = [(0, 0x000, "8003"), (2, 0x000, "0103"), (32, 0x000, "0203")];
    assert!(masters(&f).is_empty());
}

#[test]
fn a_reset_asked_for_is_not_an_unexpected_reboot() {
    let mut f = heartbeats(3, 0, 500, "05");
    f.push((550, 0x000, "8203"));
    f.push((560, 0x703, "00"));
    assert!(run(&f).is_empty(), "{:?}", run(&f));
    let mut f = heartbeats(3, 0, 500, "05");
    f.push((560, 0x703, "00"));
    assert_eq!(run(&f), ["3 rebooted warning 1"]);
}
