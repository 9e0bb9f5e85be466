//! Memory bounded whatever the input: peak RSS of a child `cotui` on generated logs.

use std::io::Write;
use std::process::{Command, Stdio};

/// Runs `cotui ARGS` with stdout to `out`; its exit code and peak RSS (KiB).
///
/// Measured by GNU time, which forks the child from its own small process: the rusage of
/// a child spawned straight from this test process would count this process's own peak
/// (Linux carries the spawning image's high-water mark over `exec`), which grows with
/// whatever the other tests of this binary do in parallel.
fn peak_rss_kib(args: &[&str], out: &std::path::Path) -> (i32, u64) {
    let rss_file = out.with_extension("rss");
    let status = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("%M")
        .arg("-o")
        .arg(&rss_file)
        .arg(env!("CARGO_BIN_EXE_cotui"))
        .args(args)
        .stdout(std::fs::File::create(out).unwrap())
        .stderr(Stdio::null())
        .status()
        .expect("GNU time (scripts/install-test-deps.sh installs it)");
    let text = std::fs::read_to_string(&rss_file).unwrap();
    // With a non-zero exit, GNU time writes "Command exited with non-zero status N" first.
    let rss = text.lines().last().and_then(|l| l.trim().parse().ok());
    (
        status.code().unwrap_or(-1),
        rss.unwrap_or_else(|| panic!("no peak RSS from time: {text}")),
    )
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cotui-bounded-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn diagnose_of_60000_distinct_aborts_keeps_1000_incidents() {
    // Node 7 refuses reads of 60,000 distinct objects, each once.
    let log = temp("aborts.log");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&log).unwrap());
    for i in 0..60_000u32 {
        let (index, sub) = (0x2000 + (i >> 8) as u16, (i & 0xFF) as u8);
        let [lo, hi] = index.to_le_bytes();
        let t = f64::from(i) * 0.002;
        writeln!(w, "({:.6}) can0 607#40{lo:02X}{hi:02X}{sub:02X}00000000", 1.7e9 + t).unwrap();
        writeln!(
            w,
            "({:.6}) can0 587#80{lo:02X}{hi:02X}{sub:02X}00000206",
            1.7e9 + t + 0.001
        )
        .unwrap();
    }
    w.flush().unwrap();
    let out = temp("aborts.txt");
    let (rc, rss) = peak_rss_kib(&["diagnose", log.to_str().unwrap()], &out);
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(rc, 0, "{}", &text[..text.len().min(2000)]);
    // One incident per object for the first 1,000; the other 59,000 refusals are one.
    assert_eq!(text.matches("Node 7: A value could not be read").count(), 1_001);
    assert!(
        text.contains("Cause: 59000 more refusals of objects beyond the first 1000 refused on the bus: "),
        "{}",
        &text[text.len().saturating_sub(3000)..]
    );
    assert!(text.len() < 4 << 20, "{} bytes of report", text.len());
    // 60,000 incidents took ~100 MB.
    assert!(rss < 48 << 10, "peak RSS {rss} KiB");
    std::fs::remove_dir_all(log.parent().unwrap()).unwrap();
}

/// The MF4 reader keeps one chunk and one inflated block per data group: `decode --summary`
/// of a file 8 times larger peaks within a few MiB of the smaller one's.
#[test]
fn mf4_reading_is_flat_in_file_size() {
    // A directory of its own: the other test removes the shared one when it ends.
    let dir = std::env::temp_dir().join(format!("cotui-bounded-mf4-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (small, big) = (dir.join("small.mf4"), dir.join("big.mf4"));
    cotui::bench::log::write_format_log(&small, 50_000, "mf4").unwrap();
    cotui::bench::log::write_format_log(&big, 400_000, "mf4").unwrap();
    let out = dir.join("mf4.out");
    let (code, small_kib) = peak_rss_kib(&["decode", "--summary", small.to_str().unwrap()], &out);
    assert_eq!(code, 0);
    let (code, big_kib) = peak_rss_kib(&["decode", "--summary", big.to_str().unwrap()], &out);
    assert_eq!(code, 0);
    let size = std::fs::metadata(&big).unwrap().len() / 1024;
    assert!(
        big_kib < small_kib + 4096,
        "peak {big_kib} KiB for a {size} KiB file, {small_kib} KiB for one 8 times smaller"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
