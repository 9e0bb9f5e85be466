//! `cotui gateway demo --stdio`: canopend's lines in, canopend's answers out.

use crate::client::Gateway;
use base64::Engine;

#[test]
fn reads_of_every_kind_and_an_abort() {
    let mut g = Gateway::start(&[]);
    let c = &mut g.client;
    assert_eq!(c.ask("[1] 2 read 0x1017 0 u16"), "[1] 500");
    assert_eq!(c.ask("[2] 2 r 0x1017 0 x16"), "[2] 0x01F4");
    assert_eq!(c.ask("[3] 2 r 0x1017 0"), "[3] F4 01", "no type: hex bytes");
    // Segmented upload of a 38-byte string.
    assert_eq!(
        c.ask("[4] 3 read 0x1008 0 vs"),
        "[4] \"cotui simulated Syn-tron-like DS servo\""
    );
    assert_eq!(c.ask("[5] set node 2"), "[5] OK");
    assert_eq!(c.ask("[6] r 0x1000 0 u32"), "[6] 131474");
    assert_eq!(
        c.ask("[7] r 0x2345 0 u8"),
        "[7] ERROR:0x06020000 #Object does not exist in the object dictionary."
    );
    assert_eq!(
        c.ask("[8] r 0x1017 0 u8"),
        "[8] F4 01",
        "a length that does not fit: hex"
    );
    // Block upload of the 200-byte domain, in base64.
    assert_eq!(c.ask("[9] set sdo_block 1"), "[9] OK");
    let want: Vec<u8> = (0..200u32).map(|i| (i * 7 + 2) as u8).collect();
    let b64 = base64::engine::general_purpose::STANDARD.encode(&want);
    assert_eq!(c.ask("[10] r 0x2000 0 d"), format!("[10] {b64}"));
    assert_eq!(
        c.ask("[11] 3 r 0x1008 0 vs"),
        "[11] \"cotui simulated Syn-tron-like DS servo\""
    );
    // No answer within the timeout: the client's abort, as canopend answers it.
    assert_eq!(c.ask("[12] set sdo_timeout 50"), "[12] OK");
    assert_eq!(
        c.ask("[13] 9 r 0x1000 0"),
        "[13] ERROR:0x05040000 #SDO protocol timed out."
    );
    c.send(b"[14] help\r\n");
    let help = c.text();
    assert!(help.iter().any(|l| l.contains("r[ead] INDEX SUB [TYPE]")), "{help:?}");
    c.send(b"[15] help datatype\r\n");
    assert!(c.text().iter().any(|l| l.contains("x8 x16 x32 x64")));
}

#[test]
fn without_allow_writes_write_nmt_and_lss_are_refused_and_the_value_stays() {
    let mut g = Gateway::start(&[]);
    let c = &mut g.client;
    let refused = "ERROR:100 #Request not supported. the gateway is read-only";
    for (n, line) in [
        "2 write 0x1017 0 u16 1000",
        "2 start",
        "0 reset node",
        "lss_switch_glob 1",
        "lss_inquire_addr",
    ]
    .iter()
    .enumerate()
    {
        let a = c.ask(&format!("[{n}] {line}"));
        assert!(a.starts_with(&format!("[{n}] {refused}")), "{line}: {a}");
    }
    assert_eq!(c.ask("[9] 2 r 0x1017 0 u16"), "[9] 500", "nothing was written");
}

#[test]
fn writes_read_back_and_nmt_changes_are_notified() {
    let mut g = Gateway::start(&["--allow-writes", "--notify"]);
    let c = &mut g.client;
    assert_eq!(c.ask("[1] 2 write 0x1017 0 u16 1000"), "[1] OK");
    assert_eq!(c.ask("[2] 2 read 0x1017 0 u16"), "[2] 1000");
    assert_eq!(c.ask("[3] 2 w 0x6060 0 i8 -3"), "[3] OK");
    assert_eq!(c.ask("[4] 2 r 0x6060 0 i8"), "[4] -3");
    // Segmented and block downloads of 50 bytes, read back.
    let data: Vec<u8> = (0..50).collect();
    let b64 = base64::engine::general_purpose::STANDARD.encode(&data);
    assert_eq!(c.ask(&format!("[5] 2 w 0x2000 0 d {b64}")), "[5] OK");
    assert_eq!(c.ask("[6] 2 r 0x2000 0 d"), format!("[6] {b64}"));
    assert_eq!(c.ask("[7] set sdo_block 1"), "[7] OK");
    assert_eq!(c.ask("[8] 3 w 0x2000 0 hex 01 02 03 04 05 06 07 08 09"), "[8] OK");
    assert_eq!(c.ask("[9] 3 r 0x2000 0"), "[9] 01 02 03 04 05 06 07 08 09");
    assert_eq!(
        c.ask("[10] 2 w 0x1008 0 vs \"read only\""),
        "[10] ERROR:0x06010002 #Attempt to write a read only object."
    );
    // The demo's master starts every node; then NMT from the gateway.
    c.notice("Remote node ID = 0x02 (index = 0): NMT state changed to: \"operational\" (5)");
    c.notices.clear();
    assert_eq!(c.ask("[11] 2 preop"), "[11] OK");
    c.notice("Remote node ID = 0x02 (index = 0): NMT state changed to: \"pre-operational\" (127)");
    c.notices.clear();
    assert_eq!(c.ask("[12] 0 start"), "[12] OK");
    c.notice("Remote node ID = 0x02 (index = 0): NMT state changed to: \"operational\" (5)");
    c.notices.clear();
    assert_eq!(c.ask("[13] 2 reset node"), "[13] OK");
    c.notice("Remote node ID = 0x02 (index = 0): NMT state changed to: \"initializing\" (0)");
    // `log` gives the notifications kept since the last `log`.
    c.send(b"[14] log\r\n");
    let log = c.text();
    assert!(log.iter().any(|l| l.contains("NMT state changed")), "{log:?}");
}

