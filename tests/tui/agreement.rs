//! One capture, one answer: every fixture and every public real-world log goes through the
//! TUI as `cotui open` loads it (the log's reader thread, `App::ingest` to the end of the
//! input, a TestBackend draw) and through the command line, and the two faces agree:
//!
//! - the SDO pane's rows are the transfers `cotui decode --transactions --format jsonl`
//!   lists (same count, order and record, partial and cut-off transfers included);
//! - the Problems pane's incidents are those of `cotui diagnose --format jsonl`;
//! - the Nodes pane's nodes and frame counts are `decode --summary`'s nodes (node-IDs
//!   without CANopen evidence yet counted as the pane's other frames);
//! - the receive list (Stats pane) counts add up to `--summary`'s frames, and per COB-ID
//!   equal the frames `decode --format jsonl` prints with that COB-ID (`--summary` has no
//!   per-COB-ID table).

use cotui::analysis::trace::Trace;
use cotui::frame::json::write_line;
use cotui::tui::app::{App, SourceInfo, SourceKind};
use cotui::tui::keymap::{Action, Keymap};
use cotui::tui::source;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_cotui");

/// `cotui ARGS... PATH`'s standard output.
fn cli(args: &[&str], path: &Path) -> String {
    let out = Command::new(BIN).args(args).arg(path).output().expect("run cotui");
    String::from_utf8(out.stdout).expect("UTF-8")
}

/// The public real-world logs, beside the checkout (`../shared/realworld/logs`, or two
/// levels up from a worktree); None when they are not there.
pub(crate) fn realworld() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [
        root.join("../shared/realworld/logs"),
        root.join("../../shared/realworld/logs"),
    ]
    .into_iter()
    .find(|p| p.is_dir())
}

