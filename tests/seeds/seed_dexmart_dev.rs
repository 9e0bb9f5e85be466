//! Dexmart DEV dual-motor drive (manual 000): every worked example frame of the manual through
//! `cotui decode --format jsonl --profile 1=dexmart-dev`. Frames are in
//! `tests/fixtures/seeds/dexmart-dev.log` (line numbers below) with the manual's lines as comments.

use crate::seed_common;
use seed_common::{decode, fixture, label_has, run, sdo, signal};
use serde_json::{Value, json};

fn frames() -> seed_common::Frames {
    decode(&["1=dexmart-dev"], &fixture("dexmart-dev.log"))
}

#[test]
fn sdo_download_and_expedited_upload() {
    let f = frames();
    // "Node-ID = 1 ... 03-01 (Index = 3003h - Sub-Index = 01h) = 3000 (0BB8h)": "601 2B 03 30 01 B8 0B 00 00"
    let x = f.at(3, 0x601, "2B033001B80B0000");
    sdo(x, "sdo_rx", 1, 0x3003, 1, Some(3000));
    assert_eq!(x["label"], "Download 0x3003:01 M1 digital speed 0 (03-01) = 3000 rpm");
    // "581 60 03 30 01 00 00 00 00"
    let x = f.at(4, 0x581, "6003300100000000");
    sdo(x, "sdo_tx", 1, 0x3003, 1, None);
    assert_eq!(x["sdo"]["cs"], "initiate_download");
    // "Dynamic Data 10 (Index = 3000h - Sub-Index = 0Ah)": "601 40 00 30 0A", "581 4B 00 30 0A 6E 09" = 096Eh = 2414
    sdo(f.at(6, 0x601, "4000300A00000000"), "sdo_rx", 1, 0x3000, 0x0A, None);
    let x = f.at(7, 0x581, "4B00300A6E090000");
    sdo(x, "sdo_tx", 1, 0x3000, 0x0A, Some(2414));
    label_has(x, &["Dynamic Data 10 = 2414"]);
}

#[test]
fn segmented_upload_with_toggle_bits() {
    let f = frames();
    // "601 40 82 30 00": initiate upload of 3082h sub 0; "581 41 ... 10h": segmented, 16 bytes
    sdo(f.at(11, 0x601, "4082300000000000"), "sdo_rx", 1, 0x3082, 0, None);
    let x = f.at(12, 0x581, "4182300010000000");
    assert_eq!(
        (x["sdo"]["expedited"].as_bool(), x["sdo"]["size"].as_u64()),
        (Some(false), Some(16))
    );
    // "601 60" (t=0), "581 00 ..." (t=0, n=0, c=0)
    assert_eq!(f.at(13, 0x601, "6000000000000000")["sdo"]["toggle"], 0);
    let x = f.at(14, 0x581, "0032303336493034");
    assert_eq!(
        (x["sdo"]["toggle"].as_u64(), x["sdo"]["last"].as_bool()),
        (Some(0), Some(false))
    );
    // "601 70" (t=1), "581 10 ..." (t=1)
    assert_eq!(f.at(15, 0x601, "7000000000000000")["sdo"]["toggle"], 1);
    assert_eq!(f.at(16, 0x581, "1041303032302020")["sdo"]["toggle"], 1);
    // "581 0B ..." t=0, n=5, c=1: 7 - 5 = 2 bytes
    let x = f.at(18, 0x581, "0B20200000000000");
    assert_eq!(
        (x["sdo"]["last"].as_bool(), x["sdo"]["data"].as_str()),
        (Some(true), Some("2020"))
    );
    // The reassembled transfer: "0x32 0x30 0x33 0x36 0x49 0x30 0x34 0x41 0x30 0x30 0x32 0x30 0x20 0x20 0x20 0x20"
    let lines = run(
        &["--transactions", "--format", "jsonl", "--profile", "1=dexmart-dev"],
        &fixture("dexmart-dev.log"),
    );
    let t: Vec<Value> = lines.iter().map(|l| serde_json::from_str(l).unwrap()).collect();
    let up = t.iter().find(|t| t["index"] == 0x3082).expect("3082h transfer");
    assert_eq!(up["protocol"], "segmented");
    assert_eq!(up["outcome"], "ok");
    assert_eq!(up["value"], "2036I04A0020    ");
    assert_eq!(up["data"], "32303336493034413030323020202020");
}

