//! Vector BLF (binary logging format): the pure part, bytes in and values out. The caller
//! (cotui's `logio::blf`) reads the file, inflates the zlib log containers and hands the
//! object bytes here; the writer half encodes frames into objects the same way.
//!
//! The layout, as python-can and Toby Lorenz' `vector_blf` read it (all little-endian):
//! - a file header: `LOGG`, its size (144), versions, sizes, object count, and the start
//!   and stop times as Windows `SYSTEMTIME`s (UTC, millisecond precision);
//! - objects, each `LOBJ`, header size (u16), header version (u16), object size (u32),
//!   object type (u32), then for header version 1 or 2: flags (u32: 1 = 10 µs ticks,
//!   2 = 1 ns ticks), ..., timestamp (u64 at byte 24), and the object's body at the header
//!   size; objects are followed by up to 3 bytes of padding;
//! - `LOG_CONTAINER` objects (type 10) hold a run of further objects, plain or zlib
//!   compressed, and an object may continue in the next container.
//!
//! Choices: channel N is interface `can{N-1}` (channel 0 is `canX`), as in ASC logs, so
//! one measurement saved as ASC and as BLF names the same interfaces; timestamps are the
//! header's start time plus the object's time (zero-based when the start time is unset);
//! `CAN_ERROR_EXT` becomes an error frame of class `CAN_ERR_BUSERROR` (0x80) with the
//! object's data bytes, as ASC `ErrorFrame` lines do.

use super::asc::CAN_ERR_BUSERROR;
use crate::frame::{Flags, Frame};

/// The file's first four bytes.
pub const FILE_SIGNATURE: &[u8; 4] = b"LOGG";
/// Every object's first four bytes.
pub const OBJECT_SIGNATURE: &[u8; 4] = b"LOBJ";
/// The file header size written by Vector tools and python-can.
pub const FILE_HEADER_SIZE: usize = 144;
/// The object header's common part (signature to type).
pub const OBJECT_BASE: usize = 16;
/// Object type of a log container.
pub const LOG_CONTAINER: u32 = 10;
/// Object type of a classic CAN frame.
pub const CAN_MESSAGE: u32 = 1;
/// Object type of a classic CAN frame with frame length and bit count.
pub const CAN_MESSAGE2: u32 = 86;
/// Object type of a CAN FD frame (64 data bytes always present).
pub const CAN_FD_MESSAGE: u32 = 100;
/// Object type of a CAN FD frame (data bytes as long as the frame).
pub const CAN_FD_MESSAGE_64: u32 = 101;
/// Object type of an extended CAN error frame.
pub const CAN_ERROR_EXT: u32 = 73;

/// The object header flag for timestamps in 10 µs ticks (else 1 ns ticks).
const TIME_TEN_MICS: u32 = 1;
/// Bit 31 of a BLF CAN id: 29-bit identifier.
const ID_EXT: u32 = 0x8000_0000;
/// `CAN_MESSAGE` flags: sent (else received), remote frame.
const MSG_TX: u8 = 0x01;
const MSG_RTR: u8 = 0x80;
/// `CAN_FD_MESSAGE` FD flags: EDL (an FD frame), BRS, ESI.
const FD_EDL: u8 = 0x01;
const FD_BRS: u8 = 0x02;
const FD_ESI: u8 = 0x04;
/// `CAN_FD_MESSAGE_64` flags: remote, EDL, BRS, ESI.
const FD64_RTR: u32 = 0x0010;
const FD64_EDL: u32 = 0x1000;
const FD64_BRS: u32 = 0x2000;
const FD64_ESI: u32 = 0x4000;
/// The body of a `CAN_FD_MESSAGE_64` before its data bytes.
const FD64_HEAD: usize = 40;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// What the file header tells a reader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FileHeader {
    /// Bytes of the header (objects start there).
    pub size: u32,
    /// The start time in ns since the Unix epoch (0 when unset).
    pub start_ns: u64,
}

/// Reads the file header from the file's first bytes (at least 72 of them).
pub fn file_header(b: &[u8]) -> Result<FileHeader, &'static str> {
    if b.get(..4) != Some(&FILE_SIGNATURE[..]) {
        return Err("not a BLF file (no LOGG signature)");
    }
    let size = u32_at(b, 4).ok_or("file header cut short")?;
    if (size as usize) < 72 || b.len() < 72 {
        return Err("file header cut short");
    }
    let mut st = [0u16; 8];
    for (k, v) in st.iter_mut().enumerate() {
        *v = u16_at(b, 40 + 2 * k).unwrap_or(0);
    }
    Ok(FileHeader {
        size,
        start_ns: systemtime_ns(st),
    })
}

