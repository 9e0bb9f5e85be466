//! The filter and search language.
//!
//! A filter is words separated by spaces; a frame must match all of them:
//!
//! | word | matches |
//! |---|---|
//! | `node N` / `node=N` | frames of node N (decimal, or hex with `0x`) |
//! | `kind K` / `kind=K` | frames of kind K (`nmt sync emcy time tpdo rpdo pdo sdo sdo_tx sdo_rx heartbeat hb lss error other`) |
//! | `id X` / `id=X` | COB-ID X (hex) |
//! | `IIII:SS` / `IIII` | SDO frames of transfers of object IIII (sub SS), hex |
//! | `abort` | SDO frames of aborted transfers |
//! | `emcy` | EMCY frames |
//! | `"text"` or any other word | the decoded label contains the text (case-insensitive) |

use super::store::Packed;
use crate::decode::Kind;
use crate::sdo::{Outcome, Transaction};

/// One condition of a filter.
#[derive(Clone, Debug, PartialEq)]
pub enum Term {
    /// Frames of this node.
    Node(u8),
    /// Frames of any of these kinds.
    Kinds(Vec<Kind>),
    /// This COB-ID.
    Id(u32),
    /// SDO frames of transfers of this object (sub optional).
    Object(u16, Option<u8>),
    /// SDO frames of aborted transfers.
    Abort,
    /// The label contains this text (lower case).
    Text(String),
}

/// A parsed filter: all terms must match.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Filter {
    /// The conditions.
    pub terms: Vec<Term>,
    /// The text it was parsed from.
    pub source: String,
}

/// A filter that did not parse: 1-based column and what was wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FilterError {
    /// 1-based column.
    pub column: usize,
    /// What was wrong.
    pub message: String,
}

impl std::fmt::Display for FilterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "column {}: {}", self.column, self.message)
    }
}

/// Words with their 1-based columns; `"..."` keeps spaces.
fn words(s: &str) -> Result<Vec<(usize, String)>, FilterError> {
    let mut out = Vec::new();
    let mut chars = s.char_indices().peekable();
    while let Some(&(i, c)) = chars.peek() {
        if c.is_whitespace() {
            chars.next();
            continue;
        }
        let mut w = String::new();
        if c == '"' {
            chars.next();
            let mut closed = false;
            for (_, c) in chars.by_ref() {
                if c == '"' {
                    closed = true;
                    break;
                }
                w.push(c);
            }
            if !closed {
                return Err(FilterError {
                    column: i + 1,
                    message: "unterminated quote".into(),
                });
            }
            out.push((i + 1, format!("\"{w}")));
            continue;
        }
        while let Some(&(_, c)) = chars.peek() {
            if c.is_whitespace() {
                break;
            }
            w.push(c);
            chars.next();
        }
        out.push((i + 1, w));
    }
    Ok(out)
}

fn number(s: &str) -> Option<u32> {
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16).ok(),
        None => s.parse().ok(),
    }
}

/// The kinds a kind word names.
pub fn kinds(word: &str) -> Option<Vec<Kind>> {
    Some(match word.to_ascii_lowercase().as_str() {
        "nmt" => vec![Kind::Nmt],
        "sync" => vec![Kind::Sync],
        "emcy" => vec![Kind::Emcy],
        "time" => vec![Kind::Time],
        "tpdo" => vec![Kind::Tpdo],
        "rpdo" => vec![Kind::Rpdo],
        "pdo" => vec![Kind::Tpdo, Kind::Rpdo],
        "sdo" => vec![Kind::SdoTx, Kind::SdoRx],
        "sdo_tx" => vec![Kind::SdoTx],
        "sdo_rx" => vec![Kind::SdoRx],
        "heartbeat" | "hb" => vec![Kind::Heartbeat],
        "lss" => vec![Kind::Lss],
        "error" | "error_frame" => vec![Kind::ErrorFrame],
        "other" => vec![Kind::Other],
        _ => return None,
    })
}

fn object(w: &str) -> Option<(u16, Option<u8>)> {
    let w = w.strip_prefix("0x").unwrap_or(w);
    let (i, s) = match w.split_once(':') {
        Some((i, s)) => (i, Some(s)),
        None => (w, None),
    };
    if i.len() != 4 || !i.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    let index = u16::from_str_radix(i, 16).ok()?;
    let sub = match s {
        Some(s) => Some(u8::from_str_radix(s, 16).ok()?),
        None => None,
    };
    Some((index, sub))
}

