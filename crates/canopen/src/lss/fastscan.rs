//! LSS Fastscan (CiA 305): finds the LSS address of one non-configured slave bit by bit
//! and leaves that slave in configuration state, so its node-ID can be set. A pure state
//! machine like [`super::master::Exchange`]: every request waits its whole timeout and
//! counts as matched when any slave answered "identify slave" meanwhile (several slaves
//! answer the first requests, so moving on at the first answer would take a late second
//! one for the answer to the next request).
//! Parts already known (e.g. the vendor-ID) are confirmed in one request instead of 32.

use super::master::Step;
use super::{Address, FASTSCAN_RESET, Part, Request, Response};

/// Why a fastscan ended without an address.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FastscanError {
    #[error(
        "fastscan: the slave stopped answering while confirming its {0} (another master on the bus, or the timeout too short?)"
    )]
    Lost(&'static str),
}

/// A running fastscan.
#[derive(Clone, Debug)]
pub struct Fastscan {
    known: [Option<u32>; 4],
    address: Address,
    /// Part being scanned (0..3).
    sub: u8,
    /// Bit being checked: 0x80 = the reset request, 0..31 = that bit, `None` = confirming.
    bit: Option<u8>,
    /// The current request had an answer.
    answered: bool,
    deadline_ns: u64,
    timeout_ns: u64,
    requests: usize,
}

/// How a fastscan ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Found {
    /// No non-configured slave answered.
    Nobody,
    /// This slave is now in configuration state.
    Slave(Address),
}

impl Fastscan {
    /// Starts at `now_ns`; `known` parts (vendor, product, revision, serial) are not scanned.
    pub fn start(known: [Option<u32>; 4], now_ns: u64, timeout_ns: u64) -> (Fastscan, Vec<[u8; 8]>) {
        let mut f = Fastscan {
            known,
            address: Address::default(),
            sub: 0,
            bit: Some(FASTSCAN_RESET),
            answered: false,
            deadline_ns: 0,
            timeout_ns,
            requests: 0,
        };
        let first = f.request(now_ns);
        (f, vec![first])
    }

    /// Requests sent so far.
    pub fn requests(&self) -> usize {
        self.requests
    }

    /// The deadline of the current request (ns).
    pub fn deadline_ns(&self) -> u64 {
        self.deadline_ns
    }

    fn part(&self) -> Part {
        Part::from_index(self.sub).unwrap_or(Part::Serial)
    }

    fn request(&mut self, now_ns: u64) -> [u8; 8] {
        self.answered = false;
        self.deadline_ns = now_ns.saturating_add(self.timeout_ns);
        self.requests += 1;
        let id = self.address.get(self.part());
        let (bit_check, next) = match self.bit {
            Some(b) if b == FASTSCAN_RESET => (b, 0),
            Some(b) => (b, self.sub),
            None => (0, (self.sub + 1) % 4),
        };
        Request::Fastscan {
            id,
            bit_check,
            sub: self.sub,
            next,
        }
        .encode()
    }

    /// A frame from an LSS slave.
    pub fn on_frame(&mut self, data: &[u8]) {
        if Response::parse(data) == Some(Response::IdentifySlave) {
            self.answered = true;
        }
    }

    /// Time passed: at the deadline the current request is judged and the next one sent.
    pub fn on_time(&mut self, now_ns: u64) -> Result<Step<Found>, FastscanError> {
        if now_ns < self.deadline_ns {
            return Ok(Step::wait());
        }
        self.advance(self.answered, now_ns)
    }

    fn advance(&mut self, answer: bool, now_ns: u64) -> Result<Step<Found>, FastscanError> {
        match self.bit {
            Some(FASTSCAN_RESET) if !answer => return Ok(Step::done(Found::Nobody)),
            Some(FASTSCAN_RESET) => self.begin_part(),
            Some(b) => {
                if !answer {
                    let part = self.part();
                    self.address.set(part, self.address.get(part) | 1 << b);
                }
                self.bit = b.checked_sub(1);
            }
            None if !answer => return Err(FastscanError::Lost(self.part().name())),
            None => {
                if self.sub == 3 {
                    return Ok(Step::done(Found::Slave(self.address)));
                }
                self.sub += 1;
                self.begin_part();
            }
        }
        Ok(Step::send(self.request(now_ns)))
    }

