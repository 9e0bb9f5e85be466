//! `cotui explain` and the Detail pane's wire view: a frame's identifier split into
//! function code and node, its data bits by CANopen field with CANopen bit numbers, and
//! the frame on the wire (see [`crate::wire`]) with its stuff bits and figures.

use crate::decode::{Body, Decoded, Kind};
use crate::frame::Frame;
use crate::wire::{Field, Wire, WireError, rebuild};
use serde::Serialize;
use std::ops::Range;

/// A CANopen identifier split as the predefined connection set builds it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Split {
    /// Bits 10..7 of the identifier.
    pub function_code: u8,
    /// What the function code means in the predefined connection set.
    pub function: &'static str,
    /// Bits 6..0 (0: the service of no node, as SYNC or NMT).
    pub node: u8,
    /// `0x185 = 3 x 0x80 + 5`.
    pub text: String,
}

/// The split of an 11-bit identifier (None for a 29-bit one, which CANopen does not use,
/// and for an error frame, whose identifier is an error class).
pub fn split(frame: &Frame) -> Option<Split> {
    if frame.is_ext() || frame.is_err() || frame.id > 0x7FF {
        return None;
    }
    let (fc, node) = ((frame.id >> 7) as u8, (frame.id & 0x7F) as u8);
    let function = match (fc, node) {
        (0, _) => "NMT",
        (1, 0) => "SYNC",
        (1, _) => "EMCY",
        (2, _) => "TIME",
        (3, _) => "TPDO1",
        (4, _) => "RPDO1",
        (5, _) => "TPDO2",
        (6, _) => "RPDO2",
        (7, _) => "TPDO3",
        (8, _) => "RPDO3",
        (9, _) => "TPDO4",
        (10, _) => "RPDO4",
        (11, _) => "SDO server to client",
        (12, _) => "SDO client to server",
        (15, 0x64 | 0x65) => "LSS",
        (14, _) => "NMT error control (heartbeat)",
        _ => "not in the predefined connection set",
    };
    Some(Split {
        function_code: fc,
        function,
        node,
        text: format!("0x{:X} = {fc} x 0x80 + {node}", frame.id),
    })
}

/// The CANopen fields of a payload, as byte ranges with their names.
pub fn data_fields(kind: Kind, payload: &[u8]) -> Vec<(Range<usize>, &'static str)> {
    let cs = payload.first().map_or(0, |b| b >> 5);
    let layout: &[(Range<usize>, &'static str)] = match kind {
        Kind::Nmt => &[(0..1, "command"), (1..2, "node")],
        Kind::Sync => &[(0..1, "counter")],
        Kind::Time => &[(0..4, "ms after midnight"), (4..6, "days since 1984")],
        Kind::Emcy => &[
            (0..2, "error code"),
            (2..3, "error register"),
            (3..8, "manufacturer data"),
        ],
        Kind::Heartbeat => &[(0..1, "state")],
        Kind::Lss => &[(0..1, "command specifier"), (1..8, "data")],
        Kind::Tpdo | Kind::Rpdo => &[(0..64, "PDO data")],
        Kind::SdoRx | Kind::SdoTx => {
            let initiate = match kind {
                Kind::SdoRx => matches!(cs, 1 | 2 | 4),
                _ => matches!(cs, 2..=4),
            };
            if initiate {
                &[(0..1, "command"), (1..3, "index"), (3..4, "subindex"), (4..8, "data")]
            } else {
                &[(0..1, "command"), (1..8, "segment data")]
            }
        }
        Kind::ErrorFrame | Kind::Other => &[(0..64, "data")],
    };
    layout
        .iter()
        .filter(|(r, _)| r.start < payload.len())
        .map(|(r, name)| (r.start..r.end.min(payload.len()), *name))
        .collect()
}

/// A mapped object of a PDO and the CANopen bits of the payload it takes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MappedBits {
    /// Object index.
    pub index: u16,
    /// Subindex.
    pub sub: u8,
    /// `6041 Statusword` (`6041:02 Name` for a subindex, `6041:00` for an unnamed object).
    pub label: String,
    /// CANopen numbers of its last and first bit (`15, 0` for bits 15..0).
    pub canopen_bits: [usize; 2],
}

impl MappedBits {
    fn holds(&self, canopen_bit: usize) -> bool {
        (self.canopen_bits[1]..=self.canopen_bits[0]).contains(&canopen_bit)
    }
}

