//! The byte-level half of ASAM MDF4 bus logging (the `CAN_DataFrame`, `CAN_RemoteFrame` and
//! `CAN_ErrorFrame` channel groups written by asammdf, python-can's `MF4Writer` and CAN
//! loggers): block headers, the channel and conversion blocks that describe a record, the
//! data block lists, undoing a transposed `##DZ` block and a record as a [`Frame`]. The
//! file IO (following links, inflating) lives in cotui's `logio`.
//!
//! Every block starts with `##XX`, a reserved word, its length and its link count; links
//! are file offsets (0: none). Never panics: a short or inconsistent block is an error.

use super::asc::CAN_ERR_BUSERROR;
use crate::frame::{FD_LENS, Flags, Frame};

/// The first eight bytes of an MDF file (the `##ID` block has no block header).
pub const FILE_ID: &[u8; 8] = b"MDF     ";

/// Size of the identification block at the start of the file.
pub const ID_SIZE: usize = 64;

/// Size of a block header: `##XX`, reserved, length, link count.
pub const HEAD_SIZE: usize = 24;

/// The header of a block: its id (`b"##DT"`), whole length and link count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Head {
    /// The block's four-byte id.
    pub id: [u8; 4],
    /// Length of the whole block, header included.
    pub len: u64,
    /// Number of links after the header.
    pub links: u64,
}

/// Reads a block header from the start of `b`.
pub fn head(b: &[u8]) -> Result<Head, &'static str> {
    let id: [u8; 4] = b
        .get(..4)
        .and_then(|s| s.try_into().ok())
        .ok_or("block header cut short")?;
    if &id[..2] != b"##" {
        return Err("no block id (`##`) where a link points");
    }
    let len = u64_at(b, 8).ok_or("block header cut short")?;
    let links = u64_at(b, 16).ok_or("block header cut short")?;
    if links > (1 << 24) || len < HEAD_SIZE as u64 + links * 8 {
        return Err("block length smaller than its links");
    }
    Ok(Head { id, len, links })
}

/// One whole block: its links and its data.
#[derive(Clone, Copy, Debug)]
pub struct Block<'a> {
    /// The block's id (`b"##CG"`).
    pub id: [u8; 4],
    links: &'a [u8],
    /// The data after the links.
    pub data: &'a [u8],
}

impl<'a> Block<'a> {
    /// The block in `b` (header, links and data; `b` may run past its end).
    pub fn parse(b: &'a [u8]) -> Result<Block<'a>, &'static str> {
        let h = head(b)?;
        let len = usize::try_from(h.len).map_err(|_| "block too long")?;
        let whole = b.get(..len).ok_or("block cut short")?;
        let links_end = HEAD_SIZE + h.links as usize * 8;
        Ok(Block {
            id: h.id,
            links: &whole[HEAD_SIZE..links_end],
            data: &whole[links_end..],
        })
    }
    /// Link `i` (0 when absent or null).
    pub fn link(&self, i: usize) -> u64 {
        u64_at(self.links, i * 8).unwrap_or(0)
    }
    /// Number of links.
    pub fn link_count(&self) -> usize {
        self.links.len() / 8
    }
}

/// The version number of the `##ID` block at the start of `b` (410 for 4.10).
pub fn id_block(b: &[u8]) -> Result<u16, &'static str> {
    if !b.starts_with(FILE_ID) {
        return Err("not an MDF file (no `MDF     ` file id)");
    }
    let v = u16_at(b, 28).ok_or("identification block cut short")?;
    if !(400..500).contains(&v) {
        return Err("not an MDF 4 file (only version 4.x is read)");
    }
    Ok(v)
}

/// The measurement's start (ns since the Unix epoch) from the `##HD` block.
pub fn start_ns(hd: &Block) -> Result<u64, &'static str> {
    u64_at(hd.data, 0).ok_or("##HD block cut short")
}

/// How a channel's value is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataType {
    /// Unsigned integer, little or big endian.
    Uint { be: bool },
    /// Signed integer, little or big endian.
    Int { be: bool },
    /// IEEE float (32 or 64 bits), little or big endian.
    Float { be: bool },
    /// A byte array (or a string, read as bytes).
    Bytes,
}

