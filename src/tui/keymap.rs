//! Key bindings: JSON files mapping key specs to actions, validated at start.
//!
//! A keymap file is one JSON object, `{"KEYS": "action", ...}`. KEYS is one key or a
//! sequence separated by spaces (`"g g"`); a key is a character or a name (`enter esc tab
//! backtab space up down left right pageup pagedown home end backspace delete f1`..`f12`)
//! with optional `ctrl-`/`alt-`/`shift-` prefixes. The action `none` unbinds a key.
//! The embedded `keymaps/default.json` is the base, or `keymaps/vim.json` with `--keymap
//! vim`, or a file given with `--keymap FILE`; the user's `keymap.json` in the config
//! directory then overrides key by key. Unknown actions, keys bound twice and keys that
//! are a prefix of another binding are errors with file, line and column.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use serde::de::{Deserializer, MapAccess, Visitor};
use std::collections::BTreeMap;
use std::fmt;

/// The embedded default keymap.
pub const DEFAULT: &str = include_str!("../../keymaps/default.json");
/// The embedded vim-style keymap.
pub const VIM: &str = include_str!("../../keymaps/vim.json");

macro_rules! actions {
    ($($variant:ident = $name:literal : $help:literal,)*) => {
        /// Everything a key can do.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Action { $(#[doc = $help] $variant,)* }

        impl Action {
            /// Every action, in help order.
            pub const ALL: &[Action] = &[$(Action::$variant,)*];
            /// The name used in keymap files.
            pub fn name(self) -> &'static str {
                match self { $(Action::$variant => $name,)* }
            }
            /// One-line help.
            pub fn help(self) -> &'static str {
                match self { $(Action::$variant => $help,)* }
            }
            /// The action with this keymap name.
            pub fn from_name(s: &str) -> Option<Action> {
                match s { $($name => Some(Action::$variant),)* _ => None }
            }
        }
    };
}

