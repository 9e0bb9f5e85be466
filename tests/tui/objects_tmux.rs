//! End-to-end: the real binary in a tmux pane. In `cotui demo`, the Objects pane (tab 6)
//! finds 0x6060 of drive 2 by typing, reads it with `enter`, writes a new value through the
//! palette that `e` prefills, and reads it back. Needs tmux (scripts/install-test-deps.sh).

use crate::tmux::Options;
use std::time::Duration;

/// The row of 0x6060 in the pane (without the side column).
fn row(screen: &str) -> String {
    screen
        .lines()
        .find(|l| l.contains("6060:00   Modes of operation"))
        .and_then(|l| l.split('┃').nth(1))
        .unwrap_or_default()
        .trim_end()
        .to_string()
}

/// The row shows a value with its age.
fn has_age(screen: &str) -> bool {
    let r = row(screen);
    r.ends_with(" ms") || r.ends_with(" s")
}

#[test]
fn demo_objects_pane_reads_and_writes_an_object() {
    let bin = env!("CARGO_BIN_EXE_cotui");
    let home = std::env::temp_dir().join(format!("cotui-objects-{}", std::process::id()));
    std::fs::create_dir_all(&home).unwrap();
    let cmd = format!("env XDG_CONFIG_HOME={} {bin} demo; sleep 60", home.display());
    let s = Options::default()
        .size(160, 45)
        .key_delay(Duration::from_millis(60))
        .start(&format!("cotui-objects-{}", std::process::id()), &cmd);
    s.wait_for("drive 2 in the nodes list", |t| t.contains("│  2 "));
    s.type_text("6");
    // The Nodes selection may be another node: `]` picks the next one (each key once the
    // screen shows what the one before did).
    let title = |t: &str| t.lines().nth(1).unwrap_or_default().to_string();
    let mut t = s.wait_for("the Objects pane", |t| t.contains("Objects · node "));
    for _ in 0..4 {
        if t.contains("Objects · node 2 aimotor > cia402") {
            break;
        }
        let before = title(&t);
        s.type_text("]");
        t = s.wait_for("the next node", |t| title(t) != before);
    }
    s.wait_for("node 2's dictionary", |t| {
        t.contains("Objects · node 2 aimotor > cia402")
    });

    // Find by typing, read with enter: the value and its age show in the row.
    s.type_text("/");
    s.type_text("6060");
    s.keys(&["Enter"]);
    s.wait_for("the find", |t| t.contains("find `6060`") && !row(t).is_empty());
    // The demo reads nothing by itself: the value and its age in the row come from our read.
    assert!(!has_age(&s.screen()), "{}", s.screen());
    s.keys(&["Enter"]);
    s.wait_for("the value read", has_age);

    // `e` opens the palette with the typed write; replace the value with 1 (profile position).
    s.type_text("e");
    let t = s.wait_for("the prefilled write", |t| t.contains(":sdo write 2 0x6060:0x00 "));
    let line = t
        .lines()
        .find(|l| l.starts_with(":sdo write 2 0x6060:0x00 "))
        .unwrap()
        .to_string();
    assert!(line.trim_end().ends_with("--type i8"), "{line}");
    let value = line[":sdo write 2 0x6060:0x00 ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    for _ in 0..value.chars().count() {
        s.keys(&["BSpace"]);
    }
    s.type_text("1");
    s.wait_for("the preview", |t| t.contains("will send: 602#2F60600001000000"));
    s.keys(&["Enter"]);
    // The row shows the value written (the download seen on the bus).
    s.wait_for("the write", |t| row(t).contains("1 (Profile position (PP))"));
    // Read it back: the message log has both results (the status line may show news of the
    // bus meanwhile).
    s.keys(&["Enter"]);
    s.type_text("m");
    s.wait_for("the value read back", |t| {
        t.contains("node 2 0x6060:00 Modes of operation written (1 bytes: 01)")
            && t.contains(
                "sdo read 2 0x6060:0x00: node 2 0x6060:00 Modes of operation = 1 (Profile position (PP)) (data 01)",
            )
    });
}