/// Where a channel's value lies in a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// Byte offset in the record (after the record id).
    pub byte: u32,
    /// Bit offset in that byte (0..7).
    pub bit: u8,
    /// Width in bits.
    pub bits: u32,
    /// How the value is stored.
    pub kind: DataType,
}

impl Field {
    fn span<'r>(&self, rec: &'r [u8]) -> Option<&'r [u8]> {
        let n = (u64::from(self.bit) + u64::from(self.bits)).div_ceil(8);
        let start = self.byte as usize;
        rec.get(start..start.checked_add(usize::try_from(n).ok()?)?)
    }
    /// The value as an unsigned integer (integers up to 64 bits).
    pub fn uint(&self, rec: &[u8]) -> Option<u64> {
        let le = !matches!(self.kind, DataType::Uint { be: true } | DataType::Int { be: true });
        let width = u32::from(self.bit) + self.bits;
        // Little endian, at most 8 bytes and 8 bytes of record from its first: one load,
        // the bytes past the field shifted and masked away.
        if le
            && self.bits > 0
            && width <= 64
            && let Some(word) = rec.get(self.byte as usize..).and_then(|r| r.first_chunk::<8>())
        {
            let v = u64::from_le_bytes(*word) >> self.bit;
            return Some(if self.bits >= 64 {
                v
            } else {
                v & ((1u64 << self.bits) - 1)
            });
        }
        let bytes = self.span(rec)?;
        if bytes.len() > 8 || self.bits == 0 {
            return (self.bits == 0).then_some(0);
        }
        let mut raw = [0u8; 8];
        let be = matches!(self.kind, DataType::Uint { be: true } | DataType::Int { be: true });
        let v = if be {
            raw[8 - bytes.len()..].copy_from_slice(bytes);
            u64::from_be_bytes(raw) >> ((bytes.len() * 8) as u32 - self.bits - u32::from(self.bit))
        } else {
            raw[..bytes.len()].copy_from_slice(bytes);
            u64::from_le_bytes(raw) >> self.bit
        };
        Some(if self.bits >= 64 {
            v
        } else {
            v & ((1u64 << self.bits) - 1)
        })
    }
    /// The value as a float (floats of 32 or 64 bits, integers converted).
    pub fn float(&self, rec: &[u8]) -> Option<f64> {
        match self.kind {
            DataType::Float { be } => {
                let b = self.span(rec)?;
                match (self.bits, be) {
                    (64, false) => Some(f64::from_le_bytes(b.try_into().ok()?)),
                    (64, true) => Some(f64::from_be_bytes(b.try_into().ok()?)),
                    (32, false) => Some(f64::from(f32::from_le_bytes(b.try_into().ok()?))),
                    (32, true) => Some(f64::from(f32::from_be_bytes(b.try_into().ok()?))),
                    _ => None,
                }
            }
            DataType::Int { .. } => {
                let v = self.uint(rec)?;
                let shift = 64 - self.bits.clamp(1, 64);
                Some((((v << shift) as i64) >> shift) as f64)
            }
            DataType::Uint { .. } => self.uint(rec).map(|v| v as f64),
            DataType::Bytes => None,
        }
    }
    /// The value's bytes (byte-aligned fields).
    pub fn bytes<'r>(&self, rec: &'r [u8]) -> Option<&'r [u8]> {
        if self.bit != 0 {
            return None;
        }
        self.span(rec)
    }
}

/// What a `##CN` block says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Channel {
    /// The next channel of the group (0: last).
    pub next: u64,
    /// The first channel of its composition (a structure's members), 0: none.
    pub composition: u64,
    /// Its name (`##TX`).
    pub name: u64,
    /// Its conversion (`##CC`), 0: none.
    pub conversion: u64,
    /// Its signal data (`##SD`, `##DL`, `##DZ`, `##HL`, or the `##CG` of VLSD records).
    pub data: u64,
    /// 0 fixed, 1 variable length (VLSD), 2 master, 3 virtual master, ...
    pub cn_type: u8,
    /// 1: time.
    pub sync_type: u8,
    /// Where its value lies.
    pub field: Field,
}

/// Channel type of a variable-length signal: the record holds an offset into signal data.
pub const CN_VLSD: u8 = 1;
/// Channel type of the master (time) channel.
pub const CN_MASTER: u8 = 2;

