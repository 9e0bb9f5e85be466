//! Reading Vector BLF files as a stream: the file's objects are read one at a time, log
//! containers are inflated (zlib) and their objects decoded by the core's byte-level
//! parser (`canopen::log::blf`). Memory stays within one object and one container's data,
//! whatever the file's size. A damaged object, container or header is a warning that
//! says where (byte offsets) and reading goes on at the next object.

use crate::frame::Interfaces;
use crate::log::blf::{self, Compression, Object, Step};
use crate::log::{Counts, Outcome, SkipReason};
use std::io::{self, BufRead, Read};

/// The largest object taken (containers hold about 128 KiB): a larger size is damage.
const MAX_OBJECT: usize = 16 << 20;

/// The most bytes one container may inflate to (a guard against zlib bombs).
const MAX_UNPACKED: u64 = 64 << 20;

/// Streams a BLF file's frames as `(object number, Outcome)`, as `LogReader` streams lines.
pub struct BlfReader<R> {
    src: R,
    /// Bytes read from the file and not yet used; `outer[0]` is at file byte `outer_off`.
    outer: Vec<u8>,
    outer_off: u64,
    eof: bool,
    /// Unpacked container data; `inner[inner_at..inner_end]` is not yet used and starts
    /// at byte `inner_off` of the unpacked object stream. The bytes after `inner_end` are
    /// room kept from container to container (written once, never zeroed again).
    inner: Vec<u8>,
    inner_at: usize,
    inner_end: usize,
    inner_off: u64,
    /// File byte of the container whose data `inner` ends with.
    container_at: u64,
    /// The inflater, reset for each container (not made anew).
    zlib: flate2::Decompress,
    start_ns: u64,
    header_read: bool,
    objects: u64,
    channels: Vec<Option<u16>>,
    ifaces: Interfaces,
    counts: Counts,
    done: bool,
}

impl<R: BufRead> BlfReader<R> {
    /// A reader of the BLF file `src` (its header is read on the first call).
    pub fn new(src: R) -> Self {
        BlfReader {
            src,
            outer: Vec::with_capacity(1 << 17),
            outer_off: 0,
            eof: false,
            inner: Vec::with_capacity(1 << 18),
            inner_at: 0,
            inner_end: 0,
            inner_off: 0,
            container_at: 0,
            zlib: flate2::Decompress::new(true),
            start_ns: 0,
            header_read: false,
            objects: 0,
            channels: Vec::new(),
            ifaces: Interfaces::default(),
            counts: Counts::default(),
            done: false,
        }
    }

    /// Interface names seen so far (frames hold indexes into it).
    pub fn interfaces(&self) -> &Interfaces {
        &self.ifaces
    }

    /// Totals so far.
    pub fn counts(&self) -> &Counts {
        &self.counts
    }

    /// The next object's number (1-based) and outcome; `None` at the end of the file.
    pub fn next_line(&mut self) -> io::Result<Option<(u64, Outcome)>> {
        let mut one = Vec::with_capacity(1);
        self.fill(&mut one, 1)?;
        Ok(one.pop())
    }

    /// Appends outcomes to `out` until it holds `max` or the file ends.
    pub fn fill(&mut self, out: &mut Vec<(u64, Outcome)>, max: usize) -> io::Result<()> {
        if !self.header_read {
            self.header_read = true;
            if let Some(w) = self.header()? {
                self.push(out, w);
            }
        }
        while out.len() < max && !self.done {
            if let Some(o) = self.next_inner() {
                self.push(out, o);
                continue;
            }
            match self.next_outer()? {
                Some(o) => self.push(out, o),
                None if self.eof && self.outer.is_empty() => {
                    self.done = true;
                    if self.inner[self.inner_at..self.inner_end].iter().any(|&b| b != 0) {
                        let w = format!(
                            "byte {} of the unpacked objects (container at byte {}): object cut short at the end of the file",
                            self.inner_off, self.container_at
                        );
                        self.inner_end = self.inner_at;
                        self.push(out, Outcome::Warning(w));
                    }
                }
                None => {}
            }
        }
        Ok(())
    }

    fn push(&mut self, out: &mut Vec<(u64, Outcome)>, o: Outcome) {
        self.objects += 1;
        self.counts.record(&o);
        out.push((self.objects, o));
    }

