//! Object dictionaries: what an (index, sub) means on a given node.
//!
//! A [`Profile`] is everything we know about one device type: object names,
//! types, units, value texts, EMCY texts, default PDO mappings and vendor
//! quirks. Profiles are loaded from JSON in `decoders/` (see
//! `docs/PROFILE_FORMAT.md`) or imported from EDS/DCF files. All of this is
//! pure data: loading takes text and returns values plus warnings.

mod value;

pub use value::{DataType, Value};

use std::collections::BTreeMap;

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
}

/// Where a PDO mapping came from, kept with every mapping we decode through.
#[derive(Clone, Debug, PartialEq)]
pub enum MappingSource {
    /// A built-in or user profile (`decoders/NAME.json`).
    Profile(String),
    /// An EDS/DCF file.
    Eds(String),
    /// Learned from SDO traffic on the bus, at this timestamp (ns).
    Sniffed { ts_ns: u64 },
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

/// One field of the EMCY manufacturer-specific bytes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EmcyField {
    /// Offset in the 8-byte EMCY frame (3..=7).
    pub offset: u8,
    /// Length in bytes (little-endian).
    pub len: u8,
    /// Name shown in labels, e.g. "M1 alarm".
    pub name: String,
    /// Texts for values of this field.
    pub values: BTreeMap<i64, String>,
}

/// Everything known about one device type.
#[derive(Clone, Debug, Default)]
pub struct Profile {
    /// Short name, e.g. "cia402" or "syntron-ds".
    pub name: String,
    /// Objects by (index, sub). Single-valued objects use sub 0.
    pub objects: BTreeMap<(u16, u8), ObjectInfo>,
    /// Vendor EMCY code texts by exact code.
    pub emcy_codes: BTreeMap<u16, String>,
    /// How the 5 manufacturer bytes of an EMCY are laid out (empty: shown as hex).
    pub emcy_layout: Vec<EmcyField>,
    /// Default RPDO mappings by PDO number (1-based).
    pub rpdo: BTreeMap<u16, PdoMapping>,
    /// Default TPDO mappings by PDO number (1-based).
    pub tpdo: BTreeMap<u16, PdoMapping>,
}

impl Profile {
    /// The entry at (index, sub), falling back to sub 0 for the name of a record/array.
    pub fn object(&self, index: u16, sub: u8) -> Option<&ObjectInfo> {
        self.objects.get(&(index, sub))
    }
}

/// The layered dictionary of one node: the first layer that knows an entry wins
/// (e.g. EDS, then vendor profile, then CiA 402, then CiA 301).
#[derive(Clone, Debug, Default)]
pub struct Dictionary {
    layers: Vec<std::sync::Arc<Profile>>,
}

impl Dictionary {
    /// A dictionary made of these layers, most specific first.
    pub fn new(layers: Vec<std::sync::Arc<Profile>>) -> Self {
        Dictionary { layers }
    }
    /// The layers, most specific first.
    pub fn layers(&self) -> &[std::sync::Arc<Profile>] {
        &self.layers
    }
    /// The entry at (index, sub) from the first layer that has it.
    pub fn object(&self, index: u16, sub: u8) -> Option<&ObjectInfo> {
        self.layers.iter().find_map(|p| p.object(index, sub))
    }
    /// The name of the object (index level, sub 0 when it has no own entry), for labels.
    pub fn name(&self, index: u16, sub: u8) -> Option<&str> {
        self.object(index, sub)
            .or_else(|| self.object(index, 0))
            .map(|o| o.name.as_str())
    }
    /// The most specific profile's name (e.g. "syntron-ds"), or "cia301".
    pub fn profile_name(&self) -> &str {
        self.layers.first().map(|p| p.name.as_str()).unwrap_or("cia301")
    }
    /// A vendor EMCY text for an exact code.
    pub fn emcy_text(&self, code: u16) -> Option<&str> {
        self.layers
            .iter()
            .find_map(|p| p.emcy_codes.get(&code))
            .map(String::as_str)
    }
}

/// Formats a decoded value for a label: enum text, scaled value with unit, or the raw value.
///
/// `0x0006` of a U16 with values {6: "Shutdown"} -> `6 (Shutdown)`;
/// `15000` of an I32 with scale 0.1 and unit "rpm" -> `1500 rpm`.
pub fn format_value(info: Option<&ObjectInfo>, value: &Value) -> String {
    let Some(info) = info else { return value.to_string() };
    if let Some((raw, text)) = value.as_i64().and_then(|raw| info.values.get(&raw).map(|t| (raw, t))) {
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

/// The EMCY manufacturer fields of an 8-byte frame through the first layout in `dict`.
pub fn emcy_fields(dict: &Dictionary, frame: &[u8; 8]) -> Vec<(String, String)> {
    let Some(layout) = dict.layers().iter().map(|p| &p.emcy_layout).find(|l| !l.is_empty()) else {
        return Vec::new();
    };
    layout
        .iter()
        .filter(|f| (3..8).contains(&f.offset) && f.len >= 1 && f.offset as usize + f.len as usize <= 8)
        .map(|f| {
            let bytes = &frame[f.offset as usize..f.offset as usize + f.len as usize];
            let raw = bytes.iter().rev().fold(0i64, |acc, b| (acc << 8) | *b as i64);
            let text = match f.values.get(&raw) {
                Some(t) => format!("0x{raw:02X} ({t})"),
                None => format!("0x{raw:02X}"),
            };
            (f.name.clone(), text)
        })
        .collect()
}
