//! The wire figures of `canopen::wire` against a second implementation written here from
//! ISO 11898-1 the plain way: the frame as a vector of 0/1 values, the CRC by the
//! standard's shift-register pseudo-code, stuffing by scanning for runs. Thousands of
//! random classic and CAN FD frames must give the same bits, stuff bits and CRC.

// Test code may unwrap: a failed unwrap is a failed test with its location.
#![allow(clippy::unwrap_used)]

use canopen::frame::{Flags, Frame};
use canopen::wire::cache::FiguresCache;
use canopen::wire::{figures, rebuild};
use proptest::prelude::*;

/// `n` bits of `v`, MSB first.
fn bits(v: u64, n: usize) -> Vec<u8> {
    (0..n).rev().map(|k| ((v >> k) & 1) as u8).collect()
}

/// ISO 11898-1 CRC: CRC_RG shifted left, NXTBIT = bit XOR CRC_RG(top); XOR the generator
/// when NXTBIT is 1.
fn iso_crc(stream: &[u8], width: usize, generator: u64, init: u64) -> u64 {
    let mut reg: Vec<u8> = bits(init, width);
    let gen_bits = bits(generator, width);
    for &b in stream {
        let next = b ^ reg[0];
        reg.remove(0);
        reg.push(0);
        if next == 1 {
            for (r, g) in reg.iter_mut().zip(&gen_bits) {
                *r ^= g;
            }
        }
    }
    reg.iter().fold(0, |acc, &b| (acc << 1) | u64::from(b))
}

/// Inserts a complement after every 5 equal consecutive bits (the inserted bit counts in
/// the next run). Returns the stuffed stream and the count.
///
/// With `before_fixed` (CAN FD, the stream ends where the stuff count starts): the stuff
/// condition is checked when the next bit is about to go out, so 5 equal bits at the very
/// end take no stuff bit here, nor count one: the fixed stuff bit that starts the stuff
/// count (the complement of the last bit) is their stuff bit. ISO 11898-1:2015 10.5 as
/// modelled by CTU CAN FD's ISO 16845 test framework (`BitFrame::InsertNormalStuffBits`:
/// "there shall be no regular stuff bit inserted before stuff count").
fn iso_stuff(stream: &[u8], before_fixed: bool) -> (Vec<u8>, usize) {
    let mut out: Vec<u8> = Vec::new();
    let mut count = 0;
    for (k, &b) in stream.iter().enumerate() {
        out.push(b);
        let tail = &out[out.len().saturating_sub(5)..];
        let run_of_five = tail.len() == 5 && tail.iter().all(|&x| x == b);
        let at_end = k + 1 == stream.len();
        if run_of_five && !(before_fixed && at_end) {
            out.push(1 - b);
            count += 1;
        }
    }
    (out, count)
}

/// SOF and the identifier (with SRR, IDE and the extension for 29 bits), unstuffed.
fn iso_id(f: &Frame) -> Vec<u8> {
    let mut head = vec![0u8];
    let id = u64::from(f.id);
    if f.flags.has(Flags::EXT) {
        head.extend(bits(id >> 18, 11));
        head.extend([1, 1]);
        head.extend(bits(id & 0x3FFFF, 18));
    } else {
        head.extend(bits(id, 11));
    }
    head
}

fn iso_data(f: &Frame) -> Vec<u8> {
    f.payload().iter().flat_map(|&b| bits(u64::from(b), 8)).collect()
}

/// A CAN FD frame from SOF to the end of its data field, unstuffed: the part with dynamic
/// stuff bits.
fn iso_fd_dynamic_part(f: &Frame) -> Vec<u8> {
    let mut head = iso_id(f);
    let dlc = [0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64]
        .iter()
        .position(|&l| l == f.len)
        .unwrap() as u64;
    head.push(0); // RRS
    if !f.flags.has(Flags::EXT) {
        head.push(0); // IDE
    }
    head.extend([1, 0]); // FDF, res
    head.push(u8::from(f.flags.has(Flags::BRS)));
    head.push(u8::from(f.flags.has(Flags::ESI)));
    head.extend(bits(dlc, 4));
    head.extend(iso_data(f));
    head
}

