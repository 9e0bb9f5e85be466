//! Capture tasks: each runs on its own thread and feeds frames in batches to the UI,
//! which puts them in the one trace. `open` reads a log as fast as it can; `replay`
//! paces it by its timestamps and obeys pause, step, speed and seek.

use crate::frame::Frame;
use crate::log::Outcome;
use crate::logio::reader::{ReadAs, Reader};
use crate::wire::WireFigures;
use crate::wire::cache::FiguresCache;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, SyncSender, TryRecvError, channel, sync_channel};
use std::thread;
use std::time::{Duration, Instant};

/// Frames per batch sent to the UI.
const BATCH: usize = 4096;

/// Lines the log reader parses in one go before their frames are batched.
const LINES: usize = 1024;

/// What a capture task sends.
#[derive(Debug)]
pub enum Feed {
    /// Frames in order, with their wire figures in the same order when the sending thread
    /// worked them out (a log read or replayed: bus load is then counted on its core, not
    /// the UI's); empty otherwise.
    Frames {
        frames: Vec<Frame>,
        figures: Vec<WireFigures>,
    },
    /// Interface names first seen since the previous such message, in index order
    /// (frames index into the table they extend).
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
    BusError(BusNote),
    /// The interface is (again) capturing with an error-active controller; the text says so
    /// (and for how long capture had stopped).
    BusOk(BusNote),
    /// Where a replay is (after its batches and every command).
    Position(Position),
    /// The size of a replayed log, once measured.
    Extent(Extent),
    /// The result of a palette command, and how much it matters.
    Result(super::messages::Level, String),
    /// The Transmit pane's list stopped by itself (a quick stop another program put on the
    /// bus): why; the pane shows every entry off.
    TransmitStopped(String),
    /// The result of a stop-all, as [`Feed::Result`], with the nodes not confirmed stopped
    /// (every target when nothing could be sent).
    Stopped(super::messages::Level, String, Vec<u8>),
}

impl Feed {
    /// Frames without their wire figures (the UI works them out).
    pub fn frames(frames: Vec<Frame>) -> Feed {
        Feed::Frames {
            frames,
            figures: Vec::new(),
        }
    }
}

/// A change of one interface's condition, from a live capture task.
#[derive(Debug, Clone, PartialEq)]
pub struct BusNote {
    /// The interface's index in the interface table (0 for the first one captured).
    pub iface: u16,
    /// Its condition in a word or two: `capturing`, `error-active`, `error-passive`,
    /// `bus-off`, `interface down`, `unavailable` (see [`crate::bus::BusState::name`]).
    pub state: &'static str,
    /// What the user reads (with the fix, for trouble).
    pub text: String,
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
    /// Go back one frame: replay from the start up to the frame before the last one sent.
    StepBack,
    /// Jump by this many nanoseconds of log time (negative: back).
    Seek(i64),
    /// Go to just after this many frames from the start (0: the start).
    GotoFrame(u64),
    /// Go to just after the frames up to this log time (ns after the first frame).
    GotoTime(u64),
    /// Start over from the first frame (paused or playing as before).
    Rewind,
    /// Loop (`true`): at the end, start over from the first frame and play on.
    Loop(bool),
}

/// A feed and, for sources that take commands, its control line.
pub type Feeds = (Receiver<Feed>, Option<Sender<Control>>);

/// Capacity of the feed channel in batches; a full channel makes the reader wait.
const QUEUE: usize = 16;

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

/// A reader of `path` as `format` (`None`: detected from its content).
fn reader(path: &Path, format: Option<ReadAs>) -> Result<Reader<BufReader<File>>, ReadError> {
    let file = File::open(path).map_err(|e| ReadError::new(path, e))?;
    Reader::open_file(file, format, |f| BufReader::with_capacity(1 << 20, f)).map_err(|e| ReadError::new(path, e))
}

