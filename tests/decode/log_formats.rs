//! Golden and round-trip tests of the log formats on the files in `tests/fixtures/`.

use std::fs;
use std::io::BufReader;

use cotui::frame::Flags;
use cotui::log::writer::{LogWriter, Timestamps, push_compact};
use cotui::log::{Format, LogReader, Outcome, SkipReason};

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Every line of a fixture as `line: outcome`, frames in compact form.
fn render(name: &str) -> (Format, String) {
    let file = fs::File::open(fixture(name)).unwrap();
    let mut reader = LogReader::new(BufReader::new(file)).unwrap();
    let mut out = String::new();
    while let Some((n, outcome)) = reader.next_line().unwrap() {
        out.push_str(&format!("{n}: "));
        match outcome {
            Outcome::Frame(f) => {
                out.push_str(&format!("{} {} ", f.ts_ns, reader.interfaces().name(f.iface)));
                push_compact(&mut out, &f);
                if f.flags.has(Flags::TX) {
                    out.push_str(" T");
                }
            }
            Outcome::Skip(r) => out.push_str(&format!("skip {}", r.label())),
            Outcome::Warning(w) => out.push_str(&format!("warning {w}")),
        }
        out.push('\n');
    }
    let c = reader.counts();
    out.push_str(&format!(
        "frames {} warnings {} skipped {}\n",
        c.frames,
        c.warnings,
        c.skipped_total()
    ));
    (reader.format(), out)
}

fn golden(name: &str, format: Format) {
    let (got_format, got) = render(name);
    assert_eq!(got_format, format, "{name}: detected format");
    insta::assert_snapshot!(name.replace('.', "_"), got);
}

#[test]
fn screen_capture_golden() {
    golden("screen_capture.txt", Format::Screen);
}

#[test]
fn vector_asc_golden() {
    golden("vector.asc", Format::Asc);
}

#[test]
fn candump_multi_golden() {
    golden("candump_multi_x.log", Format::Candump);
}

/// Parses a candump fixture and writes it back with `writer`: every frame line must come
/// back byte for byte.
fn round_trip(name: &str, mut writer: LogWriter) {
    let text = fs::read_to_string(fixture(name)).unwrap();
    let mut reader = LogReader::with_format(text.as_bytes(), Format::Candump);
    let mut written = String::new();
    let mut expected = String::new();
    let lines: Vec<&str> = text.lines().collect();
    while let Some((n, outcome)) = reader.next_line().unwrap() {
        match outcome {
            Outcome::Frame(f) => {
                writer.write_line(&mut written, &f, reader.interfaces().name(f.iface));
                expected.push_str(lines[n as usize - 1]);
                expected.push('\n');
            }
            Outcome::Skip(SkipReason::DropCount) => {}
            other => panic!("{name}:{n}: {other:?}"),
        }
    }
    assert_eq!(written, expected, "{name}");
    assert!(reader.counts().frames >= 3, "{name}: too few frames to mean anything");
}

#[test]
fn candump_logs_round_trip_byte_for_byte() {
    round_trip("candump_single.log", LogWriter::new());
    round_trip("candump_diff.log", LogWriter::new().direction(true));
    round_trip(
        "candump_multi_x.log",
        LogWriter::new().pad_to(&["can0", "vcan10"]).direction(true),
    );
    round_trip("candump_ns.log", LogWriter::new().nanos(true));
    round_trip("candump_zero.log", LogWriter::new().timestamps(Timestamps::ZeroBased));
}

#[test]
fn whole_file_round_trips_through_io_writer() {
    let text = fs::read(fixture("candump_single.log")).unwrap();
    let mut reader = LogReader::with_format(&text[..], Format::Candump);
    let mut out = Vec::new();
    let mut w = LogWriter::new();
    while let Some((_, outcome)) = reader.next_line().unwrap() {
        let Outcome::Frame(f) = outcome else {
            panic!("{outcome:?}")
        };
        w.write_io(&mut out, &f, reader.interfaces().name(f.iface)).unwrap();
    }
    assert_eq!(out, text);
}

