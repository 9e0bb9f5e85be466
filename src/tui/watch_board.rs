//! The Watch pane's watch list as the bus task and the screen share it ([`Board`]): one
//! row per watched object (what it read so far, [`Watched`]), the poll group it belongs
//! to (the `:watch` line that added it, with its period), and the rounds polled, kept
//! for `:export watch FILE.csv` (the CSV of `cotui watch --format csv`).

use crate::command::watch_table::{Sample, Watched, csv_header, csv_row};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard};

/// Rounds kept for the export; beyond, the oldest go (counted).
pub const MAX_ROUNDS: usize = 100_000;

/// One watched object.
#[derive(Clone, Debug)]
pub struct WatchRow {
    /// Its number (stable while rows are deleted).
    pub id: u64,
    pub watched: Watched,
    /// The poll group polling it; None once stopped (`:watch off`, stop-all).
    pub group: Option<u64>,
    pub every_ms: u64,
    pub timeout_ms: u64,
    /// Bus time (ns) of its last value.
    pub at_ns: Option<u64>,
}

/// One poll round of a group: its time (bus ns) and what each row polled read.
#[derive(Clone, Debug)]
struct Round {
    t_ns: u64,
    samples: Vec<(u64, Sample)>,
}

/// The watch list.
#[derive(Debug, Default)]
pub struct Board {
    pub rows: Vec<WatchRow>,
    rounds: VecDeque<Round>,
    /// Rounds dropped from the export (beyond [`MAX_ROUNDS`]).
    dropped: u64,
    next_id: u64,
    next_group: u64,
}

/// A poll group: its number, period and SDO timeout (ms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Group {
    pub id: u64,
    pub every_ms: u64,
    pub timeout_ms: u64,
}

/// The board as the bus task and the screen hold it.
pub type SharedBoard = Arc<Mutex<Board>>;

/// The board, locked (a poisoned lock is still the board).
pub fn lock(b: &SharedBoard) -> MutexGuard<'_, Board> {
    b.lock().unwrap_or_else(|e| e.into_inner())
}

impl Board {
    /// Adds `objects` as a new poll group; an object already on the board is polled again
    /// in it (found absent before, it is asked again), keeping what it read.
    pub fn add(&mut self, objects: Vec<Watched>, every_ms: u64, timeout_ms: u64) -> Group {
        let group = Group {
            id: self.next_group,
            every_ms,
            timeout_ms,
        };
        self.next_group += 1;
        for w in objects {
            let same = |r: &&mut WatchRow| (r.watched.node, r.watched.index, r.watched.sub) == (w.node, w.index, w.sub);
            match self.rows.iter_mut().find(same) {
                Some(r) => {
                    r.watched.absent = false;
                    (r.group, r.every_ms, r.timeout_ms) = (Some(group.id), every_ms, timeout_ms);
                }
                None => {
                    self.rows.push(WatchRow {
                        id: self.next_id,
                        watched: w,
                        group: Some(group.id),
                        every_ms,
                        timeout_ms,
                        at_ns: None,
                    });
                    self.next_id += 1;
                }
            }
        }
        group
    }

    /// Deletes row `k`; the row deleted, if there was one.
    pub fn delete(&mut self, k: usize) -> Option<WatchRow> {
        (k < self.rows.len()).then(|| self.rows.remove(k))
    }

    /// Stops every row; how many were polled.
    pub fn stop_all(&mut self) -> usize {
        self.rows.iter_mut().filter_map(|r| r.group.take()).count()
    }

    /// The groups still polling something.
    pub fn groups(&self) -> Vec<Group> {
        let mut out: Vec<Group> = Vec::new();
        for r in self.rows.iter().filter(|r| !r.watched.absent) {
            if let Some(id) = r.group
                && !out.iter().any(|g| g.id == id)
            {
                out.push(Group {
                    id,
                    every_ms: r.every_ms,
                    timeout_ms: r.timeout_ms,
                });
            }
        }
        out
    }

