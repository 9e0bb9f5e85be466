//! `cotui bench`'s temporary logs: a size that cannot fit the free space is refused before
//! anything is written, and SIGTERM in the middle removes the folder (issue 25, item 14).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// An empty folder of its own to be the bench's TMPDIR.
fn tmpdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cotui-bench-scratch-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bench(tmp: &Path, frames: &str) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_cotui"));
    cmd.args(["bench", "--frames", frames])
        .env("TMPDIR", tmp)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    cmd
}

/// Every file under `dir`, at any depth.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(files(&p));
        }
        out.push(p);
    }
    out
}

#[test]
fn a_size_beyond_the_free_space_is_refused_and_nothing_is_left() {
    let tmp = tmpdir("refused");
    let out = bench(&tmp, "18446744073709551615").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--frames 18446744073709551615: the generated logs need about"),
        "{err}"
    );
    assert!(err.contains("give fewer --frames"), "{err}");
    assert_eq!(files(&tmp), Vec::<PathBuf>::new());
    std::fs::remove_dir_all(&tmp).unwrap();
}

#[test]
fn sigterm_while_the_logs_are_written_removes_them() {
    let tmp = tmpdir("sigterm");
    let mut child = bench(&tmp, "5000000").spawn().unwrap();
    // Wait (on the condition, 60 s at most on a busy machine) until a log has bytes in it.
    let start = Instant::now();
    while !files(&tmp)
        .iter()
        .any(|f| f.is_file() && f.metadata().is_ok_and(|m| m.len() > 0))
    {
        assert!(child.try_wait().unwrap().is_none(), "bench ended before it wrote a log");
        assert!(start.elapsed() < Duration::from_secs(60), "no log written");
        std::thread::yield_now();
    }
    // SAFETY: kill has no memory effects; the pid is our child's.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(128 + libc::SIGTERM), "{err}");
    assert!(
        err.contains("cotui bench: stopped;") && err.contains("removed"),
        "{err}"
    );
    assert_eq!(files(&tmp), Vec::<PathBuf>::new(), "the temporary logs are gone");
    std::fs::remove_dir_all(&tmp).unwrap();
}
