//! Object dictionaries: what an (index, sub) means on a given node.
//!
//! A [`Profile`] is everything we know about one device type: object names,
//! types, units, value texts, EMCY texts, default PDO mappings and vendor
//! quirks. Profiles are loaded from JSON in `decoders/` (see
//! `docs/PROFILE_FORMAT.md`) or imported from EDS/DCF files. All of this is
//! pure data: loading takes text and returns values plus warnings.

pub mod alias;
pub mod bind;
pub mod dcf;
mod device;
pub mod eds;
pub mod expr;
pub mod family;
pub mod fields;
mod index_set;
pub mod json;
pub mod merge;
pub mod procedure;
pub mod text;
mod value;

pub use alias::{AliasRule, resolve_object};
pub use bind::Bindings;
pub use device::{Axis, IdCondition, IdTest, IndexRange, ObjectRange, PdoSet, PdoTemplate, TextMatch};
pub use expr::Expr;
pub use family::SubFamily;
pub use fields::{ByteField, SdoCommand, SdoDirection};
pub use procedure::{Procedure, Step};
pub use value::{DataType, Value};

use std::collections::BTreeMap;

/// A problem found while loading a profile or EDS that did not stop the load.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning {
    /// The file (or built-in name) being loaded.
    pub file: String,
    /// Where: a JSON path such as `objects.0x6041.type`, or `line 12`.
    pub at: String,
    /// What is wrong and what was done about it.
    pub message: String,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.file, self.at, self.message)
    }
}

/// Access rights of an object entry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Access {
    #[default]
    Rw,
    Ro,
    Wo,
    Const,
    /// Readable and writable, mappable to an RPDO.
    Rww,
    /// Readable and writable, mappable to a TPDO.
    Rwr,
}

/// One entry (index, sub) of an object dictionary.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectInfo {
    /// Name shown in labels, e.g. "Statusword" or "Heartbeat producer time".
    pub name: String,
    /// Data type used to decode SDO and PDO bytes.
    pub data_type: DataType,
    /// Access rights.
    pub access: Access,
    /// Unit shown after the scaled value, e.g. "rpm".
    pub unit: Option<String>,
    /// Physical value = raw * scale (1.0 when absent).
    pub scale: Option<f64>,
    /// Texts for enumerated raw values.
    pub values: BTreeMap<i64, String>,
    /// Vendor parameter alias printed on the drive or in its manual, e.g. `F0.3.018`.
    pub alias: Option<String>,
    /// Names of single bits of a bit field (bit 0 = LSB).
    pub bits: BTreeMap<u8, String>,
    /// Whether the entry may be mapped into PDOs.
    pub pdo: PdoMappable,
    /// Default value (from an EDS `DefaultValue`, or a DCF's configured `ParameterValue`).
    pub default: Option<Value>,
    /// Lowest allowed raw value.
    pub min: Option<i64>,
    /// Highest allowed raw value.
    pub max: Option<i64>,
    /// Longer help text.
    pub description: Option<String>,
    /// Parts of a structured value (bytes of its little-endian encoding), e.g. 0x1016's
    /// node-ID and heartbeat time, 0x1003's error code and manufacturer information.
    pub fields: Vec<fields::ByteField>,
    /// What the raw value stands for when a vendor object holds a communication
    /// parameter (profile `"meaning"`), e.g. Syn-tron F0.7.041 is a TPDO COB-ID.
    pub meaning: Option<Meaning>,
}

/// A CiA 301 reading of a vendor object's raw value, so it is shown like the standard
/// object it configures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Meaning {
    /// A COB-ID with its flag bits (`0x00000181 (COB-ID 0x181)`).
    CobId,
    /// A PDO transmission type (`1 (synchronous, every SYNC)`).
    TransmissionType,
    /// A 16-bit object index (`24640 (0x6040 Controlword)`).
    ObjectIndex,
}

impl Meaning {
    /// The profile word for it.
    pub fn parse(word: &str) -> Option<Meaning> {
        match word {
            "cob_id" => Some(Meaning::CobId),
            "transmission_type" => Some(Meaning::TransmissionType),
            "object_index" => Some(Meaning::ObjectIndex),
            _ => None,
        }
    }
}

