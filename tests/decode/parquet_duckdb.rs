//! `cotui decode --format parquet`: DuckDB (the python `duckdb` package, installed by
//! scripts/install-test-deps.sh) reads the tables back, and what it counts and decodes
//! agrees with `cotui decode --summary`, `--format jsonl` and `--transactions` on the
//! fixture logs and the real-world logs in ../shared/realworld.

use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The fixture logs and the real-world logs, as absolute paths.
pub(super) fn logs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for (dir, suffix) in [
        (root.join("tests/fixtures"), ".log"),
        (root.join("../shared/realworld/logs/derived"), ".l.log"),
    ] {
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for e in entries {
            let p = e.unwrap().path();
            if p.to_string_lossy().ends_with(suffix) {
                out.push(p.canonicalize().unwrap());
            }
        }
    }
    out.sort();
    assert!(out.len() >= 15, "fixture and real-world logs found: {}", out.len());
    out
}

/// Runs `cotui decode ARGS LOG`, which must succeed.
pub(super) fn cotui(args: &[&str], log: &Path) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode"])
        .args(args)
        .arg(log)
        .output()
        .expect("run cotui");
    assert!(
        out.status.success(),
        "cotui decode {args:?} {}: {}",
        log.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Writes each log's two tables to `DIR/NN/` (`-o DIR`, the layout of a fleet of logs).
pub(super) fn write_tables(dir: &Path, logs: &[PathBuf]) {
    let _ = std::fs::remove_dir_all(dir);
    for (i, log) in logs.iter().enumerate() {
        let out = dir.join(format!("{i:02}"));
        cotui(&["--format", "parquet", "-o", out.to_str().unwrap()], log);
        assert!(out.join("frames.parquet").is_file() && out.join("values.parquet").is_file());
    }
}

/// `--summary` of `log` as sorted rows: frames per kind (`[kind, n]`) and per node-ID and
/// kind (`[node, kind, n]`; nodes of several interfaces, keyed `can1/5`, add up per node-ID
/// as a query of the frames table counts them).
pub(super) fn summary_counts(log: &Path) -> (Vec<Value>, Vec<Value>) {
    let summary = &json_lines(&cotui(&["--summary", "--format", "jsonl"], log))[0];
    let kinds = summary["by_kind"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, n)| json!([k, n]))
        .collect();
    let mut per_node: BTreeMap<(u64, String), u64> = BTreeMap::new();
    for (key, per_kind) in summary["by_node"].as_object().unwrap() {
        let node = key.rsplit('/').next().unwrap().parse::<u64>().unwrap();
        for (k, n) in per_kind.as_object().unwrap() {
            *per_node.entry((node, k.clone())).or_default() += n.as_u64().unwrap();
        }
    }
    let nodes = per_node.into_iter().map(|((node, k), n)| json!([node, k, n])).collect();
    (sorted(kinds), sorted(nodes))
}

/// `v` sorted by its JSON text (the order rows are compared in).
pub(super) fn sorted(mut v: Vec<Value>) -> Vec<Value> {
    v.sort_by_key(|r| r.to_string());
    v
}

