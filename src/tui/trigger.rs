//! The TUI's trigger (`:trigger EXPR [--pre DUR] [--post DUR]`): the detector of
//! `decode --trigger` ([`crate::analysis::trigger::detect::Detector`]) run over the trace in
//! slices under a time budget (as a filter's background scan), then over new frames as they
//! arrive; it keeps the trace positions of its hits for the Trace pane's marker, the Plot
//! pane's vertical marks and `n`/`N`.

use std::time::{Duration, Instant};

use crate::analysis::filter::FilterError;
use crate::analysis::trace::Trace;
use crate::analysis::trigger::Trigger;
use crate::analysis::trigger::detect::Detector;
use crate::analysis::trigger::window::Hit;

/// Frames judged between two looks at the time budget.
const SLICE: usize = 1024;

/// `--pre` and `--post` when not given: as `decode --trigger`'s.
const DEFAULT_WINDOW_MS: u64 = 10_000;

/// A trigger running over the trace.
pub struct TriggerScan {
    /// The trigger.
    pub trigger: Trigger,
    /// Kept before each hit when recording (ms).
    pub pre_ms: u64,
    /// Kept after each hit when recording (ms).
    pub post_ms: u64,
    detector: Detector,
    /// The next trace position to judge.
    next: usize,
    /// Trace positions of the hits, rising.
    hits: Vec<usize>,
}

impl TriggerScan {
    /// Parses `EXPR [--pre DUR] [--post DUR]` with the trace's object names; an error's
    /// column counts in `text`.
    pub fn parse(text: &str, trace: &Trace) -> Result<TriggerScan, FilterError> {
        let (expr, pre_ms, post_ms) = options(text)?;
        let trigger = Trigger::parse(expr, trace.decoder())?;
        let detector = Detector::new(&trigger, trace.decoder());
        Ok(TriggerScan {
            trigger,
            pre_ms,
            post_ms,
            detector,
            next: 0,
            hits: Vec::new(),
        })
    }

    /// Judges new frames for up to `budget` (at least one slice); true when work is left.
    pub fn advance(&mut self, trace: &Trace, budget: Duration) -> bool {
        let start = Instant::now();
        let len = trace.store.len();
        if self.next > len {
            // The trace started over (a replay rewound): judge it again.
            self.detector = Detector::new(&self.trigger, trace.decoder());
            self.next = 0;
            self.hits.clear();
        }
        self.detector.name_interfaces(&trace.ifaces);
        let mut found: Vec<Hit> = Vec::new();
        while self.next < len {
            let end = (self.next + SLICE).min(len);
            for pos in self.next..end {
                self.detector.frame(&trace.store.frame(pos), &mut found);
                if !found.is_empty() {
                    found.clear();
                    self.hits.push(pos);
                }
            }
            self.next = end;
            if start.elapsed() >= budget {
                break;
            }
        }
        self.next < len
    }

    /// The capture clock reached `now_ns` with no new frame (a quiet live bus): what fires
    /// on time alone (`hb lost`, a window of `A then B within` running out) is a hit at the
    /// last frame, once every frame has been judged. True when it made a hit.
    pub fn tick(&mut self, trace: &Trace, now_ns: u64) -> bool {
        let len = trace.store.len();
        if self.next < len || len == 0 {
            return false;
        }
        let mut found: Vec<Hit> = Vec::new();
        self.detector.tick(now_ns, &mut found);
        if found.is_empty() || self.hits.last() == Some(&(len - 1)) {
            return false;
        }
        self.hits.push(len - 1);
        true
    }

    /// Trace positions of the hits so far, rising.
    pub fn hits(&self) -> &[usize] {
        &self.hits
    }

    /// Whether trace position `pos` is a hit.
    pub fn is_hit(&self, pos: usize) -> bool {
        self.hits.binary_search(&pos).is_ok()
    }

    /// The hit after (or before) position `from` (none: the first or last), wrapping: its
    /// rank (0-based), position and whether it wrapped.
    pub fn step(&self, from: Option<usize>, forward: bool) -> Option<(usize, usize, bool)> {
        let n = self.hits.len();
        if n == 0 {
            return None;
        }
        let at = match (from, forward) {
            (None, true) => Some(0),
            (None, false) => Some(n - 1),
            (Some(p), true) => Some(self.hits.partition_point(|h| *h <= p)).filter(|i| *i < n),
            (Some(p), false) => self.hits.partition_point(|h| *h < p).checked_sub(1),
        };
        Some(match at {
            Some(i) => (i, self.hits[i], false),
            None if forward => (0, self.hits[0], true),
            None => (n - 1, self.hits[n - 1], true),
        })
    }

    /// What the status line shows: `trigger EXPR: armed, N hits` (and how far it got).
    pub fn summary(&self, trace: &Trace) -> String {
        let len = trace.store.len();
        let progress = if self.next < len {
            format!(" ({}% judged)", self.next * 100 / len.max(1))
        } else {
            String::new()
        };
        let n = self.hits.len();
        format!(
            "trigger {}: armed, {n} hit{}{progress}",
            self.trigger.source,
            if n == 1 { "" } else { "s" }
        )
    }
}

/// Splits `--pre DUR` and `--post DUR` off the end of a trigger's text.
fn options(text: &str) -> Result<(&str, u64, u64), FilterError> {
    let (mut pre, mut post) = (DEFAULT_WINDOW_MS, DEFAULT_WINDOW_MS);
    let expr_end = text.find(" --").map_or(text.len(), |i| i + 1);
    let mut words = text[expr_end..].split_whitespace();
    while let Some(w) = words.next() {
        let slot = match w {
            "--pre" => &mut pre,
            "--post" => &mut post,
            _ => {
                return Err(FilterError {
                    column: text.find(w).map_or(1, |i| text[..i].chars().count() + 1),
                    message: format!("`{w}`: the options are --pre DUR and --post DUR"),
                });
            }
        };
        let dur = words.next().unwrap_or("");
        *slot = crate::analysis::duration::ms(dur, 1.0).ok_or_else(|| FilterError {
            column: text.chars().count() + 1 - dur.chars().count(),
            message: format!("{w}: `{dur}` is not a duration (500ms, 2s, 1min)"),
        })?;
    }
    Ok((text[..expr_end].trim_end(), pre, post))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_come_off_the_end_with_their_durations() {
        assert_eq!(options("emcy --pre 2s --post 1s").unwrap(), ("emcy", 2000, 1000));
        assert_eq!(
            options("node 3 and abort").unwrap(),
            ("node 3 and abort", 10_000, 10_000)
        );
        let e = options("emcy --pre soon").unwrap_err();
        assert!(e.message.contains("`soon` is not a duration"), "{}", e.message);
        assert_eq!(options("emcy --around 2s").unwrap_err().column, 6);
    }
}
