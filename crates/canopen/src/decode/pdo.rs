//! PDO payloads decoded into named, typed, scaled signals through the mapping in force.

use crate::od::{DataType, Dictionary, MappedEntry, MappingSource, ObjectInfo, PdoMapping, Value};
use serde::Serialize;

/// One mapped signal taken out of a PDO payload.
#[derive(Clone, Debug, PartialEq)]
pub struct Signal {
    pub index: u16,
    pub sub: u8,
    /// CANopen number of its first bit in the payload (bit 0 is byte 0's LSB).
    pub bit: u16,
    /// Its length in bits.
    pub bits: u8,
    /// Object name from the dictionary (or `0xIIII:SS`).
    pub name: String,
    /// Raw value typed by the object's data type.
    pub value: Value,
    /// Value as shown: enum text, scaled with unit, CiA 402 meaning.
    pub text: String,
}

/// A decoded PDO.
#[derive(Clone, Debug, PartialEq)]
pub struct Pdo {
    /// PDO number (1-based).
    pub num: u16,
    /// True for TPDO (device transmits), false for RPDO.
    pub transmit: bool,
    /// Signals; empty when no mapping is known.
    pub signals: Vec<Signal>,
    /// Where the mapping came from, when one was used.
    pub source: Option<MappingSource>,
}

impl Pdo {
    /// One-line label for `node`.
    pub fn label(&self, node: u8, payload: &[u8]) -> String {
        let mut s = String::with_capacity(64);
        self.write_label(&mut s, node, payload);
        s
    }

    /// Appends [`Pdo::label`] to `s`.
    pub fn write_label(&self, s: &mut String, node: u8, payload: &[u8]) {
        // `TPDO1 node 1: ` and, without signals, a classic payload: composed on the stack
        // and appended at once (the hot path of text and JSONL output). Nothing follows
        // `TPDO1 node 1` (no signal, no data byte): no colon.
        let mut buf = [b' '; 48];
        buf[..4].copy_from_slice(if self.transmit { b"TPDO" } else { b"RPDO" });
        let mut n = 4 + decimal_into(&mut buf[4..], self.num);
        buf[n..n + 6].copy_from_slice(b" node ");
        n += 6;
        n += decimal_into(&mut buf[n..], node.into());
        if !self.signals.is_empty() || !payload.is_empty() {
            buf[n] = b':';
            n += 2;
        }
        if self.signals.is_empty() && payload.len() <= 8 {
            for (i, b) in payload.iter().enumerate() {
                buf[n + 3 * i] = HEX[(b >> 4) as usize];
                buf[n + 3 * i + 1] = HEX[(b & 15) as usize];
            }
            n += (3 * payload.len()).saturating_sub(1);
        }
        // Only ASCII digits, letters and punctuation were written.
        crate::frame::hex::push_ascii(s, &buf[..n]);
        if self.signals.is_empty() && payload.len() > 8 {
            crate::frame::hex::push_spaced(s, payload);
        }
        for (i, sig) in self.signals.iter().enumerate() {
            if i > 0 {
                s.push_str(", ");
            }
            s.push_str(&sig.name);
            s.push('=');
            s.push_str(&sig.text);
        }
    }

    /// The kind-specific JSON object.
    pub fn to_json(&self) -> PdoJson<'_> {
        PdoJson {
            mapping_source: self.source.as_ref().map(source_text),
            num: self.num,
            signals: self
                .signals
                .iter()
                .map(|s| SignalJson {
                    index: s.index,
                    name: &s.name,
                    sub: s.sub,
                    text: &s.text,
                    value: &s.value,
                })
                .collect(),
        }
    }
}

/// Upper-case hex digits.
const HEX: &[u8; 16] = b"0123456789ABCDEF";

/// Writes `v` in decimal at the start of `out` (at least five bytes); returns the digits written.
fn decimal_into(out: &mut [u8], v: u16) -> usize {
    let digits = v.checked_ilog10().unwrap_or(0) as usize + 1;
    let mut v = v;
    for d in out[..digits].iter_mut().rev() {
        *d = b'0' + (v % 10) as u8;
        v /= 10;
    }
    digits
}

/// The `pdo` object of a JSONL frame record (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct PdoJson<'a> {
    /// Where the mapping came from ([`source_text`]), `null` when none is known.
    pub mapping_source: Option<String>,
    pub num: u16,
    /// Empty when no mapping is known.
    pub signals: Vec<SignalJson<'a>>,
}

