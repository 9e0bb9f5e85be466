//! `--profile NODE=NAME` / `--eds NODE=FILE` to a ready decoder.

use crate::decode::Decoder;
use crate::od::bind::Bindings;

/// Loads the bindings given on the command line; warnings go to stderr.
pub fn bindings(profiles: &[String], eds: &[String]) -> Result<Bindings, String> {
    let b = Bindings::from_args(profiles, eds, &|p| std::fs::read_to_string(p))?;
    for w in b.warnings() {
        eprintln!("cotui: warning: {w}");
    }
    Ok(b)
}

/// A decoder with the node bindings given on the command line.
pub fn decoder(profiles: &[String], eds: &[String]) -> Result<Decoder, String> {
    Ok(Decoder::from_bindings(&bindings(profiles, eds)?))
}