/// Whether an object may be mapped into PDOs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PdoMappable {
    #[default]
    No,
    /// Into transmit PDOs (device to bus).
    Tpdo,
    /// Into receive PDOs (bus to device).
    Rpdo,
    /// Into either.
    Both,
}

/// Where a PDO mapping came from, kept with every mapping we decode through.
#[derive(Clone, Debug, PartialEq)]
pub enum MappingSource {
    /// A built-in or user profile (`decoders/NAME.json`).
    Profile(String),
    /// An EDS/DCF file.
    Eds(String),
    /// Learned from SDO writes on the bus by another client, at this timestamp (ns).
    Sniffed { ts_ns: u64 },
    /// Written by cotui itself (its SDO requests came back marked TX), at this timestamp (ns).
    Configured { ts_ns: u64 },
    /// Read from the node (an SDO upload of the mapping seen on the bus), at this timestamp (ns).
    ReadFromNode { ts_ns: u64 },
}

/// One mapped object inside a PDO.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MappedEntry {
    pub index: u16,
    pub sub: u8,
    /// Length in bits.
    pub bits: u8,
}

/// The mapping of one PDO.
#[derive(Clone, Debug, PartialEq)]
pub struct PdoMapping {
    /// COB-ID when the profile moves it from the predefined one.
    pub cob_id: Option<u32>,
    pub entries: Vec<MappedEntry>,
    pub source: MappingSource,
}

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

/// The layered dictionary of one node: the first layer that knows an entry wins
/// (e.g. EDS, then vendor profile, then CiA 402, then CiA 301).
#[derive(Clone, Debug, Default)]
pub struct Dictionary {
    layers: Vec<std::sync::Arc<Profile>>,
    /// Per layer, the indexes it knows: lookups pass over the others.
    indexes: std::sync::Arc<[index_set::IndexSet]>,
}

impl Dictionary {
    /// A dictionary made of these layers, most specific first.
    pub fn new(layers: Vec<std::sync::Arc<Profile>>) -> Self {
        let indexes = layers.iter().map(|p| index_set::IndexSet::of(p)).collect();
        Dictionary { layers, indexes }
    }
    /// The layers that know anything at `index`, most specific first.
    fn layers_at(&self, index: u16) -> impl Iterator<Item = &Profile> {
        self.layers
            .iter()
            .zip(self.indexes.iter())
            .filter(move |(_, known)| known.contains(index))
            .map(|(p, _)| p.as_ref())
    }
    /// The layers, most specific first.
    pub fn layers(&self) -> &[std::sync::Arc<Profile>] {
        &self.layers
    }
    /// The entry at (index, sub) from the first layer that has it.
    pub fn object(&self, index: u16, sub: u8) -> Option<&ObjectInfo> {
        self.layers_at(index).find_map(|p| p.object(index, sub))
    }
    /// The name of the entry, else of the object (index level: a record's name or
    /// its sub 0 entry's), for labels.
    pub fn name(&self, index: u16, sub: u8) -> Option<&str> {
        self.object(index, sub)
            .map(|o| o.name.as_str())
            .or_else(|| self.object_name(index))
    }
    /// The name for labels: the entry's name followed by the vendor alias when the
    /// entry has one, e.g. `A speed command (F0.3.018)`.
    pub fn label_name(&self, index: u16, sub: u8) -> Option<String> {
        let object = self.object(index, sub);
        let name = object.map(|o| o.name.as_str()).or_else(|| self.object_name(index))?;
        match object.and_then(|o| o.alias.as_deref()) {
            Some(alias) => Some(format!("{name} ({alias})")),
            None => Some(name.to_string()),
        }
    }
    /// The most specific profile's name (e.g. "syntron-ds"), or "cia301".
    pub fn profile_name(&self) -> &str {
        self.layers.first().map(|p| p.name.as_str()).unwrap_or("cia301")
    }
    /// The name of an object at index level: a record's name, or its sub 0 entry's.
    pub fn object_name(&self, index: u16) -> Option<&str> {
        self.layers_at(index).find_map(|p| {
            p.object_name(index)
                .or_else(|| p.object(index, 0).map(|o| o.name.as_str()))
        })
    }
    /// The first layer with an EMCY manufacturer-byte layout, and that layout.
    pub fn emcy_fields(&self) -> &[ByteField] {
        self.layers
            .iter()
            .map(|p| p.emcy_fields.as_slice())
            .find(|f| !f.is_empty())
            .unwrap_or(&[])
    }
    /// A named procedure from the first layer that has it.
    pub fn procedure(&self, name: &str) -> Option<&Procedure> {
        self.layers.iter().find_map(|p| p.procedures.get(name))
    }
    /// Every named procedure, by name (the first layer's when several layers have one).
    pub fn procedures(&self) -> Vec<&Procedure> {
        let mut by_name: BTreeMap<&str, &Procedure> = BTreeMap::new();
        for p in self.layers.iter().rev().flat_map(|l| l.procedures.values()) {
            by_name.insert(&p.name, p);
        }
        by_name.into_values().collect()
    }
    /// A vendor SDO command from the first layer that has it.
    pub fn sdo_command(&self, command: u8, direction: SdoDirection) -> Option<&SdoCommand> {
        self.layers.iter().find_map(|p| p.sdo_command(command, direction))
    }
    /// The logical axis of an object, from the first layer that has axes.
    pub fn axis_of(&self, index: u16, sub: u8) -> Option<&Axis> {
        self.layers.iter().find_map(|p| p.axis_of(index, sub))
    }
    /// The PDO mappings (RPDO when `transmit` is false) of the first layer that has any.
    pub fn default_pdos(&self, transmit: bool) -> Option<&BTreeMap<u8, PdoMapping>> {
        self.layers
            .iter()
            .map(|p| if transmit { &p.tpdo } else { &p.rpdo })
            .find(|m| !m.is_empty())
    }
    /// The profile's "check first" steps for an exact EMCY code (empty when none).
    pub fn emcy_check(&self, code: u16) -> &[String] {
        self.layers
            .iter()
            .find_map(|p| p.emcy_check.get(&code))
            .map_or(&[], Vec::as_slice)
    }
    /// A vendor EMCY text for an exact code.
    pub fn emcy_text(&self, code: u16) -> Option<&str> {
        self.layers
            .iter()
            .find_map(|p| p.emcy_codes.get(&code))
            .map(String::as_str)
    }
}

