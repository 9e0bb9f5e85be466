//! AQMD2405BLS-MT-2 (manual 001, section 7 CANopen): the manual's CAN frames and tables through
//! `cotui decode --format jsonl --profile 1=aqmd2405`. Frames are in
//! `tests/fixtures/seeds/aqmd2405.log` (line numbers below) with the manual's lines as comments.

mod seed_common;
use seed_common::{decode, fixture, label_has, sdo, signal};
use serde_json::json;

fn frames() -> seed_common::Frames {
    decode(&["1=aqmd2405"], &fixture("aqmd2405.log"))
}

#[test]
fn nmt_commands_boot_up_and_heartbeat() {
    let f = frames();
    // 7.5.2: "0x01 start", "0x02 stop", "0x80 pre-operational", "0x81 reset node", "0x82 reset communication"
    for (line, data, command) in [
        (3, "0101", "start"),
        (4, "0201", "stop"),
        (5, "8001", "pre_operational"),
        (6, "8101", "reset_node"),
        (7, "8201", "reset_communication"),
    ] {
        let x = f.at(line, 0x000, data);
        assert_eq!(x["kind"], "nmt");
        assert_eq!(x["nmt"], json!({"command": command, "target": 1}));
    }
    // "0x00 boot-up", "0x04 stopped", "0x05 operational", "0x7F pre-operational"
    for (line, data, state) in [
        (9, "00", "boot_up"),
        (10, "04", "stopped"),
        (11, "05", "operational"),
        (12, "7F", "pre_operational"),
    ] {
        let x = f.at(line, 0x701, data);
        assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("heartbeat"), Some(1)));
        assert_eq!(x["heartbeat"]["state"], state);
    }
}

#[test]
fn rpdo_speed_command_example() {
    let f = frames();
    // 7.5.4: "0x201 03 88 13 00 F4 01 00 00": 0x2000 = 0x03, 0x2001 = 0x1388 = 5000, 0x2002 = 0, 0x2003 = 0x01F4 = 500
    let x = f.at(15, 0x201, "03881300F4010000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("rpdo"), Some(1)));
    assert_eq!(signal(x, 0x2000, 0), (json!(3), "3 (Run at target speed)".to_string()));
    assert_eq!(signal(x, 0x2001, 0).0, json!(5000));
    assert_eq!(signal(x, 0x2002, 0).0, json!(0));
    assert_eq!(signal(x, 0x2003, 0).0, json!(500));
    assert_eq!(x["pdo"]["mapping_source"], "profile aqmd2405");
    // "0x201 00 F4 01 00 00 00 00 00": command 0x00, speed 0x01F4 = 500
    let x = f.at(17, 0x201, "00F4010000000000");
    assert_eq!(signal(x, 0x2000, 0).0, json!(0));
    assert_eq!(signal(x, 0x2001, 0).0, json!(500));
    // "0x201 01 88 13 00 00 00 00 00": command 0x01, speed 5000
    let x = f.at(18, 0x201, "0188130000000000");
    assert_eq!(
        (signal(x, 0x2000, 0).0, signal(x, 0x2001, 0).0),
        (json!(1), json!(5000))
    );
    // "0x201 11 00 00 00 00 00 00 00": command 0x11
    assert_eq!(signal(f.at(19, 0x201, "1100000000000000"), 0x2000, 0).0, json!(0x11));
}

#[test]
fn tpdo_save_and_sync() {
    let f = frames();
    // TPDO1 = 0x2101 (PWM duty, 0.1 %) + 0x2105 (32 bit)
    let x = f.at(22, 0x181, "F40139300000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("tpdo"), Some(1)));
    assert_eq!(signal(x, 0x2101, 0), (json!(500), "50 %".to_string()));
    assert_eq!(signal(x, 0x2105, 0).0, json!(12345));
    // "0x1010 ... write "save" (0x65766173)"
    let x = f.at(24, 0x601, "2310100273617665");
    sdo(x, "sdo_rx", 1, 0x1010, 2, Some(0x6576_6173));
    assert!(
        x["sdo"]["value_text"]
            .as_str()
            .unwrap()
            .ends_with("(\"save\" signature)"),
        "{x}"
    );
    sdo(f.at(25, 0x581, "6010100200000000"), "sdo_tx", 1, 0x1010, 2, None);
    // event time 0x01F4 = 500 ms
    let x = f.at(26, 0x601, "2B001805F4010000");
    sdo(x, "sdo_rx", 1, 0x1800, 5, Some(500));
    assert_eq!(x["sdo"]["value_text"], "500 ms");
    // 7.5.5: "SYNC 0x80, no data"
    let x = f.at(28, 0x080, "");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("sync"), None));
}

#[test]
fn vendor_emcy_codes() {
    let f = frames();
    // 7.5.6: vendor codes 2210, 2310, 3110, 3120, 4210
    for (line, data, code, text) in [
        (30, "1022010000000000", 0x2210, "Over-current inside the driver"),
        (31, "1023030000000000", 0x2310, "Continuous over-current (motor output)"),
        (32, "1031050000000000", 0x3110, "Supply over-voltage"),
        (33, "2031050000000000", 0x3120, "Supply under-voltage"),
        (34, "1042090000000000", 0x4210, "Driver over-temperature"),
    ] {
        let x = f.at(line, 0x081, data);
        assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("emcy"), Some(1)));
        assert_eq!(x["emcy"]["code"], code);
        assert_eq!(x["emcy"]["text"], text);
    }
}

#[test]
fn communication_objects_load_signature_and_modbus_mirror() {
    let f = frames();
    // 7.6.3: "0x2201 CAN node ID 1~127"
    let x = f.at(36, 0x601, "2F01220005000000");
    sdo(x, "sdo_rx", 1, 0x2201, 0, Some(5));
    label_has(x, &["CAN node ID = 5"]);
    // "0x2202 CAN bit rate ... 7: 1Mbps"
    assert_eq!(f.at(37, 0x601, "2F02220007000000")["sdo"]["value_text"], "7 (1 Mbit/s)");
    // read back: "5: 500kbps"
    let x = f.at(39, 0x581, "4F02220005000000");
    sdo(x, "sdo_tx", 1, 0x2202, 0, Some(5));
    assert_eq!(x["sdo"]["value_text"], "5 (500 kbit/s)");
    // 7.5.7: "0x1011 ... "load" (0x64616f6c)"
    let x = f.at(41, 0x601, "231110016C6F6164");
    sdo(x, "sdo_rx", 1, 0x1011, 1, Some(0x6461_6F6C));
    assert!(
        x["sdo"]["value_text"]
            .as_str()
            .unwrap()
            .ends_with("(\"load\" signature)"),
        "{x}"
    );
    // 7.4: Modbus 0x0000-0x0FFF -> 0x4000 + REG: register 0x0121 (node ID) = 1
    let x = f.at(44, 0x581, "4B21410001000000");
    sdo(x, "sdo_tx", 1, 0x4121, 0, Some(1));
    label_has(x, &["CAN node ID (Modbus 0x0121) = 1"]);
}
