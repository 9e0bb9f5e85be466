//! `dcf save|load|diff` against the demo drives (tokio time paused: deterministic): save a
//! drive's configuration, change it, see the change in `diff`, restore it with `load`.

use cotui::command::sdo::{download, upload};
use cotui::command::{CommandError, Outcome, execute, parse_command};
use cotui::od::bind::Bindings;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use serde_json::Value as Json;
use std::path::PathBuf;

const T: u64 = 500;

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cotui-dcf-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bindings() -> Bindings {
    cotui::cli::bind::bindings_on(cotui::connect::DEMO, &[], &[]).unwrap()
}

async fn run(d: &Demo, line: &str) -> Result<Outcome, CommandError> {
    execute(&d.bus, &parse_command(line).unwrap(), &bindings()).await
}

/// The report of a command that ended in a report failure: (exit status, JSON).
fn failed(r: Result<Outcome, CommandError>) -> (i32, Json) {
    let e = r.unwrap_err();
    (e.exit_code().code(), e.to_json())
}

fn objects(v: &Json, key: &str) -> Vec<String> {
    v[key]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["object"].as_str().unwrap().to_string())
        .collect()
}

/// TPDO1 of the demo drive remapped by hand to 0x6041 + 0x606C (the CiA 301 sequence).
async fn remap_tpdo1(d: &Demo) {
    let cob = upload(&d.bus, 2, 0x1800, 1, false, T).await.unwrap();
    let mut invalid = cob.clone();
    invalid[3] |= 0x80;
    for (index, sub, data) in [
        (0x1800, 1, invalid),
        (0x1A00, 0, vec![0]),
        (0x1A00, 1, 0x6041_0010u32.to_le_bytes().to_vec()),
        (0x1A00, 2, 0x606C_0020u32.to_le_bytes().to_vec()),
        (0x1A00, 0, vec![2]),
        (0x1800, 1, cob),
    ] {
        download(&d.bus, 2, index, sub, data, false, T).await.unwrap();
    }
}

#[tokio::test(start_paused = true)]
async fn save_change_diff_and_load_restores() {
    let d = Demo::spawn(Simulation::demo(), false);
    let out = dir("restore").join("node2.dcf");
    let file = out.to_str().unwrap();
    let saved = run(&d, &format!("dcf save 2 -o {file}")).await.unwrap();
    assert!(saved.json()["objects"].as_u64().unwrap() > 100, "{}", saved.json());
    assert_eq!(saved.json()["refused"], Json::Array(vec![]));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("[FileInfo]\nFileName=node2.dcf\n"), "{text}");
    assert!(text.contains("[DeviceComissioning]\nNodeID=2\n"), "{text}");
    assert!(text.contains("[6083]\nParameterName=Profile acceleration\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\nPDOMapping=0\nParameterValue=0x4E20\n"));
    // A second save to the same file is refused without --force.
    let e = run(&d, &format!("dcf save 2 -o {file}")).await.unwrap_err();
    assert!(e.to_string().contains("exists; give --force"), "{e}");

    let same = run(&d, &format!("dcf diff 2 {file}")).await.unwrap();
    assert_eq!(same.json()["equal"], true);

    // The engineer changes a parameter, the heartbeat and the TPDO1 mapping.
    download(&d.bus, 2, 0x6083, 0, 5000u32.to_le_bytes().to_vec(), false, T)
        .await
        .unwrap();
    download(&d.bus, 2, 0x1017, 0, vec![0xE8, 0x03], false, T)
        .await
        .unwrap();
    remap_tpdo1(&d).await;

    let (rc, v) = failed(run(&d, &format!("dcf diff 2 {file}")).await);
    assert_eq!((rc, v["error"].as_str()), (6, Some("differs")));
    let differences = objects(&v, "differences");
    assert!(differences.contains(&"0x6083:00".to_string()), "{differences:?}");
    assert!(differences.contains(&"0x1017:00".to_string()), "{differences:?}");
    assert!(differences.contains(&"0x1A00:02".to_string()), "{differences:?}");
    let acc = v["differences"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["object"] == "0x6083:00")
        .unwrap();
    assert_eq!(
        (acc["file"].as_str(), acc["node"].as_str()),
        (Some("0x4E20"), Some("0x1388"))
    );
    assert_eq!(acc["name"], "Profile acceleration");

    // --dry-run lists the writes and sends none.
    let dry = run(&d, &format!("dcf load 2 {file} --dry-run")).await.unwrap();
    assert_eq!(dry.json()["dry_run"], true);
    assert!(
        dry.text.contains("would write 0x6083:00 Profile acceleration = 0x4E20"),
        "{}",
        dry.text
    );
    assert_eq!(
        upload(&d.bus, 2, 0x6083, 0, false, T).await.unwrap(),
        5000u32.to_le_bytes()
    );

    let loaded = run(&d, &format!("dcf load 2 {file} --store")).await.unwrap();
    let v = &loaded.json();
    assert_eq!(
        (v["ok"].as_bool(), v["stored"].as_bool()),
        (Some(true), Some(true)),
        "{v}"
    );
    let writes: Vec<(String, String)> = v["writes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| (w["object"].as_str().unwrap().into(), w["step"].as_str().unwrap().into()))
        .collect();
    let w = |o: &str, s: &str| (o.to_string(), s.to_string());
    // Application objects first, then communication, the PDO by the CiA 301 sequence last.
    assert_eq!(
        writes,
        [
            w("0x6083:00", "value"),
            w("0x1017:00", "value"),
            w("0x1800:01", "invalidate"),
            w("0x1A00:00", "clear_mapping"),
            w("0x1A00:01", "value"),
            w("0x1A00:02", "value"),
            w("0x1A00:00", "value"),
            w("0x1800:01", "value"),
        ]
    );
    assert!(v["verified"].as_u64().unwrap() >= 6, "{v}");
    assert!(loaded.text.contains("stored (0x1010:01 = save)"), "{}", loaded.text);
    assert_eq!(
        upload(&d.bus, 2, 0x6083, 0, false, T).await.unwrap(),
        20_000u32.to_le_bytes()
    );
    let back = run(&d, &format!("dcf diff 2 {file}")).await.unwrap();
    assert_eq!(back.json()["equal"], true, "{}", back.json());
}