    /// Reads the file header; a damaged one is a warning and objects are looked for after it.
    fn header(&mut self) -> io::Result<Option<Outcome>> {
        self.read_outer(blf::FILE_HEADER_SIZE)?;
        match blf::file_header(&self.outer) {
            Ok(h) => {
                self.start_ns = h.start_ns;
                let size = (h.size as usize).min(1 << 20);
                self.read_outer(size)?;
                self.consume_outer(size.min(self.outer.len()));
                Ok(None)
            }
            Err(why) => Ok(Some(Outcome::Warning(format!("byte 0: {why}")))),
        }
    }

    /// Fills the outer buffer to at least `want` bytes (fewer at the end of the file).
    fn read_outer(&mut self, want: usize) -> io::Result<()> {
        while self.outer.len() < want && !self.eof {
            let chunk = self.src.fill_buf()?;
            if chunk.is_empty() {
                self.eof = true;
                break;
            }
            let n = chunk.len().min(want - self.outer.len());
            self.outer.extend_from_slice(&chunk[..n]);
            self.src.consume(n);
        }
        Ok(())
    }

    fn consume_outer(&mut self, n: usize) {
        self.outer.drain(..n);
        self.outer_off += n as u64;
    }

    /// Takes the next object of the file: a container's data goes to the inner buffer
    /// (`None`), another object is decoded; `None` too at the end of the file.
    fn next_outer(&mut self) -> io::Result<Option<Outcome>> {
        self.read_outer(blf::OBJECT_BASE + 3)?;
        loop {
            match blf::step(&self.outer, MAX_OBJECT) {
                Step::Object { skip, len } => {
                    self.consume_outer(skip);
                    let at = self.outer_off;
                    let outcome = if blf::object_head(&self.outer).is_some_and(|h| h.kind == blf::LOG_CONTAINER) {
                        self.unpack(at, len)
                    } else {
                        Some(decode_object(
                            &self.outer[..len],
                            self.start_ns,
                            &mut self.channels,
                            &mut self.ifaces,
                            || format!("byte {at}"),
                        ))
                    };
                    self.consume_outer(len);
                    return Ok(outcome);
                }
                Step::NeedMore if !self.eof => {
                    let want = match blf::object_head(self.outer.get(self.pad()..).unwrap_or_default()) {
                        Some(h) => self.pad() + h.size as usize,
                        None => self.outer.len() + blf::OBJECT_BASE + 3,
                    };
                    self.read_outer(want.max(self.outer.len() + 1))?;
                }
                Step::NeedMore => {
                    let (pad, len) = (self.pad(), self.outer.len());
                    let at = self.outer_off + pad as u64;
                    if self.outer.iter().all(|&b| b == 0) {
                        self.consume_outer(len);
                        return Ok(None);
                    }
                    let head = blf::object_head(&self.outer[pad..]);
                    let mut w = format!(
                        "byte {at}: object cut short at the end of the file ({} bytes)",
                        len - pad
                    );
                    if head.is_some_and(|h| h.kind == blf::LOG_CONTAINER) {
                        // A logger that stopped mid-write: read what the container holds.
                        self.consume_outer(pad);
                        if let Some(Outcome::Warning(more)) = self.unpack(at, len - pad) {
                            w = format!("{w}; {more}");
                        }
                    }
                    self.consume_outer(self.outer.len());
                    return Ok(Some(Outcome::Warning(w)));
                }
                Step::Bad { at, skip, why } => {
                    let w = format!("byte {}: {why}", self.outer_off + at as u64);
                    self.consume_outer(skip);
                    return Ok(Some(Outcome::Warning(w)));
                }
            }
        }
    }

    /// Padding before the signature at the start of the outer buffer (0 when none is seen).
    fn pad(&self) -> usize {
        (0..4)
            .find(|&i| self.outer.get(i..i + 4) == Some(&blf::OBJECT_SIGNATURE[..]))
            .unwrap_or(0)
    }