/// A `SYSTEMTIME` (year, month, day of week, day, hour, minute, second, ms) in ns since
/// the Unix epoch; 0 for an unset or impossible date (or one past 2500, beyond u64 ns).
fn systemtime_ns(st: [u16; 8]) -> u64 {
    let [year, month, _, day, hour, min, sec, ms] = st.map(u64::from);
    if !(1970..=2500).contains(&year) || !(1..=12).contains(&month) || !(1..=31).contains(&day) {
        return 0;
    }
    if hour > 23 || min > 59 || sec > 60 || ms > 999 {
        return 0;
    }
    let days = crate::calendar::days_from_civil(year as i64, month as i64, day as i64);
    let secs = days as u64 * 86_400 + hour * 3600 + min * 60 + sec;
    secs * 1_000_000_000 + ms * 1_000_000
}

/// The common object header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObjectHead {
    /// Bytes of the whole header (the body starts there).
    pub header_size: u16,
    /// 1 or 2 for the objects read here.
    pub header_version: u16,
    /// Bytes of the whole object (header and body, without padding).
    pub size: u32,
    /// Object type.
    pub kind: u32,
}

/// Reads the object header at the start of `b` (`None` unless it starts with `LOBJ` and
/// holds 16 bytes).
pub fn object_head(b: &[u8]) -> Option<ObjectHead> {
    if b.get(..4)? != OBJECT_SIGNATURE {
        return None;
    }
    Some(ObjectHead {
        header_size: u16_at(b, 4)?,
        header_version: u16_at(b, 6)?,
        size: u32_at(b, 8)?,
        kind: u32_at(b, 12)?,
    })
}

/// Where the next object of a stream of objects is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// After `skip` bytes of padding, an object of `len` bytes lies whole in the buffer.
    Object {
        /// Padding before it.
        skip: usize,
        /// Its size.
        len: usize,
    },
    /// The buffer ends inside the padding, the header or the object: more bytes are needed.
    NeedMore,
    /// The bytes at `at` are no object: `skip` bytes (at least 1) are to be passed over.
    Bad {
        /// Where the damage starts (after any padding).
        at: usize,
        /// Bytes to pass over, to the next `LOBJ` or near the buffer's end.
        skip: usize,
        /// What was wrong.
        why: &'static str,
    },
}

/// Finds the next object in `b` (padding of up to 3 bytes before it is passed over);
/// objects longer than `max` are damage, so no object can make a reader buffer more.
pub fn step(b: &[u8], max: usize) -> Step {
    let found = (0..4).find(|&i| b.get(i..i + 4) == Some(&OBJECT_SIGNATURE[..]));
    let Some(at) = found else {
        if b.len() < 4 + 3 {
            return Step::NeedMore;
        }
        let skip = memchr::memmem::find(&b[1..], OBJECT_SIGNATURE).map_or(b.len() - 3, |p| p + 1);
        return Step::Bad {
            at: 0,
            skip,
            why: "no object signature (LOBJ): skipped to the next one",
        };
    };
    let Some(head) = object_head(&b[at..]) else {
        return Step::NeedMore;
    };
    let len = head.size as usize;
    let bad = |why| Step::Bad { at, skip: at + 4, why };
    if len < OBJECT_BASE || (head.header_size as usize) < OBJECT_BASE || head.header_size as usize > len {
        return bad("object size smaller than its header");
    }
    if len > max {
        return bad("object larger than any log object");
    }
    if b.len() < at + len {
        return Step::NeedMore;
    }
    Step::Object { skip: at, len }
}

/// How a log container's data is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    /// As is.
    None,
    /// zlib (deflate with a zlib header).
    Zlib,
}

/// A log container object's compression and data (`obj` is the whole object, or its
/// start when the file is cut short: then the data is what there is).
pub fn container(obj: &[u8]) -> Result<(Compression, &[u8]), &'static str> {
    let head = object_head(obj).ok_or("not an object")?;
    let body = obj
        .get(head.header_size as usize..(head.size as usize).min(obj.len()))
        .ok_or("container header cut short")?;
    let method = u16_at(body, 0).ok_or("container header cut short")?;
    let data = body.get(16..).ok_or("container header cut short")?;
    match method {
        0 => Ok((Compression::None, data)),
        2 => Ok((Compression::Zlib, data)),
        _ => Err("unknown container compression method"),
    }
}

