//! `--expect NODE=FILE.dcf` (`diagnose`, the TUI and its `:expect`): a DCF read as the
//! configuration a node's boots should write, typed here at the edge so the diagnosis gets
//! plain values.

use super::plan::{never_written, read_dcf, same_value, value_bytes};
use crate::analysis::boot_story::{Bytes, Expected};
use crate::od::eds::{import, key_values};
use crate::od::{Access, Dictionary};
use std::collections::BTreeMap;

/// Every `NODE=FILE` of `args` read with [`read`] against `decoder`'s dictionaries: the
/// expected values per node and the files' warnings; the first file that cannot be read is
/// the error.
pub fn read_all(args: &[String], decoder: &crate::decode::Decoder) -> Result<Expectations, String> {
    let mut out = Expectations::default();
    for arg in args {
        let (node, values, warnings) = read(arg, |n| decoder.dictionary(n))?;
        out.nodes.push((node, values));
        out.warnings.extend(warnings);
    }
    Ok(out)
}

/// What [`read_all`] read: the expected values of each node, and what was left out.
#[derive(Debug, Default)]
pub struct Expectations {
    /// Node and its expected values, in the order given.
    pub nodes: Vec<(u8, Vec<Expected>)>,
    /// Values left out of the files, located.
    pub warnings: Vec<String>,
}

/// The node and its expected values of `arg` (`NODE=FILE`), with the file's warnings
/// (values left out, located); `dict(node)` is the node's dictionary (its EDS, profile,
/// CiA 301). A DCF whose `DataType` of an object disagrees with the dictionary's is an
/// error naming the object and the line.
pub fn read<'a>(arg: &str, dict: impl Fn(u8) -> &'a Dictionary) -> Result<(u8, Vec<Expected>, Vec<String>), String> {
    let (node, file) = crate::od::bind::parse_node_arg(arg).map_err(|e| format!("--expect {arg}: {e}"))?;
    let bytes = crate::files::read_capped(std::path::Path::new(file)).map_err(|e| format!("{file}: {e}"))?;
    let text = String::from_utf8_lossy(&bytes);
    let dict = dict(node);
    check_types(file, &text, node, dict)?;
    let dcf = read_dcf(file, &text, node, dict);
    let warnings = dcf.problems.iter().map(ToString::to_string).collect();
    let defaults: BTreeMap<(u16, u8), String> = key_values(&text, "defaultvalue")
        .into_iter()
        .map(|d| ((d.index, d.sub), d.text))
        .collect();
    let values = dcf
        .values
        .into_iter()
        .filter(|v| matches!(v.access, Access::Rw | Access::Wo | Access::Rww | Access::Rwr))
        .filter(|v| never_written(v.index).is_none())
        .map(|v| {
            let default = defaults
                .get(&(v.index, v.sub))
                .and_then(|d| value_bytes(d, v.data_type, node).ok());
            Expected {
                index: v.index,
                sub: v.sub,
                must_write: default.is_none_or(|d| !same_value(v.data_type, &v.bytes, &d)),
                bytes: Bytes::of(&v.bytes),
            }
        })
        .collect();
    Ok((node, values, warnings))
}

/// Every object whose `DataType` in the DCF differs from the node's dictionary's: an
/// error at the line of the DCF's `DataType`.
fn check_types(file: &str, text: &str, node: u8, dict: &Dictionary) -> Result<(), String> {
    let (own, _) = import(file, text, node);
    for t in key_values(text, "datatype") {
        let (Some(mine), Some(known)) = (own.object(t.index, t.sub), dict.object(t.index, t.sub)) else {
            continue;
        };
        if mine.data_type != known.data_type {
            return Err(format!(
                "{file}:{}: 0x{:04X}:{:02X} {}: DataType {:?} in the DCF, {:?} in the node's EDS/dictionary",
                t.line, t.index, t.sub, known.name, mine.data_type, known.data_type
            ));
        }
    }
    Ok(())
}
