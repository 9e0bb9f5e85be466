//! The object dictionary of a simulated device: typed entries with access rights,
//! read and written by SDO and PDO with CiA 301 abort codes for bad requests.

use crate::od::{Access, DataType};
use crate::sdo::abort::codes;
use crate::sdo::server::ObjectStore;
use std::collections::BTreeMap;

/// One entry of a simulated object dictionary.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// Name, as in the profile the device follows.
    pub name: String,
    pub data_type: DataType,
    pub access: Access,
    /// Current value, little-endian.
    pub data: Vec<u8>,
}

/// The entries of one device with their power-on defaults.
#[derive(Clone, Debug, Default)]
pub struct DeviceObjects {
    entries: BTreeMap<(u16, u8), Entry>,
    defaults: BTreeMap<(u16, u8), Vec<u8>>,
    /// Vendor quirk: a write shorter than an unsigned integer object is zero-extended
    /// instead of refused (the Syn-tron manual's own examples write 2 bytes to UNSIGNED32).
    pub short_writes_extend: bool,
}

impl DeviceObjects {
    /// Adds an entry with its default value (fixed-size types take the low bytes of `value`).
    pub fn add(&mut self, index: u16, sub: u8, name: &str, data_type: DataType, access: Access, value: i64) {
        let size = data_type.size().unwrap_or(0);
        let data = value.to_le_bytes()[..size.min(8)].to_vec();
        self.add_bytes(index, sub, name, data_type, access, data);
    }
    /// Adds an entry with a byte-string default (strings, domains).
    pub fn add_bytes(&mut self, index: u16, sub: u8, name: &str, data_type: DataType, access: Access, data: Vec<u8>) {
        self.defaults.insert((index, sub), data.clone());
        self.entries.insert(
            (index, sub),
            Entry {
                name: name.to_string(),
                data_type,
                access,
                data,
            },
        );
    }
    /// Every entry for an EDS/DCF ([`crate::od::dcf`]): default and current value.
    pub fn dcf_entries(&self) -> Vec<crate::od::dcf::DcfEntry> {
        self.entries
            .iter()
            .map(|(&(index, sub), e)| crate::od::dcf::DcfEntry {
                index,
                sub,
                name: e.name.clone(),
                data_type: e.data_type,
                access: e.access,
                default: self.defaults.get(&(index, sub)).cloned(),
                value: Some(e.data.clone()),
            })
            .collect()
    }
    /// Every index with its highest sub-index.
    pub fn highest_subs(&self) -> Vec<(u16, u8)> {
        let mut out: Vec<(u16, u8)> = Vec::new();
        for &(index, sub) in self.entries.keys() {
            match out.last_mut() {
                Some((i, max)) if *i == index => *max = (*max).max(sub),
                _ => out.push((index, sub)),
            }
        }
        out
    }
    /// The entry at (index, sub).
    pub fn entry(&self, index: u16, sub: u8) -> Option<&Entry> {
        self.entries.get(&(index, sub))
    }
    /// True when the index exists with any sub-index.
    pub fn has_index(&self, index: u16) -> bool {
        self.entries.range((index, 0)..=(index, 255)).next().is_some()
    }
    /// Reads an entry for an SDO upload; `Err` is the abort code.
    pub fn read(&self, index: u16, sub: u8) -> Result<Vec<u8>, u32> {
        let e = self.lookup(index, sub)?;
        if e.access == Access::Wo {
            return Err(codes::WRITE_ONLY);
        }
        Ok(e.data.clone())
    }
    /// Writes an entry for an SDO download; `Err` is the abort code.
    pub fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let size = self.lookup(index, sub)?.data_type.size();
        match size {
            Some(size) if self.short_writes_extend && data.len() < size && self.is_unsigned(index, sub) => {
                self.writable(index, sub, Some(size))?;
                let mut full = data.to_vec();
                full.resize(size, 0);
                self.set(index, sub, &full);
            }
            _ => {
                self.writable(index, sub, Some(data.len()))?;
                self.set(index, sub, data);
            }
        }
        Ok(())
    }

    fn is_unsigned(&self, index: u16, sub: u8) -> bool {
        use DataType::*;
        self.entries
            .get(&(index, sub))
            .is_some_and(|e| matches!(e.data_type, U8 | U16 | U24 | U32 | U40 | U48 | U56 | U64))
    }
    /// Sets a value from inside the device (no access check); unknown entries are ignored.
    pub fn set(&mut self, index: u16, sub: u8, data: &[u8]) {
        if let Some(e) = self.entries.get_mut(&(index, sub)) {
            e.data = data.to_vec();
        }
    }
    /// Sets an integer value from inside the device, truncated to the entry's size.
    pub fn set_int(&mut self, index: u16, sub: u8, value: i64) {
        if let Some(e) = self.entries.get_mut(&(index, sub)) {
            let n = e.data_type.size().unwrap_or(8).min(8);
            e.data = value.to_le_bytes()[..n].to_vec();
        }
    }
    /// An unsigned integer value (0 when absent).
    pub fn uint(&self, index: u16, sub: u8) -> u64 {
        self.entry(index, sub)
            .map(|e| e.data.iter().rev().fold(0u64, |a, b| (a << 8) | *b as u64))
            .unwrap_or(0)
    }
    /// A signed integer value, sign-extended from the entry's size (0 when absent).
    pub fn int(&self, index: u16, sub: u8) -> i64 {
        let Some(e) = self.entry(index, sub) else { return 0 };
        let n = e.data.len().clamp(1, 8);
        let raw = self.uint(index, sub);
        let shift = 64 - 8 * n as u32;
        ((raw << shift) as i64) >> shift
    }
    /// Restores the defaults of every entry whose index is in `range`.
    pub fn reset(&mut self, range: std::ops::RangeInclusive<u16>) {
        for ((index, sub), data) in &self.defaults {
            if range.contains(index)
                && let Some(e) = self.entries.get_mut(&(*index, *sub))
            {
                e.data = data.clone();
            }
        }
    }

    /// Checks a write of `len` bytes (when known) without storing anything.
    fn writable(&self, index: u16, sub: u8, len: Option<usize>) -> Result<(), u32> {
        let e = self.lookup(index, sub)?;
        if matches!(e.access, Access::Ro | Access::Const) {
            return Err(codes::READ_ONLY);
        }
        match (e.data_type.size(), len) {
            (Some(size), Some(n)) if n > size => Err(codes::LENGTH_TOO_HIGH),
            (Some(size), Some(n)) if n < size => Err(codes::LENGTH_TOO_LOW),
            _ => Ok(()),
        }
    }

    fn lookup(&self, index: u16, sub: u8) -> Result<&Entry, u32> {
        match self.entries.get(&(index, sub)) {
            Some(e) => Ok(e),
            None if self.has_index(index) => Err(codes::NO_SUB),
            None => Err(codes::NO_OBJECT),
        }
    }
}

