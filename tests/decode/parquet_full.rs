//! A Parquet table that cannot be written in the middle of the input (the disk is full:
//! the frame table is /dev/full) stops the decode with one message naming the table, the
//! OS error and where in the input it stopped; exit status 1 and no panic (issue 25, item 14).

use crate::run::cotui;

#[test]
fn a_full_disk_in_the_middle_of_the_input_is_said_once_with_the_table_and_the_line() {
    let dir = std::env::temp_dir().join(format!("cotui-parquet-full-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out_dir = dir.join("tables");
    std::fs::create_dir_all(&out_dir).unwrap();
    std::os::unix::fs::symlink("/dev/full", out_dir.join("frames.parquet")).unwrap();
    let log = dir.join("big.log");
    let (log_s, out_s) = (log.to_str().unwrap(), out_dir.to_str().unwrap());
    // More frames than a row group holds: the first group is written before the input ends.
    let wrote = cotui(&["bench", "--write-log", log_s, "--frames", "70000"], None);
    assert!(wrote.status.success());
    let out = cotui(&["decode", "--format", "parquet", "-o", out_s, log_s], None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "one message: {err}");
    let want = format!(
        "cotui decode: cannot write {out_s}/frames.parquet: No space left on device (os error 28) (at {log_s} line "
    );
    assert!(lines[0].starts_with(&want), "{err}");
    assert!(lines[0].ends_with("; stopped, the tables are incomplete"), "{err}");
    let line: u64 = lines[0][want.len()..].split(')').next().unwrap().parse().unwrap();
    assert!(line > 1 && line < 70_000, "in the middle of the input: {err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
