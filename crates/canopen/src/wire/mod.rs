//! The frame on the wire: a [`Frame`] rebuilt bit by bit as a CAN controller sends it
//! (ISO 11898-1), and its figures: bits from SOF to EOF, stuff bits, CRC, time on the bus.
//!
//! Classic data and remote frames (11- and 29-bit) are rebuilt exactly: SOF, identifier
//! (SRR and IDE for 29 bits), RTR, control (IDE/r0, or r1/r0, and the DLC), data, CRC-15,
//! CRC delimiter, ACK slot and delimiter, EOF; a stuff bit of the other level after every 5
//! equal bits from SOF to the end of the CRC sequence.
//!
//! CAN FD frames follow ISO 11898-1:2015: RRS, FDF, res, BRS and ESI in the control field;
//! dynamic stuff bits from SOF to the end of the data field (the CRC covers them); then the
//! stuff count (the dynamic stuff bits modulo 8, Gray coded, and an even parity bit) and
//! the CRC-17 (up to 16 data bytes) or CRC-21, with a fixed stuff bit of the other level
//! before the stuff count and after every 4 bits of it and of the CRC. When the dynamic
//! part ends with 5 equal bits, the fixed stuff bit before the stuff count is their only
//! stuff bit: no dynamic one goes out there, and the stuff count does not count one (as
//! the ISO 16845 conformance model of CTU CAN FD does). Every bit is counted
//! at the nominal rate (the faster data phase of a BRS frame is not known to a trace).
//!
//! [`figures`] is the cheap path for bus load (table-driven CRC and stuffing for classic
//! frames, no allocation); [`rebuild`] lists every bit with its field for display.

pub mod cache;
mod tables;

use crate::frame::{Flags, Frame};
use std::fmt;
use tables::{crc_bit, crc15_byte, stuff_byte, stuff_step};

/// The bits between two frames (recessive), not part of either: [`Figures::bits`] leaves
/// them out, bus load counts them.
pub const INTERMISSION: u32 = 3;

/// The fields of a frame on the wire, in the order they are sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Field {
    /// Start of frame (dominant).
    Sof,
    /// The 11-bit identifier, or the 11 high bits of a 29-bit one.
    Id,
    /// Substitute remote request (29-bit frames; recessive).
    Srr,
    /// Identifier extension flag (recessive for 29 bits).
    Ide,
    /// The 18 low bits of a 29-bit identifier.
    IdExt,
    /// Remote transmission request (classic; recessive for a remote frame).
    Rtr,
    /// Remote request substitution (CAN FD; dominant).
    Rrs,
    /// Reserved bit r1 of a classic 29-bit frame (dominant).
    R1,
    /// Reserved bit r0 of a classic frame (dominant).
    R0,
    /// FD format flag (recessive in a CAN FD frame).
    Fdf,
    /// Reserved bit of a CAN FD frame (dominant).
    Res,
    /// Bit rate switch (CAN FD).
    Brs,
    /// Error state indicator (CAN FD).
    Esi,
    /// Data length code.
    Dlc,
    /// The data field.
    Data,
    /// CAN FD stuff count: dynamic stuff bits modulo 8 (Gray code) and parity.
    StuffCount,
    /// The CRC sequence.
    Crc,
    /// CRC delimiter (recessive).
    CrcDelim,
    /// ACK slot: sent recessive, made dominant by the receivers that acknowledge.
    AckSlot,
    /// ACK delimiter (recessive).
    AckDelim,
    /// End of frame: 7 recessive bits.
    Eof,
}

impl Field {
    /// Short name as documents print it (`SOF`, `ID`, `DLC`, `CRC`...).
    pub fn as_str(self) -> &'static str {
        match self {
            Field::Sof => "SOF",
            Field::Id => "ID",
            Field::Srr => "SRR",
            Field::Ide => "IDE",
            Field::IdExt => "ID-ext",
            Field::Rtr => "RTR",
            Field::Rrs => "RRS",
            Field::R1 => "r1",
            Field::R0 => "r0",
            Field::Fdf => "FDF",
            Field::Res => "res",
            Field::Brs => "BRS",
            Field::Esi => "ESI",
            Field::Dlc => "DLC",
            Field::Data => "data",
            Field::StuffCount => "stuff count",
            Field::Crc => "CRC",
            Field::CrcDelim => "CRC delimiter",
            Field::AckSlot => "ACK slot",
            Field::AckDelim => "ACK delimiter",
            Field::Eof => "EOF",
        }
    }
}

/// One bit on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bit {
    /// Its level: true is recessive (1), false dominant (0).
    pub level: bool,
    /// The field it belongs to (a dynamic stuff bit: the field of the bit before it; a
    /// CAN FD fixed stuff bit: the field of the bit after it).
    pub field: Field,
    /// A stuff bit (dynamic, or a CAN FD fixed one), not a bit of the field's value.
    pub stuff: bool,
}