/// Reads `path` as fast as possible.
pub fn open(path: PathBuf, format: Option<ReadAs>) -> Receiver<Feed> {
    let (tx, rx) = sync_channel(QUEUE);
    thread::spawn(move || {
        let mut r = match reader(&path, format) {
            Ok(r) => r,
            Err(e) => {
                let _ = tx.send(Feed::Status(e.to_string()));
                let _ = tx.send(Feed::Done);
                return;
            }
        };
        let _ = tx.send(Feed::Status(opened(&path, &r)));
        let mut batch = Vec::with_capacity(BATCH);
        let mut figures = FiguresCache::new();
        let mut lines = Vec::with_capacity(LINES);
        let mut names = 0;
        let mut first_warning = None;
        loop {
            lines.clear();
            let read = r.fill(&mut lines, LINES);
            let more = lines.len() == LINES;
            for (line, outcome) in lines.drain(..) {
                match outcome {
                    Outcome::Frame(f) => batch.push(f),
                    Outcome::Warning(w) => {
                        first_warning.get_or_insert(format!("line {line}: {w}"));
                    }
                    Outcome::Skip(_) => {}
                }
                if batch.len() == BATCH && !send_batch(&tx, &mut batch, &mut figures, &r, &mut names) {
                    return;
                }
            }
            if let Err(e) = read {
                let _ = tx.send(Feed::Status(ReadError::new(&path, e).to_string()));
                break;
            }
            if !more {
                break;
            }
        }
        send_batch(&tx, &mut batch, &mut figures, &r, &mut names);
        let w = r.counts().warnings;
        if w > 0 {
            let first = first_warning.unwrap_or_default();
            let _ = tx.send(Feed::Status(format!("{w} malformed lines skipped (first: {first})")));
        }
        let _ = tx.send(Feed::Done);
    });
    rx
}

/// What the status line says of an opened log: its name and the format detected.
fn opened<R: std::io::BufRead>(path: &Path, r: &Reader<R>) -> String {
    let name = path.file_name().unwrap_or(path.as_os_str()).to_string_lossy();
    format!("{name}: {}", r.format_name())
}

/// Sends the batch with its wire figures (worked out here, with `figures`'s memo), new
/// interface names first; false when the UI is gone.
fn send_batch<R: std::io::BufRead>(
    tx: &SyncSender<Feed>,
    batch: &mut Vec<Frame>,
    figures: &mut FiguresCache,
    r: &Reader<R>,
    names: &mut usize,
) -> bool {
    let ifaces = r.interfaces().names();
    if ifaces.len() > *names {
        let new = ifaces[*names..].to_vec();
        *names = ifaces.len();
        if tx.send(Feed::Interfaces(new)).is_err() {
            return false;
        }
    }
    if batch.is_empty() {
        return true;
    }
    let frames = std::mem::replace(batch, Vec::with_capacity(BATCH));
    let figures = frames.iter().map(|f| figures.figures(f)).collect();
    tx.send(Feed::Frames { frames, figures }).is_ok()
}

/// Replay speeds accepted besides 0 (as fast as possible).
pub const SPEEDS: std::ops::RangeInclusive<f64> = 0.01..=1000.0;

/// True for a replay speed the player takes: 0, or a finite factor in [`SPEEDS`].
pub fn valid_speed(x: f64) -> bool {
    x == 0.0 || SPEEDS.contains(&x)
}

/// Replays `path` at `speed` (0 = as fast as possible, else within [`SPEEDS`]); returns the
/// feed and the control line. The replay sends [`Feed::Position`] with its batches and after
/// every command, and [`Feed::Extent`] once a background pass has measured the log. At the
/// end it says "replay finished" and waits for a seek back, a step back or a rewind.
pub fn replay(path: PathBuf, speed: f64, format: Option<ReadAs>) -> (Receiver<Feed>, Sender<Control>) {
    let (tx, rx) = sync_channel(QUEUE);
    let (ctl_tx, ctl_rx) = channel();
    let measure = (path.clone(), tx.clone());
    thread::spawn(move || {
        let (path, tx) = measure;
        if let Ok(mut r) = reader(&path, format) {
            let (mut frames, mut first, mut last) = (0u64, None, 0u64);
            for item in r.by_ref() {
                if let Ok((_, Outcome::Frame(f))) = item {
                    frames += 1;
                    first.get_or_insert(f.ts_ns);
                    last = f.ts_ns;
                }
            }
            let first = first.unwrap_or(0);
            let _ = tx.send(Feed::Extent(Extent {
                frames,
                first_ns: first,
                last_ns: last,
            }));
        }
    });
    thread::spawn(move || {
        let mut player = Player {
            path,
            format,
            tx,
            ctl: ctl_rx,
            speed: if valid_speed(speed) { speed } else { 1.0 },
            paused: false,
            target: None,
            first_ns: None,
            looping: false,
            said_format: false,
            figures: FiguresCache::new(),
        };
        if let Err(e) = player.run() {
            let _ = player.tx.send(Feed::Status(e.to_string()));
        }
        let _ = player.tx.send(Feed::Done);
    });
    (rx, ctl_tx)
}