/// The mapped objects of a PDO the decoder read through a known mapping (profile, EDS or
/// learned), in mapping order; none for another frame or a PDO of unknown mapping.
pub fn pdo_objects(decoded: &Decoded) -> Vec<MappedBits> {
    let Body::Pdo(pdo) = &decoded.body else {
        return Vec::new();
    };
    pdo.signals
        .iter()
        .filter(|s| s.bits > 0)
        .map(|s| {
            let unnamed = format!("0x{:04X}:{:02X}", s.index, s.sub);
            let label = match (s.sub, s.name == unnamed) {
                (_, true) => format!("{:04X}:{:02X}", s.index, s.sub),
                (0, false) => format!("{:04X} {}", s.index, s.name),
                (sub, false) => format!("{:04X}:{sub:02X} {}", s.index, s.name),
            };
            let first = usize::from(s.bit);
            MappedBits {
                index: s.index,
                sub: s.sub,
                label,
                canopen_bits: [first + usize::from(s.bits) - 1, first],
            }
        })
        .collect()
}

/// One data byte as `explain` shows it.
#[derive(Clone, Debug, Serialize)]
pub struct DataByte {
    /// Its position in the payload.
    pub byte: usize,
    /// Its value.
    pub value: u8,
    /// Its bits as sent, MSB first.
    pub bits: String,
    /// CANopen numbers of its first and last bit as sent (`8 x byte + 7` down to `8 x byte`).
    pub canopen_bits: [usize; 2],
    /// The CANopen field it belongs to: for a PDO of known mapping the objects whose bits
    /// it holds (`6041 Statusword`, several joined by ` + `).
    pub field: String,
}

/// The payload byte by byte with its fields (`objects`: a PDO's, see [`pdo_objects`]).
pub fn data_bytes(kind: Kind, payload: &[u8], objects: &[MappedBits]) -> Vec<DataByte> {
    let fields = data_fields(kind, payload);
    payload
        .iter()
        .enumerate()
        .map(|(i, &b)| {
            let held: Vec<&str> = objects
                .iter()
                .filter(|o| (8 * i..8 * i + 8).any(|bit| o.holds(bit)))
                .map(|o| o.label.as_str())
                .collect();
            let field = if held.is_empty() {
                fields
                    .iter()
                    .find(|(r, _)| r.contains(&i))
                    .map_or("data", |(_, n)| *n)
                    .to_string()
            } else {
                held.join(" + ")
            };
            DataByte {
                byte: i,
                value: b,
                bits: format!("{b:08b}"),
                canopen_bits: [8 * i + 7, 8 * i],
                field,
            }
        })
        .collect()
}

/// A run of wire bits of one field (and, in a PDO's data, of one mapped object).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WireGroup {
    /// The field.
    pub field: Field,
    /// Data bits: the index in `objects` of the object they belong to.
    pub object: Option<usize>,
    /// The bits as `0`/`1`, stuff bits in brackets: `00000[1]0`.
    pub bits: String,
}

/// The wire bits field by field, in order; the data bits also by mapped object (`objects`
/// of [`pdo_objects`]; a data bit is sent MSB first, so the k-th data bit on the wire is
/// CANopen bit `8 x (k / 8) + 7 - k % 8`). A stuff bit goes with the bit before it.
pub fn wire_groups(wire: &Wire, objects: &[MappedBits]) -> Vec<WireGroup> {
    let mut groups: Vec<WireGroup> = Vec::new();
    let mut data_bit = 0usize;
    for b in &wire.bits {
        let c = if b.level { '1' } else { '0' };
        let text = if b.stuff { format!("[{c}]") } else { c.to_string() };
        let last = groups.last_mut().filter(|g| g.field == b.field);
        let object = match (b.field, b.stuff) {
            (Field::Data, false) => {
                let canopen = 8 * (data_bit / 8) + 7 - data_bit % 8;
                data_bit += 1;
                objects.iter().position(|o| o.holds(canopen))
            }
            _ => last.as_ref().and_then(|g| g.object),
        };
        match last {
            Some(g) if g.object == object => g.bits.push_str(&text),
            _ => groups.push(WireGroup {
                field: b.field,
                object,
                bits: text,
            }),
        }
    }
    groups
}

/// The figures line: `79 bits (+ 3 intermission), 3 stuff bits, CRC-15 0x47DC, 158.0 µs at 500 kbit/s`.
pub fn figures_text(wire: &Wire, bitrate: u64) -> String {
    let f = &wire.figures;
    format!(
        "{} bits (+ {} intermission), {} stuff bit{}, CRC-{} 0x{:0w$X}, {:.1} µs at {} kbit/s",
        f.bits,
        crate::wire::INTERMISSION,
        f.stuff_bits,
        if f.stuff_bits == 1 { "" } else { "s" },
        f.crc_bits,
        f.crc,
        f.time_us(bitrate),
        bitrate as f64 / 1000.0,
        w = usize::from(f.crc_bits).div_ceil(4),
    )
}