/// A frame's [`Figures`], or why it has none (what the bus-load counters take).
pub type WireFigures = Result<Figures, WireError>;

/// The figures of a frame on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Figures {
    /// Bits from SOF to the end of EOF, stuff bits included, the intermission not.
    pub bits: u32,
    /// Stuff bits among them (CAN FD: dynamic and fixed).
    pub stuff_bits: u32,
    /// The CRC sequence.
    pub crc: u32,
    /// Its width: 15 (classic), 17 or 21 (CAN FD).
    pub crc_bits: u8,
}

impl Figures {
    /// The frame's bits on the bus with the intermission after it: what bus load counts.
    pub fn bus_bits(&self) -> u32 {
        self.bits + INTERMISSION
    }
    /// Microseconds from SOF to the end of EOF at `bitrate` bit/s (all at that rate).
    pub fn time_us(&self, bitrate: u64) -> f64 {
        f64::from(self.bits) * 1e6 / bitrate.max(1) as f64
    }
}

/// Why a frame cannot be put on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireError {
    /// A SocketCAN error frame: a report of the controller, not a frame on the wire.
    ErrorFrame,
    /// The identifier does not fit its format.
    IdRange {
        /// The identifier.
        id: u32,
        /// 29-bit format.
        ext: bool,
    },
    /// A classic frame with more than 8 data bytes.
    ClassicLength(u8),
    /// A CAN FD frame whose length no DLC gives (0..8, 12, 16, 20, 24, 32, 48, 64).
    FdLength(u8),
    /// CAN FD has no remote frames.
    FdRemote,
}

impl fmt::Display for WireError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            WireError::ErrorFrame => {
                write!(
                    f,
                    "an error frame is a report of the controller, not a frame on the wire"
                )
            }
            WireError::IdRange { id, ext: false } => {
                write!(f, "identifier 0x{id:X} does not fit 11 bits (at most 0x7FF)")
            }
            WireError::IdRange { id, ext: true } => {
                write!(f, "identifier 0x{id:X} does not fit 29 bits (at most 0x1FFFFFFF)")
            }
            WireError::ClassicLength(n) => write!(f, "a classic CAN frame carries at most 8 bytes, not {n}"),
            WireError::FdLength(n) => write!(
                f,
                "no CAN FD DLC gives {n} bytes (0 to 8, 12, 16, 20, 24, 32, 48 or 64)"
            ),
            WireError::FdRemote => write!(f, "CAN FD has no remote frames"),
        }
    }
}

impl std::error::Error for WireError {}

/// Bits before stuffing, MSB first (a frame up to its CRC: at most 41 + 512 + 21).
#[derive(Clone, Copy)]
struct BitBuf {
    bytes: [u8; 80],
    len: usize,
}

impl BitBuf {
    fn new() -> BitBuf {
        BitBuf { bytes: [0; 80], len: 0 }
    }
    /// Appends the `n` low bits of `value`, MSB first.
    fn push(&mut self, value: u32, n: u32) {
        for k in (0..n).rev() {
            if (value >> k) & 1 == 1 {
                self.bytes[self.len / 8] |= 0x80 >> (self.len % 8);
            }
            self.len += 1;
        }
    }
    /// Appends whole bytes (the data field).
    fn push_bytes(&mut self, data: &[u8]) {
        if self.len.is_multiple_of(8) {
            self.bytes[self.len / 8..self.len / 8 + data.len()].copy_from_slice(data);
            self.len += 8 * data.len();
        } else {
            for &b in data {
                self.push(u32::from(b), 8);
            }
        }
    }
    fn get(&self, i: usize) -> bool {
        self.bytes[i / 8] & (0x80 >> (i % 8)) != 0
    }
}

/// The frame before stuffing up to the end of its data field, and where each field ends.
struct Layout {
    bits: BitBuf,
    /// (field, index of the bit after it), in order.
    ends: [(Field, u16); 14],
    fields: usize,
    fd: bool,
    /// Data bytes (the CAN FD CRC is 17 bits up to 16, else 21).
    len: usize,
}