actions! {
    Quit = "quit": "Quit",
    Help = "help": "Show or hide this help",
    Down = "down": "Next row",
    Up = "up": "Previous row",
    PageDown = "page_down": "Next page",
    PageUp = "page_up": "Previous page",
    Top = "top": "First row",
    Bottom = "bottom": "Last row (and follow)",
    Follow = "follow": "Toggle follow mode",
    Pause = "pause": "Pause or resume the capture / replay (Transmit: enable or disable the entry)",
    Expand = "expand": "Open the selected row (SDO transfer as a sequence diagram, its frame in the trace, signal to plot, PDO frames; Objects: read; Watch: the object in Objects; message log: the whole entry)",
    Back = "back": "Close popup, clear search, leave expanded view",
    NextPane = "next_pane": "Next pane",
    PrevPane = "prev_pane": "Previous pane",
    PaneTrace = "pane_trace": "Trace pane",
    PaneNodes = "pane_nodes": "Nodes pane",
    PaneSdo = "pane_sdo": "SDO transactions pane",
    PaneStats = "pane_stats": "Statistics pane",
    PanePlot = "pane_plot": "Plot pane",
    PaneObjects = "pane_objects": "Objects pane (dictionary of a node, last values)",
    PanePdo = "pane_pdo": "PDO pane (each node's RPDOs/TPDOs, their parameters and mapping source)",
    PaneProblems = "pane_problems": "Problems pane (the diagnosis: what went wrong, open first)",
    PaneTransmit = "pane_transmit": "Transmit pane (the transmit list: its frames, periods, counts sent)",
    PaneWatch = "pane_watch": "Watch pane (objects polled by SDO: value, min/max, age, last abort)",
    TransmitAdd = "transmit_add": "Transmit: add an entry (its JSON, as in the list file) (Watch: add objects, palette prefilled)",
    TransmitDelete = "transmit_delete": "Transmit: delete the selected entry (Watch: stop watching the selected object)",
    Filter = "filter": "Edit the filter (Objects: find by name, alias, index)",
    Search = "search": "Search (same language as the filter)",
    NextMatch = "next_match": "Jump to the next match (no search: the next trigger hit)",
    PrevMatch = "prev_match": "Jump to the previous match (no search: the previous trigger hit)",
    ClearFilter = "clear_filter": "Clear the filter",
    Palette = "palette": "Command palette",
    StopAll = "stop_all": "Stop all: cancel commands, stop every drive cotui commanded or sees powered",
    Messages = "messages": "Show or hide the message log (every result, event and error)",
    Copy = "copy": "Message log: copy the selected entry to the terminal's clipboard (OSC 52)",
    SpeedUp = "speed_up": "Replay faster",
    SpeedDown = "speed_down": "Replay slower",
    Step = "step": "Replay one frame (when paused)",
    StepBack = "step_back": "Replay: one frame back (replays up to the frame before)",
    Rewind = "rewind": "Replay: start over from the first frame",
    Loop = "loop": "Replay: loop at the end (on/off)",
    SeekForward = "seek_forward": "Replay: jump 10 s ahead (Plot focused: cursor right)",
    SeekBack = "seek_back": "Replay: jump 10 s back (Plot focused: cursor left)",
    NextSeries = "next_series": "Plot: next signal (Objects: next node)",
    PrevSeries = "prev_series": "Plot: previous signal (Objects: previous node)",
    PlotPick = "plot_pick": "Plot: pick signals (type to filter, enter adds or removes)",
    PlotMode = "plot_mode": "Plot: cycle the y axes (lanes, normalised, shared by unit)",
    ZoomIn = "zoom_in": "Plot: zoom in around the cursor (page keys pan, home: all)",
    ZoomOut = "zoom_out": "Plot: zoom out",
    Sort = "sort": "Stats: cycle the sort (COB-ID, count, period, last heard)",
    SyncCycles = "sync_cycles": "Stats: SYNC cycles (each period's TPDOs, late ones) or the receive list",
    SlowestCycle = "slowest_cycle": "SYNC cycles: select the slowest cycle (longest period) (Transmit: save the list to its file)",
    NextLateCycle = "next_late_cycle": "SYNC cycles: select the next cycle with a late TPDO (wraps)",
    EditObject = "edit_object": "Objects: write the entry (palette prefilled) (Transmit: edit the entry)",
    ReadAll = "read_all": "Objects: read every readable entry (again: stop)",
    TimeMode = "time_mode": "Trace: next time mode (since start, absolute, delta, delta same COB-ID, from the bookmark)",
    Bookmark = "bookmark": "Trace: set (or remove) a bookmark on the selected frame",
    NextBookmark = "next_bookmark": "Trace: jump to the next bookmark (wraps)",
    ShowFrames = "show_frames": "Problems: show the selected incident's frames in the trace (first, then the next at each press)",
    Boots = "boots": "Problems: the boot stories of each node, as diagnose --boots (again: the incidents)",
}

/// One key press, normalised (no SHIFT on characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Key {
    code: KeyCodeOrd,
    mods: u8,
}

/// `KeyCode` subset that is ordered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum KeyCodeOrd {
    Char(char),
    F(u8),
    Named(u8),
}

const NAMES: [(&str, KeyCode); 14] = [
    ("enter", KeyCode::Enter),
    ("esc", KeyCode::Esc),
    ("tab", KeyCode::Tab),
    ("backtab", KeyCode::BackTab),
    ("up", KeyCode::Up),
    ("down", KeyCode::Down),
    ("left", KeyCode::Left),
    ("right", KeyCode::Right),
    ("pageup", KeyCode::PageUp),
    ("pagedown", KeyCode::PageDown),
    ("home", KeyCode::Home),
    ("end", KeyCode::End),
    ("backspace", KeyCode::Backspace),
    ("delete", KeyCode::Delete),
];

impl Key {
    /// The key of a crossterm event, if it is one a keymap can name.
    pub fn from_event(ev: &KeyEvent) -> Option<Key> {
        let mut mods = ev.modifiers;
        let code = match ev.code {
            KeyCode::Char(c) => {
                mods.remove(KeyModifiers::SHIFT);
                KeyCodeOrd::Char(c)
            }
            KeyCode::F(n) => KeyCodeOrd::F(n),
            KeyCode::BackTab => {
                mods.remove(KeyModifiers::SHIFT);
                KeyCodeOrd::Named(3)
            }
            other => KeyCodeOrd::Named(NAMES.iter().position(|(_, c)| *c == other)? as u8),
        };
        Some(Key {
            code,
            mods: (mods & (KeyModifiers::CONTROL | KeyModifiers::ALT | KeyModifiers::SHIFT)).bits(),
        })
    }

