//! The decoder registry: every frame in, a kind, a node and a label out.
//!
//! One module per CANopen service. `registry` ties them together with the
//! per-bus state (learned COB-IDs, PDO mappings, SDO transfers).

/// The CANopen service a frame belongs to (the JSONL `kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    Nmt,
    Sync,
    Emcy,
    Time,
    Tpdo,
    Rpdo,
    /// Server to client (0x580 + node).
    SdoTx,
    /// Client to server (0x600 + node).
    SdoRx,
    /// NMT error control: heartbeat, boot-up, node guarding (0x700 + node).
    Heartbeat,
    Lss,
    ErrorFrame,
    Other,
}

impl Kind {
    /// The JSONL name of the kind.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Nmt => "nmt",
            Kind::Sync => "sync",
            Kind::Emcy => "emcy",
            Kind::Time => "time",
            Kind::Tpdo => "tpdo",
            Kind::Rpdo => "rpdo",
            Kind::SdoTx => "sdo_tx",
            Kind::SdoRx => "sdo_rx",
            Kind::Heartbeat => "heartbeat",
            Kind::Lss => "lss",
            Kind::ErrorFrame => "error_frame",
            Kind::Other => "other",
        }
    }
}

pub mod cia402;
pub mod cob_id;
pub mod comm_params;
pub mod emcy;
pub mod error_frame;
pub mod heartbeat;
pub mod lss;
pub mod nmt;
pub mod pdo;
pub mod registry;
pub mod sdo;
pub mod sync;
pub mod time;
pub mod value_text;

pub use registry::{Body, Decoded, Decoder};
