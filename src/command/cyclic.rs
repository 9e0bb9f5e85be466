//! Cyclic transmit: raw frames (`send`), the SYNC producer (`sync`) and RPDOs encoded
//! through a node's mapping (`pdo NODE send rpdoK`), once, N times or every MS until
//! stopped. The achieved period and jitter are measured from the receive timestamps of our
//! own frames as they come back marked TX (the kernel's timestamps on SocketCAN).
//!
//! Timing: a tokio interval with [`MissedTickBehavior::Skip`]. A tick missed on a busy
//! machine is dropped, not caught up: consumers never see a burst of SYNCs or RPDOs inside
//! one period, and the schedule stays on its grid so the mean period does not drift (a
//! missed tick shows as one long gap in the jitter figures).

use super::error::CommandError;
use super::value::encode;
use crate::bus::{Bus, Event};
use crate::frame::{Direction, Flags, Frame};
use crate::od::bind::Bindings;
use crate::od::resolve_object;
use crate::od::{DataType, Dictionary, PdoMapping};
use serde::Serialize;
use std::future::Future;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::time::MissedTickBehavior;

/// The default SYNC COB-ID (CiA 301 0x1005 default; a remote master's 0x1005 is not known).
pub const SYNC_COB_ID: u32 = 0x080;
/// Intervals kept for the p99 jitter (beyond, count, mean and max still go on).
const KEPT_INTERVALS: usize = 1_000_000;
/// How long to wait for the echoes of the last frames sent before reporting.
const ECHO_WAIT: Duration = Duration::from_secs(1);

/// How often a cyclic command sends: once (neither), `count` times, every `every_ms` ms
/// (until stopped without a count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Schedule {
    pub every_ms: Option<u64>,
    pub count: Option<u64>,
}

impl Schedule {
    /// How many frames it sends (`None`: until stopped).
    pub fn total(self) -> Option<u64> {
        match (self.every_ms, self.count) {
            (_, Some(n)) => Some(n),
            (Some(_), None) => None,
            (None, None) => Some(1),
        }
    }

    /// `every 10 ms, 5 times` / `once` / `every 10 ms until stopped`.
    pub fn text(self) -> String {
        match (self.every_ms, self.count) {
            (None, None | Some(1)) => "once".into(),
            (None, Some(n)) => format!("{n} times back to back"),
            (Some(ms), Some(n)) => format!("every {ms} ms, {n} times"),
            (Some(ms), None) => format!("every {ms} ms until stopped"),
        }
    }
}

/// The frame of the `i`-th SYNC (from 0): no data, or the CiA 301 counter 1..=`counter`
/// (it wraps from `counter` back to 1).
pub fn sync_frame(cob_id: u32, counter: Option<u8>, i: u64) -> Frame {
    match counter {
        Some(n) if n > 0 => Frame::classic(cob_id, &[(i % n as u64) as u8 + 1]),
        _ => Frame::classic(cob_id, &[]),
    }
}

/// An RPDO encoded through a node's mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Rpdo {
    pub frame: Frame,
    /// Names of the mapped signals not given (sent as 0).
    pub defaulted: Vec<String>,
}

/// The predefined COB-ID of RPDO `num` (1..=4) of `node`.
fn default_rpdo_cob(node: u8, num: u16) -> Option<u32> {
    (1..=4).contains(&num).then(|| crate::cob::rpdo(num as u8, node))
}

/// A signal's name as listed in errors: `Controlword (0x6040:00)`.
fn signal_name(dict: &Dictionary, index: u16, sub: u8) -> String {
    match dict.name(index, sub) {
        Some(n) => format!("{n} (0x{index:04X}:{sub:02X})"),
        None => format!("0x{index:04X}:{sub:02X}"),
    }
}