#[tokio::test(start_paused = true)]
async fn bad_values_and_unknown_objects_are_located_and_the_rest_is_loaded() {
    let d = Demo::spawn(Simulation::demo(), false);
    let path = dir("bad").join("bad.dcf");
    let dcf = "[DeviceInfo]\nProductName=x\n\n[DeviceComissioning]\nNodeID=2\n\n\
        [OptionalObjects]\nSupportedObjects=3\n1=0x6083\n2=0x6060\n3=0x1017\n\n\
        [ManufacturerObjects]\nSupportedObjects=1\n1=0x2345\n\n\
        [6083]\nParameterName=Profile acceleration\nDataType=0x0007\nAccessType=rw\nParameterValue=0x1FFFFFFFF\n\n\
        [6060]\nParameterName=Modes of operation\nDataType=0x0002\nAccessType=rw\nParameterValue=1\n\n\
        [1017]\nParameterName=Producer heartbeat time\nDataType=0x0006\nAccessType=rw\nParameterValue=0x3E8\n\n\
        [2345]\nParameterName=Not there\nDataType=0x0005\nAccessType=rw\nParameterValue=1\n";
    std::fs::write(&path, dcf).unwrap();
    let file = path.to_str().unwrap();
    let loaded = run(&d, &format!("dcf load 2 {file}")).await.unwrap();
    let v = &loaded.json();
    assert_eq!(objects(v, "writes"), ["0x6060:00", "0x1017:00"], "{v}");
    let problems: Vec<&str> = v["problems"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap())
        .collect();
    assert_eq!(
        problems,
        [format!(
            "{file}:21: 0x6083:00 Profile acceleration: ParameterValue `0x1FFFFFFFF` does not fit U32 (32 bits), skipped"
        )]
    );
    let skipped = &v["skipped"][0];
    assert_eq!(
        (skipped["object"].as_str(), skipped["line"].as_u64()),
        (Some("0x2345:00"), Some(39))
    );
    assert!(
        skipped["reason"].as_str().unwrap().starts_with("not in the node"),
        "{skipped}"
    );
    assert_eq!(upload(&d.bus, 2, 0x1017, 0, false, T).await.unwrap(), [0xE8, 0x03]);
    assert_eq!(upload(&d.bus, 2, 0x6060, 0, false, T).await.unwrap(), [1]);
}

