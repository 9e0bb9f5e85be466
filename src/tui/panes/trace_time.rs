//! The Trace pane's time column: the modes it can show (wall clock, since start, delta to
//! the previous frame, delta to the previous frame of the same COB-ID, relative to the
//! current bookmark) and how one row's time reads in each, from what the row cache found.

/// What the time column shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeMode {
    /// Seconds since the first frame.
    #[default]
    SinceStart,
    /// Wall clock (UTC) when the timestamps are Unix epoch times, else raw seconds.
    Absolute,
    /// Seconds since the previous frame of the trace.
    Delta,
    /// Seconds since the previous frame with the same COB-ID.
    DeltaCob,
    /// Seconds relative to the current bookmark (negative before it).
    Marked,
}

impl TimeMode {
    /// Every mode, in the order the key cycles them.
    pub const ALL: [TimeMode; 5] = [
        TimeMode::SinceStart,
        TimeMode::Absolute,
        TimeMode::Delta,
        TimeMode::DeltaCob,
        TimeMode::Marked,
    ];

    /// The name `:time` accepts and the pane's title shows.
    pub fn name(self) -> &'static str {
        match self {
            TimeMode::SinceStart => "start",
            TimeMode::Absolute => "absolute",
            TimeMode::Delta => "delta",
            TimeMode::DeltaCob => "delta-id",
            TimeMode::Marked => "mark",
        }
    }

    /// The mode named `s` (as [`TimeMode::name`]).
    pub fn from_name(s: &str) -> Option<TimeMode> {
        TimeMode::ALL.into_iter().find(|m| m.name() == s)
    }

    /// The next mode (wrapping).
    pub fn next(self) -> TimeMode {
        let i = TimeMode::ALL.iter().position(|m| *m == self).unwrap_or(0);
        TimeMode::ALL[(i + 1) % TimeMode::ALL.len()]
    }
}

/// The times of one frame the column needs, in ns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stamps {
    /// This frame's timestamp.
    pub ts_ns: u64,
    /// The first frame's timestamp.
    pub start_ns: u64,
    /// The previous frame's timestamp (none for the first).
    pub prev_ns: Option<u64>,
    /// The previous frame of the same COB-ID's timestamp (none when there is none within
    /// [`SAME_ID_BOUND`] frames back).
    pub prev_id_ns: Option<u64>,
}

/// How far back (frames) a row looks for the previous frame of its COB-ID; a row is
/// decoded once, so this bounds the work per visible row, not per draw.
pub const SAME_ID_BOUND: usize = 1 << 16;

/// Timestamps from this on (2001-09-09) are taken for Unix epoch times.
const EPOCH_FROM_NS: u64 = 1_000_000_000 * 1_000_000_000;

/// The time column's text of a frame in `mode` (`mark_ns`: the current bookmark's time),
/// `decimals` after the point (the wall clock: 3 fewer, it is wider), right-aligned in `width`.
pub fn format(mode: TimeMode, s: &Stamps, mark_ns: Option<u64>, width: usize, decimals: usize) -> String {
    let secs = |ns: u64| ns as f64 / 1e9;
    let text = match mode {
        TimeMode::SinceStart => format!("{:.*}", decimals, secs(s.ts_ns.saturating_sub(s.start_ns))),
        TimeMode::Absolute if s.ts_ns >= EPOCH_FROM_NS => clock(s.ts_ns, decimals.saturating_sub(3).min(3)),
        TimeMode::Absolute => format!("{:.*}", decimals, secs(s.ts_ns)),
        TimeMode::Delta => delta(s.prev_ns, s.ts_ns, decimals),
        TimeMode::DeltaCob => delta(s.prev_id_ns, s.ts_ns, decimals),
        TimeMode::Marked => match mark_ns {
            Some(m) => format!("{:+.*}", decimals, (s.ts_ns as i128 - m as i128) as f64 / 1e9),
            None => "-".to_string(),
        },
    };
    format!("{text:>width$}")
}

fn delta(prev: Option<u64>, ts: u64, decimals: usize) -> String {
    match prev {
        Some(p) => format!("+{:.*}", decimals, ts.saturating_sub(p) as f64 / 1e9),
        None => "-".to_string(),
    }
}

/// `HH:MM:SS.fff` (UTC) of an epoch time, `decimals` (0..=3) after the point.
fn clock(ns: u64, decimals: usize) -> String {
    let secs = ns / 1_000_000_000;
    let day = secs % 86_400;
    let hms = format!("{:02}:{:02}:{:02}", day / 3600, day / 60 % 60, day % 60);
    if decimals == 0 {
        return hms;
    }
    let frac = (ns % 1_000_000_000) / 10u64.pow(9 - decimals as u32);
    format!("{hms}.{frac:0decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stamps(ts_ns: u64) -> Stamps {
        Stamps {
            ts_ns,
            start_ns: 1_000_000_000,
            prev_ns: Some(ts_ns - 250_000_000),
            prev_id_ns: None,
        }
    }

    #[test]
    fn each_mode_reads_as_a_bench_engineer_expects() {
        let s = stamps(3_500_000_000);
        assert_eq!(format(TimeMode::SinceStart, &s, None, 0, 3), "2.500");
        assert_eq!(format(TimeMode::Absolute, &s, None, 0, 3), "3.500");
        assert_eq!(format(TimeMode::Delta, &s, None, 0, 3), "+0.250");
        assert_eq!(format(TimeMode::DeltaCob, &s, None, 0, 3), "-");
        assert_eq!(format(TimeMode::Marked, &s, Some(4_000_000_000), 0, 3), "-0.500");
        // 2026-12-02 08:05:03.123 UTC
        let wall = stamps(1_796_198_703_123_456_789);
        assert_eq!(format(TimeMode::Absolute, &wall, None, 12, 6), "08:05:03.123");
        assert_eq!(format(TimeMode::Absolute, &wall, None, 9, 3), " 08:05:03");
    }

    #[test]
    fn names_round_trip_and_the_key_cycles_every_mode() {
        let mut m = TimeMode::default();
        for _ in 0..TimeMode::ALL.len() {
            assert_eq!(TimeMode::from_name(m.name()), Some(m));
            m = m.next();
        }
        assert_eq!(m, TimeMode::default());
        assert_eq!(TimeMode::from_name("since"), None);
    }
}
