//! Reads and parses a log on a second thread, handing the caller batches of
//! parsed lines: parsing and decoding then run on two cores at once.

use crate::frame::Interfaces;
use crate::log::{Counts, LogReader, Outcome};
use std::io::{self, BufRead};
use std::sync::mpsc;

/// Lines per batch: large enough to amortise channel costs, small enough to stay in cache.
const BATCH: usize = 2048;

/// A batch of parsed lines: (1-based line number, outcome).
pub struct Batch {
    pub lines: Vec<(u64, Outcome)>,
    /// The interface table, sent only when it grew since the previous batch.
    pub interfaces: Option<Interfaces>,
}

/// What the reader thread reports at the end.
pub struct Finished {
    pub counts: Counts,
    pub error: Option<io::Error>,
}

/// Parses `input` on a scoped thread and calls `consume` for every batch, in
/// order, on the calling thread. Returns the reader's counts (and the read
/// error, if reading stopped on one) and whatever `consume` returned last.
pub fn for_each_batch<R, E>(
    input: R,
    mut consume: impl FnMut(&Batch) -> Result<(), E>,
) -> Result<Result<Finished, io::Error>, E>
where
    R: BufRead + Send,
{
    let (tx, rx) = mpsc::sync_channel::<Batch>(4);
    let (recycle_tx, recycle_rx) = mpsc::channel::<Vec<(u64, Outcome)>>();
    std::thread::scope(|s| {
        let producer = s.spawn(move || -> Result<Finished, io::Error> {
            let mut reader = LogReader::new(input)?;
            let mut sent_ifaces = 0;
            loop {
                let mut lines = recycle_rx.try_recv().unwrap_or_else(|_| Vec::with_capacity(BATCH));
                lines.clear();
                let error = reader.fill(&mut lines, BATCH).err();
                let done = lines.len() < BATCH;
                let names = reader.interfaces().names().len();
                let interfaces = (names != sent_ifaces).then(|| reader.interfaces().clone());
                sent_ifaces = names;
                if tx.send(Batch { lines, interfaces }).is_err() || done || error.is_some() {
                    return Ok(Finished {
                        counts: reader.counts().clone(),
                        error,
                    });
                }
            }
        });
        let mut result = Ok(());
        for batch in rx.iter() {
            if result.is_ok() {
                result = consume(&batch);
            }
            let _ = recycle_tx.send(batch.lines);
            if result.is_err() {
                break;
            }
        }
        drop(rx);
        let finished = producer
            .join()
            .unwrap_or_else(|_| Err(io::Error::other("log reader thread panicked")));
        result.map(|_| finished)
    })
}