/// Reads a `##CN` block.
pub fn channel(cn: &Block) -> Result<Channel, &'static str> {
    if cn.id != *b"##CN" {
        return Err("expected a ##CN block");
    }
    let d = cn.data;
    let short = "##CN block cut short";
    let kind = match *d.get(2).ok_or(short)? {
        0 => DataType::Uint { be: false },
        1 => DataType::Uint { be: true },
        2 => DataType::Int { be: false },
        3 => DataType::Int { be: true },
        4 => DataType::Float { be: false },
        5 => DataType::Float { be: true },
        _ => DataType::Bytes,
    };
    Ok(Channel {
        next: cn.link(0),
        composition: cn.link(1),
        name: cn.link(2),
        conversion: cn.link(4),
        data: cn.link(5),
        cn_type: *d.first().ok_or(short)?,
        sync_type: *d.get(1).ok_or(short)?,
        field: Field {
            byte: u32_at(d, 4).ok_or(short)?,
            bit: *d.get(3).ok_or(short)? & 7,
            bits: u32_at(d, 8).ok_or(short)?,
            kind,
        },
    })
}

/// The text of a `##TX` (or `##MD`) block, up to its first NUL.
pub fn text<'a>(tx: &Block<'a>) -> &'a [u8] {
    let d = tx.data;
    &d[..d.iter().position(|&b| b == 0).unwrap_or(d.len())]
}

/// A time conversion `phys = offset + factor * raw` (`##CC` identity or linear).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear {
    /// Added.
    pub offset: f64,
    /// Multiplied.
    pub factor: f64,
}

impl Linear {
    /// No conversion.
    pub const IDENTITY: Linear = Linear {
        offset: 0.0,
        factor: 1.0,
    };
}

/// Reads a `##CC` block as a linear conversion (the only kinds a time channel uses).
pub fn conversion(cc: &Block) -> Result<Linear, &'static str> {
    let d = cc.data;
    match d.first() {
        Some(0) => Ok(Linear::IDENTITY),
        Some(1) => {
            let offset = f64_at(d, 24).ok_or("##CC block cut short")?;
            let factor = f64_at(d, 32).ok_or("##CC block cut short")?;
            Ok(Linear { offset, factor })
        }
        Some(_) => Err("time channel with a non-linear conversion"),
        None => Err("##CC block cut short"),
    }
}

/// What a `##CG` block says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Group {
    /// The next group of the data group (0: last).
    pub next: u64,
    /// Its first channel.
    pub first_channel: u64,
    /// Its acquisition name (`##TX`), 0: none.
    pub acq_name: u64,
    /// Its record id (unsorted data groups).
    pub record_id: u64,
    /// Number of records.
    pub cycles: u64,
    /// Bytes of one record (data and invalidation bytes, without the record id).
    pub record_size: u64,
    /// Its records are variable-length signal data (u32 length, bytes).
    pub vlsd: bool,
}

/// Reads a `##CG` block.
pub fn group(cg: &Block) -> Result<Group, &'static str> {
    if cg.id != *b"##CG" {
        return Err("expected a ##CG block");
    }
    let d = cg.data;
    let short = "##CG block cut short";
    let flags = u16_at(d, 16).ok_or(short)?;
    let data_bytes = u32_at(d, 24).ok_or(short)?;
    let inval_bytes = u32_at(d, 28).ok_or(short)?;
    Ok(Group {
        next: cg.link(0),
        first_channel: cg.link(1),
        acq_name: cg.link(2),
        record_id: u64_at(d, 0).ok_or(short)?,
        cycles: u64_at(d, 8).ok_or(short)?,
        record_size: u64::from(data_bytes) + u64::from(inval_bytes),
        vlsd: flags & 1 != 0,
    })
}

/// What a `##DG` block says: next data group, first channel group, data, record id size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DataGroup {
    /// The next data group (0: last).
    pub next: u64,
    /// Its first channel group.
    pub first_group: u64,
    /// Its data (`##DT`, `##DZ`, `##DL`, `##HL`), 0: none.
    pub data: u64,
    /// Bytes of the record id before each record (0: sorted, one group).
    pub record_id_size: u8,
}