    /// Appends the data of the container at file byte `at` (`len` bytes at the start of
    /// the outer buffer) to the inner buffer; a warning when it cannot be unpacked.
    fn unpack(&mut self, at: u64, len: usize) -> Option<Outcome> {
        let (method, data) = match blf::container(&self.outer[..len]) {
            Ok(c) => c,
            Err(why) => return Some(Outcome::Warning(format!("container at byte {at}: {why}"))),
        };
        // Drop what was used; keep an object that continues in this container.
        self.inner.copy_within(self.inner_at..self.inner_end, 0);
        self.inner_end -= self.inner_at;
        self.inner_at = 0;
        self.container_at = at;
        match method {
            Compression::None => {
                self.inner.truncate(self.inner_end);
                self.inner.extend_from_slice(data);
                self.inner_end = self.inner.len();
            }
            Compression::Zlib => {
                let unpacked = blf::container_unpacked(&self.outer[..len]).unwrap_or(0) as usize;
                // Deflate unpacks to at most 1032 times its size: a larger size is damage.
                if unpacked as u64 <= MAX_UNPACKED.min(data.len() as u64 * 1032 + 1024) {
                    if self.inner.len() < self.inner_end + unpacked {
                        self.inner.resize(self.inner_end + unpacked, 0);
                    }
                    if let Some(n) = inflate_whole(&mut self.zlib, data, &mut self.inner[self.inner_end..]) {
                        self.inner_end += n;
                        return None;
                    }
                }
                // Not a sound stream within the room its header gives: inflated as a
                // stream instead, which keeps what comes before the damage.
                self.inner.truncate(self.inner_end);
                let mut z = flate2::read::ZlibDecoder::new(data).take(MAX_UNPACKED);
                let read = z.read_to_end(&mut self.inner);
                self.inner_end = self.inner.len();
                if let Err(e) = read {
                    // What was inflated before the damage is kept and read.
                    return Some(Outcome::Warning(format!(
                        "container at byte {at}: zlib data damaged or cut short ({e}); its objects after that are lost"
                    )));
                }
            }
        }
        None
    }

    /// The next object of the unpacked container data, when one lies whole in it.
    fn next_inner(&mut self) -> Option<Outcome> {
        let rest = &self.inner[self.inner_at..self.inner_end];
        if rest.is_empty() {
            return None;
        }
        let (used, outcome) = match blf::step(rest, MAX_OBJECT) {
            Step::Object { skip, len } => {
                let obj = &rest[skip..skip + len];
                let (off, c) = (self.inner_off + skip as u64, self.container_at);
                let o = decode_object(obj, self.start_ns, &mut self.channels, &mut self.ifaces, || {
                    format!("byte {off} of the unpacked objects (container at byte {c})")
                });
                (skip + len, Some(o))
            }
            Step::NeedMore => return None,
            Step::Bad { at, skip, why } => {
                let w = format!(
                    "byte {} of the unpacked objects (container at byte {}): {why}",
                    self.inner_off + at as u64,
                    self.container_at
                );
                (skip, Some(Outcome::Warning(w)))
            }
        };
        self.inner_at += used;
        self.inner_off += used as u64;
        outcome
    }
}

/// Inflates the whole zlib stream `data` in one call into `room` (written before, so
/// neither allocated nor zeroed again): the bytes it unpacked when the stream ends sound
/// in `room` and within [`MAX_UNPACKED`]; `None` for the streaming inflater to read the
/// same data with its located warning.
fn inflate_whole(z: &mut flate2::Decompress, data: &[u8], room: &mut [u8]) -> Option<usize> {
    z.reset(true);
    let status = z.decompress(data, room, flate2::FlushDecompress::Finish);
    let n = usize::try_from(z.total_out()).ok()?;
    (matches!(status, Ok(flate2::Status::StreamEnd)) && n as u64 <= MAX_UNPACKED).then_some(n)
}

/// One object as an outcome: its frame with the channel's interface, a skip for other
/// objects, a warning located by `at` for a damaged one.
fn decode_object(
    obj: &[u8],
    start_ns: u64,
    channels: &mut Vec<Option<u16>>,
    ifaces: &mut Interfaces,
    at: impl FnOnce() -> String,
) -> Outcome {
    match blf::object(obj, start_ns) {
        Ok(Object::Frame { channel, mut frame }) => {
            let slot = channel as usize;
            if channels.len() <= slot {
                channels.resize(slot + 1, None);
            }
            frame.iface = *channels[slot].get_or_insert_with(|| ifaces.intern(&blf::channel_name(channel)));
            Outcome::Frame(frame)
        }
        Ok(Object::Other(_)) => Outcome::Skip(SkipReason::Event),
        Err(why) => Outcome::Warning(format!("{}: {why}", at())),
    }
}

impl<R: BufRead> Iterator for BlfReader<R> {
    type Item = io::Result<(u64, Outcome)>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_line().transpose()
    }
}
