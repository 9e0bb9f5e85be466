//! The seed profiles' named procedures, expanded with their default parameters into the
//! frames an SDO client sends (expedited downloads, uploads, NMT, raw frames), reproduce the
//! manuals' step-by-step frame lists.

use cotui::od::bind::Bindings;
use cotui::od::procedure::{Step, fill_object, frame_bytes};
use cotui::od::{Dictionary, resolve_object};

/// `ID#DATA` lines (data without padding zeros of SDO frames kept: SDO frames are always 8 bytes).
fn expand(profile: &str, node: u8, procedure: &str) -> Vec<String> {
    let read = |p: &std::path::Path| std::fs::read(p);
    let b = Bindings::from_args(&[format!("{node}={profile}")], &[], &read).expect("binding");
    let dict: &Dictionary = b.dictionary(node);
    let p = dict
        .procedure(procedure)
        .unwrap_or_else(|| panic!("{profile} has no `{procedure}`"));
    let vars = |v: &str| {
        if v == "node" {
            return Some(i64::from(node));
        }
        p.params.iter().find(|q| q.name == v).and_then(|q| q.default)
    };
    let mut out = Vec::new();
    for step in &p.steps {
        match step {
            Step::SdoWrite {
                object,
                value,
                data_type,
            } => {
                let (index, sub) = resolve_object(dict, &fill_object(object, &vars).expect("object")).expect("object");
                let t = data_type
                    .or_else(|| dict.object(index, sub).map(|o| o.data_type))
                    .expect("type");
                let n = t.size().expect("fixed size");
                let cs = match n {
                    1 => 0x2F,
                    2 => 0x2B,
                    3 => 0x27,
                    _ => 0x23,
                };
                let v = value.eval(&vars).expect("value") as u32;
                let mut d = vec![cs, index as u8, (index >> 8) as u8, sub];
                d.extend_from_slice(&v.to_le_bytes()[..n.min(4)]);
                d.resize(8, 0);
                out.push(format!("{:03X}#{}", 0x600 + u32::from(node), hex(&d)));
            }
            Step::SdoRead { object } => {
                let (index, sub) = resolve_object(dict, &fill_object(object, &vars).expect("object")).expect("object");
                let d = [0x40, index as u8, (index >> 8) as u8, sub, 0, 0, 0, 0];
                out.push(format!("{:03X}#{}", 0x600 + u32::from(node), hex(&d)));
            }
            Step::Nmt { command, node: target } => {
                let t = target
                    .as_ref()
                    .map_or(i64::from(node), |e| e.eval(&vars).expect("node"));
                out.push(format!("000#{}", hex(&[command.specifier(), t as u8])));
            }
            Step::Frame { id, data } => {
                let id = id.eval(&vars).expect("id");
                out.push(format!("{id:03X}#{}", hex(&frame_bytes(data, &vars).expect("data"))));
            }
            Step::Wait { object, .. } => {
                // A wait reads the object (SDO upload) until it matches.
                let (index, sub) = resolve_object(dict, &fill_object(object, &vars).expect("object")).expect("object");
                let d = [0x40, index as u8, (index >> 8) as u8, sub, 0, 0, 0, 0];
                out.push(format!("{:03X}#{}", 0x600 + u32::from(node), hex(&d)));
            }
            Step::Delay { .. } => {}
        }
    }
    out
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02X}")).collect()
}

