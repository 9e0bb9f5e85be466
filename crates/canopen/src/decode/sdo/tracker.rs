//! The decoder's SDO tracking: the protocol's [`TransferTracker`] decides what each frame
//! means in its transfer; this adds the dictionary name and typed value for the label.

use super::frame::SdoFrame;
use super::value::view;
use crate::frame::NodeKey;
use crate::od::Dictionary;
use crate::sdo::codec::{SdoCommand, Side};
use crate::sdo::tracker::{Tracked, TransferTracker};
use crate::sdo::transaction::{Channel, Transaction};

/// Tracks SDO transfers on every channel; returns each frame labelled and collects
/// completed transactions.
#[derive(Clone, Debug, Default)]
pub struct SdoTracker {
    transfers: TransferTracker,
}

impl SdoTracker {
    /// An empty tracker.
    pub fn new() -> SdoTracker {
        SdoTracker::default()
    }

    /// Feeds one frame on the node's default channel (0x600 + node / 0x580 + node).
    pub fn on_frame(
        &mut self,
        seq: u64,
        ts_ns: u64,
        node: NodeKey,
        client_to_server: bool,
        payload: &[u8],
        dict: &Dictionary,
    ) -> SdoFrame {
        let tracked = self.track(seq, ts_ns, node, client_to_server, payload, dict);
        labelled(tracked, payload, dict)
    }

    /// [`SdoTracker::on_frame`] without the dictionary name and typed value of the frame
    /// (for callers that print no frame labels); the transfers go on the same way.
    pub fn track(
        &mut self,
        seq: u64,
        ts_ns: u64,
        node: NodeKey,
        client_to_server: bool,
        payload: &[u8],
        dict: &Dictionary,
    ) -> Tracked {
        self.transfers
            .on_frame(seq, ts_ns, node, client_to_server, payload, dict)
    }

    /// Feeds one frame of `channel` sent by `side`; returns its decoded meaning.
    pub fn on_channel_frame(
        &mut self,
        seq: u64,
        ts_ns: u64,
        channel: Channel,
        side: Side,
        payload: &[u8],
        dict: &Dictionary,
    ) -> SdoFrame {
        let tracked = self
            .transfers
            .on_channel_frame(seq, ts_ns, channel, side, payload, dict);
        labelled(tracked, payload, dict)
    }

    /// Transactions completed since the last call, oldest first (the list keeps its room).
    pub fn drain_completed(&mut self) -> std::vec::Drain<'_, Transaction> {
        self.transfers.drain_completed()
    }

    /// Ends the input: every transfer still running becomes incomplete; returns them after
    /// any completed ones not yet taken.
    pub fn finish(&mut self) -> Vec<Transaction> {
        self.transfers.finish()
    }
}

/// The frame as [`SdoTracker::track`] saw it: command, object and problems, without the
/// object's name or value (for callers that read only those, like the diagnosis).
pub(crate) fn unlabelled(tracked: Tracked, payload: &[u8]) -> SdoFrame {
    let mut frame = SdoFrame::of(tracked.side, payload, tracked.command);
    frame.object = tracked.object;
    frame.problems = tracked.problems;
    frame
}

/// The frame as [`SdoTracker::track`] saw it, with the object's name and, for expedited
/// data, its typed value.
pub(crate) fn labelled(tracked: Tracked, payload: &[u8], dict: &Dictionary) -> SdoFrame {
    let mut frame = unlabelled(tracked, payload);
    if let Some((index, sub)) = frame.object {
        frame.name = dict.label_name(index, sub);
        if let Some(data) = match frame.command {
            SdoCommand::InitiateDownload { expedited: true, .. }
            | SdoCommand::InitiateUploadResponse { expedited: true, .. } => frame.command.data(),
            _ => None,
        } {
            frame.value = Some(view(dict, index, sub, data));
        }
    }
    frame
}
