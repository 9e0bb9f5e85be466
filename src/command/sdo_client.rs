//! The SDO client of the commander: one upload or download as a pure state machine.
//!
//! Start a transfer, send what it returns on 0x600+node, feed every 0x580+node
//! payload to [`Transfer::on_response`] until it is done or aborted. Timing is the
//! caller's: on a timeout send [`Transfer::timeout_abort`].

use crate::decode::sdo::abort::codes;
use crate::decode::sdo::crc::crc16;

/// Segments per block the client asks for in block uploads.
const CLIENT_BLOCK_SIZE: u8 = 64;

/// How the client moves the data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Protocol {
    /// Expedited for up to 4 bytes, segmented above (downloads); what the server offers (uploads).
    Auto,
    /// Block transfer (CiA 301 7.2.4.3.9 ff.).
    Block,
}

/// The next thing the caller does after a response.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Progress {
    /// Send these payloads (in order), then wait for the next response.
    Send(Vec<[u8; 8]>),
    /// Nothing to send; keep waiting.
    Wait,
    /// The transfer completed: the uploaded data (empty for downloads) and a last
    /// payload to send (the block upload end response), if any.
    Done { data: Vec<u8>, reply: Option<[u8; 8]> },
    /// The transfer ended with an abort code; `reply` is our abort frame to send, if any
    /// (none when the server aborted).
    Aborted {
        code: u32,
        by_server: bool,
        reply: Option<[u8; 8]>,
    },
}

#[derive(Clone, Debug)]
enum State {
    /// Waiting for the initiate upload response.
    UploadInit,
    /// Segmented upload: received data, toggle of the segment requested last.
    UploadSeg {
        data: Vec<u8>,
        toggle: bool,
    },
    /// Block upload initiated: waiting for the server's size answer.
    BlockUpInit,
    /// Block upload segments: data, next expected sequence number, last segment seen.
    BlockUp {
        data: Vec<u8>,
        seq: u8,
        last: bool,
        crc: bool,
    },
    /// Waiting for the initiate download response.
    DownloadInit,
    /// Segmented download: next position, toggle of the segment in flight.
    DownloadSeg {
        pos: usize,
        toggle: bool,
    },
    /// Block download initiated: waiting for the block size.
    BlockDownInit,
    /// Block download: start of the unacknowledged block, segments in it.
    BlockDown {
        pos: usize,
        blksize: u8,
        crc: bool,
    },
    /// Block download end sent.
    BlockDownEnd,
    Finished,
}

/// One SDO transfer in progress.
#[derive(Clone, Debug)]
pub struct Transfer {
    index: u16,
    sub: u8,
    data: Vec<u8>,
    state: State,
}

fn cmd(cs: u8, index: u16, sub: u8) -> [u8; 8] {
    let i = index.to_le_bytes();
    [cs, i[0], i[1], sub, 0, 0, 0, 0]
}

impl Transfer {
    /// Starts reading (index, sub); returns the transfer and the request to send.
    pub fn upload(index: u16, sub: u8, protocol: Protocol) -> (Transfer, [u8; 8]) {
        let (state, req) = match protocol {
            Protocol::Auto => (State::UploadInit, cmd(0x40, index, sub)),
            Protocol::Block => {
                let mut r = cmd(0xA4, index, sub);
                r[4] = CLIENT_BLOCK_SIZE;
                (State::BlockUpInit, r)
            }
        };
        let t = Transfer {
            index,
            sub,
            data: Vec::new(),
            state,
        };
        (t, req)
    }

    /// Starts writing `data` to (index, sub); returns the transfer and the request to send.
    pub fn download(index: u16, sub: u8, data: Vec<u8>, protocol: Protocol) -> (Transfer, [u8; 8]) {
        let size = (data.len() as u32).to_le_bytes();
        let (state, req) = match protocol {
            Protocol::Auto if (1..=4).contains(&data.len()) => {
                let mut r = cmd(0x23 | (((4 - data.len()) as u8) << 2), index, sub);
                r[4..4 + data.len()].copy_from_slice(&data);
                (State::DownloadInit, r)
            }
            Protocol::Auto => {
                let mut r = cmd(0x21, index, sub);
                r[4..8].copy_from_slice(&size);
                (State::DownloadInit, r)
            }
            Protocol::Block => {
                let mut r = cmd(0xC6, index, sub);
                r[4..8].copy_from_slice(&size);
                (State::BlockDownInit, r)
            }
        };
        let t = Transfer {
            index,
            sub,
            data,
            state,
        };
        (t, req)
    }

