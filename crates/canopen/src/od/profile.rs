//! [`Profile`]: everything known about one device type.

use super::alias::AliasRule;
use super::device::{Axis, IdCondition, IndexRange, PdoSet};
use super::family::SubFamily;
use super::fields::{ByteField, SdoCommand, SdoDirection};
use super::mapping::PdoMapping;
use super::object::ObjectInfo;
use super::procedure::Procedure;
use super::value::Value;

use std::collections::BTreeMap;

/// Everything known about one device type.
#[derive(Clone, Debug, Default)]
pub struct Profile {
    /// Short name, e.g. "cia402" or "syntron-ds".
    pub name: String,
    /// One line for humans.
    pub description: String,
    /// Profiles this one builds on, most specific first (e.g. ["cia402"]).
    pub extends: Vec<String>,
    /// Names of records and arrays at index level, e.g. 0x1018 -> "Identity object";
    /// an index range's are in the range: [`Profile::object_name`] and
    /// [`Profile::names`] give both.
    pub object_names: BTreeMap<u16, String>,
    /// Extra vendor aliases besides each object's own `alias`.
    pub aliases: BTreeMap<String, (u16, u8)>,
    /// Rules turning vendor parameter numbers into objects.
    pub alias_rules: Vec<AliasRule>,
    /// Layout of the EMCY manufacturer-specific bytes.
    pub emcy_fields: Vec<ByteField>,
    /// Named default PDO mapping sets; `rpdo`/`tpdo` hold the default one's.
    pub pdo_sets: Vec<PdoSet>,
    /// Vendor SDO commands.
    pub sdo_commands: Vec<SdoCommand>,
    /// Named procedures.
    pub procedures: BTreeMap<String, Procedure>,
    /// Conditions on identity objects that recognise the device (all must hold).
    pub identification: Vec<IdCondition>,
    /// Logical axes on one node.
    pub axes: Vec<Axis>,
    /// Node-ID from an EDS/DCF `[DeviceCommissioning]` section.
    pub node_id: Option<u8>,
    /// Node name from an EDS/DCF `[DeviceCommissioning]` section.
    pub node_name: Option<String>,
    /// Objects given one by one, by (index, sub). Single-valued objects use sub 0.
    /// Entries of sub ranges are in `families`: [`Profile::entries`] lists both.
    pub objects: BTreeMap<(u16, u8), ObjectInfo>,
    /// Sub ranges of records (`"1..254"`) by (index, first sub), each one template; an
    /// entry in `objects` at the same (index, sub) wins.
    pub families: BTreeMap<(u16, u8), SubFamily>,
    /// Families of identical records over index ranges (PDO/SDO parameters),
    /// used for an index that has no entry in `objects`.
    pub ranges: Vec<IndexRange>,
    /// Vendor EMCY code texts by exact code.
    pub emcy_codes: BTreeMap<u16, String>,
    /// Device-specific "check first" steps by exact EMCY code, most likely cause first.
    pub emcy_check: BTreeMap<u16, Vec<String>>,
    /// Default RPDO mappings by PDO number (1-based).
    pub rpdo: BTreeMap<u8, PdoMapping>,
    /// Default TPDO mappings by PDO number (1-based).
    pub tpdo: BTreeMap<u8, PdoMapping>,
}

impl Profile {
    /// The entry at (index, sub): from `objects`, else from a sub family, or from an
    /// index range when the profile has nothing else at that index.
    pub fn object(&self, index: u16, sub: u8) -> Option<&ObjectInfo> {
        if let Some(o) = self.objects.get(&(index, sub)) {
            return Some(o);
        }
        if let Some(o) = self.family_entry(index, sub) {
            return Some(o);
        }
        if self.has_index(index) {
            return None;
        }
        self.range_of(index).and_then(|r| r.subs.get(&sub))
    }

    /// The entry at (index, sub) of a sub family.
    fn family_entry(&self, index: u16, sub: u8) -> Option<&ObjectInfo> {
        let (_, family) = self.families.range((index, 0)..=(index, sub)).next_back()?;
        family.get(sub)
    }

    /// Whether `objects` or `families` have anything at `index`.
    fn has_index(&self, index: u16) -> bool {
        self.objects.range((index, 0)..=(index, 255)).next().is_some()
            || self.families.range((index, 0)..=(index, 255)).next().is_some()
    }

    /// Every entry of `objects` and `families` (not index ranges), by (index, sub),
    /// each once: the one `object` gives.
    pub fn entries(&self) -> impl Iterator<Item = ((u16, u8), &ObjectInfo)> {
        let families = self.families.iter().flat_map(|(&(index, _), f)| {
            f.iter()
                .map(move |(sub, info)| ((index, sub), info))
                .filter(|(key, _)| !self.objects.contains_key(key))
        });
        let mut all: Vec<((u16, u8), &ObjectInfo)> = self.objects.iter().map(|(k, o)| (*k, o)).collect();
        if !self.families.is_empty() {
            all.extend(families);
            all.sort_unstable_by_key(|(key, _)| *key);
        }
        all.into_iter()
    }

