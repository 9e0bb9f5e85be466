//! cotui's own reads do not flood the Problems pane: on the in-process demo bus, a read-all
//! of drive 2 (the dictionary knows objects the drive does not have), then a drive fault on
//! node 2 and a silent node 3. The first Problems screen at 80x24 shows the fault and the
//! lost node; the objects the drive lacks are one info row, and the read-all summary counts
//! them as not present, not as failed.

use crate::objects_demo::demo_app;
use crate::screen::screen_at;
use cotui::tui::app::App;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

fn key(a: &mut App, code: KeyCode) {
    a.key(KeyEvent::new(code, KeyModifiers::NONE));
}

fn until(a: &mut App, what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    crate::screen::until_at(a, (80, 24), what, f)
}

#[test]
fn own_reads_of_missing_objects_do_not_hide_a_drive_fault_and_a_lost_node() {
    let mut a = demo_app();
    until(&mut a, "nodes 2 and 3 to be listed", |a, _| {
        a.trace().nodes.iter().any(|(n, _)| n.node == 2) && a.trace().nodes.iter().any(|(n, _)| n.node == 3)
    });
    key(&mut a, KeyCode::Char('6'));
    for _ in 0..4 {
        if screen_at(&mut a, 160, 40).contains("Objects · node 2 aimotor > cia402") {
            break;
        }
        key(&mut a, KeyCode::Char(']'));
    }
    key(&mut a, KeyCode::Char('R'));
    until(&mut a, "the read-all to end", |a, _| {
        !a.screen().panes().objects().reading_all()
    });
    let summary = a
        .screen()
        .messages()
        .iter()
        .map(|e| e.text.clone())
        .find(|t| t.starts_with("read all node 2: ") && t.contains(" entries read"))
        .expect("a summary in the message log");
    // The objects the drive does not have are "not present", not failures.
    assert!(summary.contains(" not present"), "{summary}");
    assert!(!summary.contains("does not exist"), "{summary}");
    assert!(summary.contains(", 0 failed"), "{summary}");
    a.run_command("sim fault 2 0x2310");
    a.run_command("sim silence 3");
    key(&mut a, KeyCode::Char('8'));
    let s = until(&mut a, "the fault and the lost node in Problems", |_, s| {
        s.contains("Went silent") && s.contains("Stopped:")
    });
    // One info row for the objects the drive lacks, ranked after the real problems.
    let absent = summary
        .split(" not present")
        .next()
        .and_then(|h| h.rsplit(' ').next())
        .unwrap()
        .to_string();
    assert_ne!(absent, "0", "{summary}");
    let rows: Vec<&str> = s.lines().filter(|l| l.contains("Node ")).collect();
    let info: Vec<&&str> = rows.iter().filter(|l| l.contains("not present")).collect();
    assert_eq!(info.len(), 1, "{s}");
    assert!(info[0].contains("INFO      Node 2 "), "{s}");
    assert!(info[0].contains(&format!("{absent} objects not present")), "{s}");
    assert!(!s.contains("could not be read"), "{s}");
    let pos = |what: &str| rows.iter().position(|l| l.contains(what)).unwrap();
    assert!(pos("OPEN      Node 3") < pos("not present"), "{s}");
    assert!(pos("OPEN      Node 2") < pos("not present"), "{s}");
}