/// Encodes RPDO `num` of `node` from `NAME=VALUE` assignments through `mapping`: names are
/// object names, aliases or index:sub; values are typed by the object's data type (else
/// unsigned of the mapped width). Mapped signals not given are 0 (listed in `defaulted`).
pub fn encode_rpdo(
    dict: &Dictionary,
    node: u8,
    num: u16,
    mapping: &PdoMapping,
    assignments: &[(String, String)],
) -> Result<Rpdo, CommandError> {
    let mapped = || {
        mapping
            .entries
            .iter()
            .filter(|e| e.index > 0x0007)
            .map(|e| signal_name(dict, e.index, e.sub))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut values: Vec<Option<u64>> = vec![None; mapping.entries.len()];
    for (name, text) in assignments {
        let (index, sub) = resolve_object(dict, name)
            .map_err(|e| CommandError::Usage(format!("{e}; RPDO{num} of node {node} maps: {}", mapped())))?;
        let Some(k) = mapping.entries.iter().position(|e| (e.index, e.sub) == (index, sub)) else {
            return Err(CommandError::Usage(format!(
                "`{name}` ({}) is not mapped in RPDO{num} of node {node}; it maps: {}",
                signal_name(dict, index, sub),
                mapped()
            )));
        };
        if values[k].is_some() {
            return Err(CommandError::Usage(format!("`{name}` is given twice")));
        }
        let bits = mapping.entries[k].bits as u32;
        let ty = dict
            .object(index, sub)
            .map(|o| o.data_type)
            .filter(|t| t.size().is_some_and(|s| s * 8 == bits as usize) || bits < 8)
            .unwrap_or(DataType::U64);
        let bytes = encode(text, ty).map_err(|e| CommandError::Usage(format!("{name}: {e}")))?;
        let mut raw = [0u8; 8];
        let n = bytes.len().min(8);
        raw[..n].copy_from_slice(&bytes[..n]);
        let v = u64::from_le_bytes(raw);
        let mask = if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 };
        // Signed values keep their two's complement low bits; anything else must fit.
        use DataType::{I8, I16, I24, I32, I40, I48, I56, I64};
        let signed = matches!(ty, I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64);
        if v & !mask != 0 && !signed {
            return Err(CommandError::Usage(format!("{name}: {text} does not fit {bits} bits")));
        }
        values[k] = Some(v & mask);
    }
    let total: usize = mapping.entries.iter().map(|e| e.bits as usize).sum();
    if total > 64 {
        return Err(CommandError::Usage(format!(
            "RPDO{num} of node {node} maps {total} bits, more than a classic frame holds"
        )));
    }
    let mut data = [0u8; 8];
    let mut pos = 0usize;
    let mut defaulted = Vec::new();
    for (e, v) in mapping.entries.iter().zip(&values) {
        if v.is_none() && e.index > 0x0007 {
            defaulted.push(
                dict.name(e.index, e.sub)
                    .map_or_else(|| format!("0x{:04X}:{:02X}", e.index, e.sub), str::to_string),
            );
        }
        let v = v.unwrap_or(0);
        for b in 0..e.bits as usize {
            if v >> b & 1 != 0 {
                data[(pos + b) / 8] |= 1 << ((pos + b) % 8);
            }
        }
        pos += e.bits as usize;
    }
    let cob = match mapping.cob_id {
        Some(c) if c & 0x8000_0000 == 0 => c,
        _ => default_rpdo_cob(node, num).ok_or_else(|| {
            CommandError::Usage(format!(
                "RPDO{num} of node {node}: no COB-ID known (valid 1..4 predefined)"
            ))
        })?,
    };
    let mut frame = Frame::classic(cob & 0x1FFF_FFFF, &data[..total.div_ceil(8)]);
    frame
        .flags
        .set(Flags::EXT, cob & 0x2000_0000 != 0 || cob & 0x1FFF_FFFF > 0x7FF);
    Ok(Rpdo { frame, defaulted })
}

