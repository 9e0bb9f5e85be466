//! The two tables that make the per-frame figures cheap: CRC-15 one byte at a time, and
//! the bit-stuffing state machine one byte at a time. Both are built at compile time from
//! the bit-by-bit rule they replace ([`crc_bit`], [`stuff_step`]).

/// The CRC-15 generator of classic CAN, x^15 + x^14 + x^10 + x^8 + x^7 + x^4 + x^3 + 1.
pub(crate) const CRC15_POLY: u32 = 0x4599;

/// One bit into a CRC register of `width` bits with generator `poly` (MSB first).
pub(crate) const fn crc_bit(crc: u32, bit: bool, width: u32, poly: u32) -> u32 {
    let top = ((crc >> (width - 1)) & 1 == 1) ^ bit;
    let shifted = (crc << 1) & ((1 << width) - 1);
    if top { shifted ^ poly } else { shifted }
}

/// CRC-15 of every byte value fed into a zero register, MSB first.
const CRC15_TABLE: [u16; 256] = {
    let mut t = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = (i as u32) << 7;
        let mut k = 0;
        while k < 8 {
            let top = crc & 0x4000 != 0;
            crc = (crc << 1) & 0x7FFF;
            if top {
                crc ^= CRC15_POLY;
            }
            k += 1;
        }
        t[i] = crc as u16;
        i += 1;
    }
    t
};

/// One whole byte into a CRC-15 register (its 8 bits, MSB first).
pub(crate) fn crc15_byte(crc: u32, byte: u8) -> u32 {
    let i = ((crc >> 7) ^ u32::from(byte)) & 0xFF;
    ((crc << 8) ^ u32::from(CRC15_TABLE[i as usize])) & 0x7FFF
}

/// The state of the stuffing rule between bits: the level of the last bit sent (bit 2) and
/// how many equal bits end the stream so far, less one (bits 0..2: 1 to 4 equal bits; at 5
/// a stuff bit of the other level goes out and starts a new run of 1).
pub(crate) type StuffState = u8;

/// The state before SOF: as if a recessive bit came last, so that SOF (dominant) starts the
/// first run.
pub(crate) const STUFF_START: StuffState = 0b100;

/// One bit through the stuffing rule: the new state, and whether a stuff bit follows it.
pub(crate) const fn stuff_step(state: StuffState, bit: bool) -> (StuffState, bool) {
    let level = state & 0b100 != 0;
    let run = if level == bit { (state & 0b11) + 2 } else { 1 };
    if run == 5 {
        // The stuff bit has the other level and is a run of 1 of its own.
        (if bit { 0b000 } else { 0b100 }, true)
    } else {
        ((if bit { 0b100 } else { 0 }) | (run - 1), false)
    }
}

/// For each state and byte: the state after the byte's 8 bits (bits 0..3) and the stuff
/// bits they cause (bits 3..).
const STUFF_TABLE: [[u8; 256]; 8] = {
    let mut t = [[0u8; 256]; 8];
    let mut s = 0;
    while s < 8 {
        let mut b = 0;
        while b < 256 {
            let mut state = s as u8;
            let mut stuffs = 0u8;
            let mut k = 0;
            while k < 8 {
                let (next, stuffed) = stuff_step(state, (b >> (7 - k)) & 1 == 1);
                state = next;
                if stuffed {
                    stuffs += 1;
                }
                k += 1;
            }
            t[s][b] = state | (stuffs << 3);
            b += 1;
        }
        s += 1;
    }
    t
};

/// One whole byte through the stuffing rule: the new state and the stuff bits it causes.
pub(crate) fn stuff_byte(state: StuffState, byte: u8) -> (StuffState, u32) {
    let e = STUFF_TABLE[usize::from(state & 0b111)][usize::from(byte)];
    (e & 0b111, u32::from(e >> 3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_tables_equal_their_bit_rules() {
        for start in [0u32, 1, 0x4599, 0x7FFF, 0x1234] {
            for byte in 0..=255u8 {
                let bitwise = (0..8).fold(start, |c, k| crc_bit(c, (byte >> (7 - k)) & 1 == 1, 15, CRC15_POLY));
                assert_eq!(crc15_byte(start, byte), bitwise);
            }
        }
        for state in 0..8u8 {
            for byte in 0..=255u8 {
                let (mut s, mut n) = (state, 0);
                for k in 0..8 {
                    let (next, stuffed) = stuff_step(s, (byte >> (7 - k)) & 1 == 1);
                    s = next;
                    n += u32::from(stuffed);
                }
                assert_eq!(stuff_byte(state, byte), (s, n));
            }
        }
    }

    #[test]
    fn five_equal_bits_take_a_stuff_bit_of_the_other_level() {
        let mut s = STUFF_START;
        let mut stuffed = Vec::new();
        for bit in [false, false, false, false, false, false, true] {
            let (next, st) = stuff_step(s, bit);
            s = next;
            stuffed.push(st);
        }
        assert_eq!(stuffed, [false, false, false, false, true, false, false]);
    }
}