impl ObjectStore for DeviceObjects {
    fn read(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, u32> {
        DeviceObjects::read(self, index, sub)
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        DeviceObjects::write(self, index, sub, data)
    }
    fn check_write(&mut self, index: u16, sub: u8, size: Option<usize>) -> Result<(), u32> {
        self.writable(index, sub, size)
    }
    fn size(&self, index: u16, sub: u8) -> Option<usize> {
        self.entry(index, sub).and_then(|e| e.data_type.size())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn store() -> DeviceObjects {
        let mut s = DeviceObjects::default();
        s.add(0x1000, 0, "Device type", DataType::U32, Access::Ro, 0x0002_0192);
        s.add(0x6040, 0, "Controlword", DataType::U16, Access::Rww, 0);
        s.add(0x6064, 0, "Position actual value", DataType::I32, Access::Ro, -5);
        s
    }

    #[test]
    fn reads_writes_and_aborts() {
        let mut s = store();
        assert_eq!(s.read(0x1000, 0), Ok(vec![0x92, 0x01, 0x02, 0x00]));
        assert_eq!(s.int(0x6064, 0), -5);
        assert_eq!(s.read(0x2000, 0), Err(codes::NO_OBJECT));
        assert_eq!(s.read(0x1000, 1), Err(codes::NO_SUB));
        assert_eq!(s.write(0x1000, 0, &[0; 4]), Err(codes::READ_ONLY));
        assert_eq!(s.write(0x6040, 0, &[6]), Err(codes::LENGTH_TOO_LOW));
        assert_eq!(s.write(0x6040, 0, &[6, 0, 0]), Err(codes::LENGTH_TOO_HIGH));
        assert_eq!(s.write(0x6040, 0, &[6, 0]), Ok(()));
        assert_eq!(s.uint(0x6040, 0), 6);
        s.reset(0x6000..=0x9FFF);
        assert_eq!(s.uint(0x6040, 0), 0);
    }
}