/// One signal of [`PdoJson`] (fields in key order).
#[derive(Clone, Debug, Serialize)]
pub struct SignalJson<'a> {
    pub index: u16,
    pub name: &'a str,
    pub sub: u8,
    pub text: &'a str,
    /// The raw typed value: a number, a string, or hex for bytes.
    pub value: &'a Value,
}

/// Short text of a mapping source: `profile syntron-ds`, `eds drive.eds`, `sniffed @ 12.345678 s`
/// (learned from another client's writes), `configured by cotui @ ...`, `read from node @ ...`.
pub fn source_text(source: &MappingSource) -> String {
    source_text_since(source, 0)
}

/// [`source_text`] with its time counted from `origin_ns` (a trace's first frame, as the
/// trace's time column counts), not from the epoch.
pub fn source_text_since(source: &MappingSource, origin_ns: u64) -> String {
    let s = |ts_ns: &u64| ts_ns.saturating_sub(origin_ns) as f64 / 1e9;
    match source {
        MappingSource::Profile(p) => format!("profile {p}"),
        MappingSource::Eds(f) => format!("eds {f}"),
        MappingSource::Sniffed { ts_ns } => format!("sniffed @ {:.6} s", s(ts_ns)),
        MappingSource::Configured { ts_ns } => format!("configured by cotui @ {:.6} s", s(ts_ns)),
        MappingSource::ReadFromNode { ts_ns } => format!("read from node @ {:.6} s", s(ts_ns)),
    }
}

/// Reads `bits` bits starting at bit `start` (little-endian, LSB first) from `data`.
fn extract_bits(data: &[u8], start: usize, bits: usize) -> u64 {
    let mut v = 0u64;
    for i in 0..bits.min(64) {
        let bit = start + i;
        if data[bit / 8] >> (bit % 8) & 1 != 0 {
            v |= 1 << i;
        }
    }
    v
}

/// Signals of `payload` through `mapping`; the second value explains a length mismatch.
/// `mode` is the node's mode of operation, for CiA 402 bit names.
pub(crate) fn decode_signals(
    payload: &[u8],
    mapping: &PdoMapping,
    dict: &Dictionary,
    mode: Option<i8>,
) -> (Vec<Signal>, Option<String>) {
    let total: usize = mapping.entries.iter().map(|e| e.bits as usize).sum();
    let mut signals = Vec::with_capacity(mapping.entries.len());
    for_each_mapped(payload, mapping, |pos, e| {
        signals.push(signal(payload, pos, e, dict, mode))
    });
    let problem = if total.div_ceil(8) != payload.len() {
        Some(format!(
            "PDO has {} data bytes, mapping needs {} bits ({} bytes)",
            payload.len(),
            total,
            total.div_ceil(8)
        ))
    } else {
        None
    };
    (signals, problem)
}

/// The values of the signals of `payload` through `mapping`, as [`decode_signals`] takes
/// them, without names or texts (both left empty): for callers that keep numbers.
pub(crate) fn decode_values(payload: &[u8], mapping: &PdoMapping, dict: &Dictionary) -> Vec<Signal> {
    let mut signals = Vec::with_capacity(mapping.entries.len());
    for_each_mapped(payload, mapping, |pos, e| {
        signals.push(Signal {
            index: e.index,
            sub: e.sub,
            bit: pos as u16,
            bits: e.bits,
            name: String::new(),
            value: value(payload, pos, e, dict.object(e.index, e.sub)),
            text: String::new(),
        })
    });
    signals
}

/// Calls `f` with the bit position and entry of every mapped object whose bits `payload`
/// holds, in mapping order; dummy entries (index 0x0001..0x0007, data type "dummies")
/// only pad and are skipped.
fn for_each_mapped(payload: &[u8], mapping: &PdoMapping, mut f: impl FnMut(usize, &MappedEntry)) {
    let available = payload.len() * 8;
    let mut pos = 0usize;
    for e in &mapping.entries {
        let bits = e.bits as usize;
        if pos + bits > available {
            break;
        }
        if !(0x0001..=0x0007).contains(&e.index) {
            f(pos, e);
        }
        pos += bits;
    }
}

fn signal(payload: &[u8], pos: usize, e: &MappedEntry, dict: &Dictionary, mode: Option<i8>) -> Signal {
    let info = dict.object(e.index, e.sub);
    let value = value(payload, pos, e, info);
    let name = dict
        .name(e.index, e.sub)
        .map(str::to_string)
        .unwrap_or_else(|| format!("0x{:04X}:{:02X}", e.index, e.sub));
    let text = super::value_text::object_text_of(dict, info, e.index, e.sub, &value, mode);
    Signal {
        index: e.index,
        sub: e.sub,
        bit: pos as u16,
        bits: e.bits,
        name,
        value,
        text,
    }
}