/// The reference: (levels SOF..EOF, stuff bits, CRC).
fn reference(f: &Frame) -> (Vec<u8>, usize, u64) {
    let rtr = f.flags.has(Flags::RTR);
    let tail = [1u8; 10];
    if f.flags.has(Flags::FD) {
        let (mut sent, dynamic) = iso_stuff(&iso_fd_dynamic_part(f), true);
        let gray = [0b000, 0b001, 0b011, 0b010, 0b110, 0b111, 0b101, 0b100][dynamic % 8];
        let mut sc = bits(gray, 3);
        sc.push(sc.iter().sum::<u8>() % 2);
        let (width, generator) = if f.len > 16 { (21, 0x10_2899) } else { (17, 0x1_685B) };
        let covered: Vec<u8> = sent.iter().chain(&sc).copied().collect();
        let crc = iso_crc(&covered, width, generator, 1 << (width - 1));
        let field: Vec<u8> = sc.into_iter().chain(bits(crc, width)).collect();
        let mut fixed = 0;
        for (k, &b) in field.iter().enumerate() {
            if k % 4 == 0 {
                let prev = *sent.last().unwrap();
                sent.push(1 - prev);
                fixed += 1;
            }
            sent.push(b);
        }
        sent.extend(tail);
        (sent, dynamic + fixed, crc)
    } else {
        let dlc = if f.len == 8 && f.raw_dlc > 8 { f.raw_dlc } else { f.len };
        let mut head = iso_id(f);
        head.push(u8::from(rtr));
        head.extend([0, 0]); // IDE/r1, r0
        head.extend(bits(u64::from(dlc), 4));
        head.extend(iso_data(f));
        let crc = iso_crc(&head, 15, 0x4599, 0);
        head.extend(bits(crc, 15));
        let (mut sent, n) = iso_stuff(&head, false);
        sent.extend(tail);
        (sent, n, crc)
    }
}

fn check(f: &Frame) -> Result<(), TestCaseError> {
    let (levels, stuffs, crc) = reference(f);
    let fig = figures(f).map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(fig.bits as usize, levels.len());
    prop_assert_eq!(fig.stuff_bits as usize, stuffs);
    prop_assert_eq!(u64::from(fig.crc), crc);
    let wire = rebuild(f).map_err(|e| TestCaseError::fail(e.to_string()))?;
    let got: Vec<u8> = wire.bits.iter().map(|b| u8::from(b.level)).collect();
    prop_assert_eq!(got, levels);
    prop_assert_eq!(wire.figures, fig);
    Ok(())
}

fn classic() -> impl Strategy<Value = Frame> {
    (
        any::<bool>(),
        any::<u32>(),
        any::<bool>(),
        proptest::collection::vec(any::<u8>(), 0..=8),
        9u8..=15,
        any::<bool>(),
    )
        .prop_map(|(ext, id, rtr, data, raw, use_raw)| {
            let mut f = Frame::classic(0, &data);
            f.id = if ext { id & 0x1FFF_FFFF } else { id & 0x7FF };
            f.flags.set(Flags::EXT, ext);
            if f.len == 8 && use_raw {
                f.raw_dlc = raw;
            }
            if rtr {
                f.flags.set(Flags::RTR, true);
                f.data = [0; 64];
            }
            f
        })
}

fn fd() -> impl Strategy<Value = Frame> {
    let lens = prop::sample::select(vec![0u8, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64]);
    (
        any::<bool>(),
        any::<u32>(),
        lens,
        proptest::collection::vec(any::<u8>(), 64),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(ext, id, len, data, brs, esi)| {
            let mut f = Frame {
                len,
                ..Frame::default()
            };
            f.data[..len as usize].copy_from_slice(&data[..len as usize]);
            f.id = if ext { id & 0x1FFF_FFFF } else { id & 0x7FF };
            f.flags.set(Flags::EXT, ext);
            f.flags.set(Flags::FD, true);
            f.flags.set(Flags::BRS, brs);
            f.flags.set(Flags::ESI, esi);
            f
        })
}

