//! Numeric values over time for the Plot pane: every numeric PDO signal and every SDO
//! upload of a number, per (node of its interface, index, sub).
//!
//! Each series keeps at most [`MAX_POINTS`] points; when full, every other point is dropped
//! and the series keeps one point in two from then on, so a long trace is covered whole at
//! a coarser step and memory stays bounded.

use crate::decode::pdo::Pdo;
use crate::frame::NodeKey;
use crate::od::Dictionary;
use crate::sdo::{Transaction, TransferDirection};
use std::collections::BTreeMap;

/// Points kept per series.
pub const MAX_POINTS: usize = 4096;

/// A series key: node (of its interface), index, sub.
pub type SeriesKey = (NodeKey, u16, u8);

/// One series.
#[derive(Clone, Debug, Default)]
pub struct Line {
    /// Signal or object name.
    pub name: String,
    /// (seconds, value) points.
    pub points: Vec<(f64, f64)>,
    stride: u64,
    seen: u64,
}

impl Line {
    fn add(&mut self, t: f64, v: f64) {
        self.seen += 1;
        if self.stride > 1 && !self.seen.is_multiple_of(self.stride) {
            return;
        }
        if self.points.len() >= MAX_POINTS {
            let kept: Vec<(f64, f64)> = self.points.iter().step_by(2).copied().collect();
            self.points = kept;
            self.stride = self.stride.max(1) * 2;
        }
        self.points.push((t, v));
    }

    /// The points from `t0` to `t1` (seconds), with the last point before `t0` first (the
    /// value held at the window's start); found by binary search, so a draw touches only
    /// what it shows.
    pub fn window(&self, t0: f64, t1: f64) -> &[(f64, f64)] {
        let start = self.points.partition_point(|p| p.0 < t0).saturating_sub(1);
        let end = self.points.partition_point(|p| p.0 <= t1).max(start);
        &self.points[start..end]
    }

    /// The value in force at `t`: the last point at or before it.
    pub fn at(&self, t: f64) -> Option<f64> {
        let n = self.points.partition_point(|p| p.0 <= t);
        n.checked_sub(1).map(|i| self.points[i].1)
    }

    /// The first and last time, if any point was seen.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((self.points.first()?.0, self.points.last()?.0))
    }
}

/// Points to draw for a state (step) signal: each value holds until the next, so each
/// change becomes a vertical edge (`(t, old)` then `(t, new)`), never a slope; the last
/// value holds to `until`.
pub fn steps(points: &[(f64, f64)], until: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(points.len() * 2 + 1);
    for (i, &(t, v)) in points.iter().enumerate() {
        if i > 0 {
            out.push((t, points[i - 1].1));
        }
        out.push((t, v));
    }
    if let Some(&(t, v)) = points.last()
        && until > t
    {
        out.push((until, v));
    }
    out
}

