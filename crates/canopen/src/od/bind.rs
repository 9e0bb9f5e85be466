//! Built-in profiles and the binding of profiles/EDS files to nodes.
//!
//! `--profile NODE=NAME` (a built-in name or a JSON file) and `--eds NODE=FILE`
//! give a node its own [`Dictionary`]: EDS first, then the profile, the
//! profiles it extends, CiA 402 and CiA 301. Other nodes use CiA 402 + CiA 301.
//! Files are read through a caller-supplied function, so this stays free of IO.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use super::dictionary::Dictionary;
use super::json::{LoadError, load_builtin_profile, load_profile};
use super::mapping::MappingSource;
use super::object::Warning;
use super::profile::Profile;
use super::value::Value;

/// The profiles built into the binary: name and JSON text. To add one, put
/// `decoders/<name>.json` in the repository and add a line here.
pub const BUILTIN: &[(&str, &str)] = &[
    ("cia301", include_str!("../../../../decoders/cia301.json")),
    ("cia402", include_str!("../../../../decoders/cia402.json")),
    ("aimotor", include_str!("../../../../decoders/aimotor.json")),
    ("aqmd2405", include_str!("../../../../decoders/aqmd2405.json")),
    ("dexmart-dev", include_str!("../../../../decoders/dexmart-dev.json")),
    ("syntron-ds", include_str!("../../../../decoders/syntron-ds.json")),
];

/// Reads a file's bytes for the bindings (the CLI reads with a size cap).
pub type ReadFile<'a> = &'a dyn Fn(&Path) -> std::io::Result<Vec<u8>>;

/// The names of the built-in profiles.
pub fn builtin_names() -> impl Iterator<Item = &'static str> {
    BUILTIN.iter().map(|(n, _)| *n)
}

/// Loads a built-in profile by name; `None` when there is no such built-in.
pub fn load_builtin(name: &str) -> Option<Result<(Profile, Vec<Warning>), LoadError>> {
    BUILTIN
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| load_profile(&format!("built-in {n}"), text))
}

/// A loaded profile, shared, with the warnings of its load.
pub type SharedProfile = (Arc<Profile>, Vec<Warning>);

/// A built-in profile loaded once per process and shared; `None` when there is
/// no such built-in. Warnings are those of the first load.
pub fn shared_builtin(name: &str) -> Option<Result<SharedProfile, LoadError>> {
    type Cache = Mutex<BTreeMap<String, SharedProfile>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some((p, w)) = cache.lock().ok()?.get(name) {
        return Some(Ok((p.clone(), w.clone())));
    }
    let (n, text) = BUILTIN.iter().find(|(n, _)| *n == name)?;
    let loaded = load_builtin_profile(&format!("built-in {n}"), text).map(|(p, w)| (Arc::new(p), w));
    if let (Ok(entry), Ok(mut c)) = (&loaded, cache.lock()) {
        c.insert(name.to_string(), entry.clone());
    }
    Some(loaded)
}

/// Why a `NODE=VALUE` argument does not read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NodeArgError {
    #[error("`{0}`: expected NODE=VALUE, e.g. 2=cia402")]
    NoEquals(String),
    #[error("`{arg}`: node `{node}` is not 1..127")]
    BadNode { arg: String, node: String },
    #[error("`{0}`: nothing after `=`")]
    NothingAfter(String),
}

