//! The SDO server of a simulated device: expedited, segmented and block transfers
//! (CiA 301 7.2.4) against an [`ObjectStore`], answering bad requests with abort codes.
//!
//! Pure: one request payload in, the response payloads out.

use super::od::ObjectStore;
use crate::decode::sdo::abort::codes;
use crate::decode::sdo::crc::crc16;

/// Block size the server offers for block downloads.
const BLOCK_SIZE: u8 = 32;

/// What the server is in the middle of.
#[derive(Clone, Debug, Default)]
enum State {
    #[default]
    Idle,
    /// Segmented upload: data still to send, next toggle.
    Upload { data: Vec<u8>, pos: usize, toggle: bool },
    /// Segmented download: target, received bytes, expected toggle.
    Download {
        index: u16,
        sub: u8,
        buf: Vec<u8>,
        toggle: bool,
    },
    /// Block download: target, received bytes, next expected sequence number, last segment seen.
    BlockDown {
        index: u16,
        sub: u8,
        buf: Vec<u8>,
        seq: u8,
        done: bool,
        crc: bool,
    },
    /// Block upload: data, first byte of the current block, client block size, started.
    BlockUp {
        index: u16,
        sub: u8,
        data: Vec<u8>,
        pos: usize,
        blksize: u8,
        crc: bool,
        ending: bool,
    },
}

/// One SDO server channel.
#[derive(Clone, Debug, Default)]
pub struct SdoServer {
    state: State,
}

fn abort(index: u16, sub: u8, code: u32) -> [u8; 8] {
    let i = index.to_le_bytes();
    let c = code.to_le_bytes();
    [0x80, i[0], i[1], sub, c[0], c[1], c[2], c[3]]
}

fn header(cs: u8, index: u16, sub: u8) -> [u8; 8] {
    let i = index.to_le_bytes();
    [cs, i[0], i[1], sub, 0, 0, 0, 0]
}

impl SdoServer {
    /// A server with no transfer in progress.
    pub fn new() -> SdoServer {
        SdoServer::default()
    }

    /// Handles one request (the payload of a 0x600+node frame); returns the responses to send.
    pub fn on_request(&mut self, req: &[u8], store: &mut ObjectStore) -> Vec<[u8; 8]> {
        if req.len() != 8 {
            // A short frame is not a valid request; answer at the object it names, if any.
            let (index, sub) = object_of(req);
            self.state = State::Idle;
            return vec![abort(index, sub, codes::UNKNOWN_COMMAND)];
        }
        let state = std::mem::take(&mut self.state);
        match state {
            State::BlockDown {
                index,
                sub,
                buf,
                seq,
                done,
                crc,
            } if !done || req[0] & 0xE3 != 0xC1 => self.block_segment(req, index, sub, buf, seq, done, crc),
            state => self.command(req, state, store),
        }
    }

