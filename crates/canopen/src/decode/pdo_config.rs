//! A PDO's configuration in words: the CiA 301 communication parameters (the 0x1400 and
//! 0x1800 records) and the mapping entries (0x1600 and 0x1A00), as read from a node or
//! learned from SDO traffic. Pure: values in, text and JSON out.

use super::comm_params::transmission_words;
use crate::od::{Dictionary, MappedEntry};
use serde::Serialize;

/// The communication parameter sub-indices a PDO record has (sub 4 is reserved).
pub const COMM_SUBS: [u8; 5] = [1, 2, 3, 5, 6];

/// Which PDO of a node: RPDO or TPDO, numbered from 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PdoId {
    /// True for a TPDO (the node transmits), false for an RPDO.
    pub transmit: bool,
    /// 1..=512.
    pub num: u16,
}

impl PdoId {
    /// Index of its communication parameter record (0x1400 + n - 1 or 0x1800 + n - 1).
    pub fn comm_index(self) -> u16 {
        (if self.transmit { 0x1800 } else { 0x1400 }) + self.num - 1
    }
    /// Index of its mapping parameter record (0x1600 + n - 1 or 0x1A00 + n - 1).
    pub fn map_index(self) -> u16 {
        self.comm_index() + 0x200
    }
    /// `tpdo1`, `rpdo2`.
    pub fn name(self) -> String {
        format!("{}{}", if self.transmit { "tpdo" } else { "rpdo" }, self.num)
    }
    /// `TPDO1`, `RPDO2`.
    pub fn title(self) -> String {
        self.name().to_ascii_uppercase()
    }
    /// The predefined COB-ID of PDO 1..=4 of `node` (CiA 301 pre-defined connection set).
    pub fn predefined_cob(self, node: u8) -> Option<u32> {
        let base = if self.transmit { 0x180 } else { 0x200 };
        (1..=4)
            .contains(&self.num)
            .then(|| base + 0x100 * u32::from(self.num - 1) + u32::from(node))
    }
}

/// A PDO COB-ID value (sub 1) taken apart: bit 31 invalid, bit 30 no RTR, bit 29 29-bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Cob {
    /// The whole 32-bit value.
    pub raw: u32,
    /// The CAN identifier (11 or 29 bits).
    pub id: u32,
    /// Bit 31 clear: the PDO exists (is in use).
    pub valid: bool,
    /// Bit 29 set: a 29-bit identifier.
    pub extended: bool,
    /// Bit 30 clear: remote frames (RTR) are allowed on this PDO.
    pub rtr_allowed: bool,
}

impl Cob {
    /// Takes a COB-ID value apart.
    pub fn new(raw: u32) -> Cob {
        let extended = raw & (1 << 29) != 0;
        Cob {
            raw,
            id: if extended { raw & 0x1FFF_FFFF } else { raw & 0x7FF },
            valid: raw & (1 << 31) == 0,
            extended,
            rtr_allowed: raw & (1 << 30) == 0,
        }
    }
    /// `0x182`, `0x182 (invalid)`, `0x00012345 (29-bit, no RTR)`.
    pub fn text(self) -> String {
        let mut s = if self.extended {
            format!("0x{:08X}", self.id)
        } else {
            format!("0x{:03X}", self.id)
        };
        let mut flags = Vec::new();
        if !self.valid {
            flags.push("invalid");
        }
        if self.extended {
            flags.push("29-bit");
        }
        if !self.rtr_allowed {
            flags.push("no RTR");
        }
        if !flags.is_empty() {
            s.push_str(&format!(" ({})", flags.join(", ")));
        }
        s
    }
}

/// The communication parameters of one PDO, each as far as known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CommParams {
    /// Sub 1: COB-ID.
    pub cob_id: Option<u32>,
    /// Sub 2: transmission type.
    pub transmission: Option<u8>,
    /// Sub 3: inhibit time in 100 µs units.
    pub inhibit_100us: Option<u16>,
    /// Sub 5: event timer in ms.
    pub event_ms: Option<u16>,
    /// Sub 6: SYNC start value.
    pub sync_start: Option<u8>,
}

impl CommParams {
    /// Takes the value of sub-index `sub`; false when `sub` is not a parameter.
    pub fn set(&mut self, sub: u8, v: u32) -> bool {
        match sub {
            1 => self.cob_id = Some(v),
            2 => self.transmission = Some(v as u8),
            3 => self.inhibit_100us = Some(v as u16),
            5 => self.event_ms = Some(v as u16),
            6 => self.sync_start = Some(v as u8),
            _ => return false,
        }
        true
    }
    /// The COB-ID taken apart.
    pub fn cob(&self) -> Option<Cob> {
        self.cob_id.map(Cob::new)
    }
    /// The parameters in words, `-` for those not known: `COB-ID 0x182, synchronous,
    /// every SYNC (1), inhibit 0 ms, event timer off, SYNC start -`.
    pub fn text(&self) -> String {
        format!(
            "COB-ID {}, {}, inhibit {}, event timer {}, SYNC start {}",
            self.cob().map_or("-".into(), Cob::text),
            self.transmission
                .map_or("transmission type -".into(), transmission_text),
            self.inhibit_100us.map_or("-".into(), inhibit_text),
            self.event_ms.map_or("-".into(), event_text),
            self.sync_start.map_or("-".into(), sync_start_text),
        )
    }
    /// The `--json` form.
    pub fn to_json(&self) -> CommJson {
        CommJson {
            cob_id: self.cob(),
            transmission_type: self.transmission,
            transmission: self.transmission.map(|t| transmission_words(u32::from(t))),
            inhibit_100us: self.inhibit_100us,
            inhibit_ms: self.inhibit_100us.map(|t| f64::from(t) / 10.0),
            event_ms: self.event_ms,
            sync_start: self.sync_start,
        }
    }
}

