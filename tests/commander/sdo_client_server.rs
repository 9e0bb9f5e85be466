//! The SDO client against the SDO server, with the passive tracker listening:
//! every transfer type both ways, aborts, CRC errors, lost segments and timeouts.

use cotui::decode::sdo::SdoTracker;
use cotui::od::{Access, DataType, Dictionary, ObjectInfo, Profile, Value};
use cotui::sdo::client::{ClientConfig, Completion, Mode, SdoClient, SdoError};
use cotui::sdo::server::{MemoryStore, ObjectStore, SdoServer, ServerConfig, ServerEvent};
use cotui::sdo::{Outcome, Problem, Protocol, Transaction, TransferDirection};
use std::sync::Arc;

const NODE: u8 = 5;

fn store() -> MemoryStore {
    let mut s = MemoryStore::default();
    s.insert(0x1000, 0, Access::Ro, Some(4), vec![0x92, 0x01, 0x02, 0x00]);
    s.insert(0x1008, 0, Access::Const, None, b"cotui test drive".to_vec());
    s.insert(0x1017, 0, Access::Rw, Some(2), vec![0, 0]);
    s.insert(0x1F50, 1, Access::Rw, None, Vec::new());
    s.insert(0x2000, 1, Access::Wo, Some(1), vec![0]);
    s.insert(0x6040, 0, Access::Rw, Some(2), vec![0, 0]);
    s
}

/// A frame filter: gets (client_to_server, frame), returns false to lose the frame.
type Filter = Box<dyn FnMut(bool, &mut [u8; 8]) -> bool>;

/// Client and server joined by a bus that a tracker listens to.
struct Link {
    client: SdoClient,
    server: SdoServer,
    store: MemoryStore,
    tracker: SdoTracker,
    dict: Dictionary,
    now: u64,
    seq: u64,
    events: Vec<ServerEvent>,
    filter: Filter,
}

impl Link {
    fn new(ccfg: ClientConfig, scfg: ServerConfig) -> Link {
        Link {
            client: SdoClient::new(ccfg),
            server: SdoServer::new(scfg),
            store: store(),
            tracker: SdoTracker::new(),
            dict: Dictionary::default(),
            now: 0,
            seq: 0,
            events: Vec::new(),
            filter: Box::new(|_, _| true),
        }
    }
    fn standard() -> Link {
        Link::new(ClientConfig::default(), ServerConfig::default())
    }

    /// Puts a frame on the bus: the tracker sees it unless the filter loses it.
    fn bus(&mut self, c2s: bool, mut frame: [u8; 8]) -> Option<[u8; 8]> {
        if !(self.filter)(c2s, &mut frame) {
            return None;
        }
        self.seq += 1;
        self.now += 100_000;
        self.tracker.on_frame(
            self.seq,
            self.now,
            cotui::frame::NodeKey::new(0, NODE),
            c2s,
            &frame,
            &self.dict,
        );
        Some(frame)
    }

    /// Runs the exchange that `first` starts until no frame is left; returns the client's result.
    fn run(&mut self, first: [u8; 8]) -> Option<Completion> {
        let mut to_server = vec![first];
        let mut done = None;
        for _ in 0..10_000 {
            let mut to_client = Vec::new();
            for f in std::mem::take(&mut to_server) {
                if let Some(f) = self.bus(true, f) {
                    let out = self.server.on_frame(&f, self.now, &mut self.store);
                    self.events.extend(out.event);
                    to_client.extend(out.frames);
                }
            }
            for f in to_client {
                if let Some(f) = self.bus(false, f) {
                    let out = self.client.on_frame(&f, self.now);
                    if out.done.is_some() {
                        done = out.done;
                    }
                    to_server.extend(out.frames);
                }
            }
            if to_server.is_empty() {
                return done;
            }
        }
        panic!("exchange did not end");
    }

