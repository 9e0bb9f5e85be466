//! The last value seen on the bus per node (of its interface) and object: every completed SDO transfer
//! (upload or download, cotui's own included: they come back as TX/RX frames) and every
//! mapped PDO signal. What the Objects pane shows as "last value" and its age.
//!
//! Pure: fed from the decoded stream with the frames' times; the text is made through the
//! node's dictionary when asked (only for the rows shown), so taking a value in costs no
//! formatting.

use crate::decode::pdo::Pdo;
use crate::frame::NodeKey;
use crate::od::{Dictionary, Value};
use crate::sdo::{Outcome, Transaction, TransferDirection};
use std::collections::BTreeMap;

/// An object of a node: (node of its interface, index, sub). Node 5 of can0 and node 5 of
/// can1 are two nodes.
pub type ObjectKey = (NodeKey, u16, u8);

/// How a value was seen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Via {
    /// Read from the node (SDO upload).
    Upload,
    /// Written to the node (SDO download).
    Download,
    /// A signal of a mapped PDO.
    Pdo,
}

impl Via {
    /// `read`, `written` or `pdo`.
    pub fn as_str(self) -> &'static str {
        match self {
            Via::Upload => "read",
            Via::Download => "written",
            Via::Pdo => "pdo",
        }
    }
}

/// A value seen on the bus.
#[derive(Clone, Debug, PartialEq)]
pub struct Seen {
    /// Typed through the node's dictionary; [`Value::Bytes`] when it does not know the object.
    pub value: Value,
    /// When (the frame time that completed it, ns).
    pub ts_ns: u64,
    /// How.
    pub via: Via,
    /// The node's mode of operation then (names controlword/statusword bits).
    pub mode: Option<i8>,
}

/// A transfer of the object that failed (aborted by a side or broken).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failed {
    /// What went wrong: `abort 06020000: Object does not exist in the object dictionary`.
    pub text: String,
    /// When (ns).
    pub ts_ns: u64,
}

/// What is known of one object.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Entry {
    /// The last value seen.
    pub last: Option<Seen>,
    /// The last failed transfer, when it came after the last value.
    pub failed: Option<Failed>,
}

impl Entry {
    /// The value's text through `dict` (enum text, scaled with its unit, ...), if one was seen.
    pub fn text(&self, dict: &Dictionary, index: u16, sub: u8) -> Option<String> {
        let s = self.last.as_ref()?;
        Some(match &s.value {
            Value::Bytes(b) => crate::decode::sdo::value::view(dict, index, sub, b).text,
            v => crate::decode::value_text::object_text(dict, index, sub, v, s.mode),
        })
    }
}

/// The last values of every node's objects.
#[derive(Clone, Debug, Default)]
pub struct Values {
    map: BTreeMap<ObjectKey, Entry>,
}

impl Values {
    /// What is known of (node, index, sub).
    pub fn get(&self, node: NodeKey, index: u16, sub: u8) -> Option<&Entry> {
        self.map.get(&(node, index, sub))
    }

    /// Every object of `node` something was seen of, in index order.
    pub fn node(&self, node: NodeKey) -> impl Iterator<Item = ((u16, u8), &Entry)> {
        self.map
            .range((node, 0, 0)..=(node, u16::MAX, u8::MAX))
            .map(|((_, i, s), e)| ((*i, *s), e))
    }

    /// Number of objects with something seen.
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// True when nothing was seen.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }

