//! The PDO table: per node, each RPDO/TPDO the decoder knows (from a profile, an EDS, SDO
//! traffic on the bus, a remap by cotui, a read of the node) with its communication
//! parameters in words and its mapping. Built for the rows asked for only.

use crate::decode::Decoder;
use crate::decode::pdo::source_text_since;
use crate::decode::pdo_config::{CommParams, PdoId, event_text, inhibit_text, sync_start_text, transmission_text};
use crate::frame::NodeKey;
use crate::od::{MappingSource, PdoMapping};

/// One PDO of one node as the decoder knows it.
#[derive(Clone, Debug, PartialEq)]
pub struct PdoRow {
    pub node: u8,
    /// The node's interface (index into the source's interface table).
    pub iface: u16,
    pub id: PdoId,
    /// The communication parameters seen (null when only a mapping is known).
    pub comm: Option<CommParams>,
    /// The mapping in force, if known.
    pub mapping: Option<PdoMapping>,
}

/// The PDOs the decoder knows, in order (node, RPDO before TPDO, number): cheap keys, so a
/// pane can count and scroll without building rows.
pub fn keys(decoder: &Decoder) -> Vec<(NodeKey, PdoId)> {
    decoder.known_pdos()
}

/// The rows of `keys` (a visible window of [`keys`]).
pub fn rows(decoder: &Decoder, keys: &[(NodeKey, PdoId)]) -> Vec<PdoRow> {
    keys.iter()
        .map(|&(node, id)| PdoRow {
            node: node.node,
            iface: node.iface,
            id,
            comm: decoder.pdo_comm(node, id.transmit, id.num),
            mapping: decoder.mapping(node, id.transmit, id.num).cloned(),
        })
        .collect()
}

/// Where a mapping came from, in one word or two: `profile aimotor`, `eds x.eds`, `learned`,
/// `configured`, `read from node`.
pub fn source_word(source: &MappingSource) -> String {
    match source {
        MappingSource::Profile(p) => format!("profile {p}"),
        MappingSource::Eds(f) => format!("eds {f}"),
        MappingSource::Sniffed { .. } => "learned".into(),
        MappingSource::Configured { .. } => "configured".into(),
        MappingSource::ReadFromNode { .. } => "read from node".into(),
    }
}

impl PdoRow {
    /// The COB-ID in words: the value seen (`0x182`, `0x382 (invalid)`), else the
    /// predefined one marked so.
    pub fn cob_text(&self) -> String {
        match self.comm.as_ref().and_then(CommParams::cob) {
            Some(c) => c.text(),
            None => match self.id.predefined_cob(self.node) {
                Some(c) => format!("0x{c:03X} (predefined)"),
                None => "-".into(),
            },
        }
    }

    /// The table cells: node, PDO, COB-ID, transmission, inhibit, event timer, SYNC start,
    /// mapping source, signals (`Statusword, Position actual value`, or `-`).
    pub fn cells(&self, name: impl Fn(u16, u8) -> Option<String>) -> [String; 9] {
        let c = self.comm.unwrap_or_default();
        let dash = || "-".to_string();
        let signals = self.mapping.as_ref().map_or_else(dash, |m| {
            if m.entries.is_empty() {
                return "nothing mapped".into();
            }
            m.entries
                .iter()
                .map(|e| name(e.index, e.sub).unwrap_or_else(|| format!("0x{:04X}:{:02X}", e.index, e.sub)))
                .collect::<Vec<_>>()
                .join(", ")
        });
        [
            self.node.to_string(),
            self.id.title(),
            self.cob_text(),
            c.transmission.map_or_else(dash, transmission_text),
            c.inhibit_100us.map_or_else(dash, inhibit_text),
            c.event_ms.map_or_else(dash, event_text),
            c.sync_start.map_or_else(dash, sync_start_text),
            self.mapping.as_ref().map_or_else(dash, |m| source_word(&m.source)),
            signals,
        ]
    }

    /// Where the mapping came from, in full (`configured by cotui @ 12.500000 s`), its time
    /// counted from `origin_ns` (the trace's first frame).
    pub fn source_text(&self, origin_ns: u64) -> Option<String> {
        self.mapping.as_ref().map(|m| source_text_since(&m.source, origin_ns))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Flags, Frame};
    use crate::od::Dictionary;

    fn sdo(id: u32, data: [u8; 8], tx: bool) -> Frame {
        let mut f = Frame::classic(id, &data);
        f.flags.set(Flags::TX, tx);
        f
    }

    #[test]
    fn rows_from_sdo_traffic_with_their_source() {
        let mut d = Decoder::new(Dictionary::default(), Vec::new());
        // cotui (TX) maps TPDO1 of node 5 to the statusword and sets type 1, event 100 ms.
        let writes: [([u8; 8], bool); 4] = [
            ([0x2F, 0x00, 0x1A, 0x00, 0, 0, 0, 0], true),
            ([0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60], true),
            ([0x2F, 0x00, 0x1A, 0x00, 1, 0, 0, 0], true),
            ([0x2F, 0x00, 0x18, 0x02, 1, 0, 0, 0], true),
        ];
        for (req, tx) in writes {
            d.decode(&sdo(0x605, req, tx));
            d.decode(&sdo(0x585, [0x60, req[1], req[2], req[3], 0, 0, 0, 0], false));
        }
        // Someone else writes RPDO2's event timer.
        d.decode(&sdo(0x605, [0x2B, 0x01, 0x14, 0x05, 100, 0, 0, 0], false));
        d.decode(&sdo(0x585, [0x60, 0x01, 0x14, 0x05, 0, 0, 0, 0], false));
        let keys = keys(&d);
        assert_eq!(
            keys,
            [
                (
                    NodeKey::new(0, 5),
                    PdoId {
                        transmit: false,
                        num: 2
                    }
                ),
                (NodeKey::new(0, 5), PdoId { transmit: true, num: 1 })
            ]
        );
        let rows = rows(&d, &keys);
        let dict = Dictionary::default();
        let name = |i, s| dict.name(i, s).map(str::to_string);
        assert_eq!(
            rows[1].cells(name),
            [
                "5",
                "TPDO1",
                "0x185 (predefined)",
                "synchronous, every SYNC (1)",
                "-",
                "-",
                "-",
                "configured",
                "0x6041:00"
            ]
        );
        assert_eq!(rows[0].cells(|_, _| None)[5], "100 ms");
        assert_eq!(rows[0].cells(|_, _| None)[7], "-", "no mapping known");
        assert!(rows[1].source_text(0).unwrap().starts_with("configured by cotui @"));
    }
}