/// The JSON of [`CommParams`] (null where not known).
#[derive(Clone, Debug, Serialize)]
pub struct CommJson {
    pub cob_id: Option<Cob>,
    pub transmission_type: Option<u8>,
    /// The transmission type in words.
    pub transmission: Option<String>,
    pub inhibit_100us: Option<u16>,
    pub inhibit_ms: Option<f64>,
    pub event_ms: Option<u16>,
    pub sync_start: Option<u8>,
}

/// `synchronous, every SYNC (1)`.
pub fn transmission_text(t: u8) -> String {
    format!("{} ({t})", transmission_words(u32::from(t)))
}

/// An inhibit time in 100 µs units in ms: `0 ms`, `2.5 ms`.
pub fn inhibit_text(units: u16) -> String {
    format!("{} ms", f64::from(units) / 10.0)
}

/// An event timer: `off` (0) or `100 ms`.
pub fn event_text(ms: u16) -> String {
    if ms == 0 { "off".into() } else { format!("{ms} ms") }
}

/// A SYNC start value: `any SYNC` (0) or `SYNC counter 3`.
pub fn sync_start_text(v: u8) -> String {
    if v == 0 {
        "any SYNC".into()
    } else {
        format!("SYNC counter {v}")
    }
}

/// One mapped object in words: `0x6041:00 Statusword, 16 bits` (with the unit when known).
pub fn entry_text(e: &MappedEntry, dict: &Dictionary) -> String {
    let mut s = format!("0x{:04X}:{:02X}", e.index, e.sub);
    if (1..=7).contains(&e.index) {
        s.push_str(" dummy");
    } else if let Some(name) = dict.name(e.index, e.sub) {
        s.push(' ');
        s.push_str(name);
    }
    s.push_str(&format!(", {} bits", e.bits));
    if let Some(unit) = dict.object(e.index, e.sub).and_then(|o| o.unit.as_deref()) {
        s.push_str(&format!(" [{unit}]"));
    }
    s
}

/// One mapped object in the `--json` forms.
#[derive(Clone, Debug, Serialize)]
pub struct EntryJson {
    pub index: u16,
    pub sub: u8,
    pub bits: u8,
    pub name: Option<String>,
    pub unit: Option<String>,
}

impl EntryJson {
    /// `e` with its name and unit from `dict`.
    pub fn new(e: &MappedEntry, dict: &Dictionary) -> EntryJson {
        EntryJson {
            index: e.index,
            sub: e.sub,
            bits: e.bits,
            name: dict.name(e.index, e.sub).map(str::to_string),
            unit: dict.object(e.index, e.sub).and_then(|o| o.unit.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cob_ids_taken_apart() {
        let c = Cob::new(0x8000_0182);
        assert!(!c.valid && !c.extended && c.rtr_allowed);
        assert_eq!(c.id, 0x182);
        assert_eq!(c.text(), "0x182 (invalid)");
        assert_eq!(Cob::new(0x6001_2345).text(), "0x00012345 (29-bit, no RTR)");
        assert_eq!(Cob::new(0x202).text(), "0x202");
        let id = PdoId { transmit: true, num: 2 };
        assert_eq!((id.comm_index(), id.map_index()), (0x1801, 0x1A01));
        assert_eq!(id.predefined_cob(5), Some(0x285));
        assert_eq!(
            PdoId {
                transmit: false,
                num: 4
            }
            .predefined_cob(5),
            Some(0x505)
        );
        assert_eq!(
            PdoId {
                transmit: false,
                num: 5
            }
            .predefined_cob(5),
            None
        );
        assert_eq!(id.title(), "TPDO2");
    }

    #[test]
    fn parameters_in_words() {
        let mut p = CommParams::default();
        for (sub, v) in [(1, 0x182), (2, 5), (3, 25), (5, 0), (6, 3)] {
            assert!(p.set(sub, v));
        }
        assert!(!p.set(4, 1), "sub 4 is reserved");
        assert_eq!(
            p.text(),
            "COB-ID 0x182, synchronous, every 5 SYNCs (5), inhibit 2.5 ms, event timer off, SYNC start SYNC counter 3"
        );
        p.transmission = Some(0xFE);
        p.event_ms = Some(100);
        p.sync_start = None;
        assert_eq!(
            p.text(),
            "COB-ID 0x182, event-driven (manufacturer-specific) (254), inhibit 2.5 ms, event timer 100 ms, SYNC start -"
        );
        assert_eq!(transmission_text(0), "synchronous, acyclic (0)");
        assert_eq!(transmission_text(253), "RTR-only, event-driven (253)");
        let j = serde_json::to_value(p.to_json()).unwrap();
        assert_eq!(j["cob_id"]["valid"], true);
        assert_eq!(j["inhibit_ms"], 2.5);
        assert_eq!(j["transmission"], "event-driven (manufacturer-specific)");
        assert_eq!(j["sync_start"], serde_json::Value::Null);
    }
}