    /// Takes a completed SDO transfer: its value (typed through `dict`, the node's
    /// dictionary) when it succeeded, what went wrong when it failed. Transfers still
    /// running, partial ones (object unknown) and empty reads are left out.
    pub fn transaction(&mut self, t: &Transaction, dict: &Dictionary) {
        if t.is_partial() || t.outcome == Outcome::Incomplete {
            return;
        }
        let e = self.map.entry((t.key(), t.index, t.sub)).or_default();
        if !t.is_ok() {
            let text = match &t.outcome {
                Outcome::Aborted { code, text, by } => {
                    let by = if *by == crate::sdo::codec::Side::Client {
                        " by the client"
                    } else {
                        ""
                    };
                    format!("abort {code:08X}{by}: {text}")
                }
                Outcome::ProtocolError(m) => format!("protocol error: {m}"),
                _ => t
                    .problems
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(", "),
            };
            e.failed = Some(Failed { text, ts_ns: t.end_ns });
            return;
        }
        if t.data.is_empty() || t.dropped > 0 {
            return;
        }
        let value = match dict.object(t.index, t.sub) {
            Some(o) => {
                let take = o.data_type.size().map_or(t.data.len(), |n| n.min(t.data.len()));
                o.data_type.decode(&t.data[..take])
            }
            None => Value::Bytes(t.data.clone()),
        };
        let via = match t.direction {
            TransferDirection::Upload => Via::Upload,
            TransferDirection::Download => Via::Download,
        };
        e.last = Some(Seen {
            value,
            ts_ns: t.end_ns,
            via,
            mode: t.mode,
        });
        e.failed = None;
    }

    /// Takes the signals of a PDO of `node` received at `ts_ns` (mode: the node's mode of
    /// operation then).
    pub fn pdo(&mut self, node: NodeKey, ts_ns: u64, p: &Pdo, mode: Option<i8>) {
        for s in &p.signals {
            let e = self.map.entry((node, s.index, s.sub)).or_default();
            match &mut e.last {
                // A PDO repeats its signals: change the value in place (no new allocation).
                Some(seen) if seen.via == Via::Pdo => {
                    if seen.value != s.value {
                        seen.value.clone_from(&s.value);
                    }
                    seen.ts_ns = ts_ns;
                    seen.mode = mode;
                }
                last => {
                    *last = Some(Seen {
                        value: s.value.clone(),
                        ts_ns,
                        via: Via::Pdo,
                        mode,
                    })
                }
            }
            e.failed = None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::{Body, Decoder};
    use crate::frame::Frame;
    use crate::od::bind::Bindings;

    /// Node 2 of the first interface.
    const N2: NodeKey = NodeKey { iface: 0, node: 2 };

    /// Decodes `frames` (id, data, ms) for a node bound to the CiA 402 profile and feeds
    /// the store as the trace does.
    fn feed(frames: &[(u32, &[u8], u64)]) -> (Values, Decoder) {
        let read = |p: &std::path::Path| std::fs::read(p);
        let b = Bindings::from_args(&["2=cia402".to_string()], &[], &read).unwrap();
        let mut dec = Decoder::from_bindings(&b);
        let mut v = Values::default();
        for (i, (id, data, ms)) in frames.iter().enumerate() {
            let mut f = Frame::classic(*id, data);
            f.ts_ns = ms * 1_000_000;
            dec.set_seq(i as u64);
            let d = dec.decode(&f);
            if let (Body::Pdo(p), Some(n)) = (&d.body, d.node) {
                let key = NodeKey::of(&f, n);
                v.pdo(key, f.ts_ns, p, dec.mode(key));
            }
            for t in dec.take_transactions() {
                v.transaction(&t, dec.dictionary(t.node));
            }
        }
        (v, dec)
    }

    #[test]
    fn reads_writes_and_pdo_signals_are_kept_typed_with_their_time_and_text() {
        let (v, dec) = feed(&[
            // Read 0x6061 (modes of operation display) = 3: profile velocity.
            (0x602, &[0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0], 1),
            (0x582, &[0x4F, 0x61, 0x60, 0x00, 0x03, 0, 0, 0], 2),
            // Write 0x1017 = 100 ms.
            (0x602, &[0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0], 3),
            (0x582, &[0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0], 4),
            // Map TPDO1 of node 2 to the statusword (the decoder learns it from the writes).
            (0x602, &[0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0], 4),
            (0x582, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0], 4),
            (0x602, &[0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60], 4),
            (0x582, &[0x60, 0x00, 0x1A, 0x01, 0, 0, 0, 0], 4),
            (0x602, &[0x2F, 0x00, 0x1A, 0x00, 0x01, 0, 0, 0], 4),
            (0x582, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0], 4),
            (0x182, &[0x37, 0x02], 5),
            (0x182, &[0x33, 0x02], 9),
            // An unknown object read: kept as bytes.
            (0x602, &[0x40, 0x00, 0x50, 0x01, 0, 0, 0, 0], 10),
            (0x582, &[0x43, 0x00, 0x50, 0x01, 0xEF, 0xBE, 0xAD, 0xDE], 11),
        ]);
        let dict = dec.dictionary(2);
        let mode = v.get(N2, 0x6061, 0).unwrap();
        let seen = mode.last.as_ref().unwrap();
        assert_eq!(
            (seen.value.clone(), seen.ts_ns, seen.via),
            (Value::Signed(3), 2_000_000, Via::Upload)
        );
        assert_eq!(mode.text(dict, 0x6061, 0).as_deref(), Some("3 (Profile velocity)"));
        let hb = v.get(N2, 0x1017, 0).unwrap().last.as_ref().unwrap();
        assert_eq!((hb.value.clone(), hb.via), (Value::Unsigned(100), Via::Download));
        let sw = v.get(N2, 0x6041, 0).unwrap();
        let s = sw.last.as_ref().unwrap();
        assert_eq!(
            (s.value.clone(), s.ts_ns, s.via),
            (Value::Unsigned(0x0233), 9_000_000, Via::Pdo)
        );
        assert!(
            sw.text(dict, 0x6041, 0).unwrap().contains("Switched on"),
            "{:?}",
            sw.text(dict, 0x6041, 0)
        );
        let raw = v.get(N2, 0x5000, 1).unwrap();
        assert_eq!(
            raw.last.as_ref().unwrap().value,
            Value::Bytes(vec![0xEF, 0xBE, 0xAD, 0xDE])
        );
        assert_eq!(raw.text(dict, 0x5000, 1).as_deref(), Some("EF BE AD DE (3735928559)"));
        let keys: Vec<(u16, u8)> = v.node(N2).map(|(k, _)| k).collect();
        assert_eq!(
            keys,
            [
                (0x1017, 0),
                (0x1A00, 0),
                (0x1A00, 1),
                (0x5000, 1),
                (0x6041, 0),
                (0x6061, 0)
            ]
        );
        assert_eq!(v.node(NodeKey::new(0, 3)).count(), 0);
    }

