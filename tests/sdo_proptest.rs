//! Random SDO traffic never panics the tracker, and every frame belongs to at most one transaction.

use cotui::decode::sdo::SdoTracker;
use cotui::od::Dictionary;
use proptest::prelude::*;
use std::collections::HashSet;

/// A payload whose first byte is usually a real command byte, so the tracker goes deep.
fn payload() -> impl Strategy<Value = Vec<u8>> {
    let cmd = prop_oneof![
        Just(0x00u8),
        Just(0x10),
        Just(0x0B),
        Just(0x21),
        Just(0x2B),
        Just(0x41),
        Just(0x40),
        Just(0x4B),
        Just(0x60),
        Just(0x70),
        Just(0x80),
        Just(0xA0),
        Just(0xA1),
        Just(0xA2),
        Just(0xA3),
        Just(0xA4),
        Just(0xC1),
        Just(0xC2),
        Just(0xC6),
        Just(0x81),
        Just(0x01),
        Just(0x02),
        any::<u8>(),
    ];
    (cmd, prop::collection::vec(any::<u8>(), 0..9)).prop_map(|(c, mut rest)| {
        if !rest.is_empty() {
            rest[0] = c;
        }
        rest
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn random_frames_never_panic(frames in prop::collection::vec((1u8..4, any::<bool>(), payload()), 0..200)) {
        let dict = Dictionary::default();
        let mut t = SdoTracker::new();
        let mut txns = Vec::new();
        for (i, (node, c2s, bytes)) in frames.iter().enumerate() {
            let f = t.on_frame(i as u64, i as u64 * 1000, *node, *c2s, bytes, &dict);
            prop_assert!(!f.label().is_empty());
            prop_assert!(f.to_json()["cs"].is_string());
            txns.extend(t.take_completed());
        }
        txns.extend(t.finish());
        let mut seen = HashSet::new();
        for tx in &txns {
            prop_assert!(!tx.label(&dict).is_empty());
            prop_assert!(tx.to_json(&dict)["outcome"].is_string());
            prop_assert!(tx.start_ns <= tx.end_ns);
            for s in &tx.frames {
                prop_assert!(seen.insert(*s), "frame {} in two transactions", s);
                prop_assert!((*s as usize) < frames.len());
            }
        }
    }
}