/// The same three frames as candump prints them with `-ta`, `-tz`, `-td` and `-tA`: each
/// decodes to the same times (from the first frame on), and the mode is said on stderr.
#[test]
fn screen_output_in_every_timestamp_mode() {
    let frames = ["can0  181   [1]  01", "can0  182   [1]  02", "can0  183   [1]  03"];
    let modes: [(&str, [&str; 3], &str); 4] = [
        (
            "-ta",
            ["1700000000.000000", "1700000000.250000", "1700000000.250100"],
            "absolute times (-ta)",
        ),
        (
            "-tz",
            ["000.000000", "000.250000", "000.250100"],
            "times since the start (-tz)",
        ),
        ("-td", ["000.000000", "000.250000", "000.000100"], "delta times (-td)"),
        (
            "-tA",
            [
                "2023-11-14 22:13:20.000000",
                "2023-11-14 22:13:20.250000",
                "2023-11-14 22:13:20.250100",
            ],
            "date and time (-tA)",
        ),
    ];
    for (mode, times, said) in modes {
        let text: String = times
            .iter()
            .zip(frames)
            .map(|(t, f)| format!(" ({t})  {f}\n"))
            .collect();
        let out = crate::run::cotui(&["decode", "--format", "jsonl", "-"], Some(&text));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr, format!("-: candump screen output, {said}\n"), "{mode}");
        let ts: Vec<f64> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| {
                serde_json::from_str::<serde_json::Value>(l).unwrap()["t"]
                    .as_f64()
                    .unwrap()
            })
            .collect();
        let rel: Vec<i64> = ts.iter().map(|t| ((t - ts[0]) * 1e6).round() as i64).collect();
        assert_eq!(rel, [0, 250_000, 250_100], "{mode}");
    }
}

/// python-can's public ASC log: its status lines (`CAN 1 Status:chip status error passive -
/// TxErr: 132 RxErr: 0`) are bus-state events, no longer lost.
#[test]
fn asc_status_lines_are_bus_state_events() {
    let log = "../shared/realworld/logs/python-can_logfile.asc";
    let out = crate::run::cotui(&["decode", "--events", log], None);
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        // The file's `date` line (Sam Sep 30 15:06:13.191 2017, as UTC) plus 0.015991 s.
        "(1506783973.206991)  bus       bus_state         can0: error active -> error passive \
         (controller problem (TX error passive); error counters tx=132 rx=0)\n"
    );
}

/// `--input-format` reads a log whose content does not tell its format: python-can CSV rows
/// without the header line (`CSVWriter(append=True)`), on decode and diagnose alike.
#[test]
fn input_format_overrides_detection() {
    let rows = "1700000000.5,0x701,0,0,0,1,BQ==\n1700000001.5,0x701,0,0,0,1,BQ==\n";
    let detected = crate::run::cotui(&["decode", "--format", "jsonl", "-"], Some(rows));
    assert_eq!(String::from_utf8_lossy(&detected.stdout), "");
    let out = crate::run::cotui(
        &["decode", "--input-format", "csv", "--format", "jsonl", "-"],
        Some(rows),
    );
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2, "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(
        (lines[0]["id"].as_u64(), lines[0]["kind"].as_str()),
        (Some(0x701), Some("heartbeat"))
    );
    assert_eq!(String::from_utf8_lossy(&out.stderr), "-: python-can CSV\n");
    let out = crate::run::cotui(
        &["diagnose", "--input-format", "csv", "--format", "jsonl", "-"],
        Some(rows),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// A SavvyCAN CSV save (written here in the shape SavvyCAN writes: µs times, hex ids,
/// `Dir` and `Bus` columns, empty data columns past `LEN`) decodes by content: bus numbers
/// become interfaces, `Tx` rows are ours, a row with a bad byte is a located warning.
#[test]
fn savvycan_csv_decodes_by_content() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("savvycan");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("capture.csv");
    std::fs::write(
        &path,
        "Time Stamp,ID,Extended,Dir,Bus,LEN,D1,D2,D3,D4,D5,D6,D7,D8\n\
         1700000000001000,00000701,false,Rx,0,1,05,,,,,,,\n\
         1700000000002000,00000601,false,Tx,1,8,40,00,10,00,00,00,00,00,\n\
         1700000000003000,00000581,false,Rx,1,8,43,00,10,00,92,01,02,00,\n\
         1700000000004000,18FF0102,true,Rx,0,2,ZZ,01,,,,,,\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--format", "jsonl"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    let lines: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["label"], "Heartbeat node 1: Operational");
    assert_eq!(
        (lines[1]["iface"].as_str(), lines[1]["dir"].as_str()),
        (Some("can1"), Some("tx"))
    );
    assert_eq!(lines[2]["t"], 1700000000.003);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.starts_with(&format!("{}: SavvyCAN CSV\n", path.display())),
        "{stderr}"
    );
    assert!(
        stderr.contains(":5: warning: column 39: expected a hex data byte"),
        "{stderr}"
    );
}

