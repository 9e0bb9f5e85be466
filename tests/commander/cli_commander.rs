//! The commander subcommands through the real binary, on the demo bus.

use crate::run::{cotui, cotui_json};
use std::process::Command;

#[test]
fn sdo_read_json_has_value_and_data() {
    let (rc, v, _) = cotui_json(&["sdo", "read", "demo", "2", "0x6041", "--json"]);
    assert_eq!(rc, 0);
    assert_eq!(v["node"], 2);
    assert_eq!(v["index"], 0x6041);
    assert_eq!(v["sub"], 0);
    assert_eq!(v["value"], 0x0250);
    assert_eq!(v["data"], "5002");
    let (rc, v, _) = cotui_json(&["sdo", "read", "demo", "0x3", "0x1018:2", "--json", "--block"]);
    assert_eq!(rc, 0);
    assert_eq!(v["value"], 0x0402_0003);
    let (rc, v, _) = cotui_json(&["sdo", "read", "demo", "3", "Manufacturer device name", "--json"]);
    assert_eq!(rc, 0);
    assert_eq!(v["name"], "Manufacturer device name");
    assert_eq!(v["value"], "cotui simulated Syn-tron-like DS servo");
}

#[test]
fn sdo_abort_exits_3_with_code_and_text() {
    let (rc, v, err) = cotui_json(&["sdo", "read", "demo", "2", "0x2345:1", "--json"]);
    assert_eq!(rc, 3);
    assert_eq!(v["abort_code"], 0x0602_0000);
    assert_eq!(v["abort_text"], "Object does not exist in the object dictionary");
    assert!(err.contains("aborted by the server"), "{err}");
    let (rc, v, _) = cotui_json(&["sdo", "write", "demo", "2", "0x6041", "6", "--type", "u16", "--json"]);
    assert_eq!(rc, 3);
    assert_eq!(v["abort_code"], 0x0601_0002);
}