    /// Parses one key spec such as `q`, `G`, `ctrl-c`, `pagedown`, `f1`.
    pub fn parse(spec: &str) -> Result<Key, KeyError> {
        let mut mods = KeyModifiers::NONE;
        let mut rest = spec;
        loop {
            let lower = rest.to_ascii_lowercase();
            let (m, len) = if lower.starts_with("ctrl-") && rest.len() > 5 {
                (KeyModifiers::CONTROL, 5)
            } else if lower.starts_with("alt-") && rest.len() > 4 {
                (KeyModifiers::ALT, 4)
            } else if lower.starts_with("shift-") && rest.len() > 6 {
                (KeyModifiers::SHIFT, 6)
            } else {
                break;
            };
            mods |= m;
            rest = &rest[len..];
        }
        let mut chars = rest.chars();
        let code = match (chars.next(), chars.next()) {
            (Some(c), None) => KeyCode::Char(c),
            _ => {
                let lower = rest.to_ascii_lowercase();
                if lower == "space" {
                    KeyCode::Char(' ')
                } else if let Some(n) = lower.strip_prefix('f').and_then(|n| n.parse::<u8>().ok()) {
                    if !(1..=12).contains(&n) {
                        return Err(KeyError::NoFunctionKey(rest.to_string()));
                    }
                    KeyCode::F(n)
                } else {
                    NAMES
                        .iter()
                        .find(|(n, _)| *n == lower)
                        .map(|(_, c)| *c)
                        .ok_or_else(|| KeyError::UnknownName(rest.to_string()))?
                }
            }
        };
        Key::from_event(&KeyEvent::new(code, mods)).ok_or_else(|| KeyError::Unknown(spec.to_string()))
    }
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mods = KeyModifiers::from_bits_truncate(self.mods);
        if mods.contains(KeyModifiers::CONTROL) {
            f.write_str("ctrl-")?;
        }
        if mods.contains(KeyModifiers::ALT) {
            f.write_str("alt-")?;
        }
        if mods.contains(KeyModifiers::SHIFT) {
            f.write_str("shift-")?;
        }
        match self.code {
            KeyCodeOrd::Char(' ') => f.write_str("space"),
            KeyCodeOrd::Char(c) => write!(f, "{c}"),
            KeyCodeOrd::F(n) => write!(f, "f{n}"),
            KeyCodeOrd::Named(i) => f.write_str(NAMES[i as usize].0),
        }
    }
}

/// A key sequence.
pub type Keys = Vec<Key>;

/// Formats a key sequence as in keymap files.
pub fn keys_text(keys: &[Key]) -> String {
    keys.iter().map(Key::to_string).collect::<Vec<_>>().join(" ")
}

/// A key spec that names no key.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum KeyError {
    /// `f` and a number outside 1..12.
    #[error("no key `{0}` (f1..f12)")]
    NoFunctionKey(String),
    /// A name that is not a key name.
    #[error("unknown key name `{0}`")]
    UnknownName(String),
    /// A key the terminal cannot report.
    #[error("unknown key `{0}`")]
    Unknown(String),
}

/// A keymap error, located in its file.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct KeymapError {
    /// File name (or `default`/`vim` for the embedded ones).
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

/// The entries of a JSON object in file order, duplicates kept.
struct Entries(Vec<(String, String)>);

impl<'de> serde::Deserialize<'de> for Entries {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Entries;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object of \"keys\": \"action\" pairs")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<Entries, A::Error> {
                let mut v = Vec::new();
                while let Some(e) = m.next_entry::<String, String>()? {
                    v.push(e);
                }
                Ok(Entries(v))
            }
        }
        d.deserialize_map(V)
    }
}

/// 1-based line and column (in characters) of byte offset `at` of `text`.
fn line_column(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at];
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (before.matches('\n').count() + 1, before[start..].chars().count() + 1)
}

/// Where each key of the top-level object of `text` starts (its opening quote), in file
/// order: the keys as written, escapes (`\u0067`) and all, so every entry is located.
fn key_positions(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let (mut depth, mut in_string, mut escaped) = (0usize, false, false);
    // At depth 1, a string right after `{` or `,` is a key.
    let mut expect_key = false;
    for (i, c) in text.char_indices() {
        if in_string {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                '"' => in_string = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => {
                if depth == 1 && expect_key {
                    out.push(line_column(text, i));
                }
                in_string = true;
                expect_key = false;
            }
            '{' | '[' => {
                depth += 1;
                expect_key = depth == 1;
            }
            '}' | ']' => depth = depth.saturating_sub(1),
            ',' => expect_key = depth == 1,
            _ => {}
        }
    }
    out
}