/// Reads a `##DG` block.
pub fn data_group(dg: &Block) -> Result<DataGroup, &'static str> {
    if dg.id != *b"##DG" {
        return Err("expected a ##DG block");
    }
    let size = *dg.data.first().ok_or("##DG block cut short")?;
    if !matches!(size, 0 | 1 | 2 | 4 | 8) {
        return Err("record id size not 0, 1, 2, 4 or 8");
    }
    Ok(DataGroup {
        next: dg.link(0),
        first_group: dg.link(1),
        data: dg.link(2),
        record_id_size: size,
    })
}

/// The record id of `size` bytes at the start of `b`.
pub fn record_id(b: &[u8], size: u8) -> Option<u64> {
    let s = b.get(..size as usize)?;
    let mut raw = [0u8; 8];
    raw[..s.len()].copy_from_slice(s);
    Some(u64::from_le_bytes(raw))
}

/// A `##DZ` block: what it holds once inflated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Zipped<'a> {
    /// The id of the block it replaces (`b"DT"`, `b"SD"`).
    pub original: [u8; 2],
    /// Transposed before deflating, in rows of this many bytes (`None`: plain deflate).
    pub transposed: Option<u32>,
    /// Bytes once inflated.
    pub original_len: u64,
    /// The zlib data.
    pub data: &'a [u8],
}

/// Reads a `##DZ` block.
pub fn zipped<'a>(dz: &Block<'a>) -> Result<Zipped<'a>, &'static str> {
    let d = dz.data;
    let short = "##DZ block cut short";
    let original = [*d.first().ok_or(short)?, *d.get(1).ok_or(short)?];
    let param = u32_at(d, 4).ok_or(short)?;
    let transposed = match d.get(2) {
        Some(0) => None,
        Some(1) => Some(param),
        Some(_) => Err("##DZ block of an unknown zip type")?,
        None => Err(short)?,
    };
    let original_len = u64_at(d, 8).ok_or(short)?;
    let len = u64_at(d, 16).ok_or(short)?;
    let data = usize::try_from(len)
        .ok()
        .and_then(|n| d.get(24..24usize.checked_add(n)?))
        .ok_or("##DZ data longer than its block")?;
    Ok(Zipped {
        original,
        transposed,
        original_len,
        data,
    })
}

/// Undoes the transposition of a `##DZ` block: `data` holds the columns of rows of `cols`
/// bytes (the bytes past the last whole row as they were); the rows go to `out`.
pub fn untranspose(data: &[u8], cols: usize, out: &mut Vec<u8>) {
    if cols < 2 {
        out.extend_from_slice(data);
        return;
    }
    let rows = data.len() / cols;
    let start = out.len();
    out.resize(start + rows * cols, 0);
    for (c, column) in data[..rows * cols].chunks_exact(rows.max(1)).enumerate() {
        for (r, &b) in column.iter().enumerate() {
            out[start + r * cols + c] = b;
        }
    }
    out.extend_from_slice(&data[rows * cols..]);
}

/// The data blocks a `##DL` block lists, and the next `##DL` (0: last).
pub fn data_list(dl: &Block) -> Result<(u64, Vec<u64>), &'static str> {
    if dl.id != *b"##DL" || dl.link_count() == 0 {
        return Err("expected a ##DL block");
    }
    Ok((dl.link(0), (1..dl.link_count()).map(|i| dl.link(i)).collect()))
}

/// The kind of frame a CAN bus-logging channel group holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `CAN_DataFrame`.
    Data,
    /// `CAN_RemoteFrame`.
    Remote,
    /// `CAN_ErrorFrame`.
    Error,
}

impl Kind {
    /// The kind a channel or group name belongs to (`CAN_DataFrame.ID` -> `Data`).
    pub fn of(name: &[u8]) -> Option<Kind> {
        let base = name.split(|&b| b == b'.').next()?;
        match base {
            b"CAN_DataFrame" => Some(Kind::Data),
            b"CAN_RemoteFrame" => Some(Kind::Remote),
            b"CAN_ErrorFrame" => Some(Kind::Error),
            _ => None,
        }
    }
}

/// Where a frame's payload lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Payload {
    /// In the record.
    Fixed(Field),
    /// In signal data: the record holds the offset.
    Vlsd(Field),
}

