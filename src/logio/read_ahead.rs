//! Reads and parses a log on a second thread, handing the caller batches of
//! parsed lines: parsing and decoding then run on two cores at once.

use crate::log::{Counts, Outcome};
use crate::logio::reader::Reader;
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
}

/// What the reader thread reports at the end.
pub struct Finished {
    pub counts: Counts,
    pub error: Option<io::Error>,
}

/// Calls `consume` for every batch of `reader`, in order, on the calling thread; past the
/// first batch the reader runs ahead on a scoped thread (a log of one batch, the 10-line
/// paste, starts no thread). Returns the reader's counts (and the read error, if reading
/// stopped on one) and whatever `consume` returned last.
pub fn for_each_batch<R, E>(
    mut reader: Reader<R>,
    mut consume: impl FnMut(&Batch) -> Result<(), E>,
) -> Result<Result<Finished, io::Error>, E>
where
    R: BufRead + Send,
{
    let mut lines = Vec::with_capacity(BATCH);
    let error = reader.fill(&mut lines, BATCH).err();
    let names = reader.interfaces().names();
    let mut sent_ifaces = names.len();
    let first = Batch {
        lines,
        new_interfaces: names.to_vec(),
    };
    if first.lines.len() < BATCH || error.is_some() {
        consume(&first)?;
        return Ok(Ok(Finished {
            counts: reader.counts().clone(),
            error,
        }));
    }
    let (tx, rx) = mpsc::sync_channel::<Batch>(4);
    let (recycle_tx, recycle_rx) = mpsc::channel::<Vec<(u64, Outcome)>>();
    std::thread::scope(|s| {
        let producer = s.spawn(move || -> Result<Finished, io::Error> {
            loop {
                let mut lines = recycle_rx.try_recv().unwrap_or_else(|_| Vec::with_capacity(BATCH));
                lines.clear();
                let error = reader.fill(&mut lines, BATCH).err();
                let done = lines.len() < BATCH;
                let names = reader.interfaces().names();
                let new_interfaces = names[sent_ifaces..].to_vec();
                sent_ifaces = names.len();
                if tx.send(Batch { lines, new_interfaces }).is_err() || done || error.is_some() {
                    return Ok(Finished {
                        counts: reader.counts().clone(),
                        error,
                    });
                }
            }
        });
        let mut result = consume(&first);
        let _ = recycle_tx.send(first.lines);
        if result.is_ok() {
            for batch in rx.iter() {
                result = consume(&batch);
                let _ = recycle_tx.send(batch.lines);
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
        for_each_batch(Reader::open(log.as_bytes(), None).unwrap(), |batch| -> Result<(), ()> {
            for name in &batch.new_interfaces {
                ifaces.intern(name);
            }
            for (_, outcome) in &batch.lines {
                if let Outcome::Frame(f) = outcome {
                    seen.push(ifaces.name(f.iface).to_string());
                }
            }
            Ok(())
        })
        .unwrap()
        .unwrap();
        assert_eq!(seen.len(), n);
        assert!(seen.iter().enumerate().all(|(i, name)| *name == format!("if{i}")));
        assert_eq!(ifaces.find("if7"), Some(7));
        assert_eq!(ifaces.find("can0"), None);
    }
}
