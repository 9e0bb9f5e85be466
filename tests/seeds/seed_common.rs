//! Shared helpers of the seed drive tests: run the real `cotui` binary on a log.

use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};

/// The text of `tests/fixtures/seeds/NAME`.
pub fn fixture(name: &str) -> String {
    let path = format!("{}/tests/fixtures/seeds/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Runs `cotui decode ARGS -` with `log` on stdin; returns stdout lines.
pub fn run(args: &[&str], log: &str) -> Vec<String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .arg("decode")
        .args(args)
        .arg("-")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cotui runs");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(log.as_bytes())
        .expect("log written");
    let out = child.wait_with_output().expect("cotui ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "cotui decode {args:?} failed: {stderr}");
    assert!(!stderr.contains("warning"), "cotui printed warnings: {stderr}");
    String::from_utf8(out.stdout)
        .expect("utf-8")
        .lines()
        .map(str::to_string)
        .collect()
}

/// Decodes `log` with `--format jsonl --profile BINDING` (e.g. `2=syntron-ds`);
/// returns the frames by input line number.
pub fn decode(bindings: &[&str], log: &str) -> Frames {
    let mut args = vec!["--format", "jsonl"];
    for b in bindings {
        args.push("--profile");
        args.push(b);
    }
    let frames = run(&args, log)
        .iter()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("bad JSONL `{l}`: {e}")))
        .collect();
    Frames(frames)
}

/// The decoded frames of one run.
pub struct Frames(pub Vec<Value>);

impl Frames {
    /// The frame read from input line `line`; checks it is `id#data` so that the
    /// assertion next to it and the log line cannot drift apart.
    pub fn at(&self, line: u64, id: u32, data: &str) -> &Value {
        let f = self
            .0
            .iter()
            .find(|f| f["line"] == line)
            .unwrap_or_else(|| panic!("no frame on line {line}"));
        assert_eq!(f["id"], id, "line {line}: COB-ID");
        assert_eq!(f["data"], data.replace(' ', ""), "line {line}: data");
        f
    }
}

/// Asserts the SDO fields of a frame: kind, node, index, sub and (when given) value.
pub fn sdo(f: &Value, kind: &str, node: u8, index: u16, sub: u8, value: Option<i64>) {
    assert_eq!(f["kind"], kind, "{f}");
    assert_eq!(f["node"], node, "{f}");
    assert_eq!(f["sdo"]["index"], index, "{f}");
    assert_eq!(f["sdo"]["sub"], sub, "{f}");
    if let Some(v) = value {
        assert_eq!(f["sdo"]["value"], v, "{f}");
    }
}

/// Asserts that the frame's label contains every piece.
pub fn label_has(f: &Value, pieces: &[&str]) {
    let label = f["label"].as_str().unwrap_or_default();
    for p in pieces {
        assert!(label.contains(p), "label `{label}` lacks `{p}`");
    }
}

/// The PDO signal of a frame by object, as (value, text).
pub fn signal(f: &Value, index: u16, sub: u8) -> (Value, String) {
    let s = f["pdo"]["signals"]
        .as_array()
        .and_then(|a| a.iter().find(|s| s["index"] == index && s["sub"] == sub))
        .unwrap_or_else(|| panic!("no signal 0x{index:04X}:{sub} in {f}"));
    (s["value"].clone(), s["text"].as_str().unwrap_or_default().to_string())
}