/// A keymap file's bytes as text; bytes that are not UTF-8 are an error at their line
/// and column.
pub fn utf8_text(name: &str, bytes: Vec<u8>) -> Result<String, KeymapError> {
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        // The prefix before the first bad byte is valid UTF-8.
        let text = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
        let (line, column) = line_column(text, valid);
        KeymapError {
            file: name.to_string(),
            line,
            column,
            message: format!("not UTF-8 (byte 0x{:02X})", bytes[valid]),
        }
    })
}

/// A binding and where it was defined.
#[derive(Clone, Debug)]
struct Origin {
    file: String,
    line: usize,
    column: usize,
}

/// Parses one keymap file into (keys, action or None for `none`, origin).
fn parse_file(name: &str, text: &str) -> Result<Vec<(Keys, Option<Action>, Origin)>, KeymapError> {
    let entries: Entries = serde_json::from_str(text).map_err(|e| {
        let whole = e.to_string();
        let at = format!(" at line {} column {}", e.line(), e.column());
        KeymapError {
            file: name.to_string(),
            line: e.line(),
            // serde_json says column 0 for an error at the end of a line.
            column: e.column().max(1),
            message: whole.strip_suffix(&at).unwrap_or(&whole).to_string(),
        }
    })?;
    let mut out: Vec<(Keys, Option<Action>, Origin)> = Vec::new();
    let positions = key_positions(text);
    for (i, (spec, action)) in entries.0.into_iter().enumerate() {
        let (line, column) = positions.get(i).copied().unwrap_or((1, 1));
        let origin = Origin {
            file: name.to_string(),
            line,
            column,
        };
        let err = |message: String| KeymapError {
            file: name.to_string(),
            line,
            column,
            message,
        };
        let keys: Keys = spec
            .split_whitespace()
            .map(Key::parse)
            .collect::<Result<_, _>>()
            .map_err(|m| err(format!("key \"{spec}\": {m}")))?;
        if keys.is_empty() {
            return Err(err("empty key".into()));
        }
        let act = if action == "none" {
            None
        } else {
            Some(Action::from_name(&action).ok_or_else(|| err(format!("unknown action \"{action}\"")))?)
        };
        if let Some((_, _, o)) = out.iter().find(|(k, _, _)| *k == keys) {
            return Err(err(format!(
                "key \"{}\" is already bound at line {}",
                keys_text(&keys),
                o.line
            )));
        }
        out.push((keys, act, origin));
    }
    Ok(out)
}

/// A validated keymap.
#[derive(Clone, Debug)]
pub struct Keymap {
    bindings: BTreeMap<Keys, (Action, Origin)>,
}

/// What a key press did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// A complete binding.
    Action(Action),
    /// The start of a longer binding: wait for more keys.
    Pending,
    /// Nothing bound.
    None,
}

impl Keymap {
    /// Builds a keymap: `base` (name, text) overridden key by key by each of `overrides`.
    /// A map with no key to quit is refused: only a signal could end the TUI.
    pub fn load(base: (&str, &str), overrides: &[(&str, &str)]) -> Result<Keymap, KeymapError> {
        let mut bindings: BTreeMap<Keys, (Action, Origin)> = BTreeMap::new();
        // The file the map's last quit key went away in (else the base, which has none).
        let mut quit_lost = Origin {
            file: base.0.to_string(),
            line: 1,
            column: 1,
        };
        for (i, (name, text)) in std::iter::once(&base).chain(overrides).enumerate() {
            for (keys, act, origin) in parse_file(name, text)? {
                let old = match act {
                    Some(a) => bindings.insert(keys, (a, origin.clone())),
                    None if i > 0 => bindings.remove(&keys),
                    None => None,
                };
                let quits = |b: &BTreeMap<Keys, (Action, Origin)>| b.values().any(|(a, _)| *a == Action::Quit);
                if old.is_some_and(|(a, _)| a == Action::Quit) && !quits(&bindings) {
                    quit_lost = origin;
                }
            }
        }
        let all: Vec<(&Keys, &Origin)> = bindings.iter().map(|(k, (_, o))| (k, o)).collect();
        for (a, oa) in &all {
            for (b, ob) in &all {
                if a.len() < b.len() && b.starts_with(a) {
                    // Blame the file that was given over the map it overrides.
                    let blame = if oa.file == base.0 && ob.file != base.0 { ob } else { oa };
                    return Err(KeymapError {
                        file: blame.file.clone(),
                        line: blame.line,
                        column: blame.column,
                        message: format!(
                            "key \"{}\" is a prefix of \"{}\": the longer binding could never be typed",
                            keys_text(a),
                            keys_text(b)
                        ),
                    });
                }
            }
        }
        if !bindings.values().any(|(a, _)| *a == Action::Quit) {
            return Err(KeymapError {
                file: quit_lost.file,
                line: quit_lost.line,
                column: quit_lost.column,
                message: "no key quits: bind one to \"quit\" (e.g. \"q\": \"quit\")".into(),
            });
        }
        Ok(Keymap { bindings })
    }

