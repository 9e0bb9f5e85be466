//! Values the palette offers for argument positions of the commander commands: node
//! numbers heard on the bus, object names and aliases from the node's dictionary, procedure
//! names and their parameters from its profile. Which position takes which is read from
//! the command declaration ([`super::syntax`]) by argument name.

use crate::od::Dictionary;
use std::collections::BTreeSet;

/// What the session knows for completing argument values.
pub trait Known {
    /// The nodes heard on the bus, rising.
    fn nodes(&self) -> Vec<u8>;
    /// The dictionary of `node` (object names, aliases, procedures).
    fn dictionary(&self, node: u8) -> &Dictionary;
}

/// Nothing known (completion offers only what the declaration lists).
pub struct Nothing(Dictionary);

impl Nothing {
    /// An empty source.
    pub fn new() -> Nothing {
        Nothing(Dictionary::default())
    }
}

impl Default for Nothing {
    fn default() -> Self {
        Nothing::new()
    }
}

impl Known for Nothing {
    fn nodes(&self) -> Vec<u8> {
        Vec::new()
    }
    fn dictionary(&self, _node: u8) -> &Dictionary {
        &self.0
    }
}

/// A word as the palette splits it: quoted when it holds a space.
fn word(s: &str) -> String {
    if s.contains(' ') {
        format!("\"{s}\"")
    } else {
        s.to_string()
    }
}

/// The object names and aliases of `dict`, each once, in name order; `suffix` follows each
/// (`=` for signal assignments).
pub fn objects(dict: &Dictionary, suffix: &str) -> Vec<String> {
    let mut names = BTreeSet::new();
    for layer in dict.layers() {
        names.extend(layer.aliases.keys().cloned());
        names.extend(layer.names().into_values().map(String::from));
        for (_, o) in layer.entries() {
            names.insert(o.name.clone());
            names.extend(o.alias.clone());
        }
    }
    names.into_iter().map(|n| word(&format!("{n}{suffix}"))).collect()
}

/// The procedure names of `dict`.
pub fn procedures(dict: &Dictionary) -> Vec<String> {
    dict.procedures().iter().map(|p| p.name.clone()).collect()
}

/// The parameters of procedure `name` of `dict` as `NAME=`, those given already left out.
pub fn parameters(dict: &Dictionary, name: &str, given: &[String]) -> Vec<String> {
    let Some(p) = dict.procedure(name) else {
        return Vec::new();
    };
    p.params
        .iter()
        .map(|a| format!("{}=", a.name))
        .filter(|a| !given.iter().any(|g| g.starts_with(a.as_str())))
        .collect()
}

/// The values for the positional argument `id` of a command: `node`/`nodes` the nodes
/// heard, `object` the node's objects, `signals` the node's objects as `NAME=`, `procedure`
/// (of `run`) the node's procedures, `params` the procedure's parameters not given yet.
/// `node` is the node given before, `given` the positional arguments given so far (id,
/// value). None: no such kind of argument.
pub fn values(id: &str, node: Option<u8>, given: &[(String, String)], known: &dyn Known) -> Option<Vec<String>> {
    let dict = |n: Option<u8>| n.map(|n| known.dictionary(n));
    let of = |arg: &'static str| given.iter().filter(move |(a, _)| a == arg).map(|(_, v)| v.clone());
    Some(match id {
        "node" | "nodes" => known.nodes().iter().map(u8::to_string).collect(),
        "object" => dict(node).map(|d| objects(d, "")).unwrap_or_default(),
        "signals" => dict(node).map(|d| objects(d, "=")).unwrap_or_default(),
        "procedure" => dict(node).map(procedures).unwrap_or_default(),
        "params" => match (dict(node), of("procedure").next()) {
            (Some(d), Some(proc)) => parameters(d, &proc, &of("params").collect::<Vec<_>>()),
            _ => Vec::new(),
        },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::syntax::completions;
    use crate::od::bind::Bindings;

    /// Nodes 2 (syntron-ds) and 3 (aimotor) heard.
    struct Bus(Bindings);

    impl Known for Bus {
        fn nodes(&self) -> Vec<u8> {
            vec![2, 3]
        }
        fn dictionary(&self, node: u8) -> &Dictionary {
            self.0.dictionary(node)
        }
    }

    fn bus() -> Bus {
        let mut b = Bindings::new();
        let no_files = |_: &std::path::Path| Err(std::io::Error::other("no files here"));
        b.bind_profile(2, "syntron-ds", &no_files).unwrap();
        b.bind_profile(3, "aimotor", &no_files).unwrap();
        Bus(b)
    }

    #[test]
    fn node_positions_offer_the_nodes_heard() {
        let k = bus();
        assert_eq!(completions("sdo read ", &k), ["2", "3"]);
        assert_eq!(completions("drive ", &k), ["2", "3"]);
        assert_eq!(completions("run ", &k), ["2", "3"]);
        assert_eq!(completions("stop 2 ", &k), ["2", "3"]);
        // Not a node position: the declaration's words.
        assert!(completions("nmt ", &k).contains(&"start".to_string()));
        assert_eq!(completions("nmt start ", &k), ["2", "3"]);
    }

    #[test]
    fn object_positions_offer_the_nodes_dictionary_names_and_aliases() {
        let k = bus();
        let objs = completions("sdo read 2 ", &k);
        assert!(objs.contains(&"Statusword".to_string()), "{objs:?}");
        assert!(objs.contains(&"\"Modes of operation\"".to_string()), "quoted: {objs:?}");
        assert!(objs.contains(&"Fn1.002".to_string()), "syntron alias: {objs:?}");
        assert!(!completions("sdo read 3 ", &k).contains(&"Fn1.002".to_string()));
        let sigs = completions("pdo 2 send rpdo1 ", &k);
        assert!(sigs.contains(&"Controlword=".to_string()), "{sigs:?}");
    }

    #[test]
    fn run_offers_procedures_then_their_parameters_not_yet_given() {
        let k = bus();
        let procs = completions("run 2 ", &k);
        assert!(
            procs.contains(&"pv".to_string()) && procs.contains(&"vendor_speed".to_string()),
            "{procs:?}"
        );
        assert!(!completions("run 3 ", &k).contains(&"vendor_speed".to_string()));
        assert_eq!(completions("run 2 pv ", &k), ["speed=", "ramp=", "axis="]);
        assert_eq!(completions("run 2 pv speed=100 a", &k), ["ramp=", "axis="]);
        assert_eq!(completions("run 3 pv ", &k), ["speed=", "accel="]);
        assert!(completions("run 9 nosuch ", &k).is_empty());
    }
}
