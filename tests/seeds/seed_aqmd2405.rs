//! AQMD2405BLS-MT-2 (manual 001, section 7 CANopen): the manual's CAN frames and tables through
//! `cotui decode --format jsonl --profile 1=aqmd2405`. Frames are in
//! `tests/fixtures/seeds/aqmd2405.log` (line numbers below) with the manual's lines as comments.

use crate::seed_common;
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

#[test]
fn sdo_abort_code_table() {
    let f = frames();
    // 7.3: every abort code of the manual's table decodes with its CiA 301 text. OCR/manual fixes:
    // "0x05030004"/"0x05030005" are 0x05040004/0x05040005, "0x0606001x" are 0x0607001x.
    for (i, (code, text)) in [
        (0x0503_0000_u32, "Toggle bit not alternated"),
        (0x0504_0000, "SDO protocol timed out"),
        (0x0504_0001, "Client/server command specifier not valid or unknown"),
        (0x0504_0002, "Invalid block size (block mode only)"),
        (0x0504_0003, "Invalid sequence number (block mode only)"),
        (0x0504_0004, "CRC error (block mode only)"),
        (0x0504_0005, "Out of memory"),
        (0x0601_0000, "Unsupported access to an object"),
        (0x0601_0001, "Attempt to read a write only object"),
        (0x0601_0002, "Attempt to write a read only object"),
        (0x0602_0000, "Object does not exist in the object dictionary"),
        (0x0604_0041, "Object cannot be mapped to the PDO"),
        (0x0604_0042, "would exceed PDO length"),
        (0x0604_0043, "General parameter incompatibility reason"),
        (0x0604_0047, "General internal incompatibility in the device"),
        (0x0606_0000, "Access failed due to an hardware error"),
        (0x0607_0010, "length of service parameter does not match"),
        (0x0607_0012, "length of service parameter too high"),
        (0x0607_0013, "length of service parameter too low"),
        (0x0609_0011, "Sub-index does not exist"),
        (0x0609_0030, "Invalid value for parameter"),
        (0x0609_0031, "Value of parameter written too high"),
        (0x0609_0032, "Value of parameter written too low"),
        (0x0609_0036, "Maximum value is less than minimum value"),
        (0x0800_0000, "General error"),
        (0x0800_0020, "Data cannot be transferred or stored to the application"),
        (0x0800_0021, "because of local control"),
        (0x0800_0022, "because of the present device state"),
        (0x0800_0023, "Object dictionary dynamic generation fails"),
    ]
    .into_iter()
    .enumerate()
    {
        let b = code.to_le_bytes();
        let data = format!("80002000{:02X}{:02X}{:02X}{:02X}", b[0], b[1], b[2], b[3]);
        let x = f.at(48 + i as u64, 0x581, &data);
        sdo(x, "sdo_tx", 1, 0x2000, 0, None);
        assert_eq!(x["sdo"]["abort_code"], code, "{x}");
        let shown = x["sdo"]["abort_text"].as_str().unwrap_or_default();
        assert!(shown.contains(text), "0x{code:08X}: `{shown}`");
    }
}