fn json_lines(out: &std::process::Output) -> Vec<Value> {
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Runs `sql` queries in DuckDB over the tables under `dir`; each answer is a list of
/// rows (lists of values). A missing duckdb package fails the test with how to fix it.
pub(super) fn duckdb(dir: &Path, queries: &[(&str, String)]) -> BTreeMap<String, Value> {
    let script = r#"
import json, sys
try:
    import duckdb
except ImportError:
    sys.exit("python package duckdb missing: run scripts/install-test-deps.sh")
con = duckdb.connect()
con.execute("SET TimeZone='UTC'")
out = {}
for name, sql in json.loads(sys.argv[1]):
    out[name] = [list(r) for r in con.execute(sql).fetchall()]
print(json.dumps(out, default=str))
"#;
    let queries: Vec<(String, String)> = queries
        .iter()
        .map(|(n, q)| (n.to_string(), q.replace("DIR", &dir.display().to_string())))
        .collect();
    let out = Command::new("python3")
        .args(["-c", script, &serde_json::to_string(&queries).unwrap()])
        .output()
        .expect("python3");
    assert!(out.status.success(), "duckdb: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn duckdb_counts_and_decoded_fields_agree_with_summary_jsonl_and_transactions() {
    let dir = std::env::temp_dir().join(format!("cotui-parquet-{}", std::process::id()));
    let logs = logs();
    write_tables(&dir, &logs);
    let got = duckdb(
        &dir,
        &[
            (
                "kinds",
                "SELECT file, kind, count(*) FROM 'DIR/*/frames.parquet' GROUP BY ALL".into(),
            ),
            (
                "nodes",
                "SELECT file, node, kind, count(*) FROM 'DIR/*/frames.parquet' WHERE node IS NOT NULL GROUP BY ALL"
                    .into(),
            ),
            (
                "emcy_by_node",
                "SELECT node, count(*) FROM 'DIR/*/frames.parquet' WHERE kind='emcy' GROUP BY node".into(),
            ),
            (
                "emcy",
                "SELECT file, line, emcy_code, emcy_register FROM 'DIR/*/frames.parquet' WHERE kind='emcy'".into(),
            ),
            (
                "aborts",
                "SELECT file, line, sdo_index, sdo_sub, abort_code FROM 'DIR/*/frames.parquet' WHERE abort_code IS NOT NULL"
                    .into(),
            ),
            (
                "frames",
                "SELECT file, line, ts_ns, id, hex(data), label, epoch_us(ts) = ts_ns // 1000 FROM 'DIR/*/frames.parquet'"
                    .into(),
            ),
            (
                "transactions",
                "SELECT file, node, index, sub, outcome, abort_code, value_text, hex(data) FROM 'DIR/*/values.parquet' WHERE source='sdo'"
                    .into(),
            ),
            (
                "signals",
                "SELECT file, node, pdo_num, index, sub, name, value_text FROM 'DIR/*/values.parquet' WHERE source='pdo'"
                    .into(),
            ),
        ],
    );
    let rows = |name: &str, file: &str| -> Vec<Value> {
        let mut v: Vec<Value> = got[name]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r[0] == file)
            .map(|r| Value::Array(r.as_array().unwrap()[1..].to_vec()))
            .collect();
        v.sort_by_key(|r| r.to_string());
        v
    };
    let mut emcy_by_node: BTreeMap<u64, u64> = BTreeMap::new();
    let (mut emcy_seen, mut aborts_seen, mut signals_seen) = (0, 0, 0);
    for log in &logs {
        let file = log.to_str().unwrap();
        // Per-kind and per-node counts: --summary.
        let (kinds, nodes) = summary_counts(log);
        assert_eq!(rows("kinds", file), kinds, "{file}: frames per kind");
        assert_eq!(rows("nodes", file), nodes, "{file}: frames per node and kind");
        for r in nodes.iter().filter(|r| r[1] == "emcy") {
            *emcy_by_node.entry(r[0].as_u64().unwrap()).or_default() += r[2].as_u64().unwrap();
        }

        // Decoded fields: the JSONL frames.
        let (mut emcy, mut aborts, mut frames, mut signals) = (vec![], vec![], vec![], vec![]);
        for f in json_lines(&cotui(&["--format", "jsonl"], log)) {
            let t = f["t"].as_f64().unwrap();
            frames.push((
                f["line"].as_i64().unwrap(),
                t,
                f["id"].clone(),
                f["data"].clone(),
                f["label"].clone(),
            ));
            if let Some(e) = f.get("emcy") {
                emcy.push(json!([f["line"], e["code"], e["register"]]));
            }
            if let Some(code) = f.get("sdo").map(|s| &s["abort_code"]).filter(|c| !c.is_null()) {
                aborts.push(json!([f["line"], f["sdo"]["index"], f["sdo"]["sub"], code]));
            }
            for s in f.get("pdo").and_then(|p| p["signals"].as_array()).into_iter().flatten() {
                signals.push(json!([
                    f["node"],
                    f["pdo"]["num"],
                    s["index"],
                    s["sub"],
                    s["name"],
                    s["text"]
                ]));
            }
        }
        emcy_seen += emcy.len();
        aborts_seen += aborts.len();
        signals_seen += signals.len();
        assert_eq!(rows("emcy", file), sorted(emcy), "{file}: EMCY codes and registers");
        assert_eq!(rows("aborts", file), sorted(aborts), "{file}: SDO abort codes");
        assert_eq!(rows("signals", file), sorted(signals), "{file}: PDO signals");
        let mut pq_frames = rows("frames", file);
        pq_frames.sort_by_key(|r| r[0].as_i64());
        assert_eq!(pq_frames.len(), frames.len(), "{file}: frame count");
        for (p, (line, t, id, data, label)) in pq_frames.iter().zip(&frames) {
            assert_eq!(p[0].as_i64(), Some(*line), "{file}");
            // `ts_ns` is the JSONL `t` (a float of seconds, so to the microsecond), and `ts`
            // is `ts_ns` truncated to microseconds.
            let ns = p[1].as_i64().unwrap();
            assert!((ns as f64 / 1e9 - t).abs() < 1e-6, "{file}:{line}: time {p} vs {t}");
            assert_eq!((&p[2], &p[3], &p[4]), (id, data, label), "{file}:{line}");
            assert_eq!(p[5], true, "{file}:{line}: ts is ts_ns in microseconds");
        }

        // SDO transactions: --transactions.
        let mut tr = Vec::new();
        for t in json_lines(&cotui(&["--transactions", "--format", "jsonl"], log)) {
            tr.push(json!([
                t["node"],
                t["index"],
                t["sub"],
                t["outcome"],
                t["abort_code"],
                t["value_text"],
                t["data"]
            ]));
        }
        assert_eq!(rows("transactions", file), sorted(tr), "{file}: SDO transactions");
    }
    // The README's query over the whole fleet.
    let mut fleet: Vec<Value> = emcy_by_node.iter().map(|(n, c)| json!([n, c])).collect();
    fleet.sort_by_key(|r| r.to_string());
    let mut q = got["emcy_by_node"].as_array().unwrap().clone();
    q.sort_by_key(|r| r.to_string());
    assert_eq!(q, fleet, "EMCY frames per node over all logs");
    // The comparison saw each kind of decoded field.
    assert!(
        emcy_seen >= 3 && aborts_seen >= 1 && signals_seen >= 1,
        "{emcy_seen} {aborts_seen} {signals_seen}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn parquet_needs_an_output_path_and_a_file_name_layout() {
    let log = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cia301_mix.log");
    let run = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(["decode", "--format", "parquet"])
        .arg(&log)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1), "usage error");
    assert!(String::from_utf8_lossy(&run.stderr).contains("give -o DIR"), "{run:?}");
    assert!(run.stdout.is_empty());

    let dir = std::env::temp_dir().join(format!("cotui-parquet-file-{}", std::process::id()));
    let file = dir.join("run1.parquet");
    cotui(&["--format", "parquet", "-o", file.to_str().unwrap()], &log);
    let got = duckdb(
        &dir,
        &[
            ("frames", "SELECT count(*) FROM 'DIR/run1.parquet'".into()),
            ("values", "SELECT count(*) FROM 'DIR/run1.values.parquet'".into()),
            (
                "ts",
                "SELECT typeof(ts), strftime(ts, '%Y-%m-%d %H:%M:%S.%f') FROM 'DIR/run1.parquet' WHERE line = 18"
                    .into(),
            ),
        ],
    );
    assert_eq!(got["frames"], json!([[54]]));
    assert_eq!(got["values"][0][0].as_u64().map(|n| n > 0), Some(true));
    // A UTC timestamp (TIMESTAMPTZ_NS in DuckDB 2.0, TIMESTAMP WITH TIME ZONE in 1.x).
    let ty = got["ts"][0][0].as_str().unwrap();
    assert!(
        ty.contains("TIMESTAMP") && (ty.contains("TZ") || ty.contains("TIME ZONE")),
        "{ty}"
    );
    assert_eq!(got["ts"][0][1], "2023-11-14 22:13:20.018000");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_value_row_names_the_interface_of_its_node() {
    // tests/fixtures/two_buses.log: a read of node 2 on can0 never answered, its answer
    // seen on can1 only; two transfers of two nodes 2.
    let log = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/two_buses.log");
    let dir = std::env::temp_dir().join(format!("cotui-parquet-ifaces-{}", std::process::id()));
    cotui(&["--format", "parquet", "-o", dir.to_str().unwrap()], &log);
    let got = duckdb(
        &dir,
        &[(
            "sdo",
            "SELECT iface, node, outcome FROM 'DIR/values.parquet' WHERE source='sdo' ORDER BY iface".into(),
        )],
    );
    assert_eq!(got["sdo"], json!([["can0", 2, "incomplete"], ["can1", 2, "ok"]]));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_schema_is_the_documented_one() {
    // The column names, physical types, nullability and annotations of both tables (the
    // README's "Parquet tables"): only types Spark and Trino accept (signed integers,
    // TIMESTAMP_MICROS rather than NANOS), pinned so a change is deliberate.
    let log = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cia301_mix.log");
    let dir = std::env::temp_dir().join(format!("cotui-parquet-schema-{}", std::process::id()));
    cotui(&["--format", "parquet", "-o", dir.to_str().unwrap()], &log);
    let query = |table: &str| {
        format!(
            "SELECT name, type, repetition_type, converted_type FROM parquet_schema('DIR/{table}.parquet') WHERE type IS NOT NULL"
        )
    };
    let got = duckdb(&dir, &[("frames", query("frames")), ("values", query("values"))]);
    let mut text = String::new();
    for table in ["frames", "values"] {
        text.push_str(&format!("{table}.parquet\n"));
        for col in got[table].as_array().unwrap() {
            let c: Vec<&str> = col
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_str().unwrap_or("-"))
                .collect();
            text.push_str(&format!("  {}\n", c.join(" ")));
        }
    }
    insta::assert_snapshot!("parquet_schema", text);
    std::fs::remove_dir_all(&dir).unwrap();
}
