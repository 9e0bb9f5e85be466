//! AIMOTOR CiA 402 servo (manual 004): every worked example frame of the manual through
//! `cotui decode --format jsonl --profile 1=aimotor`. Frames are in
//! `tests/fixtures/seeds/aimotor.log` (line numbers below) with the manual's lines as comments;
//! the manual's "xx" data bytes are filled with the values the fixture notes.

use crate::seed_common;
use seed_common::{decode, fixture, label_has, sdo, signal};
use serde_json::json;

fn frames() -> seed_common::Frames {
    decode(&["1=aimotor"], &fixture("aimotor.log"))
}

#[test]
fn pv_by_sdo_section_4_2() {
    let f = frames();
    // "601 2F 60 60 00 03 00 00 00" mode = 3, "581 60 60 60 00 00 00 00 00"
    let x = f.at(5, 0x601, "2F60600003000000");
    sdo(x, "sdo_rx", 1, 0x6060, 0, Some(3));
    label_has(x, &["Modes of operation", "Profile velocity"]);
    let x = f.at(6, 0x581, "6060600000000000");
    sdo(x, "sdo_tx", 1, 0x6060, 0, None);
    assert_eq!(x["sdo"]["cs"], "initiate_download");
    // "601 23 FF 60 00 xx xx xx xx" target velocity in Pul/s
    let x = f.at(7, 0x601, "23FF600010270000");
    sdo(x, "sdo_rx", 1, 0x60FF, 0, Some(10000));
    assert_eq!(x["sdo"]["value_text"], "10000 Pul/s");
    // "601 23 83 60 00 xx", "601 23 84 60 00 xx" in Pul/s^2
    assert_eq!(f.at(9, 0x601, "23836000A0860100")["sdo"]["value_text"], "100000 Pul/s²");
    sdo(
        f.at(11, 0x601, "23846000A0860100"),
        "sdo_rx",
        1,
        0x6084,
        0,
        Some(100000),
    );
    // "601 2B 40 60 00 06 / 07 / 0F" with "581 60 40 60 00" replies
    sdo(f.at(13, 0x601, "2B40600006000000"), "sdo_rx", 1, 0x6040, 0, Some(6));
    sdo(f.at(14, 0x581, "6040600000000000"), "sdo_tx", 1, 0x6040, 0, None);
    sdo(f.at(15, 0x601, "2B40600007000000"), "sdo_rx", 1, 0x6040, 0, Some(7));
    sdo(f.at(17, 0x601, "2B4060000F000000"), "sdo_rx", 1, 0x6040, 0, Some(15));
    // "601 40 41 60 00", "581 4B 41 60 00 xx xx" statusword
    assert_eq!(f.at(19, 0x601, "4041600000000000")["sdo"]["cs"], "initiate_upload");
    let x = f.at(20, 0x581, "4B41600037020000");
    sdo(x, "sdo_tx", 1, 0x6041, 0, Some(0x0237));
    let state = x["sdo"]["value_text"].as_str().unwrap();
    assert!(state.starts_with("0x0237 (Operation enabled"), "{state}");
    // "601 40 6C 60 00", "581 43 6C 60 00 xx xx xx xx" actual velocity
    let x = f.at(22, 0x581, "436C600010270000");
    sdo(x, "sdo_tx", 1, 0x606C, 0, Some(10000));
    assert_eq!(x["sdo"]["value_text"], "10000 Pul/s");
}