/// The size a log container's data has unpacked, as its header says (`None` when the
/// header is cut short). Only a hint for the room to inflate into: damage may make it wrong.
pub fn container_unpacked(obj: &[u8]) -> Option<u32> {
    let head = object_head(obj)?;
    u32_at(obj, usize::from(head.header_size).checked_add(8)?)
}

/// What one (non-container) object held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Object {
    /// A frame on BLF channel `channel` (its `iface` is left 0 for the caller to set).
    Frame {
        /// The BLF channel (1 is the first).
        channel: u16,
        /// The frame.
        frame: Frame,
    },
    /// An object of a type that holds no CAN frame (markers, texts, other buses).
    Other(u32),
}

/// Decodes one whole object (`obj`, as [`step`] delimits it); `start_ns` is the file's
/// start time. Never panics: a short or inconsistent object is an error.
pub fn object(obj: &[u8], start_ns: u64) -> Result<Object, &'static str> {
    const SHORT: &str = "object body cut short";
    let head = object_head(obj).ok_or("not an object")?;
    if !matches!(
        head.kind,
        CAN_MESSAGE | CAN_MESSAGE2 | CAN_FD_MESSAGE | CAN_FD_MESSAGE_64 | CAN_ERROR_EXT
    ) {
        return Ok(Object::Other(head.kind));
    }
    if !matches!(head.header_version, 1 | 2) {
        return Err("unknown object header version");
    }
    let flags = u32_at(obj, 16).ok_or(SHORT)?;
    let ticks = u64_at(obj, 24).ok_or(SHORT)?;
    let rel = if flags == TIME_TEN_MICS {
        ticks.saturating_mul(10_000)
    } else {
        ticks
    };
    let end = (head.size as usize).min(obj.len());
    let body = obj.get(head.header_size as usize..end).ok_or(SHORT)?;
    let mut f = Frame {
        ts_ns: start_ns.saturating_add(rel),
        ..Frame::default()
    };
    let (channel, id) = match head.kind {
        CAN_MESSAGE | CAN_MESSAGE2 => {
            let b: &[u8; 16] = body.first_chunk().ok_or(SHORT)?;
            let (channel, mflags, dlc) = (u16::from_le_bytes([b[0], b[1]]), b[2], b[3]);
            let id = u32::from_le_bytes([b[4], b[5], b[6], b[7]]);
            f.flags.set(Flags::TX, mflags & MSG_TX != 0);
            f.flags.set(Flags::RTR, mflags & MSG_RTR != 0);
            classic_len(&mut f, dlc);
            if !f.is_rtr() {
                // The first `len` of the 8 data bytes in one store (the rest stay zero).
                let keep = u64::MAX.checked_shr(64 - 8 * u32::from(f.len)).unwrap_or(0);
                let data = u64::from_le_bytes([b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]]);
                f.data[..8].copy_from_slice(&(data & keep).to_le_bytes());
            }
            (channel, id)
        }
        CAN_FD_MESSAGE => {
            let b = body.get(..84).ok_or(SHORT)?;
            let (channel, mflags, dlc, id) = (u16_at(b, 0).ok_or(SHORT)?, b[2], b[3], u32_at(b, 4).ok_or(SHORT)?);
            let (fd_flags, valid, data) = (b[13], b[14], &b[20..84]);
            f.flags.set(Flags::TX, mflags & MSG_TX != 0);
            if fd_flags & FD_EDL != 0 {
                fd_frame(&mut f, dlc, valid, data, fd_flags & FD_BRS != 0, fd_flags & FD_ESI != 0)?;
            } else {
                f.flags.set(Flags::RTR, mflags & MSG_RTR != 0);
                classic_len(&mut f, dlc);
                if !f.is_rtr() {
                    f.data[..f.len as usize].copy_from_slice(&data[..f.len as usize]);
                }
            }
            (channel, id)
        }
        CAN_FD_MESSAGE_64 => {
            let channel = u16::from(*body.first().ok_or(SHORT)?);
            let (dlc, valid) = (*body.get(1).ok_or(SHORT)?, *body.get(2).ok_or(SHORT)?);
            let id = u32_at(body, 4).ok_or(SHORT)?;
            let fd_flags = u32_at(body, 12).ok_or(SHORT)?;
            let dir = *body.get(34).ok_or(SHORT)?;
            f.flags.set(Flags::TX, dir != 0);
            // As python-can and CANoe: data bytes past the object's end read as zeros.
            let mut data = [0u8; 64];
            let avail = body.get(FD64_HEAD..).unwrap_or_default();
            let n = avail.len().min(64).min(valid as usize);
            data[..n].copy_from_slice(&avail[..n]);
            if fd_flags & FD64_EDL != 0 {
                fd_frame(
                    &mut f,
                    dlc,
                    valid,
                    &data,
                    fd_flags & FD64_BRS != 0,
                    fd_flags & FD64_ESI != 0,
                )?;
            } else {
                f.flags.set(Flags::RTR, fd_flags & FD64_RTR != 0);
                classic_len(&mut f, dlc);
                if !f.is_rtr() {
                    f.data[..f.len as usize].copy_from_slice(&data[..f.len as usize]);
                }
            }
            (channel, id)
        }
        _ => {
            // CAN_ERROR_EXT: channel, length, flags, ecc, position, dlc, ..., data at 24.
            let channel = u16_at(body, 0).ok_or(SHORT)?;
            let dlc = *body.get(10).ok_or(SHORT)?;
            let data = body.get(24..32).ok_or(SHORT)?;
            f.flags.set(Flags::ERR, true);
            f.len = dlc.min(8);
            f.data[..f.len as usize].copy_from_slice(&data[..f.len as usize]);
            f.id = CAN_ERR_BUSERROR;
            return Ok(Object::Frame { channel, frame: f });
        }
    };
    f.flags.set(Flags::EXT, id & ID_EXT != 0);
    f.id = id & 0x1FFF_FFFF;
    if !f.is_ext() && f.id > 0x7FF {
        return Err("11-bit identifier above 0x7FF");
    }
    Ok(Object::Frame { channel, frame: f })
}

