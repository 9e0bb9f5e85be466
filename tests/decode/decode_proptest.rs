//! Fuzzing the decoder registry: any frame sequence decodes without panicking,
//! every text line is one line, and every JSONL line is valid JSON with the
//! contract fields.

use cotui::analysis::EventTracker;
use cotui::decode::Decoder;
use cotui::frame::{Flags, Frame, Interfaces};
use cotui::od::Dictionary;
use cotui::output::{jsonl, text};
use proptest::prelude::*;

fn frame_strategy() -> impl Strategy<Value = Frame> {
    // Bias ids toward CANopen function codes so every decoder gets exercised.
    let id = prop_oneof![
        (0u32..16, 0u32..128).prop_map(|(f, n)| (f << 7) | n),
        Just(0x7E4u32),
        Just(0x7E5u32),
        0u32..0x2000_0000,
    ];
    (
        id,
        any::<u8>(),
        0u8..=64,
        prop::collection::vec(any::<u8>(), 64),
        any::<u64>(),
    )
        .prop_map(|(id, flags, len, data, ts)| {
            let mut f = Frame {
                id,
                ts_ns: ts,
                ..Frame::default()
            };
            f.flags = Flags(flags & !Flags::FDF);
            if !f.is_ext() {
                f.id &= 0x7FF;
            }
            f.len = if f.is_fd() { len } else { len % 9 };
            f.data[..f.len as usize].copy_from_slice(&data[..f.len as usize]);
            f
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn any_frames_decode_to_one_line_and_valid_json(frames in prop::collection::vec(frame_strategy(), 1..200)) {
        let mut ifaces = Interfaces::default();
        ifaces.intern("can0");
        let mut decoder = Decoder::new(Dictionary::default(), vec![]);
        for (i, f) in frames.iter().enumerate() {
            let d = decoder.decode(f);
            let mut line = Vec::new();
            text::write_line(&mut line, f, &ifaces, &d);
            let line = String::from_utf8(line).expect("UTF-8 line");
            prop_assert_eq!(line.matches('\n').count(), 1);
            let mut j = Vec::new();
            jsonl::write_frame(&mut j, i as u64 + 1, f, &ifaces, &d);
            let v: serde_json::Value = serde_json::from_slice(&j).expect("valid JSON");
            prop_assert_eq!(v["kind"].as_str(), Some(d.kind.as_str()));
            prop_assert_eq!(v["len"].as_u64(), Some(f.len as u64));
        }
        let _ = decoder.finish();
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn any_frames_give_events_as_one_line_and_valid_json(
        frames in prop::collection::vec(frame_strategy(), 1..200),
        ticks in prop::collection::vec(any::<u64>(), 0..5),
    ) {
        let mut decoder = Decoder::new(Dictionary::default(), vec![]);
        let mut events = EventTracker::new(|n| decoder.dictionary(n));
        for f in &frames {
            let d = decoder.decode(f);
            events.frame(f, "can0", &d);
            for t in decoder.take_transactions() {
                events.transaction(&t);
            }
        }
        for t in ticks {
            events.tick(t);
        }
        for e in events.take_events() {
            let mut line = String::new();
            e.write_line(&mut line);
            prop_assert_eq!(line.matches('\n').count(), 1);
            let mut j = Vec::new();
            e.write_json(&mut j);
            let v: serde_json::Value = serde_json::from_slice(&j).expect("valid JSON");
            prop_assert_eq!(v["event"].as_str(), Some(e.what.name()));
            prop_assert!(v["t"].is_number());
            prop_assert_eq!(v["node"].as_u64(), e.node.map(u64::from));
        }
    }
}
