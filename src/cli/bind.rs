//! `--profile NODE=NAME` / `--eds NODE=FILE` to a ready decoder.
//!
//! Profiles are the built-in vendor profiles in `decoders/` or JSON files; each
//! bound node gets its profile placed on it (default PDO set with COB-IDs worked out).

use crate::decode::Decoder;
use crate::od::json::load_profile;
use crate::od::{Dictionary, Profile};
use std::sync::Arc;

/// The vendor profiles built into the binary: name and JSON text.
const BUILTIN: &[(&str, &str)] = &[
    ("aimotor", include_str!("../../decoders/aimotor.json")),
    ("aqmd2405", include_str!("../../decoders/aqmd2405.json")),
    ("dexmart-dev", include_str!("../../decoders/dexmart-dev.json")),
    ("syntron-ds", include_str!("../../decoders/syntron-ds.json")),
];

/// A decoder with the node bindings given on the command line; warnings go to stderr.
pub fn decoder(profiles: &[String], eds: &[String]) -> Result<Decoder, String> {
    if !eds.is_empty() {
        return Err("EDS bindings are not available yet".into());
    }
    let mut bound = Vec::new();
    for arg in profiles {
        let (node, name) = parse_node_arg(arg)?;
        let profile = load(name).map_err(|e| format!("--profile {arg}: {e}"))?;
        bound.push((node, Dictionary::new(vec![Arc::new(profile.for_node(node))])));
    }
    Ok(Decoder::new(Dictionary::default(), bound))
}

/// Loads a built-in profile by name, or a JSON file by path; prints load warnings.
fn load(name: &str) -> Result<Profile, String> {
    let (file, text) = match BUILTIN.iter().find(|(n, _)| *n == name) {
        Some((n, text)) => (format!("built-in {n}"), (*text).to_string()),
        None if name.ends_with(".json") => {
            let text = std::fs::read_to_string(name).map_err(|e| format!("cannot read {name}: {e}"))?;
            (name.to_string(), text)
        }
        None => {
            let names: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
            return Err(format!("unknown profile `{name}` (built-in: {})", names.join(", ")));
        }
    };
    let (profile, warnings) = load_profile(&file, &text).map_err(|e| e.to_string())?;
    for w in warnings {
        eprintln!("cotui: warning: {w}");
    }
    Ok(profile)
}

/// Parses `NODE=VALUE` with NODE decimal or `0x` hex in 1..=127.
fn parse_node_arg(arg: &str) -> Result<(u8, &str), String> {
    let (node, value) = arg
        .split_once('=')
        .ok_or_else(|| format!("`{arg}`: expected NODE=NAME, e.g. 2=syntron-ds"))?;
    let n = node.trim();
    let parsed = match n.strip_prefix("0x").or_else(|| n.strip_prefix("0X")) {
        Some(h) => u8::from_str_radix(h, 16).ok(),
        None => n.parse::<u8>().ok(),
    };
    let node = parsed
        .filter(|v| (1..=127).contains(v))
        .ok_or_else(|| format!("`{arg}`: node `{n}` is not 1..127"))?;
    Ok((node, value.trim()))
}