    #[test]
    fn an_abort_is_kept_until_a_value_comes_and_keeps_the_value_before_it() {
        let (v, _) = feed(&[
            (0x602, &[0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0], 1),
            (0x582, &[0x4F, 0x61, 0x60, 0x00, 0x03, 0, 0, 0], 2),
            (0x602, &[0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0], 3),
            (0x582, &[0x80, 0x61, 0x60, 0x00, 0x00, 0x00, 0x00, 0x08], 4),
            (0x602, &[0x40, 0x00, 0x50, 0x00, 0, 0, 0, 0], 5),
            (0x582, &[0x80, 0x00, 0x50, 0x00, 0x00, 0x00, 0x02, 0x06], 6),
        ]);
        let e = v.get(N2, 0x6061, 0).unwrap();
        assert_eq!(e.last.as_ref().map(|s| s.value.clone()), Some(Value::Signed(3)));
        assert_eq!(
            e.failed.as_ref().map(|f| (f.text.as_str(), f.ts_ns)),
            Some(("abort 08000000: General error", 4_000_000))
        );
        let missing = v.get(N2, 0x5000, 0).unwrap();
        assert!(missing.last.is_none());
        assert_eq!(
            missing.failed.as_ref().map(|f| f.text.as_str()),
            Some("abort 06020000: Object does not exist in the object dictionary")
        );
        // A value read afterwards clears the failure.
        let (v, _) = feed(&[
            (0x602, &[0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0], 3),
            (0x582, &[0x80, 0x61, 0x60, 0x00, 0x00, 0x00, 0x00, 0x08], 4),
            (0x602, &[0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0], 5),
            (0x582, &[0x4F, 0x61, 0x60, 0x00, 0x01, 0, 0, 0], 6),
        ]);
        let e = v.get(N2, 0x6061, 0).unwrap();
        assert!(e.failed.is_none());
        assert_eq!(e.last.as_ref().map(|s| s.ts_ns), Some(6_000_000));
    }
}
