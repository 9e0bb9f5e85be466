//! The node-level records a decode run writes (SDO transactions, the summary's totals) and
//! the interface names shown with them.

use super::decode_args::OutputFormat;
use crate::frame::json::write_line;
use crate::od::Dictionary;
use crate::output::summary::Summary;
use crate::sdo::Transaction;

/// Keeps `names` up with a source's interface table (which grows as names appear).
pub(super) fn note_interfaces(names: &mut Vec<String>, ifaces: &crate::frame::Interfaces) {
    let all = ifaces.names();
    if all.len() > names.len() {
        names.extend(all[names.len()..].iter().cloned());
    }
}

/// The interface name shown with a node-level record (event, transaction, summary row):
/// only when the input has several interfaces, so that node 5 of can0 and node 5 of can1
/// tell apart; a capture of one interface prints as it always did.
pub(super) fn shown_iface(names: &[String], iface: u16) -> Option<&str> {
    (names.len() > 1).then(|| names.get(usize::from(iface)).map_or("?", String::as_str))
}

/// Appends one transaction to `out`: its label line (built in the scratch `label`) or its
/// JSON line.
pub(super) fn write_transaction(
    out: &mut Vec<u8>,
    label: &mut String,
    t: &Transaction,
    dict: &Dictionary,
    iface: Option<&str>,
    fmt: OutputFormat,
) {
    match fmt {
        OutputFormat::Text => {
            label.clear();
            // Several interfaces: `can1 node 2: Upload 0x6041:00 ...`.
            if let Some(i) = iface {
                label.push_str(i);
                label.push_str(" node ");
                label.push_str(&t.node.to_string());
                label.push_str(": ");
            }
            t.write_label(label, dict);
            out.extend_from_slice(label.as_bytes());
            out.push(b'\n');
        }
        OutputFormat::Jsonl
        | OutputFormat::Pcapng
        | OutputFormat::Parquet
        | OutputFormat::Asc
        | OutputFormat::Trc
        | OutputFormat::Blf => {
            let mut j = t.to_json(dict);
            j.iface = iface;
            write_line(out, &j)
        }
    }
}

/// Appends the totals of a `--summary` run in `fmt`.
pub(super) fn write_summary(out: &mut Vec<u8>, summary: &mut Summary, fmt: OutputFormat) {
    summary.finish();
    match fmt {
        OutputFormat::Text => out.extend_from_slice(summary.to_text().as_bytes()),
        OutputFormat::Jsonl
        | OutputFormat::Pcapng
        | OutputFormat::Parquet
        | OutputFormat::Asc
        | OutputFormat::Trc
        | OutputFormat::Blf => write_line(out, &summary.to_json()),
    }
}
