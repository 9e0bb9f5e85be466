use super::*;

fn frame(id: u32, data: &[u8]) -> Frame {
    Frame::classic(id, data)
}

/// canworks' documented example: `185#2500EA00` is 79 bits (+ 3 intermission), 3 stuff
/// bits, CRC 0x47DC.
#[test]
fn canworks_example() {
    let f = figures(&frame(0x185, &[0x25, 0x00, 0xEA, 0x00])).unwrap();
    assert_eq!((f.bits, f.bus_bits(), f.stuff_bits, f.crc), (79, 82, 3, 0x47DC));
    assert_eq!(f.time_us(500_000), 158.0);
    let w = rebuild(&frame(0x185, &[0x25, 0x00, 0xEA, 0x00])).unwrap();
    assert_eq!(w.figures, f);
    assert_eq!(w.bits.len(), 79);
    assert_eq!(w.bits.iter().filter(|b| b.stuff).count(), 3);
    assert_eq!(
        w.bits[0],
        Bit {
            level: false,
            field: Field::Sof,
            stuff: false
        }
    );
    assert_eq!(w.bits.iter().filter(|b| b.field == Field::Eof).count(), 7);
}

#[test]
fn every_stuff_bit_follows_five_equal_bits_and_has_the_other_level() {
    for data in [&[0u8; 8][..], &[0xFF; 8], &[0x0F, 0xF0, 0x00], &[]] {
        for id in [0x000, 0x7FF, 0x1FFF_FFFF, 0x80] {
            let w = rebuild(&frame(id, data)).unwrap();
            let end = w.bits.iter().position(|b| b.field == Field::CrcDelim).unwrap();
            let mut run = (true, 0);
            for b in &w.bits[..end] {
                if b.stuff {
                    assert_eq!(run, (!b.level, 5), "{id:X} {data:?}");
                }
                run = if b.level == run.0 {
                    (run.0, run.1 + 1)
                } else {
                    (b.level, 1)
                };
                assert!(run.1 <= 5, "six equal bits in {id:X} {data:?}");
            }
        }
    }
}

#[test]
fn refusals_say_why() {
    let mut err = frame(4, &[0; 8]);
    err.flags = Flags(Flags::ERR);
    assert_eq!(figures(&err), Err(WireError::ErrorFrame));
    let mut big = frame(0x7FF, &[]);
    big.id = 0x800;
    assert_eq!(
        figures(&big).unwrap_err().to_string(),
        "identifier 0x800 does not fit 11 bits (at most 0x7FF)"
    );
    let mut fd = frame(0x185, &[]);
    fd.flags = Flags(Flags::FD);
    fd.len = 13;
    assert!(
        figures(&fd)
            .unwrap_err()
            .to_string()
            .contains("no CAN FD DLC gives 13 bytes")
    );
    fd.len = 8;
    fd.flags = Flags(Flags::FD | Flags::RTR);
    assert_eq!(figures(&fd), Err(WireError::FdRemote));
    let mut long = frame(0x185, &[]);
    long.len = 9;
    assert_eq!(figures(&long), Err(WireError::ClassicLength(9)));
}

#[test]
fn remote_frames_carry_no_data_but_their_dlc() {
    let mut r = frame(0x705, &[]);
    r.flags = Flags(Flags::RTR);
    r.len = 1;
    let w = rebuild(&r).unwrap();
    assert!(w.bits.iter().all(|b| b.field != Field::Data));
    let dlc: Vec<bool> = w
        .bits
        .iter()
        .filter(|b| b.field == Field::Dlc && !b.stuff)
        .map(|b| b.level)
        .collect();
    assert_eq!(dlc, [false, false, false, true]);
    assert_eq!(figures(&r).unwrap(), w.figures);
}

#[test]
fn fd_frames_have_a_stuff_count_and_fixed_stuff_bits() {
    let mut fd = frame(0x185, &[]);
    fd.flags = Flags(Flags::FD | Flags::BRS);
    fd.len = 20;
    let w = rebuild(&fd).unwrap();
    assert_eq!(w.figures.crc_bits, 21);
    let tail = w
        .bits
        .iter()
        .skip_while(|b| !matches!(b.field, Field::StuffCount))
        .take_while(|b| b.field != Field::CrcDelim);
    // 4 stuff count bits + 21 CRC bits with 7 fixed stuff bits.
    let (fixed, plain): (Vec<&Bit>, Vec<&Bit>) = tail.partition(|b| b.stuff);
    assert_eq!((fixed.len(), plain.len()), (7, 25));
    fd.len = 16;
    assert_eq!(figures(&fd).unwrap().crc_bits, 17);
}

/// ISO 11898-1:2015: CAN FD `185##020` ends its data field with 5 dominant bits; the fixed
/// stuff bit before the stuff count is their only stuff bit (no dynamic one before it) and
/// the stuff count counts only the one dynamic stuff bit of the identifier.
#[test]
fn fd_run_of_five_before_the_stuff_count_takes_only_the_fixed_stuff_bit() {
    let mut fd = frame(0x185, &[0x20]);
    fd.flags = Flags(Flags::FD);
    let w = rebuild(&fd).unwrap();
    let sc = w.bits.iter().position(|b| b.field == Field::StuffCount).unwrap();
    let before: Vec<(bool, bool)> = w.bits[sc - 5..sc].iter().map(|b| (b.level, b.stuff)).collect();
    assert_eq!(
        before,
        [(false, false); 5],
        "the data field ends with 5 dominant data bits"
    );
    assert_eq!(
        w.bits[sc],
        Bit {
            level: true,
            field: Field::StuffCount,
            stuff: true
        }
    );
    let dynamic = w.bits[..sc].iter().filter(|b| b.stuff).count();
    assert_eq!(dynamic, 1);
    // Gray code of 1 is 001, even parity 1.
    let count: Vec<bool> = w.bits[sc..]
        .iter()
        .filter(|b| b.field == Field::StuffCount && !b.stuff)
        .map(|b| b.level)
        .collect();
    assert_eq!(count, [false, false, true, true]);
}
