//! The frame model shared by every source, decoder and pane.
//!
//! A [`Frame`] is one CAN or CAN FD frame as seen on one interface at one
//! instant. It is a plain `Copy` value with no heap data so that parsers and
//! decoders never allocate per frame; the trace store packs it further.

use std::collections::HashMap;

pub mod hex;
pub mod json;
pub mod linux;

/// Flag bits of a [`Frame`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Flags(pub u8);

impl Flags {
    /// 29-bit identifier.
    pub const EXT: u8 = 1 << 0;
    /// Remote transmission request (classic CAN only).
    pub const RTR: u8 = 1 << 1;
    /// CAN FD frame.
    pub const FD: u8 = 1 << 2;
    /// Error frame (`id` holds the CAN_ERR class bits, `data` the details).
    pub const ERR: u8 = 1 << 3;
    /// CAN FD bit rate switch.
    pub const BRS: u8 = 1 << 4;
    /// CAN FD error state indicator.
    pub const ESI: u8 = 1 << 5;
    /// Sent by this program (candump's `T`), not received from another node.
    pub const TX: u8 = 1 << 6;
    /// FD "FDF" flag as written by candump (`##4x`); kept for round trips.
    pub const FDF: u8 = 1 << 7;

    /// True when every bit of `mask` is set.
    pub fn has(self, mask: u8) -> bool {
        self.0 & mask == mask
    }
    /// Sets or clears the bits of `mask`.
    pub fn set(&mut self, mask: u8, on: bool) {
        if on { self.0 |= mask } else { self.0 &= !mask }
    }
}

/// Direction of a frame relative to this program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Received from the bus.
    Rx,
    /// Transmitted by us.
    Tx,
}

/// Bytes of a CAN FD frame with each DLC (0..15).
pub(crate) const FD_LENS: [u8; 16] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64];

/// The DLC of a CAN FD frame of `len` bytes, rounded up to the next length a DLC gives.
pub(crate) fn fd_dlc_at_least(len: u8) -> u8 {
    FD_LENS.iter().position(|&n| n >= len).unwrap_or(15) as u8
}

/// The DLC of a CAN FD payload of exactly `len` bytes (`None`: no DLC gives it).
pub(crate) fn fd_dlc_exact(len: u8) -> Option<u8> {
    FD_LENS.iter().position(|&n| n == len).map(|d| d as u8)
}

/// One CAN / CAN FD / error frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Timestamp in nanoseconds (since the Unix epoch for live and absolute
    /// logs, since the start for zero-based logs).
    pub ts_ns: u64,
    /// Identifier without flag bits (11 or 29 bits; error class for error frames).
    pub id: u32,
    /// See [`Flags`].
    pub flags: Flags,
    /// Payload length in bytes (0..=8 classic, 0..=64 FD). For an RTR frame
    /// this is the requested length.
    pub len: u8,
    /// Raw DLC 9..=15 of a classic frame with `len == 8`, else 0.
    pub raw_dlc: u8,
    /// Index into the source's [`Interfaces`] table.
    pub iface: u16,
    /// Payload; bytes past `len` are zero.
    pub data: [u8; 64],
}

impl Default for Frame {
    fn default() -> Self {
        Frame {
            ts_ns: 0,
            id: 0,
            flags: Flags::default(),
            len: 0,
            raw_dlc: 0,
            iface: 0,
            data: [0; 64],
        }
    }
}

impl Frame {
    /// A received classic data frame with an 11-bit id (handy in tests and the simulator).
    pub fn classic(id: u32, bytes: &[u8]) -> Frame {
        let mut f = Frame { id, ..Frame::default() };
        let n = bytes.len().min(8);
        f.len = n as u8;
        f.data[..n].copy_from_slice(&bytes[..n]);
        if id > 0x7FF {
            f.flags.set(Flags::EXT, true);
        }
        f
    }
    /// The payload bytes (empty for RTR frames).
    pub fn payload(&self) -> &[u8] {
        if self.is_rtr() {
            &[]
        } else {
            &self.data[..self.len as usize]
        }
    }
    /// 29-bit identifier?
    pub fn is_ext(&self) -> bool {
        self.flags.has(Flags::EXT)
    }
    /// Remote request?
    pub fn is_rtr(&self) -> bool {
        self.flags.has(Flags::RTR)
    }
    /// CAN FD?
    pub fn is_fd(&self) -> bool {
        self.flags.has(Flags::FD)
    }
    /// Error frame?
    pub fn is_err(&self) -> bool {
        self.flags.has(Flags::ERR)
    }
    /// Sent by us?
    pub fn direction(&self) -> Direction {
        if self.flags.has(Flags::TX) {
            Direction::Tx
        } else {
            Direction::Rx
        }
    }
    /// Timestamp in seconds.
    pub fn seconds(&self) -> f64 {
        self.ts_ns as f64 / 1e9
    }
}

/// A node as every derived view knows it: a node-ID on one interface. Two buses may each
/// have a node 5; they are two nodes. Ordered by interface, then node-ID, so a capture of
/// one interface keeps node-ID order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeKey {
    /// Index into the source's [`Interfaces`] table (as [`Frame::iface`]).
    pub iface: u16,
    /// The CANopen node-ID (0 for frames of no node).
    pub node: u8,
}

impl NodeKey {
    /// Node `node` on interface `iface`.
    pub const fn new(iface: u16, node: u8) -> NodeKey {
        NodeKey { iface, node }
    }
    /// Node `node` on the interface `frame` came from.
    pub const fn of(frame: &Frame, node: u8) -> NodeKey {
        NodeKey {
            iface: frame.iface,
            node,
        }
    }
}

/// Interned interface names: frames carry a `u16` index instead of a string.
/// Lookups go through a hash index, so a log with tens of thousands of names stays linear.
#[derive(Clone, Debug, Default)]
pub struct Interfaces {
    names: Vec<String>,
    index: HashMap<String, u16>,
}

impl Interfaces {
    /// The index of `name`, adding it on first sight.
    pub fn intern(&mut self, name: &str) -> u16 {
        match self.find(name) {
            Some(i) => i,
            None => self.add(name),
        }
    }
    /// Adds `name`, known not to be interned yet (one hash lookup less than [`Interfaces::intern`]).
    pub(crate) fn add(&mut self, name: &str) -> u16 {
        let i = self.names.len() as u16;
        self.names.push(name.to_string());
        self.index.insert(name.to_string(), i);
        i
    }
    /// The index of `name` if it was interned.
    pub fn find(&self, name: &str) -> Option<u16> {
        self.index.get(name).copied()
    }
    /// The name behind an index (`"?"` when unknown).
    pub fn name(&self, idx: u16) -> &str {
        self.names.get(idx as usize).map(String::as_str).unwrap_or("?")
    }
    /// All names, in index order.
    pub fn names(&self) -> &[String] {
        &self.names
    }
}
