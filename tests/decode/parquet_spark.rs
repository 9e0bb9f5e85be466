//! `cotui decode --format parquet` read by Spark: local-mode pyspark (a JRE and the python
//! `pyspark` package, installed by scripts/install-test-deps.sh) loads `frames.parquet` and
//! `values.parquet` of the fixture and real-world logs as written, and its counts per
//! file, kind and node agree with `cotui decode --summary` and with DuckDB.
//!
//! Without java or pyspark the test says so and passes, except in CI (`CI=true`), where
//! it fails: there the suite must prove Spark reads the tables.

use super::parquet_duckdb::{duckdb, logs, sorted, summary_counts, write_tables};
use serde_json::Value;
use std::collections::BTreeMap;
use std::process::Command;

/// The Spark job: one session for all files (the JVM start is the slow part). It prints
/// the column types Spark sees and the counts as one JSON object.
const SPARK: &str = r#"
import json, sys
try:
    from pyspark.sql import SparkSession
except ImportError:
    sys.exit("python package pyspark missing: run scripts/install-test-deps.sh")
root = sys.argv[1]
spark = (SparkSession.builder.master("local[2]").appName("cotui-parquet")
         .config("spark.ui.enabled", "false")
         .config("spark.sql.session.timeZone", "UTC")
         .config("spark.sql.shuffle.partitions", "2")
         .getOrCreate())
spark.sparkContext.setLogLevel("ERROR")
spark.read.parquet(root + "/*/frames.parquet").createOrReplaceTempView("frames")
spark.read.parquet(root + "/*/values.parquet").createOrReplaceTempView("vals")
q = lambda sql: [list(r) for r in spark.sql(sql).collect()]
out = {
    "types": {t: {f.name: f.dataType.simpleString() for f in spark.table(t).schema.fields}
              for t in ["frames", "vals"]},
    "kinds": q("SELECT file, kind, count(*) FROM frames GROUP BY file, kind"),
    "nodes": q("SELECT file, node, kind, count(*) FROM frames WHERE node IS NOT NULL GROUP BY file, node, kind"),
    "values": q("SELECT file, source, node, count(*) FROM vals GROUP BY file, source, node"),
    "ts_mismatch": q("SELECT count(*) FROM frames WHERE unix_micros(ts) != ts_ns div 1000")
        + q("SELECT count(*) FROM vals WHERE unix_micros(ts) != ts_ns div 1000 OR unix_micros(start_ts) != start_ts_ns div 1000"),
}
spark.stop()
print(json.dumps(out))
"#;

/// Why Spark cannot run here (java or pyspark missing), if so.
fn spark_missing() -> Option<String> {
    let java = Command::new("java").arg("-version").output();
    if !java.is_ok_and(|o| o.status.success()) {
        return Some("java not found".into());
    }
    let pyspark = Command::new("python3").args(["-c", "import pyspark"]).output();
    if !pyspark.is_ok_and(|o| o.status.success()) {
        return Some("python package pyspark not found".into());
    }
    None
}

/// Rows of a query grouped by their first field (the file), the rest of each row kept,
/// sorted.
fn by_file(rows: &Value) -> BTreeMap<String, Vec<Value>> {
    let mut out: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for r in rows.as_array().unwrap() {
        let r = r.as_array().unwrap();
        out.entry(r[0].as_str().unwrap().to_string())
            .or_default()
            .push(Value::Array(r[1..].to_vec()));
    }
    out.into_iter().map(|(file, v)| (file, sorted(v))).collect()
}

#[test]
fn spark_reads_the_tables_and_counts_as_summary_and_duckdb_do() {
    if let Some(why) = spark_missing() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{why}: CI must run the Spark check (scripts/install-test-deps.sh installs a JRE and pyspark)"
        );
        eprintln!("skipped: {why} (scripts/install-test-deps.sh installs a JRE and pyspark)");
        return;
    }
    let dir = std::env::temp_dir().join(format!("cotui-parquet-spark-{}", std::process::id()));
    let logs = logs();
    write_tables(&dir, &logs);
    let out = Command::new("python3")
        .args(["-c", SPARK, dir.to_str().unwrap()])
        .output()
        .expect("python3");
    assert!(out.status.success(), "spark: {}", String::from_utf8_lossy(&out.stderr));
    let spark: Value = serde_json::from_slice(&out.stdout).unwrap();

    // Spark's types: timestamps as timestamps (UTC micros), the rest as written.
    let types = &spark["types"];
    assert_eq!(types["frames"]["ts"], "timestamp", "{types}");
    assert_eq!(types["frames"]["ts_ns"], "bigint", "{types}");
    assert_eq!(types["frames"]["id"], "int", "{types}");
    assert_eq!(types["frames"]["data"], "binary", "{types}");
    assert_eq!(types["vals"]["start_ts"], "timestamp", "{types}");
    assert_eq!(
        spark["ts_mismatch"],
        serde_json::json!([[0], [0]]),
        "ts is ts_ns in microseconds"
    );

    let db = duckdb(
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
                "values",
                "SELECT file, source, node, count(*) FROM 'DIR/*/values.parquet' GROUP BY ALL".into(),
            ),
        ],
    );
    for q in ["kinds", "nodes", "values"] {
        assert_eq!(by_file(&spark[q]), by_file(&db[q]), "{q}: Spark vs DuckDB");
    }
    let (kinds, nodes, values) = (
        by_file(&spark["kinds"]),
        by_file(&spark["nodes"]),
        by_file(&spark["values"]),
    );
    let mut with_values = 0;
    for log in &logs {
        let file = log.to_str().unwrap();
        let (want_kinds, want_nodes) = summary_counts(log);
        let none = Vec::new();
        assert_eq!(kinds.get(file).unwrap_or(&none), &want_kinds, "{file}: frames per kind");
        assert_eq!(
            nodes.get(file).unwrap_or(&none),
            &want_nodes,
            "{file}: frames per node and kind"
        );
        with_values += usize::from(values.contains_key(file));
    }
    assert!(with_values >= 3, "logs with value rows: {with_values}");
    std::fs::remove_dir_all(&dir).unwrap();
}
