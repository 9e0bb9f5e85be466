//! One LSS master service as a pure state machine: [`Service::start`] gives the frames to
//! send, then every slave frame ([`Exchange::on_frame`]) and the passing of time
//! ([`Exchange::on_time`]) move it on until it ends with an [`Answer`] or an [`LssError`].
//! The caller sends what it returns on 0x7E5 and never reads a clock inside.

use super::{Address, Part, RangeBound, Request, Response, configure_error_text};

/// An LSS service the master runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Service {
    /// Switch state global (no answer): `true` = configuration, `false` = waiting.
    SwitchGlobal(bool),
    /// Switch state selective: the one slave with this address enters configuration.
    SwitchSelective(Address),
    ConfigureNodeId(u8),
    ConfigureBitTiming {
        table: u8,
        index: u8,
    },
    /// Activate bit timing (no answer): every slave in configuration switches after the delay.
    ActivateBitTiming {
        delay_ms: u16,
    },
    StoreConfiguration,
    /// Inquire the four parts of the LSS address, one after the other.
    InquireAddress,
    /// Inquire one part of the LSS address.
    Inquire(Part),
    InquireNodeId,
    /// Identify remote slave: do slaves with vendor, product and revision/serial within
    /// the ranges exist? Answers are counted until the timeout.
    IdentifyRemote {
        vendor: u32,
        product: u32,
        revision: (u32, u32),
        serial: (u32, u32),
    },
    /// Identify non-configured remote slave: counted until the timeout.
    IdentifyNonConfigured,
}

impl Service {
    /// Name as the CLI and JSON use it.
    pub fn name(&self) -> &'static str {
        match self {
            Service::SwitchGlobal(_) => "switch_state_global",
            Service::SwitchSelective(_) => "switch_state_selective",
            Service::ConfigureNodeId(_) => "configure_node_id",
            Service::ConfigureBitTiming { .. } => "configure_bit_timing",
            Service::ActivateBitTiming { .. } => "activate_bit_timing",
            Service::StoreConfiguration => "store_configuration",
            Service::InquireAddress => "inquire_address",
            Service::Inquire(_) => "inquire",
            Service::InquireNodeId => "inquire_node_id",
            Service::IdentifyRemote { .. } => "identify_remote_slave",
            Service::IdentifyNonConfigured => "identify_non_configured_remote_slave",
        }
    }

    /// The requests in order; the exchange waits for an answer after those that have one.
    pub fn requests(&self) -> Vec<Request> {
        match *self {
            Service::SwitchGlobal(c) => vec![Request::SwitchGlobal(c)],
            Service::SwitchSelective(a) => Part::ALL
                .iter()
                .map(|p| Request::SwitchSelective(*p, a.get(*p)))
                .collect(),
            Service::ConfigureNodeId(n) => vec![Request::ConfigureNodeId(n)],
            Service::ConfigureBitTiming { table, index } => vec![Request::ConfigureBitTiming { table, index }],
            Service::ActivateBitTiming { delay_ms } => vec![Request::ActivateBitTiming { delay_ms }],
            Service::StoreConfiguration => vec![Request::StoreConfiguration],
            Service::InquireAddress => Part::ALL.iter().map(|p| Request::Inquire(*p)).collect(),
            Service::Inquire(p) => vec![Request::Inquire(p)],
            Service::InquireNodeId => vec![Request::InquireNodeId],
            Service::IdentifyRemote {
                vendor,
                product,
                revision,
                serial,
            } => vec![
                Request::IdentifyRemote(RangeBound::Vendor, vendor),
                Request::IdentifyRemote(RangeBound::Product, product),
                Request::IdentifyRemote(RangeBound::RevisionLow, revision.0),
                Request::IdentifyRemote(RangeBound::RevisionHigh, revision.1),
                Request::IdentifyRemote(RangeBound::SerialLow, serial.0),
                Request::IdentifyRemote(RangeBound::SerialHigh, serial.1),
            ],
            Service::IdentifyNonConfigured => vec![Request::IdentifyNonConfigured],
        }
    }

    /// Starts the service at `now_ns`; `timeout_ns` bounds each wait for an answer.
    pub fn start(self, now_ns: u64, timeout_ns: u64) -> (Exchange, Step) {
        let mut x = Exchange {
            service: self,
            queue: self.requests().into_iter().rev().collect(),
            waiting: None,
            deadline_ns: 0,
            timeout_ns,
            address: Address::default(),
            answers: 0,
        };
        let step = x.next(now_ns);
        (x, step)
    }
}

/// What the master waits for after a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Awaiting {
    SwitchResponse,
    Configured(u8),
    Identity(Part),
    NodeId,
    /// Identify answers, counted until the deadline.
    Identify,
}

