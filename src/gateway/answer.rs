//! The gateway's answers and notifications as text, in canopend's format: `[seq] OK`,
//! `[seq] VALUE`, `[seq] ERROR:0x06020000 #description` (an SDO abort code) and
//! `[seq] ERROR:101 #description` (a CiA 309-3 gateway code), each closed by CR LF; EMCY
//! and NMT state change notifications as the lines of canopend's message log. Pure: no IO.

use crate::decode::heartbeat::NmtState;

/// CiA 309-3 gateway error codes (the `ERROR:NNN` answers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Code {
    /// 100: the gateway does not do this (unknown command, or refused by configuration).
    NotSupported = 100,
    /// 101: the line is not a well-formed request.
    Syntax = 101,
    /// 102: the request cannot be processed in the gateway's current state.
    InternalState = 102,
    /// 103: no answer in time (LSS).
    TimeOut = 103,
    /// 105: no node given and none set with `set node`.
    NoDefaultNode = 105,
    /// 106: a network number out of range.
    UnsupportedNet = 106,
    /// 107: a node-ID out of range.
    UnsupportedNode = 107,
    /// 501: an LSS slave refused with a manufacturer-specific error.
    LssManufacturer = 501,
    /// 502: an LSS slave does not take that node-ID.
    LssNodeId = 502,
    /// 503: an LSS slave does not take that bit rate.
    LssBitRate = 503,
    /// 504: an LSS slave could not store its configuration.
    LssStore = 504,
}

impl Code {
    /// The number after `ERROR:`.
    pub fn number(self) -> u16 {
        self as u16
    }
    /// The description of the code (CiA 309-3's words).
    pub fn text(self) -> &'static str {
        match self {
            Code::NotSupported => "Request not supported.",
            Code::Syntax => "Syntax error.",
            Code::InternalState => "Request not processed due to internal state.",
            Code::TimeOut => "Time-out.",
            Code::NoDefaultNode => "No default node set.",
            Code::UnsupportedNet => "Unsupported net.",
            Code::UnsupportedNode => "Unsupported node.",
            Code::LssManufacturer => "LSS implementation- / manufacturer-specific error.",
            Code::LssNodeId => "LSS node-ID not supported.",
            Code::LssBitRate => "LSS bit-rate not supported.",
            Code::LssStore => "LSS parameter storing failed.",
        }
    }
}

/// `[seq] OK`.
pub fn ok(seq: u32) -> String {
    format!("[{seq}] OK\r\n")
}

/// `[seq] VALUE`.
pub fn value(seq: u32, value: &str) -> String {
    format!("[{seq}] {value}\r\n")
}

/// `[seq] ERROR:NNN #description`, with what went wrong after it when known.
pub fn error(seq: u32, code: Code, detail: &str) -> String {
    let detail = one_line(detail);
    if detail.is_empty() {
        format!("[{seq}] ERROR:{} #{}\r\n", code.number(), code.text())
    } else {
        format!("[{seq}] ERROR:{} #{} {detail}\r\n", code.number(), code.text())
    }
}

/// `[seq] ERROR:0x0602000 #description`: an SDO transfer ended with this abort code.
pub fn abort(seq: u32, code: u32) -> String {
    format!("[{seq}] ERROR:0x{code:08X} #{}.\r\n", crate::sdo::abort_text(code))
}

/// A multi-line text (help): lines separated by LF, closed by CR LF, no sequence number (as canopend).
pub fn text(lines: &str) -> String {
    format!("{}\r\n", lines.trim_end().replace("\r\n", "\n"))
}

/// The answer to an empty line or a line of comment only: an empty line.
pub fn empty() -> String {
    "\r\n".into()
}

/// `detail` on one line (a CR or LF would end the answer early).
fn one_line(detail: &str) -> String {
    detail.replace(['\r', '\n'], " ").trim().to_string()
}

/// canopend's number for an NMT state (`CO_NMT_internalState_t`): initializing 0,
/// stopped 4, operational 5, pre-operational 127; -1 unknown.
fn state_number(state: NmtState) -> i32 {
    match state {
        NmtState::BootUp => 0,
        NmtState::Stopped => 4,
        NmtState::Operational => 5,
        NmtState::PreOperational => 127,
        NmtState::Unknown(_) => -1,
    }
}

/// canopend's word for an NMT state.
fn state_word(state: NmtState) -> &'static str {
    match state {
        NmtState::BootUp => "initializing",
        NmtState::Stopped => "stopped",
        NmtState::Operational => "operational",
        NmtState::PreOperational => "pre-operational",
        NmtState::Unknown(_) => "unknown",
    }
}

/// A notification: `time` (`YYYY-MM-DD HH:MM:SS`), then canopend's log message, closed by CR LF.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Notice {
    /// An EMCY of `node`: error code, error register, the manufacturer byte 3 (canopend's
    /// "errorBit") and bytes 4..7 (its "infoCode", little-endian).
    Emcy {
        node: u8,
        code: u16,
        register: u8,
        bit: u8,
        info: u32,
    },
    /// `node`'s heartbeat (or boot-up) shows a new NMT state; `index` counts the nodes in the
    /// order the gateway first heard them (canopend: the node's entry in 0x1016).
    State { node: u8, index: usize, state: NmtState },
}

impl Notice {
    /// The notification's line, stamped with `time`.
    pub fn line(&self, time: &str) -> String {
        match *self {
            Notice::Emcy {
                node,
                code,
                register,
                bit,
                info,
            } => format!(
                "{time}: CANopen Emergency message from node 0x{node:02X}: errorCode=0x{code:04X}, \
                 errorRegister=0x{register:02X}, errorBit=0x{bit:02X}, infoCode=0x{info:08X}\r\n"
            ),
            Notice::State { node, index, state } => format!(
                "{time}: CANopen Remote node ID = 0x{node:02X} (index = {index}): NMT state changed to: \"{}\" ({})\r\n",
                state_word(state),
                state_number(state)
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_as_canopend_writes_them() {
        assert_eq!(ok(7), "[7] OK\r\n");
        assert_eq!(value(1, "500"), "[1] 500\r\n");
        assert_eq!(error(3, Code::Syntax, ""), "[3] ERROR:101 #Syntax error.\r\n");
        assert_eq!(
            error(3, Code::NotSupported, "a\nb"),
            "[3] ERROR:100 #Request not supported. a b\r\n"
        );
        assert!(abort(2, 0x0602_0000).starts_with("[2] ERROR:0x06020000 #Object does not exist"));
        let n = Notice::Emcy {
            node: 4,
            code: 0x8130,
            register: 0x11,
            bit: 0,
            info: 0x1234,
        };
        assert_eq!(
            n.line("2026-12-02 06:00:00"),
            "2026-12-02 06:00:00: CANopen Emergency message from node 0x04: errorCode=0x8130, errorRegister=0x11, errorBit=0x00, infoCode=0x00001234\r\n"
        );
        let s = Notice::State {
            node: 2,
            index: 0,
            state: NmtState::PreOperational,
        };
        assert_eq!(
            s.line("T"),
            "T: CANopen Remote node ID = 0x02 (index = 0): NMT state changed to: \"pre-operational\" (127)\r\n"
        );
    }
}
