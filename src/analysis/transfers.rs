//! The SDO transfers of one capture, the way `cotui decode --transactions` prints them and
//! the TUI's SDO pane lists them: both take them from the decoder through [`Transfers`],
//! so both list the same transfers in the same order.
//!
//! While frames come, a transfer is listed when a frame completes it (ends it, aborts it,
//! or breaks its protocol). When the input ends, every transfer still running (a block
//! transfer the capture cut, a segmented download that stopped after one segment) is
//! listed after them as incomplete: the capture ended before the transfer did.

use crate::decode::Decoder;
use crate::sdo::Transaction;

/// Where a capture's SDO transfers come out of the decoder (see the module text).
#[derive(Clone, Debug, Default)]
pub struct Transfers {
    ended: bool,
}

impl Transfers {
    /// A capture whose input has not ended.
    pub fn new() -> Transfers {
        Transfers::default()
    }

    /// Every transfer the frames fed to `decoder` since the last call completed, oldest
    /// first. Called after every frame; a frame after the end starts a new input.
    pub fn completed(&mut self, decoder: &mut Decoder) -> Vec<Transaction> {
        self.ended = false;
        decoder.take_transactions()
    }

    /// The input ended: the completed transfers not yet taken, then every transfer still
    /// running, as incomplete. A second end without frames between lists nothing.
    pub fn end(&mut self, decoder: &mut Decoder) -> Vec<Transaction> {
        if self.ended {
            return Vec::new();
        }
        self.ended = true;
        decoder.finish()
    }

    /// True when the input ended (and no frame came since).
    pub fn ended(&self) -> bool {
        self.ended
    }
}