/// Everything `explain` says about one frame.
pub struct Explained<'a> {
    /// The frame as given.
    pub text: &'a str,
    /// The frame.
    pub frame: &'a Frame,
    /// The decoder's reading of it.
    pub decoded: &'a Decoded,
    /// The bit rate, and whether it was assumed.
    pub bitrate: u64,
    /// True when nobody gave the bit rate.
    pub assumed: bool,
}

impl Explained<'_> {
    /// The wire rebuild (an error frame or an impossible one: why not).
    fn wire(&self) -> Result<Wire, WireError> {
        rebuild(self.frame)
    }

    /// The text report.
    pub fn to_text(&self) -> String {
        let f = self.frame;
        let mut s = format!("{}\n", self.text);
        match split(f) {
            Some(sp) => s.push_str(&format!(
                "  identifier  {}: function code {} ({}), node {}\n",
                sp.text, sp.function_code, sp.function, sp.node
            )),
            None if f.is_err() => s.push_str(&format!("  identifier  error class 0x{:X}\n", f.id)),
            None => s.push_str(&format!("  identifier  0x{:X} (29-bit: no CANopen split)\n", f.id)),
        }
        s.push_str(&format!("  CANopen     {}\n", self.decoded.label));
        if let Some(m) = &self.decoded.malformed {
            s.push_str(&format!("  malformed   {m}\n"));
        }
        let objects = pdo_objects(self.decoded);
        let bytes = data_bytes(self.decoded.kind, f.payload(), &objects);
        if !bytes.is_empty() {
            s.push_str("  data bits (as sent, MSB first; CANopen bit numbers)\n");
        }
        for b in &bytes {
            let numbers = format!("{}..{}", b.canopen_bits[0], b.canopen_bits[1]);
            s.push_str(&format!(
                "    byte {:<2} 0x{:02X}  {}  bits {numbers:<8} {}\n",
                b.byte, b.value, b.bits, b.field
            ));
        }
        if !objects.is_empty() {
            s.push_str("  PDO objects (CANopen bit numbers)\n");
        }
        for o in &objects {
            let numbers = format!("{}..{}", o.canopen_bits[0], o.canopen_bits[1]);
            s.push_str(&format!("    bits {numbers:<8} {}\n", o.label));
        }
        match self.wire() {
            Ok(w) => {
                s.push_str("  on the wire (stuff bits in [ ])\n");
                for g in wire_groups(&w, &objects) {
                    match g.object {
                        Some(i) => s.push_str(&format!(
                            "    {:<14} {}  {}\n",
                            g.field.as_str(),
                            g.bits,
                            objects[i].label
                        )),
                        None => s.push_str(&format!("    {:<14} {}\n", g.field.as_str(), g.bits)),
                    }
                }
                let assumed = if self.assumed { " (assumed)" } else { "" };
                s.push_str(&format!("  figures     {}{assumed}\n", figures_text(&w, self.bitrate)));
            }
            Err(e) => s.push_str(&format!("  on the wire  none: {e}\n")),
        }
        s
    }

    /// The JSON record.
    pub fn to_json(&self) -> ExplainJson {
        let wire = self.wire();
        let objects = pdo_objects(self.decoded);
        let (bits, stuff_bits, crc, crc_bits, time_us, groups, why) = match &wire {
            Ok(w) => (
                Some(w.figures.bits),
                Some(w.figures.stuff_bits),
                Some(format!("0x{:X}", w.figures.crc)),
                Some(w.figures.crc_bits),
                Some((w.figures.time_us(self.bitrate) * 1000.0).round() / 1000.0),
                wire_groups(w, &objects)
                    .into_iter()
                    .map(|g| WireField {
                        field: g.field.as_str(),
                        object: g.object.map(|i| objects[i].label.clone()),
                        bits: g.bits,
                    })
                    .collect(),
                None,
            ),
            Err(e) => (None, None, None, None, None, Vec::new(), Some(e.to_string())),
        };
        ExplainJson {
            frame: self.text.to_string(),
            id: self.frame.id,
            ext: self.frame.is_ext(),
            split: split(self.frame),
            kind: self.decoded.kind.as_str(),
            node: self.decoded.node,
            canopen: self.decoded.label.clone(),
            malformed: self.decoded.malformed.clone(),
            data: data_bytes(self.decoded.kind, self.frame.payload(), &objects),
            objects,
            wire: groups,
            no_wire: why,
            bits,
            intermission: crate::wire::INTERMISSION,
            stuff_bits,
            crc,
            crc_bits,
            bitrate: self.bitrate,
            bitrate_source: if self.assumed { "assumed" } else { "option" },
            time_us,
        }
    }
}