#[test]
fn abort_transfer() {
    let f = frames();
    // "Index = 3000h, Sub-Index = 21h": "601 40 00 30 21 00 00 00 00"
    sdo(f.at(21, 0x601, "4000302100000000"), "sdo_rx", 1, 0x3000, 0x21, None);
    // "581 80 00 32 21 00 00 02 06" = 0602 0000h (OCR: 32h for the index byte 30h)
    let x = f.at(22, 0x581, "8000302100000206");
    sdo(x, "sdo_tx", 1, 0x3000, 0x21, None);
    assert_eq!(x["sdo"]["abort_code"], 0x0602_0000);
    assert_eq!(x["sdo"]["abort_text"], "Object does not exist in the object dictionary");
}

#[test]
fn worked_tpdo_mapping_decode() {
    let f = frames();
    // "1A00h | 00h 05h", "1A00h | 01h 30460810h" ... "1A00h | 05h 30460F10h"
    sdo(
        f.at(28, 0x601, "23001A0110084630"),
        "sdo_rx",
        1,
        0x1A00,
        1,
        Some(0x3046_0810),
    );
    sdo(
        f.at(30, 0x601, "23001A0208064630"),
        "sdo_rx",
        1,
        0x1A00,
        2,
        Some(0x3046_0608),
    );
    sdo(
        f.at(32, 0x601, "23001A0308124630"),
        "sdo_rx",
        1,
        0x1A00,
        3,
        Some(0x3046_1208),
    );
    sdo(
        f.at(34, 0x601, "23001A04100E4630"),
        "sdo_rx",
        1,
        0x1A00,
        4,
        Some(0x3046_0E10),
    );
    sdo(
        f.at(36, 0x601, "23001A05100F4630"),
        "sdo_rx",
        1,
        0x1A00,
        5,
        Some(0x3046_0F10),
    );
    sdo(f.at(38, 0x601, "2F001A0005000000"), "sdo_rx", 1, 0x1A00, 0, Some(5));
    // Data "60 09 01 03 F4 01 E8 03": "3046h|08h 0960h", "06h 0001h", "12h 0003h", "0Eh 01F4h", "0Fh 03E8h"
    let x = f.at(40, 0x181, "60090103F401E803");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("tpdo"), Some(1)));
    assert_eq!(signal(x, 0x3046, 0x08).0, json!(0x0960));
    assert_eq!(signal(x, 0x3046, 0x06).0, json!(1));
    assert_eq!(signal(x, 0x3046, 0x12).0, json!(3));
    assert_eq!(signal(x, 0x3046, 0x0E).0, json!(0x01F4));
    assert_eq!(signal(x, 0x3046, 0x0F).0, json!(0x03E8));
    label_has(x, &["BusV=2400", "XIN=1", "YOUT=3", "A0X=500", "A1X=1000"]);
}

#[test]
fn nmt_error_control_and_sync() {
    let f = frames();
    // "01h Start remote node", "02h Stop remote node", "80h Enter pre-operational state" (Node-ID 0 = all),
    // "81h Reset node", "82h Reset communication"
    for (line, data, command, target) in [
        (42, "0101", "start", 1),
        (43, "0201", "stop", 1),
        (44, "8000", "pre_operational", 0),
        (45, "8101", "reset_node", 1),
        (46, "8201", "reset_communication", 1),
    ] {
        assert_eq!(
            f.at(line, 0x000, data)["nmt"],
            json!({"command": command, "target": target})
        );
    }
    // Boot-up "700h + Node-ID, Data 0"; "04h Stopped", "05h Operational State", "7Fh Pre-operational State"
    for (line, data, state) in [
        (48, "00", "boot_up"),
        (49, "04", "stopped"),
        (50, "05", "operational"),
        (51, "7F", "pre_operational"),
    ] {
        assert_eq!(f.at(line, 0x701, data)["heartbeat"]["state"], state);
    }
    // SYNC "CAN-ID = 80h", DLC 0, or DLC 1 with the counter ("Counter=10")
    assert_eq!(f.at(53, 0x080, "")["sync"]["counter"], json!(null));
    assert_eq!(f.at(54, 0x080, "0A")["sync"]["counter"], 10);
}

#[test]
fn emcy_carries_both_motor_alarm_codes() {
    let f = frames();
    // "Byte 6 M1 Alarm Code, Byte 7 M2 Alarm Code"
    let x = f.at(57, 0x081, "1023030000000500");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("emcy"), Some(1)));
    assert_eq!(x["emcy"]["code"], 0x2310);
    assert_eq!(
        x["emcy"]["mfr_fields"],
        json!({"M1 alarm code": "0x05", "M2 alarm code": "0x00"})
    );
    label_has(x, &["M1 alarm code=0x05", "M2 alarm code=0x00"]);
    // "Error Reset: 0x0000"
    assert_eq!(f.at(58, 0x081, "0000000000000000")["emcy"]["code"], 0);
}