    /// The first entry by (index, sub) for which `pred` holds: what `entries().find` gives,
    /// without listing every entry.
    pub fn find_entry(&self, pred: impl Fn(&ObjectInfo) -> bool) -> Option<((u16, u8), &ObjectInfo)> {
        let own = self.objects.iter().find(|(_, o)| pred(o)).map(|(k, o)| (*k, o));
        let in_family = self
            .families
            .iter()
            .flat_map(|(&(index, _), f)| f.iter().map(move |(sub, o)| ((index, sub), o)))
            .find(|(key, o)| pred(o) && !self.objects.contains_key(key));
        match (own, in_family) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
            (a, b) => a.or(b),
        }
    }

    /// The lowest index whose record name (as `object_name` gives it) `pred` accepts: what
    /// `names().find` gives, without listing every name.
    pub fn find_name(&self, pred: impl Fn(&str) -> bool) -> Option<u16> {
        let own = self.object_names.iter().find(|(_, n)| pred(n)).map(|(i, _)| *i);
        let ranged = self
            .ranges
            .iter()
            .filter_map(|r| {
                (r.first..=r.last).find(|&i| r.name(i).is_some_and(&pred) && self.object_name(i) == r.name(i))
            })
            .min();
        own.into_iter().chain(ranged).min()
    }

    /// The entries of `objects` and `families` at `index`, by sub, each once.
    pub fn entries_at(&self, index: u16) -> Vec<(u8, &ObjectInfo)> {
        let mut subs: BTreeMap<u8, &ObjectInfo> = self
            .families
            .range((index, 0)..=(index, 255))
            .flat_map(|(_, f)| f.iter())
            .collect();
        subs.extend(self.objects.range((index, 0)..=(index, 255)).map(|(k, o)| (k.1, o)));
        subs.into_iter().collect()
    }

    /// Adds a sub family at `index`.
    pub fn add_family(&mut self, index: u16, family: SubFamily) {
        self.families.insert((index, *family.subs().start()), family);
    }

    /// Removes every entry and family at `index`.
    pub fn remove_index(&mut self, index: u16) {
        let stale: Vec<(u16, u8)> = self.objects.range((index, 0)..=(index, 255)).map(|(k, _)| *k).collect();
        for k in stale {
            self.objects.remove(&k);
        }
        let stale: Vec<(u16, u8)> = self
            .families
            .range((index, 0)..=(index, 255))
            .map(|(k, _)| *k)
            .collect();
        for k in stale {
            self.families.remove(&k);
        }
    }

    /// The name of the record at `index`: its own, else the last-defined index range's
    /// that names it (`TPDO3 mapping parameter`).
    pub fn object_name(&self, index: u16) -> Option<&str> {
        match self.object_names.get(&index) {
            Some(name) => Some(name),
            None => self.ranges.iter().rev().find_map(|r| r.name(index)),
        }
    }

    /// Every record name by index, as `object_name` gives it.
    pub fn names(&self) -> BTreeMap<u16, &str> {
        let mut names = BTreeMap::new();
        for r in &self.ranges {
            names.extend((r.first..=r.last).filter_map(|i| Some((i, r.name(i)?))));
        }
        names.extend(self.object_names.iter().map(|(i, n)| (*i, n.as_str())));
        names
    }

    /// The last-defined index range containing `index`.
    fn range_of(&self, index: u16) -> Option<&IndexRange> {
        self.ranges.iter().rev().find(|r| r.contains(index))
    }

    /// Copies an index range's entries for `index` into `objects`, so that single
    /// entries can then be changed there.
    pub fn materialize(&mut self, index: u16) {
        if self.has_index(index) {
            return;
        }
        let Some(subs) = self.range_of(index).map(|r| r.subs.clone()) else {
            return;
        };
        for (sub, info) in subs {
            self.objects.insert((index, sub), info);
        }
    }

    /// The default PDO set (the one marked default, else the first).
    pub fn default_pdo_set(&self) -> Option<&PdoSet> {
        self.pdo_sets.iter().find(|s| s.default).or(self.pdo_sets.first())
    }

    /// Whether the identity values (`read(index, sub)`) match all identification
    /// conditions; false when the profile has none or a value is missing.
    pub fn identifies(&self, read: &dyn Fn(u16, u8) -> Option<Value>) -> bool {
        !self.identification.is_empty()
            && self
                .identification
                .iter()
                .all(|c| read(c.index, c.sub).is_some_and(|v| c.matches(&v)))
    }

    /// The logical axis an object belongs to.
    pub fn axis_of(&self, index: u16, sub: u8) -> Option<&Axis> {
        self.axes
            .iter()
            .find(|a| a.objects.iter().any(|r| r.contains(index, sub)))
    }

    /// The vendor SDO command for this command byte and direction.
    pub fn sdo_command(&self, command: u8, direction: SdoDirection) -> Option<&SdoCommand> {
        self.sdo_commands
            .iter()
            .find(|c| c.command == command && c.direction == direction)
    }
}