    fn upload(&mut self, index: u16, sub: u8, mode: Mode) -> Option<Completion> {
        let f = self.client.upload(index, sub, mode, self.now).expect("idle client");
        self.run(f)
    }
    fn download(&mut self, index: u16, sub: u8, data: &[u8], mode: Mode) -> Option<Completion> {
        let f = self
            .client
            .download(index, sub, data.to_vec(), mode, self.now)
            .expect("idle client");
        self.run(f)
    }
    /// The one transaction the tracker reassembled.
    fn seen(&mut self) -> Transaction {
        let mut v: Vec<Transaction> = self.tracker.drain_completed().collect();
        assert_eq!(v.len(), 1, "{v:#?}");
        v.remove(0)
    }
}

fn check_upload(l: &mut Link, index: u16, sub: u8, mode: Mode, want: &[u8], protocol: Protocol) {
    let c = l.upload(index, sub, mode).expect("completion");
    assert_eq!(
        c,
        Completion::Uploaded {
            index,
            sub,
            protocol,
            data: want.to_vec()
        }
    );
    let t = l.seen();
    assert_eq!(
        (t.index, t.sub, t.direction, t.protocol),
        (index, sub, TransferDirection::Upload, protocol)
    );
    assert_eq!(t.data, want);
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty(), "{:?}", t.problems);
    assert!(!l.client.is_busy() && !l.server.is_busy());
}

fn check_download(l: &mut Link, index: u16, sub: u8, mode: Mode, data: &[u8], protocol: Protocol) {
    let c = l.download(index, sub, data, mode).expect("completion");
    assert_eq!(
        c,
        Completion::Downloaded {
            index,
            sub,
            protocol,
            len: data.len()
        }
    );
    assert_eq!(l.store.objects[&(index, sub)].value, data);
    let t = l.seen();
    assert_eq!(
        (t.index, t.sub, t.direction, t.protocol),
        (index, sub, TransferDirection::Download, protocol)
    );
    assert_eq!(t.data, data);
    assert_eq!(t.outcome, Outcome::Ok);
    assert!(t.problems.is_empty(), "{:?}", t.problems);
    assert!(!l.client.is_busy() && !l.server.is_busy());
}

#[test]
fn expedited_both_ways() {
    let mut l = Link::standard();
    check_upload(
        &mut l,
        0x1000,
        0,
        Mode::Auto,
        &[0x92, 0x01, 0x02, 0x00],
        Protocol::Expedited,
    );
    check_download(&mut l, 0x6040, 0, Mode::Auto, &[0x0F, 0x00], Protocol::Expedited);
    check_download(&mut l, 0x2000, 1, Mode::Auto, &[7], Protocol::Expedited);
    assert_eq!(
        l.events.last(),
        Some(&ServerEvent::Written {
            index: 0x2000,
            sub: 1,
            protocol: Protocol::Expedited,
            len: 1
        })
    );
}

#[test]
fn segmented_both_ways() {
    let mut l = Link::standard();
    check_upload(&mut l, 0x1008, 0, Mode::Auto, b"cotui test drive", Protocol::Segmented);
    let data: Vec<u8> = (0..=99).collect();
    check_download(&mut l, 0x1F50, 1, Mode::Auto, &data, Protocol::Segmented);
    check_upload(&mut l, 0x1F50, 1, Mode::Auto, &data, Protocol::Segmented);
    // Forced segmented for two bytes; exactly seven and fourteen bytes end on a segment boundary.
    check_download(&mut l, 0x6040, 0, Mode::Segmented, &[6, 0], Protocol::Segmented);
    check_download(&mut l, 0x1F50, 1, Mode::Auto, b"seven!!", Protocol::Segmented);
    check_download(&mut l, 0x1F50, 1, Mode::Auto, b"fourteen bytes", Protocol::Segmented);
    check_upload(&mut l, 0x1F50, 1, Mode::Auto, b"fourteen bytes", Protocol::Segmented);
    // An empty domain is uploaded as one empty segment.
    check_download(&mut l, 0x1F50, 1, Mode::Segmented, b"", Protocol::Segmented);
    check_upload(&mut l, 0x1F50, 1, Mode::Auto, b"", Protocol::Segmented);
}