/// At most four points per column (first, lowest, highest, last of the points falling in
/// it, in time order) for `columns` columns between `t0` and `t1`: what a draw needs of a
/// dense series, whatever its length.
pub fn decimate(points: &[(f64, f64)], t0: f64, t1: f64, columns: usize) -> Vec<(f64, f64)> {
    let columns = columns.max(1);
    if points.len() <= columns * 4 || t1 <= t0 {
        return points.to_vec();
    }
    let width = (t1 - t0) / columns as f64;
    let mut out = Vec::with_capacity(columns * 4);
    let mut i = 0;
    while i < points.len() {
        let col = ((points[i].0 - t0) / width).floor();
        let mut j = i;
        let (mut lo, mut hi) = (i, i);
        while j < points.len() && ((points[j].0 - t0) / width).floor() == col {
            if points[j].1 < points[lo].1 {
                lo = j;
            }
            if points[j].1 > points[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let mut picks = [i, lo.min(hi), lo.max(hi), j - 1];
        picks.sort_unstable();
        let mut last = usize::MAX;
        for k in picks {
            if k != last {
                out.push(points[k]);
                last = k;
            }
        }
        i = j;
    }
    out
}

/// The time window a plot shows (seconds): zoomed and panned within the whole span.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeWindow {
    /// Start.
    pub start: f64,
    /// End (greater than `start`).
    pub end: f64,
}

/// The narrowest window zooming in gives (seconds).
pub const MIN_WINDOW: f64 = 1e-3;

impl TimeWindow {
    /// Width in seconds.
    pub fn width(&self) -> f64 {
        self.end - self.start
    }

    /// The window `factor` times as wide (below 1 zooms in), keeping the time `around` at
    /// the same place on the screen, kept within `span` and no narrower than [`MIN_WINDOW`].
    pub fn zoom(self, factor: f64, around: f64, span: TimeWindow) -> TimeWindow {
        let around = around.clamp(self.start, self.end);
        let width = (self.width() * factor).clamp(MIN_WINDOW, span.width().max(MIN_WINDOW));
        let at = if self.width() > 0.0 {
            (around - self.start) / self.width()
        } else {
            0.5
        };
        let start = around - at * width;
        TimeWindow {
            start,
            end: start + width,
        }
        .within(span)
    }

    /// The window moved by `fraction` of its width (negative: back in time), within `span`.
    pub fn pan(self, fraction: f64, span: TimeWindow) -> TimeWindow {
        let d = self.width() * fraction;
        TimeWindow {
            start: self.start + d,
            end: self.end + d,
        }
        .within(span)
    }

    /// The window shifted (not resized) to lie within `span` where it can.
    fn within(self, span: TimeWindow) -> TimeWindow {
        let w = self.width();
        if w >= span.width() {
            return span;
        }
        let start = self.start.clamp(span.start, span.end - w);
        TimeWindow { start, end: start + w }
    }
}

/// Every series.
#[derive(Default)]
pub struct Series {
    lines: BTreeMap<SeriesKey, Line>,
}

impl Series {
    /// The series keys in order.
    pub fn keys(&self) -> Vec<SeriesKey> {
        self.lines.keys().copied().collect()
    }
    /// Number of series.
    pub fn len(&self) -> usize {
        self.lines.len()
    }
    /// True when no series was seen.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }
    /// One series.
    pub fn get(&self, key: &SeriesKey) -> Option<&Line> {
        self.lines.get(key)
    }

    /// Adds a point to the series `key`, named by `dict` when it is new.
    fn add(&mut self, key: SeriesKey, dict: &Dictionary, t: f64, v: f64) {
        let line = self.lines.entry(key).or_insert_with(|| {
            let (_, index, sub) = key;
            Line {
                name: dict
                    .name(index, sub)
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("0x{index:04X}:{sub:02X}")),
                ..Line::default()
            }
        });
        line.add(t, v);
    }

    /// Adds the numeric signals of a PDO of `node` at `ts_ns` (`dict`: the node's dictionary,
    /// which names new series).
    pub fn pdo(&mut self, node: NodeKey, ts_ns: u64, p: &Pdo, dict: &Dictionary) {
        for s in &p.signals {
            if let Some(v) = s.value.as_f64() {
                self.add((node, s.index, s.sub), dict, ts_ns as f64 / 1e9, v);
            }
        }
    }

    /// Adds the value of a successful numeric SDO upload.
    pub fn transaction(&mut self, t: &Transaction, dict: &Dictionary) {
        if !t.is_ok() || t.direction != TransferDirection::Upload || t.data.is_empty() || t.data.len() > 8 {
            return;
        }
        let ty = dict.object(t.index, t.sub).map(|o| o.data_type);
        let value = match ty {
            Some(ty) => ty.decode(&t.data).as_f64(),
            None => {
                let mut b = [0u8; 8];
                b[..t.data.len()].copy_from_slice(&t.data);
                Some(u64::from_le_bytes(b) as f64)
            }
        };
        let Some(v) = value else { return };
        self.add((t.key(), t.index, t.sub), dict, t.end_ns as f64 / 1e9, v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_series_halves_and_keeps_covering_the_whole_span() {
        let mut l = Line::default();
        for i in 0..(MAX_POINTS * 3) {
            l.add(i as f64, i as f64);
        }
        assert!(l.points.len() <= MAX_POINTS);
        assert_eq!(l.points[0].0, 0.0);
        assert!(l.points.last().unwrap().0 > (MAX_POINTS * 3 - 10) as f64);
    }

    fn line(points: &[(f64, f64)]) -> Line {
        Line {
            points: points.to_vec(),
            ..Line::default()
        }
    }

    #[test]
    fn a_state_signal_steps_and_holds_its_last_value() {
        let p = [(1.0, 0x21 as f64), (2.0, 0x23 as f64), (3.0, 0x27 as f64)];
        assert_eq!(
            steps(&p, 5.0),
            [
                (1.0, 33.0),
                (2.0, 33.0),
                (2.0, 35.0),
                (3.0, 35.0),
                (3.0, 39.0),
                (5.0, 39.0)
            ]
        );
        assert_eq!(steps(&[], 5.0), []);
        let l = line(&p);
        assert_eq!(l.at(0.5), None);
        assert_eq!(l.at(2.0), Some(35.0));
        assert_eq!(l.at(2.9), Some(35.0));
        assert_eq!(l.at(9.0), Some(39.0));
    }

    #[test]
    fn a_window_holds_the_value_before_it_and_only_its_points() {
        let l = line(&[(1.0, 1.0), (2.0, 2.0), (3.0, 3.0), (4.0, 4.0)]);
        assert_eq!(l.window(2.5, 3.5), [(2.0, 2.0), (3.0, 3.0)]);
        assert_eq!(l.window(0.0, 1.0), [(1.0, 1.0)]);
        assert_eq!(l.window(5.0, 6.0), [(4.0, 4.0)]);
        assert_eq!(l.span(), Some((1.0, 4.0)));
    }

    #[test]
    fn decimation_keeps_the_extremes_of_each_column() {
        let p: Vec<(f64, f64)> = (0..1000)
            .map(|i| (i as f64 / 1000.0, if i == 503 { 99.0 } else { (i % 7) as f64 }))
            .collect();
        let d = decimate(&p, 0.0, 1.0, 10);
        assert!(d.len() <= 40, "{}", d.len());
        assert!(d.contains(&(0.503, 99.0)), "the spike survives");
        assert!(d.windows(2).all(|w| w[0].0 <= w[1].0), "time order kept");
        assert_eq!(decimate(&p[..20], 0.0, 1.0, 10).len(), 20, "few points: all kept");
    }

    #[test]
    fn zoom_keeps_the_cursor_in_place_and_stays_within_the_span() {
        let span = TimeWindow { start: 0.0, end: 100.0 };
        let z = span.zoom(0.5, 25.0, span);
        assert_eq!(z, TimeWindow { start: 12.5, end: 62.5 });
        // Zooming out past the span gives the span; panning stops at its ends.
        assert_eq!(z.zoom(4.0, 30.0, span), span);
        assert_eq!(z.pan(-1.0, span), TimeWindow { start: 0.0, end: 50.0 });
        assert_eq!(
            z.pan(2.0, span),
            TimeWindow {
                start: 50.0,
                end: 100.0
            }
        );
        // Never narrower than a millisecond.
        let tiny = span.zoom(1e-9, 50.0, span);
        assert!((tiny.width() - MIN_WINDOW).abs() < 1e-12, "{tiny:?}");
        assert!((tiny.start - 50.0 + MIN_WINDOW / 2.0).abs() < 1e-9, "{tiny:?}");
    }
}