#[test]
fn syntron_pv_and_hm_match_the_manual_lists() {
    // 3.7.1 STEP1 "F0/1.1.002=20" (0x2102 = 20: "602 2B 02 21 00 14"), STEP2 "000 01 02", "602 2F 60 60 00 03", "602 23 83 60 00 E8 03", "602 23 84 60 00 E8 03",
    // "602 23 FF 60 00 64 00 00 00", "602 2B 40 60 00 06 / 07 / 0F"
    assert_eq!(
        expand("syntron-ds", 2, "pv"),
        [
            "602#2B02210014000000",
            "000#0102",
            "602#2F60600003000000",
            "602#23836000E8030000",
            "602#23846000E8030000",
            "602#23FF600064000000",
            "602#2B40600006000000",
            "602#2B40600007000000",
            "602#2B4060000F000000",
        ]
    );
    // 3.7.4: "602 2F 60 60 00 06", "602 2F 98 60 00 14", "602 23 99 60 01 D0 07", "602 23 99 60 02 C8 00",
    // "602 23 9A 60 00 E8 03", "602 23 93 60 01 01", "602 23 93 60 02 01", 06 / 07 / 0F, "0F", "5F", "4F"
    let hm = expand("syntron-ds", 2, "hm");
    assert_eq!(hm[..2], ["602#2B02210014000000", "000#0102"]);
    assert_eq!(
        hm[2..15],
        [
            "602#2F60600006000000",
            "602#2F98600014000000",
            "602#23996001D0070000",
            "602#23996002C8000000",
            "602#239A6000E8030000",
            "602#2393600101000000",
            "602#2393600201000000",
            "602#2B40600006000000",
            "602#2B40600007000000",
            "602#2B4060000F000000",
            "602#2B4060000F000000",
            "602#2B4060005F000000",
            "602#2B4060004F000000",
        ]
    );
    // Then the statusword is read until homing attained (the manual leaves this to the user).
    assert_eq!(hm[15..], ["602#4041600000000000"]);
    // 3.7.2: "602 2F 60 60 00 01", "602 23 7A 60 00 60 EA 00 00", "602 23 81 60 00 B8 0B 00 00", 6083h, 6084h,
    // "602 2B 93 60 01 01", "602 2B 93 60 02 01", 06 / 07 / 0F, then "1F" / "0F" (absolute move)
    assert_eq!(
        expand("syntron-ds", 2, "pp")[2..],
        [
            "602#2F60600001000000",
            "602#237A600060EA0000",
            "602#23816000B80B0000",
            "602#23836000E8030000",
            "602#23846000E8030000",
            "602#2B93600101000000",
            "602#2B93600201000000",
            "602#2B40600006000000",
            "602#2B40600007000000",
            "602#2B4060000F000000",
            "602#2B4060001F000000",
            "602#2B4060000F000000",
        ]
    );
    // 3.8.1: "601 E9 18 23 00 36 00 CA FF  // write 0x2318 and 0x3318 = 54 and -54"
    assert_eq!(expand("syntron-ds", 1, "dual_speed"), ["601#E91823003600CAFF"]);
    // 3.8 STEP1 "F0.1.002 = 1, F0.3.018 = 0, F0.1.000 = 0, Pn5.00A = 0" (speed mode, speed 0, stopped,
    // RAM only), STEP2 "602 2B 18 23 00 64 00 00 00", "602 2B 00 21 00 01 ...", "602 40 00 50 00 ..."
    assert_eq!(
        expand("syntron-ds", 2, "vendor_speed"),
        [
            "602#2B02210001000000",
            "602#2B18230000000000",
            "602#2B00210000000000",
            "602#2B0A450000000000",
            "602#2B18230064000000",
            "602#2B00210001000000",
            "602#4000500000000000",
        ]
    );
}

#[test]
fn aimotor_pdo_remapping_matches_section_5_4() {
    let frames = expand("aimotor", 1, "csv_pdo_remap");
    assert_eq!(
        frames,
        [
            "000#8001",
            "601#2300140101020080",
            "601#2301140101030080",
            "601#2302140101040080",
            "601#2303140101050080",
            "601#2300180181010080",
            "601#2301180181020080",
            "601#2302180181030080",
            "601#2303180181040080",
            "601#2F00140201000000",
            "601#2F00160000000000",
            "601#2300160110004060",
            "601#2300160208006060",
            "601#230016032000FF60",
            "601#2F00160003000000",
            "601#2300140101020000",
            "601#2F00180201000000",
            "601#2F001A0000000000",
            "601#23001A0110004160",
            "601#23001A0220006C60",
            "601#2F001A0002000000",
            "601#2300180181010000",
            "000#0101",
        ]
    );
    // 4.3 PP: "601 2F 60 60 00 01", "601 23 7A 60 00 ..", "601 23 81 60 00 ..", 6083h, 6084h, 06 / 07 / 0F / 1F,
    // "601 40 41 60 00", "601 40 64 60 00"
    let pp = expand("aimotor", 1, "pp");
    assert_eq!(pp[0], "601#2F60600001000000");
    assert_eq!(pp[1], "601#237A600094880100");
    assert_eq!(pp[8], "601#2B4060001F000000");
    assert_eq!(pp[9..], ["601#4041600000000000", "601#4064600000000000"]);
}

