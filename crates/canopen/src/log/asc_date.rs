//! The `date` line of a Vector ASC log as nanoseconds since the Unix epoch.
//!
//! ```text
//! date Tue Nov 14 22:13:20 2023
//! date Tue Nov 14 22:13:20.000 2023
//! date Tue Mar 5 10:00:00.000 am 2024
//! date Sam Sep 30 15:06:13.191 2017
//! ```
//! The weekday is read past (it may be in any language); months are English or German
//! (`Mär`, `Mai`, `Okt`, `Dez`); the time may have a fraction and an `am`/`pm` marker. ASC
//! does not say the time zone of the logging PC: the date is taken as UTC.

use super::lex::{Tokens, dec_u32};

/// The time a `date` line's words (after `date`) name, in ns since 1970; `None` when the
/// words are not a date of 1970 or later.
pub(crate) fn parse(toks: &mut Tokens<'_>) -> Option<u64> {
    let _weekday = toks.next()?;
    let month = month(toks.next()?.1)?;
    let day = dec_u32(toks.next()?.1).filter(|d| (1..=31).contains(d))?;
    let (h, m, sec_ns) = clock(toks.next()?.1)?;
    let (mut word, mut h) = (toks.next()?.1, h);
    if let Some(pm) = am_pm(word) {
        if !(1..=12).contains(&h) {
            return None;
        }
        h = h % 12 + if pm { 12 } else { 0 };
        word = toks.next()?.1;
    }
    let year = dec_u32(word).filter(|y| (1970..=9999).contains(y))?;
    let days = days_since_epoch(year, month, day);
    let secs = ((days * 24 + u64::from(h)) * 60 + u64::from(m)) * 60;
    secs.checked_mul(1_000_000_000)?.checked_add(sec_ns)
}

fn month(word: &[u8]) -> Option<u32> {
    Some(match word {
        b"Jan" => 1,
        b"Feb" => 2,
        b"Mar" | b"M\xC3\xA4r" | b"Mrz" => 3,
        b"Apr" => 4,
        b"May" | b"Mai" => 5,
        b"Jun" => 6,
        b"Jul" => 7,
        b"Aug" => 8,
        b"Sep" => 9,
        b"Oct" | b"Okt" => 10,
        b"Nov" => 11,
        b"Dec" | b"Dez" => 12,
        _ => return None,
    })
}

/// `am` (false) or `pm` (true), any case.
fn am_pm(word: &[u8]) -> Option<bool> {
    match word.to_ascii_lowercase().as_slice() {
        b"am" => Some(false),
        b"pm" => Some(true),
        _ => None,
    }
}

/// `HH:MM:SS[.fraction]`: hours, minutes and the seconds in ns.
fn clock(word: &[u8]) -> Option<(u32, u32, u64)> {
    let mut parts = word.splitn(3, |&b| b == b':');
    let h = dec_u32(parts.next()?).filter(|&h| h < 24)?;
    let m = dec_u32(parts.next()?).filter(|&m| m < 60)?;
    let sec = parts.next()?;
    let (whole, frac) = match sec.iter().position(|&b| b == b'.') {
        Some(i) => (&sec[..i], &sec[i + 1..]),
        None => (sec, &sec[..0]),
    };
    let s = dec_u32(whole).filter(|&s| s < 61)?;
    let mut ns = 0u64;
    for k in 0..9 {
        let digit = match frac.get(k) {
            Some(b) if b.is_ascii_digit() => u64::from(b - b'0'),
            Some(_) => return None,
            None => 0,
        };
        ns = ns * 10 + digit;
    }
    if frac.len() > 9 && !frac[9..].iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some((h, m, u64::from(s) * 1_000_000_000 + ns))
}

/// Days from 1970-01-01 to `year-month-day` (proleptic Gregorian; `year` >= 1970).
fn days_since_epoch(year: u32, month: u32, day: u32) -> u64 {
    let leap = |y: u32| (y.is_multiple_of(4) && !y.is_multiple_of(100)) || y.is_multiple_of(400);
    const BEFORE: [u32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
    let full_years: u64 = (1970..year).map(|y| if leap(y) { 366 } else { 365 }).sum();
    let in_year = BEFORE[(month - 1) as usize] + u32::from(month > 2 && leap(year)) + day - 1;
    full_years + u64::from(in_year)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn date(s: &str) -> Option<u64> {
        parse(&mut Tokens::new(s.as_bytes(), 0))
    }

    #[test]
    fn the_shapes_of_date_lines() {
        assert_eq!(date("Tue Nov 14 22:13:20 2023"), Some(1_700_000_000_000_000_000));
        assert_eq!(date("Tue Nov 14 22:13:20.250 2023"), Some(1_700_000_000_250_000_000));
        assert_eq!(date("Tue Nov 14 10:13:20.000 pm 2023"), Some(1_700_000_000_000_000_000));
        assert_eq!(date("Tue Mar 5 12:00:00.000 am 2024"), Some(1_709_596_800_000_000_000));
        assert_eq!(date("Tue Mar 5 12:00:00 PM 2024"), Some(1_709_640_000_000_000_000));
        assert_eq!(date("Sam Sep 30 15:06:13.191 2017"), Some(1_506_783_973_191_000_000));
        assert_eq!(date("Thu Feb 29 00:00:00 2024"), Some(1_709_164_800_000_000_000));
        assert_eq!(date("Thu Jan 1 00:00:00 1970"), Some(0));
    }

    #[test]
    fn malformed_dates_are_none() {
        for bad in [
            "Tue Nov 14 22:13:20",
            "Tue Foo 14 22:13:20 2023",
            "Tue Nov 32 22:13:20 2023",
            "Tue Nov 14 24:13:20 2023",
            "Tue Nov 14 13:13:20 pm 2023",
            "Tue Nov 14 22:13:2x 2023",
            "Tue Nov 14 22:13:20.1x 2023",
            "Tue Nov 14 22:13:20 1969",
            "",
        ] {
            assert_eq!(date(bad), None, "{bad}");
        }
    }
}
