//! Numeric values over time for the Plot pane: every numeric PDO signal and every SDO
//! upload of a number, per (node, index, sub).
//!
//! Each series keeps at most [`MAX_POINTS`] points; when full, every other point is dropped
//! and the series keeps one point in two from then on, so a long trace is covered whole at
//! a coarser step and memory stays bounded.

use crate::decode::pdo::Pdo;
use crate::od::Dictionary;
use crate::sdo::{Transaction, TransferDirection};
use std::collections::BTreeMap;

/// Points kept per series.
pub const MAX_POINTS: usize = 4096;

/// A series key: node, index, sub.
pub type SeriesKey = (u8, u16, u8);

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
    /// One series.
    pub fn get(&self, key: &SeriesKey) -> Option<&Line> {
        self.lines.get(key)
    }

    fn add(&mut self, key: SeriesKey, name: &str, t: f64, v: f64) {
        let line = self.lines.entry(key).or_insert_with(|| Line {
            name: name.to_string(),
            ..Line::default()
        });
        line.add(t, v);
    }

    /// Adds the numeric signals of a PDO of `node` at `ts_ns`.
    pub fn pdo(&mut self, node: u8, ts_ns: u64, p: &Pdo) {
        for s in &p.signals {
            if let Some(v) = s.value.as_f64() {
                self.add((node, s.index, s.sub), &s.name, ts_ns as f64 / 1e9, v);
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
        let name = dict
            .name(t.index, t.sub)
            .map(str::to_string)
            .unwrap_or_else(|| format!("0x{:04X}:{:02X}", t.index, t.sub));
        self.add((t.node, t.index, t.sub), &name, t.end_ns as f64 / 1e9, v);
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
}