/// The PEAK CSV fixture rows (`Number, Time, Bus, Direction, Type, ID, Reserved, Length,
/// D0..`, as PEAK-Converter exports a trace; time in ms): a heartbeat, a CAN FD frame with
/// BRS on bus 2 (ours), a 29-bit frame, a remote request, a status row (PCAN BUSPASSIVE)
/// and an error frame.
const PEAK_CSV_ROWS: [[&str; 8 + 12]; 6] = {
    const E: &str = "";
    [
        [
            "1", "0.100", "1", "Rx", "DT", "0701", "-", "1", "05", E, E, E, E, E, E, E, E, E, E, E,
        ],
        [
            "2", "1.500", "2", "Tx", "FB", "18FF0102", "-", "12", "00", "01", "02", "03", "04", "05", "06", "07", "08",
            "09", "0A", "0B",
        ],
        [
            "3", "2.000", "1", "Rx", "DT", "01ABCDEF", "-", "8", "01", "02", "03", "04", "05", "06", "07", "08", E, E,
            E, E,
        ],
        [
            "4", "3.250", "1", "Rx", "RR", "0701", "-", "1", E, E, E, E, E, E, E, E, E, E, E, E,
        ],
        [
            "5", "100.000", "1", "Rx", "ST", "-", "-", "4", "00", "04", "00", "00", E, E, E, E, E, E, E, E,
        ],
        [
            "6", "200.000", "1", "Rx", "ER", "-", "-", "5", "04", "00", "02", "00", "00", E, E, E, E, E, E, E,
        ],
    ]
};

/// A decoded PEAK CSV row as the test compares it: seconds since the start, interface, id,
/// `[ext, rtr, fd, err]`, data and direction.
type PeakRow<'a> = (f64, &'a str, u64, [bool; 4], &'a str, &'a str);

/// PEAK CSV exports decode by content, with `,` (a copied TRC header and a row of column
/// names) and with `;` (comment lines only, decimal commas): every frame's id, flags, data,
/// interface, direction and time ($STARTTIME plus the offset, or the offset alone), and
/// the status row's error passive state as a bus-state event.
#[test]
fn peak_csv_decodes_by_content() {
    let names = "Number,Time,Bus,Direction,Type,ID,Reserved,Length,D0,D1,D2,D3,D4,D5,D6,D7,D8,D9,D10,D11";
    let rows = |delim: &str| -> String {
        PEAK_CSV_ROWS
            .iter()
            .map(|r| {
                let mut r = r.map(String::from);
                if delim == ";" {
                    r[1] = r[1].replace('.', ",");
                }
                r.join(delim) + "\r\n"
            })
            .collect()
    };
    let comma = format!(
        ";$FILEVERSION=2.1\r\n;$STARTTIME=45244.5\r\n;   Generated by PEAK-Converter\r\n{names}\r\n{}",
        rows(",")
    );
    let semi = format!(";##########\r\n; PEAK-Converter CSV export\r\n;\r\n{}", rows(";"));
    for (name, text, t0) in [("comma", comma, 1_699_963_200.0), ("semicolon", semi, 0.0)] {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("peak-csv");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("{name}.csv"));
        std::fs::write(&path, &text).unwrap();
        let out = crate::run::cotui(&["decode", "--format", "jsonl", path.to_str().unwrap()], None);
        assert!(out.status.success(), "{name}");
        let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        let got: Vec<PeakRow> = lines
            .iter()
            .map(|l| {
                let flag = |k: &str| l[k].as_bool().unwrap();
                (
                    ((l["t"].as_f64().unwrap() - t0) * 1e6).round() / 1e6,
                    l["iface"].as_str().unwrap(),
                    l["id"].as_u64().unwrap(),
                    [flag("ext"), flag("rtr"), flag("fd"), flag("err")],
                    l["data"].as_str().unwrap(),
                    l["dir"].as_str().unwrap(),
                )
            })
            .collect();
        let no = [false; 4];
        assert_eq!(
            got,
            [
                (0.0001, "can0", 0x701, no, "05", "rx"),
                (
                    0.0015,
                    "can1",
                    0x18FF_0102,
                    [true, false, true, false],
                    "000102030405060708090A0B",
                    "tx"
                ),
                (
                    0.002,
                    "can0",
                    0x1AB_CDEF,
                    [true, false, false, false],
                    "0102030405060708",
                    "rx"
                ),
                (0.00325, "can0", 0x701, [false, true, false, false], "", "rx"),
                (0.1, "can0", 0x4, [false, false, false, true], "0020000000000000", "rx"),
                (0.2, "can0", 0x88, [false, false, false, true], "0000000000000000", "rx"),
            ],
            "{name}"
        );
        assert_eq!(lines[3]["len"], 1, "{name}: the remote request's DLC");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.starts_with(&format!("{}: PEAK CSV\n", path.display())),
            "{stderr}"
        );
        assert!(stderr.contains("6 frames"), "{stderr}");
        let out = crate::run::cotui(&["decode", "--events", path.to_str().unwrap()], None);
        let events = String::from_utf8_lossy(&out.stdout);
        assert!(
            events.contains(
                "bus_state         can0: error active -> error passive (controller problem (TX error passive))"
            ),
            "{name}: {events}"
        );
    }
    // The same rows read as PEAK CSV when named so, and a bad row is a located warning.
    let bad = format!("{}1,0.300,1,Rx,DT,0181,-,2,11\n", rows(","));
    let out = crate::run::cotui(
        &["decode", "--input-format", "peak-csv", "--format", "jsonl", "-"],
        Some(&bad),
    );
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 6);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("-:7: warning: column 28: fewer data bytes than the length says"),
        "{stderr}"
    );
}

