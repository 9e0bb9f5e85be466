//! One object dictionary entry and what is known of it: access, PDO mappability, a vendor
//! object's CiA 301 meaning, and the warnings a load gives.

use std::collections::BTreeMap;

use super::fields::ByteField;
use super::value::{DataType, Value};

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
    pub fields: Vec<ByteField>,
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
