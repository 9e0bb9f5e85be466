//! What the Watch pane and the palette's `watch` ask: `:watch NODE OBJ... [--every DUR]
//! [--timeout DUR]` adds objects to the board ([`super::watch_board`]) and has the bus task
//! poll them ([`Request::Watch`]); `:watch off` and stop-all stop every poll; the pane's
//! keys add (the palette, prefilled), delete, or open a row's object in the Objects pane;
//! `:export watch FILE.csv` writes the rounds polled. A listen-only session or a log
//! (open, replay) refuses to start a watch and says why.

use super::capture::Capture;
use super::event::{Event, Queue, WatchAsk};
use super::export::ExportError;
use super::live::Request;
use super::messages::Level;
use super::panes::watch::WatchPane;
use super::watch_board::lock;
use crate::command::Command;
use crate::command::watch_table::WatchFormat;
use crate::frame::NodeKey;
use crate::od::bind::Bindings;
use std::io::Write;
use std::path::Path;

/// Why a listen-only session polls nothing.
const LISTEN_ONLY: &str = "watch: listen-only session — nothing can be sent, so no object is polled";
/// Why a log polls nothing.
const NO_BUS: &str =
    "watch: this source is a log (open/replay), there is no bus to poll (use `cotui live IFACE` or `cotui demo`)";

/// Has the bus task poll what the board holds now (replacing the polls before).
fn send(capture: &Capture, pane: &WatchPane) {
    if capture.has_bus() && !capture.listen_only() {
        capture.request(Request::Watch {
            board: pane.board.clone(),
        });
    }
}

/// The palette's `watch ...` line: `watch off`, or objects to add.
pub(crate) fn command(capture: &Capture, pane: &mut WatchPane, bindings: &Bindings, line: &str, q: &mut Queue) {
    let rest = line.trim().strip_prefix("watch").unwrap_or_default().trim();
    if rest == "off" {
        let n = lock(&pane.board).stop_all();
        send(capture, pane);
        let text = match n {
            0 => "watch off: nothing was polled".to_string(),
            n => format!("watch off: {n} objects no longer polled (the rows stay: export watch FILE.csv)"),
        };
        return q.push(Event::Say(Level::Info, text));
    }
    let refused = if capture.listen_only() {
        Some(LISTEN_ONLY)
    } else if !capture.has_bus() {
        Some(NO_BUS)
    } else {
        None
    };
    if let Some(why) = refused {
        return q.push(Event::Say(Level::Error, why.into()));
    }
    let w = match crate::command::parse_command(line) {
        Ok(Command::Watch(w)) => w,
        Ok(_) => return,
        Err(e) => return q.push(Event::Say(Level::Error, format!("watch: {e}"))),
    };
    if w.duration_ms.is_some() || w.format != WatchFormat::Text {
        return q.push(Event::Say(
            Level::Error,
            "watch: --duration and --format are `cotui watch`'s; here the rows show in the Watch pane \
             (0) and `export watch FILE.csv` writes them"
                .into(),
        ));
    }
    let objects = match w.resolve(bindings) {
        Ok(o) => o,
        Err(e) => return q.push(Event::Say(Level::Error, format!("watch: {e}"))),
    };
    let titles: Vec<String> = objects.iter().map(|o| o.title()).collect();
    lock(&pane.board).add(objects, w.every_ms, w.timeout_ms);
    send(capture, pane);
    q.push(Event::Say(
        Level::Info,
        format!("watch: {} every {} ms (Watch pane: 0)", titles.join(", "), w.every_ms),
    ));
}

/// Stop-all: every row stopped; the stop-all request that follows has the bus task cancel
/// the polls first (its report lists them), before it stops the drives.
pub(crate) fn stop_all(pane: &mut WatchPane, q: &mut Queue) {
    if lock(&pane.board).stop_all() == 0 {
        return;
    }
    q.push(Event::Log(Level::Warn, "stop all: every watch stopped".into()));
}

/// What the Watch pane asked: the palette line to open for `a` (and its hint), or nothing.
pub(crate) fn ask(
    capture: &Capture,
    pane: &mut WatchPane,
    objects: &mut super::panes::objects::ObjectsPane,
    ask: WatchAsk,
    q: &mut Queue,
) -> Option<String> {
    match ask {
        WatchAsk::Add(node) => {
            q.push(Event::Note("watch NODE OBJ... [--every DUR] [--timeout DUR]".into()));
            Some(node.map_or("watch ".into(), |n| format!("watch {n} ")))
        }
        WatchAsk::Delete(k) => {
            let gone = lock(&pane.board).delete(k)?;
            send(capture, pane);
            q.push(Event::Note(format!(
                "watch: {} no longer watched",
                gone.watched.title()
            )));
            None
        }
        WatchAsk::Open(k) => {
            let (node, index, sub) = {
                let board = lock(&pane.board);
                let w = &board.rows.get(k)?.watched;
                (w.node, w.index, w.sub)
            };
            objects.pick(NodeKey::new(0, node));
            objects.set_query(&format!("{index:04x}:{sub:02x}"));
            q.push(Event::Act(super::keymap::Action::PaneObjects));
            None
        }
    }
}

