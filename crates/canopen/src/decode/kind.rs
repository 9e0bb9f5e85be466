//! The CANopen service a frame belongs to, as the decoder names it.

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
    /// Every kind, in declaration order: `Kind::ALL[k.index()] == k`.
    pub const ALL: [Kind; 12] = [
        Kind::Nmt,
        Kind::Sync,
        Kind::Emcy,
        Kind::Time,
        Kind::Tpdo,
        Kind::Rpdo,
        Kind::SdoTx,
        Kind::SdoRx,
        Kind::Heartbeat,
        Kind::Lss,
        Kind::ErrorFrame,
        Kind::Other,
    ];

    /// Position of the kind in [`Kind::ALL`] (a dense index for counters and packed stores).
    pub fn index(self) -> usize {
        self as usize
    }

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

#[cfg(test)]
mod tests {
    use super::Kind;

    #[test]
    fn all_kinds_in_index_order() {
        for (i, k) in Kind::ALL.iter().enumerate() {
            assert_eq!(k.index(), i);
        }
    }
}