/// Why `--profile NODE=NAME` / `--eds NODE=FILE` (or a profile's `extends`) cannot be bound.
#[derive(Debug, thiserror::Error)]
pub enum BindError {
    #[error(transparent)]
    NodeArg(#[from] NodeArgError),
    /// The profile given as `--profile ARG` did not load.
    #[error("--profile {arg}: {error}")]
    Profile { arg: String, error: Box<BindError> },
    #[error("--eds {arg}: cannot read {file}: {source}")]
    ReadEds {
        arg: String,
        file: String,
        source: std::io::Error,
    },
    /// `builtin` lists the built-in names.
    #[error("unknown profile `{name}` (built-in: {builtin}; or give a path to a .json file)")]
    UnknownProfile { name: String, builtin: String },
    #[error("cannot read {file}: {source}")]
    Read { file: String, source: std::io::Error },
    #[error("{file}: line {line}: not UTF-8 (JSON profiles are UTF-8)")]
    NotUtf8 { file: String, line: usize },
    /// The profile file is not a valid profile (located message).
    #[error(transparent)]
    Load(#[from] LoadError),
}

/// Parses `NODE=VALUE` with NODE decimal or `0x` hex in 1..=127.
pub fn parse_node_arg(arg: &str) -> Result<(u8, &str), NodeArgError> {
    let (node, value) = arg
        .split_once('=')
        .ok_or_else(|| NodeArgError::NoEquals(arg.to_string()))?;
    let n = node.trim();
    let parsed = match n.strip_prefix("0x").or_else(|| n.strip_prefix("0X")) {
        Some(h) => u8::from_str_radix(h, 16).ok(),
        None => n.parse::<u8>().ok(),
    };
    let node = parsed
        .filter(|v| (1..=127).contains(v))
        .ok_or_else(|| NodeArgError::BadNode {
            arg: arg.to_string(),
            node: n.to_string(),
        })?;
    let value = value.trim();
    if value.is_empty() {
        return Err(NodeArgError::NothingAfter(arg.to_string()));
    }
    Ok((node, value))
}

/// What is bound to one node.
#[derive(Clone, Debug, Default)]
struct NodeBinding {
    /// The device's own configuration (e.g. the PDO mappings it starts with), above its EDS.
    config: Option<Arc<Profile>>,
    eds: Option<Arc<Profile>>,
    profile: Option<Arc<Profile>>,
    /// Where the profile came from, to resolve `extends` next to it.
    profile_dir: Option<PathBuf>,
}

/// Profiles bound to nodes and the dictionaries made from them.
#[derive(Clone, Debug)]
pub struct Bindings {
    loaded: BTreeMap<String, Arc<Profile>>,
    nodes: BTreeMap<u8, NodeBinding>,
    dictionaries: BTreeMap<u8, Dictionary>,
    /// CiA 402 + CiA 301, built on first use: a capture that names no object (NMT,
    /// heartbeats, SYNC, PDOs without a mapping) never parses the built-in profiles.
    default: Dictionary,
    warnings: Vec<Warning>,
}

/// The layers of nodes without bindings: CiA 402 over CiA 301, from the process's shared
/// built-ins (the same `Arc`s [`Bindings`] hands out by name).
fn base_layers() -> Vec<Arc<Profile>> {
    let layers = ["cia402", "cia301"]
        .iter()
        .filter_map(|name| match shared_builtin(name) {
            Some(Ok((profile, _))) => Some(profile),
            // The built-ins load without error or warning (their tests check it).
            _ => None,
        });
    layers.collect()
}

impl Default for Bindings {
    fn default() -> Bindings {
        Bindings::new()
    }
}

impl Bindings {
    /// Bindings with no node bound: every node uses CiA 402 + CiA 301 (built when first
    /// asked for).
    pub fn new() -> Bindings {
        Bindings {
            loaded: BTreeMap::new(),
            nodes: BTreeMap::new(),
            dictionaries: BTreeMap::new(),
            default: Dictionary::lazy(base_layers),
            warnings: Vec::new(),
        }
    }

    /// Bindings from `--profile NODE=NAME` and `--eds NODE=FILE` arguments.
    pub fn from_args(profiles: &[String], eds: &[String], read: ReadFile) -> Result<Bindings, BindError> {
        let mut b = Bindings::new();
        for arg in profiles {
            let (node, name) = parse_node_arg(arg)?;
            b.bind_profile(node, name, read).map_err(|e| BindError::Profile {
                arg: arg.clone(),
                error: Box::new(e),
            })?;
        }
        for arg in eds {
            let (node, file) = parse_node_arg(arg)?;
            let bytes = read(Path::new(file)).map_err(|source| BindError::ReadEds {
                arg: arg.clone(),
                file: file.to_string(),
                source,
            })?;
            b.bind_eds_bytes(node, file, &bytes);
        }
        Ok(b)
    }

    /// Binds a profile (built-in name, or path to a JSON file) to a node.
    pub fn bind_profile(&mut self, node: u8, name: &str, read: ReadFile) -> Result<(), BindError> {
        let is_file = name.ends_with(".json") || name.contains('/') || name.contains('\\');
        let (profile, dir) = if is_file {
            let path = Path::new(name);
            let p = self.load_file(path, read)?;
            (p, path.parent().map(Path::to_path_buf))
        } else {
            (self.named(name, None, Some(read))?, None)
        };
        let entry = self.nodes.entry(node).or_default();
        entry.profile = Some(profile);
        entry.profile_dir = dir;
        self.rebuild(node, read);
        Ok(())
    }

    /// Binds an EDS/DCF file as read from disk: UTF-8, or CP1252 for the lines that are not
    /// (vendor files often have a Latin-1 comment), each such line named in a warning.
    pub fn bind_eds_bytes(&mut self, node: u8, file: &str, bytes: &[u8]) {
        let (text, fallback) = super::text::decode(bytes);
        self.warnings.extend(fallback.into_iter().map(|line| Warning {
            file: file.to_string(),
            at: format!("line {line}"),
            message: "not UTF-8, read as Windows-1252 (CP1252)".into(),
        }));
        self.bind_eds(node, file, &text);
    }

    /// Binds an EDS/DCF file's contents to a node (its `$NODEID` becomes `node`).
    pub fn bind_eds(&mut self, node: u8, file: &str, text: &str) {
        let (profile, warnings) = super::eds::import(file, text, node);
        self.warnings.extend(warnings);
        self.bind_layer(node, profile);
    }

    /// Binds a ready-made top layer to a node, in the place an EDS takes: the device's own
    /// configuration (e.g. the PDO mappings the demo's simulated drives start with).
    pub fn bind_layer(&mut self, node: u8, profile: Profile) {
        self.nodes.entry(node).or_default().eds = Some(Arc::new(profile));
        self.rebuild(node, &|p| {
            Err(std::io::Error::other(format!("{} not read", p.display())))
        });
    }

    /// Binds what a node is configured with (e.g. the PDO mappings a simulated drive starts
    /// with) above its EDS and profile, which keep giving names and types.
    pub fn bind_config(&mut self, node: u8, profile: Profile) {
        self.nodes.entry(node).or_default().config = Some(Arc::new(profile));
        self.rebuild(node, &|p| {
            Err(std::io::Error::other(format!("{} not read", p.display())))
        });
    }

    /// The dictionary of a node: its bound layers, or CiA 402 + CiA 301.
    pub fn dictionary(&self, node: u8) -> &Dictionary {
        self.dictionaries.get(&node).unwrap_or(&self.default)
    }

    /// The dictionary used for nodes without bindings.
    pub fn default_dictionary(&self) -> &Dictionary {
        &self.default
    }

    /// Nodes with a profile or EDS bound.
    pub fn bound_nodes(&self) -> impl Iterator<Item = u8> + '_ {
        self.dictionaries.keys().copied()
    }

    /// Warnings from loading profiles and EDS files.
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// The built-in profile whose identification matches the identity values
    /// `read(index, sub)` returns, preferring the one with most conditions.
    pub fn identify(&mut self, read: &dyn Fn(u16, u8) -> Option<Value>) -> Option<Arc<Profile>> {
        let mut best: Option<Arc<Profile>> = None;
        for name in builtin_names() {
            let Ok(p) = self.named(name, None, None) else { continue };
            let better = best
                .as_ref()
                .is_none_or(|b| p.identification.len() > b.identification.len());
            if p.identifies(read) && better {
                best = Some(p);
            }
        }
        best
    }

    /// Binds the built-in profile that `identify` picks to `node`, unless the node
    /// already has a profile; returns the name bound.
    pub fn bind_identified(&mut self, node: u8, read: &dyn Fn(u16, u8) -> Option<Value>) -> Option<String> {
        if self.nodes.get(&node).is_some_and(|b| b.profile.is_some()) {
            return None;
        }
        let profile = self.identify(read)?;
        let no_files = |p: &Path| Err(std::io::Error::other(format!("{} not read", p.display())));
        self.bind_profile(node, &profile.name, &no_files).ok()?;
        Some(profile.name.clone())
    }

    /// A profile by name: already loaded, built-in, or `dir/NAME.json`.
    fn named(&mut self, name: &str, dir: Option<&Path>, read: Option<ReadFile>) -> Result<Arc<Profile>, BindError> {
        if let Some(p) = self.loaded.get(name) {
            return Ok(p.clone());
        }
        if let Some(result) = shared_builtin(name) {
            let (p, w) = result?;
            self.warnings.extend(w);
            self.loaded.insert(name.to_string(), p.clone());
            return Ok(p);
        }
        match (dir, read) {
            (Some(dir), Some(read)) => self.load_file(&dir.join(format!("{name}.json")), read),
            _ => Err(BindError::UnknownProfile {
                name: name.to_string(),
                builtin: builtin_names().collect::<Vec<_>>().join(", "),
            }),
        }
    }

    fn load_file(&mut self, path: &Path, read: ReadFile) -> Result<Arc<Profile>, BindError> {
        let key = path.display().to_string();
        if let Some(p) = self.loaded.get(&key) {
            return Ok(p.clone());
        }
        let bytes = read(path).map_err(|source| BindError::Read {
            file: key.clone(),
            source,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let line = e.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count() + 1;
            BindError::NotUtf8 {
                file: key.clone(),
                line,
            }
        })?;
        let (p, w) = load_profile(&key, &text)?;
        self.warnings.extend(w);
        let p = Arc::new(p);
        self.loaded.insert(key, p.clone());
        Ok(p)
    }

    /// Rebuilds a node's layers: EDS, node PDOs, profile chain, cia402, cia301.
    fn rebuild(&mut self, node: u8, read: ReadFile) {
        let Some(binding) = self.nodes.get(&node).cloned() else {
            return;
        };
        let mut layers: Vec<Arc<Profile>> = Vec::new();
        if let Some(config) = &binding.config {
            layers.push(config.clone());
        }
        // Where the EDS is, to enrich it from the layers below.
        let at = layers.len();
        if let Some(eds) = &binding.eds {
            layers.push(eds.clone());
        }
        if let Some(profile) = &binding.profile {
            // The profile's default PDO set placed on this node (COB-IDs may use `node`).
            if let Some(set) = profile.default_pdo_set() {
                let source = MappingSource::Profile(profile.name.clone());
                let pdo_layer = Profile {
                    name: profile.name.clone(),
                    rpdo: set.mappings(false, Some(node), &source),
                    tpdo: set.mappings(true, Some(node), &source),
                    ..Default::default()
                };
                layers.push(Arc::new(pdo_layer));
            }
            let mut queue = vec![profile.clone()];
            while let Some(p) = queue.pop() {
                if layers.iter().any(|l| Arc::ptr_eq(l, &p)) {
                    continue;
                }
                layers.push(p.clone());
                // Push in reverse so the first `extends` entry is visited next.
                for name in p.extends.iter().rev() {
                    match self.named(name, binding.profile_dir.as_deref(), Some(read)) {
                        // CiA 402 and 301 always come last, in that order.
                        Ok(parent) if self.default.layers().iter().any(|d| Arc::ptr_eq(d, &parent)) => {}
                        Ok(parent) => queue.push(parent),
                        Err(e) => self.warnings.push(Warning {
                            file: p.name.clone(),
                            at: "extends".into(),
                            message: e.to_string(),
                        }),
                    }
                }
            }
        }
        for base in self.default.layers() {
            if !layers.iter().any(|l| Arc::ptr_eq(l, base)) {
                layers.push(base.clone());
            }
        }
        if binding.eds.is_some()
            && let Some(top) = super::merge::enriched(&layers[at], &layers[at + 1..])
        {
            layers[at] = Arc::new(top);
        }
        self.dictionaries.insert(node, Dictionary::new(layers));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::{Access, DataType, format_value, resolve_object};

    #[test]
    fn builtins_load_without_warnings() {
        for name in builtin_names() {
            let (p, w) = load_builtin(name).unwrap().unwrap();
            assert_eq!(w, vec![], "{name}");
            assert_eq!(p.name, name);
        }
    }

    #[test]
    fn builtins_have_what_the_seeds_need() {
        let b = Bindings::new();
        let d = b.dictionary(5);
        assert_eq!(d.profile_name(), "cia402");
        let sw = d.object(0x6041, 0).unwrap();
        assert_eq!(
            (sw.name.as_str(), sw.data_type, sw.access),
            ("Statusword", DataType::U16, Access::Ro)
        );
        assert_eq!(sw.bits.get(&10).map(String::as_str), Some("Target reached"));
        let hb = d.object(0x1017, 0).unwrap();
        assert_eq!(
            (hb.name.as_str(), hb.data_type),
            ("Producer heartbeat time", DataType::U16)
        );
        assert_eq!(format_value(Some(hb), &crate::od::Value::Unsigned(1000)), "1000 ms");
        assert_eq!(d.name(0x1018, 1), Some("Vendor-ID"));
        assert_eq!(d.name(0x1018, 0), Some("Highest sub-index supported"));
        assert_eq!(d.object_name(0x1018), Some("Identity object"));
        assert_eq!(d.object_name(0x1A01), Some("TPDO2 mapping parameter"));
        assert_eq!(d.name(0x1600, 3), Some("Mapped object 3"));
        assert_eq!(d.name(0x1400, 5), Some("Event timer"));
        assert_eq!(d.name(0x1016, 127), Some("Consumer heartbeat time 127"));
        let modes = d.object(0x6060, 0).unwrap();
        assert_eq!(
            format_value(Some(modes), &crate::od::Value::Signed(3)),
            "3 (Profile velocity)"
        );
        assert_eq!(
            format_value(d.object(0x6071, 0), &crate::od::Value::Signed(500)),
            "50 %"
        );
        assert_eq!(
            format_value(d.object(0x603F, 0), &crate::od::Value::Unsigned(0x8611)),
            "34321 (Following error)"
        );
        assert_eq!(d.object(0x605A, 0).unwrap().values.len(), 9);
        assert_eq!(d.emcy_text(0x8130), Some("Life guard error or heartbeat error"));
        assert_eq!(d.emcy_text(0x2310), Some("Continuous over-current"));
        assert_eq!(
            format_value(d.object(0x1010, 1), &crate::od::Value::Unsigned(0x65766173)),
            "1702257011 (save)"
        );
    }

    #[test]
    fn node_args() {
        assert_eq!(parse_node_arg("2=cia402"), Ok((2, "cia402")));
        assert_eq!(parse_node_arg("0x7F = drive.eds"), Ok((127, "drive.eds")));
        assert!(
            parse_node_arg("0=cia402")
                .unwrap_err()
                .to_string()
                .contains("not 1..127")
        );
        assert!(
            parse_node_arg("128=cia402")
                .unwrap_err()
                .to_string()
                .contains("not 1..127")
        );
        assert!(parse_node_arg("cia402").unwrap_err().to_string().contains("NODE=VALUE"));
        assert!(parse_node_arg("3=").unwrap_err().to_string().contains("nothing after"));
    }

    const VENDOR: &str = r#"{ "name": "vendor", "extends": ["base", "cia402"],
        "objects": { "0x2318": { "name": "Speed gain", "type": "u16", "alias": "F0.3.018" } },
        "aliases": { "09-26": "0x2009:27" },
        "alias_rules": [ { "pattern": "F{x:hex}.{y:hex}.{z:hex}", "index": "0x2000 + 0x1000*x + 0x100*y + z" } ],
        "tpdo": { "1": { "cob_id": "0x180 + node", "entries": ["0x6041/16"] } } }"#;
    const BASE: &str = r#"{ "name": "base", "extends": ["cia301"],
        "objects": { "0x6041": { "name": "Drive status", "type": "u16" } } }"#;

