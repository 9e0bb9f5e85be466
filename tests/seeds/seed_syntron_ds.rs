//! Syn-tron DS/RS (manual 002): every CAN worked example of the manual through
//! `cotui decode --format jsonl --profile N=syntron-ds`. Frames are in
//! `tests/fixtures/seeds/syntron-ds.log` (line numbers below) with the manual's lines as comments.
//! The manual's Modbus RTU frames (`01 06 ...`, `01 43 ...`) are not CAN traffic and are left out.

use crate::seed_common;
use seed_common::{decode, fixture, label_has, run, sdo, signal};
use serde_json::json;

fn frames() -> seed_common::Frames {
    decode(&["2=syntron-ds", "1=syntron-ds"], &fixture("syntron-ds.log"))
}

#[test]
fn nmt_heartbeat_and_life_guarding() {
    let f = frames();
    // 3.6.1: "000h 01h 06h  // start node 6"
    let x = f.at(3, 0x000, "0106");
    assert_eq!(x["kind"], "nmt");
    assert_eq!(x["nmt"], json!({"command": "start", "target": 6}));
    // "000h 01h 00h  // all nodes"
    assert_eq!(f.at(4, 0x000, "0100")["nmt"]["target"], 0);
    // "702 00" boot-up of node 2
    let x = f.at(6, 0x702, "00");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("heartbeat"), Some(2)));
    assert_eq!(x["heartbeat"]["state"], "boot_up");
    // "602 2B 17 10 00 00 ..." heartbeat off, "602 2B 17 10 00 64 ..." 100 ms
    sdo(f.at(8, 0x602, "2B17100000000000"), "sdo_rx", 2, 0x1017, 0, Some(0));
    let x = f.at(9, 0x602, "2B17100064000000");
    sdo(x, "sdo_rx", 2, 0x1017, 0, Some(100));
    assert_eq!(x["sdo"]["value_text"], "100 ms");
    // Life guard example 1: "702 -" (remote request), "702 FF" (toggle 1, pre-operational), "702 7F" (toggle 0)
    let x = f.at(11, 0x702, "");
    assert_eq!(x["rtr"], true);
    assert_eq!(x["heartbeat"]["request"], true);
    let x = f.at(12, 0x702, "FF");
    assert_eq!(
        x["heartbeat"],
        json!({"state": "pre_operational", "toggle": true, "request": false})
    );
    let x = f.at(14, 0x702, "7F");
    assert_eq!(
        x["heartbeat"],
        json!({"state": "pre_operational", "toggle": false, "request": false})
    );
    // Life guard example 2: "000 01 02  start node 2", "702 85" (toggle 1, operational), "702 05"
    assert_eq!(f.at(16, 0x000, "0102")["nmt"], json!({"command": "start", "target": 2}));
    let x = f.at(18, 0x702, "85");
    assert_eq!(
        x["heartbeat"],
        json!({"state": "operational", "toggle": true, "request": false})
    );
    label_has(x, &["node 2", "Operational", "toggle 1"]);
    assert_eq!(f.at(20, 0x702, "05")["heartbeat"]["state"], "operational");
}

#[test]
fn sdo_examples_of_section_3_6_3() {
    let f = frames();
    // "602 40 00 30 00 00 00 00 00": upload 0x3000 (the manual calls it Dn00; by its own rule
    // Fx.y.z -> 0x2000 + 0x1000*x + ... it is F1.0.000).
    let x = f.at(22, 0x602, "4000300000000000");
    sdo(x, "sdo_rx", 2, 0x3000, 0, None);
    assert_eq!(x["sdo"]["cs"], "initiate_upload");
    // "582 4B 00 30 00 64 00 00 00  100rpm"
    sdo(f.at(23, 0x582, "4B00300064000000"), "sdo_tx", 2, 0x3000, 0, Some(100));
    // "602 2B 33 20 00 C8 00 00 00  Fn33 = 200RPM", "582 60 33 20 00 C8 00 00 00"
    sdo(f.at(25, 0x602, "2B332000C8000000"), "sdo_rx", 2, 0x2033, 0, Some(200));
    let x = f.at(26, 0x582, "60332000C8000000");
    sdo(x, "sdo_tx", 2, 0x2033, 0, None);
    assert_eq!(x["label"], "Download response 0x2033:00");
}

