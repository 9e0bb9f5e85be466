//! The parts of a device profile beyond single objects: PDO mapping sets,
//! identification, logical axes and index-range templates.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use super::expr::Expr;
use super::family::Numbered;
use super::mapping::{MappedEntry, MappingSource, PdoMapping};
use super::object::ObjectInfo;
use super::value::Value;

/// A PDO of a mapping set before it is placed on a node.
#[derive(Clone, Debug, PartialEq)]
pub struct PdoTemplate {
    /// COB-ID, may use `node`; `None` = the predefined COB-ID for that PDO number.
    pub cob_id: Option<Expr>,
    /// Transmission type (0x00..0xFF), when the profile gives one.
    pub transmission_type: Option<u8>,
    /// The mapped objects.
    pub entries: Vec<MappedEntry>,
}

/// A named set of default PDO mappings (Dexmart has two, chosen by parameter 09-26).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PdoSet {
    /// Set name, e.g. "mapping-0".
    pub name: String,
    /// Help text.
    pub description: Option<String>,
    /// The set the decoder uses until it learns better.
    pub default: bool,
    /// The parameter (object text, may be an alias) and value that select this set on the device.
    pub selected_by: Option<(String, i64)>,
    /// RPDOs by number (1-based).
    pub rpdo: BTreeMap<u8, PdoTemplate>,
    /// TPDOs by number (1-based).
    pub tpdo: BTreeMap<u8, PdoTemplate>,
}

impl PdoSet {
    /// The mappings of this set on `node`, with COB-IDs worked out (`None` when the
    /// profile leaves the predefined one, or the expression needs a node and none is given).
    pub fn mappings(&self, transmit: bool, node: Option<u8>, source: &MappingSource) -> BTreeMap<u8, PdoMapping> {
        let pdos = if transmit { &self.tpdo } else { &self.rpdo };
        pdos.iter()
            .map(|(n, t)| {
                let cob_id = t.cob_id.as_ref().and_then(|e| {
                    let v = e.eval(&|v| node.filter(|_| v == "node").map(i64::from)).ok()?;
                    u32::try_from(v).ok()
                });
                let mapping = PdoMapping {
                    cob_id,
                    entries: t.entries.clone(),
                    source: source.clone(),
                };
                (*n, mapping)
            })
            .collect()
    }
}

/// How a value of an identity object is compared.
#[derive(Clone, Debug, PartialEq)]
pub enum IdTest {
    /// `(value & mask) == expected`.
    Number { expected: u64, mask: u64 },
    /// Visible string, case-insensitive, trailing NULs and spaces ignored.
    Text { expected: String, mode: TextMatch },
}

/// How an identification text is compared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextMatch {
    #[default]
    Exact,
    Prefix,
    Contains,
}

/// One condition on an identity object (0x1000, 0x1008, 0x1018:1, ...).
#[derive(Clone, Debug, PartialEq)]
pub struct IdCondition {
    /// The object read.
    pub index: u16,
    /// Its sub-index.
    pub sub: u8,
    /// The test.
    pub test: IdTest,
}

impl IdCondition {
    /// Whether a read value passes.
    pub fn matches(&self, value: &Value) -> bool {
        match (&self.test, value) {
            (IdTest::Number { expected, mask }, v) => match v.as_i64() {
                Some(x) => (x as u64) & mask == expected & mask,
                None => false,
            },
            (IdTest::Text { expected, mode }, Value::Text(t)) => {
                let t = t.trim_end_matches(['\0', ' ']).to_lowercase();
                let e = expected.to_lowercase();
                match mode {
                    TextMatch::Exact => t == e,
                    TextMatch::Prefix => t.starts_with(&e),
                    TextMatch::Contains => t.contains(&e),
                }
            }
            _ => false,
        }
    }
}

/// Objects an axis owns: one sub, all subs of an index, or an index range.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjectRange {
    /// First index.
    pub first: u16,
    /// Last index (inclusive).
    pub last: u16,
    /// One sub only, when given.
    pub sub: Option<u8>,
}

impl ObjectRange {
    /// Whether (index, sub) is in the range.
    pub fn contains(&self, index: u16, sub: u8) -> bool {
        (self.first..=self.last).contains(&index) && self.sub.is_none_or(|s| s == sub)
    }
}

/// A logical axis served by a node (Dexmart M1/M2, Syn-tron A/B).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Axis {
    /// Label, e.g. "M1".
    pub name: String,
    /// Help text.
    pub description: Option<String>,
    /// The objects that belong to this axis.
    pub objects: Vec<ObjectRange>,
    /// Name of the EMCY manufacturer field carrying this axis' alarm code.
    pub emcy_field: Option<String>,
}

/// Identical records at every index of a range, stored once.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexRange {
    /// First index.
    pub first: u16,
    /// Last index (inclusive).
    pub last: u16,
    /// The sub-entries every index in the range has.
    pub subs: BTreeMap<u8, ObjectInfo>,
    /// The record name, `{i}` standing for the 1-based place in the range
    /// (`TPDO{i} mapping parameter`).
    pub name: Option<String>,
    /// The names made from `name`, on first use (thousands in CiA 301).
    names: OnceLock<Vec<String>>,
}

impl IndexRange {
    /// Records at `first..=last` with these subs and record name.
    pub fn new(first: u16, last: u16, subs: BTreeMap<u8, ObjectInfo>, name: Option<String>) -> IndexRange {
        IndexRange {
            first,
            last: last.max(first),
            subs,
            name,
            names: OnceLock::new(),
        }
    }

    /// Whether `index` is in the range.
    pub fn contains(&self, index: u16) -> bool {
        (self.first..=self.last).contains(&index)
    }

    /// The record name at `index` (`TPDO3 mapping parameter`), `None` outside the range
    /// or when the range has no name.
    pub fn name(&self, index: u16) -> Option<&str> {
        let template = self.name.as_deref().filter(|_| self.contains(index))?;
        let names = self.names.get_or_init(|| {
            let name = Numbered::new(template, "{i}");
            (1..=u32::from(self.last - self.first) + 1)
                .map(|i| name.with(i))
                .collect()
        });
        names.get(usize::from(index - self.first)).map(String::as_str)
    }
}
