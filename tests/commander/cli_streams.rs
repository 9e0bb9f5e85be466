//! `-o -`: stdout carries the data alone, every report (text or `--json`) goes to stderr.

use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cotui")).args(args).output().unwrap()
}

/// The pcapng blocks of `bytes` (type of each), or why they do not parse: every block's
/// leading and trailing lengths agree and the blocks end exactly at the end of the data.
fn pcapng_blocks(bytes: &[u8]) -> Result<Vec<u32>, String> {
    let u32_at = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .ok_or(format!("cut short at byte {at}"))
    };
    if bytes.get(..4) != Some(&[0x0A, 0x0D, 0x0D, 0x0A]) || u32_at(8)? != 0x1A2B_3C4D {
        return Err("no section header block (magic) at the start".into());
    }
    let (mut at, mut blocks) = (0, Vec::new());
    while at < bytes.len() {
        let (kind, len) = (u32_at(at)?, u32_at(at + 4)? as usize);
        if len < 12 || len % 4 != 0 || at + len > bytes.len() || u32_at(at + len - 4)? as usize != len {
            return Err(format!("damaged block at byte {at} (type {kind:#x}, length {len})"));
        }
        blocks.push(kind);
        at += len;
    }
    Ok(blocks)
}

#[test]
fn record_to_stdout_as_pcapng_is_pcapng_alone_with_the_report_on_stderr() {
    let out = run(&["record", "demo", "-o", "-", "--count", "3", "--format", "pcapng"]);
    assert_eq!(out.status.code(), Some(0));
    let blocks = pcapng_blocks(&out.stdout).unwrap();
    assert_eq!(
        blocks.iter().filter(|&&b| b == 6).count(),
        3,
        "three enhanced packet blocks: {blocks:?}"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("3 frames written to -"));
    let out = run(&[
        "record", "demo", "-o", "-", "--count", "3", "--format", "pcapng", "--json",
    ]);
    pcapng_blocks(&out.stdout).unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stderr).unwrap();
    assert_eq!(report["frames"], 3);
}

#[test]
fn record_to_stdout_as_candump_is_log_lines_alone() {
    for json in [false, true] {
        let mut args = vec!["record", "demo", "-o", "-", "--count", "4"];
        if json {
            args.push("--json");
        }
        let out = run(&args);
        assert_eq!(out.status.code(), Some(0));
        let stdout = String::from_utf8(out.stdout).unwrap();
        assert_eq!(stdout.lines().count(), 4, "{stdout}");
        for line in stdout.lines() {
            let (time, rest) = line
                .split_once(") ")
                .unwrap_or_else(|| panic!("not candump -l: {line}"));
            let (iface, frame) = rest.split_once(' ').unwrap();
            assert!(
                time.starts_with('(') && iface == "demo" && frame.contains('#'),
                "{line}"
            );
        }
        let stderr = String::from_utf8(out.stderr).unwrap();
        if json {
            let v: serde_json::Value = serde_json::from_str(stderr.trim()).unwrap();
            assert_eq!(v["frames"], 4);
        } else {
            assert!(stderr.contains("4 frames written to -"), "{stderr}");
        }
    }
}

#[test]
fn sdo_read_and_dcf_save_to_stdout_give_the_data_alone() {
    let out = run(&["sdo", "read", "demo", "2", "0x1008", "-o", "-", "--json"]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(out.stdout, b"cotui simulated AIMOTOR-like servo");
    let v: serde_json::Value = serde_json::from_slice(&out.stderr).unwrap();
    assert_eq!(v["index"], 0x1008);
    let out = run(&["dcf", "save", "demo", "2", "-o", "-"]);
    assert_eq!(out.status.code(), Some(0));
    let dcf = String::from_utf8(out.stdout).unwrap();
    assert!(dcf.starts_with("[FileInfo]"), "{}", &dcf[..dcf.len().min(200)]);
    assert!(!dcf.contains("saved to"), "no report in the DCF");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("objects saved to -"),
        "report on stderr"
    );
    assert!(!std::path::Path::new("-").exists(), "no file named -");
}

