//! SDO abort codes (CiA 301, table "SDO abort codes") and their texts.

/// Text used for codes CiA 301 does not define.
pub(crate) const UNKNOWN_ABORT_TEXT: &str = "unknown abort code";

/// Every abort code CiA 301 defines, with its text as the standard words it, grammar
/// included ("an hardware error"). The standard's trailing full stops are left out so
/// texts end cleanly in labels.
pub(crate) const ABORT_CODES: &[(u32, &str)] = &[
    (0x0503_0000, "Toggle bit not alternated"),
    (0x0504_0000, "SDO protocol timed out"),
    (0x0504_0001, "Client/server command specifier not valid or unknown"),
    (0x0504_0002, "Invalid block size (block mode only)"),
    (0x0504_0003, "Invalid sequence number (block mode only)"),
    (0x0504_0004, "CRC error (block mode only)"),
    (0x0504_0005, "Out of memory"),
    (0x0601_0000, "Unsupported access to an object"),
    (0x0601_0001, "Attempt to read a write only object"),
    (0x0601_0002, "Attempt to write a read only object"),
    (0x0602_0000, "Object does not exist in the object dictionary"),
    (0x0604_0041, "Object cannot be mapped to the PDO"),
    (
        0x0604_0042,
        "The number and length of the objects to be mapped would exceed PDO length",
    ),
    (0x0604_0043, "General parameter incompatibility reason"),
    (0x0604_0047, "General internal incompatibility in the device"),
    (0x0606_0000, "Access failed due to an hardware error"),
    (
        0x0607_0010,
        "Data type does not match, length of service parameter does not match",
    ),
    (
        0x0607_0012,
        "Data type does not match, length of service parameter too high",
    ),
    (
        0x0607_0013,
        "Data type does not match, length of service parameter too low",
    ),
    (0x0609_0011, "Sub-index does not exist"),
    (0x0609_0030, "Invalid value for parameter (download only)"),
    (0x0609_0031, "Value of parameter written too high (download only)"),
    (0x0609_0032, "Value of parameter written too low (download only)"),
    (0x0609_0036, "Maximum value is less than minimum value"),
    (0x060A_0023, "Resource not available: SDO connection"),
    (0x0800_0000, "General error"),
    (0x0800_0020, "Data cannot be transferred or stored to the application"),
    (
        0x0800_0021,
        "Data cannot be transferred or stored to the application because of local control",
    ),
    (
        0x0800_0022,
        "Data cannot be transferred or stored to the application because of the present device state",
    ),
    (
        0x0800_0023,
        "Object dictionary dynamic generation fails or no object dictionary is present \
         (e.g. object dictionary is generated from file and generation fails because of an file error)",
    ),
    (0x0800_0024, "No data available"),
];

/// The CiA 301 text of an abort code, or `None` for codes the standard does not define.
pub fn known_abort_text(code: u32) -> Option<&'static str> {
    ABORT_CODES.iter().find(|(c, _)| *c == code).map(|(_, t)| *t)
}

/// The CiA 301 text of an abort code, or [`UNKNOWN_ABORT_TEXT`].
pub fn abort_text(code: u32) -> &'static str {
    known_abort_text(code).unwrap_or(UNKNOWN_ABORT_TEXT)
}

/// What an abort code tells about the failure, for the words a diagnosis gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AbortClass {
    /// The transfer itself broke (CiA 301 0x0503xxxx toggle bit, 0x0504xxxx timeout,
    /// command specifier, block size, sequence number, CRC, memory): the protocol between
    /// client and server failed, whatever the object.
    Protocol,
    /// The object or sub-index is not on the device: [`NOT_PRESENT`].
    NotPresent,
    /// The server refused the access (rights, data type or length, value range, device
    /// state, hardware, ...): every other code.
    Refused,
}

/// Codes that say the device does not have the entry asked for: object does not exist
/// (0x06020000), sub-index does not exist (0x06090011), no data available (0x08000024,
/// e.g. an empty error-history entry). A read of such an entry answers "not present", it
/// is not a failure of the device.
pub const NOT_PRESENT: &[u32] = &[codes::NO_OBJECT, codes::NO_SUB, 0x0800_0024];