/// The fields of a CAN bus-logging record, found by their channel names.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// The group's kind.
    pub kind: Kind,
    /// The master (time) channel and its conversion to seconds.
    pub time: (Field, Linear),
    /// `.ID`, `.IDE`, `.DLC`, `.DataLength`, `.Dir`, `.EDL`, `.BRS`, `.ESI`, `.BusChannel`.
    fields: [Option<Field>; 9],
    /// `.DataBytes`.
    pub payload: Option<Payload>,
    /// The fields as fixed loads, resolved when a member is added.
    plan: Plan,
}

/// A little-endian integer field as one 8-byte load at `at`, shifted and masked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Slot {
    at: u32,
    shift: u8,
    mask: u64,
}

impl Slot {
    /// The slot of `f`, `None` when `f` needs [`Field::uint`]'s general path (big endian,
    /// or wider than one load).
    fn of(f: Field) -> Option<Slot> {
        let be = matches!(f.kind, DataType::Uint { be: true } | DataType::Int { be: true });
        (!be && u32::from(f.bit) + f.bits <= 64).then_some(Slot {
            at: f.byte,
            shift: f.bit,
            mask: if f.bits >= 64 { u64::MAX } else { (1u64 << f.bits) - 1 },
        })
    }

    /// The value in `buf` (whose record holds the field's bytes: bytes after them, of the
    /// record or of the next ones, are masked off).
    #[inline(always)]
    fn read(self, buf: &[u8]) -> u64 {
        let at = self.at as usize;
        let word = match buf.get(at..).and_then(|r| r.first_chunk::<8>()) {
            Some(w) => u64::from_le_bytes(*w),
            None => {
                let tail = buf.get(at..).unwrap_or_default();
                let mut raw = [0u8; 8];
                raw[..tail.len().min(8)].copy_from_slice(&tail[..tail.len().min(8)]);
                u64::from_le_bytes(raw)
            }
        };
        (word >> self.shift) & self.mask
    }
}

/// A [`Layout`]'s fields resolved once per channel group: when `slots` is `Some`, every
/// member is a [`Slot`] and a record of at least `end` bytes reads with no check a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Plan {
    /// Bytes a record needs for every field, the time and a fixed payload to lie in it.
    end: usize,
    /// The members' slots (`None` inside: the member is absent); `None`: some member needs
    /// the general path.
    slots: Option<[Option<Slot>; 9]>,
    /// The time channel's byte when it is a little-endian f64 at bit 0.
    time_f64: Option<u32>,
}

impl Plan {
    fn of(l: &Layout) -> Plan {
        let span = |f: Field| f.byte as usize + (u64::from(f.bit) + u64::from(f.bits)).div_ceil(8) as usize;
        let (time, _) = l.time;
        let mut end = span(time);
        if let Some(Payload::Fixed(p)) = l.payload {
            end = end.max(span(p));
        }
        let mut slots = Some([None; 9]);
        for (i, f) in l.fields.iter().enumerate() {
            let Some(f) = *f else { continue };
            end = end.max(span(f));
            match (Slot::of(f), slots.as_mut()) {
                (Some(slot), Some(s)) => s[i] = Some(slot),
                _ => slots = None,
            }
        }
        let time_f64 =
            (time.kind == DataType::Float { be: false } && time.bit == 0 && time.bits == 64).then_some(time.byte);
        Plan { end, slots, time_f64 }
    }
}

const NAMES: [&[u8]; 9] = [
    b"ID",
    b"IDE",
    b"DLC",
    b"DataLength",
    b"Dir",
    b"EDL",
    b"BRS",
    b"ESI",
    b"BusChannel",
];
const ID: usize = 0;
const IDE: usize = 1;
const DLC: usize = 2;
const DATA_LENGTH: usize = 3;
const DIR: usize = 4;
const EDL: usize = 5;
const BRS: usize = 6;
const ESI: usize = 7;
const BUS: usize = 8;

impl Layout {
    /// A layout for a group of `kind` with its time channel; members are added by name.
    pub fn new(kind: Kind, time: (Field, Linear)) -> Layout {
        let mut l = Layout {
            kind,
            time,
            fields: [None; 9],
            payload: None,
            plan: Plan {
                end: 0,
                slots: None,
                time_f64: None,
            },
        };
        l.plan = Plan::of(&l);
        l
    }