/// Sets a classic frame's length from its DLC (9..=15 mean 8 bytes, kept in `raw_dlc`).
fn classic_len(f: &mut Frame, dlc: u8) {
    let dlc = dlc & 0x0F;
    f.len = dlc.min(8);
    f.raw_dlc = if dlc > 8 { dlc } else { 0 };
}

/// Fills an FD frame: length from the DLC (checked against the valid byte count).
fn fd_frame(f: &mut Frame, dlc: u8, valid: u8, data: &[u8], brs: bool, esi: bool) -> Result<(), &'static str> {
    let len = usize::from(crate::frame::FD_LENS[usize::from(dlc & 0x0F)]);
    if valid > 64 {
        return Err("more valid data bytes than a CAN FD frame holds");
    }
    f.flags.set(Flags::FD, true);
    f.flags.set(Flags::BRS, brs);
    f.flags.set(Flags::ESI, esi);
    f.len = len as u8;
    let n = (valid as usize).min(len).min(data.len());
    f.data[..n].copy_from_slice(&data[..n]);
    Ok(())
}

/// The interface name of BLF channel `n`: `can{n-1}`, `canX` for 0.
pub fn channel_name(n: u16) -> String {
    match n {
        0 => "canX".to_string(),
        n => format!("can{}", n - 1),
    }
}

/// The BLF channel an interface name stands for when it is one [`channel_name`] gives
/// (`can0` is channel 1); `None` for other names.
pub fn name_channel(name: &str) -> Option<u16> {
    let digits = name.strip_prefix("can")?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) || (digits.len() > 1 && digits.starts_with('0'))
    {
        return None;
    }
    digits.parse::<u16>().ok()?.checked_add(1)
}

/// Appends a `SYSTEMTIME` (UTC) for `ns` since the Unix epoch (zeros for 0).
fn put_systemtime(out: &mut Vec<u8>, ns: u64) {
    if ns == 0 {
        out.extend_from_slice(&[0; 16]);
        return;
    }
    let secs = ns / 1_000_000_000;
    let days = (secs / 86_400) as i64;
    let (y, m, d) = crate::calendar::civil_from_days(days);
    let sod = secs % 86_400;
    let dow = (days + 4).rem_euclid(7); // 1970-01-01 was a Thursday (Sunday = 0).
    let ms = (ns / 1_000_000) % 1000;
    for v in [
        y,
        i64::from(m),
        dow,
        i64::from(d),
        (sod / 3600) as i64,
        (sod / 60 % 60) as i64,
        (sod % 60) as i64,
        ms as i64,
    ] {
        out.extend_from_slice(&(v as u16).to_le_bytes());
    }
}

