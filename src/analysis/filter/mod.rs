//! The filter and search language (the same for the TUI's filter, its search and
//! `cotui decode --filter`).
//!
//! Conditions side by side must all match (`and` may be written); `or` matches either
//! side; `not` or `!` negates; parentheses group (`or` binds loosest, `not` tightest).
//!
//! | condition | matches |
//! |---|---|
//! | `node N`, `node=N`, `node 2-5` | frames of node N (decimal, or hex with `0x`), or of a range of nodes |
//! | `iface NAME`, `iface=NAME` | frames of the interface so named (`iface can1 and node 5`: node 5 of can1) |
//! | `kind K`, `kind=K`, or just `K` | frames of kind K (`nmt sync emcy time tpdo rpdo pdo sdo sdo_tx sdo_rx heartbeat hb lss error other`) |
//! | `id 181`, `id 700-77f`, `id 180/780` | COB-ID (hex), a range, or a mask (`id & 780 == 180`) |
//! | `tx`, `rx` | frames cotui sent (candump's `T`), frames received |
//! | `time 1.5-3.0`, `time 10-`, `time < 2` | seconds from the first frame of the capture (ranges include both ends) |
//! | `6041`, `6041:00`, `0x6041`, `Statusword`, `F0.1.002` | frames carrying the object: its SDO transfers and the PDOs whose mapping has it (index hex; a name or vendor alias of a bound profile) |
//! | `OBJECT OP NUMBER`, `OBJECT & MASK [OP NUMBER]` | ... whose raw value (before scaling) compares so (`== != < <= > >=`; `&` alone: some masked bit set); expedited SDO values and PDO signals |
//! | `abort`, `abort 0x0602` | SDO frames of aborted transfers; with hex digits, whose abort code starts with them |
//! | `"text"` | the decoded label contains the text (case-insensitive) |
//!
//! Any other word is an error with its column: free text must be quoted.

mod eval;
mod lex;
mod parse;
pub mod stream;

pub use eval::{Facts, Subject, Transfer, Tri};
pub use lex::Cmp;
pub use parse::{CodePrefix, Expr, IdMatch, Term, Test, kinds};

use crate::decode::Decoder;
use crate::od::Dictionary;
use crate::sdo::Transaction;

/// Resolves object names and vendor aliases to (index, sub).
pub trait Names {
    /// The object `text` names, if any.
    fn object(&self, text: &str) -> Option<(u16, u8)>;
}

/// No names: only hex object forms.
pub struct NoNames;

impl Names for NoNames {
    fn object(&self, _: &str) -> Option<(u16, u8)> {
        None
    }
}

/// Names of every dictionary a decoder uses (the default and each bound profile).
impl Names for Decoder {
    fn object(&self, text: &str) -> Option<(u16, u8)> {
        let mut seen: Vec<&Dictionary> = Vec::new();
        for node in 0..128u8 {
            let d = self.dictionary(node);
            let same = |o: &&Dictionary| {
                o.layers().len() == d.layers().len()
                    && o.layers()
                        .iter()
                        .zip(d.layers())
                        .all(|(a, b)| std::sync::Arc::ptr_eq(a, b))
            };
            if seen.iter().any(same) {
                continue;
            }
            seen.push(d);
            if let Ok(r) = crate::od::resolve_object(d, text) {
                return Some(r);
            }
        }
        None
    }
}

/// A filter that did not parse: 1-based column and what was wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("column {column}: {message}")]
pub struct FilterError {
    /// 1-based column.
    pub column: usize,
    /// What was wrong.
    pub message: String,
}

/// Characters of a word quoted in a message, and of the filter shown either side of an
/// error's column: a filter of 16,000 words is not repeated in its error.
const QUOTE_CHARS: usize = 40;

impl FilterError {
    fn new(column: usize, message: impl Into<String>) -> FilterError {
        FilterError {
            column,
            message: clip_words(message.into()),
        }
    }

    /// The part of `text` (the filter it was parsed from) around the error's column: at
    /// most [`QUOTE_CHARS`] characters either side, `…` where cut.
    pub fn excerpt(&self, text: &str) -> String {
        let at = self.column.saturating_sub(1);
        let from = at.saturating_sub(QUOTE_CHARS);
        let len = text.chars().count();
        let mut s: String = text.chars().skip(from).take(2 * QUOTE_CHARS).collect();
        if from > 0 {
            s.insert(0, '…');
        }
        if from + 2 * QUOTE_CHARS < len {
            s.push('…');
        }
        s
    }
}

/// `message` with each word longer than [`QUOTE_CHARS`] cut to its start, `…` and its
/// closing punctuation (a backquote, a quote).
fn clip_words(message: String) -> String {
    if !message.split(' ').any(|w| w.chars().count() > QUOTE_CHARS) {
        return message;
    }
    let clip = |w: &str| {
        if w.chars().count() <= QUOTE_CHARS {
            return w.to_string();
        }
        let mut s: String = w.chars().take(QUOTE_CHARS).collect();
        s.push('…');
        let tail: Vec<char> = w.chars().rev().take_while(|c| !c.is_alphanumeric()).take(2).collect();
        s.extend(tail.into_iter().rev());
        s
    };
    message.split(' ').map(clip).collect::<Vec<_>>().join(" ")
}

/// A parsed filter.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Filter {
    expr: Option<Expr>,
    /// The text it was parsed from.
    pub source: String,
}

impl Filter {
    /// Parses a filter with hex object forms only; an empty text matches everything.
    pub fn parse(text: &str) -> Result<Filter, FilterError> {
        Filter::parse_with(text, &NoNames)
    }

    /// Parses a filter; object names and aliases resolve through `names`.
    pub fn parse_with(text: &str, names: &dyn Names) -> Result<Filter, FilterError> {
        let toks = lex::tokens(text)?;
        let expr = parse::Parser::new(toks, text.chars().count(), names).parse()?;
        Ok(Filter {
            expr,
            source: text.trim().to_string(),
        })
    }

    /// Frames matching both `self` and `other` (e.g. a search within a filter).
    pub fn and(&self, other: &Filter) -> Filter {
        let expr = match (&self.expr, &other.expr) {
            (Some(a), Some(b)) => Some(Expr::And(vec![a.clone(), b.clone()])),
            (a, b) => a.clone().or_else(|| b.clone()),
        };
        Filter {
            expr,
            source: other.source.clone(),
        }
    }

    /// The expression (`None` for the empty filter).
    pub fn expr(&self) -> Option<&Expr> {
        self.expr.as_ref()
    }

    /// True when the filter has no condition.
    pub fn is_empty(&self) -> bool {
        self.expr.is_none()
    }

    /// True when some condition is about the outcome of SDO transfers (`abort`).
    pub fn needs_transfer(&self) -> bool {
        self.expr.as_ref().is_some_and(eval::needs_transfer)
    }

    /// Judges one frame.
    pub fn eval(&self, s: &Subject) -> Tri {
        match &self.expr {
            Some(e) => eval::eval(e, s),
            None => Tri::True,
        }
    }

    /// Judges one SDO transfer of interface `iface` (`t0_ns`: the first frame's time).
    pub fn matches_transaction(&self, t: &Transaction, iface: &str, dict: &Dictionary, t0_ns: u64) -> bool {
        self.expr
            .as_ref()
            .is_none_or(|e| eval::eval_transaction(e, t, iface, dict, t0_ns))
    }
}

#[cfg(test)]
mod tests;
