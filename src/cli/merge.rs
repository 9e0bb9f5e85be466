//! Several logs read as one capture (`cotui decode a.log b.log`): each file is parsed on its
//! own thread and their frames are merged by timestamp (ties in the order the files were
//! given). An interface name met in several files is the same bus (one bus's log split in
//! parts); with `--iface-per-file` each file's interfaces are named `FILE:IFACE` instead, so
//! buses recorded apart stay apart.

use crate::frame::Interfaces;
use crate::log::{Counts, Outcome};
use crate::logio::reader::{Log, report_counts};
use std::collections::VecDeque;
use std::io;
use std::sync::mpsc::{Receiver, sync_channel};

/// Lines per batch, read and handed on.
const BATCH: usize = 2048;

/// What a file's reader thread sends.
enum Piece {
    /// Parsed lines and the interface names first seen in them.
    Lines(Vec<(u64, Outcome)>, Vec<String>),
    /// The end: the reader's counts and the read error that stopped it, if any.
    End(Counts, Option<io::Error>),
}

/// What the merge has to say about its files: a malformed line, or a file's closing
/// counts.
pub enum Said<'a> {
    /// A malformed line (1-based) of a file, and why.
    Warning { path: &'a str, line: u64, message: &'a str },
    /// A file has ended: what its reader counted.
    Counts { path: &'a str, counts: &'a Counts },
}

impl Said<'_> {
    /// Says it on stderr, as a command that reads logs does (`FILE:LINE: warning: ...`).
    pub fn to_stderr(&self) {
        match self {
            Said::Warning { path, line, message } => eprintln!("{path}:{line}: warning: {message}"),
            Said::Counts { path, counts } => report_counts(path, counts),
        }
    }
}

/// One file being merged.
struct Part {
    path: String,
    rx: Receiver<Piece>,
    pending: VecDeque<(u64, Outcome)>,
    /// The merged table's index of each of the file's own interface indices.
    map: Vec<u16>,
    end: Option<(Counts, Option<io::Error>)>,
}