impl Layout {
    fn of(frame: &Frame) -> Result<Layout, WireError> {
        let flags = frame.flags;
        if flags.has(Flags::ERR) {
            return Err(WireError::ErrorFrame);
        }
        let (ext, fd, rtr) = (frame.is_ext(), frame.is_fd(), frame.is_rtr());
        let max_id = if ext { 0x1FFF_FFFF } else { 0x7FF };
        if frame.id > max_id {
            return Err(WireError::IdRange { id: frame.id, ext });
        }
        let dlc = if fd {
            if rtr {
                return Err(WireError::FdRemote);
            }
            crate::frame::fd_dlc_exact(frame.len).ok_or(WireError::FdLength(frame.len))?
        } else if frame.len > 8 {
            return Err(WireError::ClassicLength(frame.len));
        } else if frame.len == 8 && (9..=15).contains(&frame.raw_dlc) {
            frame.raw_dlc
        } else {
            frame.len
        };
        let mut l = Layout {
            bits: BitBuf::new(),
            ends: [(Field::Sof, 0); 14],
            fields: 0,
            fd,
            len: frame.payload().len(),
        };
        l.field(Field::Sof, 0, 1);
        if ext {
            l.field(Field::Id, frame.id >> 18, 11);
            l.field(Field::Srr, 1, 1);
            l.field(Field::Ide, 1, 1);
            l.field(Field::IdExt, frame.id & 0x3FFFF, 18);
        } else {
            l.field(Field::Id, frame.id, 11);
        }
        if fd {
            l.field(Field::Rrs, 0, 1);
            if !ext {
                l.field(Field::Ide, 0, 1);
            }
            l.field(Field::Fdf, 1, 1);
            l.field(Field::Res, 0, 1);
            l.field(Field::Brs, u32::from(flags.has(Flags::BRS)), 1);
            l.field(Field::Esi, u32::from(flags.has(Flags::ESI)), 1);
        } else {
            l.field(Field::Rtr, u32::from(rtr), 1);
            if ext {
                l.field(Field::R1, 0, 1);
            } else {
                l.field(Field::Ide, 0, 1);
            }
            l.field(Field::R0, 0, 1);
        }
        l.field(Field::Dlc, u32::from(dlc), 4);
        let payload = frame.payload();
        if !payload.is_empty() {
            l.bits.push_bytes(payload);
            l.mark(Field::Data);
        }
        Ok(l)
    }

    fn field(&mut self, field: Field, value: u32, n: u32) {
        self.bits.push(value, n);
        self.mark(field);
    }

    fn mark(&mut self, field: Field) {
        self.ends[self.fields] = (field, self.bits.len as u16);
        self.fields += 1;
    }

    fn ends(&self) -> &[(Field, u16)] {
        &self.ends[..self.fields]
    }
}

/// The figures of `frame` on the wire, without listing its bits (no allocation). Classic
/// frames go a whole byte at a time through the CRC and stuffing tables: the fields from
/// SOF to the DLC end where the data bytes start, so the frame up to its CRC is whole bytes
/// once a few bits go before SOF (see [`classic_head`]).
pub fn figures(frame: &Frame) -> WireFigures {
    if frame.is_fd() || frame.is_err() || frame.len > 8 {
        let layout = Layout::of(frame)?;
        return Ok(walk(&layout, &mut |_| {}));
    }
    let ext = frame.is_ext();
    if frame.id > if ext { 0x1FFF_FFFF } else { 0x7FF } {
        return Err(WireError::IdRange { id: frame.id, ext });
    }
    let (head, padded, head_bytes) = classic_head(frame, ext);
    let (mut crc, mut state, mut stuffs) = (0, tables::STUFF_START, 0);
    for k in (0..head_bytes).rev() {
        crc = crc15_byte(crc, (head >> (8 * k)) as u8);
        let s;
        (state, s) = stuff_byte(state, (padded >> (8 * k)) as u8);
        stuffs += s;
    }
    let payload = frame.payload();
    for &b in payload {
        crc = crc15_byte(crc, b);
        let s;
        (state, s) = stuff_byte(state, b);
        stuffs += s;
    }
    // The CRC, then one bit of the other level than its last: that bit stuffs nothing
    // (after a stuff bit it makes a run of 2) and makes the CRC two whole bytes.
    let tail = (crc << 1) | (!crc & 1);
    let (state, s) = stuff_byte(state, (tail >> 8) as u8);
    let (_, s2) = stuff_byte(state, tail as u8);
    let stuffs = stuffs + s + s2;
    let unstuffed = if ext { 39 } else { 19 } + 8 * payload.len() as u32 + 15;
    Ok(Figures {
        bits: unstuffed + stuffs + TAIL,
        stuff_bits: stuffs,
        crc,
        crc_bits: 15,
    })
}