#[test]
fn aqmd_and_dexmart_pdo_commands() {
    // AQMD 7.5.4: "0x201 03 88 13 00 F4 01 00 00"
    assert_eq!(
        expand("aqmd2405", 1, "rpdo_speed"),
        ["000#0101", "201#03881300F4010000"]
    );
    // Dexmart: "201 [5] 0A 00 00 B8 0B" (encoder speed), "201 [3] 01 B8 0B" (hall speed)
    // with the prerequisites the manual names first: "01-11 = 2, 09-26 = 0" (3001h sub 0Bh, 3009h sub 1Ah),
    // "01-27 = 0, 01-28 = 4, 09-26 = 1" (M2 hall speed)
    assert_eq!(
        expand("dexmart-dev", 1, "encoder_speed_m1"),
        [
            "601#2B01300B02000000",
            "601#2B09301A00000000",
            "000#0101",
            "201#0A0000B80B"
        ]
    );
    assert_eq!(
        expand("dexmart-dev", 1, "encoder_position_m2"),
        [
            "601#2B01301B02000000",
            "601#2B09301A00000000",
            "000#0101",
            "301#0F64000000"
        ]
    );
    assert_eq!(
        expand("dexmart-dev", 1, "hall_speed_m2"),
        [
            "601#2B01301B00000000",
            "601#2B01301C04000000",
            "601#2B09301A01000000",
            "000#0101",
            "301#01B80B"
        ]
    );
    // "601 2B 03 30 01 B8 0B 00 00" (03-01 = 3000), "601 40 00 30 0A 00 00 00 00" (Dynamic Data 10)
    assert_eq!(expand("dexmart-dev", 1, "write_parameter"), ["601#2B033001B80B0000"]);
    assert_eq!(expand("dexmart-dev", 1, "read_dynamic_data"), ["601#4000300A00000000"]);
}

/// A Dexmart-like SDO server on node 1 of a virtual bus: 3000h sub 0Ah = 2414 (096Eh) and a
/// writable 3003h sub 1 (03-01), nothing else. Gives the bus end for the commander.
fn dexmart_peer() -> cotui::bus::Bus {
    use cotui::od::Access;
    let mut store = cotui::sdo::server::MemoryStore::default();
    store.insert(0x3000, 0x0A, Access::Ro, Some(2), vec![0x6E, 0x09]);
    store.insert(0x3003, 0x01, Access::Rw, Some(2), vec![0, 0]);
    sdo_peer(store)
}

/// An SDO server on node 1 of a virtual bus answering from `store`; gives the commander's end.
fn sdo_peer(mut store: cotui::sdo::server::MemoryStore) -> cotui::bus::Bus {
    use cotui::sdo::server::{SdoServer, ServerConfig};
    let vbus = cotui::bus::virt::VirtualBus::new("vcan-test");
    let peer = vbus.endpoint(false);
    let mut rx = peer.subscribe();
    tokio::spawn(async move {
        let mut server = SdoServer::new(ServerConfig::default());
        while let Ok(f) = rx.recv().await {
            if f.id != 0x601 {
                continue;
            }
            for reply in server.on_frame(f.payload(), 0, &mut store).frames {
                let _ = peer.send(&cotui::frame::Frame::classic(0x581, &reply)).await;
            }
        }
    });
    vbus.endpoint(false)
}

#[tokio::test(start_paused = true)]
async fn dexmart_sdo_procedures_show_the_value_and_fail_on_an_abort() {
    use cotui::command::run::{plan, run};
    let b = Bindings::from_args(&["1=dexmart-dev".to_string()], &[], &|p| std::fs::read(p)).unwrap();
    let dict = b.dictionary(1);
    let bus = dexmart_peer();
    // "581 4B 00 30 0A 6E 09": Dynamic Data 10 = 096Eh = 2414, shown with the object's name.
    let p = plan(dict, 1, "read_dynamic_data", &[]).unwrap();
    let v = serde_json::to_value(run(&bus, dict, &p, 1000, &mut |_| {}).await.unwrap()).unwrap();
    assert_eq!(v["steps"][0]["result"]["value"], 2414, "{v}");
    assert_eq!(v["steps"][0]["result"]["text"], "0x3000:0A = 2414", "{v}");
    assert_eq!(v["steps"][0]["text"], "sdo read 0x3000:0A Dynamic Data 10");
    // "601 2B 03 30 01 B8 0B 00 00" answered "581 60 03 30 01": written.
    let p = plan(dict, 1, "write_parameter", &[]).unwrap();
    let v = serde_json::to_value(run(&bus, dict, &p, 1000, &mut |_| {}).await.unwrap()).unwrap();
    assert_eq!(v["steps"][0]["frame"], "601#2B033001B80B0000");
    assert_eq!(v["steps"][0]["result"], "written");
    // Objects the drive does not have: the abort fails the run with exit status 3.
    let args = [("sub".to_string(), "33".to_string())];
    let e = run(
        &bus,
        dict,
        &plan(dict, 1, "read_dynamic_data", &args).unwrap(),
        1000,
        &mut |_| {},
    )
    .await
    .unwrap_err();
    assert_eq!(e.exit_code(), 3, "{e}");
    assert_eq!(e.to_json()["failed_step"], 1, "{}", e.to_json());
    let args = [
        ("page".to_string(), "3".to_string()),
        ("number".to_string(), "2".to_string()),
    ];
    let e = run(
        &bus,
        dict,
        &plan(dict, 1, "write_parameter", &args).unwrap(),
        1000,
        &mut |_| {},
    )
    .await
    .unwrap_err();
    assert_eq!(e.exit_code(), 3, "{e}");
    assert!(e.to_string().contains("0x06090011"), "{e}");
}