#[test]
fn multi_drive_rpdo_commands_and_mapping_sets() {
    let f = frames();
    // Encoder speed mode M1, mapping 09-26 = 0: "201 [5] 0A 00 00 B8 0B" = 3000 (0BB8h) rpm
    let x = f.at(60, 0x201, "0A0000B80B");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("rpdo"), Some(1)));
    assert_eq!(
        signal(x, 0x3051, 1),
        (json!(0x0A), "10 (Speed command (encoder))".to_string())
    );
    assert_eq!(signal(x, 0x3051, 3).0, json!(3000));
    assert_eq!(x["pdo"]["mapping_source"], "profile dexmart-dev");
    assert!(x.get("malformed").is_none(), "{x}");
    // Encoder position mode M1: "201 [5] 0F 64 ..." Data1 = 100
    let x = f.at(62, 0x201, "0F64000000");
    assert_eq!(signal(x, 0x3051, 1).0, json!(0x0F));
    assert_eq!(signal(x, 0x3051, 2).0, json!(100));
    // M2 on RPDO2: "301 [5] 0A ...", "301 [5] 0F 64 ..."
    assert_eq!(signal(f.at(64, 0x301, "0A0000B80B"), 0x3052, 3).0, json!(3000));
    assert_eq!(signal(f.at(65, 0x301, "0F64000000"), 0x3052, 2).0, json!(100));
    // Hall speed mode needs 09-26 = 1: the write switches the node to mapping set 1
    let x = f.at(67, 0x601, "2B09301A01000000");
    sdo(x, "sdo_rx", 1, 0x3009, 26, Some(1));
    label_has(x, &["CANopen PDO Mapping (09-26) = 1"]);
    // "201 [3] 01 B8 0B": Multi-Drive Lite M1, CMD 01h, 3000 rpm; "301 [3] 01 B8 0B": M2
    let x = f.at(70, 0x201, "01B80B");
    assert_eq!(signal(x, 0x305B, 1).0, json!(1));
    assert_eq!(signal(x, 0x305B, 2).0, json!(3000));
    assert!(x.get("malformed").is_none(), "{x}");
    let x = f.at(71, 0x301, "01B80B");
    assert_eq!(signal(x, 0x305C, 2).0, json!(3000));
}

#[test]
fn monitor_data_single_subs_win_over_the_range() {
    // TPDO1 of mapping set 0: 3046h sub 1 "M1: Motor State" (u8), sub 2 alarm code, sub 5 speed 3000 (0BB8h),
    // subs 22/23 encoder index/position; sub 1 must not be taken from the "1..32" Monitor Data range.
    let f = decode(&["1=dexmart-dev"], "(0.000) can0 181#0300B80B01000200\n");
    let x = f.at(1, 0x181, "0300B80B01000200");
    let s = &x["pdo"]["signals"][0];
    assert_eq!(
        (s["sub"].as_u64(), s["name"].as_str()),
        (Some(1), Some("M1: Motor State"))
    );
    assert_eq!(signal(x, 0x3046, 5), (json!(3000), "3000 rpm".to_string()));
    label_has(x, &["M1: Motor State=", "M1: Current Speed=3000 rpm"]);
    let p = cotui::od::json::load_profile("dexmart-dev", include_str!("../../decoders/dexmart-dev.json"))
        .unwrap()
        .0;
    for index in [0x3046, 0x304A] {
        let o = p.object(index, 1).unwrap();
        assert!(o.name.ends_with("Motor State"), "{}", o.name);
        assert_eq!(o.data_type, cotui::od::DataType::U8);
    }
}

