//! What the gateway notifies its clients of, from the frames on the bus: every EMCY, and
//! each change of a node's NMT state its heartbeat (or boot-up) shows. Pure: frames in,
//! notices out.

use super::answer::Notice;
use crate::cob;
use crate::decode::heartbeat::NmtState;
use crate::frame::{Direction, Frame};
use std::collections::BTreeMap;

/// The NMT state last heard of each node, and the order the nodes were first heard in.
#[derive(Debug, Default)]
pub struct Watch {
    nodes: BTreeMap<u8, (usize, NmtState)>,
}

impl Watch {
    /// The notice `frame` gives, if any: an EMCY of a node, a boot-up, or a heartbeat showing
    /// another state than the node's last one (the first heartbeat of a node counts).
    pub fn on_frame(&mut self, frame: &Frame) -> Option<Notice> {
        if frame.direction() != Direction::Rx || frame.is_ext() || frame.is_rtr() {
            return None;
        }
        let data = frame.payload();
        if let Some(node) = cob::heartbeat_node(frame.id) {
            let [b] = data else { return None };
            let state = NmtState::from_byte(*b);
            let next = self.nodes.len();
            let (index, last) = self.nodes.entry(node).or_insert((next, NmtState::Unknown(0xFF)));
            if *last == state && state != NmtState::BootUp {
                return None;
            }
            *last = state;
            return Some(Notice::State {
                node,
                index: *index,
                state,
            });
        }
        let node = u8::try_from(frame.id.checked_sub(cob::emcy(0))?).ok()?;
        if !(1..=127).contains(&node) || data.is_empty() {
            return None;
        }
        let mut d = [0u8; 8];
        d[..data.len().min(8)].copy_from_slice(&data[..data.len().min(8)]);
        Some(Notice::Emcy {
            node,
            code: u16::from_le_bytes([d[0], d[1]]),
            register: d[2],
            bit: d[3],
            info: u32::from_le_bytes([d[4], d[5], d[6], d[7]]),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boot_up_state_changes_and_emcy_are_noticed_once() {
        let mut w = Watch::default();
        let hb = |node: u8, s: u8| Frame::classic(cob::heartbeat(node), &[s]);
        let state = |n: Option<Notice>| match n {
            Some(Notice::State { node, index, state }) => Some((node, index, state)),
            _ => None,
        };
        assert_eq!(state(w.on_frame(&hb(2, 0))), Some((2, 0, NmtState::BootUp)));
        assert_eq!(state(w.on_frame(&hb(2, 0x7F))), Some((2, 0, NmtState::PreOperational)));
        assert_eq!(w.on_frame(&hb(2, 0x7F)), None, "same state: no notice");
        assert_eq!(state(w.on_frame(&hb(3, 0x05))), Some((3, 1, NmtState::Operational)));
        assert_eq!(state(w.on_frame(&hb(2, 0))), Some((2, 0, NmtState::BootUp)), "a reboot");
        let emcy = Frame::classic(cob::emcy(4), &[0x30, 0x81, 0x11, 0, 0x34, 0x12, 0, 0]);
        assert_eq!(
            w.on_frame(&emcy),
            Some(Notice::Emcy {
                node: 4,
                code: 0x8130,
                register: 0x11,
                bit: 0,
                info: 0x1234
            })
        );
        assert_eq!(w.on_frame(&Frame::classic(cob::SYNC, &[])), None, "SYNC is no EMCY");
    }
}