fn awaited(r: &Request) -> Option<Awaiting> {
    match *r {
        Request::SwitchSelective(Part::Serial, _) => Some(Awaiting::SwitchResponse),
        Request::ConfigureNodeId(_) => Some(Awaiting::Configured(0x11)),
        Request::ConfigureBitTiming { .. } => Some(Awaiting::Configured(0x13)),
        Request::StoreConfiguration => Some(Awaiting::Configured(0x17)),
        Request::Inquire(p) => Some(Awaiting::Identity(p)),
        Request::InquireNodeId => Some(Awaiting::NodeId),
        Request::IdentifyRemote(RangeBound::SerialHigh, _) | Request::IdentifyNonConfigured => Some(Awaiting::Identify),
        _ => None,
    }
}

/// How a service ended well.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Answer {
    /// Sent; the service has no answer (switch state global, activate bit timing).
    Sent,
    /// The slave confirmed (switch state selective, configure, store).
    Confirmed,
    Address(Address),
    Value(Part, u32),
    NodeId(u8),
    /// Identify services: how many slaves answered (0 = none there).
    Identified(usize),
}

/// How a service failed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LssError {
    #[error("{service}: no answer from an LSS slave within {timeout_ms} ms{hint}")]
    NoAnswer {
        service: &'static str,
        timeout_ms: u64,
        hint: &'static str,
    },
    #[error("{service}: the slave refused: {text} (error code {error})")]
    Refused {
        service: &'static str,
        error: u8,
        spec: u8,
        text: String,
    },
}

/// What the caller does next: send `send` (data of 0x7E5 frames) in order, then, if
/// `done`, the service has ended; otherwise keep feeding slave frames and time.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Step<T = Result<Answer, LssError>> {
    pub send: Vec<[u8; 8]>,
    pub done: Option<T>,
}

impl<T> Step<T> {
    /// Nothing to send yet.
    pub fn wait() -> Step<T> {
        Step {
            send: Vec::new(),
            done: None,
        }
    }

    /// Ended with `r`.
    pub fn done(r: T) -> Step<T> {
        Step {
            send: Vec::new(),
            done: Some(r),
        }
    }

    /// Send one frame and go on.
    pub fn send(frame: [u8; 8]) -> Step<T> {
        Step {
            send: vec![frame],
            done: None,
        }
    }
}

/// A running service.
#[derive(Clone, Debug)]
pub struct Exchange {
    service: Service,
    /// Requests still to send, the next one last.
    queue: Vec<Request>,
    waiting: Option<Awaiting>,
    deadline_ns: u64,
    timeout_ns: u64,
    address: Address,
    answers: usize,
}

impl Exchange {
    /// The deadline of the current wait (ns), if waiting.
    pub fn deadline_ns(&self) -> Option<u64> {
        self.waiting.map(|_| self.deadline_ns)
    }

    /// Sends requests up to and including the next one that has an answer.
    fn next(&mut self, now_ns: u64) -> Step {
        let mut out = Vec::new();
        while let Some(r) = self.queue.pop() {
            out.push(r.encode());
            if let Some(a) = awaited(&r) {
                self.waiting = Some(a);
                self.deadline_ns = now_ns.saturating_add(self.timeout_ns);
                return Step { send: out, done: None };
            }
        }
        self.waiting = None;
        Step {
            send: out,
            done: Some(Ok(self.finished())),
        }
    }

    fn finished(&self) -> Answer {
        match self.service {
            Service::SwitchGlobal(_) | Service::ActivateBitTiming { .. } => Answer::Sent,
            Service::InquireAddress => Answer::Address(self.address),
            Service::Inquire(p) => Answer::Value(p, self.address.get(p)),
            Service::IdentifyRemote { .. } | Service::IdentifyNonConfigured => Answer::Identified(self.answers),
            _ => Answer::Confirmed,
        }
    }

    /// A frame from an LSS slave (data of 0x7E4).
    pub fn on_frame(&mut self, data: &[u8], now_ns: u64) -> Step {
        let Some(waiting) = self.waiting else {
            return Step::wait();
        };
        let Some(resp) = Response::parse(data) else {
            return Step::wait();
        };
        match (waiting, resp) {
            (Awaiting::SwitchResponse, Response::SwitchSelective) => {}
            (Awaiting::Configured(cs), Response::Configured { cs: got, error, spec }) if cs == got => {
                if error != 0 {
                    self.waiting = None;
                    return Step::done(Err(LssError::Refused {
                        service: self.service.name(),
                        error,
                        spec,
                        text: configure_error_text(cs, error, spec),
                    }));
                }
            }
            (Awaiting::Identity(p), Response::Identity(q, v)) if p == q => self.address.set(p, v),
            (Awaiting::NodeId, Response::NodeId(n)) => {
                self.waiting = None;
                return Step::done(Ok(Answer::NodeId(n)));
            }
            (Awaiting::Identify, Response::IdentifySlave | Response::IdentifyNonConfiguredSlave) => {
                self.answers += 1;
                return Step::wait();
            }
            _ => return Step::wait(),
        }
        self.next(now_ns)
    }

