//! Exact bus load: every frame's bits on the wire (SOF to EOF, stuff bits, the 3-bit
//! intermission; see [`crate::wire`]) summed over the capture, per node, in the busiest
//! 100 ms and over the longest burst. Error frames are reports of the controller, not
//! frames on the wire: they count nothing.

use crate::frame::{Frame, NodeKey};
use crate::wire::WireFigures;
use serde::Serialize;
use std::collections::{HashMap, VecDeque};

/// The window of [`BusLoad`]'s busiest stretch: 100 ms.
const BUSY_WINDOW_NS: u64 = 100_000_000;

/// Where the bit rate of the load came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BitrateSource {
    /// `--bitrate`.
    Option,
    /// The interface's configured rate (live capture).
    Interface,
    /// Nobody said: 500 kbit/s is assumed.
    Assumed,
}

impl BitrateSource {
    /// How the text reports say it (`given`, `of the interface`, `assumed`).
    pub fn as_str(self) -> &'static str {
        match self {
            BitrateSource::Option => "given",
            BitrateSource::Interface => "of the interface",
            BitrateSource::Assumed => "assumed",
        }
    }
}

/// A bus bit rate and where it came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bitrate {
    /// Bits per second (nominal, arbitration phase).
    pub bps: u64,
    /// Where it came from.
    pub source: BitrateSource,
    /// Of the interface: the interface it came from; assumed: why (`vcan0 reports no bit
    /// rate`); then what the other interfaces of the session said, when they disagree.
    pub note: Option<String>,
}

impl Bitrate {
    /// The rate assumed when nobody gives one: 500 kbit/s.
    pub const ASSUMED: Bitrate = Bitrate {
        bps: 500_000,
        source: BitrateSource::Assumed,
        note: None,
    };
    /// `--bitrate` when given, else [`Bitrate::ASSUMED`].
    pub fn given_or_assumed(bps: Option<u64>) -> Bitrate {
        bps.map_or(Bitrate::ASSUMED, Bitrate::from)
    }

    /// The rate of a live session: `--bitrate` when given; else the rate of the first of
    /// its interfaces that reports one; else 500 kbit/s assumed. `ifaces` are each
    /// interface's name and its configured rate, or why it has none (the words after its
    /// name: `reports no bit rate`). What every other interface said, when it is not that
    /// rate, goes into the note.
    pub fn of_live(option: Option<u64>, ifaces: &[(&str, Result<u64, String>)]) -> Bitrate {
        if option.is_some() {
            return Bitrate::given_or_assumed(option);
        }
        let chosen = ifaces
            .iter()
            .find_map(|(name, r)| r.as_ref().ok().map(|&bps| (*name, bps)));
        let mut said: Vec<String> = chosen.iter().map(|(name, _)| name.to_string()).collect();
        for (name, r) in ifaces {
            match r {
                Ok(bps) if chosen.is_some_and(|(_, c)| c == *bps) => {}
                Ok(bps) => said.push(format!("{name} reports {} kbit/s", *bps as f64 / 1000.0)),
                Err(why) => said.push(format!("{name} {why}")),
            }
        }
        let note = (!said.is_empty()).then(|| said.join("; "));
        match chosen {
            Some((_, bps)) => Bitrate {
                bps,
                source: BitrateSource::Interface,
                note,
            },
            None => Bitrate {
                note,
                ..Bitrate::ASSUMED
            },
        }
    }

    /// Where the rate came from, as the reports say it after the rate: `given`, `of can0`,
    /// `assumed`, `assumed: vcan0 reports no bit rate`.
    pub fn said(&self) -> String {
        match (self.source, &self.note) {
            (source, None) => source.as_str().to_string(),
            (BitrateSource::Interface, Some(note)) => format!("of {note}"),
            (source, Some(note)) => format!("{}: {note}", source.as_str()),
        }
    }
}