#[tokio::test(start_paused = true)]
async fn a_silent_node_stops_save_at_once_and_writes_no_file() {
    let d = Demo::spawn(Simulation::demo(), false);
    let out = dir("silent").join("node9.dcf");
    let e = run(&d, &format!("dcf save 9 -o {} --timeout 100", out.to_str().unwrap()))
        .await
        .unwrap_err();
    assert_eq!(e.exit_code().code(), 4);
    assert!(e.to_string().starts_with("node 9 does not answer (SDO 1000:00"), "{e}");
    assert!(!out.exists());
}

#[tokio::test(start_paused = true)]
async fn a_refused_write_is_reported_with_its_abort_text() {
    let d = Demo::spawn(Simulation::demo(), false);
    let path = dir("refused").join("r.dcf");
    // 0x6083 as one byte: the drive refuses the length.
    let dcf = "[DeviceInfo]\nProductName=x\n\n[OptionalObjects]\nSupportedObjects=1\n1=0x6083\n\n\
        [6083]\nParameterName=Profile acceleration\nDataType=0x0005\nAccessType=rw\nParameterValue=7\n";
    std::fs::write(&path, dcf).unwrap();
    let (rc, v) = failed(run(&d, &format!("dcf load 2 {}", path.to_str().unwrap())).await);
    assert_eq!((rc, v["error"].as_str()), (3, Some("refused")), "{v}");
    let r = &v["refused"][0];
    assert_eq!(r["object"], "0x6083:00");
    assert!(r["abort_text"].as_str().unwrap().contains("length"), "{r}");
}

