//! The flight recorder's windows, pure: frames and trigger hits in (in time order), the
//! frames of each capture window out. A hit at `t` asks for the frames of `[t - pre, t +
//! post]`; a hit whose window overlaps the open one extends it (the windows merge). Frames
//! not (yet) in a window wait in a ring that keeps the last `pre` of the stream, capped at
//! [`RING_FRAMES`] frames; one the cap pushes out is counted in the window it would have
//! belonged to ([`Closed::ring_overflow`]). The logs (`decode --trigger`) and the live bus
//! (`record --trigger`) feed the same [`Windows`].

use crate::frame::Frame;
use std::collections::VecDeque;

/// The most frames the ring holds (88 bytes each: about 92 MB): at 8,000 frames/s (a full 1 Mbit/s bus)
/// that is more than two minutes of `--pre`.
pub const RING_FRAMES: usize = 1 << 20;

const MS_NS: u64 = 1_000_000;

/// One hit of the trigger: when, and what fired (the trigger's words or the event's).
#[derive(Clone, Debug, PartialEq)]
pub struct Hit {
    /// Time (ns, the frames' time base).
    pub t_ns: u64,
    /// What fired, e.g. `emcy` or `incident drive_fault node 3`.
    pub what: String,
}

/// What the windows give, in order: a window opens (with its first hit), its frames, its
/// further hits, and it closes.
#[derive(Clone, Debug, PartialEq)]
pub enum Out {
    /// A window opens at `start_ns` for `hit`.
    Open {
        /// `hit.t_ns - pre` (not before 0).
        start_ns: u64,
        /// The first hit.
        hit: Hit,
    },
    /// A frame of the open window.
    Frame(Frame),
    /// Another hit inside the open window (it extended the window).
    Hit(Hit),
    /// The open window closes.
    Close(Closed),
}

/// The end of a window.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Closed {
    /// Planned end: the last hit plus `post`.
    pub end_ns: u64,
    /// The input (or the capture) ended before `end_ns`: the window has what there was.
    pub cut_short: bool,
    /// Frames of the window the ring's cap pushed out before the hit (0 unless the bus
    /// carried more than [`RING_FRAMES`] frames in `pre`).
    pub ring_overflow: u64,
}

/// The window being written.
struct Open {
    end_ns: u64,
    ring_overflow: u64,
}

/// The windowing state.
pub struct Windows {
    pre_ns: u64,
    post_ns: u64,
    cap: usize,
    ring: VecDeque<Frame>,
    /// Time of the newest frame taken.
    now_ns: u64,
    /// Frames the cap pushed out of the ring within the last `pre`: (ms since the epoch of
    /// the frames' time base, frames in that ms), oldest first.
    evicted: VecDeque<(u64, u64)>,
    open: Option<Open>,
}

impl Windows {
    /// Windows of `pre_ns` before and `post_ns` after each hit.
    pub fn new(pre_ns: u64, post_ns: u64) -> Windows {
        Windows::with_cap(pre_ns, post_ns, RING_FRAMES)
    }

    /// As [`Windows::new`] with a ring of at most `cap` frames (at least 1).
    pub fn with_cap(pre_ns: u64, post_ns: u64, cap: usize) -> Windows {
        Windows {
            pre_ns,
            post_ns,
            cap: cap.max(1),
            ring: VecDeque::new(),
            now_ns: 0,
            evicted: VecDeque::new(),
            open: None,
        }
    }

    /// Frames waiting in the ring now.
    pub fn ring_len(&self) -> usize {
        self.ring.len()
    }

    /// True while a window is open.
    pub fn is_open(&self) -> bool {
        self.open.is_some()
    }

    /// Takes the next frame of the stream (frames come in time order; one earlier than the
    /// one before counts as at the same time).
    pub fn frame(&mut self, f: &Frame, out: &mut Vec<Out>) {
        self.now_ns = self.now_ns.max(f.ts_ns);
        match &self.open {
            Some(o) if f.ts_ns <= o.end_ns && self.ring.is_empty() => out.push(Out::Frame(*f)),
            _ => self.keep(*f),
        }
        self.settle(out);
    }

    /// The stream's clock reached `now_ns` without a frame (a quiet live bus): a window
    /// whose end and merge margin passed closes.
    pub fn tick(&mut self, now_ns: u64, out: &mut Vec<Out>) {
        self.now_ns = self.now_ns.max(now_ns);
        self.settle(out);
    }

    /// A hit at `hit.t_ns` (not before the frames it follows: a hit is dated when it is
    /// known). It opens a window, or extends the open one.
    pub fn hit(&mut self, hit: Hit, out: &mut Vec<Out>) {
        let t = hit.t_ns.max(self.now_ns);
        let start = t.saturating_sub(self.pre_ns);
        let end = t.saturating_add(self.post_ns);
        match &mut self.open {
            Some(o) if start <= o.end_ns => {
                o.end_ns = o.end_ns.max(end);
                out.push(Out::Hit(hit));
            }
            _ => {
                self.close(false, out);
                while self.ring.front().is_some_and(|f| f.ts_ns < start) {
                    self.ring.pop_front();
                }
                let from_ms = start / MS_NS;
                let ring_overflow = self
                    .evicted
                    .iter()
                    .filter(|(ms, _)| *ms >= from_ms)
                    .map(|(_, n)| n)
                    .sum();
                self.evicted.clear();
                out.push(Out::Open { start_ns: start, hit });
                self.open = Some(Open {
                    end_ns: end,
                    ring_overflow,
                });
            }
        }
        self.drain(out);
    }