/// Why writing an object is no configuration, whatever a DCF says: commands (store and
/// restore, program control, clearing the error history, the CiA 402 controlword) and the
/// CiA 402 set-points that move a motor (target position, velocity, torque). None: it may
/// be configuration.
pub fn not_configuration(index: u16) -> Option<&'static str> {
    match index {
        0x1010 => Some("store command (use --store)"),
        0x1011 => Some("restore-defaults command"),
        0x1003 => Some("error history (writing clears it)"),
        0x1F50..=0x1F57 => Some("program download/control"),
        0x6040 => Some("controlword (a command, not configuration)"),
        0x6042 | 0x6071 | 0x607A | 0x60C1 | 0x60FF => Some("set-point (moves the motor), not configuration"),
        _ => None,
    }
}

/// Formats a decoded value for a label: enum text, scaled value with unit, or the raw value.
///
/// `0x0006` of a U16 with values {6: "Shutdown"} -> `6 (Shutdown)`;
/// `15000` of an I32 with scale 0.1 and unit "rpm" -> `1500 rpm`.
pub fn format_value(info: Option<&ObjectInfo>, value: &Value) -> String {
    let Some(info) = info else { return value.to_string() };
    if let Some(raw) = value.as_i64()
        && let Some(text) = info.values.get(&raw)
    {
        return format!("{raw} ({text})");
    }
    match (value.as_f64(), info.scale, &info.unit) {
        (Some(x), scale, unit) if scale.is_some() || unit.is_some() => {
            let scaled = x * scale.unwrap_or(1.0);
            let mut s = format_number(scaled);
            if let Some(u) = unit {
                s.push(' ');
                s.push_str(u);
            }
            s
        }
        _ => value.to_string(),
    }
}

/// A float printed without trailing zeros (`1500`, `0.25`, `-3.5`).
pub fn format_number(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{}", x as i64)
    } else {
        let s = format!("{x:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The EMCY manufacturer fields of an 8-byte frame through the node's layout,
/// as (name, shown value) pairs; empty when no profile describes them.
pub fn emcy_fields(dict: &Dictionary, frame: &[u8; 8]) -> Vec<(String, String)> {
    dict.emcy_fields()
        .iter()
        .filter_map(|f| f.raw(frame).map(|raw| (f.name.clone(), f.format(raw))))
        .collect()
}