/// What the file header of a written BLF file records.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Totals {
    /// The whole file's size.
    pub file_size: u64,
    /// The file's size with every container unpacked.
    pub uncompressed_size: u64,
    /// Objects in the containers.
    pub objects: u32,
    /// The start time (ns since the Unix epoch, 0 when unknown), at ms precision.
    pub start_ns: u64,
    /// The last object's time.
    pub stop_ns: u64,
}

/// The file header of a BLF file with these totals ([`FILE_HEADER_SIZE`] bytes).
pub fn encode_file_header(t: &Totals) -> Vec<u8> {
    let mut out = Vec::with_capacity(FILE_HEADER_SIZE);
    out.extend_from_slice(FILE_SIGNATURE);
    out.extend_from_slice(&(FILE_HEADER_SIZE as u32).to_le_bytes());
    // Application id 5 (python-can's), version 0.0.0; binlog 2.6.8.1 as python-can writes.
    out.extend_from_slice(&[5, 0, 0, 0, 2, 6, 8, 1]);
    out.extend_from_slice(&t.file_size.to_le_bytes());
    out.extend_from_slice(&t.uncompressed_size.to_le_bytes());
    out.extend_from_slice(&t.objects.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    put_systemtime(&mut out, t.start_ns);
    put_systemtime(&mut out, t.stop_ns);
    out.resize(FILE_HEADER_SIZE, 0);
    out
}

/// The start time a writer records for a first frame at `ts_ns`: whole milliseconds (the
/// header's precision), so object times stay exact offsets from it.
pub fn start_of(ts_ns: u64) -> u64 {
    ts_ns - ts_ns % 1_000_000
}

/// Appends `f` as one object (header version 1, 1 ns ticks since `start_ns`) on BLF
/// channel `channel`, padded to 4 bytes: `CAN_MESSAGE` for classic frames, `CAN_FD_MESSAGE_64`
/// for FD frames, `CAN_ERROR_EXT` for error frames.
pub fn encode_frame(out: &mut Vec<u8>, f: &Frame, channel: u16, start_ns: u64) {
    let mut body = [0u8; FD64_HEAD + 64];
    let id = f.id & 0x1FFF_FFFF | if f.is_ext() { ID_EXT } else { 0 };
    let tx = f.flags.has(Flags::TX);
    let (kind, n) = if f.is_err() {
        body[..2].copy_from_slice(&channel.to_le_bytes());
        body[10] = f.len.min(8);
        body[24..32].copy_from_slice(&f.data[..8]);
        (CAN_ERROR_EXT, 32)
    } else if f.is_fd() {
        body[0] = channel.min(255) as u8;
        body[1] = crate::frame::fd_dlc_at_least(f.len);
        body[2] = f.len.min(64);
        body[4..8].copy_from_slice(&id.to_le_bytes());
        let mut flags = FD64_EDL;
        flags |= if f.flags.has(Flags::BRS) { FD64_BRS } else { 0 };
        flags |= if f.flags.has(Flags::ESI) { FD64_ESI } else { 0 };
        body[12..16].copy_from_slice(&flags.to_le_bytes());
        body[34] = tx as u8;
        let len = f.len.min(64) as usize;
        body[FD64_HEAD..FD64_HEAD + len].copy_from_slice(&f.data[..len]);
        (CAN_FD_MESSAGE_64, FD64_HEAD + len)
    } else {
        body[..2].copy_from_slice(&channel.to_le_bytes());
        body[2] = if tx { MSG_TX } else { 0 } | if f.is_rtr() { MSG_RTR } else { 0 };
        body[3] = if f.raw_dlc > 8 { f.raw_dlc } else { f.len.min(8) };
        body[4..8].copy_from_slice(&id.to_le_bytes());
        if !f.is_rtr() {
            body[8..16].copy_from_slice(&f.data[..8]);
        }
        (CAN_MESSAGE, 16)
    };
    let size = 32 + n as u32;
    out.extend_from_slice(OBJECT_SIGNATURE);
    out.extend_from_slice(&32u16.to_le_bytes());
    out.extend_from_slice(&1u16.to_le_bytes());
    out.extend_from_slice(&size.to_le_bytes());
    out.extend_from_slice(&kind.to_le_bytes());
    out.extend_from_slice(&2u32.to_le_bytes()); // 1 ns ticks
    out.extend_from_slice(&[0; 4]); // client index, object version
    out.extend_from_slice(&f.ts_ns.saturating_sub(start_ns).to_le_bytes());
    out.extend_from_slice(&body[..n]);
    out.resize(out.len() + (4 - size as usize % 4) % 4, 0);
}

/// The header of a log container object holding `stored` bytes of data (`unpacked`
/// before compression); the caller appends the data and [`container_padding`].
pub fn encode_container_head(stored: usize, unpacked: usize, compression: Compression) -> [u8; 32] {
    let mut h = [0u8; 32];
    h[..4].copy_from_slice(OBJECT_SIGNATURE);
    h[4..6].copy_from_slice(&(OBJECT_BASE as u16).to_le_bytes());
    h[6..8].copy_from_slice(&1u16.to_le_bytes());
    h[8..12].copy_from_slice(&((32 + stored) as u32).to_le_bytes());
    h[12..16].copy_from_slice(&LOG_CONTAINER.to_le_bytes());
    let method: u16 = match compression {
        Compression::None => 0,
        Compression::Zlib => 2,
    };
    h[16..18].copy_from_slice(&method.to_le_bytes());
    h[24..28].copy_from_slice(&(unpacked as u32).to_le_bytes());
    h
}

/// Padding bytes after a container holding `stored` bytes of data.
pub fn container_padding(stored: usize) -> usize {
    (32 + stored) % 4
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn systemtime_round_trips_and_unset_is_zero() {
        let ns = 1_700_000_000_123_000_000;
        let mut b = Vec::new();
        put_systemtime(&mut b, ns);
        let st: Vec<u16> = b.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
        assert_eq!(st, [2023, 11, 2, 14, 22, 13, 20, 123]);
        assert_eq!(systemtime_ns(st.try_into().unwrap()), ns);
        assert_eq!(systemtime_ns([0; 8]), 0);
        assert_eq!(systemtime_ns([9999, 12, 0, 31, 23, 59, 59, 999]), 0, "past u64 ns");
    }

    #[test]
    fn frames_encode_and_decode_back() {
        let mut fd = Frame::classic(0x1ABC_DEF0, &[]);
        fd.flags.set(Flags::FD | Flags::BRS | Flags::TX, true);
        fd.len = 12;
        fd.data[..12].copy_from_slice(&[7; 12]);
        let mut rtr = Frame::classic(0x7FF, &[]);
        rtr.flags.set(Flags::RTR, true);
        rtr.len = 3;
        let mut err = Frame::classic(0, &[1, 2]);
        err.flags = Flags(Flags::ERR);
        err.id = CAN_ERR_BUSERROR;
        for (i, mut f) in [Frame::classic(0x123, &[1, 2, 3]), fd, rtr, err]
            .into_iter()
            .enumerate()
        {
            f.ts_ns = 1_700_000_000_000_000_000 + i as u64 * 1_234_567;
            let mut out = Vec::new();
            encode_frame(&mut out, &f, 2, 1_700_000_000_000_000_000);
            assert_eq!(out.len() % 4, 0);
            let Step::Object { skip: 0, len } = step(&out, 1 << 20) else {
                panic!("no object in {out:?}")
            };
            let got = object(&out[..len], 1_700_000_000_000_000_000).unwrap();
            assert_eq!(got, Object::Frame { channel: 2, frame: f }, "frame {i}");
        }
    }

    #[test]
    fn step_finds_objects_past_padding_and_damage() {
        let mut out = vec![0, 0, 0];
        encode_frame(&mut out, &Frame::classic(1, &[1]), 1, 0);
        assert_eq!(step(&out, 1 << 20), Step::Object { skip: 3, len: 48 });
        assert_eq!(step(&out[..20], 1 << 20), Step::NeedMore);
        let mut bad = b"garbage!".to_vec();
        bad.extend_from_slice(&out);
        assert!(matches!(step(&bad, 1 << 20), Step::Bad { at: 0, skip: 11, .. }));
        assert!(matches!(step(&out[3..], 40), Step::Bad { at: 0, skip: 4, .. }));
    }

    #[test]
    fn channel_names_match_asc() {
        assert_eq!(
            (channel_name(1), channel_name(0)),
            ("can0".to_string(), "canX".to_string())
        );
        assert_eq!(name_channel("can0"), Some(1));
        assert_eq!(name_channel("can12"), Some(13));
        assert_eq!(
            (name_channel("vcan0"), name_channel("can01"), name_channel("can")),
            (None, None, None)
        );
    }
}