/// A rate in bit/s someone gave (`--bitrate`).
impl From<u64> for Bitrate {
    fn from(bps: u64) -> Bitrate {
        Bitrate {
            bps,
            source: BitrateSource::Option,
            note: None,
        }
    }
}

impl Default for Bitrate {
    fn default() -> Self {
        Bitrate::ASSUMED
    }
}

/// The bits on the wire of `frame` with the intermission after it; 0 for an error frame
/// (or a frame no controller could send).
pub fn bus_bits(frame: &Frame) -> u64 {
    crate::wire::figures(frame).map_or(0, |f| u64::from(f.bus_bits()))
}

/// Running bus-load totals of a capture.
#[derive(Clone, Debug, Default)]
pub struct BusLoad {
    bitrate: Bitrate,
    frames: u64,
    bits: u64,
    stuff_bits: u64,
    first_ns: Option<u64>,
    last_ns: u64,
    /// Bits of the first interface's 128 nodes (made on its first node frame).
    first_nodes: Vec<u64>,
    /// Bits of the nodes of every other interface (a fast seeded hash: looked up per frame).
    other_nodes: HashMap<NodeKey, u64, foldhash::fast::RandomState>,
    /// Frames of the last 100 ms: (time, bits, interface).
    window: VecDeque<(u64, u32, u16)>,
    window_bits: u64,
    busiest_bits: u64,
    /// The current burst: its start (ns) and the time its last frame ended.
    burst: Option<(u64, u64)>,
    longest_burst_ns: u64,
    /// The nanoseconds a frame of n bits takes at the bit rate, for every classic frame's
    /// n (made by [`BusLoad::new`]; a division per frame otherwise).
    took_ns: Vec<u64>,
    /// The figures of the frames seen, for those that come again.
    figures: crate::wire::cache::FiguresCache,
    /// Each interface's figures by index, once a second interface is seen (until then the
    /// capture's figures are the first interface's): plain counters, no allocation per
    /// interface.
    ifaces: Vec<IfaceLoad>,
}

/// The figures of one interface of a capture of several.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IfaceLoad {
    /// Frames (error frames included).
    pub frames: u64,
    /// Bits on the wire.
    pub bits: u64,
    first_ns: Option<u64>,
    last_ns: u64,
    /// Bits of this interface among [`BusLoad`]'s last 100 ms.
    window_bits: u64,
    busiest_bits: u64,
    burst: Option<(u64, u64)>,
    longest_burst_ns: u64,
}

/// The burst after a frame of `took` ns that ended at `t`, and the one before: it goes on
/// while the bus stays idle for less than the frame takes.
fn next_burst(burst: Option<(u64, u64)>, t: u64, took: u64) -> (u64, u64) {
    let start = t.saturating_sub(took);
    match burst {
        Some((since, end)) if start < end.saturating_add(took) => (since, t.max(end)),
        _ => (start, t),
    }
}

/// More bits than any classic frame takes with its intermission (at most 160).
const TOOK_TABLE: u64 = 192;

impl BusLoad {
    /// Empty totals for a bus at `bitrate`.
    pub fn new(bitrate: Bitrate) -> BusLoad {
        let bps = bitrate.bps.max(1);
        BusLoad {
            bitrate: Bitrate { bps, ..bitrate },
            took_ns: (0..TOOK_TABLE).map(|bits| took_ns(bits, bps)).collect(),
            ..BusLoad::default()
        }
    }

    /// The bit rate the load is counted against.
    pub fn bitrate(&self) -> &Bitrate {
        &self.bitrate
    }