#[test]
fn syntron_tpdo_remap_pv_sends_all_13_frames_of_3_7_1_step_4() {
    // 3.7.1 STEP4: TPDO1 (COB-ID 0x182) = 6069h + 6063h, TPDO2 (0x282) = 6041h, each with
    // transmission type 1, then sub 3 (inhibit time) = 2 and sub 5 (event timer) = 2. The manual
    // writes subs 3 and 5 with "2F" (1 byte); CiA 301 has both UNSIGNED16, so cotui writes 2 bytes ("2B").
    assert_eq!(
        expand("syntron-ds", 2, "tpdo_remap_pv"),
        [
            "602#2F001A0000000000",
            "602#23001A0120006960",
            "602#23001A0220006360",
            "602#2F001A0002000000",
            "602#2F00180201000000",
            "602#2B00180302000000",
            "602#2B00180502000000",
            "602#2F011A0000000000",
            "602#23011A0110004160",
            "602#2F011A0001000000",
            "602#2F01180201000000",
            "602#2B01180302000000",
            "602#2B01180502000000",
        ]
    );
    let read = |p: &std::path::Path| std::fs::read(p);
    let b = Bindings::from_args(&["2=syntron-ds".to_string()], &[], &read).unwrap();
    let d = b
        .dictionary(2)
        .procedure("tpdo_remap_pv")
        .unwrap()
        .description
        .clone()
        .unwrap();
    assert!(d.contains("transmission type 1 (on every SYNC)"), "{d}");
    assert!(!d.contains("2nd"), "{d}");
}

#[test]
fn syntron_pt_pp_relative_and_examples_match_the_manual() {
    // 3.7.3: STEP1, STEP2, "602 2F 60 60 00 04", "602 2F 87 60 00 E8 03" (6087h = 1000), "602 2F 71 60 00 64 00"
    // (6071h = 100 = 10 %), 06 / 07 / 0F. The manual's "2F" (1 byte) cannot hold E8 03; 6087h is a 32-bit and
    // 6071h a 16-bit object (CiA 402), so cotui writes "23" and "2B".
    assert_eq!(
        expand("syntron-ds", 2, "pt"),
        [
            "602#2B02210014000000",
            "000#0102",
            "602#2F60600004000000",
            "602#23876000E8030000",
            "602#2B71600064000000",
            "602#2B40600006000000",
            "602#2B40600007000000",
            "602#2B4060000F000000",
        ]
    );
    // 3.7.2 with step 7's relative start: "602 2B 40 60 00 5F" (new set-point, relative), "... 4F" (bit 4 back)
    assert_eq!(
        expand("syntron-ds", 2, "pp_relative"),
        [
            "602#2B02210014000000",
            "000#0102",
            "602#2F60600001000000",
            "602#237A600060EA0000",
            "602#23816000B80B0000",
            "602#23836000E8030000",
            "602#23846000E8030000",
            "602#2B93600101000000",
            "602#2B93600201000000",
            "602#2B40600006000000",
            "602#2B40600007000000",
            "602#2B4060000F000000",
            "602#2B4060005F000000",
            "602#2B4060004F000000",
        ]
    );
    // Axis B sets F1.1.002 (0x3102) in STEP1.
    let read = |p: &std::path::Path| std::fs::read(p);
    let b = Bindings::from_args(&["3=syntron-ds".to_string()], &[], &read).unwrap();
    let args = [("axis".to_string(), "1".to_string())];
    let plan = cotui::command::run::plan(b.dictionary(3), 3, "pv", &args).unwrap();
    assert_eq!(plan.steps[0].frame.as_deref(), Some("603#2B02310014000000"));
    // 3.6.4 RPDO example: "602 2F 00 16 00 00", "602 23 00 16 01 20 00 FF 60", "602 2F 00 16 00 01",
    // "602 2F 01 16 00 00", "602 23 01 16 01 10 00 40 60", "602 23 01 16 02 20 00 FF 60", "602 2F 01 16 00 02"
    assert_eq!(
        expand("syntron-ds", 2, "rpdo_remap"),
        [
            "602#2F00160000000000",
            "602#230016012000FF60",
            "602#2F00160001000000",
            "602#2F01160000000000",
            "602#2301160110004060",
            "602#230116022000FF60",
            "602#2F01160002000000",
        ]
    );
    // 3.6.4 TPDO example: TPDO1 "602 2F 00 1A 00 00", "602 23 00 1A 01 10 00 41 60", "602 2F 00 1A 00 01",
    // "602 2F 00 18 05 32" (50 ms), "602 2F 00 18 03 32", "602 2F 00 18 02 FE" (254); TPDO2 the same with
    // "23 01 1A 01 20 00 63 60", "23 01 1A 02 20 00 69 60". Subs 3 and 5 are UNSIGNED16 (CiA 301), so
    // cotui writes them with "2B" where the manual has "2F".
    assert_eq!(
        expand("syntron-ds", 2, "tpdo_example"),
        [
            "602#2F001A0000000000",
            "602#23001A0110004160",
            "602#2F001A0001000000",
            "602#2B00180532000000",
            "602#2B00180332000000",
            "602#2F001802FE000000",
            "602#2F011A0000000000",
            "602#23011A0120006360",
            "602#23011A0220006960",
            "602#2F011A0002000000",
            "602#2B01180532000000",
            "602#2B01180332000000",
            "602#2F011802FE000000",
        ]
    );
}