/// `export watch FILE.csv [--force]` (the words after `watch`): the rounds polled as CSV,
/// as `cotui watch --format csv` writes them; the text says what was written.
pub(crate) fn export(rest: &str, pane: &WatchPane) -> Result<String, ExportError> {
    let (mut file, mut force) = (None, false);
    for w in rest.split_whitespace() {
        match w {
            "--force" => force = true,
            w if w.starts_with("--") => return Err(ExportError::UnknownOption(w.to_string())),
            w if file.is_none() => file = Some(w.to_string()),
            w => return Err(ExportError::ExtraFile(w.to_string())),
        }
    }
    let file = file.ok_or(ExportError::WatchUsage)?;
    let board = lock(&pane.board);
    if board.rows.is_empty() {
        return Err(ExportError::NothingWatched);
    }
    let text = board.csv();
    crate::tui::export::create(Path::new(&file), force)
        .and_then(|mut f| f.write_all(text.as_bytes()))
        .map_err(|source| ExportError::Write {
            file: file.clone(),
            source,
        })?;
    let rows = text.lines().count().saturating_sub(1);
    let dropped = match board.rounds().1 {
        0 => String::new(),
        d => format!(" (the oldest {d} rounds were dropped)"),
    };
    Ok(format!(
        "exported {rows} rounds of {} objects to {file}{dropped}",
        board.rows.len()
    ))
}

#[cfg(test)]
mod tests {
    use crate::command::watch_table::Sample;
    use crate::od::Value;
    use crate::tui::app::App;
    use crate::tui::keymap::Action;
    use crate::tui::live::Request;
    use crate::tui::panes::Pane;
    use crate::tui::panes::testutil::{app, live_app, screen};
    use crate::tui::watch_board::lock;
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

    /// The requests sent: `watch` or `stop`.
    fn sent(req: &mut tokio::sync::mpsc::UnboundedReceiver<Request>) -> Vec<String> {
        let mut out = Vec::new();
        while let Ok(r) = req.try_recv() {
            match r {
                Request::Watch { .. } => out.push("watch".into()),
                Request::StopAll { .. } => out.push("stop".into()),
                _ => {}
            }
        }
        out
    }

    fn key(a: &mut App, code: KeyCode) {
        a.key(KeyEvent::new(code, KeyModifiers::NONE));
    }

    /// Fills the board as the bus task would: a round with a value, the absent object and
    /// a timeout of node 9, at capture times before the fixture's last frame.
    fn polled(a: &mut App) {
        let now = a.trace().nodes.now_ns();
        let bindings = crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap();
        let mut board = lock(&a.screen().panes().watch().board);
        for (dt, pos) in [(400_000_000, 1200i64), (200_000_000, -35)] {
            let samples = vec![
                (0, Sample::Value(Value::Unsigned(0x0237))),
                (1, Sample::Value(Value::Signed(pos))),
                (
                    2,
                    Sample::Absent("abort 0x06020000 Object does not exist in the object dictionary".into()),
                ),
                (3, Sample::Failed("timeout".into())),
            ];
            board.took(now - dt, now - dt, samples, |w, s| {
                w.take(bindings.dictionary(w.node), s)
            });
        }
    }

    #[test]
    fn watch_adds_rows_polled_by_the_bus_task_and_the_pane_shows_values_min_max_age_and_aborts() {
        let (mut a, mut req) = live_app(false);
        a.run_command("watch 2 Statusword 0x6064 0x2FFF 9 0x1000 --every 100ms --timeout 50");
        assert_eq!(sent(&mut req), ["watch"]);
        assert_eq!(
            a.message(),
            Some(
                "watch: 2:0x6041 Statusword, 2:0x6064 Position actual value, 2:0x2FFF, 9:0x1000 Device type every 100 ms (Watch pane: 0)"
            )
        );
        polled(&mut a);
        key(&mut a, KeyCode::Char('0'));
        assert_eq!(a.focus(), Pane::Watch);
        let s = screen(&mut a, 200, 12);
        assert!(s.contains("  0 Watch"), "{s}");
        let row = |what: &str| s.lines().find(|l| l.contains(what)).unwrap_or_default().to_string();
        assert!(row("Position actual value").contains("-35"), "{s}");
        assert!(row("Position actual value").contains("1200"), "{s}");
        assert!(row("Position actual value").contains("0.2 s"), "{s}");
        assert!(row("0x2FFF").contains("absent"), "{s}");
        assert!(row("0x2FFF").contains("not polled again: abort 0x06020000"), "{s}");
        assert!(row("Device type").contains("2 failed; last: timeout"), "{s}");
        insta::assert_snapshot!("watch_pane_polled", s);
        // The same object again: one row, polled again.
        a.run_command("watch 2 0x2FFF");
        assert_eq!(sent(&mut req), ["watch"]);
        assert_eq!(lock(&a.screen().panes().watch().board).rows.len(), 4);
    }

