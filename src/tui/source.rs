//! Capture tasks: each runs on its own thread and feeds frames in batches to the UI,
//! which puts them in the one trace. `open` reads a log as fast as it can; `replay`
//! paces it by its timestamps and obeys pause, step, speed and seek.

use crate::frame::Frame;
use crate::log::{LogReader, Outcome};
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, SyncSender, TryRecvError, channel, sync_channel};
use std::thread;
use std::time::{Duration, Instant};

/// Frames per batch sent to the UI.
const BATCH: usize = 4096;

/// What a capture task sends.
#[derive(Debug)]
pub enum Feed {
    /// Frames in order.
    Frames(Vec<Frame>),
    /// Interface names, whenever a new one appears (frames index into it).
    Interfaces(Vec<String>),
    /// Forget all frames: what follows starts over (a replay seeking back).
    Reset,
    /// A note for the status bar (warnings, errors, end of input).
    Status(String),
    /// The source ended; no more frames will come.
    Done,
    /// Frames lost before reaching the UI (queue full, reader too slow).
    Lost(u64),
    /// The interface is unavailable, down, gone, or its controller is bus-off, error-passive
    /// or warning; the text says so, whether frames are captured, and the command that fixes it.
    BusError(String),
    /// The interface is (again) capturing with an error-active controller; the text says so
    /// (and for how long capture had stopped).
    BusOk(String),
    /// The result of a palette command, and how much it matters.
    Result(super::messages::Level, String),
}

/// Replay commands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// Pause (`true`) or resume.
    Pause(bool),
    /// Replay speed factor (0 = as fast as possible).
    Speed(f64),
    /// Send the next frame (while paused).
    Step,
    /// Jump by this many nanoseconds of log time (negative: back).
    Seek(i64),
}

/// A feed and, for sources that take commands, its control line.
pub type Feeds = (Receiver<Feed>, Option<Sender<Control>>);

/// Capacity of the feed channel in batches; a full channel makes the reader wait.
const QUEUE: usize = 64;

/// A log that cannot be read, with its path.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct ReadError {
    /// The log.
    pub path: PathBuf,
    /// Why.
    pub source: std::io::Error,
}

impl ReadError {
    fn new(path: &Path, source: std::io::Error) -> ReadError {
        ReadError {
            path: path.to_path_buf(),
            source,
        }
    }
}

fn reader(path: &Path) -> Result<LogReader<BufReader<File>>, ReadError> {
    let file = File::open(path).map_err(|e| ReadError::new(path, e))?;
    LogReader::new(BufReader::with_capacity(1 << 20, file)).map_err(|e| ReadError::new(path, e))
}

/// Reads `path` as fast as possible.
pub fn open(path: PathBuf) -> Receiver<Feed> {
    let (tx, rx) = sync_channel(QUEUE);
    thread::spawn(move || {
        let mut r = match reader(&path) {
            Ok(r) => r,
            Err(e) => {
                let _ = tx.send(Feed::Status(e.to_string()));
                let _ = tx.send(Feed::Done);
                return;
            }
        };
        let mut batch = Vec::with_capacity(BATCH);
        let mut names = 0;
        let mut first_warning = None;
        while let Some(item) = r.next() {
            match item {
                Ok((_, Outcome::Frame(f))) => batch.push(f),
                Ok((line, Outcome::Warning(w))) => {
                    first_warning.get_or_insert(format!("line {line}: {w}"));
                }
                Ok(_) => {}
                Err(e) => {
                    let _ = tx.send(Feed::Status(ReadError::new(&path, e).to_string()));
                    break;
                }
            }
            if batch.len() == BATCH && !send_batch(&tx, &mut batch, &r, &mut names) {
                return;
            }
        }
        send_batch(&tx, &mut batch, &r, &mut names);
        let w = r.counts().warnings;
        if w > 0 {
            let first = first_warning.unwrap_or_default();
            let _ = tx.send(Feed::Status(format!("{w} malformed lines skipped (first: {first})")));
        }
        let _ = tx.send(Feed::Done);
    });
    rx
}

