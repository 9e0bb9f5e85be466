//! `cotui run` through the real binary on the demo bus.

use crate::run::cotui;

fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn frames(v: &serde_json::Value) -> Vec<String> {
    v["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["frame"].as_str().unwrap_or("").to_string())
        .collect()
}

#[test]
fn aimotor_pv_on_the_demo_drive_reaches_operation_enabled() {
    let (rc, out, err) = cotui(&[
        "run",
        "demo",
        "2",
        "pv",
        "speed=2000",
        "--profile",
        "2=aimotor",
        "--json",
    ]);
    assert_eq!(rc, 0, "{err}");
    let v = json(&out);
    assert_eq!(
        (v["ok"].as_bool(), v["procedure"].as_str(), v["node"].as_u64()),
        (Some(true), Some("pv"), Some(2))
    );
    assert_eq!(v["params"]["speed"], 2000);
    assert_eq!(v["params"]["accel"], 100_000);
    assert_eq!(
        frames(&v),
        [
            "602#2F60600003000000",
            "602#23FF6000D0070000",
            "602#23836000A0860100",
            "602#23846000A0860100",
            "602#2B40600006000000",
            "602#2B40600007000000",
            "602#2B4060000F000000",
            "602#4041600000000000",
            "602#406C600000000000",
        ]
    );
    assert_eq!(v["steps"][4]["object"], "0x6040:00");
    assert_eq!(v["steps"][4]["value"], 6);
    assert_eq!(v["steps"][4]["result"], "written");
    let status = v["steps"][7]["result"]["text"].as_str().unwrap();
    assert!(status.starts_with("0x6041:00 = 0x"), "{status}");
    assert!(status.contains("Operation enabled"), "{status}");
}

#[test]
fn text_mode_prints_each_step_before_its_result() {
    let (rc, out, err) = cotui(&["run", "demo", "3", "pv", "--profile", "3=syntron-ds"]);
    assert_eq!(rc, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    // STEP1 of the manual: F0.1.002 = 20 (CANopen control).
    assert_eq!(
        lines[0],
        "step 1/9: sdo write 0x2102:00 A control mode = 20 (CANopen (CiA 402))  [603#2B02210014000000]"
    );
    assert_eq!(lines[1], "  -> written (1400)");
    assert_eq!(lines[2], "step 2/9: nmt start to node 3  [000#0103]");
    assert_eq!(lines[3], "  -> sent");
    assert_eq!(
        lines[12],
        "step 7/9: sdo write 0x6040:00 Controlword = 0x0006 (Shutdown)  [603#2B40600006000000]"
    );
    assert_eq!(lines[13], "  -> written (0600)");
    assert_eq!(lines.last(), Some(&"`pv` on node 3: 9 steps done"));
}

#[test]
fn a_step_on_a_missing_object_stops_with_abort_0x06020000_and_exit_3() {
    // AIMOTOR's manual example run on the Syn-tron-like drive (node 3), which has no
    // AIMOTOR vendor object H02-00 (0x2002:01): it stops at step 1, nothing after it runs.
    let (rc, out, err) = cotui(&["run", "demo", "3", "pp_example", "--profile", "3=aimotor", "--json"]);
    assert_eq!(rc, 3, "{err}");
    let v = json(&out);
    assert_eq!(v["ok"], false);
    assert_eq!(v["error"], "sdo_abort");
    assert_eq!(v["abort_code"], 0x0602_0000);
    assert_eq!(v["abort_text"], "Object does not exist in the object dictionary");
    assert_eq!(v["failed_step"], 1);
    assert_eq!(v["steps"].as_array().map(Vec::len), Some(1));
    assert!(
        err.contains("`pp_example` stopped at step 1/11: SDO 2002:01 on node 3 aborted by the server: 0x06020000"),
        "{err}"
    );
    let (rc, out, _) = cotui(&["run", "demo", "3", "pp_example", "--profile", "3=aimotor"]);
    assert_eq!(rc, 3);
    assert!(
        out.lines()
            .any(|l| l.starts_with("step 1/11: sdo write 0x2002:01 Control mode = 8")),
        "{out}"
    );
    assert!(!out.contains("step 2/11"), "{out}");
}

#[test]
fn dry_run_gives_the_syntron_manual_frame_list_without_a_send_path() {
    // Syn-tron manual 3.7.1, the same list tests/seed_procedures.rs checks.
    let (rc, out, err) = cotui(&[
        "run",
        "demo",
        "2",
        "pv",
        "--profile",
        "2=syntron-ds",
        "--dry-run",
        "--listen-only",
        "--json",
    ]);
    assert_eq!(rc, 0, "{err}");
    let v = json(&out);
    assert_eq!(v["dry_run"], true);
    assert_eq!(
        frames(&v),
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
    assert!(v["steps"].as_array().unwrap().iter().all(|s| s["result"] == "not sent"));
    let (rc, out, _) = cotui(&[
        "run",
        "demo",
        "2",
        "pv",
        "speed=-5",
        "--profile",
        "2=syntron-ds",
        "--dry-run",
    ]);
    assert_eq!(rc, 0);
    assert!(
        out.contains("Target velocity = -5 rpm  [602#23FF6000CEFFFFFF]"),
        "{out}"
    );
    assert!(
        out.starts_with("dry run of `pv` on node 2: 9 steps, nothing sent\n"),
        "{out}"
    );
}

#[test]
fn listen_only_refuses_to_run_and_prints_no_step() {
    let (rc, out, err) = cotui(&["run", "demo", "2", "pv", "--profile", "2=aimotor", "--listen-only"]);
    assert_eq!(rc, 2);
    assert!(!out.contains("step"), "{out}");
    assert!(err.contains("listen-only"), "{err}");
}

#[test]
fn unknown_procedures_and_parameters_name_the_valid_ones() {
    let (rc, _, err) = cotui(&["run", "demo", "2", "fly", "--profile", "2=aimotor"]);
    assert_eq!(rc, 1);
    assert!(
        err.contains(
            "node 2 has no procedure `fly`; its procedures: csp, cst, csv, csv_pdo_remap, hm, pp, pp_example, pt, pv"
        ),
        "{err}"
    );
    let (rc, out, err) = cotui(&["run", "demo", "2", "pv", "rpm=3", "--profile", "2=aimotor", "--json"]);
    assert_eq!(rc, 1);
    assert_eq!(json(&out)["error"], "usage");
    assert!(
        err.contains("`pv` has no parameter `rpm`; its parameters: speed=10000, accel=100000"),
        "{err}"
    );
    let (rc, _, err) = cotui(&["run", "demo", "2", "pv", "speed=fast", "--profile", "2=aimotor"]);
    assert_eq!(rc, 1);
    assert!(err.contains("speed=`fast` is not a number"), "{err}");
    // The demo's drives (nodes 2 and 3) come with their seed profiles; other nodes need one.
    let (rc, _, err) = cotui(&["run", "demo", "5", "pv"]);
    assert_eq!(rc, 1);
    assert!(err.contains("bind a profile: --profile 5=NAME"), "{err}");
    let (rc, out, _) = cotui(&["run", "demo", "2", "--list"]);
    assert_eq!(rc, 0);
    assert!(out.contains("pv"), "{out}");
}

#[test]
fn list_shows_procedures_with_descriptions_and_parameters() {
    let (rc, out, _) = cotui(&["run", "demo", "3", "--profile", "3=syntron-ds"]);
    assert_eq!(rc, 0);
    assert!(
        out.starts_with("node 3 procedures: dual_speed, hm, pp, pp_relative, pt, pv, "),
        "{out}"
    );
    assert!(out.contains("\npv  Profile velocity (manual 3.7.1)"), "{out}");
    assert!(
        out.contains("    speed=VALUE (default 10 rpm): target velocity"),
        "{out}"
    );
    let (rc, out, _) = cotui(&["run", "demo", "3", "--list", "--profile", "3=syntron-ds", "--json"]);
    assert_eq!(rc, 0);
    let v = json(&out);
    let pv = v["procedures"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "pv")
        .unwrap();
    assert_eq!(pv["params"][1]["name"], "ramp");
    assert_eq!(pv["params"][1]["default"], 1000);
    assert_eq!(pv["steps"], 9);
}

/// `cotui demo --node` takes the same NODE=MODEL as `cotui sim`; a wrong one is refused
/// before the terminal is touched, naming the simulated drives.
#[test]
fn demo_node_errors_name_the_simulated_drives() {
    let (rc, out, err) = cotui(&["demo", "--node", "2=plc"]);
    assert_eq!((rc, out.as_str()), (1, ""));
    assert_eq!(
        err.trim(),
        "cotui demo: --node 2=plc: unknown drive `plc`; the simulated drives: aimotor, syntron-ds, dexmart-dev, aqmd2405, servo"
    );
    let (rc, _, err) = cotui(&["demo", "--node", "0=aimotor"]);
    assert_eq!(rc, 1);
    assert!(err.contains("node-ID `0` is not 1..127 or ff"), "{err}");
    let (rc, _, err) = cotui(&["demo", "--node", "4=aqmd2405", "--node", "4=dexmart-dev"]);
    assert_eq!(rc, 1);
    assert!(err.contains("node 4 is given twice"), "{err}");
}