/// Where a seek goes: after this many frames, or after the frames up to this log time (ns
/// after the first frame).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Frame(u64),
    Time(u64),
}

/// The replay task's state.
struct Player {
    path: PathBuf,
    /// The format to read the log as (`None`: detected).
    format: Option<ReadAs>,
    tx: SyncSender<Feed>,
    ctl: Receiver<Control>,
    speed: f64,
    paused: bool,
    /// A seek in progress: frames go out at once until it is reached.
    target: Option<Target>,
    /// The log time of the first frame (time seeks count from it).
    first_ns: Option<u64>,
    /// At the end, start over.
    looping: bool,
    /// The format detected was said (on the first play only).
    said_format: bool,
    /// The wire figures of the frames played, for those that come again.
    figures: FiguresCache,
}

/// Why the replay loop stopped reading.
enum Stop {
    /// The UI went away.
    Gone,
    /// Start over (seek back, step back, rewind) towards the target.
    Restart,
    /// The end of the log.
    End,
}

/// What a command asks of the reading loop.
enum Next {
    /// Go on (waiting or not as the state says; a new target is judged on the next frame).
    Stay,
    /// Send the next frame now (a step while paused).
    Step,
    /// Stop reading.
    Stop(Stop),
}

/// What waiting for a frame's time ended with.
enum Wait {
    /// Send it.
    Send,
    /// A seek forward came: judge the frame against it again.
    Retry,
    /// Stop reading.
    Stop(Stop),
}

/// Where a replay is, as [`Feed::Position`] says it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Position {
    /// Frames played since the start of the log.
    pub frames: u64,
    /// Log time of the last frame played (ns, 0 before the first).
    pub ts_ns: u64,
}

/// The size of a replayed log, measured in the background.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Extent {
    /// Frames in the log.
    pub frames: u64,
    /// Log time of the first frame (ns).
    pub first_ns: u64,
    /// Log time of the last frame (ns).
    pub last_ns: u64,
}

impl Player {
    fn run(&mut self) -> Result<(), ReadError> {
        loop {
            let stop = match self.play()? {
                (Stop::End, at) => self.finished(at),
                (other, _) => other,
            };
            match stop {
                Stop::Restart => {
                    if self.tx.send(Feed::Reset).is_err() {
                        return Ok(());
                    }
                }
                Stop::Gone | Stop::End => return Ok(()),
            }
        }
    }

    /// At the end: starts over when looping (a log with frames), else waits for a command
    /// that goes back (or turns looping on).
    fn finished(&mut self, end: Position) -> Stop {
        self.target = None;
        if self.looping && end.frames > 0 {
            let _ = self
                .tx
                .send(Feed::Status("replay finished, looping: from the start".into()));
            return Stop::Restart;
        }
        let _ = self.tx.send(Feed::Status("replay finished".into()));
        while let Ok(c) = self.ctl.recv() {
            if let Next::Stop(s) = self.apply(c, end) {
                return s;
            }
            self.target = None;
            if self.looping && end.frames > 0 {
                return Stop::Restart;
            }
            if self.tx.send(Feed::Position(end)).is_err() {
                return Stop::Gone;
            }
        }
        Stop::Gone
    }