/// Sends the batch (and new interface names first); false when the UI is gone.
fn send_batch<R: std::io::BufRead>(
    tx: &SyncSender<Feed>,
    batch: &mut Vec<Frame>,
    r: &LogReader<R>,
    names: &mut usize,
) -> bool {
    let ifaces = r.interfaces().names();
    if ifaces.len() > *names {
        *names = ifaces.len();
        if tx.send(Feed::Interfaces(ifaces.to_vec())).is_err() {
            return false;
        }
    }
    if batch.is_empty() {
        return true;
    }
    tx.send(Feed::Frames(std::mem::replace(batch, Vec::with_capacity(BATCH))))
        .is_ok()
}

/// Replays `path` at `speed` (0 = as fast as possible); returns the feed and the control line.
pub fn replay(path: PathBuf, speed: f64) -> (Receiver<Feed>, Sender<Control>) {
    let (tx, rx) = sync_channel(QUEUE);
    let (ctl_tx, ctl_rx) = channel();
    thread::spawn(move || {
        let mut player = Player {
            path,
            tx,
            ctl: ctl_rx,
            speed,
            paused: false,
        };
        if let Err(e) = player.run() {
            let _ = player.tx.send(Feed::Status(e.to_string()));
        }
        let _ = player.tx.send(Feed::Done);
    });
    (rx, ctl_tx)
}

/// The replay task's state.
struct Player {
    path: PathBuf,
    tx: SyncSender<Feed>,
    ctl: Receiver<Control>,
    speed: f64,
    paused: bool,
}

/// Why the replay loop stopped reading.
enum Stop {
    /// The UI went away.
    Gone,
    /// Seek back to this log time: start over.
    Restart(u64),
}

impl Player {
    fn run(&mut self) -> Result<(), ReadError> {
        let mut skip_to = 0u64;
        loop {
            match self.play(skip_to)? {
                Some(Stop::Restart(t)) => {
                    if self.tx.send(Feed::Reset).is_err() {
                        return Ok(());
                    }
                    skip_to = t;
                }
                Some(Stop::Gone) => return Ok(()),
                None => {
                    let _ = self.tx.send(Feed::Status("replay finished".into()));
                    return Ok(());
                }
            }
        }
    }

    /// Plays the log from the start; frames before `skip_to` go out at once.
    fn play(&mut self, mut skip_to: u64) -> Result<Option<Stop>, ReadError> {
        let mut r = reader(&self.path)?;
        let mut names = 0;
        let mut batch = Vec::with_capacity(256);
        // Log time `anchor_ts` is played at wall time `anchor_wall`.
        let mut anchor: Option<(u64, Instant)> = None;
        let mut last_send = Instant::now();
        let mut step = false;
        while let Some(item) = r.next() {
            let f = match item {
                Ok((_, Outcome::Frame(f))) => f,
                Ok(_) => continue,
                Err(e) => return Err(ReadError::new(&self.path, e)),
            };
            let fast = f.ts_ns < skip_to || self.speed <= 0.0;
            if !fast {
                loop {
                    let (ats, awall) = *anchor.get_or_insert((f.ts_ns, Instant::now()));
                    let due = awall + Duration::from_secs_f64(f.ts_ns.saturating_sub(ats) as f64 / 1e9 / self.speed);
                    let now = Instant::now();
                    if !self.paused && (now >= due || step) {
                        break;
                    }
                    if !batch.is_empty() && !send_batch(&self.tx, &mut batch, &r, &mut names) {
                        return Ok(Some(Stop::Gone));
                    }
                    let wait = if self.paused {
                        Duration::from_millis(100)
                    } else {
                        (due - now).min(Duration::from_millis(10))
                    };
                    match self.ctl.recv_timeout(wait) {
                        Ok(c) => match self.apply(c, f.ts_ns, &mut anchor, &mut step, &mut skip_to) {
                            Some(stop) => return Ok(Some(stop)),
                            None => continue,
                        },
                        Err(RecvTimeoutError::Timeout) => {}
                        Err(RecvTimeoutError::Disconnected) => return Ok(Some(Stop::Gone)),
                    }
                }
            }
            if step {
                step = false;
                anchor = Some((f.ts_ns, Instant::now()));
            }
            batch.push(f);
            if batch.len() >= BATCH || last_send.elapsed() >= Duration::from_millis(10) {
                if !send_batch(&self.tx, &mut batch, &r, &mut names) {
                    return Ok(Some(Stop::Gone));
                }
                last_send = Instant::now();
            }
            loop {
                match self.ctl.try_recv() {
                    Ok(c) => {
                        if let Some(stop) = self.apply(c, f.ts_ns, &mut anchor, &mut step, &mut skip_to) {
                            return Ok(Some(stop));
                        }
                    }
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => return Ok(Some(Stop::Gone)),
                }
            }
        }
        send_batch(&self.tx, &mut batch, &r, &mut names);
        Ok(None)
    }