/// SOF, identifier, [SRR, IDE, extension], RTR, IDE or r1, r0 and DLC of a classic frame
/// (19 or 39 bits) in the low bits of whole bytes: (for the CRC, zeros above them: zeros
/// before SOF leave a CRC register at 0 unchanged; for stuffing, alternating bits ending
/// recessive above them: they stuff nothing and end on the level before SOF; the bytes).
fn classic_head(frame: &Frame, ext: bool) -> (u64, u64, u32) {
    let rtr = u64::from(frame.is_rtr());
    let dlc = u64::from(if frame.len == 8 && (9..=15).contains(&frame.raw_dlc) {
        frame.raw_dlc
    } else {
        frame.len
    });
    let id = u64::from(frame.id);
    if ext {
        let head = (id >> 18) << 27 | 0b11 << 25 | (id & 0x3FFFF) << 7 | rtr << 6 | dlc;
        (head, head | 1 << 39, 5)
    } else {
        let head = id << 7 | rtr << 6 | dlc;
        (head, head | 0b10101 << 19, 3)
    }
}

/// A frame on the wire: every bit from SOF to EOF, and the figures.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Wire {
    /// The bits in the order they are sent.
    pub bits: Vec<Bit>,
    /// Its figures (those of [`figures`]).
    pub figures: Figures,
}

/// `frame` rebuilt as a controller sends it: every bit with its field, stuff bits marked.
pub fn rebuild(frame: &Frame) -> Result<Wire, WireError> {
    let layout = Layout::of(frame)?;
    let mut bits = Vec::with_capacity(160);
    let figures = walk(&layout, &mut |b| bits.push(b));
    Ok(Wire { bits, figures })
}

/// CRC delimiter, ACK slot, ACK delimiter and EOF: never stuffed.
const TAIL: u32 = 3 + 7;

/// Sends `layout` bit by bit to `out` (stuff bits included) and gives the figures.
fn walk(layout: &Layout, out: &mut dyn FnMut(Bit)) -> Figures {
    let (crc_bits, init, poly) = match (layout.fd, layout.len > 16) {
        (false, _) => (15u32, 0, tables::CRC15_POLY),
        (true, false) => (17, 1 << 16, 0x1_685B),
        (true, true) => (21, 1 << 20, 0x10_2899),
    };
    // The field of bit i, from the ends of the fields.
    let ends = layout.ends();
    let mut at = 0;
    let mut field_of = |i: usize| {
        while at + 1 < ends.len() && usize::from(ends[at].1) <= i {
            at += 1;
        }
        ends[at].0
    };
    let mut sent = 0u32;
    let mut stuffs = 0u32;
    let mut emit = |level: bool, field: Field, stuff: bool| {
        out(Bit { level, field, stuff });
        sent += 1;
    };
    let mut state = tables::STUFF_START;
    let mut crc = init;
    let mut last = false;
    // Classic: the CRC covers the unstuffed bits; FD: the bits as sent, stuff bits too.
    for i in 0..layout.bits.len {
        let (level, field) = (layout.bits.get(i), field_of(i));
        emit(level, field, false);
        last = level;
        crc = crc_bit(crc, level, crc_bits, poly);
        let (next, stuffed) = stuff_step(state, level);
        state = next;
        // CAN FD: 5 equal bits that end the dynamic part take no dynamic stuff bit (nor
        // count one): the fixed stuff bit before the stuff count is their stuff bit.
        if stuffed && !(layout.fd && i + 1 == layout.bits.len) {
            emit(!level, field, true);
            last = !level;
            stuffs += 1;
            if layout.fd {
                crc = crc_bit(crc, !level, crc_bits, poly);
            }
        }
    }
    if layout.fd {
        let count = stuffs % 8;
        let gray = count ^ (count >> 1);
        let parity = gray.count_ones() & 1;
        let sc = (gray << 1) | parity;
        for k in (0..4).rev() {
            crc = crc_bit(crc, (sc >> k) & 1 == 1, crc_bits, poly);
        }
        // Stuff count then CRC, a fixed stuff bit before and after every 4 bits.
        let fields = (0..4)
            .rev()
            .map(|k| ((sc >> k) & 1 == 1, Field::StuffCount))
            .chain((0..crc_bits).rev().map(|k| ((crc >> k) & 1 == 1, Field::Crc)));
        for (n, (level, field)) in fields.enumerate() {
            if n % 4 == 0 {
                emit(!last, field, true);
                stuffs += 1;
            }
            emit(level, field, false);
            last = level;
        }
    } else {
        for k in (0..15).rev() {
            let level = (crc >> k) & 1 == 1;
            emit(level, Field::Crc, false);
            let (next, stuffed) = stuff_step(state, level);
            state = next;
            if stuffed {
                emit(!level, Field::Crc, true);
                stuffs += 1;
            }
        }
    }
    for (field, n) in [
        (Field::CrcDelim, 1),
        (Field::AckSlot, 1),
        (Field::AckDelim, 1),
        (Field::Eof, 7),
    ] {
        for _ in 0..n {
            emit(true, field, false);
        }
    }
    Figures {
        bits: sent,
        stuff_bits: stuffs,
        crc,
        crc_bits: crc_bits as u8,
    }
}

#[cfg(test)]
mod tests;
