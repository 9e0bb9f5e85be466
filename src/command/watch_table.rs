//! The watch list's rows (`watch IFACE NODE OBJ...`): what each watched object last read,
//! its minimum and maximum, its last failure, and the three ways a poll round is written
//! (a text table, a CSV row, JSON lines). Pure: samples come in, text comes out.

use crate::decode::value_text::object_text;
use crate::od::{Dictionary, ObjectInfo, Value};
use serde::Serialize;

/// How `watch` writes its rounds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WatchFormat {
    /// A table per poll round: value, unit, min, max.
    #[default]
    Text,
    /// A header naming the objects, then a row per round: time, one column per object.
    Csv,
    /// One JSON object per object per round.
    Jsonl,
}

impl WatchFormat {
    /// Parses `text`, `csv` or `jsonl`.
    pub fn parse(word: &str) -> Result<WatchFormat, super::error::ParseError> {
        match word {
            "text" => Ok(WatchFormat::Text),
            "csv" => Ok(WatchFormat::Csv),
            "jsonl" => Ok(WatchFormat::Jsonl),
            _ => Err(super::error::ParseError::Invalid(format!(
                "unknown format `{word}`: use text, csv or jsonl"
            ))),
        }
    }
}

/// What one poll of an object gave.
#[derive(Clone, Debug, PartialEq)]
pub enum Sample {
    /// The value read.
    Value(Value),
    /// The object is not on the node (abort 0x06020000 or 0x06090011): shown once, not polled again.
    Absent(String),
    /// A timeout or another abort, shown in this round's row.
    Failed(String),
    /// Not polled this round (absent before).
    Skipped,
}

/// One watched object and what it has read so far.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Watched {
    pub node: u8,
    pub index: u16,
    pub sub: u8,
    /// Its name from the node's profile or EDS, when known.
    pub name: Option<String>,
    pub unit: Option<String>,
    /// Polls answered with a value, and polls that failed (timeouts, aborts).
    pub reads: u64,
    pub failures: u64,
    /// The object is not on the node; it is no longer polled.
    pub absent: bool,
    /// The last value read, and its text.
    pub last: Option<Value>,
    pub last_text: Option<String>,
    /// The smallest and largest numeric value read (raw), and as shown (`0x0237`, `12.5 rpm`).
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub min_text: Option<String>,
    pub max_text: Option<String>,
    /// The last failure (timeout or abort).
    pub last_error: Option<String>,
    #[serde(skip)]
    info: Option<ObjectInfo>,
}

impl Watched {
    /// Object (index, sub) of `node` with its entry of `dict`.
    pub fn new(dict: &Dictionary, node: u8, index: u16, sub: u8) -> Watched {
        let info = dict.object(index, sub).cloned();
        Watched {
            node,
            index,
            sub,
            name: info.as_ref().map(|o| o.name.clone()),
            unit: info.as_ref().and_then(|o| o.unit.clone()),
            reads: 0,
            failures: 0,
            absent: false,
            last: None,
            last_text: None,
            min: None,
            max: None,
            min_text: None,
            max_text: None,
            last_error: None,
            info,
        }
    }

    /// `2:0x6041 Statusword` (a column header; the sub is written when it is not 0).
    pub fn title(&self) -> String {
        let sub = if self.sub == 0 {
            String::new()
        } else {
            format!(":{}", self.sub)
        };
        let name = self.name.as_ref().map(|n| format!(" {n}")).unwrap_or_default();
        format!("{}:0x{:04X}{sub}{name}", self.node, self.index)
    }

    /// Notes a sample: counts, last value and its text, min, max, last failure.
    pub fn take(&mut self, dict: &Dictionary, s: &Sample) {
        match s {
            Sample::Value(v) => {
                self.reads += 1;
                let text = object_text(dict, self.index, self.sub, v, None);
                // The value alone, without the words of a bit field or an enumeration.
                let short = text.split(" (").next().unwrap_or_default().to_string();
                if let Some(x) = v.as_f64() {
                    if self.min.is_none_or(|m| x < m) {
                        (self.min, self.min_text) = (Some(x), Some(short.clone()));
                    }
                    if self.max.is_none_or(|m| x > m) {
                        (self.max, self.max_text) = (Some(x), Some(short));
                    }
                }
                self.last_text = Some(text);
                self.last = Some(v.clone());
            }
            Sample::Absent(why) => {
                self.absent = true;
                self.last_error = Some(why.clone());
            }
            Sample::Failed(why) => {
                self.failures += 1;
                self.last_error = Some(why.clone());
            }
            Sample::Skipped => {}
        }
    }