    /// Plays the log from the start; frames up to the target go out at once. Returns why
    /// it stopped and where it was.
    fn play(&mut self) -> Result<(Stop, Position), ReadError> {
        let mut r = reader(&self.path, self.format)?;
        if !self.said_format {
            self.said_format = true;
            let _ = self.tx.send(Feed::Status(opened(&self.path, &r)));
        }
        let mut names = 0;
        let mut batch = Vec::with_capacity(256);
        // Log time `anchor_ts` is played at wall time `anchor_wall`.
        let mut anchor: Option<(u64, Instant)> = None;
        let mut last_send = Instant::now();
        let mut at = Position::default();
        let mut held: Option<Frame> = None;
        loop {
            let f = match held.take() {
                Some(f) => f,
                None => match r.next() {
                    Some(Ok((_, Outcome::Frame(f)))) => f,
                    Some(Ok(_)) => continue,
                    Some(Err(e)) => return Err(ReadError::new(&self.path, e)),
                    None => break,
                },
            };
            let first = *self.first_ns.get_or_insert(f.ts_ns);
            let seeking = match self.target {
                Some(Target::Frame(n)) => at.frames < n,
                Some(Target::Time(t)) => f.ts_ns <= first.saturating_add(t),
                None => false,
            };
            if !seeking {
                if self.target.take().is_some() {
                    // Reached: show it, then play on (or stay paused) from here.
                    anchor = None;
                    if !self.flush(&mut batch, &r, &mut names, at) {
                        return Ok((Stop::Gone, at));
                    }
                }
                match self.wait(f.ts_ns, &mut anchor, at, &mut batch, &r, &mut names) {
                    Wait::Send => {}
                    Wait::Retry => {
                        held = Some(f);
                        continue;
                    }
                    Wait::Stop(s) => return Ok((s, at)),
                }
            }
            let ts_ns = f.ts_ns;
            batch.push(f);
            at = Position {
                frames: at.frames + 1,
                ts_ns,
            };
            let stepped = self.paused && !seeking;
            if stepped || batch.len() >= BATCH || last_send.elapsed() >= Duration::from_millis(10) {
                if !self.flush(&mut batch, &r, &mut names, at) {
                    return Ok((Stop::Gone, at));
                }
                last_send = Instant::now();
            }
            loop {
                match self.ctl.try_recv() {
                    Ok(c) => {
                        if let Next::Stop(s) = self.apply(c, at) {
                            self.flush(&mut batch, &r, &mut names, at);
                            return Ok((s, at));
                        }
                    }
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => return Ok((Stop::Gone, at)),
                }
            }
        }
        if !self.flush(&mut batch, &r, &mut names, at) {
            return Ok((Stop::Gone, at));
        }
        Ok((Stop::End, at))
    }

    /// Waits until the frame of log time `ts_ns` is due (or a step while paused), taking
    /// commands meanwhile.
    fn wait<R: std::io::BufRead>(
        &mut self,
        ts_ns: u64,
        anchor: &mut Option<(u64, Instant)>,
        at: Position,
        batch: &mut Vec<Frame>,
        r: &Reader<R>,
        names: &mut usize,
    ) -> Wait {
        loop {
            let timeout = if self.paused {
                Duration::from_millis(100)
            } else if self.speed <= 0.0 {
                return Wait::Send;
            } else {
                let (ats, awall) = *anchor.get_or_insert((ts_ns, Instant::now()));
                let secs = ts_ns.saturating_sub(ats) as f64 / 1e9 / self.speed;
                let due = awall + Duration::try_from_secs_f64(secs).unwrap_or(Duration::from_secs(1 << 32));
                let now = Instant::now();
                if now >= due {
                    return Wait::Send;
                }
                (due - now).min(Duration::from_millis(10))
            };
            if !batch.is_empty() && !self.flush(batch, r, names, at) {
                return Wait::Stop(Stop::Gone);
            }
            match self.ctl.recv_timeout(timeout) {
                Ok(c) => match self.apply(c, at) {
                    Next::Stop(s) => return Wait::Stop(s),
                    Next::Step => {
                        *anchor = None;
                        return Wait::Send;
                    }
                    Next::Stay if self.target.is_some() => return Wait::Retry,
                    Next::Stay => {
                        *anchor = None;
                        if self.tx.send(Feed::Position(at)).is_err() {
                            return Wait::Stop(Stop::Gone);
                        }
                    }
                },
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => return Wait::Stop(Stop::Gone),
            }
        }
    }

    /// Sends the batch and the position; false when the UI is gone.
    fn flush<R: std::io::BufRead>(
        &mut self,
        batch: &mut Vec<Frame>,
        r: &Reader<R>,
        names: &mut usize,
        at: Position,
    ) -> bool {
        send_batch(&self.tx, batch, &mut self.figures, r, names) && self.tx.send(Feed::Position(at)).is_ok()
    }

