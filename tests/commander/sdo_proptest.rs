//! Random SDO traffic never panics the tracker, and every frame belongs to at most one
//! transaction; random transfers between client and server arrive intact, and the passive
//! tracker reassembles exactly what was transferred.

use cotui::decode::sdo::SdoTracker;
use cotui::od::{Access, Dictionary};
use cotui::sdo::client::{ClientConfig, Completion, Mode, SdoClient};
use cotui::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use cotui::sdo::{Outcome, Protocol as P, Transaction};
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
    #![proptest_config(ProptestConfig::with_cases(128))]
    #[test]
    fn random_frames_never_panic(frames in prop::collection::vec((1u8..4, any::<bool>(), payload()), 0..200)) {
        let dict = Dictionary::default();
        let mut t = SdoTracker::new();
        let mut txns = Vec::new();
        for (i, (node, c2s, bytes)) in frames.iter().enumerate() {
            let f = t.on_frame(i as u64, i as u64 * 1000, cotui::frame::NodeKey::new(0, *node), *c2s, bytes, &dict);
            prop_assert!(!f.label().is_empty());
            prop_assert!(serde_json::to_value(f.to_json()).unwrap()["cs"].is_string());
            txns.extend(t.drain_completed());
        }
        txns.extend(t.finish());
        let mut seen = HashSet::new();
        for tx in &txns {
            prop_assert!(!tx.label(&dict).is_empty());
            prop_assert!(serde_json::to_value(tx.to_json(&dict)).unwrap()["outcome"].is_string());
            prop_assert!(tx.start_ns <= tx.end_ns);
            for s in &tx.frames {
                prop_assert!(seen.insert(*s), "frame {} in two transactions", s);
                prop_assert!((*s as usize) < frames.len());
            }
        }
    }
}

/// Runs one transfer between a client and a server with a tracker listening;
/// returns the client's result and what the tracker reassembled.
fn exchange(
    scfg: ServerConfig,
    store: &mut MemoryStore,
    first: [u8; 8],
    client: &mut SdoClient,
) -> (Option<Completion>, Vec<Transaction>) {
    let dict = Dictionary::default();
    let mut server = SdoServer::new(scfg);
    let mut tracker = SdoTracker::new();
    let (mut now, mut seq) = (0u64, 0u64);
    let mut to_server = vec![first];
    let mut done = None;
    while !to_server.is_empty() {
        let mut to_client = Vec::new();
        for f in std::mem::take(&mut to_server) {
            seq += 1;
            now += 1000;
            tracker.on_frame(seq, now, cotui::frame::NodeKey::new(0, 9), true, &f, &dict);
            to_client.extend(server.on_frame(&f, now, store).frames);
        }
        for f in to_client {
            seq += 1;
            now += 1000;
            tracker.on_frame(seq, now, cotui::frame::NodeKey::new(0, 9), false, &f, &dict);
            let out = client.on_frame(&f, now);
            done = out.done.or(done);
            to_server.extend(out.frames);
        }
    }
    (done, tracker.finish())
}

fn mode() -> impl Strategy<Value = Mode> {
    prop_oneof![Just(Mode::Auto), Just(Mode::Segmented), Just(Mode::Block)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]
    #[test]
    fn client_server_and_tracker_agree(
        data in prop::collection::vec(any::<u8>(), 0..400),
        upload in any::<bool>(),
        mode in mode(),
        cblk in 1u8..=127,
        sblk in 1u8..=127,
        ccrc in any::<bool>(),
        scrc in any::<bool>(),
    ) {
        let ccfg = ClientConfig { block_size: cblk, crc: ccrc, ..ClientConfig::default() };
        let scfg = ServerConfig { block_size: sblk, crc: scrc, ..ServerConfig::default() };
        let mut store = MemoryStore::default();
        store.insert(0x2100, 3, Access::Rw, None, if upload { data.clone() } else { Vec::new() });
        let mut client = SdoClient::new(ccfg);
        let first = if upload {
            client.upload(0x2100, 3, mode, 0).unwrap()
        } else {
            client.download(0x2100, 3, data.clone(), mode, 0).unwrap()
        };
        let (done, seen) = exchange(scfg, &mut store, first, &mut client);
        let protocol = match done {
            Some(Completion::Uploaded { data: ref got, protocol, .. }) => {
                prop_assert!(upload);
                prop_assert_eq!(got, &data);
                protocol
            }
            Some(Completion::Downloaded { len, protocol, .. }) => {
                prop_assert!(!upload);
                prop_assert_eq!(len, data.len());
                prop_assert_eq!(&store.objects[&(0x2100, 3)].value, &data);
                protocol
            }
            other => return Err(TestCaseError::fail(format!("{other:?}"))),
        };
        if mode == Mode::Block {
            prop_assert_eq!(protocol, P::Block);
        }
        prop_assert_eq!(seen.len(), 1);
        prop_assert_eq!(&seen[0].data, &data);
        prop_assert_eq!(seen[0].protocol, protocol);
        prop_assert_eq!(&seen[0].outcome, &Outcome::Ok);
        prop_assert!(seen[0].problems.is_empty(), "{:?}", seen[0].problems);
    }
}

