//! Lines that would put something wrong on the bus are refused before anything is sent,
//! with a message that says why (exit status 1): reserved COB-IDs, a mapping length that is
//! not the object's, an FD flags digit no flag uses, an LSS range upside down.

use crate::run::cotui;
use cotui::command::parse_command;

/// `cotui ARGS` is refused (exit 1) with a message containing `why`, and nothing was sent.
fn refused_cli(args: &[&str], why: &str) {
    let (rc, out, err) = cotui(args);
    assert_eq!(rc, 1, "{args:?}: {out}{err}");
    assert!(err.contains(why), "{args:?}: {err}");
    assert!(!out.contains("sent") && !out.contains("mapped"), "{args:?}: {out}");
}

/// [`refused_cli`], and the palette's parse of the same line refuses it alike.
fn refused(args: &[&str], why: &str) {
    refused_cli(args, why);
    // The palette takes the same line (without IFACE) and refuses it alike.
    let line: Vec<String> = args
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 1)
        .map(|(_, a)| {
            if a.contains(' ') {
                format!("\"{a}\"")
            } else {
                a.to_string()
            }
        })
        .collect();
    let e = parse_command(&line.join(" ")).unwrap_err();
    assert!(e.to_string().contains(why), "{line:?}: {e}");
}

#[test]
fn reserved_cob_ids_are_refused_with_their_owner() {
    let map = |cob: &'static str| ["pdo", "demo", "2", "map", "tpdo1", "0x6041", "--cob-id", cob];
    refused(&map("0x602"), "--cob-id 0x602 is node 2's SDO request");
    refused(&map("0x080"), "--cob-id 0x080 is SYNC");
    refused(&map("0x5A5"), "node 37's SDO response");
    refused(&map("0x703"), "node 3's heartbeat");
    refused(&map("0x081"), "node 1's EMCY");
    refused(&map("0x100"), "TIME");
    refused(&map("0x7E5"), "LSS");
    let sync = |cob: &'static str| ["sync", "demo", "--period", "10", "--count", "1", "--cob-id", cob];
    refused(&sync("0x602"), "--cob-id 0x602 is node 2's SDO request");
    refused(&sync("0x000"), "must be an 11-bit COB-ID");
    // SYNC's own COB-ID (not listening for the demo's SYNC producer), a free one, and
    // --force go out.
    for args in [
        [&sync("0x080")[..], &["--listen", "0"]].concat(),
        sync("0x1A0").to_vec(),
        [&sync("0x602")[..], &["--force"]].concat(),
    ] {
        let (rc, out, err) = cotui(&args);
        assert_eq!(rc, 0, "{args:?}: {err}");
        assert!(out.contains("1 frame sent"), "{out}");
    }
    let (rc, out, err) = cotui(&["pdo", "demo", "2", "map", "tpdo1", "0x6041", "--cob-id", "0x1A2"]);
    assert_eq!(rc, 0, "{err}");
    assert!(out.contains("COB-ID 0x1A2"), "{out}");
}

#[test]
fn a_mapping_length_other_than_the_objects_type_is_refused() {
    refused_cli(
        &["pdo", "demo", "2", "map", "tpdo1", "0x6041/8"],
        "0x6041:00 Statusword cannot be mapped into TPDO1: 8 bits given, but the node's dictionary (aimotor) types it U16, 16 bits",
    );
    refused_cli(&["pdo", "demo", "2", "map", "tpdo1", "0x6041/32"], "32 bits given");
    let (rc, out, err) = cotui(&["pdo", "demo", "2", "map", "tpdo1", "0x6041/16", "--dry-run"]);
    assert_eq!(rc, 0, "{out}{err}");
}

#[test]
fn send_refuses_fd_flags_no_flag_uses_and_says_what_0x_and_blanks_are() {
    refused(&["send", "demo", "123##F00"], "CAN FD flags digit `F` is not 0..7");
    refused(&["send", "demo", "123##800"], "CAN FD flags digit `8` is not 0..7");
    refused(
        &["send", "demo", "0x123#00"],
        "the CAN id is hex without 0x, as cansend takes it: `123#00`",
    );
    let (rc, out, err) = cotui(&["send", "demo", "123##700"]);
    assert_eq!((rc, out.trim()), (0, "123##700: 1 frame sent"), "{err}");
    // Blanks around a quoted frame are a quoting artifact, not CAN XL.
    let (rc, out, err) = cotui(&["send", "demo", "  123#00 "]);
    assert_eq!((rc, out.trim()), (0, "123#00: 1 frame sent"), "{err}");
}

#[test]
fn lss_identify_refuses_a_range_upside_down_and_each_service_its_words() {
    refused(
        &["lss", "demo", "identify", "1", "2", "5", "3", "0", "9"],
        "REV_LO 0x00000005 is above REV_HI 0x00000003",
    );
    refused(
        &["lss", "demo", "identify", "1", "2", "0", "3", "9", "8"],
        "SER_LO 0x00000009 is above SER_HI",
    );
    refused(&["lss", "demo", "store", "x"], "unexpected argument 'x' found");
    refused(&["lss", "demo", "select", "1", "2", "3"], "<SERIAL>");
}