#[test]
fn aimotor_sdo_procedures_match_section_4_and_2_3() {
    // 4.2 PV: "2F 60 60 00 03", "23 FF 60 00 xx", "23 83 60 00 xx", "23 84 60 00 xx", "2B 40 60 00 06 / 07 / 0F",
    // "40 41 60 00", "40 6C 60 00" (xx: the defaults speed 10000, acceleration 100000)
    assert_eq!(
        expand("aimotor", 1, "pv"),
        [
            "601#2F60600003000000",
            "601#23FF600010270000",
            "601#23836000A0860100",
            "601#23846000A0860100",
            "601#2B40600006000000",
            "601#2B40600007000000",
            "601#2B4060000F000000",
            "601#4041600000000000",
            "601#406C600000000000",
        ]
    );
    // 4.4 HM: "2F 60 60 00 06", "2F 98 60 00 xx", "23 99 60 01 xx", "23 99 60 02 xx", "23 9A 60 00 xx",
    // 06 / 07 / 0F / 1F, "40 41 60 00" (repeated until homing attained), "40 64 60 00"
    assert_eq!(
        expand("aimotor", 1, "hm"),
        [
            "601#2F60600006000000",
            "601#2F98600023000000",
            "601#2399600110270000",
            "601#23996002E8030000",
            "601#239A600010270000",
            "601#2B40600006000000",
            "601#2B40600007000000",
            "601#2B4060000F000000",
            "601#2B4060001F000000",
            "601#4041600000000000",
            "601#4064600000000000",
        ]
    );
    // 4.5 PT: "2F 60 60 00 04", "2B 71 60 00 xx", "23 7F 60 01 xx" (607Fh max profile velocity has no sub 1:
    // the manual copies the sub byte of its 6099h row; cotui writes sub 0), 06 / 07 / 0F, "40 41 60", "40 77 60"
    assert_eq!(
        expand("aimotor", 1, "pt"),
        [
            "601#2F60600004000000",
            "601#2B71600064000000",
            "601#237F6000A0860100",
            "601#2B40600006000000",
            "601#2B40600007000000",
            "601#2B4060000F000000",
            "601#4041600000000000",
            "601#4077600000000000",
        ]
    );
    // 2.3 (no frames, the steps): "H02-00 = 8 (CANopen)", "6060h = 1", "607Ah = 100500", "6081h = 33333",
    // "6083h = 16666", "6084h = 11111", "6040h 00h -> 06h -> 07h -> 0Fh -> 1F"
    assert_eq!(
        expand("aimotor", 1, "pp_example"),
        [
            "601#2B02200108000000",
            "601#2F60600001000000",
            "601#237A600094880100",
            "601#2381600035820000",
            "601#238360001A410000",
            "601#23846000672B0000",
            "601#2B40600000000000",
            "601#2B40600006000000",
            "601#2B40600007000000",
            "601#2B4060000F000000",
            "601#2B4060001F000000",
        ]
    );
}

