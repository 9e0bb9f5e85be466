//! Reading ASAM MDF4 bus-logging files: the block tree (`##HD` -> `##DG` -> `##CG` ->
//! `##CN`) is read once to find the CAN frame groups and the data blocks of each data group
//! (`##DT`, `##DZ` inflated and un-transposed, lists in `##DL` and `##HL`); then every data
//! group's records are streamed and merged by time (a sorted file keeps each frame kind in
//! its own data group), with the payloads of variable-length groups taken from their signal
//! data (`##SD`, or VLSD records of an unsorted group). The byte-level half is the core's
//! `canopen::log::mf4`.
//!
//! MDF needs random access (links are file offsets), so this reads a file, not a stream.
//! Memory holds the block index (one offset per data block), one chunk of each data group
//! (64 KiB) and at most one inflated `##DZ` block per data group, whatever the file's size.
//! A damaged block is a warning that says where (byte offsets); the rest is read.

use crate::frame::Interfaces;
use crate::log::mf4::{self, Block, Kind, Layout, Linear};
use crate::log::{Counts, Outcome};
use std::collections::{HashSet, VecDeque};
use std::io::{self, Read, Seek, SeekFrom};

/// A file MDF can be read from: random access.
pub trait Source: Read + Seek + Send {}
impl<T: Read + Seek + Send> Source for T {}

/// The largest block read whole (metadata, lists, `##DZ`): a larger length is damage.
const MAX_BLOCK: u64 = 64 << 20;
/// The most bytes one `##DZ` block may inflate to (a guard against zlib bombs).
const MAX_UNPACKED: u64 = 64 << 20;
/// Bytes of a `##DT` block read at a time.
const CHUNK: u64 = 1 << 16;
/// The most blocks followed along one chain (groups, channels, lists): more is a loop.
const MAX_CHAIN: usize = 1 << 16;
/// The longest variable-length payload taken.
const MAX_VLSD: usize = 1 << 20;

/// Streams an MDF4 file's CAN frames as `(number, Outcome)`, in time order.
pub struct Mf4Reader<S> {
    src: S,
    opened: bool,
    start_ns: u64,
    streams: Vec<Stream>,
    heads: Vec<Option<(u64, crate::frame::Frame)>>,
    pending: VecDeque<Outcome>,
    buses: Vec<(u64, u16)>,
    /// The group and channel blocks read (a loop of links is read once).
    visited: HashSet<u64>,
    ifaces: Interfaces,
    counts: Counts,
    n: u64,
}

