//! Vector BLF files of CAN frames, for CANalyzer/CANoe and python-can's `BLFReader`: the
//! objects are encoded by the core (`canopen::log::blf`), gathered into log containers of
//! up to 128 KiB and compressed with zlib here.
//!
//! The file header records sizes and counts known only at the end: [`BlfEncoder`] gives
//! the header with the first container (with the start time, which readers need) and the
//! final one from [`BlfEncoder::header`], for the caller to write over the first 144 bytes
//! when its output can be rewritten (a file; a pipe keeps the first).
//!
//! Interfaces `can0`, `can1`, ... are channels 1, 2, ... (as the reader names them);
//! other names get the next free channel numbers in the order they are first seen.

use crate::frame::Frame;
use crate::log::blf::{self, Compression, Totals};
use std::io::{self, Write};

/// Unpacked bytes of objects per container (python-can and Vector tools use 128 KiB).
const CONTAINER: usize = 128 * 1024;

/// Turns frames into the bytes of a BLF file, container by container.
#[derive(Default)]
pub struct BlfEncoder {
    /// Objects waiting for their container.
    pending: Vec<u8>,
    /// Interface names and their channels.
    channels: Vec<(String, u16)>,
    totals: Totals,
    header_out: bool,
    /// Frames in `pending`.
    pending_frames: u64,
}

impl BlfEncoder {
    /// An encoder with nothing written yet.
    pub fn new() -> BlfEncoder {
        BlfEncoder::default()
    }

    /// Adds `f`, seen on `iface`; appends to `out` the bytes of a container (and, the first
    /// time, the file header) when one is full; gives the number of frames that went out.
    pub fn frame(&mut self, out: &mut Vec<u8>, iface: &str, f: &Frame) -> u64 {
        if self.totals.objects == 0 {
            self.totals.start_ns = blf::start_of(f.ts_ns);
        }
        let channel = self.channel(iface);
        let before = self.pending.len();
        blf::encode_frame(&mut self.pending, f, channel, self.totals.start_ns);
        let mut sent = 0;
        if self.pending.len() > CONTAINER {
            let object = self.pending.split_off(before);
            sent = self.container(out);
            self.pending = object;
        }
        self.pending_frames += 1;
        self.totals.objects += 1;
        self.totals.stop_ns = self.totals.stop_ns.max(f.ts_ns);
        sent
    }

    /// Appends the last container (and the header, if none went out yet) to `out`; gives
    /// the number of frames in it.
    pub fn finish(&mut self, out: &mut Vec<u8>) -> u64 {
        let sent = self.container(out);
        if !self.header_out {
            self.header_out = true;
            out.extend_from_slice(&blf::encode_file_header(&self.totals));
            self.totals.file_size += blf::FILE_HEADER_SIZE as u64;
            self.totals.uncompressed_size += blf::FILE_HEADER_SIZE as u64;
        }
        sent
    }

    /// The file header with the totals of everything given to `out` so far.
    pub fn header(&self) -> Vec<u8> {
        blf::encode_file_header(&self.totals)
    }

    /// The BLF channel of `iface`.
    fn channel(&mut self, iface: &str) -> u16 {
        if let Some((_, c)) = self.channels.iter().find(|(n, _)| n == iface) {
            return *c;
        }
        let taken = |c: u16, all: &[(String, u16)]| all.iter().any(|(_, x)| *x == c);
        let c = match blf::name_channel(iface) {
            Some(c) if !taken(c, &self.channels) => c,
            _ => {
                let mut c = self
                    .channels
                    .iter()
                    .map(|(_, c)| *c)
                    .max()
                    .unwrap_or(0)
                    .saturating_add(1);
                while taken(c, &self.channels) && c < u16::MAX {
                    c += 1;
                }
                c
            }
        };
        self.channels.push((iface.to_string(), c));
        c
    }

    /// Appends the frames given so far as one zlib container (after the header, the first
    /// time); gives their number.
    pub fn container(&mut self, out: &mut Vec<u8>) -> u64 {
        if self.pending.is_empty() {
            return 0;
        }
        if !self.header_out {
            self.header_out = true;
            out.extend_from_slice(&blf::encode_file_header(&self.totals));
            self.totals.file_size += blf::FILE_HEADER_SIZE as u64;
            self.totals.uncompressed_size += blf::FILE_HEADER_SIZE as u64;
        }
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        // Writing to a Vec cannot fail.
        let packed = z.write_all(&self.pending).and_then(|_| z.finish()).unwrap_or_default();
        let head = blf::encode_container_head(packed.len(), self.pending.len(), Compression::Zlib);
        let pad = blf::container_padding(packed.len());
        let start = out.len();
        out.extend_from_slice(&head);
        out.extend_from_slice(&packed);
        out.resize(out.len() + pad, 0);
        self.totals.file_size += (out.len() - start) as u64;
        self.totals.uncompressed_size += (head.len() + self.pending.len()) as u64;
        self.pending.clear();
        std::mem::take(&mut self.pending_frames)
    }
}

/// Streams frames into a BLF file on `out` (see [`BlfEncoder`]).
pub struct BlfWriter<W: Write> {
    out: W,
    enc: BlfEncoder,
    buf: Vec<u8>,
}

impl<W: Write> BlfWriter<W> {
    /// A writer of a BLF file on `out`.
    pub fn new(out: W) -> BlfWriter<W> {
        BlfWriter {
            out,
            enc: BlfEncoder::new(),
            buf: Vec::new(),
        }
    }

    /// Writes one frame seen on the interface called `iface` (a container at a time).
    pub fn write_frame(&mut self, iface: &str, f: &Frame) -> io::Result<()> {
        self.enc.frame(&mut self.buf, iface, f);
        self.drain()
    }

    /// Writes the last container and flushes; gives the final file header, for a caller
    /// that can write it over the file's first bytes.
    pub fn finish(&mut self) -> io::Result<Vec<u8>> {
        self.enc.finish(&mut self.buf);
        self.drain()?;
        self.out.flush()?;
        Ok(self.enc.header())
    }

    fn drain(&mut self) -> io::Result<()> {
        if !self.buf.is_empty() {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }
}
