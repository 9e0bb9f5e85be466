//! `cotui explain` (golden text and JSON over frames of every shape, refusals) and the
//! exact bus load of `decode --summary` on a fixture computed by hand.

use crate::run::cotui;

fn explain(args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["explain"];
    all.extend_from_slice(args);
    let out = cotui(&all, None);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// Frames of every shape: canworks' example (a TPDO), an SDO request, a heartbeat, a
/// remote frame, a 29-bit frame, a CAN FD frame and an error frame.
const FRAMES: [&str; 7] = [
    "185#2500EA00",
    "605#4041600000000000",
    "705#05",
    "705#R1",
    "12345678#11",
    "185##1000102030405060708090A0B",
    "20000004#000C000000000000",
];

#[test]
fn explain_text_and_json_golden() {
    let (code, text, err) = explain(&FRAMES);
    assert_eq!(code, 0, "{err}");
    insta::assert_snapshot!("explain_text", text);
    let (code, jsonl, err) = explain(&[&["--format", "jsonl", "--bitrate", "250k"][..], &FRAMES].concat());
    assert_eq!(code, 0, "{err}");
    insta::assert_snapshot!("explain_jsonl", jsonl);
}

#[test]
fn explain_of_canworks_example_gives_its_figures() {
    let (_, jsonl, _) = explain(&["--format", "jsonl", "185#2500EA00"]);
    let j: serde_json::Value = serde_json::from_str(jsonl.trim()).unwrap();
    assert_eq!(j["bits"], 79);
    assert_eq!(j["intermission"], 3);
    assert_eq!(j["stuff_bits"], 3);
    assert_eq!(j["crc"], "0x47DC");
    assert_eq!(j["time_us"], 158.0);
    assert_eq!(j["bitrate_source"], "assumed");
    assert_eq!(j["split"]["text"], "0x185 = 3 x 0x80 + 5");
    assert_eq!(j["split"]["node"], 5);
    assert_eq!(j["data"][0]["canopen_bits"], serde_json::json!([7, 0]));
    let (_, text, _) = explain(&["--bitrate", "1M", "185#2500EA00"]);
    assert!(
        text.contains("79 bits (+ 3 intermission), 3 stuff bits, CRC-15 0x47DC, 79.0 µs at 1000 kbit/s\n"),
        "{text}"
    );
}

/// A TPDO1 of the aimotor seed profile (statusword, mode display, position actual value):
/// each data bit range is named by its mapped object, in the bytes, in a list of the
/// objects and on the wire; in JSON as `objects` and each data run's `object`.
#[test]
fn explain_names_a_mapped_pdos_bits_by_object() {
    let args = ["--profile", "1=aimotor", "181#3702030A000000"];
    let (code, text, err) = explain(&args);
    assert_eq!(code, 0, "{err}");
    for line in [
        "    byte 1  0x02  00000010  bits 15..8    6041 Statusword\n",
        "    byte 2  0x03  00000011  bits 23..16   6061 Modes of operation display\n",
        "  PDO objects (CANopen bit numbers)\n    bits 15..0    6041 Statusword\n",
        "    bits 55..24   6064 Position actual value\n",
        "    data           0011011100000[1]010  6041 Statusword\n",
        "    data           0000[1]0011  6061 Modes of operation display\n",
    ] {
        assert!(text.contains(line), "{line}: {text}");
    }
    let (_, jsonl, _) = explain(&[&["--format", "jsonl"][..], &args].concat());
    let j: serde_json::Value = serde_json::from_str(jsonl.trim()).unwrap();
    assert_eq!(
        j["objects"][0],
        serde_json::json!({"index": 0x6041, "sub": 0, "label": "6041 Statusword", "canopen_bits": [15, 0]})
    );
    assert_eq!(j["objects"][2]["canopen_bits"], serde_json::json!([55, 24]));
    assert_eq!(j["data"][3]["field"], "6064 Position actual value");
    let data: Vec<&str> = j["wire"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["field"] == "data")
        .map(|w| w["object"].as_str().unwrap())
        .collect();
    assert_eq!(
        data,
        [
            "6041 Statusword",
            "6061 Modes of operation display",
            "6064 Position actual value"
        ]
    );
    // Without the profile the mapping is unknown: plain PDO data, no objects.
    let (_, plain, _) = explain(&["--format", "jsonl", "181#3702030A000000"]);
    let j: serde_json::Value = serde_json::from_str(plain.trim()).unwrap();
    assert!(j.get("objects").is_none(), "{plain}");
    assert_eq!(j["data"][0]["field"], "PDO data");
}

#[test]
fn a_malformed_frame_says_why_and_exits_1() {
    for (frame, why) in [
        ("800#11", "11-bit CAN id above 7FF"),
        ("12345678#R9", "remote frame length must be a digit 0..8"),
        ("185##1000102030405060708090A0B0C", "no CAN FD DLC gives 13 bytes"),
        ("hello", "expected a CAN id"),
    ] {
        let (code, out, err) = explain(&["705#05", frame]);
        assert_eq!(code, 1, "{frame}: {err}");
        assert!(err.contains(&format!("cotui explain: {frame}: ")), "{frame}: {err}");
        assert!(err.contains(why), "{frame}: {err}");
        assert!(out.contains("705#05"), "the good frame is still explained: {out}");
    }
}

/// tests/fixtures/bus_load.log by hand: three times canworks' 185#2500EA00 (79 bits + 3
/// intermission = 82, 3 stuff bits each) and an error frame (no bits): 246 bits, 9 stuff
/// bits, all node 5's; over 1 s at 500 kbit/s a load of 246 / 500000 = 0.000492. The
/// busiest 100 ms holds the first two: 164 of the 50,000 bits 100 ms hold = 0.00328. Each
/// frame takes 164 µs at 500 kbit/s; the second starts 200 - 164 = 36 µs after the first
/// ended, less than a frame's time: one burst from 164 µs before the first to the end of
/// the second, 0.364 ms.
#[test]
fn summary_bus_figures_by_hand() {
    let out = cotui(
        &[
            "decode",
            "--summary",
            "--format",
            "jsonl",
            "tests/fixtures/bus_load.log",
        ],
        None,
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        j["bus"],
        serde_json::json!({
            "bitrate": 500000, "bitrate_source": "assumed", "bits": 246, "stuff_bits": 9,
            "load": 0.000492, "by_node": {"5": 246}, "busiest_100ms": 0.00328, "longest_burst_ms": 0.364
        })
    );
    let out = cotui(
        &[
            "decode",
            "--summary",
            "--bitrate",
            "250k",
            "tests/fixtures/bus_load.log",
        ],
        None,
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("bus: 246 bits (9 stuff bits) at 250 kbit/s (given): load 0.10 %, busiest 100 ms 0.66 %, longest burst 0.528 ms\n  node 5          246 bits\n"),
        "{text}"
    );
    // The same figures through --filter (its own summary path).
    let out = cotui(
        &[
            "decode",
            "--summary",
            "--format",
            "jsonl",
            "--filter",
            "node 5",
            "tests/fixtures/bus_load.log",
        ],
        None,
    );
    let f: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(f["bus"]["bits"], 246);
}