impl<S: Source> Mf4Reader<S> {
    /// A reader of the MDF file `src` (its blocks are read on the first call).
    pub fn new(src: S) -> Self {
        Mf4Reader {
            src,
            opened: false,
            start_ns: 0,
            streams: Vec::new(),
            heads: Vec::new(),
            pending: VecDeque::new(),
            buses: Vec::new(),
            visited: HashSet::new(),
            ifaces: Interfaces::default(),
            counts: Counts::default(),
            n: 0,
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

    /// The next outcome's number (1-based) and outcome; `None` at the end of the file.
    pub fn next_line(&mut self) -> io::Result<Option<(u64, Outcome)>> {
        let mut one = Vec::with_capacity(1);
        self.fill(&mut one, 1)?;
        Ok(one.pop())
    }

    /// Appends outcomes to `out` until it holds `max` or the file ends.
    pub fn fill(&mut self, out: &mut Vec<(u64, Outcome)>, max: usize) -> io::Result<()> {
        if !self.opened {
            self.opened = true;
            let mut warn = Vec::new();
            self.open(&mut warn)?;
            self.pending.extend(warn.into_iter().map(Outcome::Warning));
            self.heads = vec![None; self.streams.len()];
        }
        while out.len() < max {
            if let Some(o) = self.pending.pop_front() {
                self.push(out, o);
                continue;
            }
            if let [stream] = &mut self.streams[..] {
                // One data group: its records in their order, nothing to merge.
                let o = match stream.next(&mut self.src, self.start_ns)? {
                    Some(Ok((bus, frame))) => self.framed(bus, frame),
                    Some(Err(w)) => Outcome::Warning(w),
                    None => break,
                };
                self.push(out, o);
                continue;
            }
            for (stream, head) in self.streams.iter_mut().zip(&mut self.heads) {
                if head.is_none() && stream.live() {
                    match stream.next(&mut self.src, self.start_ns)? {
                        Some(Ok(frame)) => *head = Some(frame),
                        Some(Err(w)) => self.pending.push_back(Outcome::Warning(w)),
                        None => {}
                    }
                }
            }
            if !self.pending.is_empty() {
                continue;
            }
            let first = self
                .heads
                .iter()
                .enumerate()
                .filter_map(|(i, h)| h.as_ref().map(|(_, f)| (f.ts_ns, i)))
                .min();
            let Some((_, i)) = first else { break };
            let Some((bus, frame)) = self.heads[i].take() else {
                break;
            };
            let o = self.framed(bus, frame);
            self.push(out, o);
        }
        Ok(())
    }

    /// The outcome of a frame on bus channel `bus`: the frame with its interface.
    fn framed(&mut self, bus: u64, mut frame: crate::frame::Frame) -> Outcome {
        frame.iface = match self.buses.iter().find(|(b, _)| *b == bus) {
            Some(&(_, iface)) => iface,
            None => {
                let iface = self.ifaces.intern(&mf4::channel_name(bus));
                self.buses.push((bus, iface));
                iface
            }
        };
        Outcome::Frame(frame)
    }

    fn push(&mut self, out: &mut Vec<(u64, Outcome)>, o: Outcome) {
        self.n += 1;
        self.counts.record(&o);
        out.push((self.n, o));
    }

    /// Reads the block tree: the start time and a stream per data group holding CAN frames.
    fn open(&mut self, warn: &mut Vec<String>) -> io::Result<()> {
        let mut id = [0u8; mf4::ID_SIZE];
        self.src.seek(SeekFrom::Start(0))?;
        if let Err(e) = self.src.read_exact(&mut id) {
            return match e.kind() {
                io::ErrorKind::UnexpectedEof => {
                    warn.push("byte 0: identification block cut short".into());
                    Ok(())
                }
                _ => Err(e),
            };
        }
        if let Err(why) = mf4::id_block(&id) {
            warn.push(format!("byte 0: {why}"));
            return Ok(());
        }
        let at = mf4::ID_SIZE as u64;
        let hd = match read_block(&mut self.src, at, b"##HD")? {
            Ok(b) => b,
            Err(why) => {
                warn.push(why);
                return Ok(());
            }
        };
        let Ok(hd) = Block::parse(&hd) else {
            return Ok(());
        };
        self.start_ns = mf4::start_ns(&hd).unwrap_or(0);
        let mut dg_at = hd.link(0);
        while dg_at != 0 {
            if !self.first_visit(dg_at) {
                warn.push(format!(
                    "byte {dg_at}: a data group linked twice (a loop); not read again"
                ));
                break;
            }
            let bytes = match read_block(&mut self.src, dg_at, b"##DG")? {
                Ok(b) => b,
                Err(why) => {
                    warn.push(format!("{why}; the data groups after it are not read"));
                    break;
                }
            };
            let dg = match Block::parse(&bytes).and_then(|b| mf4::data_group(&b)) {
                Ok(dg) => dg,
                Err(why) => {
                    warn.push(format!("byte {dg_at}: {why}; the data groups after it are not read"));
                    break;
                }
            };
            if let Some(stream) = self.data_group(dg_at, &dg, warn)? {
                self.streams.push(stream);
            }
            dg_at = dg.next;
        }
        Ok(())
    }

    /// The stream of one data group, `None` when it holds no CAN frame group.
    fn data_group(&mut self, at: u64, dg: &mf4::DataGroup, warn: &mut Vec<String>) -> io::Result<Option<Stream>> {
        let mut groups = Vec::new();
        let mut cg_at = dg.first_group;
        while cg_at != 0 && groups.len() < MAX_CHAIN {
            if !self.first_visit(cg_at) {
                warn.push(format!(
                    "byte {cg_at}: a channel group linked twice (a loop); not read again"
                ));
                break;
            }
            let bytes = match read_block(&mut self.src, cg_at, b"##CG")? {
                Ok(b) => b,
                Err(why) => {
                    warn.push(format!("{why}; data group at byte {at} not read"));
                    return Ok(None);
                }
            };
            let cg = match Block::parse(&bytes).and_then(|b| mf4::group(&b)) {
                Ok(cg) => cg,
                Err(why) => {
                    warn.push(format!("byte {cg_at}: {why}; data group at byte {at} not read"));
                    return Ok(None);
                }
            };
            let what = if cg.vlsd {
                What::Vlsd { next: 0, last: None }
            } else {
                match self.layout(cg_at, &cg)? {
                    Ok(Some(frames)) => What::Frames(Box::new(frames)),
                    Ok(None) => What::Other,
                    Err(why) => {
                        warn.push(why);
                        What::Other
                    }
                }
            };
            groups.push(Cg {
                record_id: cg.record_id,
                size: cg.record_size,
                what,
            });
            cg_at = cg.next;
        }
        if !groups.iter().any(|g| matches!(g.what, What::Frames(_))) {
            return Ok(None);
        }
        if dg.record_id_size == 0 && groups.len() > 1 {
            warn.push(format!(
                "byte {at}: several channel groups in a data group without record ids; not read"
            ));
            return Ok(None);
        }
        let blocks = block_list(&mut self.src, dg.data, warn)?;
        Ok(Some(Stream {
            at,
            record_id_size: dg.record_id_size,
            bytes: Bytes::new(blocks),
            groups,
            payload: Vec::new(),
            records: 0,
            held: VecDeque::new(),
            done: false,
        }))
    }

    /// The layout of a CAN frame group (`None`: a group of something else).
    fn layout(&mut self, at: u64, cg: &mf4::Group) -> io::Result<Result<Option<Frames>, String>> {
        let mut channels = Vec::new();
        let mut chains = vec![cg.first_channel];
        while let Some(mut cn_at) = chains.pop() {
            while cn_at != 0 && channels.len() < MAX_CHAIN && self.first_visit(cn_at) {
                let bytes = match read_block(&mut self.src, cn_at, b"##CN")? {
                    Ok(b) => b,
                    Err(why) => return Ok(Err(format!("{why}; channel group at byte {at} not read"))),
                };
                let cn = match Block::parse(&bytes).and_then(|b| mf4::channel(&b)) {
                    Ok(cn) => cn,
                    Err(why) => return Ok(Err(format!("byte {cn_at}: {why}; channel group at byte {at} not read"))),
                };
                let name = self.text(cn.name)?;
                if cn.composition != 0 && chains.len() < 4 {
                    chains.push(cn.composition);
                }
                channels.push((name, cn));
                cn_at = cn.next;
            }
        }
        let acq = self.text(cg.acq_name)?;
        let Some(kind) = channels
            .iter()
            .find_map(|(n, _)| Kind::of(n))
            .or_else(|| Kind::of(&acq))
        else {
            return Ok(Ok(None));
        };
        let Some((_, master)) = channels
            .iter()
            .find(|(_, c)| c.cn_type == mf4::CN_MASTER && c.sync_type == 1)
        else {
            return Ok(Err(format!(
                "byte {at}: CAN frame group without a time channel; not read"
            )));
        };
        let conv = if master.conversion == 0 {
            Linear::IDENTITY
        } else {
            let bytes = match read_block(&mut self.src, master.conversion, b"##CC")? {
                Ok(b) => b,
                Err(why) => return Ok(Err(format!("{why}; channel group at byte {at} not read"))),
            };
            match Block::parse(&bytes).and_then(|b| mf4::conversion(&b)) {
                Ok(c) => c,
                Err(why) => return Ok(Err(format!("byte {}: {why}; not read", master.conversion))),
            }
        };
        let mut layout = Layout::new(kind, (master.field, conv));
        let mut vlsd = Vlsd::None;
        for (name, cn) in &channels {
            let is_vlsd = cn.cn_type == mf4::CN_VLSD;
            layout.add(name, cn.field, is_vlsd);
            if is_vlsd && name.ends_with(b"DataBytes") {
                vlsd = self.signal_data(cn.data)?;
            }
        }
        if let Err(why) = layout.check() {
            return Ok(Err(format!("byte {at}: {why}; not read")));
        }
        Ok(Ok(Some(Frames { layout, vlsd })))
    }

    /// Where the signal data of a VLSD channel lies: VLSD records of a channel group of
    /// the same data group, or data blocks of its own.
    fn signal_data(&mut self, at: u64) -> io::Result<Vlsd> {
        let mut head = [0u8; mf4::HEAD_SIZE];
        if at == 0 || seek_read(&mut self.src, at, &mut head)?.is_err() {
            return Ok(Vlsd::None);
        }
        if head.starts_with(b"##CG") {
            if let Ok(Ok(bytes)) = read_block(&mut self.src, at, b"##CG")
                && let Ok(cg) = Block::parse(&bytes).and_then(|b| mf4::group(&b))
            {
                return Ok(Vlsd::Group(cg.record_id));
            }
            return Ok(Vlsd::None);
        }
        let mut warn = Vec::new();
        let blocks = block_list(&mut self.src, at, &mut warn)?;
        Ok(Vlsd::Stream {
            bytes: Box::new(Bytes::new(blocks)),
            offset: 0,
        })
    }

    /// Whether the block at `at` is met for the first time (links of a damaged file may
    /// loop).
    fn first_visit(&mut self, at: u64) -> bool {
        self.visited.insert(at)
    }

    /// The text of the `##TX` block at `at` (empty when none or damaged).
    fn text(&mut self, at: u64) -> io::Result<Vec<u8>> {
        if at == 0 {
            return Ok(Vec::new());
        }
        Ok(match read_block(&mut self.src, at, b"##TX")? {
            Ok(b) => Block::parse(&b).map(|b| mf4::text(&b).to_vec()).unwrap_or_default(),
            Err(_) => Vec::new(),
        })
    }
}

impl<S: Source> Iterator for Mf4Reader<S> {
    type Item = io::Result<(u64, Outcome)>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_line().transpose()
    }
}

/// Reads `buf.len()` bytes at `at`; `Err(())` when the file ends first.
fn seek_read<S: Source>(src: &mut S, at: u64, buf: &mut [u8]) -> io::Result<Result<(), ()>> {
    src.seek(SeekFrom::Start(at))?;
    match src.read_exact(buf) {
        Ok(()) => Ok(Ok(())),
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Ok(Err(())),
        Err(e) => Err(e),
    }
}

/// The whole block at `at`, which must be `want` (`##DT`, `##SD`, `##DZ`, `##DL` and `##HL`
/// are told apart by the caller: `want` `b"##"` takes any); a located reason when it
/// cannot be read.
fn read_block<S: Source>(src: &mut S, at: u64, want: &[u8]) -> io::Result<Result<Vec<u8>, String>> {
    let mut head = [0u8; mf4::HEAD_SIZE];
    if seek_read(src, at, &mut head)?.is_err() {
        return Ok(Err(format!("byte {at}: link past the end of the file")));
    }
    let h = match mf4::head(&head) {
        Ok(h) => h,
        Err(why) => return Ok(Err(format!("byte {at}: {why}"))),
    };
    if !h.id.starts_with(want) {
        let id = String::from_utf8_lossy(&h.id).into_owned();
        let want = String::from_utf8_lossy(want);
        return Ok(Err(format!("byte {at}: a {id} block where a {want} block belongs")));
    }
    if h.len > MAX_BLOCK {
        return Ok(Err(format!("byte {at}: block length {} too large", h.len)));
    }
    let mut bytes = vec![0u8; h.len as usize];
    bytes[..mf4::HEAD_SIZE].copy_from_slice(&head);
    match src.read_exact(&mut bytes[mf4::HEAD_SIZE..]) {
        Ok(()) => Ok(Ok(bytes)),
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
            Ok(Err(format!("byte {at}: block cut short at the end of the file")))
        }
        Err(e) => Err(e),
    }
}

