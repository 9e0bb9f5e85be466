//! [`Dictionary`]: the layered profiles of one node.

use super::device::Axis;
use super::fields::{ByteField, SdoCommand, SdoDirection};
use super::index_set::IndexSet;
use super::mapping::PdoMapping;
use super::object::ObjectInfo;
use super::procedure::Procedure;
use super::profile::Profile;

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};

/// The layered dictionary of one node: the first layer that knows an entry wins
/// (e.g. EDS, then vendor profile, then CiA 402, then CiA 301).
///
/// Clones share the layers; a dictionary made by [`Dictionary::lazy`] builds them on its
/// first lookup, once for all its clones.
#[derive(Clone, Debug, Default)]
pub struct Dictionary {
    built: Arc<OnceLock<Layers>>,
    /// What builds the layers of a lazy dictionary (none: no layers).
    load: Option<fn() -> Vec<Arc<Profile>>>,
}

/// The layers of a dictionary, most specific first, and the indexes each knows.
#[derive(Debug)]
struct Layers {
    profiles: Vec<Arc<Profile>>,
    /// Per layer, the indexes it knows: lookups pass over the others.
    indexes: Vec<IndexSet>,
}

impl Layers {
    fn of(profiles: Vec<Arc<Profile>>) -> Layers {
        let indexes = profiles.iter().map(|p| IndexSet::of(p)).collect();
        Layers { profiles, indexes }
    }
}

impl Dictionary {
    /// A dictionary made of these layers, most specific first.
    pub fn new(layers: Vec<Arc<Profile>>) -> Self {
        Dictionary {
            built: Arc::new(OnceLock::from(Layers::of(layers))),
            load: None,
        }
    }
    /// A dictionary whose layers `load` gives when it is first looked into (so a run that
    /// names no object never builds them).
    pub fn lazy(load: fn() -> Vec<Arc<Profile>>) -> Self {
        Dictionary {
            built: Arc::new(OnceLock::new()),
            load: Some(load),
        }
    }
    fn built(&self) -> &Layers {
        self.built
            .get_or_init(|| Layers::of(self.load.map_or_else(Vec::new, |load| load())))
    }
    /// The layers that know anything at `index`, most specific first.
    fn layers_at(&self, index: u16) -> impl Iterator<Item = &Profile> {
        let built = self.built();
        built
            .profiles
            .iter()
            .zip(built.indexes.iter())
            .filter(move |(_, known)| known.contains(index))
            .map(|(p, _)| p.as_ref())
    }
    /// The layers, most specific first.
    pub fn layers(&self) -> &[Arc<Profile>] {
        &self.built().profiles
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
        self.layers().first().map(|p| p.name.as_str()).unwrap_or("cia301")
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
        self.layers()
            .iter()
            .map(|p| p.emcy_fields.as_slice())
            .find(|f| !f.is_empty())
            .unwrap_or(&[])
    }
    /// A named procedure from the first layer that has it.
    pub fn procedure(&self, name: &str) -> Option<&Procedure> {
        self.layers().iter().find_map(|p| p.procedures.get(name))
    }
    /// Every named procedure, by name (the first layer's when several layers have one).
    pub fn procedures(&self) -> Vec<&Procedure> {
        let mut by_name: BTreeMap<&str, &Procedure> = BTreeMap::new();
        for p in self.layers().iter().rev().flat_map(|l| l.procedures.values()) {
            by_name.insert(&p.name, p);
        }
        by_name.into_values().collect()
    }
    /// A vendor SDO command from the first layer that has it.
    pub fn sdo_command(&self, command: u8, direction: SdoDirection) -> Option<&SdoCommand> {
        self.layers().iter().find_map(|p| p.sdo_command(command, direction))
    }
    /// The logical axis of an object, from the first layer that has axes.
    pub fn axis_of(&self, index: u16, sub: u8) -> Option<&Axis> {
        self.layers().iter().find_map(|p| p.axis_of(index, sub))
    }
    /// The PDO mappings (RPDO when `transmit` is false) of the first layer that has any.
    pub fn default_pdos(&self, transmit: bool) -> Option<&BTreeMap<u8, PdoMapping>> {
        self.layers()
            .iter()
            .map(|p| if transmit { &p.tpdo } else { &p.rpdo })
            .find(|m| !m.is_empty())
    }
    /// The profile's "check first" steps for an exact EMCY code (empty when none).
    pub fn emcy_check(&self, code: u16) -> &[String] {
        self.layers()
            .iter()
            .find_map(|p| p.emcy_check.get(&code))
            .map_or(&[], Vec::as_slice)
    }
    /// A vendor EMCY text for an exact code.
    pub fn emcy_text(&self, code: u16) -> Option<&str> {
        self.layers()
            .iter()
            .find_map(|p| p.emcy_codes.get(&code))
            .map(String::as_str)
    }
}
