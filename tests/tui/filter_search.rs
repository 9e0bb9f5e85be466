//! The filter language end to end: `cotui decode --filter` and the TUI's filtered view
//! count the same frames on the same log (or/not/range/object/abort filters); a bad
//! expression exits 1 with its column, and in the TUI keeps the typed text; on a
//! 1,000,001-frame log, a search for a frame that only the last frame matches runs in the
//! background while the UI answers keys, and only then moves the selection.
//! The TUI parts run the real binary in tmux (scripts/install-test-deps.sh installs it).

use crate::tmux::Options;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_cotui");

/// A generated log of `frames` frames (`cotui bench --write-log`) in a fresh directory.
fn generated(name: &str, frames: u64) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("cotui-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("g.log");
    let ok = Command::new(BIN)
        .args([
            "bench",
            "--write-log",
            log.to_str().unwrap(),
            "--frames",
            &frames.to_string(),
        ])
        .status()
        .unwrap();
    assert!(ok.success());
    (dir, log)
}

/// Frames `cotui decode --filter EXPR` prints (one JSON object each).
fn decode_count(log: &Path, expr: &str) -> usize {
    let out = Command::new(BIN)
        .args(["decode", "--format", "jsonl", "--filter", expr, log.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    for l in text.lines() {
        serde_json::from_str::<serde_json::Value>(l).expect("a JSON object per line");
    }
    text.lines().count()
}

#[test]
fn a_bad_expression_exits_1_with_its_column() {
    let out = Command::new(BIN)
        .args(["decode", "--filter", "node 2 or zz", "tests/fixtures/cia301_mix.log"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("column 11: unknown word `zz`"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn decode_and_the_tui_filtered_view_count_the_same_frames() {
    let (dir, log) = generated("filter-counts", 40_000);
    let exprs = [
        "node 2 or node 3",
        "!sdo",
        "not (hb or sync) node 1-2",
        "id 700-77f",
        "id 180/780",
        "time 1.5-3.0",
        "abort or emcy",
        "sdo !abort node 4",
        "6060 or 6041",
    ];
    let counts: Vec<usize> = exprs.iter().map(|e| decode_count(&log, e)).collect();
    assert!(counts.iter().all(|&n| n > 0 && n < 40_000), "{counts:?}");
    let name = format!("cotui-fcount-{}", std::process::id());
    let s = Options::default().size(220, 40).key_delay(Duration::ZERO).start(
        &name,
        &format!("cd {} && {BIN} open g.log; echo cotui-exit=$?; sleep 60", dir.display()),
    );
    s.wait_within("the log to load", Duration::from_secs(120), |t| {
        t.contains("(end) | 40000 frames")
    });
    for (e, n) in exprs.iter().zip(&counts) {
        s.keys(&["/"]);
        s.keys(&["C-u"]);
        s.type_text(e);
        s.keys(&["Enter"]);
        let want = format!("filter: {e} ({n} rows)");
        s.wait_within(&want, Duration::from_secs(120), |t| t.contains(&want));
    }
    // A bad filter keeps the prompt open with the text, and says where it is wrong.
    s.keys(&["/"]);
    s.keys(&["C-u"]);
    s.type_text("node 2 or 6041:zz");
    s.keys(&["Enter"]);
    let t = s.wait_for("the error", |t| {
        t.contains("filter: column 16: `zz` is not a sub-index")
    });
    assert!(t.contains("filter: node 2 or 6041:zz"), "{t}");
    s.keys(&["Escape"]);
    s.wait_for("the prompt to close", |t| !t.contains("filter: node 2 or 6041:zz"));
    s.keys(&["q"]);
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_search_through_millions_of_frames_runs_in_the_background() {
    // Four million frames: long enough a search (every label decoded, ~1.5 s on the build
    // machine) that the help key is answered while it runs, even on a quiet machine.
    let (dir, log) = generated("search-4m", 4_000_000);
    // One heartbeat of node 125, only at the very end.
    let mut f = std::fs::OpenOptions::new().append(true).open(&log).unwrap();
    std::io::Write::write_all(&mut f, b"(1700001000.000000) can0 77D#05\n").unwrap();
    drop(f);
    let name = format!("cotui-search-{}", std::process::id());
    let s = Options::default().size(220, 40).key_delay(Duration::ZERO).start(
        &name,
        &format!("cd {} && {BIN} open g.log; echo cotui-exit=$?; sleep 60", dir.display()),
    );
    s.wait_within("the log to load", Duration::from_secs(600), |t| {
        t.contains("(end) | 4000001 frames")
    });
    s.keys(&["Home"]);
    s.wait_for("the first frame selected", |t| t.contains("frame 1  t 0.000000 s"));
    // The label text needs every frame decoded: the slowest kind of search.
    s.keys(&["C-f"]);
    s.type_text("\"node 125\"");
    // `?` right behind `enter`, in the same read: it is answered while the search has just
    // started, however slowly this machine delivers keys.
    s.keys_together(&["Enter", "?"]);
    // Wait for the whole frame that opened help: ratatui writes only the changed cells, top
    // to bottom, so a capture can catch the help drawn above a prompt line not yet
    // redrawn. The bottom line's message is written last.
    let t = s.wait_for("help", |t| {
        t.contains("Show or hide this help")
            && (t.contains("the selection stays until a match is found") || t.contains("match 1 of 1"))
    });
    assert!(
        t.contains("0 matches so far"),
        "the search ended before help opened:\n{t}"
    );
    s.keys(&["?"]);
    let t = s.wait_for("help to close", |t| !t.contains("Show or hide this help"));
    // Until the match is found, the selection stays on the first frame.
    if t.contains("0 matches so far") {
        assert!(t.contains("frame 1  t 0.000000 s"), "the selection moved:\n{t}");
    }
    // The match is found at the end, the selection goes there.
    let t = s.wait_within("the match", Duration::from_secs(600), |t| {
        t.contains("match 1 of 1 at frame 4000001")
    });
    assert!(t.contains("search: \"node 125\" (1 match)"), "{t}");
    assert!(t.contains("Heartbeat node 125: Operational"), "{t}");
    // `n` wraps around to the only match.
    s.keys(&["n"]);
    s.wait_for("the wrap", |t| {
        t.contains("match 1 of 1 at frame 4000001 (wrapped around)")
    });
    s.keys(&["q"]);
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    let _ = std::fs::remove_dir_all(&dir);
}