/// The data blocks (`##DT`, `##SD`, `##DZ`) the link `at` leads to, through `##HL` and
/// `##DL` lists. Damage ends the list with a warning.
fn block_list<S: Source>(src: &mut S, at: u64, warn: &mut Vec<String>) -> io::Result<Vec<u64>> {
    let mut head = [0u8; mf4::HEAD_SIZE];
    if at == 0 {
        return Ok(Vec::new());
    }
    if seek_read(src, at, &mut head)?.is_err() {
        warn.push(format!("byte {at}: link past the end of the file"));
        return Ok(Vec::new());
    }
    let mut dl_at = match &head[..4] {
        b"##DT" | b"##SD" | b"##DZ" => return Ok(vec![at]),
        b"##HL" => match read_block(src, at, b"##HL")? {
            Ok(b) => Block::parse(&b).map(|b| b.link(0)).unwrap_or(0),
            Err(why) => {
                warn.push(why);
                return Ok(Vec::new());
            }
        },
        _ => at,
    };
    let mut blocks = Vec::new();
    let mut lists = HashSet::new();
    while dl_at != 0 && lists.len() < MAX_CHAIN {
        if !lists.insert(dl_at) {
            warn.push(format!(
                "byte {dl_at}: a data list linked twice (a loop); not read again"
            ));
            break;
        }
        let list = match read_block(src, dl_at, b"##DL")? {
            Ok(b) => Block::parse(&b).and_then(|b| mf4::data_list(&b)),
            Err(why) => {
                warn.push(format!("{why}; the data blocks after it are not read"));
                break;
            }
        };
        match list {
            Ok((next, links)) => {
                blocks.extend(links.into_iter().filter(|&l| l != 0));
                dl_at = next;
            }
            Err(why) => {
                warn.push(format!("byte {dl_at}: {why}; the data blocks after it are not read"));
                break;
            }
        }
    }
    Ok(blocks)
}

