//! The indexes one dictionary layer knows anything about, as a bit per index, so that a
//! lookup passes over the layers that have nothing there without searching them.

use super::profile::Profile;

/// A set of object indexes (0x0000..=0xFFFF).
#[derive(Clone, Debug)]
pub(crate) struct IndexSet {
    bits: Box<[u64]>,
}

impl IndexSet {
    /// Every index at which `p` has an entry, a sub family, a record name or an index range.
    pub fn of(p: &Profile) -> IndexSet {
        let mut set = IndexSet {
            bits: vec![0; 1 << 10].into_boxed_slice(),
        };
        let explicit = p.objects.keys().chain(p.families.keys()).map(|k| k.0);
        for index in explicit.chain(p.object_names.keys().copied()) {
            set.insert(index);
        }
        for r in &p.ranges {
            for index in r.first..=r.last {
                set.insert(index);
            }
        }
        set
    }

    fn insert(&mut self, index: u16) {
        self.bits[usize::from(index >> 6)] |= 1 << (index & 63);
    }

    /// Whether `index` is in the set.
    pub fn contains(&self, index: u16) -> bool {
        self.bits[usize::from(index >> 6)] & (1 << (index & 63)) != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::{IndexRange, ObjectInfo, SubFamily};

    #[test]
    fn holds_the_indexes_of_entries_families_names_and_ranges_only() {
        let mut p = Profile::default();
        p.objects.insert((0x6041, 0), ObjectInfo::default());
        p.add_family(0x1003, SubFamily::new(1, 254, ObjectInfo::default()));
        p.object_names.insert(0x1018, "Identity object".into());
        p.ranges.push(IndexRange::new(0x1400, 0x15FF, Default::default(), None));
        let set = IndexSet::of(&p);
        for index in [0x6041, 0x1003, 0x1018, 0x1400, 0x1500, 0x15FF] {
            assert!(set.contains(index), "{index:#06x}");
        }
        for index in [0x0000, 0x6040, 0x6042, 0x1004, 0x13FF, 0x1600, 0xFFFF] {
            assert!(!set.contains(index), "{index:#06x}");
        }
    }
}
