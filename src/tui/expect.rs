//! `:expect NODE=FILE.dcf ...` / `:expect off` / `:expect` (and `--expect` at start): the
//! configuration each node's boots should write, compared in the boot stories (`B`) as
//! `diagnose --expect` compares it.

use crate::analysis::trace::Trace;
use crate::command::dcf::expect::read_all;

/// Runs the words after `expect` on `trace`'s diagnosis: the status line's text, or why
/// nothing changed (a file that cannot be read, a DCF that disagrees with the EDS). The
/// files' warnings (values left out) come back beside the text.
pub(crate) fn command(rest: &str, trace: &mut Trace) -> Result<(String, Vec<String>), String> {
    match rest.trim() {
        "" => Ok((listed(trace), Vec::new())),
        "off" => {
            trace.diagnosis.expect_nothing();
            trace.diagnosis_version += 1;
            Ok((
                "expect: no expected configuration; boots are compared with their first complete boot".into(),
                Vec::new(),
            ))
        }
        words => {
            let args: Vec<String> = words.split_whitespace().map(str::to_string).collect();
            let warnings = set(trace, &args)?;
            Ok((listed(trace), warnings))
        }
    }
}

/// Reads every `NODE=FILE` of `args` and makes them the expected configurations of their
/// nodes in `trace` (others kept); the files' warnings, or the first error.
pub fn set(trace: &mut Trace, args: &[String]) -> Result<Vec<String>, String> {
    let read = read_all(args, trace.decoder()).map_err(|e| format!("expect: {e}"))?;
    for (node, values) in read.nodes {
        trace.diagnosis.expect(node, values);
    }
    trace.diagnosis_version += 1;
    Ok(read.warnings)
}

/// `expect: node 3, 5 (boot stories: B)`, or that none is set.
fn listed(trace: &Trace) -> String {
    match nodes_text(&trace.diagnosis.expected_nodes()) {
        None => "expect: no expected configuration (`expect NODE=FILE.dcf`)".into(),
        Some(list) => format!("expect: configuration expected of node {list} (the boot stories compare it: B)"),
    }
}

/// `3, 5`: the nodes with an expected configuration; None when there are none.
pub(crate) fn nodes_text(nodes: &[u8]) -> Option<String> {
    (!nodes.is_empty()).then(|| nodes.iter().map(u8::to_string).collect::<Vec<_>>().join(", "))
}
