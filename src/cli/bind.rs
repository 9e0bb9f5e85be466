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

/// The bindings for a bus: on the `demo` bus, the simulated drives are also named by the
/// seed profiles they are built after (unless the user bound others to those nodes) and
/// their start-up PDO mappings are known, so PDOs decode from the first frame.
pub fn bindings_on(iface: &str, profiles: &[String], eds: &[String]) -> Result<Bindings, String> {
    if iface != crate::bus::DEMO {
        return bindings(profiles, eds);
    }
    let mut profiles = profiles.to_vec();
    for (node, profile) in crate::sim::DEMO_PROFILES {
        let bound = profiles
            .iter()
            .chain(eds)
            .any(|a| crate::od::bind::parse_node_arg(a).is_ok_and(|(n, _)| n == node));
        if !bound {
            profiles.push(format!("{node}={profile}"));
        }
    }
    let mut b = bindings(&profiles, eds)?;
    for (node, layer) in crate::sim::Simulation::demo().pdo_layers() {
        b.bind_layer(node, layer);
    }
    Ok(b)
}

/// A decoder with the node bindings given on the command line.
pub fn decoder(profiles: &[String], eds: &[String]) -> Result<Decoder, String> {
    Ok(Decoder::from_bindings(&bindings(profiles, eds)?))
}