    /// The stream ended: an open window closes with what it has.
    pub fn finish(&mut self, out: &mut Vec<Out>) {
        let short = self.open.as_ref().is_some_and(|o| self.now_ns < o.end_ns);
        self.close(short, out);
    }

    /// Frames of the ring that are now in the open window go out (in order).
    fn drain(&mut self, out: &mut Vec<Out>) {
        let Some(o) = &self.open else { return };
        while let Some(f) = self.ring.front()
            && f.ts_ns <= o.end_ns
        {
            out.push(Out::Frame(*f));
            self.ring.pop_front();
        }
    }

    /// Closes the open window once no hit can still merge into it (the stream is past its
    /// end plus `pre`); trims the ring to the last `pre`.
    fn settle(&mut self, out: &mut Vec<Out>) {
        if self
            .open
            .as_ref()
            .is_some_and(|o| self.now_ns > o.end_ns.saturating_add(self.pre_ns))
        {
            self.close(false, out);
        }
        if self.open.is_none() {
            let keep_from = self.now_ns.saturating_sub(self.pre_ns);
            while self.ring.front().is_some_and(|f| f.ts_ns < keep_from) {
                self.ring.pop_front();
            }
            while self.evicted.front().is_some_and(|(ms, _)| *ms < keep_from / MS_NS) {
                self.evicted.pop_front();
            }
        }
    }

    fn close(&mut self, cut_short: bool, out: &mut Vec<Out>) {
        if let Some(o) = self.open.take() {
            out.push(Out::Close(Closed {
                end_ns: o.end_ns,
                cut_short,
                ring_overflow: o.ring_overflow,
            }));
        }
    }

    /// Puts a frame into the ring, pushing the oldest out at the cap.
    fn keep(&mut self, f: Frame) {
        if self.ring.len() >= self.cap
            && let Some(old) = self.ring.pop_front()
        {
            let ms = old.ts_ns / MS_NS;
            match self.evicted.back_mut() {
                Some((last, n)) if *last == ms => *n += 1,
                _ => self.evicted.push_back((ms, 1)),
            }
        }
        self.ring.push_back(f);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn at(ms: u64) -> Frame {
        let mut f = Frame::classic(0x181, &[ms as u8]);
        f.ts_ns = ms * MS;
        f
    }

    /// Feeds a frame every 10 ms for `until` ms with hits at `hits` (ms), returns each
    /// window as (start ms, planned end ms, frame times in ms, hits).
    fn windows(pre: u64, post: u64, cap: usize, until: u64, hits: &[u64]) -> Vec<(u64, u64, Vec<u64>, usize, u64)> {
        let mut w = Windows::with_cap(pre * MS, post * MS, cap);
        let mut out = Vec::new();
        for t in (0..until).step_by(10) {
            w.frame(&at(t), &mut out);
            for &h in hits.iter().filter(|&&h| h == t) {
                w.hit(
                    Hit {
                        t_ns: h * MS,
                        what: "x".into(),
                    },
                    &mut out,
                );
            }
        }
        w.finish(&mut out);
        let mut got = Vec::new();
        for o in out {
            match o {
                Out::Open { start_ns, .. } => got.push((start_ns / MS, 0, Vec::new(), 1, 0)),
                Out::Frame(f) => got.last_mut().unwrap().2.push(f.ts_ns / MS),
                Out::Hit(_) => got.last_mut().unwrap().3 += 1,
                Out::Close(c) => {
                    let g = got.last_mut().unwrap();
                    g.1 = c.end_ns / MS;
                    g.4 = c.ring_overflow;
                }
            }
        }
        got
    }

    fn span(from: u64, to: u64) -> Vec<u64> {
        (from..=to).step_by(10).collect()
    }

    #[test]
    fn a_window_holds_the_frames_from_pre_before_to_post_after() {
        let got = windows(100, 50, 1000, 1000, &[300]);
        assert_eq!(got, [(200, 350, span(200, 350), 1, 0)]);
    }

    #[test]
    fn hits_inside_or_overlapping_an_open_window_extend_it_others_open_their_own() {
        // 300: [200, 350]; 340 (inside): to 390; 480 (its pre reaches back to 380): to 530;
        // 800: a window of its own.
        let got = windows(100, 50, 1000, 1000, &[300, 340, 480, 800]);
        assert_eq!(
            got,
            [(200, 530, span(200, 530), 3, 0), (700, 850, span(700, 850), 1, 0)]
        );
    }

    #[test]
    fn a_window_at_the_start_or_the_end_has_what_there_is() {
        let got = windows(100, 500, 1000, 400, &[30]);
        assert_eq!(got, [(0, 530, span(0, 390), 1, 0)]);
    }

    #[test]
    fn the_ring_is_capped_and_says_how_many_frames_the_window_lost() {
        // 100 ms of pre is 10 frames; a ring of 4 keeps the last 4 (and the hit's own frame).
        let got = windows(100, 20, 4, 1000, &[500]);
        assert_eq!(got, [(400, 520, span(470, 520), 1, 7)]);
    }
}