#[test]
fn bad_lines_get_a_clear_error_and_the_gateway_goes_on() {
    let mut g = Gateway::start(&["--allow-writes"]);
    let c = &mut g.client;
    assert_eq!(
        c.ask("[1] 2 frobnicate"),
        "[1] ERROR:100 #Request not supported. unknown command `frobnicate` (`help` lists them)"
    );
    let a = c.ask("[2] 2 read 0x1017 0 u7");
    assert!(
        a.starts_with("[2] ERROR:101 #Syntax error. unknown data type `u7`"),
        "{a}"
    );
    let a = c.ask("[3] 2 write 0x1017 0 u8 256");
    assert_eq!(a, "[3] ERROR:101 #Syntax error. 256 does not fit 8 bits (0..255)");
    let a = c.ask("[4] 2 write 0x1017 0 i16 -40000");
    assert!(a.starts_with("[4] ERROR:101"), "{a}");
    let a = c.ask("[5] 2 write 0x1008 0 vs two words");
    assert!(a.contains("between double quotes"), "{a}");
    assert!(c.ask("[6] 200 read 0x1017 0").starts_with("[6] ERROR:107"));
    assert!(
        c.ask("[7] read 0x1017 0")
            .starts_with("[7] ERROR:105 #No default node set.")
    );
    // A 1 MB line: refused, skipped to its end, with its sequence number.
    let mut long = b"[8] 2 w 0x2000 0 hex ".to_vec();
    long.extend(std::iter::repeat_n(b'A', 1 << 20));
    long.extend(b"\r\n");
    c.send(&long);
    let a = c.answer_of(8);
    assert_eq!(
        a,
        "[8] ERROR:101 #Syntax error. the line is longer than 262144 bytes (skipped to its end)"
    );
    // Garbled bytes.
    c.send(b"[9] 2 r \xff\xfe\x00\x01\r\n");
    assert_eq!(
        c.answer_of(9),
        "[9] ERROR:101 #Syntax error. the line is not text (not UTF-8)"
    );
    c.send(b"\x00\x13garbage\r\n");
    assert!(c.answer_of(0).starts_with("[0] ERROR:101"));
    // A line without a sequence number, an empty line, a comment.
    c.send(b"2 read 0x1017 0\r\n");
    assert!(c.answer_of(0).contains("a request starts with [SEQUENCE]"));
    c.send(b"\r\n# comment\r\n");
    assert_eq!(c.next_raw(), "\r\n");
    assert_eq!(c.next_raw(), "\r\n");
    // Still serving.
    assert_eq!(c.ask("[10] 2 r 0x1017 0 u16"), "[10] 500");
}

#[test]
fn listen_only_sends_nothing_even_with_allow_writes() {
    let mut g = Gateway::start(&["--listen-only", "--allow-writes", "--notify"]);
    let c = &mut g.client;
    for (n, line) in ["2 r 0x1017 0 u16", "2 w 0x1017 0 u16 1", "0 start", "lss_get_node"]
        .iter()
        .enumerate()
    {
        let a = c.ask(&format!("[{n}] {line}"));
        assert!(
            a.starts_with(&format!(
                "[{n}] ERROR:102 #Request not processed due to internal state. the gateway is listen-only"
            )),
            "{line}: {a}"
        );
    }
    // It still hears the bus.
    c.notice("NMT state changed to: \"operational\"");
}

#[test]
fn without_notify_the_notifications_wait_for_log() {
    let mut g = Gateway::start(&["--allow-writes"]);
    let c = &mut g.client;
    // The demo starts its nodes 0.8 s after power-on: ask until `log` has that.
    let mut seq = 0;
    let log = loop {
        seq += 1;
        assert_eq!(c.ask(&format!("[{seq}] 2 r 0x1017 0 u16")), format!("[{seq}] 500"));
        seq += 1;
        c.send(format!("[{seq}] log\r\n").as_bytes());
        let log = c.text();
        if log
            .iter()
            .any(|l| l.contains("0x03 (index = 1): NMT state changed to: \"operational\" (5)"))
        {
            break log;
        }
    };
    assert!(
        log.iter().all(|l| l.contains("NMT state changed") || l.is_empty()),
        "{log:?}"
    );
    assert!(
        c.notices.iter().all(String::is_empty),
        "no line besides the answers: {:?}",
        c.notices
    );
}