    /// The abort frame to send when the server did not answer in time.
    pub fn timeout_abort(&self) -> [u8; 8] {
        self.abort_frame(codes::TIMEOUT)
    }

    fn abort_frame(&self, code: u32) -> [u8; 8] {
        let mut r = cmd(0x80, self.index, self.sub);
        r[4..8].copy_from_slice(&code.to_le_bytes());
        r
    }

    fn fail(&mut self, code: u32) -> Progress {
        self.state = State::Finished;
        Progress::Aborted {
            code,
            by_server: false,
            reply: Some(self.abort_frame(code)),
        }
    }

    fn names_our_object(&self, r: &[u8]) -> bool {
        u16::from_le_bytes([r[1], r[2]]) == self.index && r[3] == self.sub
    }

    /// Feeds one server response (payload of 0x580+node).
    pub fn on_response(&mut self, r: &[u8]) -> Progress {
        if matches!(self.state, State::Finished) {
            return Progress::Wait;
        }
        if r.len() != 8 {
            return self.fail(codes::UNKNOWN_COMMAND);
        }
        if r[0] == 0x80 {
            self.state = State::Finished;
            return Progress::Aborted {
                code: u32::from_le_bytes([r[4], r[5], r[6], r[7]]),
                by_server: true,
                reply: None,
            };
        }
        let state = std::mem::replace(&mut self.state, State::Finished);
        match state {
            State::UploadInit if r[0] & 0xE0 == 0x40 && self.names_our_object(r) => {
                if r[0] & 2 != 0 {
                    let n = if r[0] & 1 != 0 {
                        4 - ((r[0] >> 2) & 3) as usize
                    } else {
                        4
                    };
                    return Progress::Done {
                        data: r[4..4 + n].to_vec(),
                        reply: None,
                    };
                }
                self.state = State::UploadSeg {
                    data: Vec::new(),
                    toggle: false,
                };
                Progress::Send(vec![[0x60, 0, 0, 0, 0, 0, 0, 0]])
            }
            State::UploadSeg { mut data, toggle } if r[0] & 0xE0 == 0 => {
                if (r[0] >> 4) & 1 != toggle as u8 {
                    return self.fail(codes::TOGGLE);
                }
                let n = 7 - ((r[0] >> 1) & 7) as usize;
                data.extend_from_slice(&r[1..1 + n]);
                if r[0] & 1 != 0 {
                    return Progress::Done { data, reply: None };
                }
                let next = !toggle;
                self.state = State::UploadSeg { data, toggle: next };
                Progress::Send(vec![[0x60 | ((next as u8) << 4), 0, 0, 0, 0, 0, 0, 0]])
            }
            State::BlockUpInit if r[0] & 0xE1 == 0xC0 && self.names_our_object(r) => {
                self.state = State::BlockUp {
                    data: Vec::new(),
                    seq: 1,
                    last: false,
                    crc: r[0] & 0x04 != 0,
                };
                Progress::Send(vec![[0xA3, 0, 0, 0, 0, 0, 0, 0]])
            }
            State::BlockUp { data, last, crc, .. } if last && r[0] & 0xE3 == 0xC1 => {
                let pad = ((r[0] >> 2) & 7) as usize;
                let mut data = data;
                data.truncate(data.len().saturating_sub(pad));
                if crc && u16::from_le_bytes([r[1], r[2]]) != crc16(&data) {
                    return self.fail(codes::CRC);
                }
                Progress::Done {
                    data,
                    reply: Some([0xA1, 0, 0, 0, 0, 0, 0, 0]),
                }
            }
            State::BlockUp {
                mut data,
                mut seq,
                mut last,
                crc,
            } if !last => {
                let got = r[0] & 0x7F;
                if got == seq {
                    data.extend_from_slice(&r[1..8]);
                    last = r[0] & 0x80 != 0;
                    seq += 1;
                }
                let end_of_block = r[0] & 0x80 != 0 || got >= CLIENT_BLOCK_SIZE;
                let out = if end_of_block {
                    let ack = [0xA2, seq - 1, CLIENT_BLOCK_SIZE, 0, 0, 0, 0, 0];
                    seq = 1;
                    Progress::Send(vec![ack])
                } else {
                    Progress::Wait
                };
                self.state = State::BlockUp { data, seq, last, crc };
                out
            }
            State::DownloadInit if r[0] == 0x60 && self.names_our_object(r) => {
                if self.data.len() <= 4 && !self.data.is_empty() {
                    return Progress::Done {
                        data: Vec::new(),
                        reply: None,
                    };
                }
                self.next_segment(0, false)
            }
            State::DownloadSeg { pos, toggle } if r[0] & 0xE0 == 0x20 => {
                if (r[0] >> 4) & 1 != toggle as u8 {
                    return self.fail(codes::TOGGLE);
                }
                if pos >= self.data.len() {
                    return Progress::Done {
                        data: Vec::new(),
                        reply: None,
                    };
                }
                self.next_segment(pos, !toggle)
            }
            State::BlockDownInit if r[0] & 0xE3 == 0xA0 && self.names_our_object(r) => {
                let blksize = r[4];
                if !(1..=127).contains(&blksize) {
                    return self.fail(codes::BLOCK_SIZE);
                }
                let crc = r[0] & 0x04 != 0;
                Progress::Send(self.send_block(0, blksize, crc))
            }
            State::BlockDown { pos, blksize, crc } if r[0] & 0xE3 == 0xA2 => {
                let acked = r[1] as usize;
                let sent = self.block_len(pos, blksize);
                if acked > sent {
                    return self.fail(codes::SEQUENCE);
                }
                let pos = (pos + acked * 7).min(self.data.len());
                let next = if (1..=127).contains(&r[2]) { r[2] } else { blksize };
                if acked == sent && pos >= self.data.len() {
                    let pad = if self.data.is_empty() {
                        7
                    } else {
                        (7 - self.data.len() % 7) % 7
                    };
                    let c = if crc { crc16(&self.data) } else { 0 }.to_le_bytes();
                    self.state = State::BlockDownEnd;
                    return Progress::Send(vec![[0xC1 | ((pad as u8) << 2), c[0], c[1], 0, 0, 0, 0, 0]]);
                }
                Progress::Send(self.send_block(pos, next, crc))
            }
            State::BlockDownEnd if r[0] & 0xE3 == 0xA1 => Progress::Done {
                data: Vec::new(),
                reply: None,
            },
            other => {
                // A response that does not belong here: an unexpected command specifier.
                self.state = other;
                self.fail(codes::UNKNOWN_COMMAND)
            }
        }
    }