    /// Takes the channel `name` (`CAN_DataFrame.ID`, or `ID`) when it is one of the frame's
    /// members; `vlsd`: its value is an offset into signal data.
    pub fn add(&mut self, name: &[u8], field: Field, vlsd: bool) {
        let member = match name.iter().rposition(|&b| b == b'.') {
            Some(dot) => &name[dot + 1..],
            None => name,
        };
        if member == b"DataBytes" {
            self.payload = Some(if vlsd {
                Payload::Vlsd(field)
            } else {
                Payload::Fixed(field)
            });
        } else if let Some(i) = NAMES.iter().position(|n| *n == member) {
            self.fields[i] = Some(field);
        }
        self.plan = Plan::of(self);
    }

    /// Whether the group can give frames (data and remote frames need their ID).
    pub fn check(&self) -> Result<(), &'static str> {
        match (self.kind, self.fields[ID]) {
            (Kind::Error, _) | (_, Some(_)) => Ok(()),
            _ => Err("CAN frame group without an ID channel"),
        }
    }

    fn get(&self, i: usize, rec: &[u8]) -> Result<Option<u64>, &'static str> {
        match self.fields[i] {
            Some(f) => f.uint(rec).map(Some).ok_or("record shorter than its channels"),
            None => Ok(None),
        }
    }

    /// The signal-data offset of the record's payload (VLSD groups).
    pub fn vlsd_offset(&self, rec: &[u8]) -> Option<u64> {
        match self.payload {
            Some(Payload::Vlsd(f)) => f.uint(rec),
            _ => None,
        }
    }

    /// The record `rec` as a frame and its bus channel number; `vlsd` holds the payload of
    /// a VLSD group. Times are seconds after `start_ns`.
    pub fn frame(&self, rec: &[u8], vlsd: Option<&[u8]>, start_ns: u64) -> Result<(u64, Frame), &'static str> {
        self.frame_in(rec, rec.len(), vlsd, start_ns)
    }

    /// [`Layout::frame`] of the record `buf[..size]`, read in place: the bytes after it
    /// (the next records) are only loaded and masked off, so a record whose fields all lie
    /// in it is read by the group's fixed offsets, with no check a field.
    pub fn frame_in(
        &self,
        buf: &[u8],
        size: usize,
        vlsd: Option<&[u8]>,
        start_ns: u64,
    ) -> Result<(u64, Frame), &'static str> {
        let rec = buf.get(..size).unwrap_or(buf);
        match &self.plan.slots {
            Some(slots) if rec.len() == size && size >= self.plan.end => {
                let time = match self.plan.time_f64 {
                    Some(at) => Some(f64::from_bits(
                        Slot {
                            at,
                            shift: 0,
                            mask: u64::MAX,
                        }
                        .read(buf),
                    )),
                    None => self.time.0.float(rec),
                };
                self.build(time, &Planned { slots, buf }, rec, vlsd, start_ns)
            }
            _ => self.build(
                self.time.0.float(rec),
                &General { layout: self, rec },
                rec,
                vlsd,
                start_ns,
            ),
        }
    }

    /// The frame of a record whose time is `raw_t` and whose members `m` reads.
    #[inline(always)]
    fn build(
        &self,
        raw_t: Option<f64>,
        m: &impl Members,
        rec: &[u8],
        vlsd: Option<&[u8]>,
        start_ns: u64,
    ) -> Result<(u64, Frame), &'static str> {
        let get = |i| m.get(i);
        let conv = self.time.1;
        let raw_t = raw_t.ok_or("record shorter than its time channel")?;
        let secs = conv.offset + conv.factor * raw_t;
        if !secs.is_finite() {
            return Err("time is not a number");
        }
        let ns = (secs * 1e9).round();
        // Within an i64 (every time of a log) the cheaper conversion gives the same.
        let ns = if ns.abs() < 9.2e18 {
            i128::from(ns as i64)
        } else {
            ns as i128
        };
        let ts = i128::from(start_ns).saturating_add(ns);
        let mut f = Frame {
            ts_ns: u64::try_from(ts.max(0)).unwrap_or(u64::MAX),
            ..Frame::default()
        };
        let bus = get(BUS)?.unwrap_or(0);
        let flag = |i| get(i).map(|v| v.unwrap_or(0) != 0);
        f.flags.set(Flags::TX, flag(DIR)?);
        let dlc = get(DLC)?;
        if self.kind == Kind::Error {
            f.flags.set(Flags::ERR, true);
            f.id = CAN_ERR_BUSERROR;
            return Ok((bus, f));
        }
        let raw_id = get(ID)?.ok_or("no ID channel")?;
        let ext = flag(IDE)? || raw_id & 0x8000_0000 != 0;
        f.id = (raw_id & 0x1FFF_FFFF) as u32;
        f.flags.set(Flags::EXT, ext);
        if !ext && f.id > 0x7FF {
            return Err("11-bit identifier above 0x7FF");
        }
        let fd = flag(EDL)?;
        if self.kind == Kind::Remote {
            f.flags.set(Flags::RTR, true);
            let n = get(DATA_LENGTH)?.filter(|&n| n > 0).or(dlc).unwrap_or(0);
            f.len = n.min(8) as u8;
            return Ok((bus, f));
        }
        f.flags.set(Flags::FD, fd);
        f.flags.set(Flags::BRS, fd && flag(BRS)?);
        f.flags.set(Flags::ESI, fd && flag(ESI)?);
        let len = match (get(DATA_LENGTH)?, dlc) {
            (Some(n), _) => n,
            (None, Some(d)) if fd => u64::from(FD_LENS[(d & 15) as usize]),
            (None, Some(d)) => d.min(8),
            (None, None) => Err("CAN frame group without a DLC or DataLength channel")?,
        };
        if len > if fd { 64 } else { 8 } {
            return Err("data length above what the frame can hold");
        }
        if fd && !FD_LENS.contains(&(len as u8)) {
            return Err("CAN FD data length no DLC gives");
        }
        f.len = len as u8;
        if !fd && let Some(d) = dlc.filter(|&d| (9..=15).contains(&d) && len == 8) {
            f.raw_dlc = d as u8;
        }
        let bytes = match self.payload {
            Some(Payload::Fixed(p)) => p.bytes(rec).ok_or("record shorter than its DataBytes channel")?,
            Some(Payload::Vlsd(_)) => vlsd.ok_or("no signal data for the record")?,
            None if len == 0 => &[],
            None => Err("CAN frame group without a DataBytes channel")?,
        };
        let data = bytes
            .get(..f.len as usize)
            .ok_or("fewer data bytes than the data length")?;
        f.data[..data.len()].copy_from_slice(data);
        Ok((bus, f))
    }
}

