//! `cotui open A.log B.log`: several logs in one TUI session, merged by time as `decode`
//! merges them. `split_bus_a.log` and `split_bus_b.log` are the two buses of
//! `two_buses.log`, recorded apart and both named `can0`: with `--iface-per-file` they are
//! two buses (node 5 twice in the Nodes pane, lost on one), without it one.

use cotui::analysis::trace::Trace;
use cotui::decode::Decoder;
use cotui::frame::NodeKey;
use cotui::tui::app::{App, SourceInfo, SourceKind};
use cotui::tui::keymap::Keymap;
use std::path::PathBuf;

const A: &str = "tests/fixtures/split_bus_a.log";
const B: &str = "tests/fixtures/split_bus_b.log";
/// Frames of both files.
const FRAMES: usize = 114;

fn open(per_file: bool) -> App {
    let files = [PathBuf::from(A), PathBuf::from(B)];
    let (name, rx) = cotui::cli::open_logs::open(&files, per_file, None).unwrap();
    assert_eq!(name, format!("{A} + {B}"));
    let trace = Trace::new(Decoder::new(Default::default(), Vec::new()), 500_000);
    App::new(
        trace,
        Keymap::default_map(),
        SourceInfo::new(&name, SourceKind::Open, rx, None),
    )
}

fn all_frames(a: &mut App) -> String {
    crate::screen::until_at(a, (160, 40), "every frame of both logs", |a, _| {
        a.trace().len() == FRAMES
    })
}

#[test]
fn two_logs_with_iface_per_file_are_two_buses_merged_by_time() {
    let mut a = open(true);
    let s = all_frames(&mut a);
    let names = a.trace().ifaces.names().to_vec();
    assert_eq!(names, [format!("{A}:can0"), format!("{B}:can0")]);
    let t = a.trace();
    let times: Vec<u64> = (0..t.len()).map(|i| t.store.frame(i).ts_ns).collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "frames merged by time");
    let ifaces: Vec<u16> = (0..t.len()).map(|i| t.store.frame(i).iface).collect();
    assert_eq!(ifaces.iter().filter(|&&i| i == 1).count(), 12, "B's frames on B's bus");
    // The second frame of the capture is B's first heartbeat (100.050), between A's.
    assert_eq!(ifaces[..3], [0, 1, 0]);
    for i in [0, 1] {
        assert!(
            t.nodes.iter().any(|(k, _)| *k == NodeKey::new(i, 5)),
            "node 5 on bus {i}"
        );
    }
    // The Nodes pane has node 5 once per bus: on A's still heartbeating, on B's lost (B's
    // log ends after 1 s, A's goes on for 10 s), as for `two_buses.log`.
    let rows: Vec<&str> = s.lines().filter(|l| l.contains("│tests/fixtu…")).collect();
    assert_eq!(rows.len(), 2, "{s}");
    assert!(rows[0].contains("   5 Operational"), "{s}");
    assert!(rows[1].contains("   5 LOST"), "{s}");
}

#[test]
fn two_logs_naming_the_same_interface_are_one_bus() {
    let mut a = open(false);
    all_frames(&mut a);
    let t = a.trace();
    assert_eq!(t.ifaces.names(), ["can0"]);
    let fives = t.nodes.iter().filter(|(k, _)| k.node == 5).count();
    assert_eq!(fives, 1, "one node 5 on the one bus");
}