    fn files(path: &Path) -> std::io::Result<Vec<u8>> {
        match path.to_str() {
            Some("/p/vendor.json") => Ok(VENDOR.into()),
            Some("/p/base.json") => Ok(BASE.into()),
            Some("/p/drive.eds") => {
                Ok("[DeviceInfo]\nProductName=X\n[1000]\nParameterName=EDS device type\nDataType=7\n".into())
            }
            _ => Err(std::io::Error::new(std::io::ErrorKind::NotFound, "no such file")),
        }
    }

    #[test]
    fn profile_file_with_extends_and_eds_layers() {
        let b = Bindings::from_args(&["2=/p/vendor.json".into()], &["2=/p/drive.eds".into()], &files).unwrap();
        let names: Vec<&str> = b.dictionary(2).layers().iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, vec!["drive.eds", "vendor", "vendor", "base", "cia402", "cia301"]);
        let d = b.dictionary(2);
        assert_eq!(d.name(0x1000, 0), Some("EDS device type"));
        assert_eq!(d.name(0x6041, 0), Some("Drive status"));
        assert_eq!(d.name(0x6040, 0), Some("Controlword"));
        assert_eq!(d.default_pdos(true).unwrap()[&1].cob_id, Some(0x182));
        assert_eq!(b.dictionary(3).profile_name(), "cia402");
        assert_eq!(b.default_dictionary().layers().len(), 2);
        assert_eq!(b.bound_nodes().collect::<Vec<_>>(), vec![2]);
        assert_eq!(resolve_object(d, "F1.3.018"), Ok((0x3318, 0)));
        assert_eq!(resolve_object(d, "f0.3.018"), Ok((0x2318, 0)));
        assert_eq!(resolve_object(d, "09-26"), Ok((0x2009, 27)));
        assert_eq!(resolve_object(d, "speed gain"), Ok((0x2318, 0)));
        assert!(
            resolve_object(b.dictionary(3), "F1.3.018")
                .unwrap_err()
                .to_string()
                .contains("unknown object")
        );
    }

    #[test]
    fn resolve_forms() {
        let b = Bindings::new();
        let d = b.dictionary(1);
        assert_eq!(resolve_object(d, "0x6041"), Ok((0x6041, 0)));
        assert_eq!(resolve_object(d, "0x1018:1"), Ok((0x1018, 1)));
        assert_eq!(resolve_object(d, "1018sub4"), Ok((0x1018, 4)));
        assert_eq!(resolve_object(d, "STATUSWORD"), Ok((0x6041, 0)));
        assert_eq!(resolve_object(d, "Vendor-ID"), Ok((0x1018, 1)));
        assert_eq!(resolve_object(d, "identity object:2"), Ok((0x1018, 2)));
        assert_eq!(resolve_object(d, "producer heartbeat time"), Ok((0x1017, 0)));
        let e = resolve_object(d, "warp drive").unwrap_err().to_string();
        assert!(e.contains("unknown object `warp drive`") && e.contains("cia402"), "{e}");
        assert!(resolve_object(d, "  ").is_err());
    }

    #[test]
    fn bad_bindings_are_errors() {
        let e = Bindings::from_args(&["2=nosuch".into()], &[], &files)
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown profile `nosuch`") && e.contains("cia402"), "{e}");
        let e = Bindings::from_args(&["2=/p/missing.json".into()], &[], &files)
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot read /p/missing.json"), "{e}");
        let e = Bindings::from_args(&[], &["2=/p/missing.eds".into()], &files)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--eds 2=/p/missing.eds"), "{e}");
    }

    #[test]
    fn identify_picks_a_matching_builtin() {
        let mut b = Bindings::new();
        let drive = |i: u16, _s: u8| (i == 0x1000).then_some(crate::od::Value::Unsigned(0x0002_0192));
        assert_eq!(b.identify(&drive).map(|p| p.name.clone()), Some("cia402".to_string()));
        assert!(b.identify(&|_, _| Some(crate::od::Value::Unsigned(0x191))).is_none());
        assert_eq!(b.bind_identified(7, &drive), Some("cia402".to_string()));
        assert_eq!(b.bound_nodes().collect::<Vec<_>>(), vec![7]);
        assert_eq!(b.dictionary(7).profile_name(), "cia402");
        // A node that already has a profile keeps it.
        assert_eq!(b.bind_identified(7, &drive), None);
    }
}
