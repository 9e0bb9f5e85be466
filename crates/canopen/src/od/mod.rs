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
mod dictionary;
pub mod eds;
pub mod expr;
pub mod family;
pub mod fields;
mod format;
mod index_set;
pub mod json;
mod mapping;
pub mod merge;
mod number;
mod object;
pub mod procedure;
mod profile;
mod resolve;
pub mod text;
mod value;

pub use alias::AliasRule;
pub use bind::Bindings;
pub use device::{Axis, IdCondition, IdTest, IndexRange, ObjectRange, PdoSet, PdoTemplate, TextMatch};
pub use dictionary::Dictionary;
pub use expr::Expr;
pub use family::SubFamily;
pub use fields::{ByteField, SdoCommand, SdoDirection};
pub use format::{emcy_fields, format_value, not_configuration};
pub use mapping::{MappedEntry, MappingSource, PdoMapping};
pub use number::format_number;
pub use object::{Access, Meaning, ObjectInfo, PdoMappable, Warning};
pub use procedure::{Procedure, Step};
pub use profile::Profile;
pub use resolve::resolve_object;
pub use value::{DataType, Value};
