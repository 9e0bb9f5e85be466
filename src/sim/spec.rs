//! `--node NODE=MODEL[@SERIAL]`: which simulated drive sits at which node, for both
//! `cotui sim IFACE` and `cotui demo` (one parser, one list of models).

use super::drive::Drive;
use super::profile::{DriveProfile, MODELS};

/// Why a `--node` does not parse.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NodeSpecError {
    #[error("--node {0}: expected NODE=MODEL[@SERIAL], e.g. 2=aimotor")]
    Form(String),
    #[error("--node {spec}: node-ID `{node}` is not 1..127 or ff")]
    NodeId { spec: String, node: String },
    #[error("--node {spec}: serial `{serial}` is not a number")]
    Serial { spec: String, serial: String },
    #[error("--node {spec}: unknown drive `{model}`; the simulated drives: {}", models())]
    Model { spec: String, model: String },
    #[error("--node {0}: node {1} is given twice")]
    Twice(String, u8),
}

/// The models, comma separated.
fn models() -> String {
    MODELS.join(", ")
}

/// A number in decimal or `0x` hex.
pub fn number(s: &str) -> Option<u32> {
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16).ok(),
        None => s.parse().ok(),
    }
}

/// Parses `NODE=MODEL[@SERIAL]` (NODE 1..127, or `ff` for a drive without node-ID).
pub fn parse_node(spec: &str) -> Result<(u8, DriveProfile), NodeSpecError> {
    let (node, rest) = spec.split_once('=').ok_or_else(|| NodeSpecError::Form(spec.into()))?;
    let node = match node.to_ascii_lowercase().as_str() {
        "ff" | "0xff" => 0xFF,
        n => match n.parse::<u8>() {
            Ok(v @ (1..=127 | 255)) => v,
            _ => {
                return Err(NodeSpecError::NodeId {
                    spec: spec.into(),
                    node: node.into(),
                });
            }
        },
    };
    let (name, serial) = match rest.split_once('@') {
        Some((m, s)) => {
            let serial = number(s).ok_or_else(|| NodeSpecError::Serial {
                spec: spec.into(),
                serial: s.into(),
            })?;
            (m, Some(serial))
        }
        None => (rest, None),
    };
    let mut profile = DriveProfile::model(name).ok_or_else(|| NodeSpecError::Model {
        spec: spec.into(),
        model: name.into(),
    })?;
    profile.serial_number = serial;
    Ok((node, profile))
}

/// The drives of a list of `--node` values, `default` when the list is empty; a node-ID
/// given twice is an error (several `ff` drives are fine: LSS tells them apart).
pub fn drives(specs: &[String], default: &[&str]) -> Result<Vec<Drive>, NodeSpecError> {
    let specs: Vec<&str> = if specs.is_empty() {
        default.to_vec()
    } else {
        specs.iter().map(String::as_str).collect()
    };
    let mut drives: Vec<Drive> = Vec::new();
    for spec in specs {
        let (node, profile) = parse_node(spec)?;
        if node != 0xFF && drives.iter().any(|d| d.node() == node) {
            return Err(NodeSpecError::Twice(spec.into(), node));
        }
        drives.push(Drive::new(node, profile));
    }
    Ok(drives)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_specs_parse_or_say_what_is_wrong() {
        let (n, p) = parse_node("ff=servo@0x1234").unwrap();
        assert_eq!((n, p.serial_number), (0xFF, Some(0x1234)));
        assert_eq!(parse_node("3=syntron-ds").unwrap().0, 3);
        assert_eq!(parse_node("4=dexmart-dev").unwrap().1.dictionary, "dexmart-dev");
        assert_eq!(
            parse_node("200=aimotor").unwrap_err().to_string(),
            "--node 200=aimotor: node-ID `200` is not 1..127 or ff"
        );
        assert_eq!(
            parse_node("2=plc").unwrap_err().to_string(),
            "--node 2=plc: unknown drive `plc`; the simulated drives: aimotor, syntron-ds, dexmart-dev, aqmd2405, servo"
        );
        assert!(parse_node("2").unwrap_err().to_string().contains("expected NODE=MODEL"));
        assert!(
            parse_node("2=aimotor@x")
                .unwrap_err()
                .to_string()
                .contains("serial `x`")
        );
    }

    #[test]
    fn drive_lists_default_and_refuse_a_node_twice() {
        let d = drives(&[], &["2=aimotor", "3=syntron-ds"]).unwrap();
        assert_eq!(d.iter().map(Drive::node).collect::<Vec<_>>(), vec![2, 3]);
        let twice = ["5=aqmd2405".to_string(), "5=servo".to_string()];
        assert_eq!(
            drives(&twice, &[]).unwrap_err().to_string(),
            "--node 5=servo: node 5 is given twice"
        );
        let lss = ["ff=servo@1".to_string(), "ff=servo@2".to_string()];
        assert_eq!(drives(&lss, &[]).unwrap().len(), 2);
    }

    #[test]
    fn every_built_in_drive_profile_has_a_model() {
        // A new device profile in decoders/ needs a simulated drive (the demo runs its
        // procedures): the models cover every built-in profile except the generic ones.
        for name in crate::od::bind::builtin_names().filter(|n| !matches!(*n, "cia301" | "cia402")) {
            assert!(MODELS.contains(&name), "no simulated drive for profile {name}");
        }
    }
}