#[test]
fn error_history_and_manufacturer_status_are_split() {
    // 1003h sub 01h: "(alarm_m1 << 24) | (alarm_m0 << 16) | error_code" (m0 = M1, m1 = M2);
    // 1002h: "Byte0 = Motor State M1, Byte1 = Motor State M2"; 1016h sub 1: node 2, 100 ms.
    let log = "\
(0.000) can0 601#4003100100000000
(0.001) can0 581#4303100110230507
(0.002) can0 601#4002100000000000
(0.003) can0 581#4302100003020000
(0.004) can0 601#4016100100000000
(0.005) can0 581#4316100164000200
";
    let f = decode(&["1=dexmart-dev"], log);
    let x = f.at(2, 0x581, "4303100110230507");
    // The fields are in the JSON too, raw and as shown.
    assert_eq!(
        x["sdo"]["value_parts"],
        json!([
            {"name": "error code", "raw": 0x2310, "text": "0x2310 Continuous over-current"},
            {"name": "M1 alarm code", "raw": 5, "text": "0x05"},
            {"name": "M2 alarm code", "raw": 7, "text": "0x07"}
        ])
    );
    label_has(
        x,
        &[
            "Standard error field 1 = 0x07052310 (error code 0x2310 Continuous over-current, M1 alarm code 0x05, M2 alarm code 0x07)",
        ],
    );
    label_has(
        f.at(4, 0x581, "4302100003020000"),
        &["Manufacturer status register = 0x00000203 (M1 motor state 3, M2 motor state 2)"],
    );
    label_has(
        f.at(6, 0x581, "4316100164000200"),
        &["Consumer heartbeat time 1 = 0x00020064 (node 2, time 100 ms)"],
    );
    // The transfers' records carry the same fields.
    let lines = run(
        &["--transactions", "--format", "jsonl", "--profile", "1=dexmart-dev"],
        log,
    );
    let records: Vec<Value> = lines.iter().map(|l| serde_json::from_str(l).unwrap()).collect();
    let heartbeat = records.iter().find(|r| r["index"] == 0x1016).expect("0x1016 transfer");
    assert_eq!(
        heartbeat["value_parts"][0],
        json!({"name": "node", "raw": 2, "text": "2"})
    );
    assert_eq!(heartbeat["value_parts"][1]["text"], "100 ms");
    let status = records.iter().find(|r| r["index"] == 0x1002).expect("0x1002 transfer");
    assert_eq!(status["value_parts"][0]["name"], "M1 motor state");
    assert_eq!(status["value_parts"][0]["raw"], 3);
}

#[test]
fn emcy_error_code_table() {
    let f = frames();
    // The manual's EMCY Error Code table, row by row (class rows "... — generic" show the class name)
    let rows = [
        (0x0000, "No error"),
        (0x1000, "Generic error"),
        (0x2000, "Current"),
        (0x2100, "Current, device input side"),
        (0x2200, "Current inside the device"),
        (0x2300, "Current, device output side"),
        (0x3000, "Voltage"),
        (0x3100, "Mains voltage"),
        (0x3200, "Voltage inside the device"),
        (0x3300, "Output voltage"),
        (0x4000, "Temperature"),
        (0x4100, "Ambient temperature"),
        (0x4200, "Device temperature"),
        (0x5000, "Device hardware"),
        (0x6000, "Device software"),
        (0x6100, "Internal software"),
        (0x6200, "User software"),
        (0x6300, "Data set"),
        (0x7000, "Additional modules"),
        (0x8000, "Monitoring"),
        (0x8100, "Communication"),
        (0x8110, "CAN overrun (objects lost)"),
        (0x8120, "CAN in error passive mode"),
        (0x8130, "Life guard error or heartbeat error"),
        (0x8140, "Recovered from bus off"),
        (0x8150, "CAN-ID collision"),
        (0x8200, "Protocol error"),
        (0x8210, "PDO not processed due to length error"),
        (0x8220, "PDO length exceeded"),
        (0x8230, "DAM MPDO not processed, destination object not available"),
        (0x8240, "Unexpected SYNC data length"),
        (0x8250, "RPDO timeout"),
        (0x9000, "External error"),
        (0xF000, "Additional functions"),
        (0xFF00, "Device specific"),
    ];
    for (i, (code, text)) in rows.into_iter().enumerate() {
        let data = format!("{:02X}{:02X}010000000102", code & 0xFF, code >> 8);
        let x = f.at(74 + i as u64, 0x081, &data);
        assert_eq!(x["emcy"]["code"], code, "{x}");
        assert_eq!(x["emcy"]["text"], text, "{x}");
        // "Byte 2 Error Register", "Byte 6 M1 Alarm Code, Byte 7 M2 Alarm Code"
        assert_eq!(x["emcy"]["register_bits"], json!(["generic"]));
        assert_eq!(
            x["emcy"]["mfr_fields"],
            json!({"M1 alarm code": "0x01", "M2 alarm code": "0x02"})
        );
    }
}

