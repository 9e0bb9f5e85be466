//! The evaluator: an expression over one frame (what the store keeps, plus its decoded
//! form and its SDO transfer when they are known), or over one SDO transfer.
//!
//! Frames are judged in three-valued logic: a condition that needs the decoded frame
//! (label text, objects, values) or the transfer's outcome (`abort`) is
//! [`Tri::Unknown`] until that is given, so a scan decodes only the frames whose result
//! depends on it, and keeps back only the SDO frames whose transfer has not ended yet.

use super::parse::{Expr, IdMatch, Term, Test};
use crate::decode::{Body, Decoded, Kind};
use crate::frame::Flags;
use crate::od::{Dictionary, Value};
use crate::sdo::SdoCommand;
use crate::sdo::{Outcome, Transaction};

/// True, false, or not decidable from what is known yet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tri {
    /// Matches.
    True,
    /// Does not match.
    False,
    /// Needs the decoded frame or its transfer.
    Unknown,
}

impl Tri {
    fn of(b: bool) -> Tri {
        if b { Tri::True } else { Tri::False }
    }
    fn not(self) -> Tri {
        match self {
            Tri::True => Tri::False,
            Tri::False => Tri::True,
            Tri::Unknown => Tri::Unknown,
        }
    }
}

/// What the store keeps of a frame (enough for node, kind, ID, direction and time).
#[derive(Clone, Copy, Debug)]
pub struct Facts {
    /// Timestamp (ns).
    pub ts_ns: u64,
    /// Identifier.
    pub id: u32,
    /// [`Flags`] bits.
    pub flags: u8,
    /// Kind from the indexing pass.
    pub kind: Kind,
    /// Node from the indexing pass.
    pub node: Option<u8>,
}

impl From<&crate::analysis::store::Packed> for Facts {
    fn from(p: &crate::analysis::store::Packed) -> Facts {
        Facts {
            ts_ns: p.ts_ns,
            id: p.id,
            flags: p.flags,
            kind: p.kind(),
            node: p.node(),
        }
    }
}

/// The SDO transfer a frame belongs to, as far as known.
#[derive(Clone, Copy, Debug)]
pub enum Transfer {
    /// Not known yet (the transfer may still be running).
    Unknown,
    /// Known: how the transfer ended, or none (not an SDO frame, or a frame of no transfer).
    Known(Option<Ended>),
}

/// How an SDO transfer ended, as far as a filter asks (`abort`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ended {
    /// Aborted with this code.
    Aborted(u32),
    /// Completed, broken off or cut by the end of the input.
    Otherwise,
}

impl Ended {
    /// How a transfer with `outcome` ended.
    pub fn of(outcome: &Outcome) -> Ended {
        match outcome {
            Outcome::Aborted { code, .. } => Ended::Aborted(*code),
            _ => Ended::Otherwise,
        }
    }
}

/// One frame to judge.
#[derive(Clone, Copy, Debug)]
pub struct Subject<'a> {
    /// What the store keeps.
    pub facts: Facts,
    /// Timestamp of the first frame of the capture (for `time`).
    pub t0_ns: u64,
    /// The name of the frame's interface (for `iface`).
    pub iface: &'a str,
    /// The decoded frame, when decoded.
    pub decoded: Option<&'a Decoded>,
    /// Its SDO transfer.
    pub transfer: Transfer,
}

fn is_sdo(k: Kind) -> bool {
    matches!(k, Kind::SdoTx | Kind::SdoRx)
}

fn id_matches(m: IdMatch, id: u32) -> bool {
    match m {
        IdMatch::Range(lo, hi) => (lo..=hi).contains(&id),
        IdMatch::Mask { value, mask } => id & mask == value & mask,
    }
}

/// True when `v` passes `test` (a value that is not a number never does).
fn passes(test: &Test, v: &Value) -> bool {
    let x = match test.mask {
        Some(m) => match v.as_i64() {
            Some(i) => (i as u64 & m) as f64,
            None => return false,
        },
        None => match v.as_f64() {
            Some(x) => x,
            None => return false,
        },
    };
    match test.cmp {
        Some((cmp, want)) => cmp.holds(x, want),
        None => x != 0.0,
    }
}

fn sub_ok(want: Option<u8>, sub: u8) -> bool {
    want.is_none_or(|w| w == sub)
}

/// The typed value an SDO frame carries (expedited data), typed by the dictionary or
/// else the little-endian number.
fn sdo_value(v: &crate::decode::sdo::value::ValueView) -> Option<Value> {
    v.typed.clone().or_else(|| match &v.json {
        serde_json::Value::Number(n) => n
            .as_u64()
            .map(Value::Unsigned)
            .or_else(|| n.as_i64().map(Value::Signed))
            .or_else(|| n.as_f64().map(Value::Float)),
        _ => None,
    })
}

