//! docs/ARCHITECTURE.md tells the truth: every path it names exists, and each layer of
//! src/ imports only the layers it may (the protocol core no IO front end, the analysis no
//! terminal or bus). Test modules (after `#[cfg(test)]`) may use anything.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The repository paths a document names in backticks (and, bare, in its diagram).
fn paths_named(doc: &str) -> Vec<String> {
    let prefixes = [
        "src/",
        "crates/",
        "tests/",
        "docs/",
        "decoders/",
        "keymaps/",
        "scripts/",
    ];
    let mut paths = Vec::new();
    for (i, piece) in doc.split('`').enumerate() {
        let word = piece.split_whitespace().next().unwrap_or("");
        let word = word.trim_end_matches([',', ')', ':']);
        if i % 2 == 1 && prefixes.iter().any(|p| word.starts_with(p)) && !word.contains(['<', '*']) {
            paths.push(word.to_string());
        }
    }
    for word in doc.split_whitespace().filter(|w| w.starts_with("src/")) {
        paths.push(word.trim_end_matches([',', ')', ':', '`']).to_string());
    }
    paths
}

#[test]
fn every_path_architecture_md_and_contributing_md_name_exists() {
    for (doc, at_least) in [("docs/ARCHITECTURE.md", 40), ("CONTRIBUTING.md", 20)] {
        let text = std::fs::read_to_string(root().join(doc)).unwrap();
        let paths = paths_named(&text);
        for path in &paths {
            assert!(root().join(path).exists(), "{doc} names `{path}`, which does not exist");
        }
        assert!(
            paths.len() > at_least,
            "{doc}: only {} paths found: did the format change?",
            paths.len()
        );
    }
}

/// The Rust files under `dir`, recursively.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

/// The code of a source file without its tests and comments.
fn non_test(text: &str) -> String {
    let code = text.split("#[cfg(test)]").next().unwrap_or(text);
    code.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The normal dependencies named in a Cargo.toml's `[dependencies]` table.
fn dependencies(manifest: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut inside = false;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line == "[dependencies]";
        } else if inside && !line.is_empty() && !line.starts_with('#') {
            names.push(line.split(['=', ' ']).next().unwrap_or("").to_string());
        }
    }
    names
}

#[test]
fn the_protocol_core_depends_only_on_pure_crates() {
    let manifest = std::fs::read_to_string(root().join("crates/canopen/Cargo.toml")).unwrap();
    let allowed = [
        "memchr",
        "serde",
        "serde_ignored",
        "serde_json",
        "serde_path_to_error",
        "thiserror",
    ];
    let deps = dependencies(&manifest);
    assert!(deps.contains(&"serde".to_string()), "parsed {deps:?}");
    for dep in &deps {
        assert!(
            allowed.contains(&dep.as_str()),
            "crates/canopen depends on `{dep}`: the core takes bytes and returns values, so only \
             {allowed:?} (see docs/ARCHITECTURE.md)"
        );
    }
}

#[test]
fn the_protocol_core_does_no_io_and_never_imports_the_application() {
    let forbidden = [
        "std::fs",
        "std::net",
        "std::thread",
        "std::process",
        "std::env",
        "Instant",
        "SystemTime",
        "tokio",
        "ratatui",
        "crossterm",
        "socketcan",
        "libc",
        "cotui::",
    ];
    let files = rust_files(&root().join("crates/canopen/src"));
    assert!(files.len() > 50, "only {} core files", files.len());
    for path in files {
        let text = non_test(&std::fs::read_to_string(&path).unwrap());
        for f in forbidden {
            assert!(!text.contains(f), "{} (protocol core) uses {f}", path.display());
        }
    }
}

/// The modules of a crate (`src/NAME.rs` or `src/NAME/`) each module's non-test code names
/// with `crate::NAME` (also inside `use crate::{a::.., b::..}`).
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for path in rust_files(src) {
        let rel = path.strip_prefix(src).unwrap();
        let top = rel.components().next().unwrap().as_os_str().to_string_lossy();
        let top = top.trim_end_matches(".rs").to_string();
        if top == "lib" || top == "main" {
            continue;
        }
        let text = non_test(&std::fs::read_to_string(&path).unwrap());
        let entry = graph.entry(top.clone()).or_default();
        let mut rest = text.as_str();
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let names: Vec<&str> = if let Some(group) = rest.strip_prefix('{') {
                let group = &group[..group.find('}').unwrap_or(group.len())];
                group
                    .split(',')
                    .map(|n| n.trim().split("::").next().unwrap_or(""))
                    .collect()
            } else {
                vec![
                    rest.split(|c: char| !c.is_alphanumeric() && c != '_')
                        .next()
                        .unwrap_or(""),
                ]
            };
            for name in names.into_iter().filter(|n| !n.is_empty() && *n != top) {
                entry.insert(name.to_string());
            }
        }
    }
    graph
}

/// A cycle in `graph`, if there is one (as the list of modules on it).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|p| p == node) {
            return Some(path[at..].to_vec());
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(next, graph, path, done) {
                return Some(cycle);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|k| visit(k, graph, &mut Vec::new(), &mut done))
}

#[test]
fn no_module_imports_a_module_that_imports_it_back() {
    for src in ["src", "crates/canopen/src"] {
        let graph = module_graph(&root().join(src));
        assert!(graph.len() >= 6, "{src}: only {graph:?}");
        assert_eq!(find_cycle(&graph), None, "{src}: an import cycle between modules");
    }
}

#[test]
fn layers_import_only_downwards() {
    let front = [
        "crate::tui",
        "crate::cli",
        "crate::bench",
        "crate::command",
        "crate::connect",
    ];
    let io = ["tokio::", "crossterm", "ratatui"];
    let rules: Vec<(&str, Vec<&str>)> = vec![
        ("analysis", [&front[..], &io, &["crate::bus", "crate::sim"]].concat()),
        ("output", [&front[..], &io, &["crate::bus", "crate::sim"]].concat()),
        ("sim", [&front[..], &["crossterm", "ratatui"][..]].concat()),
        (
            "bus",
            [&front[..], &["crate::sim", "crossterm", "ratatui"][..]].concat(),
        ),
        (
            "command",
            vec!["crate::tui", "crate::cli", "crate::bench", "crossterm", "ratatui"],
        ),
    ];
    let mut files = 0;
    for (layer, forbidden) in rules {
        let dir = root().join("src").join(layer);
        let paths = if dir.is_dir() {
            rust_files(&dir)
        } else {
            vec![root().join(format!("src/{layer}.rs"))]
        };
        for path in paths {
            let text = std::fs::read_to_string(&path).unwrap();
            for f in &forbidden {
                assert!(
                    !non_test(&text).contains(f),
                    "{} (layer {layer}) uses {f}: see docs/ARCHITECTURE.md for what each layer may import",
                    path.display()
                );
            }
            files += 1;
        }
    }
    assert!(files > 60, "only {files} files checked");
}
