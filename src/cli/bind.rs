//! `--profile NODE=NAME` / `--eds NODE=FILE` to a ready decoder.

use crate::decode::Decoder;
use crate::od::Dictionary;

/// A decoder with the node bindings given on the command line; warnings go to stderr.
pub fn decoder(profiles: &[String], eds: &[String]) -> Result<Decoder, String> {
    if !profiles.is_empty() || !eds.is_empty() {
        return Err("profile bindings are not available yet".into());
    }
    Ok(Decoder::new(Dictionary::default(), vec![]))
}