    fn command(&mut self, req: &[u8], state: State, store: &mut ObjectStore) -> Vec<[u8; 8]> {
        let (index, sub) = object_of(req);
        let cs = req[0] >> 5;
        match (cs, state) {
            (4, _) => Vec::new(),
            (2, _) => self.initiate_upload(index, sub, store),
            (1, _) => self.initiate_download(req, index, sub, store),
            (3, State::Upload { data, pos, toggle }) => {
                if (req[0] >> 4) & 1 != toggle as u8 {
                    return vec![abort(0, 0, codes::TOGGLE)];
                }
                let n = (data.len() - pos).min(7);
                let last = pos + n == data.len();
                let mut r = [0u8; 8];
                r[0] = ((toggle as u8) << 4) | (((7 - n) as u8) << 1) | last as u8;
                r[1..1 + n].copy_from_slice(&data[pos..pos + n]);
                if !last {
                    self.state = State::Upload {
                        data,
                        pos: pos + n,
                        toggle: !toggle,
                    };
                }
                vec![r]
            }
            (
                0,
                State::Download {
                    index,
                    sub,
                    mut buf,
                    toggle,
                },
            ) => {
                if (req[0] >> 4) & 1 != toggle as u8 {
                    return vec![abort(index, sub, codes::TOGGLE)];
                }
                let n = 7 - ((req[0] >> 1) & 7) as usize;
                buf.extend_from_slice(&req[1..1 + n]);
                let ack = [0x20 | ((toggle as u8) << 4), 0, 0, 0, 0, 0, 0, 0];
                if req[0] & 1 == 1 {
                    return match store.write(index, sub, &buf) {
                        Ok(()) => vec![ack],
                        Err(code) => vec![abort(index, sub, code)],
                    };
                }
                self.state = State::Download {
                    index,
                    sub,
                    buf,
                    toggle: !toggle,
                };
                vec![ack]
            }
            (6, _) if req[0] & 1 == 0 => {
                self.state = State::BlockDown {
                    index,
                    sub,
                    buf: Vec::new(),
                    seq: 1,
                    done: false,
                    crc: req[0] & 0x04 != 0,
                };
                if let Some(e) = store.entry(index, sub).map(|e| e.access) {
                    if matches!(e, crate::od::Access::Ro | crate::od::Access::Const) {
                        self.state = State::Idle;
                        return vec![abort(index, sub, codes::READ_ONLY)];
                    }
                } else {
                    self.state = State::Idle;
                    let code = if store.has_index(index) {
                        codes::NO_SUB
                    } else {
                        codes::NO_OBJECT
                    };
                    return vec![abort(index, sub, code)];
                }
                let mut r = header(0xA4, index, sub);
                r[4] = BLOCK_SIZE;
                vec![r]
            }
            (
                6,
                State::BlockDown {
                    index,
                    sub,
                    mut buf,
                    crc,
                    ..
                },
            ) => {
                // End of block download: n bytes of the last segment were padding.
                let pad = ((req[0] >> 2) & 7) as usize;
                buf.truncate(buf.len().saturating_sub(pad));
                if crc && u16::from_le_bytes([req[1], req[2]]) != crc16(&buf) {
                    return vec![abort(index, sub, codes::CRC)];
                }
                match store.write(index, sub, &buf) {
                    Ok(()) => vec![[0xA1, 0, 0, 0, 0, 0, 0, 0]],
                    Err(code) => vec![abort(index, sub, code)],
                }
            }
            (
                5,
                State::BlockUp {
                    index,
                    sub,
                    data,
                    pos,
                    blksize,
                    crc,
                    ending,
                },
            ) => self.block_upload_step(req, index, sub, data, pos, blksize, crc, ending),
            (5, _) if req[0] & 3 == 0 => {
                let data = match store.read(index, sub) {
                    Ok(d) => d,
                    Err(code) => return vec![abort(index, sub, code)],
                };
                let blksize = req[4];
                if !(1..=127).contains(&blksize) {
                    return vec![abort(index, sub, codes::BLOCK_SIZE)];
                }
                let mut r = header(0xC6, index, sub);
                r[4..8].copy_from_slice(&(data.len() as u32).to_le_bytes());
                self.state = State::BlockUp {
                    index,
                    sub,
                    data,
                    pos: 0,
                    blksize,
                    crc: req[0] & 0x04 != 0,
                    ending: false,
                };
                vec![r]
            }
            _ => vec![abort(index, sub, codes::UNKNOWN_COMMAND)],
        }
    }

    fn initiate_upload(&mut self, index: u16, sub: u8, store: &ObjectStore) -> Vec<[u8; 8]> {
        let data = match store.read(index, sub) {
            Ok(d) => d,
            Err(code) => return vec![abort(index, sub, code)],
        };
        if (1..=4).contains(&data.len()) {
            let mut r = header(0x43 | (((4 - data.len()) as u8) << 2), index, sub);
            r[4..4 + data.len()].copy_from_slice(&data);
            return vec![r];
        }
        // Segmented upload; an empty value is one empty last segment.
        let mut r = header(0x41, index, sub);
        r[4..8].copy_from_slice(&(data.len() as u32).to_le_bytes());
        self.state = State::Upload {
            data,
            pos: 0,
            toggle: false,
        };
        vec![r]
    }