#[test]
fn pp_hm_pt_by_sdo_sections_4_3_to_4_5() {
    let f = frames();
    // 4.3: "601 2F 60 60 00 01", "601 23 7A 60 00 xx" (Pul), "601 23 81 60 00 xx" (Pul/s), "0F -> 1F" starts
    label_has(f.at(25, 0x601, "2F60600001000000"), &["Profile position"]);
    assert_eq!(f.at(27, 0x601, "237A600094880100")["sdo"]["value_text"], "100500 Pul");
    assert_eq!(f.at(29, 0x601, "2381600035820000")["sdo"]["value_text"], "33333 Pul/s");
    sdo(f.at(31, 0x601, "2B4060001F000000"), "sdo_rx", 1, 0x6040, 0, Some(0x1F));
    // "601 40 64 60 00", "581 43 64 60 00 xx" position actual value
    let x = f.at(34, 0x581, "4364600094880100");
    sdo(x, "sdo_tx", 1, 0x6064, 0, Some(100500));
    assert_eq!(x["sdo"]["value_text"], "100500 Pul");
    // 4.4: "601 2F 60 60 00 06", "601 2F 98 60 00 xx" homing method, "601 23 99 60 01/02", "601 23 9A 60 00"
    label_has(f.at(37, 0x601, "2F60600006000000"), &["Homing"]);
    let x = f.at(38, 0x601, "2F98600023000000");
    sdo(x, "sdo_rx", 1, 0x6098, 0, Some(35));
    label_has(x, &["Homing method = 35 (Current position)"]);
    sdo(f.at(39, 0x601, "2399600110270000"), "sdo_rx", 1, 0x6099, 1, Some(10000));
    sdo(f.at(40, 0x581, "6099600100000000"), "sdo_tx", 1, 0x6099, 1, None);
    sdo(f.at(41, 0x601, "23996002E8030000"), "sdo_rx", 1, 0x6099, 2, Some(1000));
    assert_eq!(f.at(43, 0x601, "239A600010270000")["sdo"]["value_text"], "10000 Pul/s²");
    // 4.5: "601 2F 60 60 00 04", "601 2B 71 60 00 xx" target torque in 0.1 % (reply printed "60 98 60": it is 60 71 60)
    label_has(f.at(47, 0x601, "2F60600004000000"), &["Profile torque"]);
    let x = f.at(48, 0x601, "2B71600064000000");
    sdo(x, "sdo_rx", 1, 0x6071, 0, Some(100));
    assert_eq!(x["sdo"]["value_text"], "10 %");
    sdo(f.at(49, 0x581, "6071600000000000"), "sdo_tx", 1, 0x6071, 0, None);
    // "601 23 7F 60 01 xx" printed with sub 01: 607Fh (max profile velocity) is a single value, sub 00
    sdo(
        f.at(50, 0x601, "237F6000A0860100"),
        "sdo_rx",
        1,
        0x607F,
        0,
        Some(100000),
    );
    // "601 40 77 60 00", "581 4B 77 60 00 xx" actual torque, 0.1 %
    let x = f.at(53, 0x581, "4B77600032000000");
    sdo(x, "sdo_tx", 1, 0x6077, 0, Some(50));
    assert_eq!(x["sdo"]["value_text"], "5 %");
}

#[test]
fn pdo_remapping_list_of_section_5_4() {
    let f = frames();
    // "000 80 01" NMT pre-operational for node 1
    let x = f.at(55, 0x000, "8001");
    assert_eq!(x["nmt"], json!({"command": "pre_operational", "target": 1}));
    // "601 23 00 14 01 01 02 00 80": RPDO1 COB-ID 0x80000201 (invalid) ... RPDO4 0x80000501
    sdo(
        f.at(57, 0x601, "2300140101020080"),
        "sdo_rx",
        1,
        0x1400,
        1,
        Some(0x8000_0201),
    );
    sdo(
        f.at(63, 0x601, "2303140101050080"),
        "sdo_rx",
        1,
        0x1403,
        1,
        Some(0x8000_0501),
    );
    // "601 23 00 18 01 81 01 00 80": TPDO1 COB-ID 0x80000181 ... TPDO4 0x80000481
    sdo(
        f.at(66, 0x601, "2300180181010080"),
        "sdo_rx",
        1,
        0x1800,
        1,
        Some(0x8000_0181),
    );
    sdo(
        f.at(72, 0x601, "2303180181040080"),
        "sdo_rx",
        1,
        0x1803,
        1,
        Some(0x8000_0481),
    );
    // "601 2F 00 14 02 01" RPDO1 transmission type 1; mapping 6040h/16, 6060h/8, 60FFh/32; 3 entries
    sdo(f.at(77, 0x601, "2F00140201000000"), "sdo_rx", 1, 0x1400, 2, Some(1));
    sdo(
        f.at(81, 0x601, "2300160110004060"),
        "sdo_rx",
        1,
        0x1600,
        1,
        Some(0x6040_0010),
    );
    sdo(
        f.at(83, 0x601, "2300160208006060"),
        "sdo_rx",
        1,
        0x1600,
        2,
        Some(0x6060_0008),
    );
    sdo(
        f.at(85, 0x601, "230016032000FF60"),
        "sdo_rx",
        1,
        0x1600,
        3,
        Some(0x60FF_0020),
    );
    sdo(f.at(87, 0x601, "2F00160003000000"), "sdo_rx", 1, 0x1600, 0, Some(3));
    // "601 23 00 14 01 01 02 00 00": RPDO1 valid again on 0x201
    sdo(f.at(89, 0x601, "2300140101020000"), "sdo_rx", 1, 0x1400, 1, Some(0x201));
    // TPDO1 mapping 6041h/16 + 606Ch/32, valid again on 0x181
    sdo(
        f.at(98, 0x601, "23001A0110004160"),
        "sdo_rx",
        1,
        0x1A00,
        1,
        Some(0x6041_0010),
    );
    sdo(
        f.at(100, 0x601, "23001A0220006C60"),
        "sdo_rx",
        1,
        0x1A00,
        2,
        Some(0x606C_0020),
    );
    sdo(
        f.at(104, 0x601, "2300180181010000"),
        "sdo_rx",
        1,
        0x1800,
        1,
        Some(0x181),
    );
    // "000 01 01" start node 1
    assert_eq!(
        f.at(107, 0x000, "0101")["nmt"],
        json!({"command": "start", "target": 1})
    );
}

