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

/// The module a source file is (`analysis::diagnose` for `src/analysis/diagnose/mod.rs`,
/// `analysis::diagnose::sdo` for its `sdo.rs`; the crate root is the empty path).
fn module_of(src: &Path, path: &Path) -> Vec<String> {
    let rel = path.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
        parts.pop();
    }
    parts
}

/// The paths a `use` tree names, its `{..}` groups expanded (`a::{b, c::d}` gives `a::b`
/// and `a::c::d`).
fn expand_use(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap_or("").to_string()];
    };
    let prefix = &tree[..open];
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.is_empty())
        .flat_map(|p| expand_use(p).into_iter().map(move |s| format!("{prefix}{s}")))
        .collect()
}

/// The paths a file's non-test code names: every `use` (groups expanded) and every
/// `crate::..`/`super::..` path written in the code.
fn named_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for stmt in code.split(';') {
        let s = stmt.trim_start();
        let s = s
            .strip_prefix("pub(crate) ")
            .or_else(|| s.strip_prefix("pub(super) "))
            .unwrap_or(s);
        let s = s.strip_prefix("pub ").unwrap_or(s);
        if let Some(tree) = s.strip_prefix("use ") {
            out.extend(expand_use(tree));
        }
    }
    for start in ["crate::", "super::"] {
        let mut rest = code;
        while let Some(at) = rest.find(start) {
            let before = rest[..at].chars().last();
            rest = &rest[at..];
            let end = rest
                .find(|c: char| !c.is_alphanumeric() && c != '_' && c != ':')
                .unwrap_or(rest.len());
            // `super::{a, b}` names a, b (expand_use has them), not the parent itself.
            let path = rest[..end].trim_end_matches(':');
            if !before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':')
                && !path.ends_with(start.trim_end_matches(':'))
            {
                out.push(path.to_string());
            }
            rest = &rest[start.len()..];
        }
    }
    out
}

/// The file-level import graph of a crate: each module (file) to the modules its non-test
/// code names (`use crate::..`, `super::..`, `self::..` and a child module's name), each
/// path taken to the longest module it starts with.
fn file_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = rust_files(src);
    let modules: BTreeSet<Vec<String>> = files.iter().map(|p| module_of(src, p)).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for path in &files {
        let me = module_of(src, path);
        let entry = graph.entry(me.join("::")).or_default();
        let code = non_test(&std::fs::read_to_string(path).unwrap());
        for named in named_paths(&code) {
            let segs: Vec<&str> = named.split("::").filter(|s| !s.is_empty()).collect();
            let mut abs: Vec<String> = match segs.first() {
                Some(&"crate") => Vec::new(),
                Some(&"super") | Some(&"self") => me.clone(),
                Some(first) if modules.contains(&[&me[..], &[first.to_string()]].concat()) => me.clone(),
                _ => continue,
            };
            let mut rest = &segs[..];
            if rest.first() == Some(&"crate") || rest.first() == Some(&"self") {
                rest = &rest[1..];
            }
            while rest.first() == Some(&"super") {
                abs.pop();
                rest = &rest[1..];
            }
            abs.extend(rest.iter().map(|s| s.to_string()));
            let target = (0..=abs.len()).rev().map(|n| &abs[..n]).find(|m| modules.contains(*m));
            if let Some(t) = target.filter(|t| **t != me[..] && !t.is_empty()) {
                entry.insert(t.join("::"));
            }
        }
    }
    graph
}

/// The groups of modules that import each other, directly or around a cycle (strongly
/// connected components of more than one module), each as its sorted module names, with
/// one cycle through the group to show.
fn cycle_groups(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<(String, Vec<String>)> {
    let reach = |from: &str| {
        let (mut seen, mut todo) = (BTreeSet::new(), vec![from.to_string()]);
        while let Some(n) = todo.pop() {
            for m in graph.get(&n).into_iter().flatten() {
                if seen.insert(m.clone()) {
                    todo.push(m.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&String, BTreeSet<String>> = graph.keys().map(|k| (k, reach(k))).collect();
    let mut groups = BTreeSet::new();
    for (k, r) in &reached {
        let group: BTreeSet<&String> = r
            .iter()
            .filter(|m| reached.get(m).is_some_and(|back| back.contains(*k)))
            .collect();
        if group.len() > 1 {
            groups.insert(group.into_iter().cloned().collect::<Vec<String>>());
        }
    }
    groups
        .into_iter()
        .map(|g| {
            let sub: BTreeMap<String, BTreeSet<String>> = g
                .iter()
                .map(|m| (m.clone(), graph[m].iter().filter(|t| g.contains(t)).cloned().collect()))
                .collect();
            (g.join(", "), find_cycle(&sub).unwrap_or_default())
        })
        .collect()
}

/// No files import each other, directly or around a cycle (issue 23, item 7: "no import
/// cycles between modules"): the test names each group it finds, with one cycle through it.
#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    let mut found = Vec::new();
    for src in ["src", "crates/canopen/src"] {
        let graph = file_graph(&root().join(src));
        assert!(graph.len() > 40, "{src}: only {} files", graph.len());
        for (group, cycle) in cycle_groups(&graph) {
            found.push(format!("    {src}: {group} (cycle: {})", cycle.join(" -> ")));
        }
    }
    assert!(
        found.is_empty(),
        "files importing each other (break the cycle):\n{}",
        found.join("\n")
    );
}

/// The diagnoser's detectors import no other detector: besides the facade
/// (`analysis::diagnose`, which owns them all and carries what one tells another), a file
/// of `src/analysis/diagnose/` imports only the modules they share.
#[test]
fn no_detector_imports_another_detector() {
    const SHARED: [&str; 4] = ["timeline", "detector", "texts", "two_masters"];
    let facade = "analysis::diagnose";
    let graph = file_graph(&root().join("src"));
    let inside = |m: &str| {
        m.strip_prefix(facade)
            .and_then(|r| r.strip_prefix("::"))
            .map(str::to_string)
    };
    // (The unit tests, `diagnose::tests`, may use anything.)
    let detectors: Vec<&String> = graph
        .keys()
        .filter(|m| inside(m).is_some_and(|name| name != "tests"))
        .collect();
    assert!(detectors.len() > 10, "only {} files in {facade}", detectors.len());
    let wrong: Vec<String> = detectors
        .iter()
        .flat_map(|m| graph[*m].iter().map(move |t| (m, t)))
        .filter(|(_, t)| inside(t).is_some_and(|name| !SHARED.contains(&name.as_str())))
        .map(|(m, t)| format!("    {m} -> {t}"))
        .collect();
    assert!(
        wrong.is_empty(),
        "diagnose files importing a detector (route it through the Diagnoser):\n{}",
        wrong.join("\n")
    );
}