    /// Time passed: a wait past its deadline ends the service (identify services end
    /// with the count of answers, the others fail with no answer).
    pub fn on_time(&mut self, now_ns: u64) -> Step {
        let Some(waiting) = self.waiting else {
            return Step::wait();
        };
        if now_ns < self.deadline_ns {
            return Step::wait();
        }
        self.waiting = None;
        if waiting == Awaiting::Identify {
            return Step::done(Ok(Answer::Identified(self.answers)));
        }
        let hint = match waiting {
            Awaiting::SwitchResponse => " (no slave has that address)",
            Awaiting::Configured(_) | Awaiting::Identity(_) | Awaiting::NodeId => {
                " (is a slave in configuration state? switch one there first, e.g. `lss switch` or `lss select`)"
            }
            Awaiting::Identify => "",
        };
        Step::done(Err(LssError::NoAnswer {
            service: self.service.name(),
            timeout_ms: self.timeout_ns / 1_000_000,
            hint,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lss::slave::Slave;

    const MS: u64 = 1_000_000;

    /// Runs a service against slaves until it ends; returns the answer and every master frame.
    pub(crate) fn run(service: Service, slaves: &mut [Slave]) -> (Result<Answer, LssError>, Vec<[u8; 8]>) {
        let mut now = 0;
        let (mut x, mut step) = service.start(now, 100 * MS);
        let mut sent = Vec::new();
        loop {
            let mut answers = Vec::new();
            for f in &step.send {
                sent.push(*f);
                answers.extend(slaves.iter_mut().filter_map(|s| s.on_request(f)));
            }
            if let Some(r) = step.done {
                return (r, sent);
            }
            step = Step::wait();
            for a in answers {
                let s = x.on_frame(&a, now);
                step.send.extend(s.send);
                step.done = step.done.or(s.done);
            }
            if step.send.is_empty() && step.done.is_none() {
                now += 10 * MS;
                step = x.on_time(now);
            }
        }
    }

    fn addr(serial: u32) -> Address {
        Address {
            vendor: 0x3A,
            product: 0x1234,
            revision: 2,
            serial,
        }
    }

    #[test]
    fn selective_switch_then_configure_and_store() {
        let mut slaves = [Slave::new(addr(7), 0xFF), Slave::new(addr(8), 0xFF)];
        let (r, sent) = run(Service::SwitchSelective(addr(8)), &mut slaves);
        assert_eq!(r, Ok(Answer::Confirmed));
        assert_eq!(sent.len(), 4);
        assert_eq!(run(Service::ConfigureNodeId(12), &mut slaves).0, Ok(Answer::Confirmed));
        assert_eq!(run(Service::StoreConfiguration, &mut slaves).0, Ok(Answer::Confirmed));
        assert_eq!(slaves[1].pending_node_id(), 12);
        assert_eq!(slaves[0].pending_node_id(), 0xFF);
    }

    #[test]
    fn configure_out_of_range_is_refused_with_the_text() {
        let mut slaves = [Slave::new(addr(1), 0xFF)];
        assert_eq!(run(Service::SwitchGlobal(true), &mut slaves).0, Ok(Answer::Sent));
        let (r, _) = run(Service::ConfigureNodeId(200), &mut slaves);
        let e = r.unwrap_err();
        assert_eq!(
            e.to_string(),
            "configure_node_id: the slave refused: node-ID out of range (1..127 or 255) (error code 1)"
        );
    }

    #[test]
    fn no_slave_in_configuration_gives_no_answer_with_a_hint() {
        let mut slaves = [Slave::new(addr(1), 5)];
        let e = run(Service::InquireNodeId, &mut slaves).0.unwrap_err();
        assert!(
            e.to_string()
                .starts_with("inquire_node_id: no answer from an LSS slave within 100 ms (is a slave")
        );
    }

    #[test]
    fn inquire_address_and_identify() {
        let mut slaves = [Slave::new(addr(9), 4)];
        assert_eq!(run(Service::SwitchGlobal(true), &mut slaves).0, Ok(Answer::Sent));
        assert_eq!(
            run(Service::InquireAddress, &mut slaves).0,
            Ok(Answer::Address(addr(9)))
        );
        assert_eq!(run(Service::InquireNodeId, &mut slaves).0, Ok(Answer::NodeId(4)));
        assert_eq!(run(Service::SwitchGlobal(false), &mut slaves).0, Ok(Answer::Sent));
        let within = Service::IdentifyRemote {
            vendor: 0x3A,
            product: 0x1234,
            revision: (0, 5),
            serial: (1, 9),
        };
        assert_eq!(run(within, &mut slaves).0, Ok(Answer::Identified(1)));
        let outside = Service::IdentifyRemote {
            vendor: 0x3A,
            product: 0x1234,
            revision: (0, 5),
            serial: (10, 20),
        };
        assert_eq!(run(outside, &mut slaves).0, Ok(Answer::Identified(0)));
        assert_eq!(
            run(Service::IdentifyNonConfigured, &mut slaves).0,
            Ok(Answer::Identified(0))
        );
    }
}