    /// Applies a command at log time `now_ts`.
    fn apply(
        &mut self,
        c: Control,
        now_ts: u64,
        anchor: &mut Option<(u64, Instant)>,
        step: &mut bool,
        skip_to: &mut u64,
    ) -> Option<Stop> {
        match c {
            Control::Pause(p) => {
                self.paused = p;
                *anchor = None;
            }
            Control::Speed(s) => {
                self.speed = s;
                *anchor = None;
            }
            Control::Step => *step = true,
            Control::Seek(d) if d < 0 => {
                return Some(Stop::Restart(now_ts.saturating_sub(d.unsigned_abs())));
            }
            Control::Seek(d) => {
                *skip_to = now_ts + d as u64;
                *anchor = None;
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log(frames: u64) -> tempfile_path::TempLog {
        tempfile_path::TempLog::new(frames)
    }

    mod tempfile_path {
        use std::path::PathBuf;
        /// A synthetic log in the temp dir, removed on drop.
        pub struct TempLog(pub PathBuf);
        impl TempLog {
            pub fn new(frames: u64) -> TempLog {
                let p = std::env::temp_dir().join(format!("cotui-src-{}-{frames}.log", std::process::id()));
                crate::bench::log::write_log(&p, frames).unwrap();
                TempLog(p)
            }
        }
        impl Drop for TempLog {
            fn drop(&mut self) {
                let _ = std::fs::remove_file(&self.0);
            }
        }
    }

    fn drain(rx: &Receiver<Feed>) -> (usize, usize, Vec<String>) {
        let (mut frames, mut resets, mut notes) = (0, 0, Vec::new());
        for f in rx.iter() {
            match f {
                Feed::Frames(b) => frames += b.len(),
                Feed::Reset => resets += 1,
                Feed::Status(s) => notes.push(s),
                Feed::Interfaces(n) => assert_eq!(n, ["can0"]),
                Feed::Done => break,
                other => panic!("{other:?}"),
            }
        }
        (frames, resets, notes)
    }

    #[test]
    fn open_delivers_every_frame_then_done() {
        let l = log(10_000);
        assert_eq!(drain(&open(l.0.clone())).0, 10_000);
        let (n, _, notes) = drain(&open("/nonexistent/x.log".into()));
        assert_eq!(n, 0);
        assert!(notes[0].starts_with("/nonexistent/x.log: "), "{notes:?}");
    }

    #[test]
    fn replay_paces_and_seeks_back_with_a_reset() {
        // 2000 frames 100 µs apart = 0.2 s of log; at speed 1 it takes about that long.
        let l = log(2000);
        let start = Instant::now();
        let (rx, _ctl) = replay(l.0.clone(), 1.0);
        assert_eq!(drain(&rx).0, 2000);
        assert!(start.elapsed() >= Duration::from_millis(150));
        let (rx, ctl) = replay(l.0.clone(), 0.5);
        match rx.recv().unwrap() {
            Feed::Interfaces(_) => {}
            other => panic!("{other:?}"),
        }
        ctl.send(Control::Seek(-1_000_000_000)).unwrap();
        let (n, resets, notes) = drain(&rx);
        assert_eq!(resets, 1);
        assert!(n >= 2000);
        assert_eq!(notes, ["replay finished"]);
    }
}