/// The real binary: `--eds FILE` binds to the command's node, diff exits 0 then 6 after the
/// file is edited, and `--listen-only` makes a load impossible (exit 2, nothing sent).
#[test]
fn through_the_binary_exit_statuses_follow_the_differences() {
    let cotui = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(args)
            .output()
            .unwrap();
        let json = serde_json::from_slice(&out.stdout).unwrap_or(Json::Null);
        (
            out.status.code().unwrap_or(-1),
            json,
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let path = dir("cli").join("node3.dcf");
    let file = path.to_str().unwrap();
    let eds = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/eds/servo-ds.eds");
    let (rc, v, err) = cotui(&["dcf", "save", "demo", "3", "-o", file, "--eds", eds, "--json"]);
    assert_eq!(rc, 0, "{err}");
    assert!(v["objects"].as_u64().unwrap() > 50, "{v}");
    let (rc, v, err) = cotui(&["dcf", "diff", "demo", "3", file, "--json"]);
    assert_eq!((rc, v["equal"].as_bool()), (0, Some(true)), "{err}");
    let text = std::fs::read_to_string(&path).unwrap();
    let at = text.find("[6083]").unwrap();
    let value = at + text[at..].find("ParameterValue=").unwrap();
    let end = value + text[value..].find('\n').unwrap();
    std::fs::write(&path, format!("{}ParameterValue=0x7{}", &text[..value], &text[end..])).unwrap();
    let (rc, v, err) = cotui(&["dcf", "diff", "demo", "3", file, "--json"]);
    assert_eq!((rc, v["error"].as_str()), (6, Some("differs")), "{err}");
    assert_eq!(v["differences"][0]["object"], "0x6083:00");
    assert!(err.contains("0x6083:00 Profile acceleration: file 0x7, node "), "{err}");
    let (rc, _, err) = cotui(&["dcf", "load", "demo", "3", file, "--listen-only"]);
    assert_eq!(rc, 2, "{err}");
}

/// The SDO download requests (index, sub) we sent to `node` among `frames`.
fn downloads_sent(frames: &[cotui::frame::Frame], node: u8) -> Vec<(u16, u8)> {
    frames
        .iter()
        .filter(|f| f.direction() == cotui::frame::Direction::Tx && f.id == 0x600 + u32::from(node))
        .filter(|f| f.payload()[0] & 0xE0 == 0x20)
        .map(|f| (u16::from_le_bytes([f.payload()[1], f.payload()[2]]), f.payload()[3]))
        .collect()
}

/// A DCF for node 2 with RPDO1 (`rpdo1`: its [1400]/[1600] sections) and 0x1017 = 0x3E8.
fn dcf_with(rpdo1: &str) -> String {
    format!(
        "[DeviceInfo]\nProductName=x\n\n[DeviceComissioning]\nNodeID=2\n\n\
         [1017]\nParameterName=Producer heartbeat time\nDataType=0x0006\nAccessType=rw\nParameterValue=0x3E8\n\n{rpdo1}"
    )
}

#[tokio::test(start_paused = true)]
async fn load_refuses_a_pdo_that_pdo_map_would_refuse_and_sends_nothing_of_it() {
    let entry = |sub: u8, value: &str| {
        format!("[1600sub{sub}]\nParameterName=Entry {sub}\nDataType=0x0007\nAccessType=rw\nParameterValue={value}\n\n")
    };
    let comm = |cob: &str| {
        format!("[1400sub1]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nParameterValue={cob}\n\n")
    };
    let count = |n: u8| {
        format!("[1600sub0]\nParameterName=Number of entries\nDataType=0x0005\nAccessType=rw\nParameterValue={n}\n\n")
    };
    let eight: String = (1..=8).map(|s| entry(s, "0x60FF0020")).collect();
    let cases = [
        (
            format!("{}{}{eight}", comm("0x3FFFFFFF"), count(8)),
            "256 bits, more than the 64",
        ),
        (
            format!("{}{}{}", comm("0x602"), count(1), entry(1, "0x60400010")),
            "node 2's SDO request",
        ),
        (
            format!("{}{}{}", comm("0x202"), count(1), entry(1, "0x60400008")),
            "8 bits given",
        ),
        (
            format!("{}{}{}", comm("0x202"), count(1), entry(1, "0x60410010")),
            "only into TPDOs",
        ),
        (format!("{}{}", comm("0x00000A02"), count(0)), "bits above 0x7FF"),
    ];
    for (i, (rpdo1, why)) in cases.iter().enumerate() {
        let d = Demo::spawn(Simulation::demo(), false);
        let path = dir(&format!("refused{i}")).join("rpdo1.dcf");
        std::fs::write(&path, dcf_with(rpdo1)).unwrap();
        let mut rx = d.bus.subscribe();
        let (rc, v) = failed(run(&d, &format!("dcf load 2 {}", path.display())).await);
        let sent = downloads_sent(&drain(&mut rx), 2);
        assert_eq!((rc, v["error"].as_str()), (1, Some("invalid")), "{why}: {v}");
        let refused = &v["refused"][0];
        assert_eq!(refused["object"], "0x1400:00", "{v}");
        assert!(refused["reason"].as_str().unwrap().contains(why), "{why}: {refused}");
        // The rest of the file is loaded; nothing of RPDO1 is sent.
        assert_eq!(sent, [(0x1017, 0)], "{why}");
        assert_eq!(objects(&v, "writes"), ["0x1017:00"]);
        let text = e_text(run(&d, &format!("dcf load 2 {} --dry-run", path.display())).await);
        assert!(text.contains("refused 0x1400:00 RPDO1") && text.contains(why), "{text}");
    }
}

fn drain(rx: &mut cotui::bus::Subscription) -> Vec<cotui::frame::Frame> {
    std::iter::from_fn(|| rx.try_recv()).filter_map(Result::ok).collect()
}

/// The text of a command's outcome or failure.
fn e_text(r: Result<Outcome, CommandError>) -> String {
    match r {
        Ok(o) => o.text,
        Err(e) => e.to_string(),
    }
}

/// A value the file gives in decimal is shown in the base of the node's value: both sides
/// of an unsigned object in hex.
#[tokio::test(start_paused = true)]
async fn diff_shows_both_sides_in_one_base() {
    let d = Demo::spawn(Simulation::demo(), false);
    let out = dir("base").join("node2.dcf");
    let file = out.to_str().unwrap();
    run(&d, &format!("dcf save 2 -o {file}")).await.unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    let text = text.replacen("ParameterValue=0x4E20", "ParameterValue=30000", 1);
    std::fs::write(&out, text).unwrap();
    let (rc, v) = failed(run(&d, &format!("dcf diff 2 {file}")).await);
    assert_eq!(rc, 6, "{v}");
    let acc = v["differences"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["object"] == "0x6083:00")
        .unwrap();
    assert_eq!(
        (acc["file"].as_str(), acc["node"].as_str()),
        (Some("0x7530"), Some("0x4E20"))
    );
}