#[test]
fn block_both_ways_with_and_without_crc() {
    let data: Vec<u8> = (0..1000u32).map(|i| (i * 7 % 251) as u8).collect();
    for crc in [true, false] {
        for blksize in [1u8, 4, 127] {
            let ccfg = ClientConfig {
                block_size: blksize,
                crc,
                ..ClientConfig::default()
            };
            let scfg = ServerConfig {
                block_size: blksize,
                crc,
                ..ServerConfig::default()
            };
            let mut l = Link::new(ccfg, scfg);
            check_download(&mut l, 0x1F50, 1, Mode::Block, &data, Protocol::Block);
            check_upload(&mut l, 0x1F50, 1, Mode::Block, &data, Protocol::Block);
            check_download(
                &mut l,
                0x1F50,
                1,
                Mode::Block,
                b"21 bytes, 3 segments.",
                Protocol::Block,
            );
            check_upload(
                &mut l,
                0x1F50,
                1,
                Mode::Block,
                b"21 bytes, 3 segments.",
                Protocol::Block,
            );
            check_upload(
                &mut l,
                0x1000,
                0,
                Mode::Block,
                &[0x92, 0x01, 0x02, 0x00],
                Protocol::Block,
            );
            check_download(&mut l, 0x1F50, 1, Mode::Block, b"", Protocol::Block);
            check_upload(&mut l, 0x1F50, 1, Mode::Block, b"", Protocol::Block);
        }
    }
}

#[test]
fn server_aborts_reach_the_client_and_the_tracker() {
    let cases: [(u16, u8, Option<&[u8]>, u32); 7] = [
        (0x3000, 0, None, 0x0602_0000),                            // object does not exist
        (0x1017, 9, None, 0x0609_0011),                            // sub-index does not exist
        (0x2000, 1, None, 0x0601_0001),                            // read of a write-only object
        (0x1000, 0, Some(&[1, 2, 3, 4]), 0x0601_0002),             // write of a read-only object
        (0x1017, 0, Some(&[1, 2, 3]), 0x0607_0012),                // too long
        (0x1017, 0, Some(&[1]), 0x0607_0013),                      // too short
        (0x1017, 0, Some(&[1, 2, 3, 4, 5, 6, 7, 8]), 0x0607_0012), // too long, segmented
    ];
    for (index, sub, write, code) in cases {
        let mut l = Link::standard();
        let c = match write {
            Some(d) => l.download(index, sub, d, Mode::Auto),
            None => l.upload(index, sub, Mode::Auto),
        };
        let text = cotui::sdo::abort_text(code);
        assert_eq!(
            c,
            Some(Completion::Failed {
                index,
                sub,
                error: SdoError::Aborted { code, text }
            }),
            "{index:04X}:{sub}"
        );
        let t = l.seen();
        assert_eq!(
            t.outcome,
            Outcome::Aborted {
                code,
                text,
                by: cotui::sdo::Side::Server
            }
        );
        assert!(!l.server.is_busy());
    }
}

#[test]
fn unknown_command_and_toggle_errors_make_the_server_abort() {
    let mut s = SdoServer::new(ServerConfig::default());
    let mut st = store();
    let out = s.on_frame(&[0xE8, 0x04, 0x50, 0x00, 0, 0, 0, 0], 0, &mut st);
    assert_eq!(out.frames, vec![[0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05]]);
    // Segmented download whose second segment repeats toggle 0.
    let out = s.on_frame(&[0x21, 0x50, 0x1F, 0x01, 14, 0, 0, 0], 0, &mut st);
    assert_eq!(out.frames, vec![[0x60, 0x50, 0x1F, 0x01, 0, 0, 0, 0]]);
    assert_eq!(
        s.on_frame(&[0x00, 1, 2, 3, 4, 5, 6, 7], 0, &mut st).frames,
        vec![[0x20, 0, 0, 0, 0, 0, 0, 0]]
    );
    let out = s.on_frame(&[0x01, 1, 2, 3, 4, 5, 6, 7], 0, &mut st);
    assert_eq!(out.frames, vec![[0x80, 0x50, 0x1F, 0x01, 0x00, 0x00, 0x03, 0x05]]);
    assert!(!s.is_busy());
    // A block upload asking for block size 0.
    let out = s.on_frame(&[0xA4, 0x08, 0x10, 0x00, 0, 0, 0, 0], 0, &mut st);
    assert_eq!(out.frames, vec![[0x80, 0x08, 0x10, 0x00, 0x02, 0x00, 0x04, 0x05]]);
}