    /// Starts scanning the current part, or confirms it at once when known.
    fn begin_part(&mut self) {
        match self.known[self.sub as usize] {
            Some(v) => {
                self.address.set(self.part(), v);
                self.bit = None;
            }
            None => self.bit = Some(31),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lss::slave::Slave;

    const MS: u64 = 1_000_000;

    /// Runs a fastscan over `slaves`, answering each request from every slave at once.
    fn scan(known: [Option<u32>; 4], slaves: &mut [Slave]) -> (Result<Found, FastscanError>, usize) {
        let (mut f, mut send) = Fastscan::start(known, 0, 50 * MS);
        loop {
            let answers: Vec<[u8; 8]> = send
                .iter()
                .flat_map(|req| slaves.iter_mut().filter_map(|s| s.on_request(req)).collect::<Vec<_>>())
                .collect();
            for a in &answers {
                f.on_frame(a);
            }
            let now = f.deadline_ns();
            let step = match f.on_time(now) {
                Ok(s) => s,
                Err(e) => return (Err(e), f.requests()),
            };
            if let Some(found) = step.done {
                return (Ok(found), f.requests());
            }
            send = step.send;
        }
    }

    fn addr(product: u32, serial: u32) -> Address {
        Address {
            vendor: 0x0000_02C9,
            product,
            revision: 0x0001_0002,
            serial,
        }
    }

    #[test]
    fn finds_the_lowest_address_first_then_the_next() {
        let mut slaves = [
            Slave::new(addr(0x4402, 0xDEAD_BEEF), 0xFF),
            Slave::new(addr(0x4402, 0x0000_1234), 0xFF),
            Slave::new(addr(0x0001, 0xFFFF_FFFF), 7),
        ];
        let (found, requests) = scan([None; 4], &mut slaves);
        assert_eq!(found, Ok(Found::Slave(addr(0x4402, 0x1234))));
        assert_eq!(requests, 1 + 4 * 33);
        assert!(slaves[1].in_configuration() && !slaves[0].in_configuration());
        // Give it a node-ID and send everyone back to waiting: the next scan finds the other.
        slaves[1].on_request(&Request::ConfigureNodeId(10).encode());
        for s in slaves.iter_mut() {
            s.on_request(&Request::SwitchGlobal(false).encode());
        }
        assert_eq!(
            scan([None; 4], &mut slaves).0,
            Ok(Found::Slave(addr(0x4402, 0xDEAD_BEEF)))
        );
        for s in slaves.iter_mut() {
            s.on_request(&Request::SwitchGlobal(false).encode());
        }
        slaves[0].on_request(&Request::SwitchGlobal(true).encode());
        slaves[0].on_request(&Request::ConfigureNodeId(11).encode());
        slaves[0].on_request(&Request::SwitchGlobal(false).encode());
        assert_eq!(scan([None; 4], &mut slaves).0, Ok(Found::Nobody));
    }

    #[test]
    fn known_parts_are_confirmed_not_scanned() {
        let mut slaves = [Slave::new(addr(0x4402, 0x55), 0xFF)];
        let (found, requests) = scan([Some(0x2C9), Some(0x4402), None, None], &mut slaves);
        assert_eq!(found, Ok(Found::Slave(addr(0x4402, 0x55))));
        assert_eq!(requests, 1 + 1 + 1 + 33 + 33);
        // A wrong known vendor loses the slave at once.
        let mut slaves = [Slave::new(addr(0x4402, 0x55), 0xFF)];
        let (found, _) = scan([Some(0x2CA), None, None, None], &mut slaves);
        assert!(found.unwrap_err().to_string().contains("confirming its vendor"));
    }
}