/// One data group's bytes, block after block, as one stream.
struct Bytes {
    blocks: Vec<u64>,
    next: usize,
    /// What is left of the `##DT`/`##SD` block being read: (file byte, bytes).
    plain: (u64, u64),
    buf: Vec<u8>,
    at: usize,
    /// File byte of the block being read (for warnings).
    block_at: u64,
}

impl Bytes {
    fn new(blocks: Vec<u64>) -> Bytes {
        Bytes {
            blocks,
            next: 0,
            plain: (0, 0),
            buf: Vec::new(),
            at: 0,
            block_at: 0,
        }
    }

    fn available(&self) -> &[u8] {
        &self.buf[self.at..]
    }

    fn consume(&mut self, n: usize) {
        self.at = (self.at + n).min(self.buf.len());
    }

    /// Makes at least `want` bytes available; false when the data ends first. A damaged
    /// block is a warning and the next block is read.
    #[inline(always)]
    fn fill<S: Source>(&mut self, src: &mut S, want: usize, warn: &mut Vec<String>) -> io::Result<bool> {
        if self.buf.len() - self.at >= want {
            return Ok(true);
        }
        self.refill(src, want, warn)
    }

    /// [`Bytes::fill`] when the buffer holds fewer than `want` bytes: reads blocks on.
    fn refill<S: Source>(&mut self, src: &mut S, want: usize, warn: &mut Vec<String>) -> io::Result<bool> {
        while self.buf.len() - self.at < want {
            if self.at > 0 {
                self.buf.drain(..self.at);
                self.at = 0;
            }
            let (pos, left) = self.plain;
            if left > 0 {
                let n = left.min(CHUNK).max((want - self.buf.len()) as u64).min(left) as usize;
                let start = self.buf.len();
                self.buf.resize(start + n, 0);
                if seek_read(src, pos, &mut self.buf[start..])?.is_err() {
                    self.buf.truncate(start);
                    self.plain = (0, 0);
                    warn.push(format!(
                        "byte {}: data block cut short at the end of the file",
                        self.block_at
                    ));
                    continue;
                }
                self.plain = (pos + n as u64, left - n as u64);
                continue;
            }
            let Some(&at) = self.blocks.get(self.next) else {
                return Ok(false);
            };
            self.next += 1;
            self.block_at = at;
            if let Err(why) = self.open_block(src, at)? {
                warn.push(why);
            }
        }
        Ok(true)
    }

