//! What the Transmit pane asks ([`TransmitAsk`]): loading a list file, toggling, adding,
//! editing, deleting and saving entries, and sending the list on the bus task
//! ([`Request::Transmit`]: the sender of `send --list`, [`crate::command::transmit_run`]).
//! A listen-only session refuses to enable an entry; stop-all disables every entry first.

use super::capture::Capture;
use super::event::{Event, Queue, TransmitAsk};
use super::live::Request;
use super::messages::Level;
use super::panes::transmit::{TransmitPane, TxRow};
use crate::command::transmit_list::{load_each, load_entry};
use crate::od::bind::Bindings;
use std::path::Path;

/// Why an entry cannot be enabled in a listen-only session.
const LISTEN_ONLY: &str = "transmit: listen-only session — nothing can be sent, the entry stays disabled";

/// A template for a new entry (the cursor goes inside the frame's quotes).
/// Loads the list file at `path` into `pane` (a bad entry is shown as such with its
/// line, the others work), then sends it; what went wrong goes to `q`. An unreadable file
/// or one that is not a list is an error.
pub(crate) fn load(
    capture: &Capture,
    pane: &mut TransmitPane,
    bindings: &Bindings,
    path: &Path,
    q: &mut Queue,
) -> Result<(), String> {
    let bytes = crate::files::read_capped(path).map_err(|e| format!("--transmit {}: {e}", path.display()))?;
    let text = String::from_utf8(bytes).map_err(|_| format!("--transmit {}: not UTF-8 text", path.display()))?;
    let each = load_each(&text, bindings).map_err(|e| format!("--transmit {}: {e}", path.display()))?;
    pane.file = Some(path.to_path_buf());
    pane.rows = each
        .into_iter()
        .map(|(raw, entry)| {
            if let Err(p) = &entry {
                q.push(Event::Say(Level::Error, format!("transmit {}: {p}", path.display())));
            }
            TxRow {
                raw: compact(&raw),
                entry: entry.map_err(|p| p.message),
                sent_before: 0,
            }
        })
        .collect();
    if capture.listen_only() && pane.rows.iter().any(enabled) {
        for k in 0..pane.rows.len() {
            set_enabled(pane, k, false, bindings);
        }
        q.push(Event::Say(
            Level::Warn,
            "transmit: listen-only session — every entry loaded disabled, nothing is sent".into(),
        ));
    }
    send(capture, pane);
    Ok(())
}

/// True when the row resolves and is enabled.
fn enabled(r: &TxRow) -> bool {
    r.entry.as_ref().is_ok_and(|e| e.enabled)
}

/// An entry's JSON on one line (as typed, when it is not JSON).
fn compact(raw: &str) -> String {
    serde_json::from_str::<serde_json::Value>(raw)
        .and_then(|v| serde_json::to_string(&v))
        .unwrap_or_else(|_| raw.to_string())
}

/// Sets row `k`'s `enabled` in its JSON and resolves it again.
fn set_enabled(pane: &mut TransmitPane, k: usize, on: bool, bindings: &Bindings) {
    let Some(row) = pane.rows.get_mut(k).filter(|r| r.entry.is_ok()) else {
        return;
    };
    let Ok(serde_json::Value::Object(mut m)) = serde_json::from_str::<serde_json::Value>(&row.raw) else {
        return;
    };
    if on {
        m.remove("enabled");
    } else {
        m.insert("enabled".into(), serde_json::Value::Bool(false));
    }
    row.raw = serde_json::Value::Object(m).to_string();
    row.entry = load_entry(&row.raw, k + 1, bindings).map_err(|p| p.message);
}

/// Keeps the counts so far in the rows, before the list changes and is sent again.
fn bank(pane: &mut TransmitPane) {
    let sent: Vec<u64> = (0..pane.rows.len()).map(|k| pane.sent(k)).collect();
    for (row, n) in pane.rows.iter_mut().zip(sent) {
        row.sent_before = n;
    }
    pane.progress = Default::default();
}

/// Sends the pane's entries on the bus task (replacing the list sent before; call
/// [`bank`] before changing the rows). Nothing when there is no bus.
fn send(capture: &Capture, pane: &mut TransmitPane) {
    if !capture.has_bus() || capture.listen_only() {
        return;
    }
    capture.request(Request::Transmit {
        entries: pane.entries(),
        progress: pane.progress.clone(),
    });
}

/// Every entry disabled, the counts so far kept (nothing is sent here).
fn all_off(pane: &mut TransmitPane, bindings: &Bindings) {
    bank(pane);
    for k in 0..pane.rows.len() {
        set_enabled(pane, k, false, bindings);
    }
}

