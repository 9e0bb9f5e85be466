//! The message log: every command result, event and error of the session with its time.
//! The status line shows the latest; the log (popup, `m`) keeps them all, bounded.

use std::collections::VecDeque;
use std::time::SystemTime;

/// How much a message matters (its colour in the log).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// A result or a normal event.
    Info,
    /// Something the user should look at (a lost node, a drive not confirmed stopped).
    Warn,
    /// A command failed or the interface is unusable.
    Error,
}

/// One logged message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Wall-clock time it was logged.
    pub at: SystemTime,
    pub level: Level,
    /// The full text; may span several lines (every node of a scan, every step of a run).
    pub text: String,
}

/// The log: the newest [`Messages::CAPACITY`] entries, oldest first.
#[derive(Clone, Debug, Default)]
pub struct Messages {
    entries: VecDeque<Entry>,
    /// Entries dropped from the front because the log was full.
    pub dropped: u64,
}

impl Messages {
    /// Entries kept; older ones are dropped (and counted).
    pub const CAPACITY: usize = 10_000;

    /// Appends a message logged at `at`.
    pub fn push(&mut self, at: SystemTime, level: Level, text: &str) {
        if self.entries.len() == Self::CAPACITY {
            self.entries.pop_front();
            self.dropped += 1;
        }
        self.entries.push_back(Entry {
            at,
            level,
            text: text.to_string(),
        });
    }
    /// The entries, oldest first.
    pub fn iter(&self) -> impl DoubleEndedIterator<Item = &Entry> {
        self.entries.iter()
    }
    /// Number of entries kept.
    pub fn len(&self) -> usize {
        self.entries.len()
    }
    /// True when nothing was logged.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
    /// The entry at position `i` (0 = oldest kept).
    pub fn get(&self, i: usize) -> Option<&Entry> {
        self.entries.get(i)
    }
    /// The log as display lines: `HH:MM:SS.mmm  text`, continuation lines indented.
    pub fn lines(&self) -> Vec<(Level, String)> {
        let mut out = Vec::new();
        for e in &self.entries {
            let stamp = clock(e.at);
            for (i, l) in e.text.lines().enumerate() {
                let lead = if i == 0 { stamp.as_str() } else { "            " };
                out.push((e.level, format!("{lead}  {l}")));
            }
        }
        out
    }
}

/// Width of the time stamp and the gap after it that starts every log line.
pub const LEAD: usize = 14;

impl Entry {
    /// The entry as display lines `width` characters wide: the time stamp on the first,
    /// continuation lines indented under the text, long lines wrapped by words.
    pub fn wrapped(&self, width: usize) -> Vec<String> {
        let stamp = clock(self.at);
        let mut out = Vec::new();
        for l in self.text.lines() {
            for piece in wrap(l, width.saturating_sub(LEAD).max(8)) {
                let lead = if out.is_empty() { stamp.as_str() } else { "            " };
                out.push(format!("{lead}  {piece}"));
            }
        }
        if out.is_empty() {
            out.push(stamp);
        }
        out
    }
}

/// `line` broken into pieces of at most `width` characters, between words where it can
/// (a word longer than `width` is cut); leading spaces are kept on the first piece.
pub fn wrap(line: &str, width: usize) -> Vec<String> {
    let width = width.max(1);
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut len = 0;
    let mut started = false;
    for word in line.split(' ') {
        let wl = word.chars().count();
        if !started {
            started = true;
        } else if len + 1 + wl <= width {
            cur.push(' ');
            len += 1;
        } else {
            out.push(std::mem::take(&mut cur));
            len = 0;
            if word.is_empty() {
                continue;
            }
        }
        let mut rest = word;
        while len + rest.chars().count() > width {
            let cut = rest.char_indices().nth(width - len).map_or(rest.len(), |(i, _)| i);
            cur.push_str(&rest[..cut]);
            out.push(std::mem::take(&mut cur));
            len = 0;
            rest = &rest[cut..];
        }
        len += rest.chars().count();
        cur.push_str(rest);
    }
    if !cur.is_empty() || out.is_empty() {
        out.push(cur);
    }
    out
}

/// The local time of day of `t` as `HH:MM:SS.mmm`.
pub fn clock(t: SystemTime) -> String {
    let d = t.duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default();
    let secs = d.as_secs() as libc::time_t;
    // SAFETY: `libc::tm` is plain data (integers and a pointer), for which all zeroes is valid.
    let mut tm: libc::tm = unsafe { std::mem::zeroed() };
    // SAFETY: both pointers are to live locals; localtime_r is the thread-safe variant.
    let ok = unsafe { !libc::localtime_r(&secs, &mut tm).is_null() };
    let (h, m, s) = if ok {
        (tm.tm_hour as u64, tm.tm_min as u64, tm.tm_sec as u64)
    } else {
        let day = d.as_secs() % 86_400;
        (day / 3600, day / 60 % 60, day % 60)
    };
    format!("{h:02}:{m:02}:{s:02}.{:03}", d.subsec_millis())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn keeps_every_line_with_its_time_and_bounds_the_log() {
        let mut m = Messages::default();
        let t = SystemTime::UNIX_EPOCH + Duration::from_millis(3_723_045);
        m.push(t, Level::Info, "scan: 2 nodes\nnode 2 aimotor\nnode 3 syntron-ds");
        m.push(t, Level::Warn, "node 5: heartbeat lost");
        let lines = m.lines();
        assert_eq!(lines.len(), 4);
        assert!(lines[0].1.ends_with(".045  scan: 2 nodes"), "{:?}", lines[0]);
        assert_eq!(lines[2].1, "              node 3 syntron-ds");
        assert_eq!(lines[3].0, Level::Warn);
        for i in 0..Messages::CAPACITY {
            m.push(t, Level::Info, &i.to_string());
        }
        assert_eq!((m.len(), m.dropped), (Messages::CAPACITY, 2));
        assert_eq!(m.iter().next().map(|e| e.text.as_str()), Some("0"));
    }

    #[test]
    fn long_lines_wrap_between_words_and_long_words_are_cut() {
        assert_eq!(
            wrap("will send: 602#2F00 1A 00 00", 12),
            ["will send:", "602#2F00 1A", "00 00"]
        );
        assert_eq!(wrap("  node 2", 20), ["  node 2"]);
        assert_eq!(wrap("0123456789abc", 5), ["01234", "56789", "abc"]);
        assert_eq!(wrap("", 5), [""]);
        let e = Entry {
            at: SystemTime::UNIX_EPOCH,
            level: Level::Info,
            text: "a b c d".into(),
        };
        let w = e.wrapped(LEAD + 8);
        assert_eq!(w.len(), 1);
        assert!(w[0].ends_with("  a b c d"));
    }
}
