//! Recognising block transfers a capture caught mid-way, by their pattern alone.
//!
//! Inside a sub-block the first byte of a frame is `c | seqno`, not a command, and
//! nothing says so: the initiate that announced the block transfer came before the
//! capture. Three patterns give it away:
//! - a first byte that no command of that side may carry (reserved bits set, e.g. a
//!   client `0x6F`), so it can only be a sequence number;
//! - a run: two frames in a row from the same side with no answer in between whose
//!   first bytes count up by one (segmented transfers alternate sides and toggle bit 4);
//! - a block acknowledgement (`A2 ackseq blksize`) with no transfer running.

use super::codec::{Chunk, Side, command_allowed};

/// A frame that no command explains: the first byte is `c | seqno` with seqno 1..=127.
pub(crate) fn impossible_command(side: Side, payload: &[u8]) -> bool {
    match payload {
        [first, ..] if payload.len() == 8 => first & 0x7F != 0 && !command_allowed(side, *first),
        _ => false,
    }
}

/// The last frame of a channel that fitted no transfer, kept to spot a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Orphan {
    /// Who sent it.
    pub side: Side,
    /// Its first byte.
    pub first: u8,
    /// Bytes 1..8.
    pub data: Chunk,
    /// Its frame number.
    pub seq: u64,
    /// Its timestamp (ns).
    pub ts_ns: u64,
    /// It is already part of a listed transaction (an expedited upload response, as it
    /// looked): a run it began counts from the next frame.
    pub listed: bool,
}

impl Orphan {
    /// The orphan of an 8-byte payload (shorter ones cannot be block segments).
    pub fn of(side: Side, payload: &[u8], seq: u64, ts_ns: u64) -> Option<Orphan> {
        (payload.len() == 8).then(|| Orphan {
            side,
            first: payload[0],
            data: Chunk::new(&payload[1..], 7),
            seq,
            ts_ns,
            listed: false,
        })
    }

    /// Its sequence number, if it can be a block segment.
    pub fn seqno(&self) -> Option<u8> {
        Some(self.first & 0x7F).filter(|s| *s != 0)
    }

    /// The c bit: the last segment of the transfer, if it is one.
    pub fn last(&self) -> bool {
        self.first & 0x80 != 0
    }

    /// `payload` from `side` is the next segment of a run this orphan began.
    pub fn continued_by(&self, side: Side, payload: &[u8]) -> bool {
        payload.len() == 8
            && side == self.side
            && !self.last()
            && self.seqno().is_some_and(|s| s < 127 && payload[0] & 0x7F == s + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_the_codec_builds_is_valid() {
        use crate::sdo::codec::{SdoCommand, encode};
        let c = Chunk::new(&[1, 2], 2);
        let cmds = [
            (Side::Client, SdoCommand::InitiateUpload { index: 1, sub: 0 }),
            (Side::Client, SdoCommand::UploadSegment { toggle: true }),
            (Side::Client, SdoCommand::BlockUploadStart),
            (Side::Client, SdoCommand::BlockUploadAck { ackseq: 3, blksize: 9 }),
            (Side::Client, SdoCommand::BlockUploadEndResponse),
            (Side::Client, SdoCommand::BlockDownloadEnd { unused: 7, crc: 0 }),
            (
                Side::Client,
                SdoCommand::BlockDownloadInitiate {
                    index: 1,
                    sub: 0,
                    crc: true,
                    size: Some(9),
                },
            ),
            (
                Side::Client,
                SdoCommand::BlockUploadInitiate {
                    index: 1,
                    sub: 0,
                    crc: true,
                    blksize: 9,
                    pst: 0,
                },
            ),
            (Side::Server, SdoCommand::DownloadSegmentResponse { toggle: true }),
            (Side::Server, SdoCommand::InitiateDownloadResponse { index: 1, sub: 0 }),
            (Side::Server, SdoCommand::BlockDownloadAck { ackseq: 3, blksize: 9 }),
            (Side::Server, SdoCommand::BlockDownloadEndResponse),
            (Side::Server, SdoCommand::BlockUploadEnd { unused: 5, crc: 0 }),
            (
                Side::Server,
                SdoCommand::BlockUploadInitiateResponse {
                    index: 1,
                    sub: 0,
                    crc: true,
                    size: Some(3),
                },
            ),
            (
                Side::Server,
                SdoCommand::BlockDownloadInitiateResponse {
                    index: 1,
                    sub: 0,
                    crc: true,
                    blksize: 127,
                },
            ),
            (
                Side::Server,
                SdoCommand::UploadSegmentResponse {
                    toggle: true,
                    last: true,
                    data: c,
                },
            ),
        ];
        for (side, cmd) in cmds {
            let p = encode(&cmd);
            assert!(command_allowed(side, p[0]), "{cmd:?} -> {:02X}", p[0]);
            assert!(!impossible_command(side, &p), "{cmd:?}");
        }
    }

    #[test]
    fn reserved_bits_betray_a_sequence_number() {
        // From the CANopenDemo capture: a client 0x6F would be an upload segment request
        // with reserved bits set; 0x01 from either side is a valid segment command.
        assert!(impossible_command(
            Side::Client,
            &[0x6F, 0xC3, 0xA9, 0x6E, 0xAF, 0x5C, 0x81, 0x32]
        ));
        assert!(impossible_command(
            Side::Server,
            &[0x6B, 0x72, 0x30, 0x0A, 0x0F, 0xC2, 0x2C, 0xF9]
        ));
        assert!(!impossible_command(Side::Server, &[0x01, 0, 0, 0, 0, 0, 0, 0]));
        assert!(
            !impossible_command(Side::Client, &[0x6F, 0, 0]),
            "short frames are not segments"
        );
        assert!(
            !impossible_command(Side::Client, &[0xE8, 4, 0x50, 0, 0, 0, 0, 0]),
            "vendor commands"
        );
    }

    #[test]
    fn runs_count_up_from_one_side() {
        let o = Orphan::of(Side::Server, &[0x05, 1, 2, 3, 4, 5, 6, 7], 1, 0).unwrap();
        assert!(o.continued_by(Side::Server, &[0x06, 0, 0, 0, 0, 0, 0, 0]));
        assert!(o.continued_by(Side::Server, &[0x86, 0, 0, 0, 0, 0, 0, 0]));
        assert!(!o.continued_by(Side::Client, &[0x06, 0, 0, 0, 0, 0, 0, 0]));
        assert!(!o.continued_by(Side::Server, &[0x15, 0, 0, 0, 0, 0, 0, 0]));
        let zero = Orphan::of(Side::Server, &[0x00; 8], 1, 0).unwrap();
        assert!(!zero.continued_by(Side::Server, &[0x01, 0, 0, 0, 0, 0, 0, 0]));
    }
}