/// How [`Layout::build`] reads a record's members (by index into [`NAMES`]).
trait Members {
    fn get(&self, i: usize) -> Result<Option<u64>, &'static str>;
}

/// Members read by the group's plan.
struct Planned<'a> {
    slots: &'a [Option<Slot>; 9],
    buf: &'a [u8],
}

impl Members for Planned<'_> {
    #[inline(always)]
    fn get(&self, i: usize) -> Result<Option<u64>, &'static str> {
        Ok(self.slots.get(i).copied().flatten().map(|s| s.read(self.buf)))
    }
}

/// Members read channel by channel, each checked against the record.
struct General<'a> {
    layout: &'a Layout,
    rec: &'a [u8],
}

impl Members for General<'_> {
    #[inline(always)]
    fn get(&self, i: usize) -> Result<Option<u64>, &'static str> {
        self.layout.get(i, self.rec)
    }
}

/// The interface name of bus channel `n` (`can1` for 1, as loggers number them).
pub fn channel_name(n: u64) -> String {
    format!("can{n}")
}

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    b.get(at..at + 2)?.try_into().ok().map(u16::from_le_bytes)
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)?.try_into().ok().map(u32::from_le_bytes)
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    b.get(at..at + 8)?.try_into().ok().map(u64::from_le_bytes)
}