/// Stop-all: every entry disabled (before the drives are stopped); nothing more is sent.
pub(crate) fn disable_all(capture: &Capture, pane: &mut TransmitPane, bindings: &Bindings, q: &mut Queue) {
    if !pane.rows.iter().any(enabled) {
        return;
    }
    all_off(pane, bindings);
    send(capture, pane);
    q.push(Event::Log(
        Level::Warn,
        "stop all: every transmit entry disabled".into(),
    ));
}

/// The list stopped on the bus task (`why`: a quick stop another program sent): every
/// entry shows off, as it is; nothing is sent again until one is enabled.
pub(crate) fn stopped_elsewhere(pane: &mut TransmitPane, bindings: &Bindings, why: &str, q: &mut Queue) {
    all_off(pane, bindings);
    q.push(Event::Say(
        Level::Warn,
        format!("transmit: every entry disabled: {why}"),
    ));
}

/// Does what the pane asked.
pub(crate) fn ask(
    capture: &Capture,
    pane: &mut TransmitPane,
    bindings: &Bindings,
    ask: TransmitAsk,
    q: &mut Queue,
) -> Option<(String, usize)> {
    match ask {
        TransmitAsk::Toggle(k) => {
            let row = pane.rows.get(k)?;
            let on = match &row.entry {
                Ok(e) => !e.enabled,
                Err(why) => {
                    q.push(Event::Say(
                        Level::Error,
                        format!("transmit: entry {} is bad: {why}", k + 1),
                    ));
                    return None;
                }
            };
            if on && capture.listen_only() {
                q.push(Event::Say(Level::Error, LISTEN_ONLY.into()));
                return None;
            }
            if on && !capture.has_bus() {
                q.push(Event::Say(
                    Level::Error,
                    "transmit: this source has no bus (use `cotui live IFACE` or `cotui demo`)".into(),
                ));
                return None;
            }
            bank(pane);
            set_enabled(pane, k, on, bindings);
            send(capture, pane);
            q.push(Event::Note(format!(
                "transmit: entry {} {}",
                k + 1,
                if on { "enabled" } else { "disabled" }
            )));
            None
        }
        TransmitAsk::Add => {
            pane.editing = None;
            Some((String::new(), 0))
        }
        TransmitAsk::Edit(k) => {
            let raw = pane.rows.get(k)?.raw.clone();
            pane.editing = Some(k);
            let len = raw.chars().count();
            Some((raw, len))
        }
        TransmitAsk::Delete(k) => {
            if k < pane.rows.len() {
                bank(pane);
                pane.rows.remove(k);
                // The last row deleted: the one before it is selected.
                pane.select(k.min(pane.rows.len().saturating_sub(1)));
                send(capture, pane);
                q.push(Event::Note(format!("transmit: entry {} deleted (w: save)", k + 1)));
            }
            None
        }
        TransmitAsk::Save => {
            let (level, text) = match &pane.file {
                None => (
                    Level::Error,
                    "transmit: no file to save to (start with --transmit FILE)".to_string(),
                ),
                Some(path) => match std::fs::write(path, pane.file_text()) {
                    Ok(()) => (
                        Level::Info,
                        format!("transmit: {} entries saved to {}", pane.rows.len(), path.display()),
                    ),
                    Err(e) => (Level::Error, format!("transmit: cannot save {}: {e}", path.display())),
                },
            };
            q.push(Event::Say(level, text));
            None
        }
    }
}