/// The value of the entry `e` at bit `pos` of `payload`, typed by the object `info`.
fn value(payload: &[u8], pos: usize, e: &MappedEntry, info: Option<&ObjectInfo>) -> Value {
    let bits = e.bits as usize;
    if pos.is_multiple_of(8) && bits.is_multiple_of(8) {
        let bytes = &payload[pos / 8..(pos + bits) / 8];
        match info.map(|i| i.data_type) {
            Some(dt) if dt.size().is_none_or(|s| s * 8 == bits) => dt.decode(bytes),
            _ => DataType::U64.decode(bytes),
        }
    } else {
        let raw = extract_bits(payload, pos, bits);
        match info.map(|i| i.data_type) {
            Some(DataType::Boolean) => Value::Bool(raw != 0),
            _ => Value::Unsigned(raw),
        }
    }
}

/// A mapping entry from its 32-bit object value (index << 16 | sub << 8 | bits).
pub fn entry_from_u32(v: u32) -> MappedEntry {
    MappedEntry {
        index: (v >> 16) as u16,
        sub: (v >> 8) as u8,
        bits: v as u8,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::{ObjectInfo, Profile};
    use serde_json::json;
    use std::sync::Arc;

    fn dict() -> Dictionary {
        let mut p = Profile {
            name: "test".into(),
            ..Profile::default()
        };
        p.objects.insert(
            (0x6041, 0),
            ObjectInfo {
                name: "Statusword".into(),
                data_type: DataType::U16,
                ..Default::default()
            },
        );
        p.objects.insert(
            (0x606C, 0),
            ObjectInfo {
                name: "Velocity actual value".into(),
                data_type: DataType::I32,
                unit: Some("rpm".into()),
                scale: Some(0.1),
                ..Default::default()
            },
        );
        Dictionary::new(vec![Arc::new(p)])
    }

    fn mapping(entries: &[u32]) -> PdoMapping {
        PdoMapping {
            cob_id: None,
            entries: entries.iter().map(|v| entry_from_u32(*v)).collect(),
            source: MappingSource::Profile("test".into()),
        }
    }

    #[test]
    fn typed_scaled_signals() {
        let m = mapping(&[0x6041_0010, 0x606C_0020]);
        let payload = [0x37, 0x02, 0x98, 0x3A, 0x00, 0x00];
        let (s, problem) = decode_signals(&payload, &m, &dict(), None);
        assert_eq!(problem, None);
        assert_eq!(
            s[0].text,
            "0x0237 (Operation enabled [ready to switch on, switched on, operation enabled, voltage enabled, quick stop, remote])"
        );
        assert_eq!(s[1].value, Value::Signed(15000));
        assert_eq!(s[1].text, "1500 rpm");
        let pdo = Pdo {
            num: 1,
            transmit: true,
            signals: s,
            source: Some(m.source.clone()),
        };
        assert!(
            pdo.label(2, &payload)
                .starts_with("TPDO1 node 2: Statusword=0x0237 (Operation enabled")
        );
        assert_eq!(
            serde_json::to_value(pdo.to_json()).unwrap()["signals"][1]["value"],
            15000
        );
        assert_eq!(
            serde_json::to_value(pdo.to_json()).unwrap()["mapping_source"],
            "profile test"
        );
    }

    #[test]
    fn unknown_objects_bit_fields_and_length_mismatch() {
        let m = mapping(&[0x2000_0101, 0x2000_0207, 0x2001_0010]);
        let (s, problem) = decode_signals(&[0x03, 0x34, 0x12], &m, &dict(), None);
        assert_eq!(s.len(), 3);
        assert_eq!(s[0].value, Value::Unsigned(1));
        assert_eq!(s[1].value, Value::Unsigned(1));
        assert_eq!(s[2].name, "0x2001:00");
        assert_eq!(s[2].value, Value::Unsigned(0x1234));
        assert_eq!(problem, None);
        let (s, problem) = decode_signals(&[0x03], &m, &dict(), None);
        assert_eq!(s.len(), 2, "signals that fit are still shown");
        assert!(problem.unwrap().contains("1 data bytes"));
    }

    #[test]
    fn empty_payload_without_mapping_is_raw() {
        let pdo = Pdo {
            num: 2,
            transmit: false,
            signals: vec![],
            source: None,
        };
        assert_eq!(pdo.label(3, &[1, 2]), "RPDO2 node 3: 01 02");
        assert_eq!(pdo.label(34, &[]), "RPDO2 node 34", "nothing follows: no colon");
        assert_eq!(serde_json::to_value(pdo.to_json()).unwrap()["signals"], json!([]));
    }
}