    /// Applies a command with the replay at `at`.
    fn apply(&mut self, c: Control, at: Position) -> Next {
        let first = self.first_ns.unwrap_or(0);
        let seek_time = |player: &mut Player, t: u64| {
            player.target = Some(Target::Time(t));
            if at.frames > 0 && at.ts_ns > first.saturating_add(t) {
                Next::Stop(Stop::Restart)
            } else {
                Next::Stay
            }
        };
        match c {
            Control::Pause(p) => self.paused = p,
            Control::Speed(s) if valid_speed(s) => self.speed = s,
            Control::Speed(_) => {}
            Control::Step if self.paused => return Next::Step,
            Control::Step => {}
            Control::StepBack => {
                self.target = Some(Target::Frame(at.frames.saturating_sub(1)));
                return Next::Stop(Stop::Restart);
            }
            Control::Rewind => {
                self.target = Some(Target::Frame(0));
                return Next::Stop(Stop::Restart);
            }
            Control::Loop(on) => self.looping = on,
            Control::GotoFrame(n) => {
                self.target = Some(Target::Frame(n));
                if n < at.frames {
                    return Next::Stop(Stop::Restart);
                }
            }
            Control::GotoTime(t) => return seek_time(self, t),
            Control::Seek(d) => {
                let now = at.ts_ns.max(first) as i128 - first as i128;
                let t = (now + d as i128).clamp(0, u64::MAX as i128) as u64;
                return seek_time(self, t);
            }
        }
        Next::Stay
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
                Feed::Frames { frames: b, .. } => frames += b.len(),
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
        assert_eq!(drain(&open(l.0.clone(), None)).0, 10_000);
        let (n, _, notes) = drain(&open("/nonexistent/x.log".into(), None));
        assert_eq!(n, 0);
        assert!(notes[0].starts_with("/nonexistent/x.log: "), "{notes:?}");
    }

    #[test]
    fn open_reads_a_blf_log_as_it_reads_the_same_frames_as_candump() {
        let l = log(5_000);
        let blf = l.0.with_extension("blf");
        let mut w = crate::output::blf::BlfWriter::new(File::create(&blf).unwrap());
        let mut text = reader(&l.0, None).unwrap();
        while let Some((_, outcome)) = text.next_line().unwrap() {
            if let Outcome::Frame(f) = outcome {
                w.write_frame(text.interfaces().name(f.iface), &f).unwrap();
            }
        }
        w.finish().unwrap();
        let (n, _, notes) = drain(&open(blf.clone(), None));
        let _ = std::fs::remove_file(&blf);
        let name = blf.file_name().unwrap().to_string_lossy();
        assert_eq!(
            (n, notes),
            (5_000, vec![format!("{name}: Vector BLF")]),
            "the format detected is said"
        );
        let (_, _, notes) = drain(&open(l.0.clone(), None));
        assert!(notes[0].ends_with(".log: candump log"), "{notes:?}");
    }

    /// What the UI has from a replay: the frames since the last reset, the resets, the
    /// notes and the position.
    #[derive(Default)]
    struct Ui {
        frames: Vec<Frame>,
        resets: usize,
        notes: Vec<String>,
        at: Option<Position>,
        extent: Option<Extent>,
    }

    impl Ui {
        /// Takes feed items until `done` holds (a minute at most: no timing is judged).
        fn until(&mut self, rx: &Receiver<Feed>, done: impl Fn(&Ui) -> bool) {
            while !done(self) {
                match rx.recv_timeout(Duration::from_secs(60)).expect("the replay answers") {
                    Feed::Frames { frames: b, .. } => self.frames.extend(b),
                    Feed::Reset => {
                        self.frames.clear();
                        self.resets += 1;
                    }
                    Feed::Status(s) => self.notes.push(s),
                    Feed::Position(p) => self.at = Some(p),
                    Feed::Extent(e) => self.extent = Some(e),
                    Feed::Interfaces(_) => {}
                    other => panic!("{other:?}"),
                }
            }
        }

        /// Waits until the replay says it is at `frames` frames, and checks that the UI
        /// then has exactly those frames.
        fn at(&mut self, rx: &Receiver<Feed>, frames: u64, log: &[Frame]) {
            self.until(rx, |u| u.at.is_some_and(|p| p.frames == frames));
            assert_eq!(self.frames.len() as u64, frames);
            assert_eq!(self.frames, log[..frames as usize]);
        }
    }

    fn all_frames(path: &Path) -> Vec<Frame> {
        open(path.to_path_buf(), None)
            .iter()
            .take_while(|f| !matches!(f, Feed::Done))
            .flat_map(|f| match f {
                Feed::Frames { frames: b, .. } => b,
                _ => Vec::new(),
            })
            .collect()
    }