fn f64_at(b: &[u8], at: usize) -> Option<f64> {
    u64_at(b, at).map(f64::from_bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn untranspose_restores_rows_and_keeps_the_tail() {
        // Rows "abc", "def" transposed to "adbecf", and a tail "xy".
        let mut out = Vec::new();
        untranspose(b"adbecfxy", 3, &mut out);
        assert_eq!(out, b"abcdefxy");
    }

    #[test]
    fn fields_read_bits_in_either_byte_order() {
        let f = Field {
            byte: 1,
            bit: 4,
            bits: 8,
            kind: DataType::Uint { be: false },
        };
        assert_eq!(f.uint(&[0, 0xA0, 0x0B]), Some(0xBA));
        let be = Field {
            byte: 0,
            bit: 0,
            bits: 16,
            kind: DataType::Uint { be: true },
        };
        assert_eq!(be.uint(&[0x12, 0x34]), Some(0x1234));
        assert_eq!(be.uint(&[0x12]), None, "a short record is no value");
    }

    fn byte(at: u32) -> Field {
        Field {
            byte: at,
            bit: 0,
            bits: 8,
            kind: DataType::Uint { be: false },
        }
    }

    #[test]
    fn a_record_becomes_a_frame() {
        let time = Field {
            byte: 0,
            bit: 0,
            bits: 64,
            kind: DataType::Float { be: false },
        };
        let mut l = Layout::new(Kind::Data, (time, Linear::IDENTITY));
        let id = Field {
            byte: 9,
            bits: 32,
            ..byte(9)
        };
        l.add(b"CAN_DataFrame.BusChannel", byte(8), false);
        l.add(b"CAN_DataFrame.ID", id, false);
        l.add(b"CAN_DataFrame.DataLength", byte(13), false);
        let data = Field {
            bits: 16,
            kind: DataType::Bytes,
            ..byte(14)
        };
        l.add(b"CAN_DataFrame.DataBytes", data, false);
        let mut rec = 1.5f64.to_le_bytes().to_vec();
        rec.extend_from_slice(&[2, 0x81, 1, 0, 0, 2, 0xAA, 0xBB]);
        let (bus, f) = l.frame(&rec, None, 1_000_000_000).unwrap();
        assert_eq!(
            (bus, f.id, f.payload(), f.ts_ns),
            (2, 0x181, &[0xAA, 0xBB][..], 2_500_000_000)
        );
        rec[13] = 9;
        assert_eq!(l.frame(&rec, None, 0), Err("data length above what the frame can hold"));
    }

    fn any_field() -> impl proptest::strategy::Strategy<Value = Field> {
        use proptest::prelude::*;
        let kind = prop_oneof![
            any::<bool>().prop_map(|be| DataType::Uint { be }),
            any::<bool>().prop_map(|be| DataType::Int { be }),
            any::<bool>().prop_map(|be| DataType::Float { be }),
            Just(DataType::Bytes),
        ];
        (
            0u32..24,
            0u8..8,
            prop_oneof![0u32..70, Just(8u32), Just(32u32), Just(64u32)],
            kind,
        )
            .prop_map(|(byte, bit, bits, kind)| Field { byte, bit, bits, kind })
    }

    proptest::proptest! {
        #[test]
        fn a_record_read_in_place_is_the_record_read_alone(
            time in any_field(),
            members in proptest::collection::vec((0usize..NAMES.len(), any_field()), 0..12),
            payload in proptest::option::of((any_field(), proptest::prelude::any::<bool>())),
            kind in proptest::sample::select(vec![Kind::Data, Kind::Remote, Kind::Error]),
            bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..48),
            size in 0usize..48,
        ) {
            let mut l = Layout::new(kind, (time, Linear { offset: 0.5, factor: 1e-3 }));
            for (i, f) in members {
                l.add(NAMES[i], f, false);
            }
            if let Some((f, vlsd)) = payload {
                l.add(b"CAN_DataFrame.DataBytes", f, vlsd);
            }
            let size = size.min(bytes.len());
            // The same layout read channel by channel, with no plan.
            let mut general = l;
            general.plan.slots = None;
            general.plan.time_f64 = None;
            proptest::prop_assert_eq!(
                l.frame_in(&bytes, size, Some(&[1, 2, 3][..]), 7),
                general.frame(&bytes[..size], Some(&[1, 2, 3][..]), 7)
            );
        }
    }
}
