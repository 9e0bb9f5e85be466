//! Durations as the user writes them (`500ms`, `30s`, `1.5s`, `2min`, `1h`, or a bare
//! number in a unit the flag gives), for every flag that takes a time and for the
//! triggers' `within`.

/// The units a duration takes, with their length in ms.
const UNITS: &[(&str, f64)] = &[("ms", 1.0), ("s", 1e3), ("min", 60e3), ("h", 3600e3)];

/// `text` as whole ms (0 included): a number with a unit (decimals allowed, rounded to
/// the ms), or a bare number counting `bare_ms` ms each (with `bare_ms` 1, an integer,
/// decimal or `0x` hex, as ms flags always took). None when it is neither.
pub fn ms(text: &str, bare_ms: f64) -> Option<u64> {
    let t = text.trim();
    let bare_int = bare_ms == 1.0;
    if bare_int && let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        return u64::from_str_radix(&h.replace('_', ""), 16).ok();
    }
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '_'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let scale = match unit.trim() {
        "" if bare_int => return number.replace('_', "").parse().ok(),
        "" => bare_ms,
        u => UNITS.iter().find(|(name, _)| *name == u)?.1,
    };
    let n: f64 = number.replace('_', "").parse().ok()?;
    let v = (n * scale).round();
    (n.is_finite() && (0.0..1.8e16).contains(&v)).then_some(v as u64)
}

#[cfg(test)]
mod tests {
    #[test]
    fn units_and_bare_numbers() {
        let ms = |t| super::ms(t, 1.0);
        assert_eq!(ms("1_000"), Some(1000));
        assert_eq!(ms("0x1F"), Some(31));
        assert_eq!(ms("1.5"), None, "a bare ms count is whole");
        assert_eq!(ms("2 min"), Some(120_000));
        assert_eq!(super::ms("1.5", 1e3), Some(1500));
        assert_eq!(ms("5 sec"), None);
    }
}
