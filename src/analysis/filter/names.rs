//! How a filter names objects: hex forms always, names and vendor aliases through the
//! dictionaries of a decoder.

use crate::decode::Decoder;
use crate::od::Dictionary;

/// Resolves object names and vendor aliases to (index, sub).
pub trait Names {
    /// The object `text` names, if any.
    fn object(&self, text: &str) -> Option<(u16, u8)>;
}

/// No names: only hex object forms.
pub struct NoNames;

impl Names for NoNames {
    fn object(&self, _: &str) -> Option<(u16, u8)> {
        None
    }
}

/// Names of every dictionary a decoder uses (the default and each bound profile).
impl Names for Decoder {
    fn object(&self, text: &str) -> Option<(u16, u8)> {
        let mut seen: Vec<&Dictionary> = Vec::new();
        for node in 0..128u8 {
            let d = self.dictionary(node);
            let same = |o: &&Dictionary| {
                o.layers().len() == d.layers().len()
                    && o.layers()
                        .iter()
                        .zip(d.layers())
                        .all(|(a, b)| std::sync::Arc::ptr_eq(a, b))
            };
            if seen.iter().any(same) {
                continue;
            }
            seen.push(d);
            if let Ok(r) = crate::od::resolve_object(d, text) {
                return Some(r);
            }
        }
        None
    }
}
