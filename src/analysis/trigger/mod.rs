//! Capture triggers (the flight recorder of `decode --trigger` and `record --trigger`): an
//! expression that fires on frames, bus events or incidents ([`Trigger`]), the hits it finds
//! in a stream ([`detect::Detector`]) and the windows of frames around them
//! ([`window::Windows`]). Pure: frames, ticks and link states in, hits and windows out.
//!
//! | trigger | fires at |
//! |---|---|
//! | a filter (`emcy`, `node 3 and abort`, `Statusword & 0x0008`) | every frame it matches (one judged when its SDO transfer ends, at that time) |
//! | `hb lost` (`heartbeat lost`) | a node's heartbeat found lost (1.5 periods after the last) |
//! | `bootup` (`boot-up`) | a boot-up message |
//! | `bus-off`, `error-passive` | the controller's state in an error frame, or the live interface's state |
//! | `iface down` | the live interface going down or away |
//! | `incident KIND` (`incident drive_fault`) | the diagnosis opening (or counting again) an incident of that kind |
//! | `A then B within DUR` | B within DUR after A |

pub mod detect;
pub mod window;

use super::filter::{Filter, FilterError, Names};
use super::incident::Problem;

/// A bus event a trigger can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BusEvent {
    /// A node's heartbeat lost.
    HeartbeatLost,
    /// A boot-up message.
    BootUp,
    /// The controller went bus-off.
    BusOff,
    /// The controller went error-passive.
    ErrorPassive,
    /// The interface went down or away (live only).
    IfaceDown,
}

/// The words naming each bus event (the first is how hits are named).
const EVENT_WORDS: &[(BusEvent, &[&str])] = &[
    (BusEvent::HeartbeatLost, &["hb lost", "heartbeat lost"]),
    (BusEvent::BootUp, &["bootup", "boot-up", "boot up"]),
    (BusEvent::BusOff, &["bus-off", "bus off", "busoff"]),
    (BusEvent::ErrorPassive, &["error-passive", "error passive"]),
    (BusEvent::IfaceDown, &["iface down", "interface down"]),
];

impl BusEvent {
    /// The event's name in a hit, e.g. `hb lost`.
    pub fn word(self) -> &'static str {
        EVENT_WORDS.iter().find(|(e, _)| *e == self).map_or("", |(_, w)| w[0])
    }
}

/// One condition of a trigger.
#[derive(Clone, Debug, PartialEq)]
pub enum Atom {
    /// Frames matching a filter.
    Filter(Filter),
    /// A bus event.
    Event(BusEvent),
    /// An incident of the diagnosis.
    Incident(Problem),
}

/// A parsed trigger.
#[derive(Clone, Debug, PartialEq)]
pub struct Trigger {
    /// The text it was parsed from.
    pub source: String,
    /// The condition (the first of `A then B`).
    pub first: Atom,
    /// `then B within DUR`: B and DUR in ns.
    pub then: Option<(Atom, u64)>,
}

impl Trigger {
    /// Parses a trigger; object names resolve through `names`. An error has the 1-based
    /// column in `text`, as the filter's do.
    pub fn parse(text: &str, names: &dyn Names) -> Result<Trigger, FilterError> {
        let err = |column: usize, message: String| FilterError { column, message };
        if text.trim().is_empty() {
            return Err(err(
                1,
                "an empty trigger: give a filter, a bus event or `incident KIND`".into(),
            ));
        }
        let (first, then) = match word_at(text, "then") {
            Some(at) => (&text[..at], Some((at, &text[at + 4..]))),
            None => (text, None),
        };
        let first_atom = atom(text, 0, first.len(), names)?;
        let then = match then {
            None => None,
            Some((at, rest)) => {
                let from = at + 4;
                let Some(w) = word_at(rest, "within") else {
                    return Err(err(
                        column(text, text.len()),
                        "`A then B` needs its time: `A then B within 2s`".into(),
                    ));
                };
                let dur_text = rest[w + 6..].trim();
                let dur = super::duration::ms(dur_text, 1.0).filter(|v| *v > 0).ok_or_else(|| {
                    err(
                        column(text, from + w + 6) + 1,
                        format!("`{dur_text}` is not a duration above 0 (500ms, 2s, 1min)"),
                    )
                })?;
                Some((atom(text, from, from + w, names)?, dur.saturating_mul(1_000_000)))
            }
        };
        Ok(Trigger {
            source: text.trim().to_string(),
            first: first_atom,
            then,
        })
    }

    /// The atoms (for what the detector must derive).
    pub fn atoms(&self) -> impl Iterator<Item = &Atom> {
        std::iter::once(&self.first).chain(self.then.as_ref().map(|(a, _)| a))
    }

    /// A file-name word for the trigger, e.g. `emcy`, `node-3-and-abort`, `hb-lost`.
    pub fn slug(&self) -> String {
        let mut s = String::new();
        for c in self.source.chars() {
            if c.is_ascii_alphanumeric() || c == '_' {
                s.push(c.to_ascii_lowercase());
            } else if !s.is_empty() && !s.ends_with('-') {
                s.push('-');
            }
            if s.len() >= 40 {
                break;
            }
        }
        let s = s.trim_end_matches('-').to_string();
        if s.is_empty() { "trigger".into() } else { s }
    }
}

/// The 1-based column of byte offset `at` in `text`.
fn column(text: &str, at: usize) -> usize {
    text.char_indices().take_while(|(i, _)| *i < at).count() + 1
}

/// The byte offset of `word` as a whole word of `text` outside quotes.
fn word_at(text: &str, word: &str) -> Option<usize> {
    let mut quoted = false;
    let bytes = text.as_bytes();
    for (i, c) in text.char_indices() {
        if c == '"' {
            quoted = !quoted;
        }
        if quoted || !text[i..].starts_with(word) {
            continue;
        }
        let before = i == 0 || bytes[i - 1].is_ascii_whitespace();
        let after = bytes.get(i + word.len()).is_none_or(|b| b.is_ascii_whitespace());
        if before && after {
            return Some(i);
        }
    }
    None
}

/// The atom in bytes `from..to` of the trigger `whole`.
fn atom(whole: &str, from: usize, to: usize, names: &dyn Names) -> Result<Atom, FilterError> {
    let text = &whole[from..to];
    let lead = text.len() - text.trim_start().len();
    let words = text
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_ascii_lowercase();
    if let Some((e, _)) = EVENT_WORDS.iter().find(|(_, w)| w.contains(&words.as_str())) {
        return Ok(Atom::Event(*e));
    }
    if let Some(kind) = words.strip_prefix("incident ").or(words.strip_prefix("incident")) {
        return Problem::ALL
            .iter()
            .find(|p| p.as_str() == kind)
            .map(|p| Atom::Incident(*p))
            .ok_or_else(|| FilterError {
                column: column(whole, from + lead + "incident ".len().min(text.trim().len())),
                message: format!(
                    "`{kind}` is not an incident kind; kinds: {}",
                    Problem::ALL.iter().map(|p| p.as_str()).collect::<Vec<_>>().join(", ")
                ),
            });
    }
    if words.is_empty() {
        return Err(FilterError {
            column: column(whole, from),
            message: "a condition is missing here".into(),
        });
    }
    Filter::parse_with(text, names)
        .map(Atom::Filter)
        .map_err(|e| FilterError {
            column: column(whole, from) - 1 + e.column,
            message: e.message,
        })
}

#[cfg(test)]
mod tests;