/// The RPDO of a `pdo NODE send rpdoK` command through the node's dictionary.
pub fn rpdo(bindings: &Bindings, node: u8, num: u16, assignments: &[(String, String)]) -> Result<Rpdo, CommandError> {
    let dict = bindings.dictionary(node);
    let mapping = dict
        .default_pdos(false)
        .and_then(|m| u8::try_from(num).ok().and_then(|n| m.get(&n)))
        .ok_or_else(|| {
            CommandError::Usage(format!(
                "no mapping of RPDO{num} known for node {node} (bind a profile or EDS: --profile {node}=NAME, --eds {node}=FILE)"
            ))
        })?;
    encode_rpdo(dict, node, num, mapping, assignments)
}

/// What a cyclic command sends: the frame of the `i`-th transmission, and its notes.
pub struct Source {
    /// What is sent, for reports and the jobs list (`SYNC 080`, `601#40..`, `RPDO1 node 2`).
    pub what: String,
    pub(crate) next: Box<dyn FnMut(u64) -> Frame + Send>,
    /// Mapped signals sent as 0 (pdo).
    pub defaulted: Vec<String>,
    pub schedule: Schedule,
}

impl Source {
    /// The frame of the `i`-th transmission.
    pub fn frame(&mut self, i: u64) -> Frame {
        (self.next)(i)
    }
}

/// The timing of a cyclic command so far, shared with whoever lists or stops it.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Frames sent.
    pub sent: u64,
    /// Echo timestamps: first and last (ns), count seen.
    first_ns: Option<u64>,
    last_ns: u64,
    pub seen: u64,
    /// Intervals between echoes, ns (the first [`KEPT_INTERVALS`]).
    intervals: Vec<u64>,
    max_dev_ns: u64,
}

impl Tally {
    /// Notes the echo of one of our frames at `ts_ns`, `period_ns` being the requested period.
    pub fn echo(&mut self, ts_ns: u64, period_ns: Option<u64>) {
        if let Some(p) = period_ns
            && self.first_ns.is_some()
        {
            let d = ts_ns.saturating_sub(self.last_ns);
            self.max_dev_ns = self.max_dev_ns.max(d.abs_diff(p));
            if self.intervals.len() < KEPT_INTERVALS {
                self.intervals.push(d);
            }
        }
        self.first_ns.get_or_insert(ts_ns);
        self.last_ns = ts_ns;
        self.seen += 1;
    }

    /// The time from the first echo to the last, ns (none before the first).
    pub fn span_ns(&self) -> Option<u64> {
        self.first_ns.map(|f| self.last_ns.saturating_sub(f))
    }

    /// The report of the timing: counts, mean period, jitter (deviation of each interval
    /// from `period_ns`) p99 and max.
    pub fn report(&self, what: &str, period_ms: Option<u64>, defaulted: &[String]) -> Report {
        let ms = |ns: u64| ns as f64 / 1e6;
        let mean = match (self.first_ns, self.seen) {
            (Some(f), n) if n > 1 && period_ms.is_some() => Some(ms(self.last_ns.saturating_sub(f)) / (n - 1) as f64),
            _ => None,
        };
        let p99 = period_ms.filter(|_| !self.intervals.is_empty()).map(|p| {
            let mut dev: Vec<u64> = self.intervals.iter().map(|d| d.abs_diff(p * 1_000_000)).collect();
            dev.sort_unstable();
            let k = ((dev.len() as f64 * 0.99).ceil() as usize).clamp(1, dev.len()) - 1;
            ms(dev[k])
        });
        Report {
            ok: true,
            what: what.to_string(),
            count: self.sent,
            seen: self.seen,
            period_ms,
            mean_period_ms: mean,
            jitter_p99_ms: p99,
            jitter_max_ms: p99.map(|_| ms(self.max_dev_ns)),
            defaulted: defaulted.to_vec(),
        }
    }
}

/// A shared [`Tally`]: the sender updates it, the jobs list and stop read it.
pub type Progress = Arc<Mutex<Tally>>;

