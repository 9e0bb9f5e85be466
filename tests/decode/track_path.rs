//! `Decoder::track` (the `--transactions` path, no frame labels) gives the transactions,
//! labels and JSON records that full decoding gives, on the seed logs with their profiles
//! bound (mode-dependent statusword texts, learned mappings, vendor commands).

use cotui::cli::bind;
use cotui::decode::Decoder;
use cotui::frame::Frame;
use cotui::log::{LogReader, Outcome};
use std::fs;
use std::io::BufReader;

/// Every frame of a fixture log.
fn frames(name: &str) -> Vec<Frame> {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    let mut reader = LogReader::new(BufReader::new(fs::File::open(path).unwrap())).unwrap();
    let mut out = Vec::new();
    while let Some((_, outcome)) = reader.next_line().unwrap() {
        if let Outcome::Frame(f) = outcome {
            out.push(f);
        }
    }
    out
}

/// The transactions of `frames` as text and JSON lines, fed through `feed`.
fn transactions(mut decoder: Decoder, frames: &[Frame], feed: fn(&mut Decoder, &Frame)) -> Vec<String> {
    let mut all = Vec::new();
    for f in frames {
        feed(&mut decoder, f);
        all.extend(decoder.take_transactions());
    }
    all.extend(decoder.finish());
    all.iter()
        .map(|t| {
            let dict = decoder.dictionary(t.node);
            format!(
                "{}\n{}",
                t.label(dict),
                serde_json::to_string(&t.to_json(dict)).unwrap()
            )
        })
        .collect()
}

#[test]
fn track_gives_the_transactions_decode_gives() {
    let profiles: Vec<String> = ["1=aimotor", "2=syntron-ds", "3=dexmart-dev", "4=aqmd2405"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut total = 0;
    for log in [
        "seeds/aimotor.log",
        "seeds/aimotor-default-pdo.log",
        "seeds/syntron-ds.log",
        "seeds/syntron-ds-modes.log",
        "seeds/syntron-ds-pv.log",
        "seeds/dexmart-dev.log",
        "seeds/aqmd2405.log",
        "cia301_mix.log",
        "pdo_learning.log",
    ] {
        let frames = frames(log);
        for bound in [&profiles[..], &[]] {
            let decoder = bind::decoder(bound, &[]).unwrap();
            let decoded = transactions(decoder.clone(), &frames, |d, f| {
                d.decode(f);
            });
            let tracked = transactions(decoder, &frames, Decoder::track);
            assert_eq!(tracked, decoded, "{log}, profiles {bound:?}");
            total += decoded.len();
        }
    }
    assert!(total > 50, "the logs carry SDO transfers ({total})");
}

/// A mode of operation that only a PDO carries (mapped by sniffed SDO writes) names the
/// statusword bits of a later SDO upload the same way on both paths.
#[test]
fn track_keeps_the_mode_a_pdo_carries() {
    let steps: [(u32, &[u8]); 9] = [
        (0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0]),
        (0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0]),
        (0x601, &[0x23, 0x00, 0x1A, 0x01, 0x08, 0x00, 0x61, 0x60]),
        (0x581, &[0x60, 0x00, 0x1A, 0x01, 0, 0, 0, 0]),
        (0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x01, 0, 0, 0]),
        (0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0]),
        // TPDO1: modes of operation display = 3 (profile velocity).
        (0x181, &[0x03]),
        (0x601, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]),
        (0x581, &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x16, 0, 0]),
    ];
    let frames: Vec<Frame> = steps
        .iter()
        .enumerate()
        .map(|(i, (id, data))| {
            let mut f = Frame::classic(*id, data);
            f.ts_ns = 1_000_000 * i as u64;
            f
        })
        .collect();
    let decoder = bind::decoder(&[], &[]).unwrap();
    let decoded = transactions(decoder.clone(), &frames, |d, f| {
        d.decode(f);
    });
    let tracked = transactions(decoder, &frames, Decoder::track);
    assert_eq!(tracked, decoded);
    let last = decoded.last().unwrap();
    assert!(last.starts_with("Upload 0x6041:00"), "{last}");
    // Without the PDO the statusword reads the same bits in another mode's words.
    let no_pdo: Vec<Frame> = frames.iter().filter(|f| f.id != 0x181).cloned().collect();
    let other = transactions(bind::decoder(&[], &[]).unwrap(), &no_pdo, |d, f| {
        d.decode(f);
    });
    assert_ne!(other.last(), decoded.last(), "the mode changes the statusword text");
}