    /// Number of segments a block from `pos` holds.
    fn block_len(&self, pos: usize, blksize: u8) -> usize {
        let left = self.data.len().saturating_sub(pos);
        (left.div_ceil(7)).clamp(1, blksize as usize)
    }

    fn send_block(&mut self, pos: usize, blksize: u8, crc: bool) -> Vec<[u8; 8]> {
        let count = self.block_len(pos, blksize);
        let mut out = Vec::with_capacity(count);
        for i in 0..count {
            let p = pos + i * 7;
            let n = self.data.len().saturating_sub(p).min(7);
            let mut seg = [0u8; 8];
            seg[0] = (i as u8 + 1) | if p + n >= self.data.len() { 0x80 } else { 0 };
            seg[1..1 + n].copy_from_slice(&self.data[p..p + n]);
            out.push(seg);
        }
        self.state = State::BlockDown { pos, blksize, crc };
        out
    }

    fn next_segment(&mut self, pos: usize, toggle: bool) -> Progress {
        let n = (self.data.len() - pos).min(7);
        let last = pos + n >= self.data.len();
        let mut seg = [0u8; 8];
        seg[0] = ((toggle as u8) << 4) | (((7 - n) as u8) << 1) | last as u8;
        seg[1..1 + n].copy_from_slice(&self.data[pos..pos + n]);
        self.state = State::DownloadSeg { pos: pos + n, toggle };
        Progress::Send(vec![seg])
    }
}