/// TRC 2.1 `EC` lines and PEAK CSV `EC` rows (RX error counter, then TX) are error counter
/// reports: `decode --events --format jsonl` shows the state they imply, with the counters.
#[test]
fn trc_and_peak_csv_error_counter_lines_are_bus_state_events() {
    let trc = ";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n      1         0.100 DT  1      0701 Rx -  1    05\n      2       100.000 EC  1         - Rx -  2    00 60\n      3       200.000 EC  1         - Rx -  2    02 81\n      4       300.000 EC  1         - Rx -  2    00 00\n";
    let csv = ";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n1,0.100,1,Rx,DT,0701,-,1,05,\n2,100.000,1,Rx,EC,-,-,2,00,60\n3,200.000,1,Rx,EC,-,-,2,02,81\n4,300.000,1,Rx,EC,-,-,2,00,00\n";
    for (name, log) in [("TRC", trc), ("PEAK CSV", csv)] {
        let out = crate::run::cotui(&["decode", "--events", "--format", "jsonl", "-"], Some(log));
        let events: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .filter(|e: &serde_json::Value| e["event"] == "bus_state")
            .collect();
        let got: Vec<(f64, &str, &str, &str)> = events
            .iter()
            .map(|e| {
                (
                    e["t"].as_f64().unwrap(),
                    e["from"].as_str().unwrap(),
                    e["to"].as_str().unwrap(),
                    e["detail"].as_str().unwrap(),
                )
            })
            .collect();
        assert_eq!(
            got,
            [
                (
                    1_699_963_200.1,
                    "error_active",
                    "error_warning",
                    "controller problem (TX error warning); error counters tx=96 rx=0"
                ),
                (
                    1_699_963_200.2,
                    "error_warning",
                    "error_passive",
                    "controller problem (TX error passive); error counters tx=129 rx=2"
                ),
                (
                    1_699_963_200.3,
                    "error_passive",
                    "error_active",
                    "controller problem (recovered to error active); error counters tx=0 rx=0"
                ),
            ],
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Hand-made PEAK TRC 2.1 and 1.1 logs (after PEAK's format description) with status
/// (`ST`, 1.1 `Warng` with id FFFFFFFF: the PCAN status code in the last four bytes) and
/// error lines (`ER`, 1.1 `Error`): status lines are bus-state events, and with the error
/// lines they are diagnose's `bus_errors` incident; an `EC` line (RX counter 0, TX 0x80) is
/// the error counters and the state they imply (error passive from 128).
#[test]
fn trc_status_and_error_lines_are_bus_state_events_and_bus_errors() {
    let v21 = ";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n      1         0.100 DT  1      0701 Rx -  1    05\n      2       100.000 ST  1           Rx    00 00 00 08\n      3       200.000 ER  1           Rx    04 00 02 00 00\n      4       250.000 EC  1           Rx    00 80\n      5       300.000 ST  1           Rx    00 04 00 00\n      6       400.000 ST  1           Rx    00 00 00 10\n";
    let v11 = ";$FILEVERSION=1.1\n;$STARTTIME=45244.5\n     1)       0.1  Rx         0701  1  05\n     2)     100.0  Warng  FFFFFFFF  4  00 00 00 08  BUSHEAVY\n     3)     200.0  Error      0100  3  00 19 08\n     4)     400.0  Warng  FFFFFFFF  4  00 00 00 10  BUSOFF\n";
    let warning = "(1699963200.100000)  bus       bus_state         can0: error active -> error warning (controller problem (TX error warning))\n";
    let off =
        |from: &str| format!("(1699963200.400000)  bus       bus_state         can0: {from} -> bus off (bus off)\n");
    let boot = "(1699963200.000100)  node   1  state             Operational (first heartbeat)\n";
    let counters = "(1699963200.250000)  bus       bus_state         can0: error warning -> error passive (controller problem (TX error passive); error counters tx=128 rx=0)\n";
    for (name, log, want, errors) in [
        (
            "2.1",
            v21,
            format!("{boot}{warning}{counters}{}", off("error passive")),
            5,
        ),
        ("1.1", v11, format!("{boot}{warning}{}", off("error warning")), 3),
    ] {
        let out = crate::run::cotui(&["decode", "--events", "-"], Some(log));
        assert_eq!(String::from_utf8_lossy(&out.stdout), want, "TRC {name}");
        let out = crate::run::cotui(&["diagnose", "--format", "jsonl", "-"], Some(log));
        let incidents: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        let bus = incidents
            .iter()
            .find(|i| i["kind"] == "bus_errors")
            .unwrap_or_else(|| panic!("TRC {name}: no bus_errors in {incidents:?}"));
        assert_eq!(bus["count"], errors, "TRC {name}");
        assert_eq!(
            bus["title"],
            format!("{errors} CAN error frames (the controller went bus off)"),
            "TRC {name}"
        );
    }
}

/// A controller that went bus off and then, by an error counter line, back to error
/// passive: diagnose's `bus_errors` title names the worst state it reached (bus off), not
/// the last one.
#[test]
fn bus_errors_title_names_the_worst_state_reached() {
    let log = ";$FILEVERSION=2.1\n;$STARTTIME=45244.5\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n      1         0.100 DT  1      0701 Rx -  1    05\n      2       100.000 ER  1           Rx    04 00 02 00 00\n      3       200.000 ST  1           Rx    00 00 00 10\n      4       300.000 EC  1           Rx    00 80\n";
    let out = crate::run::cotui(&["decode", "--events", "-"], Some(log));
    let events = String::from_utf8_lossy(&out.stdout);
    assert!(events.contains("-> bus off (bus off)"), "{events}");
    assert!(events.contains("bus off -> error passive"), "{events}");
    let out = crate::run::cotui(&["diagnose", "--format", "jsonl", "-"], Some(log));
    let bus: serde_json::Value = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .find(|i| i["kind"] == "bus_errors")
        .expect("a bus_errors incident");
    assert_eq!(bus["title"], "3 CAN error frames (the controller went bus off)");
    assert_eq!(bus["status"], "open", "still error passive at the end");
}

/// A TRC 1.0 log (no `$FILEVERSION`): a status line is id FFFFFFFF, an error frame has
/// `ERROR` in place of its data; both count in diagnose's `bus_errors`.
#[test]
fn trc_1_0_error_frames_and_status_lines() {
    let v10 = "     1)       0.1  0701  1  05\n     2)     100.0  FFFFFFFF  4  00 00 00 04\n     3)     200.0  0008  4  ERROR 00 19 08 08\n     4)     400.0  FFFFFFFF  4  00 00 00 10\n";
    let out = crate::run::cotui(&["decode", "--events", "-"], Some(v10));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "(0.000100)  node   1  state             Operational (first heartbeat)\n\
         (0.100000)  bus       bus_state         can0: error active -> error warning (controller problem (TX error warning))\n\
         (0.400000)  bus       bus_state         can0: error warning -> bus off (bus off)\n"
    );
    let out = crate::run::cotui(&["diagnose", "--format", "jsonl", "-"], Some(v10));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("\"count\":3,") && text.contains("\"kind\":\"bus_errors\""),
        "{text}"
    );
}