#[test]
fn pdo_cob_ids_read_only_and_communication_defaults() {
    let f = frames();
    // "1401h 01h Read Only unsigned32 00000300h + Node-ID": read 0x301; a write is refused
    let x = f.at(113, 0x581, "4301140101030000");
    sdo(x, "sdo_tx", 1, 0x1401, 1, Some(0x301));
    assert_eq!(x["sdo"]["value_text"], "0x00000301 (COB-ID 0x301)");
    label_has(x, &["COB-ID used by RPDO"]);
    let x = f.at(115, 0x581, "8001140102000106");
    assert_eq!(x["sdo"]["abort_text"], "Attempt to write a read only object");
    // "29Bits-ID : 20000180h + Node-ID"
    let x = f.at(116, 0x581, "4300180181010020");
    assert_eq!(x["sdo"]["value_text"], "0x20000181 (COB-ID 0x00000181, 29-bit)");
    // "06h ... 00h SYNC_StartValue" in the RPDO table
    label_has(
        f.at(117, 0x581, "4F00140600000000"),
        &["0x1400:06 SYNC start value = 0"],
    );
    // "1005h ... 11Bits-ID : 00000080h"
    assert_eq!(
        f.at(119, 0x581, "4305100080000000")["sdo"]["value_text"],
        "0x00000080 (COB-ID 0x080)"
    );

    use cotui::od::json::load_profile;
    use cotui::od::{Access, Dictionary, Value};
    use std::sync::Arc;
    let path = format!("{}/decoders/dexmart-dev.json", env!("CARGO_MANIFEST_DIR"));
    let (p, _) = load_profile(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let d = Dictionary::new(vec![Arc::new(p)]);
    let o = |i: u16, s: u8| d.object(i, s).unwrap_or_else(|| panic!("0x{i:04X}:{s}"));
    for i in [0x1400, 0x1403, 0x1800, 0x1803] {
        assert_eq!(o(i, 1).access, Access::Ro, "0x{i:04X}:1");
        assert_eq!(
            (o(i, 4).access, o(i, 4).default.clone()),
            (Access::Ro, Some(Value::Unsigned(0)))
        );
    }
    assert_eq!(o(0x1001, 0).bits[&6], "Reserved (always 0)");
    assert_eq!(o(0x1005, 0).default, Some(Value::Unsigned(0x80)));
    assert_eq!(o(0x1017, 0).default, Some(Value::Unsigned(0)));
    assert_eq!(o(0x1008, 0).default, Some(Value::Text("DEV-N050CQ".into())));
}

#[test]
fn sdo_abort_code_table_in_the_manuals_words() {
    let f = frames();
    // "Abort code | Description": each row, the manual's text without its final period
    // (OCR "e.g.object" is "e.g. object")
    let rows: [(u32, &str); 31] = [
        (0x0503_0000, "Toggle bit not alternated"),
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
        (
            0x0604_0042,
            "The number and length of the objects to be mapped would exceed PDO length",
        ),
        (0x0604_0043, "General parameter incompatibility reason"),
        (0x0604_0047, "General internal incompatibility in the device"),
        (0x0606_0000, "Access failed due to an hardware error"),
        (
            0x0607_0010,
            "Data type does not match, length of service parameter does not match",
        ),
        (
            0x0607_0012,
            "Data type does not match, length of service parameter too high",
        ),
        (
            0x0607_0013,
            "Data type does not match, length of service parameter too low",
        ),
        (0x0609_0011, "Sub-index does not exist"),
        (0x0609_0030, "Invalid value for parameter (download only)"),
        (0x0609_0031, "Value of parameter written too high (download only)"),
        (0x0609_0032, "Value of parameter written too low (download only)"),
        (0x0609_0036, "Maximum value is less than minimum value"),
        (0x060A_0023, "Resource not available: SDO connection"),
        (0x0800_0000, "General error"),
        (0x0800_0020, "Data cannot be transferred or stored to the application"),
        (
            0x0800_0021,
            "Data cannot be transferred or stored to the application because of local control",
        ),
        (
            0x0800_0022,
            "Data cannot be transferred or stored to the application because of the present device state",
        ),
        (
            0x0800_0023,
            "Object dictionary dynamic generation fails or no object dictionary is present (e.g. object dictionary is generated from file and generation fails because of an file error)",
        ),
        (0x0800_0024, "No data available"),
    ];
    for (i, (code, text)) in rows.into_iter().enumerate() {
        let b = code.to_le_bytes();
        let data = format!("80003021{:02X}{:02X}{:02X}{:02X}", b[0], b[1], b[2], b[3]);
        let x = f.at(122 + i as u64, 0x581, &data);
        sdo(x, "sdo_tx", 1, 0x3000, 0x21, None);
        assert_eq!(x["sdo"]["cs"], "abort");
        assert_eq!(x["sdo"]["abort_code"], code);
        assert_eq!(x["sdo"]["abort_text"], text, "0x{code:08X}");
    }
}