    /// Starts reading the data block at `at`: a plain one in chunks, a `##DZ` one inflated.
    fn open_block<S: Source>(&mut self, src: &mut S, at: u64) -> io::Result<Result<(), String>> {
        let mut head = [0u8; mf4::HEAD_SIZE];
        if seek_read(src, at, &mut head)?.is_err() {
            return Ok(Err(format!("byte {at}: link past the end of the file")));
        }
        let h = match mf4::head(&head) {
            Ok(h) => h,
            Err(why) => return Ok(Err(format!("byte {at}: {why}"))),
        };
        match &h.id {
            b"##DT" | b"##SD" => {
                let skip = mf4::HEAD_SIZE as u64 + h.links * 8;
                self.plain = (at + skip, h.len - skip);
                Ok(Ok(()))
            }
            b"##DZ" => {
                let bytes = match read_block(src, at, b"##DZ")? {
                    Ok(b) => b,
                    Err(why) => return Ok(Err(why)),
                };
                let z = match Block::parse(&bytes).and_then(|b| mf4::zipped(&b)) {
                    Ok(z) => z,
                    Err(why) => return Ok(Err(format!("byte {at}: {why}"))),
                };
                Ok(self.inflate(at, &z))
            }
            other => Ok(Err(format!(
                "byte {at}: a {} block where a data block belongs",
                String::from_utf8_lossy(other)
            ))),
        }
    }