impl Part {
    /// The time of the next frame, reading on (warnings said as they pass) until there is
    /// one; `None` at the end of the file.
    fn head(&mut self, merged: &mut Interfaces, per_file: bool, say: &mut impl FnMut(Said<'_>)) -> Option<u64> {
        loop {
            while let Some((line, outcome)) = self.pending.front() {
                match outcome {
                    Outcome::Frame(f) => return Some(f.ts_ns),
                    Outcome::Warning(message) => say(Said::Warning {
                        path: &self.path,
                        line: *line,
                        message,
                    }),
                    Outcome::Skip(_) => {}
                }
                self.pending.pop_front();
            }
            if self.end.is_some() {
                return None;
            }
            match self.rx.recv() {
                Ok(Piece::Lines(lines, names)) => {
                    for name in names {
                        let shown = if per_file {
                            format!("{}:{name}", self.path)
                        } else {
                            name
                        };
                        self.map.push(merged.intern(&shown));
                    }
                    self.pending.extend(lines);
                }
                Ok(Piece::End(counts, error)) => self.end = Some((counts, error)),
                Err(_) => self.end = Some((Counts::default(), None)),
            }
        }
    }
}

/// Parses `input` and sends its lines in batches, then its counts.
fn read(path: &str, input: Log, tx: std::sync::mpsc::SyncSender<Piece>) {
    let mut reader = match input.reader(path) {
        Ok(r) => r,
        Err(e) => {
            let _ = tx.send(Piece::End(Counts::default(), Some(e)));
            return;
        }
    };
    let mut sent = 0;
    loop {
        let mut lines = Vec::with_capacity(BATCH);
        let error = reader.fill(&mut lines, BATCH).err();
        let done = lines.len() < BATCH || error.is_some();
        let names = reader.interfaces().names()[sent..].to_vec();
        sent += names.len();
        if tx.send(Piece::Lines(lines, names)).is_err() {
            return;
        }
        if done {
            let _ = tx.send(Piece::End(reader.counts().clone(), error));
            return;
        }
    }
}

/// Reads `inputs` (path, reader) as one capture and calls `consume` with batches of their
/// frames merged by time, each frame's `iface` an index of the merged table (the second
/// argument). Malformed lines and each file's counts (at the end) go to `say`; the first
/// read error (naming its file) or error of `consume` is returned.
pub fn for_each_merged(
    inputs: Vec<(String, Log)>,
    per_file: bool,
    mut say: impl FnMut(Said<'_>),
    mut consume: impl FnMut(&[(u64, Outcome)], &Interfaces) -> io::Result<()>,
) -> io::Result<()> {
    std::thread::scope(|s| {
        let mut parts: Vec<Part> = inputs
            .into_iter()
            .map(|(path, input)| {
                let (tx, rx) = sync_channel(4);
                let name = path.clone();
                s.spawn(move || read(&name, input, tx));
                Part {
                    path,
                    rx,
                    pending: VecDeque::new(),
                    map: Vec::new(),
                    end: None,
                }
            })
            .collect();
        let mut merged = Interfaces::default();
        let mut out: Vec<(u64, Outcome)> = Vec::with_capacity(BATCH);
        let mut result = Ok(());
        'merge: loop {
            // The part with the earliest next frame (of equal times, the first file's), and
            // the next frame of the others: the first part's frames before it go as a run.
            let mut first: Option<(u64, usize)> = None;
            let mut next_other: Option<(u64, usize)> = None;
            for (i, p) in parts.iter_mut().enumerate() {
                let Some(t) = p.head(&mut merged, per_file, &mut say) else {
                    continue;
                };
                if first.is_none_or(|(f, _)| t < f) {
                    next_other = first;
                    first = Some((t, i));
                } else if next_other.is_none_or(|(o, _)| t < o) {
                    next_other = Some((t, i));
                }
            }
            let Some((_, i)) = first else { break };
            let goes_first = |t: u64| next_other.is_none_or(|(o, j)| t < o || (t == o && i < j));
            let p = &mut parts[i];
            while p.head(&mut merged, per_file, &mut say).is_some_and(goes_first) {
                if let Some((line, Outcome::Frame(mut f))) = p.pending.pop_front() {
                    f.iface = p.map.get(usize::from(f.iface)).copied().unwrap_or(0);
                    out.push((line, Outcome::Frame(f)));
                }
                if out.len() == BATCH {
                    result = consume(&out, &merged);
                    out.clear();
                    if result.is_err() {
                        break 'merge;
                    }
                }
            }
        }
        if result.is_ok() && !out.is_empty() {
            result = consume(&out, &merged);
        }
        // Dropping the parts ends readers still running (after an error of `consume`).
        let mut first_error = None;
        for p in parts {
            let Part { path, end, .. } = p;
            if let Some((counts, error)) = end {
                say(Said::Counts {
                    path: &path,
                    counts: &counts,
                });
                if let Some(e) = error {
                    first_error.get_or_insert(io::Error::new(e.kind(), format!("{path}: {e}")));
                }
            }
        }
        result.and(first_error.map_or(Ok(()), Err))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A candump log of `times` (µs), frame id `id`, data the frame's place in its file.
    fn log(id: u32, times: &[u64]) -> (String, Log) {
        let text: String = times
            .iter()
            .enumerate()
            .map(|(k, t)| format!("(1700000000.{t:06}) can0 {id:03X}#{:02X}\n", k % 256))
            .collect();
        (
            format!("{id:X}.log"),
            Log::new(Box::new(io::Cursor::new(text.into_bytes())), None),
        )
    }

    /// Frames come out by time; of equal times, the first file's first; runs of one file
    /// and single frames between the others' alike, across batch borders.
    #[test]
    fn frames_merge_by_time_with_ties_in_file_order() {
        let a: Vec<u64> = (0..5000).collect();
        let b = [3, 3, 4, 10, 4999, 6000];
        let c = [0, 3, 7000];
        let mut got = Vec::new();
        let inputs = vec![log(0x100, &a), log(0x200, &b), log(0x300, &c)];
        for_each_merged(
            inputs,
            false,
            |_| {},
            |batch, _| {
                got.extend(batch.iter().filter_map(|(_, o)| match o {
                    Outcome::Frame(f) => Some((f.ts_ns / 1000 % 1_000_000, f.id, f.data[0])),
                    _ => None,
                }));
                Ok(())
            },
        )
        .expect("merged");
        let mut want: Vec<(u64, u32, u8)> = Vec::new();
        for (id, times) in [(0x100, &a[..]), (0x200, &b[..]), (0x300, &c[..])] {
            want.extend(times.iter().enumerate().map(|(k, &t)| (t, id, k as u8)));
        }
        // A stable sort by time keeps the file order of equal times.
        want.sort_by_key(|w| w.0);
        assert_eq!(got.len(), want.len());
        assert_eq!(got, want);
    }
}