/// One field of the wire bits in JSON.
#[derive(Clone, Debug, Serialize)]
pub struct WireField {
    /// Field name (`SOF`, `ID`, `DLC`, `CRC`...).
    pub field: &'static str,
    /// Data bits of a PDO of known mapping: the object they belong to (`6041 Statusword`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    /// Its bits as sent, stuff bits in brackets.
    pub bits: String,
}

/// The JSON record of `cotui explain --format jsonl` (one per frame).
#[derive(Clone, Debug, Serialize)]
pub struct ExplainJson {
    /// The frame as given.
    pub frame: String,
    /// Identifier.
    pub id: u32,
    /// 29-bit identifier.
    pub ext: bool,
    /// Function code and node (null for 29 bits).
    pub split: Option<Split>,
    /// The decoder's kind.
    pub kind: &'static str,
    /// The decoder's node.
    pub node: Option<u8>,
    /// The decoder's label.
    pub canopen: String,
    /// What breaks the kind's rules, if anything.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub malformed: Option<String>,
    /// The data bytes with bits and fields.
    pub data: Vec<DataByte>,
    /// A PDO of known mapping: its mapped objects and their CANopen bits.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub objects: Vec<MappedBits>,
    /// The wire bits field by field.
    pub wire: Vec<WireField>,
    /// Why the frame has no wire form (an error frame).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_wire: Option<String>,
    /// Bits SOF..EOF.
    pub bits: Option<u32>,
    /// The intermission after it (3).
    pub intermission: u32,
    /// Stuff bits.
    pub stuff_bits: Option<u32>,
    /// CRC in hex.
    pub crc: Option<String>,
    /// CRC width.
    pub crc_bits: Option<u8>,
    /// Bit rate of `time_us`.
    pub bitrate: u64,
    /// `option` or `assumed`.
    pub bitrate_source: &'static str,
    /// Microseconds SOF..EOF at `bitrate`.
    pub time_us: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_of_predefined_identifiers() {
        let s = split(&Frame::classic(0x185, &[])).unwrap();
        assert_eq!(s.text, "0x185 = 3 x 0x80 + 5");
        assert_eq!((s.function, s.node), ("TPDO1", 5));
        assert_eq!(split(&Frame::classic(0x80, &[])).unwrap().function, "SYNC");
        assert_eq!(split(&Frame::classic(0x7E5, &[])).unwrap().function, "LSS");
        assert_eq!(split(&Frame::classic(0x1234_5678, &[])), None);
    }

    /// A bit-packed mapping: object A in CANopen bits 0..3, B in bits 4..15. Byte 0 goes
    /// out MSB first, so its wire bits are B's (7..4) then A's (3..0), then byte 1 (B's).
    #[test]
    fn packed_pdo_bits_on_the_wire_go_by_object_in_the_order_sent() {
        let object = |label: &str, canopen_bits| MappedBits {
            index: 0x2000,
            sub: 0,
            label: label.into(),
            canopen_bits,
        };
        let objects = [object("A", [3, 0]), object("B", [15, 4])];
        let wire = rebuild(&Frame::classic(0x181, &[0x5A, 0xC3])).unwrap();
        let data: Vec<(&str, String)> = wire_groups(&wire, &objects)
            .into_iter()
            .filter(|g| g.field == Field::Data)
            .map(|g| {
                (
                    objects[g.object.unwrap()].label.as_str(),
                    g.bits.replace(['[', ']'], ""),
                )
            })
            .collect();
        assert_eq!(
            data,
            [("B", "0101".into()), ("A", "1010".into()), ("B", "11000011".into())]
        );
        let bytes = data_bytes(Kind::Tpdo, &[0x5A, 0xC3], &objects);
        assert_eq!((bytes[0].field.as_str(), bytes[1].field.as_str()), ("A + B", "B"));
        // Without a mapping the data stays one field.
        let plain = wire_groups(&wire, &[]);
        assert_eq!(plain.iter().filter(|g| g.field == Field::Data).count(), 1);
        assert_eq!(data_bytes(Kind::Tpdo, &[0x5A], &[])[0].field, "PDO data");
    }

    #[test]
    fn sdo_fields_follow_the_command() {
        let init = data_fields(Kind::SdoRx, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]);
        assert_eq!(
            init.iter().map(|(_, n)| *n).collect::<Vec<_>>(),
            ["command", "index", "subindex", "data"]
        );
        let seg = data_fields(Kind::SdoTx, &[0x00, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(seg[1], (1..8, "segment data"));
        assert_eq!(data_bytes(Kind::Heartbeat, &[0x05], &[])[0].canopen_bits, [7, 0]);
    }
}