#[test]
fn server_protocol_switch_for_small_block_uploads() {
    let mut s = SdoServer::new(ServerConfig::default());
    let mut st = store();
    // pst = 8: a 4-byte object is answered expedited instead of by block.
    let out = s.on_frame(&[0xA4, 0x00, 0x10, 0x00, 127, 8, 0, 0], 0, &mut st);
    assert_eq!(out.frames, vec![[0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]]);
}

#[test]
fn bad_block_download_crc_is_aborted_by_the_server() {
    let mut l = Link::standard();
    l.filter = Box::new(|c2s, f| {
        if c2s && f[0] & 0xE3 == 0xC1 {
            f[1] ^= 0xFF; // corrupt the CRC of the end frame
        }
        true
    });
    let c = l.download(0x1F50, 1, b"some block data, 24 byte", Mode::Block);
    let code = 0x0504_0004;
    let text = "CRC error (block mode only)";
    assert_eq!(
        c,
        Some(Completion::Failed {
            index: 0x1F50,
            sub: 1,
            error: SdoError::Aborted { code, text }
        })
    );
    let t = l.seen();
    assert!(matches!(t.problems[..], [Problem::BadCrc { .. }]), "{:?}", t.problems);
    assert_eq!(
        t.outcome,
        Outcome::Aborted {
            code,
            text,
            by: cotui::sdo::Side::Server
        }
    );
}

#[test]
fn bad_block_upload_crc_is_aborted_by_the_client() {
    let mut l = Link::standard();
    // 16 bytes are three segments (seqno 1..3), so 0xC1 | n << 2 from the server is the end frame.
    l.filter = Box::new(|c2s, f| {
        if !c2s && f[0] & 0xE3 == 0xC1 {
            f[2] ^= 0x01; // corrupt the CRC
        }
        true
    });
    let c = l.upload(0x1008, 0, Mode::Block).expect("completion");
    assert!(
        matches!(
            c,
            Completion::Failed {
                error: SdoError::Protocol { code: 0x0504_0004, .. },
                ..
            }
        ),
        "{c:?}"
    );
    let t = l.seen();
    assert!(matches!(t.problems[..], [Problem::BadCrc { .. }]), "{:?}", t.problems);
    assert!(matches!(
        t.outcome,
        Outcome::Aborted {
            code: 0x0504_0004,
            by: cotui::sdo::Side::Client,
            ..
        }
    ));
}

#[test]
fn lost_block_segments_are_sent_again() {
    let data: Vec<u8> = (0..60).collect(); // nine segments
    for upload in [false, true] {
        let ccfg = ClientConfig {
            block_size: 4,
            ..ClientConfig::default()
        };
        let scfg = ServerConfig {
            block_size: 4,
            ..ServerConfig::default()
        };
        let mut l = Link::new(ccfg, scfg);
        l.store.insert(0x1F50, 1, Access::Rw, None, data.clone());
        let mut lost = false;
        l.filter = Box::new(move |c2s, f| {
            // Lose the first segment numbered 3 of the sending side.
            if c2s != upload && f[0] & 0x7F == 3 && !lost && f[0] != 0xA3 && f[0] != 0x83 {
                lost = true;
                return false;
            }
            true
        });
        let c = if upload {
            l.upload(0x1F50, 1, Mode::Block)
        } else {
            l.download(0x1F50, 1, &data, Mode::Block)
        };
        assert!(
            matches!(c, Some(Completion::Uploaded { .. } | Completion::Downloaded { .. })),
            "{c:?}"
        );
        assert_eq!(l.store.read(0x1F50, 1), Ok(data.clone()));
        let t = l.seen();
        assert_eq!(t.data, data, "upload={upload}");
        assert_eq!(t.outcome, Outcome::Ok);
        assert_eq!(t.problems, vec![Problem::SequenceError]);
    }
}