/// Runs of equal bytes (0x00, 0xFF) stuff the most: make them likely.
fn sparse_classic() -> impl Strategy<Value = Frame> {
    let byte = prop::sample::select(vec![0x00u8, 0xFF, 0x0F, 0xF0, 0x7E, 0x81]);
    (
        any::<bool>(),
        prop::sample::select(vec![0u32, 0x7FF, 0x1FFF_FFFF, 0x80, 0x3E0]),
        proptest::collection::vec(byte, 0..=8),
    )
        .prop_map(|(ext, id, data)| {
            let mut f = Frame::classic(0, &data);
            f.id = if ext { id } else { id & 0x7FF };
            f.flags.set(Flags::EXT, ext);
            f
        })
}

/// A CAN FD frame whose dynamic part (SOF to the end of the data field) ends with 5 equal
/// bits since the last bit change or stuff bit: the stuff condition is met exactly where
/// the stuff count starts.
fn ends_in_a_pending_stuff_bit(f: &Frame) -> bool {
    let part = iso_fd_dynamic_part(f);
    iso_stuff(&part, false).1 != iso_stuff(&part, true).1
}

/// Random CAN FD frames that end in five equal bits before the stuff count: the last byte
/// ends in 0b00000 or 0b11111 (or there is no data and the DLC ends the run), and those
/// whose run does not end exactly there are left out.
fn fd_ending_in_a_run() -> impl Strategy<Value = Frame> {
    (fd(), prop::sample::select(vec![0x00u8, 0xE0, 0x1F, 0xFF, 0x20, 0xDF]))
        .prop_map(|(mut f, last)| {
            if f.len > 0 {
                let i = usize::from(f.len) - 1;
                f.data[i] = (f.data[i] & 0xE0) | (last & 0x1F);
                if last & 0x20 != 0 {
                    f.data[i] = last;
                }
            }
            f
        })
        .prop_filter("the stuff condition is met where the stuff count starts", |f| {
            ends_in_a_pending_stuff_bit(f)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    #[test]
    fn classic_frames_match_the_iso_reference(f in classic()) {
        check(&f)?;
    }
    #[test]
    fn fd_frames_match_the_iso_reference(f in fd()) {
        check(&f)?;
    }
    /// The edge of ISO 11898-1:2015: 5 equal bits right before the stuff count take the
    /// fixed stuff bit as their only stuff bit, and the stuff count does not count it.
    #[test]
    fn fd_frames_ending_in_five_equal_bits_match_the_iso_reference(f in fd_ending_in_a_run()) {
        check(&f)?;
    }
    #[test]
    fn long_runs_match_the_iso_reference(f in sparse_classic()) {
        check(&f)?;
    }
}

/// Frames that repeat (a pool of a few, picked again and again) and near repeats (the same
/// identifier with other data or length, bytes past the length set), classic and CAN FD,
/// 11- and 29-bit, and identifiers out of range.
fn repeating() -> impl Strategy<Value = Vec<Frame>> {
    let any_frame = prop_oneof![classic(), sparse_classic(), fd()];
    (
        proptest::collection::vec(any_frame, 1..12),
        proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..200),
    )
        .prop_map(|(pool, picks)| {
            picks
                .into_iter()
                .map(|(i, byte, change)| {
                    let mut f = *i.get(&pool);
                    match change {
                        // Another first byte, or a byte past the length (not on the wire).
                        1 => f.data[0] = byte,
                        2 if !f.is_fd() && f.len < 8 => f.data[usize::from(f.len)] = byte,
                        3 if !f.is_fd() => f.id = u32::from(byte) << 21,
                        _ => {}
                    }
                    f
                })
                .collect()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]
    /// The memo gives what `figures` gives, frame after frame, refusals included.
    #[test]
    fn the_figures_cache_gives_the_figures(frames in repeating()) {
        let mut cache = FiguresCache::new();
        for f in &frames {
            prop_assert_eq!(cache.figures(f), figures(f), "{:?}", f);
        }
    }
}

/// canworks' documented example (docs/frame-inspector.md): 79 bits + 3 intermission, 3
/// stuff bits, CRC 0x47DC.
#[test]
fn canworks_example_by_the_reference_too() {
    let f = Frame::classic(0x185, &[0x25, 0x00, 0xEA, 0x00]);
    let (levels, stuffs, crc) = reference(&f);
    assert_eq!((levels.len(), stuffs, crc), (79, 3, 0x47DC));
    assert_eq!(figures(&f).unwrap().bus_bits(), 82);
}