    /// The value's CSV cell: the physical number (raw times the dictionary's scale), text
    /// quoted, bytes in hex; a failure in words.
    fn csv_cell(&self, s: &Sample) -> String {
        match s {
            Sample::Value(v) => match (v.as_f64(), self.info.as_ref().and_then(|o| o.scale)) {
                (Some(x), Some(scale)) => crate::od::format_number(x * scale),
                (Some(_), None) => v.to_string(),
                (None, _) => match v {
                    Value::Text(t) => csv_quote(t),
                    other => other.to_string(),
                },
            },
            Sample::Absent(_) => "absent".into(),
            Sample::Failed(why) => csv_quote(why),
            Sample::Skipped => String::new(),
        }
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line end.
pub fn csv_quote(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The CSV header: `time_s` and each object's title.
pub fn csv_header(objects: &[Watched]) -> String {
    let mut cols = vec!["time_s".to_string()];
    cols.extend(objects.iter().map(|o| csv_quote(&o.title())));
    cols.join(",")
}

/// One CSV row: the round's time (s since the watch started) and one cell per object.
pub fn csv_row(t_s: f64, objects: &[Watched], samples: &[Sample]) -> String {
    let mut cols = vec![format!("{t_s:.3}")];
    cols.extend(objects.iter().zip(samples).map(|(o, s)| o.csv_cell(s)));
    cols.join(",")
}

/// One JSON line per object of the round.
#[derive(Serialize)]
struct SampleJson<'a> {
    t_s: f64,
    node: u8,
    index: u16,
    sub: u8,
    name: Option<&'a str>,
    value: Option<&'a Value>,
    text: Option<String>,
    unit: Option<&'a str>,
    error: Option<&'a str>,
    absent: bool,
}

/// The round as JSON lines (objects not polled, absent before, are left out).
/// Call after [`Watched::take`] of the round's samples (a value's text is the object's last).
pub fn jsonl_rows(t_s: f64, objects: &[Watched], samples: &[Sample]) -> Vec<String> {
    objects
        .iter()
        .zip(samples)
        .filter(|(_, s)| **s != Sample::Skipped)
        .map(|(o, s)| {
            let (value, error) = match s {
                Sample::Value(v) => (Some(v), None),
                Sample::Absent(w) | Sample::Failed(w) => (None, Some(w.as_str())),
                Sample::Skipped => (None, None),
            };
            let json = SampleJson {
                t_s: (t_s * 1000.0).round() / 1000.0,
                node: o.node,
                index: o.index,
                sub: o.sub,
                name: o.name.as_deref(),
                value,
                text: value.and(o.last_text.clone()),
                unit: o.unit.as_deref(),
                error,
                absent: matches!(s, Sample::Absent(_)),
            };
            serde_json::to_string(&json).unwrap_or_default()
        })
        .collect()
}

/// The round as a text table: a line with the time, then per object its value, unit, min
/// and max so far, or what went wrong.
pub fn text_table(t_s: f64, objects: &[Watched], samples: &[Sample]) -> String {
    let width = objects.iter().map(|o| o.title().chars().count()).max().unwrap_or(0);
    let mut lines = vec![format!("t = {t_s:.3} s")];
    for (o, s) in objects.iter().zip(samples) {
        let value = match s {
            Sample::Value(_) => o.last_text.clone().unwrap_or_default(),
            Sample::Absent(why) => format!("absent ({why}); not polled again"),
            Sample::Failed(why) => format!("-- {why}"),
            Sample::Skipped => continue,
        };
        let unit = o.unit.as_deref().unwrap_or("-");
        let range = match (&o.min_text, &o.max_text) {
            (Some(lo), Some(hi)) => format!("min {lo}  max {hi}"),
            _ => String::new(),
        };
        lines.push(
            format!("  {:<width$}  {value}  [{unit}]  {range}", o.title())
                .trim_end()
                .to_string(),
        );
    }
    lines.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demo_dict() -> Dictionary {
        crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[])
            .unwrap()
            .dictionary(2)
            .clone()
    }

    #[test]
    fn csv_names_the_objects_and_text_keeps_min_and_max() {
        let d = demo_dict();
        let mut objs = vec![Watched::new(&d, 2, 0x6041, 0), Watched::new(&d, 2, 0x6064, 0)];
        assert_eq!(
            csv_header(&objs),
            "time_s,2:0x6041 Statusword,2:0x6064 Position actual value"
        );
        for (pos, t) in [(100i64, 0.0), (-20, 0.05)] {
            let samples = [Sample::Value(Value::Unsigned(0x237)), Sample::Value(Value::Signed(pos))];
            objs.iter_mut().zip(&samples).for_each(|(o, s)| o.take(&d, s));
            if t > 0.0 {
                assert_eq!(csv_row(t, &objs, &samples), "0.050,567,-20");
                let table = text_table(t, &objs, &samples);
                assert!(table.starts_with("t = 0.050 s\n  2:0x6041 Statusword"), "{table}");
                assert!(table.contains("min -20"), "{table}");
                assert!(table.contains("max 100"), "{table}");
            }
        }
        let samples = [
            Sample::Failed("timeout".into()),
            Sample::Absent("abort 0x06020000".into()),
        ];
        assert_eq!(csv_row(0.1, &objs, &samples), "0.100,timeout,absent");
        let rows = jsonl_rows(0.1, &objs, &[Sample::Skipped, Sample::Failed("timeout".into())]);
        assert_eq!(rows.len(), 1);
        assert!(rows[0].contains("\"error\":\"timeout\""), "{}", rows[0]);
        assert_eq!(csv_quote("a,b"), "\"a,b\"");
    }
}