/// Every log the test compares: the fixtures (not the EDS, profile or sidecar files) and
/// the real-world logs with their derived candump forms.
fn logs() -> Vec<PathBuf> {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut dirs = vec![fixtures.clone(), fixtures.join("diagnose"), fixtures.join("seeds")];
    match realworld() {
        Some(rw) => {
            dirs.push(rw.join("derived"));
            dirs.push(rw);
        }
        None => println!("note: ../shared/realworld/logs not found; only the fixtures are compared"),
    }
    let mut out = Vec::new();
    for d in dirs {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let log = [".log", ".txt", ".asc"].iter().any(|x| name.ends_with(x));
            // Fixtures that need a profile bound are compared with it by the golden tests.
            if p.is_file() && log && !name.starts_with("profile_") && name != "MANIFEST.tsv" {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// An App that loaded `path` as `cotui open PATH` does, to the end of the input, and drew
/// its SDO pane once (so every pane model is up to date).
pub(crate) fn opened(path: &Path) -> App {
    let decoder = cotui::cli::bind::decoder(&[], &[]).unwrap();
    let name = path.display().to_string();
    let src = SourceInfo::new(&name, SourceKind::Open, source::open(path.to_path_buf(), None), None);
    let mut app = App::new(Trace::new(decoder, 500_000), Keymap::default_map(), src);
    for _ in 0..10_000 {
        if app.source().done {
            break;
        }
        if !app.ingest(Duration::from_millis(50)) {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    assert!(app.source().done, "{name}: the log was not read to its end");
    for pane in [
        Action::PaneProblems,
        Action::PaneNodes,
        Action::PaneStats,
        Action::PaneSdo,
    ] {
        app.act(pane);
        draw(&mut app, 160, 40);
    }
    app
}

/// Draws `app` on a `w`x`h` TestBackend; returns the screen text.
fn draw(app: &mut App, w: u16, h: u16) -> String {
    let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
    term.draw(|f| cotui::tui::ui::draw(f, app)).unwrap();
    let buf = term.backend().buffer().clone();
    let mut out = String::new();
    for y in 0..buf.area.height {
        let line: String = (0..buf.area.width).map(|x| buf[(x, y)].symbol().to_string()).collect();
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

/// The SDO pane's transfers as `--transactions --format jsonl` records.
fn sdo_rows(app: &App) -> Vec<String> {
    let dec = app.trace().decoder();
    // Several interfaces: each transfer names its own, as decode --transactions does.
    let several = app.trace().ifaces.names().len() > 1;
    app.trace()
        .transactions
        .iter()
        .map(|t| {
            let mut line = Vec::new();
            let mut json = t.to_json(dec.dictionary(t.node));
            json.iface = several.then(|| app.trace().ifaces.name(t.iface));
            write_line(&mut line, &json);
            String::from_utf8(line).unwrap().trim_end().to_string()
        })
        .collect()
}

/// Index, sub, direction and outcome of a `--transactions` record, for a readable diff.
fn brief(record: &str) -> String {
    let v: Value = serde_json::from_str(record).unwrap();
    format!(
        "{} {} {} {} {}",
        v["node"], v["index"], v["sub"], v["direction"], v["outcome"]
    )
}

#[test]
fn the_tui_and_the_command_line_agree_on_every_fixture_and_real_world_log() {
    let logs = logs();
    assert!(logs.len() >= 20, "only {} logs", logs.len());
    let mut transfers = 0;
    for path in &logs {
        let name = path.display().to_string();
        let mut app = opened(path);

        // SDO pane = decode --transactions.
        let want: Vec<String> = cli(&["decode", "--transactions", "--format", "jsonl"], path)
            .lines()
            .map(str::to_string)
            .collect();
        let got = sdo_rows(&app);
        assert_eq!(
            got.iter().map(|r| brief(r)).collect::<Vec<_>>(),
            want.iter().map(|r| brief(r)).collect::<Vec<_>>(),
            "{name}: SDO pane rows (node index sub direction outcome)"
        );
        assert_eq!(got, want, "{name}: SDO pane transfers");
        let screen = draw(&mut app, 160, 40);
        assert!(
            screen.contains(&format!("SDO transfers ({})", want.len())),
            "{name}:\n{screen}"
        );
        transfers += want.len();

        // Problems pane = diagnose.
        let want = cli(&["diagnose", "--format", "jsonl"], path);
        let origin = app.trace().diagnosis.origin_ns();
        let mut got = Vec::new();
        for i in app.screen().panes().problems().incidents() {
            write_line(&mut got, &i.to_json(origin));
        }
        assert_eq!(String::from_utf8(got).unwrap(), want, "{name}: Problems pane incidents");

        // Nodes pane = decode --summary's nodes.
        let summary: Value = serde_json::from_str(&cli(&["decode", "--summary", "--format", "jsonl"], path)).unwrap();
        // --summary names a node by its node-ID, or `IFACE/ID` when nodes of several
        // interfaces were seen.
        let several = summary["by_node"].as_object().unwrap().keys().any(|k| k.contains('/'));
        let key = |n: &cotui::frame::NodeKey| {
            if several {
                format!("{}/{}", app.trace().ifaces.name(n.iface), n.node)
            } else {
                n.node.to_string()
            }
        };
        let want: BTreeMap<String, u64> = summary["by_node"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(n, kinds)| {
                let total = kinds.as_object().unwrap().values().map(|c| c.as_u64().unwrap()).sum();
                (n.clone(), total)
            })
            .collect();
        // A node-ID shows as a node once the bus proves a CANopen node is there (a clean
        // SDO transfer, two well-formed heartbeats); until then its frames count as the
        // pane's "other" frames. Together they are --summary's nodes.
        let got: BTreeMap<String, u64> = app
            .trace()
            .nodes
            .iter()
            .map(|(n, info)| (key(n), info.frames))
            .collect();
        for (n, frames) in &got {
            assert_eq!(want.get(n), Some(frames), "{name}: node {n} in the Nodes pane");
        }
        let others: u64 = want.iter().filter(|(n, _)| !got.contains_key(*n)).map(|(_, f)| f).sum();
        assert_eq!(
            app.trace().nodes.other_frames(),
            others,
            "{name}: the Nodes pane's other frames"
        );

        // Receive list = --summary's frames, and per COB-ID the frames decode prints.
        let got: BTreeMap<(bool, u32), u64> = app.trace().stats.iter().map(|(k, s)| (*k, s.count)).collect();
        assert_eq!(
            got.values().sum::<u64>(),
            summary["frames"].as_u64().unwrap(),
            "{name}: receive list total"
        );
        let mut want: BTreeMap<(bool, u32), u64> = BTreeMap::new();
        for line in cli(&["decode", "--format", "jsonl"], path).lines() {
            let v: Value = serde_json::from_str(line).unwrap();
            let key = (v["ext"].as_bool().unwrap(), v["id"].as_u64().unwrap() as u32);
            *want.entry(key).or_default() += 1;
        }
        assert_eq!(got, want, "{name}: receive list counts per COB-ID");
    }
    assert!(transfers > 20, "the logs carry SDO transfers ({transfers})");
}

#[test]
fn the_interlaced_block_capture_shows_its_two_partial_transfers_in_the_sdo_pane() {
    let Some(rw) = realworld() else {
        println!("note: ../shared/realworld/logs not found; skipped");
        return;
    };
    let mut app = opened(&rw.join("canopendemo_sdo_block_interlaced.txt"));
    let s = draw(&mut app, 160, 20);
    assert!(s.contains("SDO transfers (2)"), "{s}");
    let rows = s.lines().filter(|l| l.contains("????:??") && l.contains(" incomplete"));
    assert_eq!(rows.count(), 2, "{s}");
}

#[test]
fn a_download_cut_short_says_how_much_of_the_announced_size_came() {
    let Some(rw) = realworld() else {
        println!("note: ../shared/realworld/logs not found; skipped");
        return;
    };
    let mut app = opened(&rw.join("canopennode_issue486_flood.txt"));
    let s = draw(&mut app, 120, 20);
    let row = s
        .lines()
        .find(|l| l.contains("7000:01"))
        .unwrap_or_else(|| panic!("{s}"));
    assert!(row.contains("7 of 64 bytes"), "{s}");
}