#[test]
fn client_timeout_sends_abort() {
    let mut c = SdoClient::new(ClientConfig {
        timeout_ns: 500_000_000,
        ..ClientConfig::default()
    });
    c.upload(0x1008, 0, Mode::Auto, 1_000).unwrap();
    assert_eq!(c.poll(400_000_000), Default::default());
    let out = c.poll(500_001_000);
    assert_eq!(out.frames, vec![[0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05]]);
    assert_eq!(
        out.done,
        Some(Completion::Failed {
            index: 0x1008,
            sub: 0,
            error: SdoError::Timeout
        })
    );
    assert!(!c.is_busy());
    assert_eq!(
        SdoError::Timeout.to_string(),
        "SDO protocol timed out (no answer from the server)"
    );
}

#[test]
fn server_timeout_sends_abort() {
    let mut s = SdoServer::new(ServerConfig {
        timeout_ns: 1_000,
        ..ServerConfig::default()
    });
    let mut st = store();
    s.on_frame(&[0x21, 0x50, 0x1F, 0x01, 20, 0, 0, 0], 10_000, &mut st);
    assert!(s.poll(10_999).frames.is_empty());
    assert_eq!(
        s.poll(11_000).frames,
        vec![[0x80, 0x50, 0x1F, 0x01, 0x00, 0x00, 0x04, 0x05]]
    );
    assert!(!s.is_busy());
    assert!(s.poll(20_000).frames.is_empty());
}

#[test]
fn busy_client_refuses_a_second_transfer_and_can_be_cancelled() {
    let mut c = SdoClient::new(ClientConfig::default());
    c.download(0x1F50, 1, vec![1; 30], Mode::Auto, 0).unwrap();
    assert!(c.upload(0x1000, 0, Mode::Auto, 0).is_err());
    let out = c.abort(0x0800_0000);
    assert_eq!(out.frames, vec![[0x80, 0x50, 0x1F, 0x01, 0x00, 0x00, 0x00, 0x08]]);
    assert_eq!(
        out.done,
        Some(Completion::Failed {
            index: 0x1F50,
            sub: 1,
            error: SdoError::Cancelled { code: 0x0800_0000 }
        })
    );
    assert!(c.upload(0x1000, 0, Mode::Auto, 0).is_ok());
}

#[test]
fn client_rejects_broken_server_answers() {
    let mut c = SdoClient::new(ClientConfig::default());
    c.upload(0x1008, 0, Mode::Auto, 0).unwrap();
    c.on_frame(&[0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0], 1);
    // The server answers the first segment request with toggle 1.
    let out = c.on_frame(&[0x10, 1, 2, 3, 4, 5, 6, 7], 2);
    assert_eq!(out.frames, vec![[0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x03, 0x05]]);
    assert!(matches!(
        out.done,
        Some(Completion::Failed {
            error: SdoError::Protocol { code: 0x0503_0000, .. },
            ..
        })
    ));
    // A download answered with an upload response.
    c.download(0x6040, 0, vec![6, 0], Mode::Auto, 3).unwrap();
    let out = c.on_frame(&[0x4B, 0x40, 0x60, 0x00, 6, 0, 0, 0], 4);
    assert_eq!(out.frames, vec![[0x80, 0x40, 0x60, 0x00, 0x01, 0x00, 0x04, 0x05]]);
    let Some(Completion::Failed { error, .. }) = out.done else {
        panic!("no failure")
    };
    assert_eq!(
        error.to_string(),
        "unexpected initiate_upload frame from the server (sent abort 0x05040001)"
    );
}

#[test]
fn uploaded_values_are_typed_through_the_dictionary() {
    let mut p = Profile::default();
    let info = ObjectInfo {
        name: "Device type".into(),
        data_type: DataType::U32,
        ..ObjectInfo::default()
    };
    p.objects.insert((0x1000, 0), info);
    let dict = Dictionary::new(vec![Arc::new(p)]);
    let mut l = Link::standard();
    let c = l.upload(0x1000, 0, Mode::Auto).unwrap();
    assert_eq!(c.value(&dict), Some(Value::Unsigned(0x0002_0192)));
    let c = l.upload(0x1008, 0, Mode::Auto).unwrap();
    assert_eq!(c.value(&dict), None);
}
