//! docs/ARCHITECTURE.md tells the truth: every path it names exists, and each layer of
//! src/ imports only the layers it may (the protocol core no IO front end, the analysis no
//! terminal or bus). Test modules (after `#[cfg(test)]`) may use anything.

use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_path_architecture_md_names_exists() {
    let doc = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let mut checked = 0;
    for (i, piece) in doc.split('`').enumerate() {
        let word = piece.split_whitespace().next().unwrap_or("");
        let word = word.trim_end_matches([',', ')', ':']);
        let in_code = i % 2 == 1;
        let prefixes = ["src/", "tests/", "docs/", "decoders/", "keymaps/", "scripts/"];
        if !in_code || !prefixes.iter().any(|p| word.starts_with(p)) || word.contains(['<', '*']) {
            continue;
        }
        assert!(
            root().join(word).exists(),
            "docs/ARCHITECTURE.md names `{word}`, which does not exist"
        );
        checked += 1;
    }
    // The diagram names paths without backticks too.
    for word in doc.split_whitespace().filter(|w| w.starts_with("src/")) {
        let word = word.trim_end_matches([',', ')', ':', '`']);
        assert!(
            root().join(word).exists(),
            "the diagram names `{word}`, which does not exist"
        );
        checked += 1;
    }
    assert!(checked > 40, "only {checked} paths found: did the format change?");
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

#[test]
fn layers_import_only_downwards() {
    let core = ["frame", "log", "od", "sdo", "lss", "decode"];
    let front = [
        "crate::tui",
        "crate::cli",
        "crate::bench",
        "crate::command",
        "crate::connect",
    ];
    let io = ["tokio::", "crossterm", "ratatui"];
    let rules: Vec<(&str, Vec<&str>)> = vec![
        (
            "frame",
            [
                &front[..],
                &io,
                &["crate::bus", "crate::sim", "crate::analysis", "crate::output"],
            ]
            .concat(),
        ),
        (
            "log",
            [
                &front[..],
                &io,
                &["crate::bus", "crate::sim", "crate::analysis", "crate::output"],
            ]
            .concat(),
        ),
        (
            "od",
            [
                &front[..],
                &io,
                &["crate::bus", "crate::sim", "crate::analysis", "crate::output"],
            ]
            .concat(),
        ),
        (
            "sdo",
            [
                &front[..],
                &io,
                &[
                    "crate::bus",
                    "crate::sim",
                    "crate::analysis",
                    "crate::output",
                    "crate::decode",
                ],
            ]
            .concat(),
        ),
        (
            "lss",
            [
                &front[..],
                &io,
                &[
                    "crate::bus",
                    "crate::sim",
                    "crate::analysis",
                    "crate::output",
                    "crate::decode",
                ],
            ]
            .concat(),
        ),
        (
            "decode",
            [
                &front[..],
                &io,
                &["crate::bus", "crate::sim", "crate::analysis", "crate::output"],
            ]
            .concat(),
        ),
        ("analysis", [&front[..], &io, &["crate::bus", "crate::sim"]].concat()),
        ("output", [&front[..], &io, &["crate::bus", "crate::sim"]].concat()),
        ("sim", [&front[..], &["crossterm", "ratatui"][..]].concat()),
        (
            "bus",
            [&front[..], &["crate::sim", "crossterm", "ratatui"][..]].concat(),
        ),
    ];
    assert_eq!(core.len(), 6);
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