#[test]
fn parameter_writes_of_section_1_5_2() {
    let f = frames();
    // "601 2B 0A 45 00 01 00 00 00  save to flash on" (Pn5.00A = 1)
    let x = f.at(81, 0x601, "2B0A450001000000");
    sdo(x, "sdo_rx", 1, 0x450A, 0, Some(1));
    label_has(x, &["Pn5.00A", "Save to flash"]);
    // "601 2B 02 21 00 01 00 00 00  F0.1.002 = 1 (speed mode)"
    let x = f.at(82, 0x601, "2B02210001000000");
    sdo(x, "sdo_rx", 1, 0x2102, 0, Some(1));
    label_has(x, &["A control mode (F0.1.002)", "Speed mode"]);
    // "601 2B 0A 45 00 00 00 00 00  save to flash off"
    label_has(f.at(83, 0x601, "2B0A450000000000"), &["Pn5.00A", "RAM only"]);
}

#[test]
fn rpdo_mapping_example_is_learned_and_used() {
    let f = frames();
    // "602 2F 00 16 00 00 ...  RPDO1 stop"; "602 23 00 16 01 20 00 FF 60  60FFh RPDO1 sub1";
    // "602 2F 00 16 00 01 ...  RPDO1 enable"
    sdo(f.at(29, 0x602, "2F00160000000000"), "sdo_rx", 2, 0x1600, 0, Some(0));
    sdo(
        f.at(31, 0x602, "230016012000FF60"),
        "sdo_rx",
        2,
        0x1600,
        1,
        Some(0x60FF0020),
    );
    sdo(f.at(33, 0x602, "2F00160001000000"), "sdo_rx", 2, 0x1600, 0, Some(1));
    // "602 23 01 16 01 10 00 40 60  6040h RPDO2 sub1", "602 23 01 16 02 20 00 FF 60  60FFh RPDO2 sub2"
    sdo(
        f.at(37, 0x602, "2301160110004060"),
        "sdo_rx",
        2,
        0x1601,
        1,
        Some(0x60400010),
    );
    sdo(
        f.at(39, 0x602, "230116022000FF60"),
        "sdo_rx",
        2,
        0x1601,
        2,
        Some(0x60FF0020),
    );
    sdo(f.at(41, 0x602, "2F01160002000000"), "sdo_rx", 2, 0x1601, 0, Some(2));
    // "202 64 00 00 00 -> RPDO1 60FFh = 100" (0.1 rpm: 10 rpm)
    let x = f.at(44, 0x202, "64000000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("rpdo"), Some(2)));
    assert_eq!(signal(x, 0x60FF, 0), (json!(100), "10 rpm".to_string()));
    assert!(x["pdo"]["mapping_source"].as_str().unwrap().starts_with("sniffed"));
    // "302 06 00 64 00 00 00 -> 6040h = 6, 60FFh = 100"
    let x = f.at(45, 0x302, "060064000000");
    assert_eq!(signal(x, 0x6040, 0).0, json!(6));
    assert!(signal(x, 0x6040, 0).1.contains("Shutdown"), "{x}");
    assert_eq!(signal(x, 0x60FF, 0), (json!(100), "10 rpm".to_string()));
}

#[test]
fn tpdo_mapping_examples() {
    let f = frames();
    // TPDO1: "602 23 00 1A 01 10 00 41 60  6041h"; "602 2F 00 18 05 32  50ms"; "602 2F 00 18 02 FE  254"
    sdo(
        f.at(49, 0x602, "23001A0110004160"),
        "sdo_rx",
        2,
        0x1A00,
        1,
        Some(0x60410010),
    );
    sdo(f.at(51, 0x602, "2F00180532000000"), "sdo_rx", 2, 0x1800, 5, Some(50));
    sdo(f.at(52, 0x602, "2F00180332000000"), "sdo_rx", 2, 0x1800, 3, Some(50));
    sdo(f.at(53, 0x602, "2F001802FE000000"), "sdo_rx", 2, 0x1800, 2, Some(254));
    // TPDO2: "602 23 01 1A 01 20 00 63 60  6063h", "602 23 01 1A 02 20 00 69 60  6069h"
    sdo(
        f.at(57, 0x602, "23011A0120006360"),
        "sdo_rx",
        2,
        0x1A01,
        1,
        Some(0x60630020),
    );
    sdo(
        f.at(58, 0x602, "23011A0220006960"),
        "sdo_rx",
        2,
        0x1A01,
        2,
        Some(0x60690020),
    );
    sdo(f.at(62, 0x602, "2F011802FE000000"), "sdo_rx", 2, 0x1801, 2, Some(254));
}

#[test]
fn vendor_emcy_codes() {
    let f = frames();
    // 3.6.2: "CCW_Disable 0x8681", "CW_Disable 0x8682", "POS_Arrived 0x8683", "Home_Done 0x8684"
    for (line, data, code, text) in [
        (65, "8186000000000000", 0x8681, "CCW_Disable"),
        (66, "8286000000000000", 0x8682, "CW_Disable"),
        (67, "8386000000000000", 0x8683, "POS_Arrived"),
        (68, "8486000000000000", 0x8684, "Home_Done"),
    ] {
        let x = f.at(line, 0x082, data);
        assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("emcy"), Some(2)));
        assert_eq!(x["emcy"]["code"], code);
        assert!(x["emcy"]["text"].as_str().unwrap().starts_with(text), "{x}");
    }
}

