//! The socketcand line parser (`cotui::bus::socketcand::wire`) on arbitrary input: the
//! splitter never panics and never holds more than one element's bound, the request and
//! reply parsers never panic, and every frame the server writes reads back as the same
//! frame (and every `< send >` the client writes as the same request), CAN FD ones
//! (`< fdframe >`, `< fdsend >`) included.

use cotui::bus::socketcand::wire::{self, MAX_ELEMENT, Reply, Request, Splitter};
use cotui::frame::{Flags, Frame};
use proptest::prelude::*;

/// Pieces that look like socketcand traffic, to reach deeper than random bytes do.
fn piece() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        Just(b"<".to_vec()),
        Just(b">".to_vec()),
        Just(b" ".to_vec()),
        "(open|rawmode|bcmmode|echo|send|subscribe|unsubscribe|frame|fdframe|fdsend|error|hi|ok|add|filter|cotui_send_policy)"
            .prop_map(String::into_bytes),
        "[0-9A-Fa-f]{1,9}".prop_map(String::into_bytes),
        "[0-9]{1,12}\\.[0-9]{0,10}".prop_map(String::into_bytes),
        proptest::collection::vec(any::<u8>(), 0..12),
        (0usize..3).prop_map(|n| vec![b'x'; n * MAX_ELEMENT]),
    ]
}

fn classic() -> impl Strategy<Value = Frame> {
    (
        any::<bool>(),
        any::<u32>(),
        proptest::collection::vec(any::<u8>(), 0..=8),
        any::<u64>(),
    )
        .prop_map(|(ext, id, data, ts)| {
            let id = if ext { id & 0x1FFF_FFFF } else { id & 0x7FF };
            let mut f = Frame::classic(id, &data);
            f.flags.set(Flags::EXT, ext);
            // The protocol carries microseconds.
            f.ts_ns = (ts % 4_000_000_000_000_000) / 1000 * 1000;
            f
        })
}

/// A CAN FD frame of one of the FD lengths, with any of BRS, ESI, FDF.
fn fd() -> impl Strategy<Value = Frame> {
    (
        classic(),
        proptest::sample::select(vec![0usize, 1, 5, 8, 12, 16, 20, 24, 32, 48, 64]),
        any::<u8>(),
        any::<u8>(),
    )
        .prop_map(|(mut f, len, fill, flags)| {
            f.flags.set(Flags::FD, true);
            f.flags.set(Flags::BRS, flags & 1 != 0);
            f.flags.set(Flags::ESI, flags & 2 != 0);
            f.flags.set(Flags::FDF, flags & 4 != 0);
            f.len = len as u8;
            f.data = [0; 64];
            for (i, b) in f.data[..len].iter_mut().enumerate() {
                *b = fill.wrapping_add(i as u8);
            }
            f
        })
}

/// The text inside `< >` of an element.
fn inner(element: &str) -> &str {
    element.trim_start_matches('<').trim_end_matches('>').trim()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_streams_never_panic_and_stay_bounded(pieces in proptest::collection::vec(piece(), 0..40)) {
        let mut s = Splitter::new();
        let mut out = Vec::new();
        for p in &pieces {
            s.push(p, &mut out);
        }
        for e in out.iter().flatten() {
            prop_assert!(e.len() <= MAX_ELEMENT);
            let _ = wire::parse_request(e);
            let _ = wire::parse_reply(e);
            // Error texts the server would send back cannot break the stream.
            let err = wire::error_element(&format!("{:?}", wire::parse_request(e)));
            prop_assert_eq!(err.matches('<').count(), 1);
            prop_assert_eq!(err.matches('>').count(), 1);
        }
    }

    #[test]
    fn frames_read_back_as_written(f in prop_oneof![classic(), fd()]) {
        let text = wire::frame_element(&f).unwrap();
        prop_assert_eq!(wire::parse_reply(inner(&text)), Ok(Reply::Frame(f)));
        let send = wire::send_element(&f).unwrap();
        let mut sent = f;
        sent.ts_ns = 0;
        prop_assert_eq!(wire::parse_request(inner(&send)), Ok(Request::Send(sent)));
    }
}
