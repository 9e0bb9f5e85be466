//! The decoder registry: every frame in, a kind, a node and a label out.
//!
//! One module per CANopen service. `registry` ties them together with the
//! per-bus state (learned COB-IDs, PDO mappings, SDO transfers).

pub mod cia402;
pub mod cob_id;
pub mod comm_params;
pub mod emcy;
pub mod error_frame;
pub mod heartbeat;
mod kind;
pub mod lss;
pub mod nmt;
pub mod pdo;
pub mod pdo_config;
pub mod registry;
pub mod sdo;
pub mod stall;
pub mod sync;
pub mod time;
pub mod value_text;
pub mod vendor_sdo;

pub use kind::Kind;
pub use registry::{Body, Decoded, Decoder};
