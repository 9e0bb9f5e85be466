//! The block transfer CRC of CiA 301: CRC-16-CCITT, polynomial 0x1021,
//! initial value 0, no reflection, no final XOR (a.k.a. CRC-16/XMODEM).

/// Continues a CRC over more bytes (start with 0).
pub(crate) fn crc16_update(mut crc: u16, bytes: &[u8]) -> u16 {
    for &b in bytes {
        crc ^= (b as u16) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// The CRC of a whole transfer.
pub(crate) fn crc16(bytes: &[u8]) -> u16 {
    crc16_update(0, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_value() {
        // The catalogue check value of CRC-16/XMODEM.
        assert_eq!(crc16(b"123456789"), 0x31C3);
        assert_eq!(crc16(&[]), 0);
    }

    #[test]
    fn incremental_equals_whole() {
        let a = crc16_update(crc16_update(0, b"1234"), b"56789");
        assert_eq!(a, crc16(b"123456789"));
    }
}