    /// Counts one frame (of `node`, when it has one) with its wire `figures` (`None`:
    /// worked out here). Frames are taken in time order; a frame's timestamp is taken as
    /// the end of its EOF.
    #[inline(always)]
    pub fn add(&mut self, frame: &Frame, node: Option<u8>, figures: Option<WireFigures>) {
        let per_iface = frame.iface != 0 || !self.ifaces.is_empty();
        if per_iface {
            self.iface_frame(frame.iface);
        }
        self.frames += 1;
        let Ok(fig) = figures.unwrap_or_else(|| self.figures.figures(frame)) else {
            return;
        };
        let bits = fig.bus_bits();
        self.bits += u64::from(bits);
        self.stuff_bits += u64::from(fig.stuff_bits);
        let t = frame.ts_ns;
        self.first_ns.get_or_insert(t);
        self.last_ns = self.last_ns.max(t);
        if let Some(n) = node {
            let key = NodeKey::new(frame.iface, n & 0x7F);
            if key.iface == 0 {
                if self.first_nodes.is_empty() {
                    self.first_nodes = vec![0; 128];
                }
                self.first_nodes[usize::from(key.node)] += u64::from(bits);
            } else {
                *self.other_nodes.entry(key).or_insert(0) += u64::from(bits);
            }
        }
        self.window.push_back((t, bits, frame.iface));
        self.window_bits += u64::from(bits);
        while let Some(&(old, b, i)) = self.window.front() {
            if old + BUSY_WINDOW_NS > t {
                break;
            }
            self.window_bits -= u64::from(b);
            // Frames come in time order: a frame of another interface that leaves the
            // window now has left it at that interface's next frame too.
            if let Some(iface) = self.ifaces.get_mut(usize::from(i)) {
                iface.window_bits -= u64::from(b);
            }
            self.window.pop_front();
        }
        self.busiest_bits = self.busiest_bits.max(self.window_bits);
        let took = match self.took_ns.get(bits as usize) {
            Some(&ns) => ns,
            None => took_ns(u64::from(bits), self.bitrate.bps),
        };
        let burst = next_burst(self.burst, t, took);
        self.longest_burst_ns = self.longest_burst_ns.max(burst.1 - burst.0);
        self.burst = Some(burst);
        if per_iface {
            let s = &mut self.ifaces[usize::from(frame.iface)];
            s.bits += u64::from(bits);
            s.first_ns.get_or_insert(t);
            s.last_ns = s.last_ns.max(t);
            s.window_bits += u64::from(bits);
            s.busiest_bits = s.busiest_bits.max(s.window_bits);
            let burst = next_burst(s.burst, t, took);
            s.longest_burst_ns = s.longest_burst_ns.max(burst.1 - burst.0);
            s.burst = Some(burst);
        }
    }

    /// Counts a frame of `iface` among the interfaces' figures; on the first frame of a
    /// second interface, the first interface's figures are the capture's so far.
    #[cold]
    fn iface_frame(&mut self, iface: u16) {
        if self.ifaces.is_empty() {
            self.ifaces.push(IfaceLoad {
                frames: self.frames,
                bits: self.bits,
                first_ns: self.first_ns,
                last_ns: self.last_ns,
                window_bits: self.window_bits,
                busiest_bits: self.busiest_bits,
                burst: self.burst,
                longest_burst_ns: self.longest_burst_ns,
            });
        }
        let i = usize::from(iface);
        if i >= self.ifaces.len() {
            self.ifaces.resize(i + 1, IfaceLoad::default());
        }
        self.ifaces[i].frames += 1;
    }

    /// Each interface's figures (by index; interfaces without frames left out). A capture
    /// of one interface has one entry, the capture's figures.
    pub fn by_iface(&self) -> Vec<(u16, IfaceLoad)> {
        if self.ifaces.is_empty() {
            let whole = IfaceLoad {
                frames: self.frames,
                bits: self.bits,
                first_ns: self.first_ns,
                last_ns: self.last_ns,
                window_bits: self.window_bits,
                busiest_bits: self.busiest_bits,
                burst: self.burst,
                longest_burst_ns: self.longest_burst_ns,
            };
            return if self.frames > 0 { vec![(0, whole)] } else { Vec::new() };
        }
        let all = self.ifaces.iter().enumerate();
        all.filter(|(_, s)| s.frames > 0).map(|(i, s)| (i as u16, *s)).collect()
    }

