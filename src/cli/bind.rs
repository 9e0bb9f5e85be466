//! `--profile NODE=NAME` / `--eds NODE=FILE` to a ready decoder.

use crate::decode::Decoder;
use crate::od::bind::Bindings;

/// A decoder with the node bindings given on the command line; warnings go to stderr.
pub fn decoder(profiles: &[String], eds: &[String]) -> Result<Decoder, String> {
    let read = |p: &std::path::Path| std::fs::read_to_string(p);
    let b = Bindings::from_args(profiles, eds, &read)?;
    for w in b.warnings() {
        eprintln!("cotui: warning: {w}");
    }
    let bound = b.bound_nodes().map(|n| (n, b.dictionary(n).clone())).collect();
    Ok(Decoder::new(b.default_dictionary().clone(), bound))
}
