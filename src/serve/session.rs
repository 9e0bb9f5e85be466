//! One client's socketcand session, pure: what the server answers to each element the
//! client sends, which frames the client sends on the bus, and which bus frames it gets.
//!
//! Modes as socketcand has them: after `< hi >` the session has no bus; `< open BUS >`
//! (the one bus this server serves) gives BCM mode, where frames reach the client only
//! for the identifiers it subscribed to (`< subscribe SECS USECS ID >`, at most one per
//! interval); `< rawmode >` gives every frame (CAN FD ones as `< fdframe >`). `< send >` and
//! `< fdsend >` work in both modes when the server allows sending; otherwise they are
//! answered with an error and nothing is sent.

use crate::bus::socketcand::wire::{self, Request, WireError};
use crate::frame::Frame;
use std::collections::BTreeMap;

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

/// The state of one client's session.
#[derive(Debug)]
pub struct Session {
    bus: String,
    /// Why this client may not send (none: it may).
    refused: Option<String>,
    mode: Mode,
    subs: BTreeMap<(u32, bool), Sub>,
}

impl Session {
    /// A session on a server of `bus`; `refused` says why sending is off (none: it is on).
    pub fn new(bus: &str, refused: Option<String>) -> Session {
        Session {
            bus: bus.to_string(),
            refused,
            mode: Mode::NoBus,
            subs: BTreeMap::new(),
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
            (_, Request::Subscribe { .. } | Request::Unsubscribe { .. }) => {
                err(&"subscribe and unsubscribe work in BCM mode (< bcmmode >); raw mode gets every frame")
            }
            (_, Request::Unsupported(word)) => err(&format!(
                "{word} is not supported by cotui serve (it serves rawmode, send, subscribe, echo)"
            )),
        }
    }

    /// The element for a bus frame this client gets, if it gets it (own frames are filtered
    /// by the caller, as a socketcand raw socket does not receive its own frames).
    pub fn forward(&mut self, f: &Frame) -> Option<String> {
        match self.mode {
            Mode::NoBus => None,
            Mode::Raw => wire::frame_element(f),
            Mode::Bcm => {
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
            say(&mut s, "filter 0 0 123 1 FF"),
            reply("< error filter is not supported by cotui serve (it serves rawmode, send, subscribe, echo) >")
        );
    }
}
