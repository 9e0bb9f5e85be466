//! LSS (CiA 305, layer setting services): the master's requests and the slave's answers
//! as typed messages, encoded to and parsed from the 8 data bytes of 0x7E5 (master ->
//! slave) and 0x7E4 (slave -> master) frames. Pure: bytes in, values out.
//!
//! [`master`] runs one service as a state machine (time injected), [`fastscan`] finds
//! non-configured slaves bit by bit, [`slave`] is the slave side the simulator runs.
//! The passive decoder that labels LSS frames in a trace is [`crate::decode::lss`].

pub mod fastscan;
pub mod master;
pub mod slave;

/// COB-ID of frames from the LSS master.
pub const MASTER_ID: u32 = 0x7E5;
/// COB-ID of frames from LSS slaves.
pub const SLAVE_ID: u32 = 0x7E4;
/// The node-ID of a node that has none ("not configured").
pub const UNCONFIGURED: u8 = 0xFF;

/// One of the four parts of an LSS address (the identity object 0x1018 sub 1..4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Part {
    Vendor,
    Product,
    Revision,
    Serial,
}

impl Part {
    /// All parts in LSS order.
    pub const ALL: [Part; 4] = [Part::Vendor, Part::Product, Part::Revision, Part::Serial];

    /// Position in the LSS address (0..3), the fastscan `LSSsub`.
    pub fn index(self) -> u8 {
        self as u8
    }

    /// The part at LSS position `i` (0..3).
    pub fn from_index(i: u8) -> Option<Part> {
        Part::ALL.get(i as usize).copied()
    }

    /// Name as the CLI and JSON use it.
    pub fn name(self) -> &'static str {
        match self {
            Part::Vendor => "vendor",
            Part::Product => "product",
            Part::Revision => "revision",
            Part::Serial => "serial",
        }
    }
}

/// An LSS address: the 128-bit identity of a node.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Address {
    pub vendor: u32,
    pub product: u32,
    pub revision: u32,
    pub serial: u32,
}

impl Address {
    /// The value of one part.
    pub fn get(&self, p: Part) -> u32 {
        match p {
            Part::Vendor => self.vendor,
            Part::Product => self.product,
            Part::Revision => self.revision,
            Part::Serial => self.serial,
        }
    }

    /// Sets one part.
    pub fn set(&mut self, p: Part, v: u32) {
        match p {
            Part::Vendor => self.vendor = v,
            Part::Product => self.product = v,
            Part::Revision => self.revision = v,
            Part::Serial => self.serial = v,
        }
    }
}

impl std::fmt::Display for Address {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "vendor 0x{:08X} product 0x{:08X} revision 0x{:08X} serial 0x{:08X}",
            self.vendor, self.product, self.revision, self.serial
        )
    }
}

/// What a bit timing table index means (CiA 305 table 0).
pub fn bit_rate_text(table: u8, index: u8) -> Option<&'static str> {
    const RATES: [&str; 10] = [
        "1000 kbit/s",
        "800 kbit/s",
        "500 kbit/s",
        "250 kbit/s",
        "125 kbit/s",
        "reserved",
        "50 kbit/s",
        "20 kbit/s",
        "10 kbit/s",
        "auto",
    ];
    if table == 0 {
        RATES.get(index as usize).copied()
    } else {
        None
    }
}

/// The table-0 index of a bit rate in kbit/s (`250` -> 3).
pub fn bit_rate_index(kbit: u32) -> Option<u8> {
    Some(match kbit {
        1000 => 0,
        800 => 1,
        500 => 2,
        250 => 3,
        125 => 4,
        50 => 6,
        20 => 7,
        10 => 8,
        _ => return None,
    })
}

/// A request from the LSS master.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Request {
    /// Switch state global: `true` = configuration state, `false` = waiting.
    SwitchGlobal(bool),
    /// One of the four frames of switch state selective.
    SwitchSelective(Part, u32),
    ConfigureNodeId(u8),
    ConfigureBitTiming {
        table: u8,
        index: u8,
    },
    ActivateBitTiming {
        delay_ms: u16,
    },
    StoreConfiguration,
    Inquire(Part),
    InquireNodeId,
    /// Identify remote slave: one bound of the address range (the vendor and product
    /// are exact, revision and serial come as low/high pairs).
    IdentifyRemote(RangeBound, u32),
    IdentifyNonConfigured,
    Fastscan {
        id: u32,
        bit_check: u8,
        sub: u8,
        next: u8,
    },
}

/// Which value of an identify-remote-slave range a frame carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RangeBound {
    Vendor,
    Product,
    RevisionLow,
    RevisionHigh,
    SerialLow,
    SerialHigh,
}