/// The class of an abort code.
pub fn abort_class(code: u32) -> AbortClass {
    match code >> 16 {
        0x0503 | 0x0504 => AbortClass::Protocol,
        _ if NOT_PRESENT.contains(&code) => AbortClass::NotPresent,
        _ => AbortClass::Refused,
    }
}

/// Named abort codes the client and server send.
pub mod codes {
    /// Toggle bit not alternated.
    pub const TOGGLE: u32 = 0x0503_0000;
    /// SDO protocol timed out.
    pub const TIMEOUT: u32 = 0x0504_0000;
    /// Client/server command specifier not valid or unknown.
    pub const UNKNOWN_COMMAND: u32 = 0x0504_0001;
    /// Invalid block size (block mode only).
    pub const BLOCK_SIZE: u32 = 0x0504_0002;
    /// Invalid sequence number (block mode only).
    pub const SEQUENCE: u32 = 0x0504_0003;
    /// CRC error (block mode only).
    pub const CRC: u32 = 0x0504_0004;
    /// Out of memory.
    pub const OUT_OF_MEMORY: u32 = 0x0504_0005;
    /// Attempt to read a write only object.
    pub const WRITE_ONLY: u32 = 0x0601_0001;
    /// Attempt to write a read only object.
    pub const READ_ONLY: u32 = 0x0601_0002;
    /// Object does not exist in the object dictionary.
    pub const NO_OBJECT: u32 = 0x0602_0000;
    /// Data type does not match, length of service parameter does not match.
    pub const LENGTH_MISMATCH: u32 = 0x0607_0010;
    /// Data type does not match, length of service parameter too high.
    pub const LENGTH_TOO_HIGH: u32 = 0x0607_0012;
    /// Data type does not match, length of service parameter too low.
    pub const LENGTH_TOO_LOW: u32 = 0x0607_0013;
    /// Sub-index does not exist.
    pub const NO_SUB: u32 = 0x0609_0011;
    /// General error.
    pub const GENERAL: u32 = 0x0800_0000;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texts_of_the_dexmart_table() {
        assert_eq!(abort_text(0x0503_0000), "Toggle bit not alternated");
        assert_eq!(abort_text(0x0504_0000), "SDO protocol timed out");
        assert_eq!(
            abort_text(0x0602_0000),
            "Object does not exist in the object dictionary"
        );
        assert_eq!(abort_text(0x0609_0011), "Sub-index does not exist");
        assert_eq!(abort_text(0x060A_0023), "Resource not available: SDO connection");
        assert_eq!(abort_text(0x0800_0024), "No data available");
        assert!(abort_text(0x0800_0023).starts_with("Object dictionary dynamic generation fails"));
        assert_eq!(abort_text(0x0606_0000), "Access failed due to an hardware error");
    }

    #[test]
    fn all_codes_defined_once() {
        assert_eq!(ABORT_CODES.len(), 31);
        for (i, (c, _)) in ABORT_CODES.iter().enumerate() {
            assert!(ABORT_CODES[i + 1..].iter().all(|(d, _)| d != c), "{c:#010X} twice");
        }
    }

    #[test]
    fn classes_of_abort_codes() {
        for c in [0x0503_0000, 0x0504_0000, 0x0504_0001, 0x0504_0004, 0x0504_0005] {
            assert_eq!(abort_class(c), AbortClass::Protocol, "{c:#010X}");
        }
        for c in [0x0602_0000, 0x0609_0011, 0x0800_0024] {
            assert_eq!(abort_class(c), AbortClass::NotPresent, "{c:#010X}");
        }
        for c in [0x0601_0002, 0x0607_0010, 0x0609_0030, 0x0800_0022, 0x1234_5678] {
            assert_eq!(abort_class(c), AbortClass::Refused, "{c:#010X}");
        }
    }

    #[test]
    fn unknown_codes() {
        assert_eq!(abort_text(0x1234_5678), "unknown abort code");
        assert_eq!(known_abort_text(0x0503_0004), None);
    }
}