/// `send|sync|pdo --json`: what was sent and how regularly.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    pub ok: bool,
    /// What was sent (`SYNC 080`, `601#4041600000000000`, `RPDO1 node 2 202#0F00F4010000`).
    pub what: String,
    /// Frames sent.
    pub count: u64,
    /// Frames seen back on the bus (their timestamps give the timing).
    pub seen: u64,
    /// The requested period (null: sent once or back to back).
    pub period_ms: Option<u64>,
    /// The achieved mean period from the receive timestamps.
    pub mean_period_ms: Option<f64>,
    /// 99th percentile and maximum of |interval - period|.
    pub jitter_p99_ms: Option<f64>,
    pub jitter_max_ms: Option<f64>,
    /// Mapped signals not given, sent as 0 (pdo).
    pub defaulted: Vec<String>,
}

impl Report {
    /// One line: `SYNC 080: 200 frames every 10 ms, mean period 10.002 ms, jitter p99 0.310 ms, max 1.2 ms`.
    pub fn text(&self) -> String {
        let mut t = format!(
            "{}: {} frame{} sent",
            self.what,
            self.count,
            if self.count == 1 { "" } else { "s" }
        );
        if let Some(p) = self.period_ms {
            t.push_str(&format!(" every {p} ms"));
        }
        if let (Some(m), Some(p99), Some(max)) = (self.mean_period_ms, self.jitter_p99_ms, self.jitter_max_ms) {
            t.push_str(&format!(
                ", mean period {m:.3} ms, jitter p99 {p99:.3} ms, max {max:.3} ms ({} seen)",
                self.seen
            ));
        }
        if !self.defaulted.is_empty() {
            t.push_str(&format!("; not given, sent as 0: {}", self.defaulted.join(", ")));
        }
        t
    }
}

/// Sends `src` on `bus` by its schedule until done or `stop` completes, noting the timing
/// in `progress`; then waits (up to a second) for the echoes of the frames sent and reports.
pub async fn transmit(
    bus: &Bus,
    mut src: Source,
    progress: Progress,
    stop: impl Future<Output = ()>,
) -> Result<Report, CommandError> {
    let mut rx = bus.subscribe();
    let period_ms = src.schedule.every_ms;
    let period_ns = period_ms.map(|p| p * 1_000_000);
    let total = src.schedule.total();
    let mut tick = tokio::time::interval(Duration::from_millis(period_ms.unwrap_or(1)));
    tick.set_missed_tick_behavior(MissedTickBehavior::Skip);
    let probe = src.frame(0);
    let ours = |f: &Frame| f.direction() == Direction::Tx && f.id == probe.id && f.is_ext() == probe.is_ext();
    tokio::pin!(stop);
    let mut sent = 0u64;
    loop {
        if total.is_some_and(|n| sent >= n) {
            break;
        }
        if period_ms.is_some() {
            tokio::select! {
                _ = &mut stop => break,
                _ = tick.tick() => {}
                ev = rx.next() => {
                    if let Ok(Event::Frame(f)) = ev && ours(&f) {
                        lock(&progress).echo(f.ts_ns, period_ns);
                    }
                    continue;
                }
            }
        }
        bus.send(&src.frame(sent)).await?;
        sent += 1;
        lock(&progress).sent = sent;
    }
    // The echoes still queued (or on their way) of the frames sent.
    let until = tokio::time::Instant::now() + ECHO_WAIT;
    while lock(&progress).seen < sent {
        match tokio::time::timeout_at(until, rx.next()).await {
            Ok(Ok(Event::Frame(f))) if ours(&f) => lock(&progress).echo(f.ts_ns, period_ns),
            Ok(Ok(_)) => {}
            Ok(Err(crate::bus::BusError::Closed)) | Err(_) => break,
            Ok(Err(_)) => {}
        }
    }
    let report = lock(&progress).report(&src.what, period_ms, &src.defaulted);
    Ok(report)
}