/// AIMOTOR `hm` against a drive whose statusword reads `sw`: the run ends when homing is attained
/// and fails with "homing error" (exit 5) when bit 13 is set.
async fn aimotor_homing(sw: u16) -> Result<serde_json::Value, cotui::command::CommandError> {
    use cotui::od::Access;
    let mut store = cotui::sdo::server::MemoryStore::default();
    for (index, sub, size) in [
        (0x6060, 0, 1),
        (0x6098, 0, 1),
        (0x6099, 1, 4),
        (0x6099, 2, 4),
        (0x609A, 0, 4),
        (0x6040, 0, 2),
        (0x6064, 0, 4),
    ] {
        store.insert(index, sub, Access::Rw, Some(size), vec![0; size]);
    }
    store.insert(0x6041, 0, Access::Ro, Some(2), sw.to_le_bytes().to_vec());
    let bus = sdo_peer(store);
    let b = Bindings::from_args(&["1=aimotor".to_string()], &[], &|p| std::fs::read(p)).unwrap();
    let dict = b.dictionary(1);
    let p = cotui::command::run::plan(dict, 1, "hm", &[]).unwrap();
    let run = cotui::command::run::run(&bus, dict, &p, 1000, &mut |_| {}).await;
    run.map(|r| serde_json::to_value(r).unwrap())
}

#[tokio::test(start_paused = true)]
async fn homing_waits_for_homing_attained_and_reports_homing_error() {
    // 0x1637: operation enabled, target reached, homing attained.
    let v = aimotor_homing(0x1637).await.unwrap();
    let wait = &v["steps"][9];
    assert_eq!(wait["kind"], "wait");
    let text = wait["result"]["text"].as_str().unwrap();
    assert!(text.contains("target reached, homing attained]"), "{text}");
    assert!(
        wait["text"]
            .as_str()
            .unwrap()
            .ends_with("fails on homing error (statusword bit 13))"),
        "{wait}"
    );
    // 0x2637: homing error.
    let e = aimotor_homing(0x2637).await.unwrap_err();
    assert_eq!(e.exit_code(), 5, "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("homing error (statusword bit 13); read 0x6041:00 = 0x2637"),
        "{msg}"
    );
    assert!(msg.contains("target reached, homing error]"), "{msg}");
}

#[test]
fn aimotor_cyclic_synchronous_enables_follow_sections_2_7_and_5_4_5_5() {
    // 5.4: RPDO1 mapped in pre-operational with the COB-ID invalid, entries written with
    // "601 23 00 16 0n ..", transmission type 1 ("601 2F 00 14 02 01"); 5.5: the RPDO
    // "201 0F 00 03 E8 03 00 00" (6040h, 6060h, target) followed by SYNC "080"; 2.7: the
    // controlword 00h -> 06h -> 07h -> 0Fh in the cyclic modes goes by PDO.
    let csv = expand("aimotor", 1, "csv");
    assert_eq!(
        csv[..11],
        [
            "000#8001",
            "601#2300140101020080",
            "601#2F00140201000000",
            "601#2F00160000000000",
            "601#2300160110004060",
            "601#2300160208006060",
            "601#230016032000FF60",
            "601#2F00160003000000",
            "601#2300140101020000",
            "601#23061000D0070000",
            "000#0101",
        ]
    );
    assert_eq!(
        csv[11..19],
        [
            "201#000009E8030000",
            "080#",
            "201#060009E8030000",
            "080#",
            "201#070009E8030000",
            "080#",
            "201#0F0009E8030000",
            "080#",
        ]
    );
    // Operation enabled is read back, then the velocity.
    assert_eq!(csv[19..], ["601#4041600000000000", "601#406C600000000000"]);
    let csp = expand("aimotor", 1, "csp");
    assert_eq!(csp[6], "601#2300160320007A60");
    assert_eq!(csp[17], "201#0F000800000000");
    let cst = expand("aimotor", 1, "cst");
    assert_eq!(cst[6], "601#2300160310007160");
    assert_eq!(cst[17], "201#0F000A6400");
    assert_eq!(cst.last().map(String::as_str), Some("601#4077600000000000"));
}
