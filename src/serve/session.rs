//! One client's socketcand session, pure: what the server answers to each element the
//! client sends, which frames the client sends on the bus, and which bus frames it gets.
//!
//! Modes as socketcand has them: after `< hi >` the session has no bus; `< open BUS >`
//! (the one bus this server serves) gives BCM mode, where frames reach the client only
//! for the identifiers it subscribed to (`< subscribe SECS USECS ID >`, at most one per
//! interval), or when the content it watches changed (`< filter >`, `< muxfilter >`), and
//! runs its send jobs (`< add >`, `< update >`, `< delete >`); `< rawmode >` gives every
//! frame (CAN FD ones as `< fdframe >`). `< send >`, `< fdsend >` and the send jobs work when
//! the server allows sending; otherwise they are answered with an error and nothing is sent.

use crate::bus::socketcand::wire::{self, Request, WireError};
use crate::frame::Frame;
use std::collections::{BTreeMap, BTreeSet};

/// What the session asks the server to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Send this element to the client.
    Reply(String),
    /// Put this frame on the bus (the server audits it).
    Send(Frame),
    /// A `< send >` refused: the frame, for the audit line (the client got an error).
    Refused(Frame),
    /// Close the connection after the replies (socketcand does so when `open` fails).
    Close,
    /// Start a send job: `frame` now and every `interval_ns` (0: once), replacing the job
    /// of its identifier.
    Cyclic { frame: Frame, interval_ns: u64 },
    /// New content for the send job of the frame's identifier (its timer kept).
    Update(Frame),
    /// End the send job of this identifier.
    Delete(u32, bool),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    NoBus,
    Bcm,
    Raw,
}

/// A BCM subscription: at most one frame per `interval_ns`, the last sent at `last_ns`.
#[derive(Clone, Copy, Debug)]
struct Sub {
    interval_ns: u64,
    last_ns: Option<u64>,
}

/// A BCM content filter: what to watch, and the last content seen.
#[derive(Clone, Debug)]
enum Watch {
    /// `filter`: the bits of `mask` (and the length).
    Content { mask: Vec<u8>, last: Option<Vec<u8>> },
    /// `muxfilter`: the multiplexer's mask, then (value and mask) tuples, the last content
    /// seen of each.
    Mux {
        tuples: Vec<[u8; 8]>,
        last: Vec<Option<[u8; 8]>>,
    },
}

/// A BCM reception filter: its throttle and what it watches.
#[derive(Clone, Debug)]
struct Filter {
    interval_ns: u64,
    last_ns: Option<u64>,
    watch: Watch,
}

impl Filter {
    fn new(interval_us: u64, watch: Watch) -> Filter {
        Filter {
            interval_ns: interval_us.saturating_mul(1000),
            last_ns: None,
            watch,
        }
    }

    /// True when `f` changed what the filter watches since the frame last passed (a change
    /// inside the throttle interval waits for the first frame after it).
    fn passes(&mut self, f: &Frame) -> bool {
        if let Some(last) = self.last_ns
            && f.ts_ns.saturating_sub(last) < self.interval_ns
        {
            return false;
        }
        let data = f.payload();
        let changed = match &mut self.watch {
            Watch::Content { mask, last } => {
                let masked: Vec<u8> = mask.iter().zip(data).map(|(m, d)| m & d).collect();
                let now = [vec![data.len() as u8], masked].concat();
                let changed = last.as_ref() != Some(&now);
                *last = Some(now);
                changed
            }
            Watch::Mux { tuples, last } => {
                let mut d = [0u8; 8];
                d[..data.len().min(8)].copy_from_slice(&data[..data.len().min(8)]);
                let mux = tuples[0];
                let of = |t: &[u8; 8]| -> [u8; 8] { std::array::from_fn(|i| t[i] & mux[i]) };
                let Some(k) = tuples[1..].iter().position(|t| of(t) == of(&d)) else {
                    return false;
                };
                let t = tuples[k + 1];
                let now: [u8; 8] = std::array::from_fn(|i| d[i] & t[i]);
                let changed = last[k] != Some(now);
                last[k] = Some(now);
                changed
            }
        };
        if changed {
            self.last_ns = Some(f.ts_ns);
        }
        changed
    }
}