/// The frames of one block transfer between a client and a server: (client to server, bytes).
fn block_transfer(data: &[u8], upload: bool, cblk: u8, sblk: u8) -> Vec<(bool, [u8; 8])> {
    let ccfg = ClientConfig {
        block_size: cblk,
        crc: true,
        ..ClientConfig::default()
    };
    let scfg = ServerConfig {
        block_size: sblk,
        crc: true,
        ..ServerConfig::default()
    };
    let mut store = MemoryStore::default();
    store.insert(
        0x2100,
        3,
        Access::Rw,
        None,
        if upload { data.to_vec() } else { Vec::new() },
    );
    let mut client = SdoClient::new(ccfg);
    let first = if upload {
        client.upload(0x2100, 3, Mode::Block, 0).unwrap()
    } else {
        client.download(0x2100, 3, data.to_vec(), Mode::Block, 0).unwrap()
    };
    let mut server = SdoServer::new(scfg);
    let (mut frames, mut now) = (Vec::new(), 0u64);
    let mut to_server = vec![first];
    while !to_server.is_empty() {
        let mut to_client = Vec::new();
        for f in std::mem::take(&mut to_server) {
            now += 1000;
            frames.push((true, f));
            to_client.extend(server.on_frame(&f, now, &mut store).frames);
        }
        for f in to_client {
            now += 1000;
            frames.push((false, f));
            to_server.extend(client.on_frame(&f, now).frames);
        }
    }
    frames
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    /// A capture that starts anywhere in a block transfer invents no transaction: what it
    /// lists is the transfer itself (its object known when the initiate response was
    /// captured) or one partial transfer whose bytes end the real data.
    #[test]
    fn a_block_transfer_caught_mid_way_invents_nothing(
        data in prop::collection::vec(any::<u8>(), 1..1200),
        upload in any::<bool>(),
        cblk in 1u8..=127,
        sblk in 1u8..=127,
        cut_at in any::<prop::sample::Index>(),
    ) {
        let frames = block_transfer(&data, upload, cblk, sblk);
        let cut = 1 + cut_at.index(frames.len() - 1);
        let dict = Dictionary::default();
        let mut t = SdoTracker::new();
        let mut labels = Vec::new();
        for (i, (c2s, f)) in frames[cut..].iter().enumerate() {
            labels.push(t.on_frame(i as u64 + 1, i as u64 * 1000, cotui::frame::NodeKey::new(0, 9), *c2s, f, &dict).label());
        }
        let txns = t.finish();
        // A server's first byte 0x42/0x43/0x47/0x4B/0x4F reads as a complete expedited upload
        // response, listed at once; nothing can take it back (a known limit).
        let (first_c2s, first) = frames[cut];
        let expedited_lookalike = !first_c2s && [0x42, 0x43, 0x47, 0x4B, 0x4F].contains(&first[0]);
        let real: Vec<&Transaction> = txns
            .iter()
            .filter(|x| !(expedited_lookalike && x.frames == [1] && x.protocol == P::Expedited))
            .collect();
        prop_assert!(real.len() <= 1, "cut {}: {:#?}\n{:#?}", cut, txns, labels);
        for x in real {
            prop_assert_eq!(x.direction == cotui::sdo::TransferDirection::Upload, upload);
            if x.is_partial() {
                prop_assert_eq!(x.protocol, P::Block);
                prop_assert!(data.ends_with(&x.data) || x.outcome != Outcome::Ok, "cut {}: {:?}", cut, x);
            } else {
                prop_assert_eq!((x.index, x.sub), (0x2100, 3), "cut {}: {:?}\n{:#?}", cut, x, labels);
            }
        }
    }
}
