//! The JSON contract, one snapshot per kind of record: the frame record with each kind's
//! object (`nmt`, `heartbeat`, `sync`, `time`, `emcy`, `lss`, `sdo`, `pdo`, `vendor_sdo`,
//! `error`), CiA 402 values, SDO transactions, the summary, events and diagnose incidents.
//! The snapshots hold the exact text `cotui` prints: key names, key order, number forms
//! and escaping are all pinned (the README documents the names).

/// Runs `cotui ARGS -` with `log` on stdin; its stdout.
fn cotui(args: &[&str], log: &str) -> String {
    let args: Vec<&str> = args.iter().copied().chain(["-"]).collect();
    let out = crate::run::cotui(&args, Some(log));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// The frame records of `log`.
fn frames(log: &str) -> String {
    cotui(&["decode", "--format", "jsonl"], log)
}

/// A fixture log.
fn fixture(path: &str) -> String {
    std::fs::read_to_string(format!("{}/tests/fixtures/{path}", env!("CARGO_MANIFEST_DIR"))).expect("fixture")
}

/// The lines of `out` that carry the object `key`.
fn with_object(out: &str, key: &str) -> String {
    let tag = format!("\"{key}\":{{");
    out.lines()
        .filter(|l| l.contains(&tag))
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn nmt() {
    insta::assert_snapshot!(frames(
        "(1.0) can0 000#8100\n(1.1) can0 000#0105\n(1.2) can0 000#0905\n(1.3) can0 000#01\n"
    ));
}

#[test]
fn heartbeat() {
    // Boot-up, heartbeat, guarding request (RTR), guarding response with toggle, a bad DLC.
    insta::assert_snapshot!(frames(
        "(1.0) can0 705#00\n(1.1) can0 705#05\n(1.2) can0 705#R\n(1.3) can0 705#FF\n(1.4) can0 705#0500\n"
    ));
}

#[test]
fn sync() {
    insta::assert_snapshot!(frames("(1.0) can0 080#\n(1.1) can0 080#07\n"));
}

#[test]
fn time() {
    insta::assert_snapshot!(frames("(1.0) can0 100#0000000000A0\n(1.1) can0 100#E05C2303D22F\n"));
}

#[test]
fn emcy() {
    insta::assert_snapshot!(frames(
        "(1.0) can0 085#1081100000000000\n(1.1) can0 085#00FF81AABBCCDDEE\n"
    ));
    // Manufacturer bytes decoded through a profile's layout (`mfr_fields`).
    let out = cotui(
        &[
            "decode",
            "--format",
            "jsonl",
            "--profile",
            "3=tests/fixtures/profiles/example.json",
        ],
        &fixture("diagnose/profile_emcy.log"),
    );
    insta::assert_snapshot!("emcy_profile", with_object(&out, "emcy"));
}

#[test]
fn lss() {
    insta::assert_snapshot!(with_object(&frames(&fixture("cia301_mix.log")), "lss"));
}

#[test]
fn sdo_frames() {
    insta::assert_snapshot!(with_object(&frames(&fixture("cia301_mix.log")), "sdo"));
}

/// A block download of 19 bytes with CRC, and a command byte CiA 301 does not define.
const BLOCK: &str = "(1.00) can0 605#C600200013000000
(1.01) can0 585#A400200003000000
(1.02) can0 605#0131323334353637
(1.03) can0 605#0238393A3B3C3D3E
(1.04) can0 605#833F404142430000
(1.05) can0 585#A203030000000000
(1.06) can0 605#C9ABCD0000000000
(1.07) can0 585#A100000000000000
(1.08) can0 605#E000000000000000
";

#[test]
fn sdo_block_frames() {
    insta::assert_snapshot!(frames(BLOCK));
}

#[test]
fn sdo_transactions() {
    let mut log = fixture("cia301_mix.log");
    log.push_str(BLOCK);
    insta::assert_snapshot!(cotui(&["decode", "--format", "jsonl", "--transactions"], &log));
}

#[test]
fn pdo_signals() {
    insta::assert_snapshot!(with_object(&frames(&fixture("pdo_learning.log")), "pdo"));
}

#[test]
fn cia402_values() {
    // Controlword and mode of operation written, statusword read: the values are named.
    let log = "(1.0) can0 602#2B40600006000000
(1.1) can0 582#6040600000000000
(1.2) can0 602#2F60600003000000
(1.3) can0 582#6060600000000000
(1.4) can0 602#4041600000000000
(1.5) can0 582#4B41600037020000
";
    insta::assert_snapshot!("cia402_frames", frames(log));
    insta::assert_snapshot!(
        "cia402_transactions",
        cotui(&["decode", "--format", "jsonl", "--transactions"], log)
    );
}

#[test]
fn error_frames() {
    insta::assert_snapshot!(with_object(&frames(&fixture("node_liveness.log")), "error"));
}

#[test]
fn vendor_sdo() {
    let out = cotui(
        &["decode", "--format", "jsonl", "--profile", "1=syntron-ds"],
        &fixture("seeds/syntron-ds.log"),
    );
    insta::assert_snapshot!(with_object(&out, "vendor_sdo"));
}

#[test]
fn frame_record_escaping_and_flags() {
    // An interface name with control characters, extended, RTR, FD and sent frames.
    let log = "(1.0) c\\x08n0 18FF0001#0102\n(1.1) can0 123#R\n(1.2) can0 123##1AABB\n(1.3) can0 080#\n";
    let log = log.replace("\\x08", "\u{8}");
    insta::assert_snapshot!(frames(&log));
}

#[test]
fn summary() {
    insta::assert_snapshot!(cotui(
        &["decode", "--format", "jsonl", "--summary"],
        &fixture("cia301_mix.log")
    ));
}

#[test]
fn events() {
    insta::assert_snapshot!(cotui(
        &["decode", "--format", "jsonl", "--events"],
        &fixture("node_liveness.log")
    ));
}

#[test]
fn diagnose_incidents() {
    insta::assert_snapshot!(cotui(
        &["diagnose", "--format", "jsonl"],
        &fixture("diagnose/drive_fault.log")
    ));
}