    #[test]
    fn a_opens_the_palette_d_deletes_and_enter_opens_the_object_in_the_objects_pane() {
        let (mut a, mut req) = live_app(false);
        a.run_command("watch 2 Statusword 0x6064");
        sent(&mut req);
        a.act(Action::PaneWatch);
        a.act(Action::Down);
        key(&mut a, KeyCode::Char('a'));
        assert_eq!(a.screen().prompt().editing().map(|p| p.text.as_str()), Some("watch 2 "));
        key(&mut a, KeyCode::Esc);
        key(&mut a, KeyCode::Enter);
        assert_eq!(a.focus(), Pane::Objects);
        let s = screen(&mut a, 160, 20);
        assert!(s.contains("6064:00"), "{s}");
        assert!(s.contains("find `6064:00`"), "{s}");
        a.act(Action::PaneWatch);
        key(&mut a, KeyCode::Char('d'));
        assert_eq!(
            a.message(),
            Some("watch: 2:0x6064 Position actual value no longer watched")
        );
        assert_eq!(sent(&mut req), ["watch"]);
        assert_eq!(lock(&a.screen().panes().watch().board).rows.len(), 1);
    }

    #[test]
    fn listen_only_and_logs_refuse_to_start_a_watch_and_say_why() {
        let (mut a, mut req) = live_app(true);
        a.run_command("watch 2 Statusword");
        assert!(sent(&mut req).is_empty(), "nothing goes to the bus task");
        assert_eq!(
            a.message(),
            Some("watch: listen-only session — nothing can be sent, so no object is polled")
        );
        let mut a = app();
        a.run_command("watch 2 Statusword");
        assert!(
            a.message().unwrap_or("").starts_with("watch: this source is a log"),
            "{:?}",
            a.message()
        );
        assert!(lock(&a.screen().panes().watch().board).rows.is_empty());
        let (mut a, _req) = live_app(false);
        a.run_command("watch 2 Statusword --duration 1s");
        assert!(
            a.message().unwrap_or("").contains("--duration and --format"),
            "{:?}",
            a.message()
        );
        a.run_command("watch 0x6041");
        assert!(
            a.message().unwrap_or("").contains("give the node first"),
            "{:?}",
            a.message()
        );
    }

    #[test]
    fn stop_all_and_watch_off_stop_every_watch_first() {
        let (mut a, mut req) = live_app(false);
        a.run_command("watch 2 Statusword");
        a.run_command("watch 2 0x6064 --every 1s");
        assert_eq!(sent(&mut req), ["watch", "watch"]);
        a.key(KeyEvent::new(KeyCode::Char('s'), KeyModifiers::CONTROL));
        // The stop-all request cancels the polls on the bus task (see live.rs), first.
        assert_eq!(sent(&mut req), ["stop"]);
        let s = {
            a.act(Action::PaneWatch);
            screen(&mut a, 160, 12)
        };
        assert!(s.contains("0 polled"), "{s}");
        assert!(lock(&a.screen().panes().watch().board).groups().is_empty());
        assert!(s.lines().filter(|l| l.contains("stopped")).count() == 2, "{s}");
        a.run_command("watch 2 Statusword");
        a.run_command("watch off");
        assert_eq!(sent(&mut req), ["watch", "watch"]);
        assert_eq!(
            a.message(),
            Some("watch off: 1 objects no longer polled (the rows stay: export watch FILE.csv)")
        );
    }

    #[test]
    fn export_watch_writes_the_csv_of_cotui_watch() {
        let (mut a, _req) = live_app(false);
        let dir = std::env::temp_dir().join(format!("cotui-watch-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("watch.csv");
        a.run_command(&format!("export watch {}", file.display()));
        assert_eq!(
            a.message(),
            Some("export watch: nothing is watched (`watch NODE OBJ...` first)")
        );
        a.run_command("watch 2 Statusword 0x6064 0x2FFF 9 0x1000");
        polled(&mut a);
        a.run_command(&format!("export watch {}", file.display()));
        assert_eq!(
            a.message(),
            Some(format!("exported 2 rounds of 4 objects to {}", file.display()).as_str())
        );
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            "time_s,2:0x6041 Statusword,2:0x6064 Position actual value,2:0x2FFF,9:0x1000 Device type\n\
             0.000,567,1200,absent,timeout\n\
             0.200,567,-35,absent,timeout\n"
        );
        a.run_command(&format!("export watch {}", file.display()));
        assert!(a.message().unwrap_or("").contains("add --force"), "{:?}", a.message());
        std::fs::remove_dir_all(&dir).ok();
    }
}