    /// The figures of `iface` (named `name`) as JSON.
    pub fn iface_json(&self, name: &str, iface: &IfaceLoad) -> IfaceJson {
        IfaceJson {
            bitrate: self.bitrate.bps,
            bitrate_source: self.bitrate.source,
            bits: iface.bits,
            busiest_100ms: round6(iface.busiest_bits as f64 / self.window_capacity()),
            frames: iface.frames,
            iface: name.to_string(),
            load: load(iface.bits, iface.first_ns, iface.last_ns, self.bitrate.bps).map(round6),
            longest_burst_ms: round6(iface.longest_burst_ns as f64 / 1e6),
        }
    }

    /// The bits 100 ms holds at the bit rate.
    fn window_capacity(&self) -> f64 {
        self.bitrate.bps as f64 * BUSY_WINDOW_NS as f64 / 1e9
    }

    /// Bits counted, intermissions included.
    pub fn bits(&self) -> u64 {
        self.bits
    }

    /// The load over the capture: bits / (bit rate x duration); None before two frames at
    /// different times.
    pub fn load(&self) -> Option<f64> {
        load(self.bits, self.first_ns, self.last_ns, self.bitrate.bps)
    }

    /// Every node's bits, in node order.
    pub fn by_node(&self) -> Vec<(NodeKey, u64)> {
        let first = self.first_nodes.iter().enumerate();
        let first = first
            .filter(|(_, b)| **b > 0)
            .map(|(n, b)| (NodeKey::new(0, n as u8), *b));
        let mut all: Vec<(NodeKey, u64)> = first.chain(self.other_nodes.iter().map(|(k, b)| (*k, *b))).collect();
        all.sort_unstable();
        all
    }

    /// The figures as JSON, nodes keyed by `key`.
    pub fn to_json(&self, key: impl Fn(NodeKey) -> String) -> BusJson {
        let window = self.window_capacity();
        BusJson {
            bitrate: self.bitrate.bps,
            bitrate_source: self.bitrate.source,
            bits: self.bits,
            stuff_bits: self.stuff_bits,
            load: self.load().map(round6),
            by_node: self.by_node().into_iter().map(|(k, b)| (key(k), b)).collect(),
            busiest_100ms: round6(self.busiest_bits as f64 / window),
            longest_burst_ms: round6(self.longest_burst_ns as f64 / 1e6),
        }
    }

    /// Appends the figures as text lines (after the summary's `by node:`) to `out`, nodes in
    /// node order, each named by `name` (which writes the name into the buffer it is given).
    pub fn to_text(&self, out: &mut String, name: impl Fn(&mut String, NodeKey)) {
        use std::fmt::Write;
        let load = self.load().map(round6);
        let load = load.map_or("-".to_string(), |l| format!("{:.2} %", l * 100.0));
        // Writing to a String cannot fail.
        let _ = writeln!(
            out,
            "bus: {} bits ({} stuff bits) at {} kbit/s ({}): load {load}, busiest 100 ms {:.2} %, longest burst {:.3} ms",
            self.bits,
            self.stuff_bits,
            self.bitrate.bps as f64 / 1000.0,
            self.bitrate.said(),
            round6(self.busiest_bits as f64 / self.window_capacity()) * 100.0,
            round6(self.longest_burst_ns as f64 / 1e6),
        );
        // One name buffer for every row: a capture of 40,000 interfaces has many.
        let mut shown = String::new();
        for (node, bits) in self.by_node() {
            shown.clear();
            name(&mut shown, node);
            // As `{shown:<8} {bits:>10}`, without the formatter's cost per row.
            out.push_str("  ");
            out.push_str(&shown);
            out.extend(std::iter::repeat_n(' ', 8usize.saturating_sub(shown.chars().count())));
            out.push(' ');
            push_num(out, bits, 10);
            out.push_str(" bits\n");
        }
    }
}