    #[test]
    fn replay_steps_seeks_and_rewinds_while_paused_and_after_the_end() {
        let l = log(3000);
        let frames = all_frames(&l.0);
        // So slow that no frame is due by time during the test: only commands move it.
        let (rx, ctl) = replay(l.0.clone(), 0.01, None);
        let mut ui = Ui::default();
        ctl.send(Control::Pause(true)).unwrap();
        ctl.send(Control::GotoFrame(10)).unwrap();
        ui.at(&rx, 10, &frames);
        ctl.send(Control::Step).unwrap();
        ui.at(&rx, 11, &frames);
        ctl.send(Control::StepBack).unwrap();
        ui.at(&rx, 10, &frames);
        assert!(ui.resets >= 1);
        // By time: the frames up to 0.5 ms after the first.
        let t = 500_000;
        let upto = frames.iter().filter(|f| f.ts_ns <= frames[0].ts_ns + t).count() as u64;
        assert!((2..10).contains(&upto), "{upto}");
        ctl.send(Control::GotoTime(t)).unwrap();
        ui.at(&rx, upto, &frames);
        // 10 s forward by a relative seek goes past the end of this 0.3 s log.
        ctl.send(Control::Seek(10_000_000_000)).unwrap();
        ui.until(&rx, |u| u.notes.iter().any(|n| n == "replay finished"));
        ui.at(&rx, 3000, &frames);
        ui.until(&rx, |u| u.extent.is_some());
        let e = ui.extent.unwrap();
        assert_eq!(
            (e.frames, e.first_ns, e.last_ns),
            (3000, frames[0].ts_ns, frames[2999].ts_ns)
        );
        // After the end: back by frame number, one step back, and a rewind to nothing.
        ctl.send(Control::GotoFrame(1500)).unwrap();
        ui.at(&rx, 1500, &frames);
        ctl.send(Control::StepBack).unwrap();
        ui.at(&rx, 1499, &frames);
        ctl.send(Control::Rewind).unwrap();
        ui.at(&rx, 0, &frames);
        ctl.send(Control::Step).unwrap();
        ui.at(&rx, 1, &frames);
        // Resumed as fast as possible, it plays to the end again.
        ctl.send(Control::Speed(0.0)).unwrap();
        ctl.send(Control::Pause(false)).unwrap();
        ui.notes.clear();
        ui.until(&rx, |u| u.notes.iter().any(|n| n == "replay finished"));
        ui.at(&rx, 3000, &frames);
        drop(ctl);
        // The UI gone, the replay ends.
        assert!(rx.iter().any(|f| matches!(f, Feed::Done)));
    }

    #[test]
    fn a_looping_replay_starts_over_at_the_end() {
        let l = log(500);
        let frames = all_frames(&l.0);
        let (rx, ctl) = replay(l.0.clone(), 0.0, None);
        let mut ui = Ui::default();
        ui.until(&rx, |u| u.notes.iter().any(|n| n == "replay finished"));
        ui.at(&rx, 500, &frames);
        // Looping turned on at the end: from the start again, and again at the next end.
        ctl.send(Control::Loop(true)).unwrap();
        ui.until(&rx, |u| u.resets == 1);
        ui.until(&rx, |u| {
            u.notes.iter().any(|n| n == "replay finished, looping: from the start")
        });
        ui.until(&rx, |u| u.resets == 2);
        ctl.send(Control::Loop(false)).unwrap();
        ui.notes.clear();
        ui.until(&rx, |u| u.notes.iter().any(|n| n == "replay finished"));
        ui.at(&rx, 500, &frames);
    }

    #[test]
    fn replay_speeds_are_bounded() {
        for ok in [0.0, 0.01, 1.0, 1000.0] {
            assert!(valid_speed(ok), "{ok}");
        }
        for bad in [1e-300, 0.001, -1.0, 1000.5, f64::NAN, f64::INFINITY] {
            assert!(!valid_speed(bad), "{bad}");
        }
    }

    #[test]
    fn replay_plays_at_speed_and_seeks_back_with_a_reset() {
        // 2000 frames 100 µs apart = 0.2 s of log; at speed 1 it takes about that long.
        let l = log(2000);
        let start = Instant::now();
        let (rx, ctl) = replay(l.0.clone(), 1.0, None);
        let mut ui = Ui::default();
        ui.until(&rx, |u| u.notes.iter().any(|n| n == "replay finished"));
        assert_eq!(ui.frames.len(), 2000);
        assert!(start.elapsed() >= Duration::from_millis(150));
        ctl.send(Control::Seek(-1_000_000_000)).unwrap();
        ui.notes.clear();
        ui.until(&rx, |u| u.notes.iter().any(|n| n == "replay finished"));
        assert_eq!(ui.resets, 1);
        assert_eq!(ui.frames.len(), 2000);
    }
}