    fn inflate(&mut self, at: u64, z: &mf4::Zipped) -> Result<(), String> {
        if z.original_len > MAX_UNPACKED {
            return Err(format!(
                "byte {at}: ##DZ block of {} bytes unpacked, too large",
                z.original_len
            ));
        }
        let mut data = Vec::with_capacity(z.original_len as usize);
        let mut inflater = flate2::read::ZlibDecoder::new(z.data).take(z.original_len);
        let damaged = inflater.read_to_end(&mut data).is_err() || data.len() as u64 != z.original_len;
        match z.transposed {
            Some(cols) if !damaged => mf4::untranspose(&data, cols as usize, &mut self.buf),
            // Transposed data cut short cannot be put back in rows.
            Some(_) => {}
            None => self.buf.extend_from_slice(&data),
        }
        if damaged {
            return Err(format!(
                "byte {at}: ##DZ zlib data damaged or cut short; its records are lost"
            ));
        }
        Ok(())
    }
}

/// A channel group of a data group and what its records are.
struct Cg {
    record_id: u64,
    size: u64,
    what: What,
}

enum What {
    /// CAN frames.
    Frames(Box<Frames>),
    /// Variable-length signal data of another group: the offset of the next record and
    /// the last one read (its offset and bytes).
    Vlsd { next: u64, last: Option<(u64, Vec<u8>)> },
    /// Something else: passed over.
    Other,
}

/// A CAN frame group: its layout and where its payloads lie.
struct Frames {
    layout: Layout,
    vlsd: Vlsd,
}

enum Vlsd {
    None,
    /// Signal data blocks of their own, read along with the records; `offset`: of the next
    /// entry.
    Stream {
        bytes: Box<Bytes>,
        offset: u64,
    },
    /// VLSD records of the group with this record id.
    Group(u64),
}

/// The records of one data group.
struct Stream {
    at: u64,
    record_id_size: u8,
    bytes: Bytes,
    groups: Vec<Cg>,
    payload: Vec<u8>,
    records: u64,
    /// Outcomes read and not yet given (warnings of block damage before a record).
    held: VecDeque<Result<(u64, crate::frame::Frame), String>>,
    done: bool,
}

type Next = Option<Result<(u64, crate::frame::Frame), String>>;

impl Stream {
    /// Whether it has more to give.
    fn live(&self) -> bool {
        !self.done || !self.held.is_empty()
    }

    /// The next frame of the data group (or a warning); `None` at its end.
    fn next<S: Source>(&mut self, src: &mut S, start_ns: u64) -> io::Result<Next> {
        if let Some(held) = self.held.pop_front() {
            return Ok(Some(held));
        }
        let mut warn = Vec::new();
        let got = self.step(src, start_ns, &mut warn)?;
        if warn.is_empty() {
            return Ok(got);
        }
        // Block damage first, then the record read after it.
        self.held.extend(warn.into_iter().map(Err));
        self.held.extend(got);
        Ok(self.held.pop_front())
    }