#[test]
fn generic_emcy_codes_and_layout() {
    let f = frames();
    // 7.5.6: "00xx Error Reset or No Error"
    let x = f.at(81, 0x081, "0000000000000000");
    assert_eq!(
        (x["emcy"]["code"].as_u64(), x["emcy"]["register"].as_u64()),
        (Some(0), Some(0))
    );
    // "81xx communication": 8110 .. 8220 with error register (byte 2) = generic + communication
    for (i, (code, text)) in [
        (0x8110, "CAN overrun"),
        (0x8120, "error passive"),
        (0x8130, "Life guard error or heartbeat error"),
        (0x8140, "Recovered from bus off"),
        (0x8210, "PDO not processed due to length error"),
        (0x8220, "PDO length exceeded"),
    ]
    .into_iter()
    .enumerate()
    {
        let data = format!("{:02X}{:02X}110000000000", code & 0xFF, code >> 8);
        let x = f.at(82 + i as u64, 0x081, &data);
        assert_eq!(x["emcy"]["code"], code);
        assert!(x["emcy"]["text"].as_str().unwrap().contains(text), "{x}");
        assert_eq!(x["emcy"]["register_bits"], json!(["generic", "communication"]));
    }
    // class rows "21xx Current, device input side" ... "FFxx Device specific"
    for (i, (code, text)) in [
        (0x2100, "Current, device input side"),
        (0x3200, "Voltage inside the device"),
        (0x4100, "Ambient temperature"),
        (0x6100, "Internal software"),
        (0x6300, "Data set"),
        (0x7000, "Additional modules"),
        (0x9000, "External error"),
        (0xF000, "Additional functions"),
        (0xFF00, "Device specific"),
    ]
    .into_iter()
    .enumerate()
    {
        let data = format!("00{:02X}010000000000", code >> 8);
        assert_eq!(f.at(88 + i as u64, 0x081, &data)["emcy"]["text"], text);
    }
}

#[test]
fn communication_object_table() {
    let f = frames();
    // 7.5.7: "0x1014 EMCY COB-ID U32 0x80L RO": read 0x81 on node 1; a write is refused (06010002)
    let x = f.at(102, 0x581, "4314100081000000");
    sdo(x, "sdo_tx", 1, 0x1014, 0, Some(0x81));
    assert_eq!(x["sdo"]["value_text"], "0x00000081 (COB-ID 0x081)");
    let x = f.at(104, 0x581, "8014100002000106");
    assert_eq!(x["sdo"]["abort_text"], "Attempt to write a read only object");
    // 0x1003 sub 1: the newest EMCY code, with the driver's own text
    let x = f.at(105, 0x581, "4303100110230500");
    sdo(x, "sdo_tx", 1, 0x1003, 1, Some(0x0005_2310));
    label_has(
        x,
        &[
            "Standard error field 1",
            "0x2310 Continuous over-current (motor output)",
        ],
    );
    // 0x1016 sub 1: "Bit23-16 Node-ID, Bit15-0 heartbeat time (ms)"
    let x = f.at(106, 0x601, "23161001F4010200");
    sdo(x, "sdo_rx", 1, 0x1016, 1, Some(0x0002_01F4));
    assert_eq!(x["sdo"]["value_text"], "0x000201F4 (node 2, time 500 ms)");
    assert_eq!(
        x["sdo"]["value_parts"],
        json!([{"name": "node", "raw": 2, "text": "2"}, {"name": "time", "raw": 500, "text": "500 ms"}])
    );
    // 0x1018 sub 0 "U8 0x04 RO"
    sdo(f.at(107, 0x581, "4F18100004000000"), "sdo_tx", 1, 0x1018, 0, Some(4));
    // 0x1400 sub 1 "0x200L" (+ node-ID), 0x1801 sub 1 with bit 31 "PDO not valid"
    let x = f.at(108, 0x581, "4300140101020000");
    label_has(x, &["COB-ID used by RPDO", "(COB-ID 0x201)"]);
    let x = f.at(109, 0x601, "2301180181020080");
    label_has(x, &["COB-ID used by TPDO", "COB-ID 0x281, invalid/disabled"]);
    // 0x1600 sub 0 "0~8", factory mapping empty
    label_has(f.at(110, 0x581, "4F00160000000000"), &["Number of mapped objects = 0"]);
    // 0x1015 in 100 us ("10*100us=1ms"): 100 = 10 ms; 0x1005 "0x80L"; 0x1017 in ms
    assert_eq!(f.at(111, 0x601, "2B15100064000000")["sdo"]["value_text"], "10 ms");
    assert_eq!(
        f.at(112, 0x581, "4305100080000000")["sdo"]["value_text"],
        "0x00000080 (COB-ID 0x080)"
    );
    assert_eq!(f.at(113, 0x601, "2B171000F4010000")["sdo"]["value_text"], "500 ms");
}

