//! `cotui decode --sync-cycles`: one record per SYNC cycle (its synchronous TPDOs, their
//! offsets from the SYNC, the late ones) as JSON lines or a text table, and the text
//! summary (cycles, mean and longest period, the slowest cycle, late TPDOs).

use crate::analysis::sync_cycles::{Cycle, Totals};
use crate::frame::json::{Seconds, write_line};
use serde::Serialize;
use std::fmt::Write;

/// One cycle as a JSONL record.
#[derive(Serialize)]
struct CycleJson<'a> {
    iface: &'a str,
    /// The SYNC's time (s, exact to the ns).
    start: Seconds,
    /// Time to the next SYNC (ms); null for the last cycle.
    period_ms: Option<f64>,
    counter: Option<u8>,
    frames: Vec<SlotJson>,
    /// TPDOs sent after the window closed.
    late: usize,
    /// The synchronous window 0x1007 (µs); null when unknown.
    window_us: Option<u64>,
    /// TPDOs beyond those a cycle keeps (only when some were not kept).
    #[serde(skip_serializing_if = "is_zero")]
    dropped: u64,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

#[derive(Serialize)]
struct SlotJson {
    cob_id: u32,
    node: u8,
    pdo: u16,
    offset_us: u32,
    late: bool,
}

/// `can0`, or `?` for an interface not in `names`.
fn iface(names: &[String], i: u16) -> &str {
    names.get(usize::from(i)).map_or("?", String::as_str)
}

/// `1700000000.010000` (s, µs digits).
fn secs(ns: u64) -> String {
    format!("{}.{:06}", ns / 1_000_000_000, ns % 1_000_000_000 / 1000)
}

/// The text table's header line.
pub(super) fn write_header(out: &mut String) {
    out.push_str("iface  start s             period ms  counter  window µs  late  TPDOs (COB-ID +offset µs, ! late)\n");
}

/// Appends one cycle to `json` (a JSON line, when `jsonl`) or `text` (a table row).
pub(super) fn write_cycle(json: &mut Vec<u8>, text: &mut String, c: &Cycle, names: &[String], jsonl: bool) {
    if jsonl {
        let j = CycleJson {
            iface: iface(names, c.iface),
            start: Seconds(c.start_ns),
            period_ms: c.period_ns.map(|p| p as f64 / 1e6),
            counter: c.counter,
            frames: c
                .frames
                .iter()
                .map(|s| SlotJson {
                    cob_id: s.cob_id,
                    node: s.node,
                    pdo: s.pdo,
                    offset_us: s.offset_us,
                    late: s.late,
                })
                .collect(),
            late: c.late(),
            window_us: c.window_us,
            dropped: c.dropped,
        };
        write_line(json, &j);
        return;
    }
    let opt = |v: Option<String>| v.unwrap_or_else(|| "-".into());
    let _ = write!(
        text,
        "{:<6} {:<18} {:>10}  {:>7}  {:>9}  {:>4}",
        iface(names, c.iface),
        secs(c.start_ns),
        opt(c.period_ns.map(|p| format!("{:.3}", p as f64 / 1e6))),
        opt(c.counter.map(|n| n.to_string())),
        opt(c.window_us.map(|w| w.to_string())),
        c.late()
    );
    for s in &c.frames {
        let _ = write!(
            text,
            "  {:03X} +{}{}",
            s.cob_id,
            s.offset_us,
            if s.late { "!" } else { "" }
        );
    }
    text.push('\n');
}

/// Appends the summary of the text table.
pub(super) fn write_totals(out: &mut String, t: &Totals, names: &[String]) {
    let _ = writeln!(out, "cycles: {}", t.cycles);
    let ms = |ns: u64| ns as f64 / 1e6;
    match t.slowest {
        Some((max, i, start)) => {
            let mean = ms(t.period_sum_ns) / t.periods.max(1) as f64;
            let _ = writeln!(out, "period: mean {mean:.3} ms, max {:.3} ms", ms(max));
            let _ = writeln!(
                out,
                "slowest: {} at {} s ({:.3} ms)",
                iface(names, i),
                secs(start),
                ms(max)
            );
        }
        None => out.push_str("period: none (fewer than two SYNCs)\n"),
    }
    let plural = |n: u64, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let _ = writeln!(
        out,
        "late: {} in {}",
        plural(t.late_frames, "TPDO", "TPDOs"),
        plural(t.late_cycles, "cycle", "cycles")
    );
}