#[test]
fn vendor_can_mode_of_section_3_8() {
    let f = frames();
    // "602 2B 18 23 00 64 00 00 00  // A speed 100rpm"
    let x = f.at(71, 0x602, "2B18230064000000");
    sdo(x, "sdo_rx", 2, 0x2318, 0, Some(100));
    assert_eq!(x["sdo"]["value_text"], "100 rpm");
    assert_eq!(x["label"], "Download 0x2318:00 A speed command (F0.3.018) = 100 rpm");
    // "602 2B 00 21 00 01 00 00 00  // 1: enable axis A"
    let x = f.at(72, 0x602, "2B00210001000000");
    sdo(x, "sdo_rx", 2, 0x2100, 0, Some(1));
    label_has(x, &["A run enable (F0.1.000)", "Run"]);
    // "602 40 00 50 00 00 00 00 00  // read A speed, rpm" (D0.00)
    let x = f.at(73, 0x602, "4000500000000000");
    sdo(x, "sdo_rx", 2, 0x5000, 0, None);
    label_has(x, &["A actual speed (D0.00)"]);
}

#[test]
fn two_axis_vendor_commands_e8_e9() {
    let f = frames();
    // 3.8.1: "601 E8 04 50 00 00 00 00 00  // read 0x5004 and 0x5104, axis A is the master"
    let x = f.at(75, 0x601, "E804500000000000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("sdo_rx"), Some(1)));
    assert_eq!(x["vendor_sdo"]["name"], "Read axis A and B");
    assert_eq!(x["vendor_sdo"]["fields"][0]["raw"], 0x5004);
    assert!(x.get("malformed").is_none(), "{x}");
    // "581 E8 04 50 00 B7 13 AB 12  // D0.04=5047, D1.04=4779"
    let x = f.at(76, 0x581, "E8045000B713AB12");
    let fields = &x["vendor_sdo"]["fields"];
    assert_eq!(
        (fields[2]["index"].as_u64(), fields[2]["raw"].as_i64()),
        (Some(0x5004), Some(5047))
    );
    assert_eq!(
        (fields[3]["index"].as_u64(), fields[3]["raw"].as_i64()),
        (Some(0x5104), Some(4779))
    );
    label_has(x, &["(D0.04) = 5047", "(D1.04) = 4779"]);
    // "601 E9 18 23 00 36 00 CA FF  // write 0x2318 and 0x3318 = 54 and -54"
    let x = f.at(78, 0x601, "E91823003600CAFF");
    let fields = &x["vendor_sdo"]["fields"];
    assert_eq!(
        (fields[2]["index"].as_u64(), fields[2]["raw"].as_i64()),
        (Some(0x2318), Some(54))
    );
    assert_eq!(
        (fields[3]["index"].as_u64(), fields[3]["raw"].as_i64()),
        (Some(0x3318), Some(-54))
    );
    label_has(
        x,
        &[
            "A speed command (F0.3.018) = 54 rpm",
            "B speed command (F1.3.018) = -54 rpm",
        ],
    );
    // "581 60 18 23 00 64 00 CA FF  // written" (a standard download response)
    let x = f.at(79, 0x581, "601823006400CAFF");
    sdo(x, "sdo_tx", 1, 0x2318, 0, None);
    assert_eq!(x["sdo"]["cs"], "initiate_download");
}

/// `cotui decode --profile 2=syntron-ds` on the PV procedure (manual 3.7.1) reads like the
/// manual's commentary: vendor names, aliases and scaled values with units.
#[test]
fn pv_procedure_reads_like_the_manual() {
    let lines = run(&["--profile", "2=syntron-ds"], &fixture("syntron-ds-pv.log"));
    let expect = [
        // STEP1 "F0/1.1.002=20" (CANopen control)
        "Download 0x2102:00 A control mode (F0.1.002) = 20 (CANopen (CiA 402))",
        // STEP2 "000 01 02 // start node 2"
        "NMT Start remote node -> node 2",
        // "602 2F 60 60 00 03 // 6060h = 3 (PV)"
        "Download 0x6060:00 Modes of operation = 3 (Profile velocity)",
        // "602 23 83 60 00 E8 03 // 6083h = 1s", "602 23 84 60 00 E8 03 // 6084h = 1s"
        "Download 0x6083:00 Profile acceleration = 1000 ms",
        "Download 0x6084:00 Profile deceleration = 1000 ms",
        // "602 23 FF 60 00 64 00 00 00 // 60FFh = 10rpm"
        "Download 0x60FF:00 Target velocity = 10 rpm",
        // "602 2B 40 60 00 06 // 6040h = 6", "07 // 6040h = 7", "0F // 6040h = F, enabled"
        "Download 0x6040:00 Controlword = 0x0006 (Shutdown)",
        // (the profile's value text, the manual's "switch on", names the controlword value)
        "Download 0x6040:00 Controlword = 0x0007 (Switch on)",
        "Download 0x6040:00 Controlword = 0x000F (Enable operation)",
    ];
    assert_eq!(lines.len(), expect.len(), "{lines:#?}");
    for (line, want) in lines.iter().zip(expect) {
        assert!(line.ends_with(want), "`{line}` should end with `{want}`");
    }
}

#[test]
fn pv_monitoring_tpdos_after_sync() {
    let f = decode(&["2=syntron-ds"], &fixture("syntron-ds-modes.log"));
    // 3.7.1 step 4: "602 23 00 1A 01 20 00 69 60 // 6069h", "602 23 00 1A 02 20 00 63 60 // 6063h"
    sdo(
        f.at(7, 0x602, "23001A0120006960"),
        "sdo_rx",
        2,
        0x1A00,
        1,
        Some(0x60690020),
    );
    sdo(
        f.at(9, 0x602, "23001A0220006360"),
        "sdo_rx",
        2,
        0x1A00,
        2,
        Some(0x60630020),
    );
    // "602 2F 00 18 02 01 00 00 00 // synchronous"
    sdo(f.at(13, 0x602, "2F00180201000000"), "sdo_rx", 2, 0x1800, 2, Some(1));
    // "602 23 01 1A 01 10 00 41 60 // 0x6041"
    sdo(
        f.at(19, 0x602, "23011A0110004160"),
        "sdo_rx",
        2,
        0x1A01,
        1,
        Some(0x60410010),
    );
    // "080 // SYNC"
    assert_eq!(f.at(28, 0x080, "")["kind"], "sync");
    // "182 byte0-7 // TPDO1": 6069h in 0.1 rpm and 6063h
    let x = f.at(29, 0x182, "E803000060EA0000");
    assert_eq!((x["kind"].as_str(), x["node"].as_u64()), (Some("tpdo"), Some(2)));
    assert_eq!(signal(x, 0x6069, 0), (json!(1000), "100 rpm".to_string()));
    assert_eq!(signal(x, 0x6063, 0).0, json!(60000));
    // "282 byte0-1 // TPDO2": the statusword, 0x37 = operation enabled (manual 3.4.2)
    let x = f.at(30, 0x282, "3702");
    let (v, text) = signal(x, 0x6041, 0);
    assert_eq!(v, json!(0x0237));
    assert!(text.contains("Operation enabled"), "{text}");
}

#[test]
fn pp_pt_hm_procedures() {
    let f = decode(&["2=syntron-ds"], &fixture("syntron-ds-modes.log"));
    // 3.7.2: "602 2F 60 60 00 01 // 6060h = 1 (Profile Position Mode)"
    let x = f.at(33, 0x602, "2F60600001000000");
    sdo(x, "sdo_rx", 2, 0x6060, 0, Some(1));
    label_has(x, &["Profile position"]);
    // "602 23 7A 60 00 60 EA 00 00 // 60000 pulses"
    assert_eq!(f.at(34, 0x602, "237A600060EA0000")["sdo"]["value_text"], "60000 pulse");
    // "602 23 81 60 00 B8 0B 00 00 // 300rpm"
    assert_eq!(f.at(35, 0x602, "23816000B80B0000")["sdo"]["value_text"], "300 rpm");
    // "602 2B 93 60 01 01 ... numerator", "602 2B 93 60 02 01 ... divisor"
    sdo(f.at(38, 0x602, "2B93600101000000"), "sdo_rx", 2, 0x6093, 1, Some(1));
    sdo(f.at(39, 0x602, "2B93600201000000"), "sdo_rx", 2, 0x6093, 2, Some(1));
    // "602 2B 40 60 00 5F // new position (relative)", "4F", "1F // new position (absolute)", "0F"
    for (line, data, cw) in [
        (44, "2B4060005F000000", 0x5F),
        (45, "2B4060004F000000", 0x4F),
        (46, "2B4060001F000000", 0x1F),
        (47, "2B4060000F000000", 0x0F),
    ] {
        sdo(f.at(line, 0x602, data), "sdo_rx", 2, 0x6040, 0, Some(cw));
    }
    // 3.7.3: "602 2F 60 60 00 04 // 6060h = 4 (torque)"
    label_has(f.at(51, 0x602, "2F60600004000000"), &["Profile torque"]);
    // "602 2F 87 60 00 E8 03 00 00 // 6087H = 1000" (sent here as 0x23, see the fixture)
    sdo(f.at(52, 0x602, "23876000E8030000"), "sdo_rx", 2, 0x6087, 0, Some(1000));
    // "602 2F 71 60 00 64 00 00 00 // 100 = 10%"
    let x = f.at(53, 0x602, "2B71600064000000");
    sdo(x, "sdo_rx", 2, 0x6071, 0, Some(100));
    assert_eq!(x["sdo"]["value_text"], "10 %");
    // 3.7.4: "602 2F 60 60 00 06 // homing", "602 2F 98 60 00 14 // 6098H = 20"
    label_has(f.at(59, 0x602, "2F60600006000000"), &["Homing"]);
    sdo(f.at(60, 0x602, "2F98600014000000"), "sdo_rx", 2, 0x6098, 0, Some(20));
    // "602 23 99 60 01 D0 07 00 00" (200 rpm), "602 23 99 60 02 C8 00 00 00" (20 rpm), 0.1 rpm units
    assert_eq!(f.at(61, 0x602, "23996001D0070000")["sdo"]["value_text"], "200 rpm");
    assert_eq!(f.at(62, 0x602, "23996002C8000000")["sdo"]["value_text"], "20 rpm");
    // "602 23 9A 60 00 E8 03 00 00" (1 s)
    assert_eq!(f.at(63, 0x602, "239A6000E8030000")["sdo"]["value_text"], "1000 ms");
    // "602 2B 40 60 00 5F // start homing", "602 2B 40 60 00 4F"
    sdo(f.at(70, 0x602, "2B4060005F000000"), "sdo_rx", 2, 0x6040, 0, Some(0x5F));
    sdo(f.at(71, 0x602, "2B4060004F000000"), "sdo_rx", 2, 0x6040, 0, Some(0x4F));
}

/// Controlword and statusword bits 4/5/6 and 10/12/13 are named per the mode in force
/// (learned from the 6060h write), with the profile's value texts ("start relative (bits 4, 6)").
#[test]
fn mode_specific_bits_follow_the_mode_in_force() {
    let log = "\
(0.000) can0 602#2B4060005F000000
(0.0005) can0 582#6040600000000000
(0.001) can0 602#2F60600001000000
(0.0015) can0 582#6060600000000000
(0.002) can0 602#2B4060005F000000
(0.0025) can0 582#6040600000000000
(0.003) can0 582#4B41600037160000
(0.004) can0 582#4B41600037260000
(0.010) can0 602#2F60600006000000
(0.0105) can0 582#6060600000000000
(0.011) can0 602#2B4060001F000000
(0.0115) can0 582#6040600000000000
(0.012) can0 582#4B41600037160000
(0.013) can0 582#4B41600037260000
(0.020) can0 602#2F60600003000000
(0.0205) can0 582#6060600000000000
(0.021) can0 582#4B41600037120000
(0.022) can0 582#4B41600037220000
";
    let f = decode(&["2=syntron-ds"], log);
    let value = |line: u64, id: u32, data: &str| f.at(line, id, data)["label"].as_str().unwrap().to_string();
    // Mode unknown: the profile's text for 0x005F says what bits 4 and 6 do.
    let l = value(1, 0x602, "2B4060005F000000");
    assert!(
        l.ends_with("= 0x005F (Enable operation, start relative (bits 4, 6))"),
        "{l}"
    );
    // PP (3.7.2 step 7 "5F"): new set-point + relative; set-point acknowledge, following error.
    let l = value(5, 0x602, "2B4060005F000000");
    assert!(
        l.ends_with("(Enable operation, start relative (bits 4, 6) [new set-point, relative])"),
        "{l}"
    );
    let l = value(7, 0x582, "4B41600037160000");
    assert!(l.contains("target reached, set-point acknowledge]"), "{l}");
    let l = value(8, 0x582, "4B41600037260000");
    assert!(l.contains("target reached, following error]"), "{l}");
    // HM (3.7.4): start homing; homing attained / homing error.
    let l = value(11, 0x602, "2B4060001F000000");
    assert!(l.ends_with("[start homing])"), "{l}");
    let l = value(13, 0x582, "4B41600037160000");
    assert!(l.contains("target reached, homing attained]"), "{l}");
    let l = value(14, 0x582, "4B41600037260000");
    assert!(l.contains("remote, target reached, homing error]"), "{l}");
    // PV: speed is zero / max slippage error.
    let l = value(17, 0x582, "4B41600037120000");
    assert!(l.contains("remote, speed is zero]"), "{l}");
    let l = value(18, 0x582, "4B41600037220000");
    assert!(l.contains("remote, max slippage error]"), "{l}");
    assert!(!f.0.iter().any(|x| x["label"].as_str().unwrap().contains("mode bit")));
    // The reassembled transfers (`--transactions`) name the bits the same way.
    let t = run(&["--transactions", "--profile", "2=syntron-ds"], log);
    assert!(
        t.iter()
            .any(|l| l.contains("= 0x005F (Enable operation, start relative (bits 4, 6) [new set-point, relative])")),
        "{t:#?}"
    );
    assert!(
        t.iter()
            .any(|l| l.contains("= 0x001F (Enable operation, start (bit 4) [start homing])")),
        "{t:#?}"
    );
}

#[test]
fn statusword_values_of_section_3_4_2() {
    let f = frames();
    // "6041H = 0x0050" at power on (bit 9 remote with it), "0x31" after controlword 6, "0x33" after 7,
    // "0x37" after F, "0x0088" on a fault
    for (line, data, value, state) in [
        (86, "4B41600050020000", 0x0250, "Switch on disabled"),
        (87, "4B41600031020000", 0x0231, "Ready to switch on"),
        (88, "4B41600033020000", 0x0233, "Switched on"),
        (89, "4B41600037020000", 0x0237, "Operation enabled"),
        (90, "4B41600088000000", 0x0088, "Fault"),
    ] {
        let x = f.at(line, 0x582, data);
        sdo(x, "sdo_tx", 2, 0x6041, 0, Some(value));
        let text = x["sdo"]["value_text"].as_str().unwrap();
        assert!(text.starts_with(&format!("0x{value:04X} ({state} [")), "{text}");
    }
}

#[test]
fn controlword_and_statusword_bits_of_sections_3_4_1_and_3_4_2() {
    // 3.4.1: "Bit8 Halt, Bit7 Fault Reset, Bit6-4 Operation mode specific, Bit3 Enable Operation,
    // Bit2 Quick Stop, Bit1 Enable Voltage, Bit0 Switch on"; "write 0x06, 0x07, 0x0F to enable,
    // 0x07 disables the motor again".
    // 3.4.2: "Bit11 Internal Limit Active, Bit10 Target Reached, Bit9 Remote, Bit7 Warning, Bit6
    // Switch On Disabled, Bit5 Quick Stop, Bit4 Voltage Enabled, Bit3 Fault, Bit2 Operation Enabled,
    // Bit1 Switched On, Bit0 Ready to Switch On".
    let log = "\
(0.000) can0 602#2B4060008F010000
(0.001) can0 602#2B40600007000000
(0.002) can0 582#4B416000370E0000
(0.003) can0 582#4B416000B80E0000
";
    let f = decode(&["2=syntron-ds"], log);
    let x = f.at(1, 0x602, "2B4060008F010000");
    label_has(x, &["Controlword = 0x018F", "Fault reset", "halt"]);
    label_has(f.at(2, 0x602, "2B40600007000000"), &["Controlword = 0x0007 (Switch on"]);
    label_has(
        f.at(3, 0x582, "4B416000370E0000"),
        &[
            "Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote, target reached, internal limit active]",
        ],
    );
    label_has(
        f.at(4, 0x582, "4B416000B80E0000"),
        &["Fault [fault, voltage enabled, quick stop, warning, remote, target reached, internal limit active]"],
    );
}

#[test]
fn pdo_configuration_parameters_of_section_3_6_4_read_like_the_objects_they_set() {
    // 3.6.4's Fn example, written by SDO: RPDO1 "F0.7.000 2, F0.7.001 513, F0.7.005 24640,
    // F0.7.007 24672" (6040h + 6060h on 0x201); TPDO1 "F0.7.041 385, F0.7.042 1, F0.7.045 24641,
    // F0.7.049 24639" (6041h ... 603Fh on 0x181, every SYNC); B: "F1.7.011 769".
    let log = "\
(0.000) can0 602#2B00270002000000
(0.001) can0 602#2B01270001020000
(0.002) can0 602#2B05270040600000
(0.003) can0 602#2B07270060600000
(0.004) can0 602#2B41270081010000
(0.005) can0 602#2B42270001000000
(0.006) can0 602#2B45270041600000
(0.007) can0 602#2B4927003F600000
(0.008) can0 602#2B11370001030000
(0.009) can0 602#2B52370002000000
";
    let f = decode(&["2=syntron-ds"], log);
    label_has(
        f.at(1, 0x602, "2B00270002000000"),
        &["A RPDO1 number of mapped objects (F0.7.000) = 2"],
    );
    label_has(
        f.at(2, 0x602, "2B01270001020000"),
        &["A RPDO1 COB-ID (F0.7.001)", "(COB-ID 0x201)"],
    );
    label_has(
        f.at(3, 0x602, "2B05270040600000"),
        &["(F0.7.005) = 24640 (0x6040 Controlword)"],
    );
    label_has(
        f.at(4, 0x602, "2B07270060600000"),
        &["24672 (0x6060 Modes of operation)"],
    );
    label_has(
        f.at(5, 0x602, "2B41270081010000"),
        &["A TPDO1 COB-ID (F0.7.041)", "(COB-ID 0x181)"],
    );
    label_has(
        f.at(6, 0x602, "2B42270001000000"),
        &["(F0.7.042) = 1 (synchronous, every SYNC)"],
    );
    label_has(f.at(7, 0x602, "2B45270041600000"), &["24641 (0x6041 Statusword)"]);
    label_has(f.at(8, 0x602, "2B4927003F600000"), &["24639 (0x603F Error code)"]);
    label_has(
        f.at(9, 0x602, "2B11370001030000"),
        &["B RPDO2 COB-ID (F1.7.011)", "(COB-ID 0x301)"],
    );
    label_has(
        f.at(10, 0x602, "2B52370002000000"),
        &["(F1.7.052) = 2 (synchronous, every 2 SYNCs)"],
    );
}

#[test]
fn homing_switch_input_of_section_3_7_4() {
    // "the home switch is one of the input terminals Pn1.000~Pn1.007, set to 18"
    let f = decode(&["2=syntron-ds"], "(0.000) can0 602#2B03410012000000\n");
    label_has(
        f.at(1, 0x602, "2B03410012000000"),
        &["Input terminal 4 function (Pn1.003) = 18 (Home switch)"],
    );
}