/// A candump log of `n` frames in a fresh temp file.
fn log_of(n: usize, name: &str) -> std::path::PathBuf {
    let path = std::env::temp_dir().join(format!("cotui-streams-{}-{name}.log", std::process::id()));
    let text: String = (0..n)
        .map(|i| format!("({}.{:06}) can0 182#{:04X}\n", 1000 + i / 1000, i % 1000, i % 0xFFFF))
        .collect();
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn an_output_that_cannot_be_written_is_blamed_not_the_input() {
    if !std::path::Path::new("/dev/full").exists() {
        return;
    }
    // Small (the error comes at the final flush) and large (in the middle of the input).
    for n in [3, 50_000] {
        let log = log_of(n, &format!("full{n}"));
        let log = log.to_str().unwrap();
        for fmt in ["text", "jsonl", "pcapng"] {
            let out = run(&["decode", log, "--format", fmt, "-o", "/dev/full"]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{fmt} {n}: {err}");
            assert!(
                err.contains("cannot write /dev/full: No space left on device"),
                "{fmt} {n}: {err}"
            );
            assert!(!err.contains(log), "the input is not to blame: {err}");
        }
        let out = run(&["decode", log, "--transactions", "-o", "/dev/full"]);
        assert_eq!(out.status.code(), Some(0), "nothing to write is no error");
        std::fs::remove_file(log).unwrap();
    }
    let log = log_of(3, "proc");
    let log = log.to_str().unwrap();
    if std::path::Path::new("/proc/version").exists() {
        let out = run(&["decode", log, "-o", "/proc/version"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("/proc/version"), "the path is named: {err}");
    }
    let out = run(&["decode", log, "--format", "parquet", "-o", "/dev/full"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot write /dev/full: not a directory"), "{err}");
    std::fs::remove_file(log).unwrap();
}

#[test]
fn record_append_refuses_a_file_of_the_other_format() {
    let dir = std::env::temp_dir().join(format!("cotui-streams-append-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (pcap, text) = (dir.join("a.pcapng"), dir.join("a.log"));
    let (pcap, text) = (pcap.to_str().unwrap(), text.to_str().unwrap());
    let rec = |path: &str, fmt: &str| {
        run(&[
            "record", "demo", "-o", path, "--count", "2", "--format", fmt, "--append",
        ])
    };
    assert_eq!(rec(pcap, "pcapng").status.code(), Some(0));
    assert_eq!(rec(text, "candump").status.code(), Some(0));
    let (pcap_before, text_before) = (std::fs::read(pcap).unwrap(), std::fs::read(text).unwrap());
    let out = rec(pcap, "candump");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("is pcapng: --append would add candump lines to it"),
        "{err}"
    );
    let out = rec(text, "pcapng");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("is not pcapng (a text log?)"), "{err}");
    assert_eq!(std::fs::read(pcap).unwrap(), pcap_before, "untouched");
    assert_eq!(std::fs::read(text).unwrap(), text_before, "untouched");
    // The same format appends: pcapng as a second section.
    assert_eq!(rec(pcap, "pcapng").status.code(), Some(0));
    let blocks = pcapng_blocks(&std::fs::read(pcap).unwrap()).unwrap();
    assert_eq!(blocks.iter().filter(|&&b| b == 0x0A0D_0D0A).count(), 2, "{blocks:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn diagnose_of_nothing_says_only_the_error_and_a_bad_duration_is_usage() {
    let out = run(&["diagnose", "/nonexistent/cotui.log"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(out.stdout, b"", "no report of 0 frames");
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/cotui.log"));
    for bad in ["nan", "1e300", "inf", "0"] {
        let out = run(&["diagnose", "--live", "demo", "--duration", bad]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "--duration {bad}: {err}");
        assert!(err.contains("--duration"), "{err}");
    }
}

/// `record --format asc|trc` writes a Vector ASC / PEAK TRC 2.1 log that reads back to the
/// frames recorded (the header comes with the first frame); `--append` is refused for them.
#[test]
fn record_as_asc_and_trc_reads_back() {
    use cotui::log::{Format, LogReader, Outcome};
    for (fmt, format) in [("asc", Format::Asc), ("trc", Format::Trc)] {
        let out = run(&["record", "demo", "-o", "-", "--count", "4", "--format", fmt]);
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        let mut r = LogReader::new(&out.stdout[..]).unwrap();
        assert_eq!(r.format(), format);
        let mut frames = 0;
        while let Some((line, o)) = r.next_line().unwrap() {
            match o {
                Outcome::Frame(_) => frames += 1,
                Outcome::Skip(_) => {}
                Outcome::Warning(w) => panic!("{fmt} line {line}: {w}"),
            }
        }
        assert_eq!(frames, 4, "{fmt}");
        if fmt == "asc" {
            assert!(out.stdout.ends_with(b"End TriggerBlock\n"));
        }
        let dir = std::env::temp_dir().join(format!("cotui-rec-{}-{fmt}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.log");
        std::fs::write(&path, b"").unwrap();
        let out = run(&[
            "record",
            "demo",
            "-o",
            path.to_str().unwrap(),
            "--count",
            "1",
            "--format",
            fmt,
            "--append",
        ]);
        assert!(!out.status.success());
        assert!(String::from_utf8_lossy(&out.stderr).contains("--append goes with candump or pcapng"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
