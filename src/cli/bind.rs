//! `--profile NODE=NAME` / `--eds NODE=FILE` to a ready decoder.

use crate::decode::Decoder;
use crate::od::Warning;
use crate::od::bind::Bindings;

use crate::files::read_capped;

/// Why the dictionaries given on the command line cannot be used.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BindError {
    /// A `--profile` or `--eds` argument, or the file it names, is not usable.
    #[error("{0}")]
    Dictionary(String),
}

impl From<BindError> for crate::command::CommandError {
    fn from(e: BindError) -> Self {
        crate::command::CommandError::Usage(e.to_string())
    }
}

/// Loads the bindings given on the command line; warnings go to stderr, one line per kind
/// of warning and file (all of them with `--verbose`).
pub fn bindings(profiles: &[String], eds: &[String]) -> Result<Bindings, BindError> {
    let b = Bindings::from_args(profiles, eds, &read_capped).map_err(|e| BindError::Dictionary(e.to_string()))?;
    for line in warning_lines(b.warnings(), super::verbose()) {
        eprintln!("cotui: warning: {line}");
    }
    Ok(b)
}

/// The warnings as printed: every one when `all`, else the first of each kind per file with
/// how many more there are. A kind is the message with its quoted parts and numbers
/// blanked, so `` `0` is not hex bytes `` and `` `NULL` is not hex bytes `` are one kind.
pub fn warning_lines(warnings: &[Warning], all: bool) -> Vec<String> {
    if all {
        return warnings.iter().map(Warning::to_string).collect();
    }
    let mut groups: Vec<((&str, String), &Warning, usize)> = Vec::new();
    for w in warnings {
        let key = (w.file.as_str(), kind_of(&w.message));
        match groups.iter_mut().find(|(k, _, _)| *k == key) {
            Some((_, _, n)) => *n += 1,
            None => groups.push((key, w, 0)),
        }
    }
    groups
        .into_iter()
        .map(|(_, w, more)| match more {
            0 => w.to_string(),
            n => format!("{w} (and {n} more like it; --verbose lists them)"),
        })
        .collect()
}

/// A warning message with `quoted` parts and digits blanked: its kind.
fn kind_of(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut quoted = false;
    for c in message.chars() {
        match c {
            '`' => {
                quoted = !quoted;
                out.push('`');
            }
            _ if quoted => {}
            c if c.is_ascii_hexdigit() && out.ends_with(['#', 'x']) => {}
            c if c.is_ascii_digit() => {
                if !out.ends_with('#') {
                    out.push('#');
                }
            }
            c => out.push(c),
        }
    }
    out
}

/// The bindings for a bus: on the `demo` bus those of [`bindings_for_demo`] with the
/// standard demo drives.
pub fn bindings_on(iface: &str, profiles: &[String], eds: &[String]) -> Result<Bindings, BindError> {
    if iface != crate::connect::DEMO {
        return bindings(profiles, eds);
    }
    bindings_for_demo(&crate::sim::Simulation::demo(), profiles, eds)
}

/// The bindings for a demo bus running `sim`: the simulated drives are also named by the
/// seed profiles they are built after (unless the user bound others to those nodes) and
/// their start-up PDO mappings are known, so PDOs decode from the first frame.
pub fn bindings_for_demo(
    sim: &crate::sim::Simulation,
    profiles: &[String],
    eds: &[String],
) -> Result<Bindings, BindError> {
    let mut profiles = profiles.to_vec();
    for (node, profile) in sim.profiles() {
        let bound = profiles
            .iter()
            .chain(eds)
            .any(|a| crate::od::bind::parse_node_arg(a).is_ok_and(|(n, _)| n == node));
        if !bound {
            profiles.push(format!("{node}={profile}"));
        }
    }
    let mut b = bindings(&profiles, eds)?;
    for (node, mut layer) in sim.pdo_layers() {
        // The layer is the device's configuration; it goes by the profile bound to the node.
        layer.name = b.dictionary(node).profile_name().to_string();
        b.bind_config(node, layer);
    }
    Ok(b)
}

/// A decoder with the node bindings given on the command line.
pub fn decoder(profiles: &[String], eds: &[String]) -> Result<Decoder, BindError> {
    Ok(Decoder::from_bindings(&bindings(profiles, eds)?))
}