impl RangeBound {
    const ALL: [(RangeBound, u8); 6] = [
        (RangeBound::Vendor, 0x46),
        (RangeBound::Product, 0x47),
        (RangeBound::RevisionLow, 0x48),
        (RangeBound::RevisionHigh, 0x49),
        (RangeBound::SerialLow, 0x4A),
        (RangeBound::SerialHigh, 0x4B),
    ];

    fn cs(self) -> u8 {
        RangeBound::ALL
            .iter()
            .find(|(b, _)| *b == self)
            .map_or(0x46, |(_, cs)| *cs)
    }

    fn from_cs(cs: u8) -> Option<RangeBound> {
        RangeBound::ALL.iter().find(|(_, c)| *c == cs).map(|(b, _)| *b)
    }
}

/// Bit-check value of a fastscan request that resets every slave's scan position.
pub(crate) const FASTSCAN_RESET: u8 = 0x80;

fn frame(cs: u8, args: &[u8]) -> [u8; 8] {
    let mut b = [0u8; 8];
    b[0] = cs;
    b[1..1 + args.len()].copy_from_slice(args);
    b
}

impl Request {
    /// The 8 data bytes of the request.
    pub fn encode(&self) -> [u8; 8] {
        match *self {
            Request::SwitchGlobal(config) => frame(0x04, &[config as u8]),
            Request::SwitchSelective(p, v) => frame(0x40 + p.index(), &v.to_le_bytes()),
            Request::ConfigureNodeId(n) => frame(0x11, &[n]),
            Request::ConfigureBitTiming { table, index } => frame(0x13, &[table, index]),
            Request::ActivateBitTiming { delay_ms } => frame(0x15, &delay_ms.to_le_bytes()),
            Request::StoreConfiguration => frame(0x17, &[]),
            Request::Inquire(p) => frame(0x5A + p.index(), &[]),
            Request::InquireNodeId => frame(0x5E, &[]),
            Request::IdentifyRemote(b, v) => frame(b.cs(), &v.to_le_bytes()),
            Request::IdentifyNonConfigured => frame(0x4C, &[]),
            Request::Fastscan {
                id,
                bit_check,
                sub,
                next,
            } => {
                let v = id.to_le_bytes();
                frame(0x51, &[v[0], v[1], v[2], v[3], bit_check, sub, next])
            }
        }
    }

    /// Parses a master frame's data bytes; `None` for a command specifier CiA 305 does
    /// not define for the master, or fewer than 8 bytes.
    pub fn parse(data: &[u8]) -> Option<Request> {
        let b: [u8; 8] = data.try_into().ok()?;
        let u32_at1 = u32::from_le_bytes([b[1], b[2], b[3], b[4]]);
        Some(match b[0] {
            0x04 => match b[1] {
                0 => Request::SwitchGlobal(false),
                1 => Request::SwitchGlobal(true),
                _ => return None,
            },
            cs @ 0x40..=0x43 => Request::SwitchSelective(Part::from_index(cs - 0x40)?, u32_at1),
            0x11 => Request::ConfigureNodeId(b[1]),
            0x13 => Request::ConfigureBitTiming {
                table: b[1],
                index: b[2],
            },
            0x15 => Request::ActivateBitTiming {
                delay_ms: u16::from_le_bytes([b[1], b[2]]),
            },
            0x17 => Request::StoreConfiguration,
            cs @ 0x46..=0x4B => Request::IdentifyRemote(RangeBound::from_cs(cs)?, u32_at1),
            0x4C => Request::IdentifyNonConfigured,
            0x51 => Request::Fastscan {
                id: u32_at1,
                bit_check: b[5],
                sub: b[6],
                next: b[7],
            },
            cs @ 0x5A..=0x5D => Request::Inquire(Part::from_index(cs - 0x5A)?),
            0x5E => Request::InquireNodeId,
            _ => return None,
        })
    }
}

/// An answer from an LSS slave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Response {
    SwitchSelective,
    /// Configure node-ID / bit timing / store configuration: error code (0 = success)
    /// and the manufacturer's code when the error code is 0xFF.
    Configured {
        cs: u8,
        error: u8,
        spec: u8,
    },
    Identity(Part, u32),
    NodeId(u8),
    IdentifySlave,
    IdentifyNonConfiguredSlave,
}

