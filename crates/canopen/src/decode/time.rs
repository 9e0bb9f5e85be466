//! TIME (0x100): TIME_OF_DAY, milliseconds after midnight and days since 1984-01-01.

use serde::Serialize;

/// A TIME stamp frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Time {
    /// Milliseconds after midnight (28 bits).
    pub ms: u32,
    /// Days since 1984-01-01.
    pub days: u16,
}

impl Time {
    /// The calendar date and time, `YYYY-MM-DD hh:mm:ss.mmm`.
    pub fn datetime(&self) -> String {
        let (y, m, d) = crate::calendar::civil_from_days(self.days as i64 + DAYS_1970_TO_1984);
        let ms = self.ms % 86_400_000;
        format!(
            "{y:04}-{m:02}-{d:02} {:02}:{:02}:{:02}.{:03}",
            ms / 3_600_000,
            ms / 60_000 % 60,
            ms / 1000 % 60,
            ms % 1000
        )
    }
    /// One-line label.
    pub fn label(&self) -> String {
        format!("TIME {}", self.datetime())
    }
    /// The kind-specific JSON object.
    pub fn to_json(&self) -> TimeJson {
        TimeJson {
            datetime: self.datetime(),
            days: self.days,
            ms: self.ms,
        }
    }
}

/// The `time` object of a JSONL frame record (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct TimeJson {
    /// `YYYY-MM-DD hh:mm:ss.mmm`.
    pub datetime: String,
    pub days: u16,
    pub ms: u32,
}

/// Days from 1970-01-01 to 1984-01-01.
const DAYS_1970_TO_1984: i64 = 5113;

/// Decodes a TIME payload; the second value explains a rule broken.
pub fn decode(payload: &[u8]) -> (Time, Option<String>) {
    let mut b = [0u8; 6];
    let n = payload.len().min(6);
    b[..n].copy_from_slice(&payload[..n]);
    let raw = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let time = Time {
        ms: raw & 0x0FFF_FFFF,
        days: u16::from_le_bytes([b[4], b[5]]),
    };
    let problem = if payload.len() != 6 {
        Some(format!("TIME frame has {} data bytes, expected 6", payload.len()))
    } else if time.ms >= 86_400_000 {
        Some(format!("TIME milliseconds {} beyond one day", time.ms))
    } else {
        None
    };
    (time, problem)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epoch_and_a_known_date() {
        assert_eq!(decode(&[0, 0, 0, 0, 0, 0]).0.datetime(), "1984-01-01 00:00:00.000");
        // 2024-05-01 is day 14731 after 1984-01-01; 12:34:56.789 = 45296789 ms.
        let ms: u32 = 45_296_789;
        let mut p = ms.to_le_bytes().to_vec();
        p.extend_from_slice(&14731u16.to_le_bytes());
        let (t, problem) = decode(&p);
        assert_eq!(t.label(), "TIME 2024-05-01 12:34:56.789");
        assert_eq!(problem, None);
    }

    #[test]
    fn short_frame_is_marked() {
        assert!(decode(&[1, 2]).1.unwrap().contains("2 data bytes"));
    }
}
