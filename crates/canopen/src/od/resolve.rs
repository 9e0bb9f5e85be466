//! What a user typed (`0x6041`, `F0.3.018`, `Statusword`) resolved to an (index, sub)
//! through a node's [`Dictionary`].

use super::alias::{ObjectError, parse_object_ref};
use super::dictionary::Dictionary;

/// Resolves what a user typed to (index, sub) through `dict`.
///
/// Accepts, in this order: an index form (`0x6041`, `0x1018:1`, `0x1018sub1`,
/// `6041h`, `6041`), a vendor alias (primary `alias`, the `aliases` table, then
/// `alias_rules`; each searched from the most specific layer), then an object
/// name (case-insensitive, the first layer that has it; `Identity object:1`
/// names a sub by number).
pub fn resolve_object(dict: &Dictionary, text: &str) -> Result<(u16, u8), ObjectError> {
    let t = text.trim();
    if t.is_empty() {
        return Err(ObjectError::Empty);
    }
    if let Some(r) = parse_object_ref(t) {
        return Ok(r);
    }
    for layer in dict.layers() {
        if let Some((k, _)) = layer.find_entry(|o| o.alias.as_deref().is_some_and(|a| a.eq_ignore_ascii_case(t))) {
            return Ok(k);
        }
        if let Some((_, r)) = layer.aliases.iter().find(|(a, _)| a.eq_ignore_ascii_case(t)) {
            return Ok(*r);
        }
    }
    for layer in dict.layers() {
        if let Some(r) = layer.alias_rules.iter().find_map(|rule| rule.apply(t)) {
            return Ok(r);
        }
    }
    let (name, sub) = match t.rsplit_once(':') {
        Some((n, s)) => match s.trim().parse::<u8>() {
            Ok(s) => (n.trim(), Some(s)),
            Err(_) => (t, None),
        },
        None => (t, None),
    };
    for layer in dict.layers() {
        if let Some(i) = layer.find_name(|n| n.eq_ignore_ascii_case(name)) {
            return Ok((i, sub.unwrap_or(0)));
        }
        if let Some(((i, s), _)) = layer.find_entry(|o| o.name.eq_ignore_ascii_case(name)) {
            return Ok((i, sub.unwrap_or(s)));
        }
    }
    Err(ObjectError::Unknown {
        text: t.to_string(),
        profile: dict.profile_name().to_string(),
    })
}
