//! PDO mappings: the mapped entries of one PDO and where the mapping came from.

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