/// The state of one client's session.
#[derive(Debug)]
pub struct Session {
    bus: String,
    /// Why this client may not send (none: it may).
    refused: Option<String>,
    mode: Mode,
    subs: BTreeMap<(u32, bool), Sub>,
    filters: BTreeMap<(u32, bool), Filter>,
    /// The identifiers of the send jobs running.
    jobs: BTreeSet<(u32, bool)>,
}

impl Session {
    /// A session on a server of `bus`; `refused` says why sending is off (none: it is on).
    pub fn new(bus: &str, refused: Option<String>) -> Session {
        Session {
            bus: bus.to_string(),
            refused,
            mode: Mode::NoBus,
            subs: BTreeMap::new(),
            filters: BTreeMap::new(),
            jobs: BTreeSet::new(),
        }
    }

    /// The greeting the server sends first.
    pub fn greeting() -> &'static str {
        "< hi >"
    }

    /// True once the client opened the bus in raw mode (the python-can client starts
    /// reading frames only after the `< ok >` of `< rawmode >`).
    pub fn raw(&self) -> bool {
        self.mode == Mode::Raw
    }

    /// True once the client opened the bus (frames may reach it).
    pub fn opened(&self) -> bool {
        self.mode != Mode::NoBus
    }

    /// What to do about one element (or the splitter's error in its place).
    pub fn on_element(&mut self, element: Result<String, WireError>) -> Vec<Action> {
        let err = |e: &dyn std::fmt::Display| vec![Action::Reply(wire::error_element(&e.to_string()))];
        let text = match element {
            Ok(t) => t,
            Err(e) => return err(&e),
        };
        let req = match wire::parse_request(&text) {
            Ok(r) => r,
            Err(e) => return err(&e),
        };
        let ok = || vec![Action::Reply("< ok >".into())];
        match (self.mode, req) {
            (_, Request::Echo) => vec![Action::Reply("< echo >".into())],
            (_, Request::SendPolicy) => vec![Action::Reply(wire::send_policy_element(self.refused.as_deref()))],
            (Mode::NoBus, Request::Open(bus)) if bus == self.bus => {
                self.mode = Mode::Bcm;
                ok()
            }
            (Mode::NoBus, Request::Open(bus)) => vec![
                Action::Reply(wire::error_element(&format!(
                    "could not open bus {}: this server serves {}",
                    wire::printable(&bus, 64),
                    self.bus
                ))),
                Action::Close,
            ],
            (Mode::NoBus, _) => err(&format!("open the bus first: < open {} >", self.bus)),
            (_, Request::Open(_)) => err(&"a bus is open already"),
            (_, Request::RawMode) => {
                self.mode = Mode::Raw;
                ok()
            }
            (_, Request::BcmMode) => {
                self.mode = Mode::Bcm;
                ok()
            }
            (_, Request::Send(frame)) => match &self.refused {
                None => vec![Action::Send(frame)],
                Some(why) => vec![
                    Action::Reply(wire::error_element(&format!("send refused: {why}"))),
                    Action::Refused(frame),
                ],
            },
            (Mode::Bcm, Request::Subscribe { id, ext, interval_us }) => {
                let sub = Sub {
                    interval_ns: interval_us.saturating_mul(1000),
                    last_ns: None,
                };
                self.subs.insert((id, ext), sub);
                vec![]
            }
            (Mode::Bcm, Request::Unsubscribe { id, ext }) => {
                self.subs.remove(&(id, ext));
                vec![]
            }
            (
                Mode::Bcm,
                Request::Filter {
                    id,
                    ext,
                    interval_us,
                    mask,
                },
            ) => {
                self.subs.remove(&(id, ext));
                let watch = Watch::Content { mask, last: None };
                self.filters.insert((id, ext), Filter::new(interval_us, watch));
                vec![]
            }
            (
                Mode::Bcm,
                Request::MuxFilter {
                    id,
                    ext,
                    interval_us,
                    tuples,
                },
            ) => {
                self.subs.remove(&(id, ext));
                let last = vec![None; tuples.len() - 1];
                let watch = Watch::Mux { tuples, last };
                self.filters.insert((id, ext), Filter::new(interval_us, watch));
                vec![]
            }
            (Mode::Bcm, Request::Add { interval_us, frame }) => self.job(frame, |frame| Action::Cyclic {
                frame,
                interval_ns: interval_us.saturating_mul(1000),
            }),
            (Mode::Bcm, Request::Update(frame)) if self.jobs.contains(&(frame.id, frame.is_ext())) => {
                self.job(frame, Action::Update)
            }
            (Mode::Bcm, Request::Update(frame)) => err(&format!(
                "no send job for {:X}: add one first (add SECS USECS ID LEN DATA)",
                frame.id
            )),
            (Mode::Bcm, Request::Delete { id, ext }) => {
                if self.jobs.remove(&(id, ext)) {
                    vec![Action::Delete(id, ext)]
                } else {
                    err(&format!("no send job for {id:X}"))
                }
            }
            (
                _,
                Request::Subscribe { .. }
                | Request::Unsubscribe { .. }
                | Request::Filter { .. }
                | Request::MuxFilter { .. },
            ) => err(
                &"subscribe, unsubscribe, filter and muxfilter work in BCM mode (< bcmmode >); raw mode gets every frame",
            ),
            (_, Request::Add { .. } | Request::Update(_) | Request::Delete { .. }) => {
                err(&"add, update and delete are send jobs of BCM mode (bcmmode)")
            }
            (_, Request::Unsupported(word)) => err(&format!(
                "{word} is not supported by cotui serve (it serves rawmode, bcmmode, send, subscribe, filter, muxfilter, add, update, delete, echo)"
            )),
        }
    }

    /// A send job's action for `frame`, or the refusal when this client may not send.
    fn job(&mut self, frame: Frame, action: impl FnOnce(Frame) -> Action) -> Vec<Action> {
        match &self.refused {
            None => {
                self.jobs.insert((frame.id, frame.is_ext()));
                vec![action(frame)]
            }
            Some(why) => vec![
                Action::Reply(wire::error_element(&format!("send refused: {why}"))),
                Action::Refused(frame),
            ],
        }
    }

    /// The element for a bus frame this client gets, if it gets it (own frames are filtered
    /// by the caller, as a socketcand raw socket does not receive its own frames).
    pub fn forward(&mut self, f: &Frame) -> Option<String> {
        match self.mode {
            Mode::NoBus => None,
            Mode::Raw => wire::frame_element(f),
            Mode::Bcm => {
                if let Some(filter) = self.filters.get_mut(&(f.id, f.is_ext())) {
                    return filter.passes(f).then(|| wire::frame_element(f)).flatten();
                }
                let sub = self.subs.get_mut(&(f.id, f.is_ext()))?;
                if let Some(last) = sub.last_ns
                    && f.ts_ns.saturating_sub(last) < sub.interval_ns
                {
                    return None;
                }
                sub.last_ns = Some(f.ts_ns);
                wire::frame_element(f)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn say(s: &mut Session, text: &str) -> Vec<Action> {
        s.on_element(Ok(text.to_string()))
    }
    fn reply(text: &str) -> Vec<Action> {
        vec![Action::Reply(text.to_string())]
    }

    #[test]
    fn python_cans_handshake_then_frames_in_raw_mode() {
        let mut s = Session::new("demo", None);
        let f = Frame::classic(0x701, &[5]);
        assert_eq!(s.forward(&f), None);
        assert_eq!(say(&mut s, "open demo"), reply("< ok >"));
        assert_eq!(s.forward(&f), None, "BCM mode: nothing unsubscribed");
        assert_eq!(say(&mut s, "rawmode"), reply("< ok >"));
        assert!(s.raw());
        assert_eq!(s.forward(&f).as_deref(), Some("< frame 701 0.000000 05 >"));
        let Ok(Request::Send(sent)) = wire::parse_request("send 601 1 40") else {
            panic!()
        };
        assert_eq!(say(&mut s, "send 601 1 40"), vec![Action::Send(sent)]);
        assert_eq!(say(&mut s, "echo"), reply("< echo >"));
    }

    #[test]
    fn a_wrong_bus_closes_and_sending_refused_says_why() {
        let mut s = Session::new("can0", Some("start the server with --allow-send".into()));
        assert_eq!(
            say(&mut s, "send 601 0"),
            reply("< error open the bus first: ? open can0 ? >")
        );
        assert_eq!(
            say(&mut s, "open can1"),
            vec![
                Action::Reply("< error could not open bus can1: this server serves can0 >".into()),
                Action::Close
            ]
        );
        say(&mut s, "open can0");
        let got = say(&mut s, "send 601 0");
        assert_eq!(
            got[0],
            Action::Reply("< error send refused: start the server with --allow-send >".into())
        );
        assert!(matches!(got[1], Action::Refused(f) if f.id == 0x601));
        assert_eq!(
            say(&mut s, "cotui_send_policy"),
            reply("< cotui_send_policy refused start the server with --allow-send >")
        );
        assert_eq!(
            s.on_element(Err(WireError::TooLong)),
            reply("< error command longer than 4096 bytes, skipped >")
        );
    }

    #[test]
    fn fd_frames_go_out_as_fdframe_and_fdsend_follows_the_send_policy() {
        let fdsend = "fdsend 123 01 12 11 12 13 14 15 16 17 18 19 1a 1b 1c";
        let Ok(Request::Send(fd)) = wire::parse_request(fdsend) else {
            panic!()
        };
        let mut open = Session::new("demo", None);
        say(&mut open, "open demo");
        say(&mut open, "rawmode");
        assert_eq!(
            open.forward(&fd).as_deref(),
            Some("< fdframe 123 01 0.000000 1112131415161718191A1B1C >")
        );
        assert_eq!(say(&mut open, fdsend), vec![Action::Send(fd)]);
        let mut closed = Session::new("demo", Some("the server was started without --allow-send".into()));
        say(&mut closed, "open demo");
        assert_eq!(
            say(&mut closed, fdsend),
            vec![
                Action::Reply("< error send refused: the server was started without --allow-send >".into()),
                Action::Refused(fd)
            ]
        );
        assert_eq!(
            say(&mut closed, "fdsend 123 01 13"),
            reply("< error fdsend: length 13 is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48, 64) >")
        );
    }

    #[test]
    fn bcm_subscriptions_forward_their_identifier_at_most_once_per_interval() {
        let mut s = Session::new("demo", None);
        say(&mut s, "open demo");
        assert_eq!(say(&mut s, "subscribe 0 100000 701"), vec![]);
        let at = |ms: u64, id| {
            let mut f = Frame::classic(id, &[5]);
            f.ts_ns = ms * 1_000_000;
            f
        };
        assert!(s.forward(&at(0, 0x701)).is_some());
        assert!(s.forward(&at(50, 0x701)).is_none());
        assert!(s.forward(&at(50, 0x702)).is_none());
        assert!(s.forward(&at(100, 0x701)).is_some());
        say(&mut s, "unsubscribe 701");
        assert!(s.forward(&at(300, 0x701)).is_none());
        assert_eq!(
            say(&mut s, "isotpmode"),
            reply(
                "< error isotpmode is not supported by cotui serve (it serves rawmode, bcmmode, send, subscribe, filter, muxfilter, add, update, delete, echo) >"
            )
        );
    }

    fn frame_at(ms: u64, id: u32, data: &[u8]) -> Frame {
        let mut f = Frame::classic(id, data);
        f.ts_ns = ms * 1_000_000;
        f
    }

    #[test]
    fn a_content_filter_forwards_changes_of_its_mask_and_length_throttled() {
        let mut s = Session::new("demo", None);
        say(&mut s, "open demo");
        assert_eq!(say(&mut s, "filter 0 100000 181 2 FF F0"), vec![]);
        let fwd = |s: &mut Session, ms, data: &[u8]| s.forward(&frame_at(ms, 0x181, data)).is_some();
        assert!(fwd(&mut s, 0, &[1, 0x10]), "the first frame");
        assert!(!fwd(&mut s, 200, &[1, 0x1F]), "bits outside the mask");
        assert!(fwd(&mut s, 300, &[1, 0x1F, 9]), "the length changed");
        assert!(!fwd(&mut s, 400, &[1, 0x10, 7]), "bytes past the mask");
        assert!(fwd(&mut s, 600, &[2, 0x1F]), "byte 0 changed");
        assert!(!fwd(&mut s, 650, &[3, 0x1F]), "inside the 100 ms throttle");
        assert!(fwd(&mut s, 800, &[4, 0x1F]), "after it: still a change");
        assert!(s.forward(&frame_at(900, 0x182, &[7])).is_none(), "another identifier");
        assert!(say(&mut s, "rawmode").len() == 1 && s.forward(&frame_at(1000, 0x182, &[7])).is_some());
    }

    #[test]
    fn a_mux_filter_watches_each_multiplexer_value_with_its_own_mask() {
        let mut s = Session::new("demo", None);
        say(&mut s, "open demo");
        let m = "muxfilter 0 0 123 3 FF 00 00 00 00 00 00 00 33 FF 00 00 00 00 00 00 56 00 00 00 00 00 00 FF";
        assert_eq!(say(&mut s, m), vec![]);
        let fwd = |s: &mut Session, ms, data: &[u8]| s.forward(&frame_at(ms, 0x123, data)).is_some();
        assert!(fwd(&mut s, 0, &[0x33, 1, 2, 3, 4, 5, 6, 7]));
        assert!(!fwd(&mut s, 1, &[0x33, 1, 9, 9, 9, 9, 9, 9]), "33 watches byte 1 only");
        assert!(fwd(&mut s, 2, &[0x33, 2, 9, 9, 9, 9, 9, 9]));
        assert!(fwd(&mut s, 3, &[0x56, 0, 0, 0, 0, 0, 0, 1]), "56: its first frame");
        assert!(!fwd(&mut s, 4, &[0x56, 9, 0, 0, 0, 0, 0, 1]), "56 watches byte 7 only");
        assert!(!fwd(&mut s, 5, &[0x44, 1, 2, 3, 4, 5, 6, 7]), "no tuple for 44");
    }

    #[test]
    fn send_jobs_start_update_and_end_and_are_refused_without_permission() {
        let mut s = Session::new("demo", None);
        say(&mut s, "open demo");
        let f = Frame::classic(0x123, &[0x11, 0x22]);
        assert_eq!(
            say(&mut s, "add 0 20000 123 2 11 22"),
            vec![Action::Cyclic {
                frame: f,
                interval_ns: 20_000_000
            }]
        );
        let g = Frame::classic(0x123, &[0x33]);
        assert_eq!(say(&mut s, "update 123 1 33"), vec![Action::Update(g)]);
        assert_eq!(say(&mut s, "delete 123"), vec![Action::Delete(0x123, false)]);
        assert_eq!(say(&mut s, "delete 123"), reply("< error no send job for 123 >"));
        assert_eq!(
            say(&mut s, "update 123 1 33"),
            reply("< error no send job for 123: add one first (add SECS USECS ID LEN DATA) >")
        );
        say(&mut s, "rawmode");
        assert_eq!(
            say(&mut s, "add 1 0 123 0"),
            reply("< error add, update and delete are send jobs of BCM mode (bcmmode) >")
        );
        let mut ro = Session::new("demo", Some("the server was started without --allow-send".into()));
        say(&mut ro, "open demo");
        assert_eq!(
            say(&mut ro, "add 1 0 123 2 11 22"),
            vec![
                Action::Reply("< error send refused: the server was started without --allow-send >".into()),
                Action::Refused(f)
            ]
        );
    }
}