/// Locks the tally (a poisoned lock still holds the counts).
pub fn lock(p: &Progress) -> std::sync::MutexGuard<'_, Tally> {
    p.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::{MappedEntry, MappingSource};

    #[test]
    fn sync_counter_wraps_from_n_to_1() {
        let counters: Vec<u8> = (0..7).map(|i| sync_frame(0x080, Some(3), i).data[0]).collect();
        assert_eq!(counters, [1, 2, 3, 1, 2, 3, 1]);
        assert_eq!(sync_frame(0x080, Some(240), 239).data[0], 240);
        assert_eq!(sync_frame(0x080, Some(240), 240).data[0], 1);
        let plain = sync_frame(0x080, None, 5);
        assert_eq!((plain.id, plain.len), (0x080, 0));
    }

    fn demo_bindings() -> Bindings {
        crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap()
    }

    #[test]
    fn demo_rpdo1_is_controlword_and_target_velocity() {
        let b = demo_bindings();
        let args = |a: &[(&str, &str)]| -> Vec<(String, String)> {
            a.iter().map(|(n, v)| (n.to_string(), v.to_string())).collect()
        };
        let r = rpdo(&b, 2, 1, &args(&[("Controlword", "0x0F"), ("Target velocity", "500")])).unwrap();
        assert_eq!(super::super::spec::candump(&r.frame), "202#0F00F4010000");
        assert!(r.defaulted.is_empty());
        // By index:sub, negative velocity, controlword left out (sent as 0).
        let r = rpdo(&b, 2, 1, &args(&[("0x60FF:0", "-2")])).unwrap();
        assert_eq!(super::super::spec::candump(&r.frame), "202#0000FEFFFFFF");
        assert_eq!(r.defaulted, ["Controlword"]);
        let e = rpdo(&b, 2, 1, &args(&[("0x6060", "3")])).unwrap_err().to_string();
        assert!(e.contains("not mapped in RPDO1 of node 2"), "{e}");
        assert!(
            e.contains("Controlword (0x6040:00), Target velocity (0x60FF:00)"),
            "{e}"
        );
        let e = rpdo(&b, 2, 1, &args(&[("Controlword", "70000")]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not fit"), "{e}");
        assert!(
            rpdo(&b, 9, 1, &[])
                .unwrap_err()
                .to_string()
                .contains("no mapping of RPDO1")
        );
    }

    #[test]
    fn bit_fields_and_default_cob_id() {
        let dict = Dictionary::default();
        let m = PdoMapping {
            cob_id: None,
            entries: vec![
                MappedEntry {
                    index: 0x2000,
                    sub: 1,
                    bits: 1,
                },
                MappedEntry {
                    index: 0x0001,
                    sub: 0,
                    bits: 3,
                },
                MappedEntry {
                    index: 0x2000,
                    sub: 2,
                    bits: 12,
                },
            ],
            source: MappingSource::Profile("test".into()),
        };
        let a = vec![
            ("0x2000:1".to_string(), "1".to_string()),
            ("0x2000:2".to_string(), "0xABC".to_string()),
        ];
        let r = encode_rpdo(&dict, 5, 3, &m, &a).unwrap();
        assert_eq!(super::super::spec::candump(&r.frame), "405#C1AB");
    }

    #[test]
    fn tally_measures_period_and_jitter() {
        let mut t = Tally {
            sent: 4,
            ..Tally::default()
        };
        for ts in [0, 10_000_000, 21_000_000, 30_000_000] {
            t.echo(ts, Some(10_000_000));
        }
        let r = t.report("SYNC 080", Some(10), &[]);
        assert_eq!((r.count, r.seen), (4, 4));
        assert_eq!(r.mean_period_ms, Some(10.0));
        assert_eq!((r.jitter_p99_ms, r.jitter_max_ms), (Some(1.0), Some(1.0)));
        assert!(
            r.text().contains("mean period 10.000 ms, jitter p99 1.000 ms"),
            "{}",
            r.text()
        );
    }
}