    /// The embedded default keymap.
    pub fn default_map() -> Keymap {
        Keymap::load(("default", DEFAULT), &[]).expect("the embedded default keymap is valid")
    }

    /// Looks up the keys typed so far.
    pub fn lookup(&self, keys: &[Key]) -> Lookup {
        if let Some((a, _)) = self.bindings.get(keys) {
            return Lookup::Action(*a);
        }
        if self.bindings.keys().any(|k| k.starts_with(keys)) {
            Lookup::Pending
        } else {
            Lookup::None
        }
    }

    /// The keys bound to each action, in action order (for the help screen).
    pub fn help(&self) -> Vec<(Action, Vec<String>)> {
        Action::ALL
            .iter()
            .map(|a| {
                let keys = self
                    .bindings
                    .iter()
                    .filter(|(_, (b, _))| b == a)
                    .map(|(k, _)| keys_text(k))
                    .collect();
                (*a, keys)
            })
            .filter(|(_, k): &(Action, Vec<String>)| !k.is_empty())
            .collect()
    }

    /// The first key bound to `action` (for hints in the status bar).
    pub fn key_for(&self, action: Action) -> Option<String> {
        self.bindings
            .iter()
            .find(|(_, (a, _))| *a == action)
            .map(|(k, _)| keys_text(k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(c: KeyCode, m: KeyModifiers) -> Key {
        Key::from_event(&KeyEvent::new(c, m)).unwrap()
    }

    #[test]
    fn embedded_keymaps_are_valid() {
        let d = Keymap::default_map();
        assert_eq!(
            d.lookup(&[key(KeyCode::Char('q'), KeyModifiers::NONE)]),
            Lookup::Action(Action::Quit)
        );
        let v = Keymap::load(("vim", VIM), &[]).unwrap();
        let g = key(KeyCode::Char('g'), KeyModifiers::NONE);
        assert_eq!(v.lookup(&[g]), Lookup::Pending);
        assert_eq!(v.lookup(&[g, g]), Lookup::Action(Action::Top));
        assert_eq!(
            v.lookup(&[key(KeyCode::Char('G'), KeyModifiers::SHIFT)]),
            Lookup::Action(Action::Bottom)
        );
    }

    #[test]
    fn user_file_overrides_and_unbinds_per_key() {
        let user = r#"{"x": "quit", "q": "none"}"#;
        let m = Keymap::load(("default", DEFAULT), &[("user.json", user)]).unwrap();
        assert_eq!(
            m.lookup(&[key(KeyCode::Char('x'), KeyModifiers::NONE)]),
            Lookup::Action(Action::Quit)
        );
        assert_eq!(m.lookup(&[key(KeyCode::Char('q'), KeyModifiers::NONE)]), Lookup::None);
        assert_eq!(
            m.lookup(&[key(KeyCode::Char('c'), KeyModifiers::CONTROL)]),
            Lookup::Action(Action::Quit)
        );
    }

    #[test]
    fn errors_are_located() {
        let bad = "{\n  \"q\": \"quit\",\n  \"j\": \"jump_around\"\n}";
        assert_eq!(
            Keymap::load(("k.json", bad), &[]).unwrap_err().to_string(),
            "k.json:3:3: unknown action \"jump_around\""
        );
        let dup = "{\n  \"ctrl-c\": \"quit\",\n  \"Ctrl-c\": \"help\"\n}";
        assert_eq!(
            Keymap::load(("k.json", dup), &[]).unwrap_err().to_string(),
            "k.json:3:3: key \"ctrl-c\" is already bound at line 2"
        );
        let prefix = "{\"g\": \"top\",\n \"g g\": \"bottom\"}";
        assert_eq!(
            Keymap::load(("k.json", prefix), &[]).unwrap_err().to_string(),
            "k.json:1:2: key \"g\" is a prefix of \"g g\": the longer binding could never be typed"
        );
        let user_prefix = r#"{"g": "top"}"#;
        let e = Keymap::load(("vim", VIM), &[("user.json", user_prefix)]).unwrap_err();
        assert!(e.to_string().starts_with("user.json:1:2: key \"g\" is a prefix"), "{e}");
        assert!(Keymap::load(("k.json", r#"{"hyper-x": "quit"}"#), &[]).is_err());
        assert_eq!(Keymap::load(("k.json", "{\"q\": 1}"), &[]).unwrap_err().line, 1);
    }

    #[test]
    fn a_map_without_quit_is_refused_where_the_quit_went() {
        let e = Keymap::load(("k.json", "{}"), &[]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "k.json:1:1: no key quits: bind one to \"quit\" (e.g. \"q\": \"quit\")"
        );
        let user = "{\n  \"q\": \"none\",\n  \"ctrl-c\": \"help\"\n}";
        let e = Keymap::load(("default", DEFAULT), &[("user.json", user)]).unwrap_err();
        assert!(e.to_string().starts_with("user.json:3:3: no key quits"), "{e}");
        // Moving quit to another key is fine.
        let user = r#"{"q": "none", "ctrl-c": "none", "x": "quit"}"#;
        assert!(Keymap::load(("default", DEFAULT), &[("user.json", user)]).is_ok());
    }

    #[test]
    fn escapes_bad_bytes_and_prefixes_of_the_users_file_are_located() {
        let escaped = "{\"q\": \"quit\",\n  \"\\u0067\": \"top\", \"x\": \"jump\"}";
        assert_eq!(
            Keymap::load(("k.json", escaped), &[]).unwrap_err().to_string(),
            "k.json:2:20: unknown action \"jump\""
        );
        let bad_escape = "{\"q\": \"quit\",\n \"\\u00zz\": \"help\"}";
        assert_eq!(
            Keymap::load(("k.json", bad_escape), &[]).unwrap_err().to_string(),
            "k.json:2:8: invalid escape"
        );
        let cut = "{\"q\": \"quit\",\n";
        let e = Keymap::load(("k.json", cut), &[]).unwrap_err();
        assert!((e.line, e.column) == (2, 1), "{e}");
        // The user's longer key under a base key: the user's file is blamed, not `default`.
        let user = "{\n  \"f x\": \"help\"}";
        let e = Keymap::load(("default", DEFAULT), &[("user.json", user)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "user.json:2:3: key \"f\" is a prefix of \"f x\": the longer binding could never be typed"
        );
        let e = utf8_text("k.json", b"{\"q\": \"quit\",\n \"\xC3x\": \"help\"}".to_vec()).unwrap_err();
        assert_eq!(e.to_string(), "k.json:2:3: not UTF-8 (byte 0xC3)");
        assert_eq!(utf8_text("k.json", b"{}".to_vec()).unwrap(), "{}");
    }

    #[test]
    fn keys_print_as_they_parse() {
        for s in ["q", "ctrl-c", "pagedown", "f5", "space", "alt-x", "backtab", "G"] {
            assert_eq!(Key::parse(s).unwrap().to_string(), s);
        }
        let bad = |s: &str| Key::parse(s).unwrap_err().to_string();
        assert_eq!(bad("f13"), "no key `f13` (f1..f12)");
        assert_eq!(bad("ctrl-hyper"), "unknown key name `hyper`");
        let located = Keymap::load(("k.json", "{\"ctrl-hyper\": \"quit\"}"), &[]).unwrap_err();
        assert_eq!(
            located.to_string(),
            "k.json:1:2: key \"ctrl-hyper\": unknown key name `hyper`"
        );
    }
}