#[test]
fn sdo_write_then_domain_round_trip_through_files() {
    let dir = std::env::temp_dir().join(format!("cotui-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("in.bin");
    let blob: Vec<u8> = (0..100u8).collect();
    std::fs::write(&input, &blob).unwrap();
    let (rc, v, _) = cotui_json(&[
        "sdo",
        "write",
        "demo",
        "2",
        "0x2000",
        input.to_str().unwrap(),
        "--type",
        "domain",
        "--block",
        "--json",
    ]);
    assert_eq!((rc, v["len"].as_u64()), (0, Some(100)));
    let (rc, v, _) = cotui_json(&["sdo", "write", "demo", "2", "0x6060", "9", "--type", "i8", "--json"]);
    assert_eq!((rc, v["data"].as_str()), (0, Some("09")));
    let out = dir.join("out.bin");
    let (rc, v, _) = cotui_json(&[
        "sdo",
        "read",
        "demo",
        "2",
        "0x2000",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(rc, 0);
    assert_eq!(v["len"], 200);
    assert_eq!(std::fs::read(&out).unwrap().len(), 200);
    let (rc, _, err) = cotui_json(&["sdo", "write", "demo", "2", "0x6060", "300", "--type", "i8"]);
    assert_eq!(rc, 1);
    assert!(err.contains("does not fit"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn drive_enable_and_failure_reason() {
    let (rc, v, _) = cotui_json(&["drive", "demo", "2", "enable", "--json"]);
    assert_eq!(rc, 0);
    assert_eq!(v["state"], "operation_enabled");
    assert_eq!(v["controlwords"], serde_json::json!(["0x0006", "0x0007", "0x000F"]));
    let (rc, v, _) = cotui_json(&["drive", "demo", "2", "status", "--json"]);
    assert_eq!((rc, v["state"].as_str()), (0, Some("switch_on_disabled")));
    let (rc, v, _) = cotui_json(&["drive", "demo", "9", "enable", "--json", "--timeout", "200"]);
    assert_eq!((rc, v["error"].as_str()), (4, Some("timeout")), "{v}");
    assert_eq!(
        v["message"],
        "drive 9: read statusword failed: no SDO answer and no heartbeat from node 9: \
         check the node id, bitrate, wiring and power"
    );
}

#[test]
fn nmt_wait_and_listen_only_and_missing_interface() {
    let (rc, v, _) = cotui_json(&["nmt", "demo", "reset-node", "0", "--wait", "--json"]);
    assert_eq!(rc, 0);
    assert_eq!(v["confirmed"], serde_json::json!({"2": "boot_up", "3": "boot_up"}));
    let (rc, v, _) = cotui_json(&["nmt", "demo", "start", "2", "--listen-only", "--json"]);
    assert_eq!(rc, 2);
    assert_eq!(v["error"], "bus");
    let (rc, _, err) = cotui_json(&["scan", "cotuinosuch0"]);
    assert_eq!(rc, 2);
    assert!(err.contains("sudo modprobe vcan"), "{err}");
    let (rc, _, err) = cotui_json(&["sdo", "read", "demo", "200", "0x1000"]);
    assert_eq!(rc, 1);
    assert!(err.contains("node `200` must be a number 1..127"), "{err}");
}

#[test]
fn sdo_write_takes_a_negative_value_without_double_dash() {
    let (rc, v, err) = cotui_json(&["sdo", "write", "demo", "2", "0x6060", "-3", "--type", "i8", "--json"]);
    assert_eq!(rc, 0, "{err}");
    assert_eq!(v["data"], "FD");
}

#[test]
fn scan_and_record() {
    let (rc, v, _) = cotui_json(&["scan", "demo", "--json"]);
    assert_eq!(rc, 0);
    let nodes = v["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 2);
    assert_eq!(nodes[0]["node"], 2);
    assert_eq!(nodes[0]["device_profile"], 402);
    assert_eq!(nodes[0]["software_version"], "AIMOTOR (cotui simulation)");
    // The AIMOTOR-like drive is recognised by its software version; Syn-tron drives carry
    // no identification, so the generic drive profile is suggested.
    assert_eq!(nodes[0]["profile"], "aimotor");
    assert_eq!(nodes[1]["profile"], "cia402");
    assert_eq!(nodes[1]["device_name"], "cotui simulated Syn-tron-like DS servo");
    let path = std::env::temp_dir().join(format!("cotui-rec-{}.log", std::process::id()));
    let (rc, v, _) = cotui_json(&["record", "demo", "-o", path.to_str().unwrap(), "--count", "5", "--json"]);
    assert_eq!((rc, v["frames"].as_u64(), v["dropped"].as_u64()), (0, Some(5), Some(0)));
    let log = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = log.lines().collect();
    assert_eq!(lines.len(), 5);
    assert!(lines[0].starts_with('(') && lines[0].ends_with(" demo 702#00"), "{log}");
    std::fs::remove_file(&path).unwrap();
}

/// `cotui record demo -o FILE --json` stopped by `signal` once FILE holds lines (lines go
/// out while recording, not only at the end): exit 0 and every frame counted is in the file.
#[test]
fn record_stops_cleanly_on_every_catchable_signal() {
    for (signal, name) in [
        (libc::SIGINT, "INT"),
        (libc::SIGTERM, "TERM"),
        (libc::SIGHUP, "HUP"),
        (libc::SIGQUIT, "QUIT"),
    ] {
        let path = std::env::temp_dir().join(format!("cotui-rec-sig{signal}-{}.log", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let child = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["record", "demo", "-o", path.to_str().unwrap(), "--json"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Wait (on the condition, however long the machine needs) for lines on disk.
        while std::fs::read_to_string(&path).map_or(true, |s| s.lines().count() < 3) {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        // SAFETY: plain kill(2) on our own child.
        assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
        let out = child.wait_with_output().unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
        let log = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "SIG{name}: {v} {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(v["frames"].as_u64(), Some(log.lines().count() as u64), "SIG{name}: {v}");
        assert_eq!(
            (v["ok"].as_bool(), v["gaps"].as_array().map(Vec::len)),
            (Some(true), Some(0))
        );
        assert!(log.ends_with('\n') && log.lines().all(|l| l.starts_with('(') && l.contains(" demo ")));
        std::fs::remove_file(&path).unwrap();
    }
}

#[test]
fn record_refuses_an_existing_log_unless_force_or_append() {
    let path = std::env::temp_dir().join(format!("cotui-rec-exists-{}.log", std::process::id()));
    std::fs::write(&path, "(1.000000) can0 123#01\n").unwrap();
    let p = path.to_str().unwrap();
    let (rc, v, err) = cotui_json(&["record", "demo", "-o", p, "--count", "2", "--json"]);
    assert_eq!((rc, v["error"].as_str()), (1, Some("usage")), "{err}");
    assert!(
        err.contains("exists; --force overwrites it, --append adds to it"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "(1.000000) can0 123#01\n");
    let (rc, v, _) = cotui_json(&["record", "demo", "-o", p, "--count", "2", "--append", "--json"]);
    assert_eq!((rc, v["frames"].as_u64()), (0, Some(2)));
    let log = std::fs::read_to_string(&path).unwrap();
    assert!(
        log.starts_with("(1.000000) can0 123#01\n") && log.lines().count() == 3,
        "{log}"
    );
    let (rc, _, _) = cotui_json(&["record", "demo", "-o", p, "--count", "1", "--force"]);
    assert_eq!(rc, 0);
    assert_eq!(std::fs::read_to_string(&path).unwrap().lines().count(), 1);
    let (rc, _, err) = cotui_json(&["record", "demo", "-o", p, "--force", "--append"]);
    assert_eq!(rc, 1, "usage error: {err}");
    assert!(err.contains("cannot be used with"), "{err}");
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn sdo_read_shows_identity_objects_and_cob_ids_in_hex_and_json_keeps_numbers() {
    let text = |object: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["sdo", "read", "demo", "2", object])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    assert_eq!(
        text("0x1000"),
        "node 2 0x1000:00 Device type = 0x00020192 (CiA 402, servo drive) (data 92010200)\n"
    );
    assert_eq!(
        text("0x1018:2"),
        "node 2 0x1018:02 Product code = 0x04020002 (data 02000204)\n"
    );
    assert_eq!(
        text("0x1018:4"),
        "node 2 0x1018:04 Serial number = 0x000003EA (data EA030000)\n"
    );
    assert!(text("0x1800:1").contains("COB-ID used by TPDO = 0x00000182 (COB-ID 0x182)"));
    // Sub 0 counts the entries: a number, not an identifier.
    assert_eq!(
        text("0x1018:0"),
        "node 2 0x1018:00 Highest sub-index supported = 4 (data 04)\n"
    );
    // JSON: the value stays a number; the text field holds the hex.
    let (rc, v, _) = cotui_json(&["sdo", "read", "demo", "2", "0x1000", "--json"]);
    assert_eq!(rc, 0);
    assert_eq!(v["value"], 0x0002_0192);
    assert_eq!(v["text"], "0x00020192 (CiA 402, servo drive)");
}

/// An EDS bound to a demo drive with `--eds` names and types its objects (the drive's own
/// PDO configuration stays above it), and the errors name the EDS.
#[test]
fn sdo_read_on_the_demo_takes_names_and_types_from_an_eds() {
    let dir = std::env::temp_dir().join(format!("cotui-eds-demo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let eds = dir.join("bench.eds");
    std::fs::write(
        &eds,
        "[FileInfo]\nFileName=bench.eds\n\n[DeviceInfo]\nVendorName=bench\n\n\
         [MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n\n\
         [OptionalObjects]\nSupportedObjects=2\n1=0x1008\n2=0x6041\n\n\
         [1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n\n\
         [1008]\nParameterName=Device name\nObjectType=0x7\nDataType=0x000A\nAccessType=const\n\n\
         [6041]\nParameterName=Drive status\nObjectType=0x7\nDataType=0x0006\nAccessType=ro\nPDOMapping=1\n",
    )
    .unwrap();
    let bound = format!("2={}", eds.display());
    let (rc, v, err) = cotui_json(&["sdo", "read", "demo", "2", "drive status", "--eds", &bound, "--json"]);
    assert_eq!(rc, 0, "{err}");
    assert_eq!(
        (v["index"].as_u64(), v["name"].as_str()),
        (Some(0x6041), Some("Drive status"))
    );
    // The EDS says OCTET_STRING where the built-in dictionary says VISIBLE_STRING.
    let (rc, out, err) = cotui(&["sdo", "read", "demo", "2", "0x1008", "--eds", &bound]);
    assert_eq!(rc, 0, "{err}");
    assert!(
        out.starts_with("node 2 0x1008:00 Device name = 63 6F 74 75 69 20 "),
        "{out}"
    );
    let (rc, _, err) = cotui(&["sdo", "read", "demo", "2", "no such thing", "--eds", &bound]);
    assert_eq!(rc, 1);
    assert_eq!(
        err.trim(),
        "cotui sdo read: unknown object `no such thing` (use 0xINDEX[:SUB], a name or a vendor alias of profile bench.eds)"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_domain_value_from_an_endless_file_is_refused_at_16_mib() {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["sdo", "write", "demo", "2", "0x1008", "/dev/zero", "--type", "domain"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot read /dev/zero: larger than 16 MiB, the most a domain write sends"),
        "{err}"
    );
}
