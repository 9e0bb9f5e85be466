//! SYNC detector (`sync_jitter`): SYNC intervals off the SYNC period become one warning
//! with the jitter figures. Keeps the last SYNC for [`super::pdo`]'s SYNC window.

use super::detector::Detector;
use super::timeline::{At, Timeline};
use crate::analysis::incident::{Problem, Status};
use crate::analysis::timing::SyncTiming;

/// Finds uneven SYNC.
#[derive(Clone, Default)]
pub(super) struct Syncs {
    timing: SyncTiming,
    /// The last SYNC.
    pub(super) last: Option<At>,
}

impl Syncs {
    /// A SYNC at the frame being read.
    #[inline]
    pub(super) fn sync(&mut self, tl: &Timeline) {
        self.timing.sync(tl.at.frame, tl.at.t);
        self.last = Some(tl.at);
    }
}

impl Detector for Syncs {
    fn end(&mut self, tl: &mut Timeline, _end: At) {
        let Some(sum) = self.timing.summary().filter(|s| s.off > 0) else {
            return;
        };
        let ms = |ns: u64| ns as f64 / 1e6;
        let first = self.timing.kept.first().map_or(0, |o| o.t_ns);
        let i = tl.grouped(None, Problem::SyncJitter, 0, first);
        let inc = &mut tl.incidents[i];
        inc.count = sum.off;
        inc.status = Status::Warning;
        inc.title = format!(
            "SYNC timing uneven: {} of {} cycles more than 10 % off the {:.3} ms period",
            sum.off,
            sum.intervals,
            ms(sum.period_ns)
        );
        inc.cause = Some(format!(
            "period {:.3} ms; intervals {:.3} to {:.3} ms; standard deviation {:.3} ms",
            ms(sum.period_ns),
            ms(sum.min_ns),
            ms(sum.max_ns),
            sum.std_ns / 1e6
        ));
        if let Some(last) = self.timing.kept.last() {
            inc.last_ns = last.t_ns;
        }
        for o in &self.timing.kept {
            let at = At {
                frame: o.frame,
                t: o.t_ns,
            };
            tl.step(i, at, format!("SYNC {:.3} ms after the one before", ms(o.interval_ns)));
        }
    }
}