    fn step<S: Source>(&mut self, src: &mut S, start_ns: u64, warn: &mut Vec<String>) -> io::Result<Next> {
        loop {
            if self.done {
                return Ok(None);
            }
            let idx = if self.record_id_size == 0 {
                0
            } else {
                if !self.bytes.fill(src, self.record_id_size as usize, warn)? {
                    return self.end();
                }
                let rid = mf4::record_id(self.bytes.available(), self.record_id_size).unwrap_or(0);
                self.bytes.consume(self.record_id_size as usize);
                match self.groups.iter().position(|g| g.record_id == rid) {
                    Some(i) => i,
                    None => {
                        self.done = true;
                        return Ok(Some(Err(format!(
                            "data group at byte {}: record {} has the id {rid} of no channel group; the rest of the group is not read",
                            self.at,
                            self.records + 1
                        ))));
                    }
                }
            };
            self.records += 1;
            if let What::Vlsd { next, last } = &mut self.groups[idx].what {
                if !self.bytes.fill(src, 4, warn)? {
                    return self.end();
                }
                let len = mf4::record_id(self.bytes.available(), 4).unwrap_or(0) as usize;
                if len > MAX_VLSD || !self.bytes.fill(src, 4 + len, warn)? {
                    return self.end();
                }
                let entry = self.bytes.available()[4..4 + len].to_vec();
                *last = Some((*next, entry));
                *next += 4 + len as u64;
                self.bytes.consume(4 + len);
                continue;
            }
            let size = self.groups[idx].size as usize;
            if !self.bytes.fill(src, size, warn)? {
                return self.end();
            }
            // The other groups (VLSD records) beside this one.
            let (before, rest) = self.groups.split_at_mut(idx);
            let Some((
                Cg {
                    what: What::Frames(frames),
                    ..
                },
                after,
            )) = rest.split_first_mut()
            else {
                self.bytes.consume(size);
                continue;
            };
            // The record is read in place: `buf` starts with it.
            let buf = self.bytes.available();
            let rec = &buf[..size];
            let Frames { layout, vlsd } = &mut **frames;
            let payload = match vlsd {
                Vlsd::None => Ok(None),
                Vlsd::Group(rid) => {
                    let want = layout.vlsd_offset(rec);
                    let rid = *rid;
                    let entry = before.iter().chain(after.iter()).find_map(|g| match &g.what {
                        What::Vlsd {
                            last: Some((off, bytes)),
                            ..
                        } if g.record_id == rid && Some(*off) == want => Some(bytes),
                        _ => None,
                    });
                    match entry {
                        Some(bytes) => {
                            self.payload.clear();
                            self.payload.extend_from_slice(bytes);
                            Ok(Some(()))
                        }
                        None => Err("its signal data record is missing"),
                    }
                }
                Vlsd::Stream { bytes, offset } => {
                    let want = layout.vlsd_offset(rec).unwrap_or(u64::MAX);
                    signal_entry(src, bytes, offset, want, &mut self.payload, warn)?.map(Some)
                }
            };
            let result = payload.and_then(|p| {
                let vlsd = p.map(|()| self.payload.as_slice());
                layout.frame_in(buf, size, vlsd, start_ns)
            });
            self.bytes.consume(size);
            return Ok(Some(result.map_err(|why| {
                format!("data group at byte {}, record {}: {why}", self.at, self.records)
            })));
        }
    }

    /// The end of the group's data: a warning when a record was cut short.
    fn end(&mut self) -> io::Result<Next> {
        self.done = true;
        if self.bytes.available().iter().any(|&b| b != 0) {
            return Ok(Some(Err(format!(
                "data group at byte {}: record {} cut short at the end of its data",
                self.at, self.records
            ))));
        }
        Ok(None)
    }
}

/// Reads the signal data entry at offset `want` into `out`, passing over entries before it.
fn signal_entry<S: Source>(
    src: &mut S,
    bytes: &mut Bytes,
    offset: &mut u64,
    want: u64,
    out: &mut Vec<u8>,
    warn: &mut Vec<String>,
) -> io::Result<Result<(), &'static str>> {
    loop {
        if *offset > want {
            return Ok(Err("its signal data offset lies before the data read"));
        }
        if !bytes.fill(src, 4, warn)? {
            return Ok(Err("its signal data ends before its offset"));
        }
        let len = mf4::record_id(bytes.available(), 4).unwrap_or(0) as usize;
        if len > MAX_VLSD || !bytes.fill(src, 4 + len, warn)? {
            return Ok(Err("its signal data ends before its offset"));
        }
        let here = *offset;
        *offset += 4 + len as u64;
        if here == want {
            out.clear();
            out.extend_from_slice(&bytes.available()[4..4 + len]);
            bytes.consume(4 + len);
            return Ok(Ok(()));
        }
        bytes.consume(4 + len);
    }
}