impl Response {
    /// The 8 data bytes of the answer.
    pub fn encode(&self) -> [u8; 8] {
        match *self {
            Response::SwitchSelective => frame(0x44, &[]),
            Response::Configured { cs, error, spec } => frame(cs, &[error, spec]),
            Response::Identity(p, v) => frame(0x5A + p.index(), &v.to_le_bytes()),
            Response::NodeId(n) => frame(0x5E, &[n]),
            Response::IdentifySlave => frame(0x4F, &[]),
            Response::IdentifyNonConfiguredSlave => frame(0x50, &[]),
        }
    }

    /// Parses a slave frame's data bytes.
    pub fn parse(data: &[u8]) -> Option<Response> {
        let b: [u8; 8] = data.try_into().ok()?;
        Some(match b[0] {
            0x44 => Response::SwitchSelective,
            cs @ (0x11 | 0x13 | 0x17) => Response::Configured {
                cs,
                error: b[1],
                spec: b[2],
            },
            cs @ 0x5A..=0x5D => Response::Identity(
                Part::from_index(cs - 0x5A)?,
                u32::from_le_bytes([b[1], b[2], b[3], b[4]]),
            ),
            0x5E => Response::NodeId(b[1]),
            0x4F => Response::IdentifySlave,
            0x50 => Response::IdentifyNonConfiguredSlave,
            _ => return None,
        })
    }
}

/// What a configure service's error code means (CiA 305 for each service).
pub(crate) fn configure_error_text(cs: u8, error: u8, spec: u8) -> String {
    match (cs, error) {
        (_, 0) => "success".into(),
        (0x11, 1) => "node-ID out of range (1..127 or 255)".into(),
        (0x13, 1) => "bit timing not supported".into(),
        (0x17, 1) => "store configuration not supported".into(),
        (0x17, 2) => "storage media access error".into(),
        (_, 0xFF) => format!("manufacturer-specific error 0x{spec:02X}"),
        (_, e) => format!("error {e} (reserved)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_encode_as_cia305_frames_and_parse_back() {
        let cases = [
            (Request::SwitchGlobal(true), [0x04, 1, 0, 0, 0, 0, 0, 0]),
            (
                Request::SwitchSelective(Part::Serial, 0x1234_5678),
                [0x43, 0x78, 0x56, 0x34, 0x12, 0, 0, 0],
            ),
            (Request::ConfigureNodeId(5), [0x11, 5, 0, 0, 0, 0, 0, 0]),
            (
                Request::ConfigureBitTiming { table: 0, index: 3 },
                [0x13, 0, 3, 0, 0, 0, 0, 0],
            ),
            (
                Request::ActivateBitTiming { delay_ms: 500 },
                [0x15, 0xF4, 0x01, 0, 0, 0, 0, 0],
            ),
            (Request::StoreConfiguration, [0x17, 0, 0, 0, 0, 0, 0, 0]),
            (Request::Inquire(Part::Product), [0x5B, 0, 0, 0, 0, 0, 0, 0]),
            (Request::InquireNodeId, [0x5E, 0, 0, 0, 0, 0, 0, 0]),
            (
                Request::IdentifyRemote(RangeBound::SerialHigh, 9),
                [0x4B, 9, 0, 0, 0, 0, 0, 0],
            ),
            (Request::IdentifyNonConfigured, [0x4C, 0, 0, 0, 0, 0, 0, 0]),
            (
                Request::Fastscan {
                    id: 0x8000_0000,
                    bit_check: 31,
                    sub: 2,
                    next: 3,
                },
                [0x51, 0, 0, 0, 0x80, 31, 2, 3],
            ),
        ];
        for (req, bytes) in cases {
            assert_eq!(req.encode(), bytes, "{req:?}");
            assert_eq!(Request::parse(&bytes), Some(req));
        }
        assert_eq!(Request::parse(&[0x04, 2, 0, 0, 0, 0, 0, 0]), None);
        assert_eq!(Request::parse(&[0x99, 0, 0, 0, 0, 0, 0, 0]), None);
        assert_eq!(Request::parse(&[0x04, 1]), None);
    }

    #[test]
    fn responses_parse_and_explain_errors() {
        assert_eq!(
            Response::parse(&[0x11, 1, 0, 0, 0, 0, 0, 0]),
            Some(Response::Configured {
                cs: 0x11,
                error: 1,
                spec: 0
            })
        );
        assert_eq!(configure_error_text(0x11, 1, 0), "node-ID out of range (1..127 or 255)");
        assert_eq!(
            configure_error_text(0x17, 0xFF, 0x21),
            "manufacturer-specific error 0x21"
        );
        assert_eq!(
            Response::parse(&Response::Identity(Part::Revision, 7).encode()),
            Some(Response::Identity(Part::Revision, 7))
        );
        assert_eq!(bit_rate_text(0, bit_rate_index(250).unwrap()), Some("250 kbit/s"));
    }
}