    /// The rows group `g` polls this round: (row id, its object), absent ones left out.
    pub fn polled(&self, g: u64) -> Vec<(u64, &Watched)> {
        self.rows
            .iter()
            .filter(|r| r.group == Some(g) && !r.watched.absent)
            .map(|r| (r.id, &r.watched))
            .collect()
    }

    /// Notes a round started at `t_ns` whose answers came by `now_ns`: each row's sample
    /// (`take` applies it with the row's dictionary), kept for the export.
    pub fn took(
        &mut self,
        t_ns: u64,
        now_ns: u64,
        samples: Vec<(u64, Sample)>,
        mut take: impl FnMut(&mut Watched, &Sample),
    ) {
        for (id, s) in &samples {
            if let Some(r) = self.rows.iter_mut().find(|r| r.id == *id) {
                take(&mut r.watched, s);
                if matches!(s, Sample::Value(_)) {
                    r.at_ns = Some(now_ns);
                }
            }
        }
        if self.rounds.len() >= MAX_ROUNDS {
            self.rounds.pop_front();
            self.dropped += 1;
        }
        self.rounds.push_back(Round { t_ns, samples });
    }

    /// Rounds kept for the export, and those dropped.
    pub fn rounds(&self) -> (usize, u64) {
        (self.rounds.len(), self.dropped)
    }

    /// The CSV of the rounds kept: `time_s` (from the first round kept) and one column per
    /// row (header: node and object), as `cotui watch --format csv` writes it; a row not
    /// polled in a round (another group's) leaves its cell empty.
    pub fn csv(&self) -> String {
        let objects: Vec<Watched> = self.rows.iter().map(|r| r.watched.clone()).collect();
        let mut lines = vec![csv_header(&objects)];
        let t0 = self.rounds.front().map_or(0, |r| r.t_ns);
        for round in &self.rounds {
            let samples: Vec<Sample> = self
                .rows
                .iter()
                .map(|r| {
                    round
                        .samples
                        .iter()
                        .find(|(id, _)| *id == r.id)
                        .map_or(Sample::Skipped, |(_, s)| s.clone())
                })
                .collect();
            if samples.iter().all(|s| *s == Sample::Skipped) {
                continue;
            }
            let t_s = round.t_ns.saturating_sub(t0) as f64 / 1e9;
            lines.push(csv_row(t_s, &objects, &samples));
        }
        lines.push(String::new());
        lines.join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::Value;

    fn dict() -> crate::od::Dictionary {
        crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[])
            .unwrap()
            .dictionary(2)
            .clone()
    }

    #[test]
    fn two_groups_export_one_csv_and_a_readded_absent_object_is_polled_again() {
        let d = dict();
        let mut b = Board::default();
        let g1 = b.add(
            vec![Watched::new(&d, 2, 0x6041, 0), Watched::new(&d, 2, 0x2FFF, 0)],
            100,
            50,
        );
        let g2 = b.add(vec![Watched::new(&d, 2, 0x6064, 0)], 300, 50);
        assert_eq!(b.groups(), [g1, g2]);
        let take = |w: &mut Watched, s: &Sample| w.take(&d, s);
        b.took(
            1_000_000_000,
            1_010_000_000,
            vec![
                (0, Sample::Value(Value::Unsigned(0x237))),
                (1, Sample::Absent("abort 0x06020000".into())),
            ],
            take,
        );
        b.took(
            1_050_000_000,
            1_060_000_000,
            vec![(2, Sample::Value(Value::Signed(-5)))],
            take,
        );
        assert_eq!(b.polled(g1.id).len(), 1, "the absent object is not polled again");
        assert_eq!(
            b.csv(),
            "time_s,2:0x6041 Statusword,2:0x2FFF,2:0x6064 Position actual value\n\
             0.000,567,absent,\n\
             0.050,,,-5\n"
        );
        assert_eq!(b.rows[0].at_ns, Some(1_010_000_000));
        let g3 = b.add(vec![Watched::new(&d, 2, 0x2FFF, 0)], 100, 50);
        assert_eq!(b.rows.len(), 3, "re-added, not doubled");
        assert_eq!(b.polled(g3.id).len(), 1, "asked again");
        assert_eq!(b.stop_all(), 3);
        assert!(b.groups().is_empty());
    }
}