#[test]
fn object_table_defaults_and_access() {
    use cotui::od::json::load_profile;
    use cotui::od::{Access, Dictionary, Value};
    use std::sync::Arc;
    let path = format!("{}/decoders/aqmd2405.json", env!("CARGO_MANIFEST_DIR"));
    let (p, _) = load_profile(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let d = Dictionary::new(vec![Arc::new(p)]);
    let o = |i: u16, s: u8| d.object(i, s).unwrap_or_else(|| panic!("0x{i:04X}:{s}"));
    // 7.5.7: defaults and access as the manual's table gives them
    for (i, s, default) in [
        (0x1000, 0, 0),
        (0x1001, 0, 0),
        (0x1003, 0, 0),
        (0x1005, 0, 0x80),
        (0x1015, 0, 0),
        (0x1017, 0, 0),
        (0x1018, 0, 4),
        (0x1200, 0, 2),
        (0x1600, 0, 0),
        (0x1603, 0, 0),
        (0x1A00, 0, 0),
        (0x1A03, 0, 0),
        (0x1802, 4, 0),
        (0x1F80, 0, 0),
    ] {
        assert_eq!(o(i, s).default, Some(Value::Unsigned(default)), "0x{i:04X}:{s}");
    }
    assert_eq!(o(0x1014, 0).access, Access::Ro, "0x1014 is RO on this driver");
    assert_eq!((o(0x1200, 1).access, o(0x1200, 2).access), (Access::Ro, Access::Ro));
    assert_eq!(o(0x1003, 8).name, "Standard error field 8");
    assert_eq!(o(0x1016, 3).name, "Consumer heartbeat time 3");
    assert_eq!(o(0x1A01, 0).max, Some(8));
    assert_eq!(o(0x1001, 0).bits[&3], "Temperature");
}

#[test]
fn vendor_object_ranges_bits_and_factory_settings() {
    let f = frames();
    // 7.6.2 / 7.6.3 / 7.6.1 frames
    let x = f.at(116, 0x581, "4F16210005000000");
    sdo(x, "sdo_tx", 1, 0x2116, 0, Some(5));
    label_has(x, &["Output states = 5"]);
    label_has(f.at(117, 0x581, "4B04220007000000"), &["0x2204:00 SYNC counter = 7"]);
    assert_eq!(f.at(118, 0x601, "2F0A200001000000")["sdo"]["value_text"], "1 (rpm)");

    use cotui::od::json::load_profile;
    use cotui::od::{Dictionary, Value};
    use std::sync::Arc;
    let path = format!("{}/decoders/aqmd2405.json", env!("CARGO_MANIFEST_DIR"));
    let (p, _) = load_profile(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let d = Dictionary::new(vec![Arc::new(p)]);
    let o = |i: u16| d.object(i, 0).unwrap_or_else(|| panic!("0x{i:04X}"));
    // 7.6.2: "0x2116 U8 0x00~0xFF bits 0~7 outputs 1~8"; "0x2114 0x00~0x03"; "0x2115 0x00~0x07"
    assert_eq!(o(0x2116).bits.len(), 8);
    assert_eq!(o(0x2116).bits[&7], "Output 8 on");
    assert_eq!(
        (o(0x2114).max, o(0x2115).max, o(0x2111).max),
        (Some(3), Some(7), Some(2))
    );
    // 7.1: "factory: 500 kbps, node ID 0x01, CANopen off until register 0x0120 = 1"
    for (i, v) in [(0x2201, 1), (0x2202, 5), (0x4121, 1), (0x4122, 5), (0x4120, 0)] {
        assert_eq!(o(i).default, Some(Value::Unsigned(v)), "0x{i:04X}");
    }
    // "RW/E" objects are stored with 0x1010
    for i in [0x200A, 0x200B, 0x2201, 0x2202] {
        assert!(o(i).description.as_deref().unwrap().contains("0x1010"), "0x{i:04X}");
    }
}