/// Appends `n` in decimal, padded with spaces to `width` (right-aligned; a negative width:
/// left-aligned), as `{n:>w}` / `{n:<w}` write it.
pub(crate) fn push_num(s: &mut String, n: u64, width: i32) {
    let mut digits = [0u8; 20];
    let mut at = digits.len();
    let mut v = n;
    loop {
        at -= 1;
        digits[at] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    let len = digits.len() - at;
    let pad = (width.unsigned_abs() as usize).saturating_sub(len);
    if width > 0 {
        s.extend(std::iter::repeat_n(' ', pad));
    }
    // ASCII digits.
    s.extend(digits[at..].iter().map(|&d| char::from(d)));
    if width < 0 {
        s.extend(std::iter::repeat_n(' ', pad));
    }
}

/// Nanoseconds `bits` take at `bps` bit/s (whole, rounded down).
fn took_ns(bits: u64, bps: u64) -> u64 {
    bits * 1_000_000_000 / bps.max(1)
}

/// bits / (bit rate x the time from `first` to `last`); None for one instant.
fn load(bits: u64, first_ns: Option<u64>, last_ns: u64, bps: u64) -> Option<f64> {
    let span = last_ns - first_ns?;
    (span > 0).then(|| bits as f64 * 1e9 / (bps as f64 * span as f64))
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The bus figures of `--summary --format jsonl` (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct BusJson {
    /// Bits per second.
    pub bitrate: u64,
    /// `option`, `interface` or `assumed`.
    pub bitrate_source: BitrateSource,
    /// Bits on the wire, intermissions included.
    pub bits: u64,
    /// Bits of the busiest 100 ms window / the bits 100 ms holds.
    pub busiest_100ms: f64,
    /// Bits per node (keyed as the summary's `by_node`).
    pub by_node: std::collections::BTreeMap<String, u64>,
    /// bits / (bitrate x capture duration); null for a capture of one instant.
    pub load: Option<f64>,
    /// The longest stretch in which the bus never stayed idle as long as the next frame took.
    pub longest_burst_ms: f64,
    /// Stuff bits among `bits`.
    pub stuff_bits: u64,
}

/// One interface's figures in `--summary --format jsonl` (`by_iface`; fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct IfaceJson {
    /// Bits per second (the capture's).
    pub bitrate: u64,
    /// `option`, `interface` or `assumed`.
    pub bitrate_source: BitrateSource,
    /// Bits on the wire of this interface's frames.
    pub bits: u64,
    /// Bits of its busiest 100 ms window / the bits 100 ms holds.
    pub busiest_100ms: f64,
    /// Frames (error frames included).
    pub frames: u64,
    /// The interface's name.
    pub iface: String,
    /// bits / (bitrate x the time from its first frame to its last); null for one instant.
    pub load: Option<f64>,
    /// Its longest burst.
    pub longest_burst_ms: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Flags;

    fn none(why: &str) -> Result<u64, String> {
        Err(why.to_string())
    }

    #[test]
    fn a_live_session_takes_the_interface_rate_else_assumes_500k_and_says_why() {
        let can0 = ("can0", Ok(250_000));
        let vcan0 = ("vcan0", none("reports no bit rate"));
        // --bitrate wins over what the interface says.
        let given = Bitrate::of_live(Some(1_000_000), std::slice::from_ref(&can0));
        assert_eq!((given.bps, given.said()), (1_000_000, "given".to_string()));
        let of_can0 = Bitrate::of_live(None, std::slice::from_ref(&can0));
        assert_eq!(of_can0.source, BitrateSource::Interface);
        assert_eq!((of_can0.bps, of_can0.said()), (250_000, "of can0".to_string()));
        let vcan = Bitrate::of_live(None, std::slice::from_ref(&vcan0));
        assert_eq!(vcan.source, BitrateSource::Assumed);
        assert_eq!(
            (vcan.bps, vcan.said()),
            (500_000, "assumed: vcan0 reports no bit rate".to_string())
        );
        // Several interfaces: the first rate reported; the others' say when they differ.
        let mixed = Bitrate::of_live(
            None,
            &[
                vcan0.clone(),
                can0.clone(),
                ("can1", Ok(125_000)),
                ("can2", Ok(250_000)),
            ],
        );
        assert_eq!(mixed.bps, 250_000);
        assert_eq!(
            mixed.said(),
            "of can0; vcan0 reports no bit rate; can1 reports 125 kbit/s"
        );
        // No interface (a log) and nothing given: assumed, nothing to say why.
        assert_eq!(Bitrate::of_live(None, &[]).said(), "assumed");
    }

    #[test]
    fn the_summary_text_says_where_the_rate_came_from() {
        let bitrate = Bitrate::of_live(None, &[("vcan0", none("reports no bit rate"))]);
        let mut bus = BusLoad::new(bitrate);
        bus.add(&at(0, 0x80, &[]), None, None);
        let mut out = String::new();
        bus.to_text(&mut out, |_, _| {});
        assert!(
            out.contains("at 500 kbit/s (assumed: vcan0 reports no bit rate)"),
            "{out}"
        );
    }

    fn at(ms: u64, id: u32, data: &[u8]) -> Frame {
        let mut f = Frame::classic(id, data);
        f.ts_ns = ms * 1_000_000;
        f
    }

    /// 185#2500EA00 is 79 + 3 = 82 bits (canworks' example); the SYNC's bits are those of
    /// `wire::figures` (checked against the ISO reference in crates/canopen/tests).
    #[test]
    fn totals_per_node_and_load_by_hand() {
        let sync = crate::wire::figures(&Frame::classic(0x80, &[])).unwrap();
        let mut b = BusLoad::new(Bitrate::ASSUMED);
        b.add(&at(0, 0x185, &[0x25, 0, 0xEA, 0]), Some(5), None);
        b.add(&at(10, 0x80, &[]), None, None);
        b.add(&at(1000, 0x185, &[0x25, 0, 0xEA, 0]), Some(5), None);
        let mut err = at(500, 4, &[0; 8]);
        err.flags = Flags(Flags::ERR);
        b.add(&err, None, None);
        let total = 82 * 2 + u64::from(sync.bus_bits());
        assert_eq!(b.bits(), total);
        assert_eq!(b.by_node(), [(NodeKey::new(0, 5), 164)]);
        // Over 1 s at 500 kbit/s.
        assert_eq!(b.load(), Some(total as f64 / 500_000.0));
        let j = serde_json::to_value(b.to_json(|k| k.node.to_string())).unwrap();
        assert_eq!(j["bitrate_source"], "assumed");
        assert_eq!(j["by_node"]["5"], 164);
        // The busiest 100 ms holds the first two frames: of the 50,000 bits 100 ms holds.
        assert_eq!(
            j["busiest_100ms"],
            round6((82 + u64::from(sync.bus_bits())) as f64 / 50_000.0)
        );
    }

    #[test]
    fn a_burst_lasts_while_frames_follow_each_other() {
        let mut b = BusLoad::new(Bitrate::from(1_000_000));
        // 82 bits at 1 Mbit/s: 82 µs each; frames every 100 µs are one burst.
        for i in 0..10u64 {
            let mut f = at(0, 0x185, &[0x25, 0, 0xEA, 0]);
            f.ts_ns = 1_000_000 + i * 100_000;
            b.add(&f, Some(5), None);
        }
        // A frame 10 ms later starts a new one.
        b.add(&at(20, 0x185, &[0x25, 0, 0xEA, 0]), Some(5), None);
        // From the start of the first (1 ms - 82 µs) to the end of the tenth (1.9 ms).
        assert_eq!(b.to_json(|k| k.node.to_string()).longest_burst_ms, 0.982);
        assert_eq!(b.load(), Some(11.0 * 82.0 / 19_000.0));
    }
}
