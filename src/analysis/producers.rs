//! Other producers of a broadcast service heard lately: who else sent SYNC (0x080) or NMT
//! (0x000) frames in the seconds before the newest frame, not counting the frames cotui sent
//! itself (those carry the TX flag). The palette warns with it before starting a second
//! SYNC producer or commanding as a second NMT master; `cotui sync` and `cotui nmt` listen
//! with [`from_other`] and [`Heard::note`] before they send (`command::listen_first`).

use super::trace::Trace;
use crate::frame::Flags;

/// How far back [`heard`] looks, before the newest frame (2 s).
pub const RECENT_NS: u64 = 2_000_000_000;

/// Frames of one COB-ID from another producer, in the last [`RECENT_NS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Heard {
    /// How many.
    pub count: usize,
    /// The newest one's timestamp (ns, the frames' time base).
    pub last_ns: u64,
}

impl Heard {
    /// `heard` with one more frame of the other producer, stamped `ts_ns`.
    pub fn note(heard: Option<Heard>, ts_ns: u64) -> Heard {
        let h = heard.unwrap_or(Heard { count: 0, last_ns: 0 });
        Heard {
            count: h.count + 1,
            last_ns: h.last_ns.max(ts_ns),
        }
    }
}

/// True for a frame another producer of `cob_id` sent: a classic 11-bit frame with that
/// id, not cotui's own (TX) and not an error frame.
pub fn from_other(id: u32, flags: Flags, cob_id: u32) -> bool {
    id == cob_id && !flags.has(Flags::TX) && !flags.has(Flags::EXT) && !flags.has(Flags::ERR)
}

/// Classic 11-bit frames with `cob_id`, not sent by cotui, in the [`RECENT_NS`] before the
/// trace's newest frame; None when there were none.
pub fn heard(trace: &Trace, cob_id: u32) -> Option<Heard> {
    let n = trace.store.len();
    let newest = trace.store.packed(n.checked_sub(1)?).ts_ns;
    let since = newest.saturating_sub(RECENT_NS);
    let mut out: Option<Heard> = None;
    // Back from the newest frame to the first one before the window (a bus that carries
    // frames of several clocks is never searched as if sorted).
    for i in (0..n).rev() {
        let p = trace.store.packed(i);
        if p.ts_ns < since {
            break;
        }
        if from_other(p.id, Flags(p.flags), cob_id) {
            out = Some(Heard::note(out, p.ts_ns));
        }
    }
    out
}
