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

mod error;
mod eval;
mod lex;
mod names;
mod parse;
pub mod stream;

pub use error::FilterError;
pub use eval::{Ended, Facts, Subject, Transfer, Tri};
pub use lex::Cmp;
pub use names::{Names, NoNames};
pub use parse::{CodePrefix, Expr, IdMatch, Term, Test, kinds};

use crate::od::Dictionary;
use crate::sdo::Transaction;

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