    fn initiate_download(&mut self, req: &[u8], index: u16, sub: u8, store: &mut ObjectStore) -> Vec<[u8; 8]> {
        let (e, s) = (req[0] & 2 != 0, req[0] & 1 != 0);
        if e {
            let n = if s { 4 - ((req[0] >> 2) & 3) as usize } else { 4 };
            return match store.write(index, sub, &req[4..4 + n]) {
                Ok(()) => vec![header(0x60, index, sub)],
                Err(code) => vec![abort(index, sub, code)],
            };
        }
        if let Err(code) = store
            .read(index, sub)
            .map(|_| ())
            .or_else(|c| if c == codes::WRITE_ONLY { Ok(()) } else { Err(c) })
        {
            return vec![abort(index, sub, code)];
        }
        self.state = State::Download {
            index,
            sub,
            buf: Vec::new(),
            toggle: false,
        };
        vec![header(0x60, index, sub)]
    }

    #[allow(clippy::too_many_arguments)]
    fn block_segment(
        &mut self,
        req: &[u8],
        index: u16,
        sub: u8,
        mut buf: Vec<u8>,
        mut seq: u8,
        mut done: bool,
        crc: bool,
    ) -> Vec<[u8; 8]> {
        if req[0] == 0x80 {
            return Vec::new();
        }
        let got = req[0] & 0x7F;
        let last = req[0] & 0x80 != 0;
        let in_order = got == seq && !done;
        if in_order {
            buf.extend_from_slice(&req[1..8]);
            done = last;
            seq += 1;
        }
        let ack_now = last || got >= BLOCK_SIZE;
        let mut out = Vec::new();
        if ack_now {
            out.push([0xA2, seq - 1, BLOCK_SIZE, 0, 0, 0, 0, 0]);
            seq = 1;
        }
        self.state = State::BlockDown {
            index,
            sub,
            buf,
            seq,
            done,
            crc,
        };
        out
    }

    #[allow(clippy::too_many_arguments)]
    fn block_upload_step(
        &mut self,
        req: &[u8],
        index: u16,
        sub: u8,
        data: Vec<u8>,
        mut pos: usize,
        mut blksize: u8,
        crc: bool,
        ending: bool,
    ) -> Vec<[u8; 8]> {
        match req[0] & 3 {
            // End response of the client: done.
            1 if ending => Vec::new(),
            // Start upload (0xA3) or block acknowledge (0xA2).
            3 | 2 => {
                if req[0] & 3 == 2 {
                    let acked = req[1] as usize;
                    pos = (pos + acked * 7).min(data.len());
                    if (1..=127).contains(&req[2]) {
                        blksize = req[2];
                    }
                    if acked > 0 && pos >= data.len() {
                        let pad = if data.is_empty() { 7 } else { (7 - data.len() % 7) % 7 };
                        let c = if crc { crc16(&data) } else { 0 };
                        let cb = c.to_le_bytes();
                        self.state = State::BlockUp {
                            index,
                            sub,
                            data,
                            pos,
                            blksize,
                            crc,
                            ending: true,
                        };
                        return vec![[0xC1 | ((pad as u8) << 2), cb[0], cb[1], 0, 0, 0, 0, 0]];
                    }
                }
                let mut out = Vec::new();
                let mut p = pos;
                for seqno in 1..=blksize {
                    let n = (data.len() - p).min(7);
                    let last = p + n >= data.len();
                    let mut seg = [0u8; 8];
                    seg[0] = seqno | if last { 0x80 } else { 0 };
                    seg[1..1 + n].copy_from_slice(&data[p..p + n]);
                    out.push(seg);
                    p += n;
                    if last {
                        break;
                    }
                }
                self.state = State::BlockUp {
                    index,
                    sub,
                    data,
                    pos,
                    blksize,
                    crc,
                    ending: false,
                };
                out
            }
            _ => vec![abort(index, sub, codes::UNKNOWN_COMMAND)],
        }
    }
}

fn object_of(req: &[u8]) -> (u16, u8) {
    match req {
        [_, lo, hi, sub, ..] => (u16::from_le_bytes([*lo, *hi]), *sub),
        _ => (0, 0),
    }
}