/// The prompt's line for the pane: a new entry, or the edited one. A bad entry keeps the
/// prompt open with the text (the problem on the status line).
pub(crate) fn submit(
    capture: &Capture,
    pane: &mut TransmitPane,
    bindings: &Bindings,
    text: &str,
    q: &mut Queue,
) -> Result<(), String> {
    let k = pane.editing.take().filter(|k| *k < pane.rows.len());
    let index = k.unwrap_or(pane.rows.len());
    let json = crate::command::transmit_line::entry_json(text).map_err(|e| {
        pane.editing = k;
        format!("transmit entry: {e}")
    })?;
    let entry = load_entry(&json, index + 1, bindings).map_err(|p| {
        pane.editing = k;
        format!("transmit entry: {}", p.message)
    })?;
    if entry.enabled && capture.listen_only() {
        pane.editing = k;
        return Err(format!("{LISTEN_ONLY}: add \"enabled\": false to keep it in the list"));
    }
    bank(pane);
    let row = TxRow {
        raw: compact(&json),
        entry: Ok(entry),
        sent_before: 0,
    };
    match k {
        Some(k) => {
            let before = pane.rows[k].sent_before;
            pane.rows[k] = TxRow {
                sent_before: before,
                ..row
            };
        }
        None => {
            pane.rows.push(row);
            pane.select(index);
        }
    }
    send(capture, pane);
    q.push(Event::Note(format!(
        "transmit: entry {} {} (w: save)",
        index + 1,
        if k.is_some() { "changed" } else { "added" }
    )));
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::tui::app::App;
    use crate::tui::keymap::Action;
    use crate::tui::live::Request;
    use crate::tui::panes::Pane;
    use crate::tui::panes::testutil::{live_app, screen};
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

    /// A list: a periodic frame, an RPDO of the demo's node 2 disabled, a bad frame.
    const LIST: &str = r#"{
  "entries": [
    { "frame": "123#0102", "every_ms": 10, "comment": "heartbeat-ish" },
    { "rpdo": "rpdo1", "node": 2, "signals": { "Controlword": "0x0F" }, "enabled": false },
    { "frame": "12G#01" }
  ]
}"#;

    fn list_file(name: &str) -> std::path::PathBuf {
        let path = std::env::temp_dir().join(format!("cotui-tx-{name}-{}.json", std::process::id()));
        std::fs::write(&path, LIST).unwrap();
        path
    }

    /// The enabled flags of the last list sent to the bus task.
    fn last_sent(req: &mut tokio::sync::mpsc::UnboundedReceiver<Request>) -> Option<Vec<(String, bool)>> {
        let mut last = None;
        while let Ok(r) = req.try_recv() {
            if let Request::Transmit { entries, .. } = r {
                last = Some(entries.iter().map(|e| (e.what.clone(), e.enabled)).collect());
            }
        }
        last
    }

    /// The on/off column of the row showing `what`.
    fn state(s: &str, what: &str) -> String {
        let line = s.lines().find(|l| l.contains(what)).unwrap_or_default();
        line.trim_start_matches('┃')
            .split_whitespace()
            .nth(1)
            .unwrap_or_default()
            .to_string()
    }

    fn key(a: &mut App, c: char) {
        a.key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE));
    }

    #[test]
    fn a_list_loads_with_its_bad_entry_located_and_the_rest_is_sent() {
        let (mut a, mut req) = live_app(false);
        // A name of fixed length: the title and the message show it (the snapshot).
        let path = std::env::temp_dir().join("cotui-transmit-pane-snapshot.json");
        std::fs::write(&path, LIST).unwrap();
        a.load_transmit(&path).unwrap();
        assert_eq!(
            last_sent(&mut req).unwrap(),
            [
                ("123#0102".to_string(), true),
                ("RPDO1 node 2 202#0F0000000000".to_string(), false)
            ]
        );
        let log: Vec<String> = a.screen().messages().iter().map(|m| m.text.clone()).collect();
        assert!(
            log.iter()
                .any(|m| m.contains("entry 3 (line 5)") && m.contains("12G#01")),
            "{log:?}"
        );
        a.act(Action::PaneTransmit);
        assert_eq!(a.focus(), Pane::Transmit);
        let s = screen(&mut a, 160, 12);
        assert!(s.contains("  9 Transmit"), "{s}");
        assert_eq!(state(&s, "123#0102"), "on", "{s}");
        assert!(s.contains("every 10 ms"), "{s}");
        assert_eq!(state(&s, "RPDO1 node 2 202#0F0000000000"), "off", "{s}");
        assert!(s.contains("bad"), "{s}");
        let s = s.replace(&path.display().to_string(), "LIST.json");
        insta::assert_snapshot!("transmit_pane_loaded", s);
    }

    #[test]
    fn a_quick_stop_from_elsewhere_ends_the_list_and_the_pane_shows_every_entry_off() {
        use crate::tui::app::{SourceInfo, SourceKind};
        use crate::tui::source::Feed;
        let (ftx, frx) = std::sync::mpsc::channel();
        let (rtx, mut req) = tokio::sync::mpsc::unbounded_channel();
        let mut a = crate::tui::panes::testutil::app();
        *a.capture_mut().source_mut() = SourceInfo::live("vcan0", SourceKind::Live { listen_only: false }, frx, rtx);
        a.set_bindings(crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap());
        a.load_transmit(&list_file("elsewhere")).unwrap();
        last_sent(&mut req);
        a.act(Action::PaneTransmit);
        assert_eq!(state(&screen(&mut a, 160, 12), "123#0102"), "on");
        // The bus task's sender saw another program's quick stop and ended.
        let why = "a quick stop of node 2 was seen on the bus (a stop-all); nothing more sent";
        ftx.send(Feed::TransmitStopped(why.into())).unwrap();
        a.ingest(std::time::Duration::from_millis(100));
        let s = screen(&mut a, 160, 12);
        assert_eq!(state(&s, "123#0102"), "off", "{s}");
        assert_eq!(
            a.message(),
            Some(format!("transmit: every entry disabled: {why}").as_str())
        );
        assert!(last_sent(&mut req).is_none(), "nothing sent again");
        // Space enables the entry again: the list is sent with it on.
        key(&mut a, ' ');
        assert_eq!(last_sent(&mut req).unwrap()[0], ("123#0102".to_string(), true));
    }

    #[test]
    fn space_toggles_a_adds_d_deletes_and_w_saves_the_list() {
        let (mut a, mut req) = live_app(false);
        let path = list_file("edit");
        a.load_transmit(&path).unwrap();
        last_sent(&mut req);
        a.act(Action::PaneTransmit);
        // Space on entry 1: disabled, the list sent again without it enabled.
        key(&mut a, ' ');
        assert_eq!(last_sent(&mut req).unwrap()[0], ("123#0102".to_string(), false));
        // `a`: an entry typed on one line (a frame, sent once).
        key(&mut a, 'a');
        for c in "7FF#AA".chars() {
            key(&mut a, c);
        }
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        let sent = last_sent(&mut req).unwrap();
        assert_eq!(sent.last().unwrap(), &("7FF#AA".to_string(), true));
        // An RPDO by its signal names, on one line, encoded through node 2's mapping.
        key(&mut a, 'a');
        for c in "rpdo1 2 Controlword=0x0F every 10ms # enable".chars() {
            key(&mut a, c);
        }
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        let sent = last_sent(&mut req).unwrap();
        assert_eq!(
            sent.last().unwrap(),
            &("RPDO1 node 2 202#0F0000000000".to_string(), true)
        );
        key(&mut a, 'd');
        last_sent(&mut req);
        // A bad entry typed keeps the prompt open and says why.
        key(&mut a, 'a');
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert!(a.screen().prompt().editing().is_some());
        assert!(
            a.message().unwrap_or("").starts_with("transmit entry: "),
            "{:?}",
            a.message()
        );
        a.key(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE));
        // `d` on the selected (the added) entry, then `w`.
        key(&mut a, 'd');
        assert_eq!(last_sent(&mut req).unwrap().len(), 2);
        key(&mut a, 'w');
        let saved = std::fs::read_to_string(&path).unwrap();
        let back = crate::command::transmit_list::load_each(
            &saved,
            &crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap(),
        )
        .unwrap();
        assert_eq!(back.len(), 3, "{saved}");
        assert!(back[0].1.as_ref().is_ok_and(|e| !e.enabled), "{saved}");
        assert!(back[2].1.is_err(), "the bad entry is kept as written: {saved}");
    }

    #[test]
    fn an_empty_pane_says_how_to_add_an_entry_and_w_says_there_is_no_file() {
        let (mut a, _req) = live_app(false);
        a.act(Action::PaneTransmit);
        let s = screen(&mut a, 160, 12);
        assert!(s.contains("no entries (a: add one)"), "{s}");
        key(&mut a, 'w');
        assert_eq!(
            a.message(),
            Some("transmit: no file to save to (start with --transmit FILE)")
        );
    }

    #[test]
    fn listen_only_refuses_to_enable_and_says_why() {
        let (mut a, mut req) = live_app(true);
        a.load_transmit(&list_file("lo")).unwrap();
        assert!(last_sent(&mut req).is_none(), "nothing goes to the bus task");
        a.act(Action::PaneTransmit);
        let s = screen(&mut a, 160, 12);
        assert_eq!(state(&s, "123#0102"), "off", "loaded disabled:\n{s}");
        key(&mut a, ' ');
        assert!(
            a.message()
                .unwrap_or("")
                .contains("listen-only session — nothing can be sent"),
            "{:?}",
            a.message()
        );
        let s = screen(&mut a, 160, 12);
        assert_eq!(state(&s, "123#0102"), "off", "still disabled:\n{s}");
    }

    #[test]
    fn stop_all_disables_every_entry_before_it_stops_the_drives() {
        let (mut a, mut req) = live_app(false);
        a.load_transmit(&list_file("stop")).unwrap();
        last_sent(&mut req);
        a.key(KeyEvent::new(KeyCode::Char('s'), KeyModifiers::CONTROL));
        let mut order = Vec::new();
        while let Ok(r) = req.try_recv() {
            match r {
                Request::Transmit { entries, .. } => {
                    assert!(entries.iter().all(|e| !e.enabled));
                    order.push("transmit");
                }
                Request::StopAll { .. } => order.push("stop"),
                _ => {}
            }
        }
        assert_eq!(order, ["transmit", "stop"]);
        a.act(Action::PaneTransmit);
        let s = screen(&mut a, 160, 12);
        assert_eq!(state(&s, "123#0102"), "off", "{s}");
    }
}