impl Filter {
    /// Parses a filter; an empty text gives a filter that matches everything.
    pub fn parse(text: &str) -> Result<Filter, FilterError> {
        let ws = words(text)?;
        let mut terms = Vec::new();
        let mut it = ws.into_iter().peekable();
        while let Some((col, w)) = it.next() {
            let (key, inline) = match w.split_once('=') {
                Some((k, v)) => (k.to_ascii_lowercase(), Some((col + k.len() + 1, v.to_string()))),
                None => (w.to_ascii_lowercase(), None),
            };
            let mut value = |what: &str| -> Result<(usize, String), FilterError> {
                inline.clone().or_else(|| it.next()).ok_or(FilterError {
                    column: col + w.len(),
                    message: format!("`{key}` needs {what}"),
                })
            };
            let term = match key.as_str() {
                "node" => {
                    let (c, v) = value("a node-ID")?;
                    match number(&v) {
                        Some(n) if n < 128 => Term::Node(n as u8),
                        _ => {
                            return Err(FilterError {
                                column: c,
                                message: format!("`{v}` is not a node-ID (0..127)"),
                            });
                        }
                    }
                }
                "kind" => {
                    let (c, v) = value("a kind")?;
                    Term::Kinds(kinds(&v).ok_or(FilterError {
                        column: c,
                        message: format!(
                            "unknown kind `{v}` (nmt sync emcy time tpdo rpdo pdo sdo heartbeat lss error other)"
                        ),
                    })?)
                }
                "id" => {
                    let (c, v) = value("a COB-ID")?;
                    let h = v.trim_start_matches("0x");
                    Term::Id(u32::from_str_radix(h, 16).map_err(|_| FilterError {
                        column: c,
                        message: format!("`{v}` is not a hex COB-ID"),
                    })?)
                }
                "abort" | "aborts" => Term::Abort,
                _ if !w.starts_with('"') && kinds(&w).is_some() => Term::Kinds(kinds(&w).unwrap_or_default()),
                _ if w.starts_with('"') => Term::Text(w[1..].to_lowercase()),
                _ => match object(&w) {
                    Some((i, s)) => Term::Object(i, s),
                    None => Term::Text(w.to_lowercase()),
                },
            };
            terms.push(term);
        }
        Ok(Filter {
            terms,
            source: text.trim().to_string(),
        })
    }

    /// True when the filter has no condition.
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// True when matching needs the decoded label.
    pub fn needs_label(&self) -> bool {
        self.terms.iter().any(|t| matches!(t, Term::Text(_)))
    }

    /// True when some condition is about SDO transfers (object, abort).
    pub fn has_transfer_terms(&self) -> bool {
        self.terms.iter().any(|t| matches!(t, Term::Object(..) | Term::Abort))
    }

    /// True when an SDO transfer meets every object and abort condition.
    pub fn transaction_matches(&self, t: &Transaction) -> bool {
        self.terms.iter().all(|term| match term {
            Term::Object(i, s) => t.index == *i && s.is_none_or(|s| s == t.sub),
            Term::Abort => matches!(t.outcome, Outcome::Aborted { .. }),
            _ => true,
        })
    }

    /// Matches a stored frame. `in_transfer` tells whether the frame belongs to a transfer
    /// that [`Filter::transaction_matches`]; `label` is the decoded label when
    /// [`Filter::needs_label`].
    pub fn matches(&self, p: &Packed, in_transfer: bool, label: Option<&str>) -> bool {
        self.terms.iter().all(|t| match t {
            Term::Node(n) => p.node() == Some(*n),
            Term::Kinds(ks) => ks.contains(&p.kind()),
            Term::Id(id) => p.id == *id,
            Term::Object(..) | Term::Abort => in_transfer,
            Term::Text(x) => label.is_some_and(|l| l.to_lowercase().contains(x.as_str())),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_word_form() {
        let f = Filter::parse("node 3 kind=sdo 6041:00 abort id 0x181 \"Boot up\" emcy warn").unwrap();
        assert_eq!(
            f.terms,
            vec![
                Term::Node(3),
                Term::Kinds(vec![Kind::SdoTx, Kind::SdoRx]),
                Term::Object(0x6041, Some(0)),
                Term::Abort,
                Term::Id(0x181),
                Term::Text("boot up".into()),
                Term::Kinds(vec![Kind::Emcy]),
                Term::Text("warn".into()),
            ]
        );
        assert!(f.needs_label());
    }

    #[test]
    fn errors_say_where() {
        assert_eq!(
            Filter::parse("node 3 kind bogus").unwrap_err().to_string(),
            "column 13: unknown kind `bogus` (nmt sync emcy time tpdo rpdo pdo sdo heartbeat lss error other)"
        );
        assert_eq!(Filter::parse("node").unwrap_err().column, 5);
        assert_eq!(
            Filter::parse("node=200").unwrap_err().to_string(),
            "column 6: `200` is not a node-ID (0..127)"
        );
        assert_eq!(Filter::parse("x \"abc").unwrap_err().column, 3);
    }

    #[test]
    fn matching_uses_stored_kind_node_and_sdo_context() {
        let mut s = super::super::store::Store::new();
        s.push(
            &crate::frame::Frame::classic(0x603, &[0x40, 0x41, 0x60, 0]),
            Kind::SdoRx,
            Some(3),
        );
        let p = s.packed(0);
        let f = Filter::parse("node 3 sdo 6041").unwrap();
        assert!(f.matches(p, true, None));
        assert!(!f.matches(p, false, None));
        assert!(!Filter::parse("node 4").unwrap().matches(p, true, None));
        assert!(
            Filter::parse("upload")
                .unwrap()
                .matches(p, false, Some("SDO Upload request"))
        );
        assert!(
            !Filter::parse("download")
                .unwrap()
                .matches(p, false, Some("SDO Upload request"))
        );
    }
}
