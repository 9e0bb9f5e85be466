//! The LSS slave side (what a simulated node answers): waiting / configuration state,
//! switch state selective, configure node-ID and bit timing, store, inquire, identify
//! remote slave, identify non-configured slave and fastscan. Pure: master frame data in,
//! the answer's data out.

use super::{Address, FASTSCAN_RESET, Part, RangeBound, Request, Response, UNCONFIGURED, bit_rate_text};

/// An LSS slave.
#[derive(Clone, Debug)]
pub struct Slave {
    address: Address,
    /// Node-ID in use (0xFF = none).
    active: u8,
    /// Node-ID configured, in use after the next NMT reset (communication).
    pending: u8,
    configuration: bool,
    /// Switch state selective: parts matched so far, in order.
    selected: u8,
    /// Identify remote slave: conditions met so far.
    identify: [bool; 6],
    /// Fastscan: the part being scanned.
    fastscan_pos: u8,
    /// Bit timing table index configured (table 0).
    pub bit_timing: Option<u8>,
    /// Times store configuration was asked for.
    pub stores: u32,
}

impl Slave {
    /// A slave with this address, using `node_id` (0xFF = not configured).
    pub fn new(address: Address, node_id: u8) -> Slave {
        Slave {
            address,
            active: node_id,
            pending: node_id,
            configuration: false,
            selected: 0,
            identify: [false; 6],
            fastscan_pos: 0,
            bit_timing: None,
            stores: 0,
        }
    }

    /// The node-ID configured by LSS (active after the next reset communication).
    pub fn pending_node_id(&self) -> u8 {
        self.pending
    }

    /// Makes the pending node-ID the active one (NMT reset node / communication).
    pub fn reset_communication(&mut self) -> u8 {
        self.active = self.pending;
        self.active
    }

    /// In LSS configuration state?
    pub fn in_configuration(&self) -> bool {
        self.configuration
    }

    fn unconfigured(&self) -> bool {
        self.active == UNCONFIGURED && self.pending == UNCONFIGURED
    }

    fn configured_reply(cs: u8, ok: bool) -> Option<[u8; 8]> {
        Some(
            Response::Configured {
                cs,
                error: if ok { 0 } else { 1 },
                spec: 0,
            }
            .encode(),
        )
    }

    /// Handles a master frame's data; the answer to send on 0x7E4, if any.
    pub fn on_request(&mut self, data: &[u8]) -> Option<[u8; 8]> {
        let req = Request::parse(data)?;
        if !matches!(req, Request::SwitchSelective(..)) {
            self.selected = 0;
        }
        match req {
            Request::SwitchGlobal(c) => {
                self.configuration = c;
                None
            }
            Request::SwitchSelective(p, v) => {
                let in_order = p.index() == self.selected && v == self.address.get(p);
                self.selected = if in_order { self.selected + 1 } else { 0 };
                if self.selected == 4 {
                    self.selected = 0;
                    self.configuration = true;
                    return Some(Response::SwitchSelective.encode());
                }
                None
            }
            _ if !self.configuration => self.in_waiting(req),
            Request::ConfigureNodeId(n) => {
                let ok = (1..=127).contains(&n) || n == UNCONFIGURED;
                if ok {
                    self.pending = n;
                }
                Self::configured_reply(0x11, ok)
            }
            Request::ConfigureBitTiming { table, index } => {
                let ok = bit_rate_text(table, index).is_some_and(|t| t != "reserved");
                if ok {
                    self.bit_timing = Some(index);
                }
                Self::configured_reply(0x13, ok)
            }
            Request::StoreConfiguration => {
                self.stores += 1;
                Self::configured_reply(0x17, true)
            }
            Request::Inquire(p) => Some(Response::Identity(p, self.address.get(p)).encode()),
            Request::InquireNodeId => Some(Response::NodeId(self.active).encode()),
            Request::ActivateBitTiming { .. } => None,
            other => self.in_waiting(other),
        }
    }

    /// Services answered in either state (identify, fastscan: waiting only).
    fn in_waiting(&mut self, req: Request) -> Option<[u8; 8]> {
        match req {
            Request::IdentifyRemote(bound, v) => {
                let a = &self.address;
                let (slot, met) = match bound {
                    RangeBound::Vendor => (0, v == a.vendor),
                    RangeBound::Product => (1, v == a.product),
                    RangeBound::RevisionLow => (2, a.revision >= v),
                    RangeBound::RevisionHigh => (3, a.revision <= v),
                    RangeBound::SerialLow => (4, a.serial >= v),
                    RangeBound::SerialHigh => (5, a.serial <= v),
                };
                self.identify[slot] = met;
                if slot == 5 {
                    let all = self.identify.iter().all(|m| *m);
                    self.identify = [false; 6];
                    return all.then(|| Response::IdentifySlave.encode());
                }
                None
            }
            Request::IdentifyNonConfigured => self
                .unconfigured()
                .then(|| Response::IdentifyNonConfiguredSlave.encode()),
            Request::Fastscan {
                id,
                bit_check,
                sub,
                next,
            } if !self.configuration && self.unconfigured() => self.fastscan(id, bit_check, sub, next),
            _ => None,
        }
    }

    fn fastscan(&mut self, id: u32, bit_check: u8, sub: u8, next: u8) -> Option<[u8; 8]> {
        if bit_check == FASTSCAN_RESET {
            self.fastscan_pos = 0;
            return Some(Response::IdentifySlave.encode());
        }
        let part = Part::from_index(sub)?;
        if bit_check > 31 || sub != self.fastscan_pos || (id ^ self.address.get(part)) >> bit_check != 0 {
            return None;
        }
        if bit_check == 0 {
            if next < sub {
                self.configuration = true;
            }
            self.fastscan_pos = next;
        }
        Some(Response::IdentifySlave.encode())
    }
}
