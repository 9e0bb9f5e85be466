//! The CiA 301 sequence of SDO writes that changes a PDO, one for `pdo map` and `dcf load`:
//! a pure function of what the node has and what it is to get.
//!
//! The order: COB-ID invalid (bit 31), the communication parameters while the PDO is
//! invalid, mapping count 0, the entries, the count, the final COB-ID. CiA 301 lets the
//! inhibit time change only while the PDO is invalid and some devices refuse any
//! communication parameter of a valid PDO; written before the mapping, a refused parameter
//! leaves the mapping untouched; and it is the order python `canopen` (`PdoMap.save`)
//! writes, so it is the one devices are most often tried against.

/// The PDO invalid bit (31) of a COB-ID.
pub const COB_INVALID: u32 = 0x8000_0000;

/// A PDO mapping to write: the entries by sub (`0xIIIISSLL` each; a DCF's unused ones
/// after the count included), then the count.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Mapping {
    pub entries: Vec<(u8, u32)>,
    pub count: u8,
}

impl Mapping {
    /// The mapping of these objects, in order (`0xIIIISSLL` each).
    pub fn of(objects: &[u32]) -> Mapping {
        Mapping {
            entries: (1..).zip(objects.iter().copied()).collect(),
            count: objects.len() as u8,
        }
    }
}

/// One PDO's communication and mapping parameters, as a remapping changes them together.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Remap {
    /// The communication parameter index (0x1400+n or 0x1800+n).
    pub comm: u16,
    /// The mapping parameter index (0x1600+n or 0x1A00+n).
    pub mapping: u16,
    /// The COB-ID the node has now, when known: a valid one is invalidated first.
    pub current_cob: Option<u32>,
    /// The COB-ID to end with: written when it is not the one the node then has.
    pub final_cob: Option<u32>,
    /// Other communication subs to write (transmission type, inhibit time, event timer,
    /// SYNC start value), with their bytes, in order.
    pub comm_subs: Vec<(u8, Vec<u8>)>,
    /// The new mapping, when it changes.
    pub mapping_entries: Option<Mapping>,
}

/// What one write of a remapping does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// COB-ID with bit 31 set: the PDO is invalid while it changes.
    Invalidate,
    /// A communication parameter other than the COB-ID.
    Comm,
    /// Mapping count 0: the entries may be changed.
    ClearMapping,
    /// A mapping entry.
    Entry,
    /// The mapping count.
    Count,
    /// The final COB-ID (valid again, unless it is to stay invalid).
    Cob,
}

/// One SDO write of a remapping.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RemapWrite {
    pub index: u16,
    pub sub: u8,
    pub data: Vec<u8>,
    pub action: Action,
}

/// The writes that change a PDO as `r` says, in the order of the module doc. A PDO the
/// node has invalid is not invalidated again; a final COB-ID equal to the node's is not
/// written.
pub fn remap_sequence(r: &Remap) -> Vec<RemapWrite> {
    let w = |index, sub, data: Vec<u8>, action| RemapWrite {
        index,
        sub,
        data,
        action,
    };
    let mut out = Vec::new();
    let mut node_cob = r.current_cob;
    if let Some(cob) = r.current_cob.filter(|v| v & COB_INVALID == 0) {
        out.push(w(
            r.comm,
            1,
            (cob | COB_INVALID).to_le_bytes().to_vec(),
            Action::Invalidate,
        ));
        node_cob = Some(cob | COB_INVALID);
    }
    for (sub, data) in &r.comm_subs {
        out.push(w(r.comm, *sub, data.clone(), Action::Comm));
    }
    if let Some(m) = &r.mapping_entries {
        out.push(w(r.mapping, 0, vec![0], Action::ClearMapping));
        for (sub, e) in &m.entries {
            out.push(w(r.mapping, *sub, e.to_le_bytes().to_vec(), Action::Entry));
        }
        out.push(w(r.mapping, 0, vec![m.count], Action::Count));
    }
    if let Some(cob) = r.final_cob
        && Some(cob) != node_cob
    {
        out.push(w(r.comm, 1, cob.to_le_bytes().to_vec(), Action::Cob));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps(r: &Remap) -> Vec<(u16, u8, Vec<u8>, Action)> {
        remap_sequence(r)
            .into_iter()
            .map(|w| (w.index, w.sub, w.data, w.action))
            .collect()
    }

    #[test]
    fn remap_follows_the_cia301_sequence() {
        let r = Remap {
            comm: 0x1800,
            mapping: 0x1A00,
            current_cob: Some(0x185),
            final_cob: Some(0x185),
            comm_subs: vec![(2, vec![1])],
            mapping_entries: Some(Mapping::of(&[0x6041_0010, 0x6064_0020])),
        };
        assert_eq!(
            steps(&r),
            [
                (0x1800, 1, vec![0x85, 1, 0, 0x80], Action::Invalidate),
                (0x1800, 2, vec![1], Action::Comm),
                (0x1A00, 0, vec![0], Action::ClearMapping),
                (0x1A00, 1, vec![0x10, 0, 0x41, 0x60], Action::Entry),
                (0x1A00, 2, vec![0x20, 0, 0x64, 0x60], Action::Entry),
                (0x1A00, 0, vec![2], Action::Count),
                (0x1800, 1, vec![0x85, 1, 0, 0], Action::Cob),
            ]
        );
        // A PDO the node has invalid, that is to stay invalid: no COB-ID writes.
        let invalid = Remap {
            current_cob: Some(0x8000_0185),
            final_cob: Some(0x8000_0185),
            mapping_entries: Some(Mapping::of(&[])),
            ..r.clone()
        };
        let at: Vec<(u16, u8)> = remap_sequence(&invalid).iter().map(|w| (w.index, w.sub)).collect();
        assert_eq!(at, [(0x1800, 2), (0x1A00, 0), (0x1A00, 0)]);
        // An invalid PDO made valid: not invalidated again, the COB-ID written last.
        let enable = Remap {
            current_cob: Some(0x8000_0000),
            ..r
        };
        let s = steps(&enable);
        assert_eq!(s[0].3, Action::Comm);
        assert_eq!(s.last().unwrap().2, vec![0x85, 1, 0, 0]);
    }

    #[test]
    fn nothing_known_nothing_of_the_cob_id_written() {
        let r = Remap {
            comm: 0x1400,
            mapping: 0x1600,
            comm_subs: vec![(5, vec![100, 0])],
            ..Remap::default()
        };
        assert_eq!(steps(&r), [(0x1400, 5, vec![100, 0], Action::Comm)]);
    }
}