#[test]
fn sync_example_uses_the_remapped_pdos() {
    let f = frames();
    // 5.5: "080" SYNC without counter
    let x = f.at(110, 0x080, "");
    assert_eq!(x["kind"], "sync");
    assert_eq!(x["sync"]["counter"], json!(null));
    // "181 37 02 E8 03 00 00": TPDO1 = 6041h = 0x0237 (operation enabled), 606Ch = 1000
    let x = f.at(111, 0x181, "3702E8030000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("tpdo"), Some(1)));
    let (v, text) = signal(x, 0x6041, 0);
    assert_eq!(v, json!(0x0237));
    assert!(text.starts_with("0x0237 (Operation enabled"), "{text}");
    assert_eq!(signal(x, 0x606C, 0), (json!(1000), "1000 Pul/s".to_string()));
    assert!(x["pdo"]["mapping_source"].as_str().unwrap().starts_with("sniffed"));
    // "201 0F 00 03 E8 03 00 00": RPDO1 = 6040h = 0x000F, 6060h = 3, 60FFh = 1000
    let x = f.at(112, 0x201, "0F0003E8030000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("rpdo"), Some(1)));
    let (v, text) = signal(x, 0x6040, 0);
    assert_eq!(v, json!(0x000F));
    assert!(text.contains("Enable operation"), "{text}");
    let (v, text) = signal(x, 0x6060, 0);
    assert_eq!(v, json!(3));
    assert!(text.contains("Profile velocity"), "{text}");
    assert_eq!(signal(x, 0x60FF, 0), (json!(1000), "1000 Pul/s".to_string()));
}

#[test]
fn node_guarding_heartbeat_emcy_and_h_parameters() {
    let f = frames();
    // 3.2: "0x700+Node-ID, 0 bytes" guarding request; reply bit 7 toggle, bits 6-0 state 5 = operational
    assert_eq!(f.at(115, 0x701, "")["heartbeat"]["request"], true);
    let x = f.at(116, 0x701, "85");
    assert_eq!(
        x["heartbeat"],
        json!({"state": "operational", "toggle": true, "request": false})
    );
    assert_eq!(f.at(118, 0x701, "05")["heartbeat"]["toggle"], false);
    // heartbeat "0 boot-up", "127 pre-operational"
    assert_eq!(f.at(120, 0x701, "00")["heartbeat"]["state"], "boot_up");
    assert_eq!(f.at(121, 0x701, "7F")["heartbeat"]["state"], "pre_operational");
    // 6.1: "CAN ... 0x0D03 -> 0x8130"
    let x = f.at(123, 0x081, "3081110000000000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("emcy"), Some(1)));
    assert_eq!(x["emcy"]["code"], 0x8130);
    assert!(
        x["emcy"]["text"].as_str().unwrap().contains("AIMOTOR fault 0D03h"),
        "{x}"
    );
    // "0x0101 -> 0x6320"
    let x = f.at(124, 0x081, "2063010000000000");
    assert!(x["emcy"]["text"].as_str().unwrap().contains("0101h"), "{x}");
    // 1.4: "H02-00 0x02 00 0x2002 0x01", set to 8 = CANopen (2.3 step 1)
    let x = f.at(126, 0x601, "2B02200108000000");
    sdo(x, "sdo_rx", 1, 0x2002, 1, Some(8));
    assert_eq!(x["label"], "Download 0x2002:01 Control mode (H02-00) = 8 (CANopen)");
}

#[test]
fn default_pdo_mapping_of_the_object_table() {
    let f = decode(&["1=aimotor"], &fixture("aimotor-default-pdo.log"));
    // 1600h: "0x60400010", "0x60600008", "607A" (target position)
    let x = f.at(3, 0x201, "0F000194880100");
    assert_eq!(signal(x, 0x6040, 0).0, json!(0x000F));
    assert_eq!(signal(x, 0x6060, 0).0, json!(1));
    assert_eq!(signal(x, 0x607A, 0), (json!(100500), "100500 Pul".to_string()));
    assert_eq!(x["pdo"]["mapping_source"], "profile aimotor");
    // 1A00h: "0x60410010", "0x60610008", "0x60640020"
    let x = f.at(5, 0x181, "37160194880100");
    assert!(signal(x, 0x6041, 0).1.contains("Operation enabled"));
    assert_eq!(signal(x, 0x6061, 0).0, json!(1));
    assert_eq!(signal(x, 0x6064, 0), (json!(100500), "100500 Pul".to_string()));
    // 1601h: "60FF0020", "60710010"; 1A01h: "606C0020", "60770010"
    let x = f.at(7, 0x301, "204E00002C01");
    assert_eq!(signal(x, 0x6071, 0), (json!(300), "30 %".to_string()));
    let x = f.at(9, 0x281, "164E00007D00");
    assert_eq!(signal(x, 0x6077, 0), (json!(125), "12.5 %".to_string()));
}

/// CSP/CSV/CST statusword bits (mode from the 6060h write): bit 12 "drive follows the command
/// value" (clear while enabled: "target ignored"), bit 13 following error in CSP; in the
/// default TPDO1 (6041h) as well as in SDO uploads.
#[test]
fn cyclic_mode_statusword_bits() {
    let log = "\
(0.000) can0 601#2F60600008000000
(0.0005) can0 581#6060600000000000
(0.001) can0 581#4B41600037020000
(0.002) can0 581#4B41600037360000
(0.003) can0 181#3716080000000000
(0.010) can0 601#2F6060000A000000
(0.0105) can0 581#6060600000000000
(0.011) can0 581#4B41600037120000
";
    let f = seed_common::decode(&["1=aimotor"], log);
    let label = |line: u64, id: u32, data: &str| f.at(line, id, data)["label"].as_str().unwrap().to_string();
    let l = label(3, 0x581, "4B41600037020000");
    assert!(l.contains("remote, target ignored]"), "{l}");
    let l = label(4, 0x581, "4B41600037360000");
    assert!(
        l.contains("remote, bit 10 (reserved in CSP), drive follows the command value, following error]"),
        "{l}"
    );
    let x = f.at(5, 0x181, "3716080000000000");
    let (_, text) = seed_common::signal(x, 0x6041, 0);
    assert!(text.contains("drive follows the command value]"), "{text}");
    let l = label(8, 0x581, "4B41600037120000");
    assert!(l.contains("drive follows the command value]"), "{l}");
    assert!(!l.contains("following error"), "{l}");
}

#[test]
fn error_history_entries_carry_the_cia402_code_and_the_fault_code() {
    // 1003h 01h..0Ah: "bit0-bit15 CiA 402 error code, bit16-bit31 AIMOTOR fault code"; fault 0101h -> 6320h.
    let log = "(0.000) can0 601#4003100100000000\n(0.001) can0 581#4303100120630101\n";
    let f = seed_common::decode(&["1=aimotor"], log);
    seed_common::label_has(
        f.at(2, 0x581, "4303100120630101"),
        &[
            "Standard error field 1 = 0x01016320 (error code 0x6320 Parameter error",
            "AIMOTOR fault code 0x0101 (Fault 0101h: 603Fh/EMCY 0x6320 (Parameter error), class NO.1))",
        ],
    );
}

#[test]
fn fault_table_of_section_6_1_row_by_row() {
    let f = frames();
    // "fault name | H0B_34 | 603Fh | ... | class": every row, read back from H0B-34 and from 603Fh
    let rows: [(u16, u16, &str, u8); 27] = [
        (0x0101, 0x6320, "Parameter error", 1),
        (0x0102, 0x6320, "Parameter error", 1),
        (0x0104, 0x6320, "Parameter error", 1),
        (0x0105, 0x6320, "Parameter error", 1),
        (0x0130, 0x6320, "Parameter error", 1),
        (0x0201, 0x2312, "Continuous over-current no. 2", 1),
        (0x0208, 0xFF00, "Device specific", 1),
        (0x0207, 0x2311, "Continuous over-current no. 1", 1),
        (0x0234, 0xFF00, "Device specific", 1),
        (0x0A33, 0x7306, "Incremental sensor 2 fault", 1),
        (0x0400, 0x3210, "DC link over-voltage", 1),
        (0x0410, 0x3220, "DC link under-voltage", 1),
        (0x0620, 0x3230, "Load error", 1),
        (0x0650, 0x4210, "Excess temperature device", 1),
        (0x0B00, 0x8611, "Following error", 1),
        (0x0668, 0xFF00, "Device specific", 2),
        (0x0601, 0x8610, "Positioning controller", 2),
        (0x0900, 0x5442, "Contacts", 3),
        (0x0950, 0x5443, "Contacts", 3),
        (0x0952, 0x5444, "Contacts", 3),
        (0x0731, 0x7306, "Incremental sensor 2 fault", 2),
        (0x0733, 0x7306, "Incremental sensor 2 fault", 2),
        (0x0735, 0x7306, "Incremental sensor 2 fault", 2),
        (0x0730, 0x7307, "Incremental sensor 3 fault", 3),
        (0x0D03, 0x8130, "Life guard error or heartbeat error", 2),
        (0x0941, 0xFF00, "Device specific", 3),
        (0x0942, 0x7600, "Data storage", 3),
    ];
    for (i, (fault, code, text, class)) in rows.into_iter().enumerate() {
        let data = format!("4B0B2023{:02X}{:02X}0000", fault & 0xFF, fault >> 8);
        let x = f.at(128 + i as u64, 0x581, &data);
        sdo(x, "sdo_tx", 1, 0x200B, 0x23, Some(i64::from(fault)));
        let want = format!("Fault {fault:04X}h: 603Fh/EMCY 0x{code:04X} ({text}), class NO.{class}");
        assert_eq!(x["sdo"]["value_text"], format!("{fault} ({want})"));
        let data = format!("4B3F6000{:02X}{:02X}0000", code & 0xFF, code >> 8);
        let x = f.at(155 + i as u64, 0x581, &data);
        sdo(x, "sdo_tx", 1, 0x603F, 0, Some(i64::from(code)));
        assert_eq!(x["sdo"]["value_text"], format!("{code} ({text})"));
    }
}

#[test]
fn cia301_object_table_of_section_2_1_1() {
    let f = frames();
    // "1014 ... Uint32 RO 0x80+ID"
    let x = f.at(185, 0x581, "4314100081000000");
    sdo(x, "sdo_tx", 1, 0x1014, 0, Some(0x81));
    assert_eq!(x["sdo"]["value_text"], "0x00000081 (COB-ID 0x081)");
    // 3.2 guarding example: 100Ch = 50 ms, 100Dh = 2
    assert_eq!(
        f.at(186, 0x601, "2B0C100032000000")["label"],
        "Download 0x100C:00 Guard time = 50 ms"
    );
    assert_eq!(
        f.at(187, 0x601, "2F0D100002000000")["label"],
        "Download 0x100D:00 Life time factor = 2"
    );
    // "1016 sub 1: bit0-bit15 ms, bit16-bit23 node-ID"
    let x = f.at(188, 0x601, "23161001F4010200");
    assert_eq!(x["sdo"]["value_text"], "0x000201F4 (node 2, time 500 ms)");
    // "1800 sub 1 TPDO1 COB-ID ... 0x180+ID": read 0x181; printed RO, but the drive accepts the
    // write of 5.4 (bit 31 set to disable TPDO1) with 60h
    label_has(
        f.at(189, 0x581, "4300180181010000"),
        &["COB-ID used by TPDO = 0x00000181 (COB-ID 0x181)"],
    );
    label_has(
        f.at(190, 0x601, "2300180181010080"),
        &["COB-ID 0x181, invalid/disabled"],
    );
    assert_eq!(f.at(191, 0x581, "6000180100000000")["sdo"]["cs"], "initiate_download");

    use cotui::od::json::load_profile;
    use cotui::od::{Access, Dictionary, Value};
    use std::sync::Arc;
    let path = format!("{}/decoders/aimotor.json", env!("CARGO_MANIFEST_DIR"));
    let (p, _) = load_profile(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let d = Dictionary::new(vec![Arc::new(p)]);
    let o = |i: u16, s: u8| d.object(i, s).unwrap_or_else(|| panic!("0x{i:04X}:{s}"));
    // "1005 0 ... Uint32 RO 0x80", "1016 0 ... Uint8 RO 1", "1200 0 Uint8 RO 2", "100C ... 0~32767"
    assert_eq!(
        (o(0x1005, 0).access, o(0x1005, 0).default.clone()),
        (Access::Ro, Some(Value::Unsigned(0x80)))
    );
    assert_eq!(o(0x1016, 0).default, Some(Value::Unsigned(1)));
    assert_eq!(o(0x1200, 0).default, Some(Value::Unsigned(2)));
    assert_eq!((o(0x100C, 0).max, o(0x100D, 0).max), (Some(32767), Some(255)));
    for i in [0x1400, 0x1403, 0x1800, 0x1803] {
        assert_eq!(o(i, 1).access, Access::Rw, "0x{i:04X}:1 is written by the 5.4 list");
    }
    assert_eq!((o(0x1014, 0).access, o(0x1200, 1).access), (Access::Ro, Access::Ro));
    assert_eq!(
        o(0x1017, 0).data_type,
        o(0x100C, 0).data_type,
        "1017h is UNSIGNED16 as 100Ch"
    );
}

#[test]
fn cia402_object_table_ranges_and_digital_outputs() {
    let f = frames();
    // 2.11: mask bit 0 in 60FEh sub 2, then 60FEh sub 1 bit 0 drives the output
    label_has(f.at(193, 0x601, "23FE600201000000"), &["0x60FE:02 Bit mask = 1"]);
    label_has(
        f.at(194, 0x601, "23FE600101000000"),
        &["0x60FE:01 Physical outputs = 1"],
    );
    // 2.1.3: "607D 0 ... Uint8 RO 2"
    sdo(f.at(195, 0x581, "4F7D600002000000"), "sdo_tx", 1, 0x607D, 0, Some(2));

    use cotui::od::json::load_profile;
    use cotui::od::{Dictionary, Value};
    use std::sync::Arc;
    let path = format!("{}/decoders/aimotor.json", env!("CARGO_MANIFEST_DIR"));
    let (p, _) = load_profile(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let d = Dictionary::new(vec![Arc::new(p)]);
    let o = |i: u16, s: u8| d.object(i, s).unwrap_or_else(|| panic!("0x{i:04X}:{s}"));
    // "6071 ... Int16 RW 0 -3000~3000", "6074/6077 ... -3000~3000", "6078 ... -32767~32767"
    assert_eq!((o(0x6071, 0).min, o(0x6071, 0).max), (Some(-3000), Some(3000)));
    assert_eq!((o(0x6074, 0).min, o(0x6077, 0).max), (Some(-3000), Some(3000)));
    assert_eq!(o(0x6078, 0).max, Some(32767));
    // defaults 0 of 607A/607C/607E/607F/6081/60FF/6071; 60FEh sub 2 = 0
    for i in [0x607A, 0x607C, 0x607E, 0x607F, 0x6081, 0x60FF, 0x6071] {
        let v = o(i, 0).default.clone();
        assert!(
            matches!(v, Some(Value::Unsigned(0) | Value::Signed(0))),
            "0x{i:04X}: {v:?}"
        );
    }
    assert_eq!(o(0x60FE, 0).default, Some(Value::Unsigned(2)));
    assert_eq!(o(0x60FE, 1).bits[&0], "Set brake");
    assert!(
        o(0x60FE, 1)
            .description
            .as_deref()
            .unwrap()
            .contains("60FEh sub 2 is 1")
    );
}