fn term(t: &Term, s: &Subject) -> Tri {
    let f = &s.facts;
    match t {
        Term::Node(lo, hi) => Tri::of(f.node.is_some_and(|n| (*lo..=*hi).contains(&n))),
        Term::Iface(name) => Tri::of(s.iface == name),
        Term::Kinds(ks) => Tri::of(ks.contains(&f.kind)),
        Term::Id(m) => Tri::of(id_matches(*m, f.id)),
        Term::Tx(tx) => Tri::of(Flags(f.flags).has(Flags::TX) == *tx),
        Term::Time(cmp, secs) => Tri::of(cmp.holds(f.ts_ns.saturating_sub(s.t0_ns) as f64 / 1e9, *secs)),
        Term::Text(x) => match s.decoded {
            Some(d) => Tri::of(d.label.to_lowercase().contains(x.as_str())),
            None => Tri::Unknown,
        },
        Term::Object { index, sub, test } => {
            if !matches!(f.kind, Kind::SdoTx | Kind::SdoRx | Kind::Tpdo | Kind::Rpdo) {
                return Tri::False;
            }
            let Some(d) = s.decoded else { return Tri::Unknown };
            Tri::of(match &d.body {
                Body::Sdo(frame) => {
                    frame.object.is_some_and(|(i, su)| i == *index && sub_ok(*sub, su))
                        && test.is_none_or(|t| frame.value.as_ref().and_then(sdo_value).is_some_and(|v| passes(&t, &v)))
                }
                Body::Pdo(p) => p.signals.iter().any(|sig| {
                    sig.index == *index && sub_ok(*sub, sig.sub) && test.is_none_or(|t| passes(&t, &sig.value))
                }),
                _ => false,
            })
        }
        Term::Abort(prefix) => {
            if !is_sdo(f.kind) {
                return Tri::False;
            }
            let code_ok = |code: u32| prefix.is_none_or(|p| p.matches(code));
            match s.transfer {
                Transfer::Unknown => Tri::Unknown,
                Transfer::Known(Some(ended)) => Tri::of(matches!(ended, Ended::Aborted(code) if code_ok(code))),
                // An abort frame outside any transfer still says abort.
                Transfer::Known(None) => match s.decoded {
                    None => Tri::Unknown,
                    Some(d) => Tri::of(matches!(&d.body,
                        Body::Sdo(frame) if matches!(frame.command, SdoCommand::Abort { code, .. } if code_ok(code)))),
                },
            }
        }
    }
}

/// Judges `e` on one frame.
pub fn eval(e: &Expr, s: &Subject) -> Tri {
    match e {
        Expr::Term(t) => term(t, s),
        Expr::Not(e) => eval(e, s).not(),
        Expr::And(parts) => {
            let mut out = Tri::True;
            for p in parts {
                match eval(p, s) {
                    Tri::False => return Tri::False,
                    Tri::Unknown => out = Tri::Unknown,
                    Tri::True => {}
                }
            }
            out
        }
        Expr::Or(parts) => {
            let mut out = Tri::False;
            for p in parts {
                match eval(p, s) {
                    Tri::True => return Tri::True,
                    Tri::Unknown => out = Tri::Unknown,
                    Tri::False => {}
                }
            }
            out
        }
    }
}

/// True when `e` has a condition on the SDO transfer's outcome (`abort`).
pub fn needs_transfer(e: &Expr) -> bool {
    match e {
        Expr::Term(t) => matches!(t, Term::Abort(_)),
        Expr::Not(e) => needs_transfer(e),
        Expr::And(p) | Expr::Or(p) => p.iter().any(needs_transfer),
    }
}

/// Judges `e` on one SDO transfer (for `cotui decode --transactions`): node, SDO kinds,
/// COB-IDs of its channel, its start time, object and (typed) value, abort, label text.
/// Direction and the other kinds never match a transfer. `iface` names its interface.
pub fn eval_transaction(e: &Expr, t: &Transaction, iface: &str, dict: &Dictionary, t0_ns: u64) -> bool {
    let term = |x: &Term| match x {
        Term::Node(lo, hi) => (*lo..=*hi).contains(&t.node),
        Term::Iface(name) => iface == name,
        Term::Kinds(ks) => ks.iter().any(|k| is_sdo(*k)),
        Term::Id(m) => id_matches(*m, t.channel.request_cob) || id_matches(*m, t.channel.response_cob),
        Term::Tx(_) => false,
        Term::Time(cmp, secs) => cmp.holds(t.start_ns.saturating_sub(t0_ns) as f64 / 1e9, *secs),
        Term::Text(x) => t.label(dict).to_lowercase().contains(x.as_str()),
        Term::Object { index, sub, test } => {
            t.index == *index
                && sub_ok(*sub, t.sub)
                && test.is_none_or(|test| {
                    let v = crate::decode::sdo::value::view(dict, t.index, t.sub, &t.data);
                    sdo_value(&v).is_some_and(|v| passes(&test, &v))
                })
        }
        Term::Abort(prefix) => {
            matches!(t.outcome, Outcome::Aborted { code, .. } if prefix.is_none_or(|p| p.matches(code)))
        }
    };
    fn walk(e: &Expr, term: &dyn Fn(&Term) -> bool) -> bool {
        match e {
            Expr::Term(x) => term(x),
            Expr::Not(e) => !walk(e, term),
            Expr::And(p) => p.iter().all(|e| walk(e, term)),
            Expr::Or(p) => p.iter().any(|e| walk(e, term)),
        }
    }
    walk(e, &term)
}
