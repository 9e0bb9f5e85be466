//! Reads and parses a log on a second thread, handing the caller batches of
//! parsed lines: parsing and decoding then run on two cores at once.

use crate::log::{Counts, Outcome};
use crate::logio::reader::Reader;
use crate::wire::WireFigures;
use crate::wire::cache::FiguresCache;
use std::io::{self, BufRead};
use std::sync::mpsc;

/// Lines per batch: large enough to amortise channel costs, small enough to stay in cache.
const BATCH: usize = 2048;

/// A batch of parsed lines: (1-based line number, outcome).
pub struct Batch {
    pub lines: Vec<(u64, Outcome)>,
    /// Interface names first seen in this batch, in the order they were interned
    /// (interning them in that order gives the reader's indices).
    pub new_interfaces: Vec<String>,
    /// The wire figures of each frame among `lines`, in order, when they were asked for
    /// (worked out on the reader's thread); empty otherwise.
    pub figures: Vec<WireFigures>,
}

/// Works out the wire figures of the frames of `lines` into `figures` (emptied first).
fn figure(cache: &mut FiguresCache, lines: &[(u64, Outcome)], figures: &mut Vec<WireFigures>) {
    figures.clear();
    for (_, outcome) in lines {
        if let Outcome::Frame(f) = outcome {
            figures.push(cache.figures(f));
        }
    }
}

/// What the reader thread reports at the end.
pub struct Finished {
    pub counts: Counts,
    pub error: Option<io::Error>,
}

/// Calls `consume` for every batch of `reader`, in order, on the calling thread; past the
/// first batch the reader runs ahead on a scoped thread (a log of one batch, the 10-line
/// paste, starts no thread). With `figured`, each batch comes with its frames' wire
/// figures, worked out by the reader (what bus load counts costs the reader's core, not the
/// caller's). Returns the reader's counts (and the read error, if reading stopped on one)
/// and whatever `consume` returned last.
pub fn for_each_batch<R, E>(
    mut reader: Reader<R>,
    figured: bool,
    mut consume: impl FnMut(&Batch) -> Result<(), E>,
) -> Result<Result<Finished, io::Error>, E>
where
    R: BufRead + Send,
{
    let mut cache = FiguresCache::new();
    let mut lines = Vec::with_capacity(BATCH);
    let error = reader.fill(&mut lines, BATCH).err();
    let names = reader.interfaces().names();
    let mut sent_ifaces = names.len();
    let mut figures = Vec::new();
    if figured {
        figure(&mut cache, &lines, &mut figures);
    }
    let first = Batch {
        lines,
        new_interfaces: names.to_vec(),
        figures,
    };
    if first.lines.len() < BATCH || error.is_some() {
        consume(&first)?;
        return Ok(Ok(Finished {
            counts: reader.counts().clone(),
            error,
        }));
    }
    let (tx, rx) = mpsc::sync_channel::<Batch>(4);
    let (recycle_tx, recycle_rx) = mpsc::channel::<Batch>();
    std::thread::scope(|s| {
        let producer = s.spawn(move || -> Result<Finished, io::Error> {
            loop {
                let (mut lines, mut figures) = match recycle_rx.try_recv() {
                    Ok(spent) => (spent.lines, spent.figures),
                    Err(_) => (Vec::with_capacity(BATCH), Vec::new()),
                };
                lines.clear();
                let error = reader.fill(&mut lines, BATCH).err();
                let done = lines.len() < BATCH;
                if figured {
                    figure(&mut cache, &lines, &mut figures);
                }
                let names = reader.interfaces().names();
                let new_interfaces = names[sent_ifaces..].to_vec();
                sent_ifaces = names.len();
                let batch = Batch {
                    lines,
                    new_interfaces,
                    figures,
                };
                if tx.send(batch).is_err() || done || error.is_some() {
                    return Ok(Finished {
                        counts: reader.counts().clone(),
                        error,
                    });
                }
            }
        });
        let mut result = consume(&first);
        let _ = recycle_tx.send(first);
        if result.is_ok() {
            for batch in rx.iter() {
                result = consume(&batch);
                let _ = recycle_tx.send(batch);
                if result.is_err() {
                    break;
                }
            }
        }
        drop(rx);
        let finished = producer
            .join()
            .unwrap_or_else(|_| Err(io::Error::other("log reader thread panicked")));
        result.map(|_| finished)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Interfaces;

    /// A log naming a new interface on every line, over several batches: each frame's
    /// index names its own interface once the batch's new names are interned in order.
    #[test]
    fn new_interface_names_arrive_with_their_batch() {
        let n = BATCH * 2 + 100;
        let log: String = (0..n).map(|i| format!("(1.{i:06}) if{i} 181#01\n")).collect();
        let mut ifaces = Interfaces::default();
        let mut seen = Vec::new();
        for_each_batch(
            Reader::open(log.as_bytes(), None).unwrap(),
            false,
            |batch| -> Result<(), ()> {
                for name in &batch.new_interfaces {
                    ifaces.intern(name);
                }
                for (_, outcome) in &batch.lines {
                    if let Outcome::Frame(f) = outcome {
                        seen.push(ifaces.name(f.iface).to_string());
                    }
                }
                Ok(())
            },
        )
        .unwrap()
        .unwrap();
        assert_eq!(seen.len(), n);
        assert!(seen.iter().enumerate().all(|(i, name)| *name == format!("if{i}")));
        assert_eq!(ifaces.find("if7"), Some(7));
        assert_eq!(ifaces.find("can0"), None);
    }

    /// Asked for, every batch's frames come with their wire figures, in order, as the
    /// frames alone give them; bad lines have none.
    #[test]
    fn figured_batches_carry_each_frames_figures() {
        let n = BATCH * 2 + 10;
        let log: String = (0..n)
            .map(|i| match i % 7 {
                3 => "not a frame\n".to_string(),
                _ => format!(
                    "(1.{i:06}) can0 {:03X}#{:02X}{}\n",
                    0x181 + i % 5,
                    i % 256,
                    "00".repeat(i % 8)
                ),
            })
            .collect();
        let (mut frames, mut figured) = (0, 0);
        for_each_batch(
            Reader::open(log.as_bytes(), None).unwrap(),
            true,
            |batch| -> Result<(), ()> {
                let mine: Vec<_> = batch
                    .lines
                    .iter()
                    .filter_map(|(_, o)| match o {
                        Outcome::Frame(f) => Some(crate::wire::figures(f)),
                        _ => None,
                    })
                    .collect();
                assert_eq!(batch.figures, mine);
                frames += mine.len();
                figured += batch.figures.iter().filter(|f| f.is_ok()).count();
                Ok(())
            },
        )
        .unwrap()
        .unwrap();
        assert_eq!((frames, figured), ((0..n).filter(|i| i % 7 != 3).count(), frames));
    }
}
