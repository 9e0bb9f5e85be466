//! The bookmarks of a log opened with `cotui open FILE`, kept beside it in
//! `FILE.cotui-bookmarks.json` (frame number, time, optional note): written when one is set
//! or cleared, read when the same file is opened again. Live sessions keep none.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// One bookmark as the sidecar file holds it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Entry {
    /// The frame number (1-based, as the trace shows it).
    frame: usize,
    /// The frame's timestamp in ns.
    t_ns: u64,
    /// A note, when the user wrote one in the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    note: Option<String>,
}

/// The sidecar file's content.
#[derive(Debug, Default, Serialize, Deserialize)]
struct File {
    /// The log's file name.
    #[serde(default)]
    log: String,
    bookmarks: Vec<Entry>,
}

/// The sidecar of one log.
pub struct Sidecar {
    /// The sidecar file's path.
    pub path: PathBuf,
    log: String,
    /// Notes by trace position (kept from the file).
    notes: BTreeMap<usize, String>,
}

impl Sidecar {
    /// The sidecar of `log` (`LOG.cotui-bookmarks.json`), not read yet.
    pub fn of(log: &Path) -> Sidecar {
        let mut name = log.as_os_str().to_owned();
        name.push(".cotui-bookmarks.json");
        Sidecar {
            path: PathBuf::from(name),
            log: log
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            notes: BTreeMap::new(),
        }
    }

    /// Reads the bookmarks kept (trace position, time); none when there is no file yet. A
    /// file that does not parse is an error naming it (and is not overwritten until a
    /// bookmark changes).
    pub fn load(&mut self) -> Result<Vec<(usize, u64)>, String> {
        let text = match std::fs::read_to_string(&self.path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => return Err(format!("{}: {e}", self.path.display())),
        };
        let file: File = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", self.path.display()))?;
        let mut out = Vec::new();
        for b in file.bookmarks.into_iter().filter(|b| b.frame > 0) {
            if let Some(n) = b.note {
                self.notes.insert(b.frame - 1, n);
            }
            out.push((b.frame - 1, b.t_ns));
        }
        Ok(out)
    }

    /// Writes `marks` (trace position, time), with the notes kept.
    pub fn save(&self, marks: &[(usize, u64)]) -> Result<(), String> {
        let file = File {
            log: self.log.clone(),
            bookmarks: marks
                .iter()
                .map(|&(p, t_ns)| Entry {
                    frame: p + 1,
                    t_ns,
                    note: self.notes.get(&p).cloned(),
                })
                .collect(),
        };
        let text = serde_json::to_string_pretty(&file).map_err(|e| e.to_string())?;
        std::fs::write(&self.path, text + "\n").map_err(|e| format!("{}: {e}", self.path.display()))
    }

    /// The note of the bookmark at trace position `pos`.
    pub fn note(&self, pos: usize) -> Option<&str> {
        self.notes.get(&pos).map(String::as_str)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bookmarks_and_their_notes_survive_a_save_and_a_load() {
        let dir = std::env::temp_dir().join(format!("cotui-bm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join("bench.log");
        let mut s = Sidecar::of(&log);
        assert_eq!(s.path, dir.join("bench.log.cotui-bookmarks.json"));
        assert_eq!(s.load().unwrap(), vec![]);
        s.notes.insert(4, "fault here".into());
        s.save(&[(4, 1_500), (9, 2_000)]).unwrap();
        let mut again = Sidecar::of(&log);
        assert_eq!(again.load().unwrap(), vec![(4, 1_500), (9, 2_000)]);
        assert_eq!(again.note(4), Some("fault here"));
        std::fs::write(&again.path, "{ nope").unwrap();
        assert!(again.load().unwrap_err().contains("bench.log.cotui-bookmarks.json"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
