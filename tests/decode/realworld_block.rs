//! The CANopenDemo tutorial capture (`../shared/realworld/logs/`, public, not copied
//! here) starts in the middle of two interleaved block transfers: a download to node 4
//! and an upload from node 3. Its per-line truth tags say which frames are block
//! segments and acknowledgements; cotui must label them so, and list one partial
//! transaction per transfer instead of inventing transactions from segment bytes.

use serde_json::Value;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;

const NAME: &str = "canopendemo_sdo_block_interlaced.txt";

fn derived(ext: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../shared/realworld/logs/derived/{NAME}.{ext}"))
}

fn decode(args: &[&str]) -> String {
    decode_file(&derived("l.log"), args)
}

fn decode_file(log: &std::path::Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
        .arg("decode")
        .args(args)
        .arg(log)
        .output()
        .expect("run cotui");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("UTF-8")
}

fn read(ext: &str) -> String {
    let p = derived(ext);
    std::fs::read_to_string(&p)
        .unwrap_or_else(|e| panic!("{}: {e} (../shared/realworld is beside the checkout)", p.display()))
}

#[test]
fn every_tagged_block_frame_is_labelled_as_one() {
    // Truth tags are per .l.log line; map.json gives the published line, for messages.
    let map: BTreeMap<String, u64> = serde_json::from_str(&read("map.json")).unwrap();
    let tags: BTreeMap<u64, String> = read("truth.jsonl")
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).unwrap();
            (v["line"].as_u64().unwrap(), v["tag"].as_str().unwrap().to_string())
        })
        .collect();
    let frames: Vec<Value> = decode(&["--format", "jsonl"])
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(frames.len(), map.len());
    let (mut segments, mut acks) = (0, 0);
    for f in &frames {
        let line = f["line"].as_u64().unwrap();
        let published = map[&line.to_string()];
        let line = format!("{line} (published line {published})");
        let label = f["label"].as_str().unwrap();
        let first = u8::from_str_radix(&f["data"].as_str().unwrap()[..2], 16).unwrap();
        match tags[&f["line"].as_u64().unwrap()].as_str() {
            "sdo_blk_seg" => {
                segments += 1;
                assert_eq!(f["sdo"]["cs"], "block_segment", "line {line}: {label}");
                let dir = if f["id"].as_u64().unwrap() & 0x780 == 0x600 {
                    "download"
                } else {
                    "upload"
                };
                let want = format!("Block {dir} segment seqno={}", first & 0x7F);
                assert!(label.starts_with(&want), "line {line}: {label}, want {want}");
            }
            "sdo_blk_ack" => {
                acks += 1;
                assert_eq!(f["sdo"]["block_step"], "ack", "line {line}: {label}");
                assert!(label.starts_with("Block ") && label.contains(" ack ackseq="), "{label}");
            }
            other => panic!("line {line}: unexpected tag {other:?}"),
        }
        assert!(
            !label.contains("outside any transfer") && !label.contains("unmatched"),
            "{label}"
        );
    }
    assert_eq!((segments, acks), (81, 4));
}

#[test]
fn the_two_transfers_are_partial_transactions_and_nothing_is_invented() {
    let out = decode(&["--transactions", "--format", "jsonl"]);
    let txns: Vec<Value> = out.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let mut seen: Vec<(u64, &str)> = txns
        .iter()
        .map(|t| (t["node"].as_u64().unwrap(), t["direction"].as_str().unwrap()))
        .collect();
    seen.sort();
    // MANIFEST.tsv block_hint: dn:4,up:3.
    assert_eq!(seen, vec![(3, "upload"), (4, "download")], "{out}");
    for t in &txns {
        assert_eq!(t["partial"], true);
        assert_eq!(t["protocol"], "block");
        assert!(t["index"].is_null());
        assert_eq!(t["outcome"], "incomplete", "the capture ends mid-transfer too");
        let kinds: Vec<&str> = t["problems"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["kind"].as_str().unwrap())
            .collect();
        // The published excerpt elides lines ("..."), so some acknowledged segments are missing.
        assert_eq!(kinds, ["partial", "sequence_error"]);
        // Bytes seen are whole 7-byte segments, acknowledged ones only.
        let len = t["len"].as_u64().unwrap();
        assert!(len > 0 && len % 7 == 0, "{t}");
    }
    let text = decode(&["--transactions"]);
    assert!(
        text.lines()
            .all(|l| l.contains("(object not captured)") && l.contains("[partial: started before the capture]")),
        "{text}"
    );
}

#[test]
fn the_published_screen_text_gives_the_same_transfers() {
    // The capture as published: candump -td -a screen output with "< response" notes and a
    // "..." elision. Timestamps are deltas there, so only what was transferred is compared.
    let published = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../shared/realworld/logs/{NAME}"));
    let key = |out: String| -> Vec<String> {
        let mut v: Vec<String> = out
            .lines()
            .map(|l| {
                let t: Value = serde_json::from_str(l).unwrap();
                format!(
                    "{} {} {} {} {}",
                    t["node"], t["direction"], t["len"], t["data"], t["problems"]
                )
            })
            .collect();
        v.sort();
        v
    };
    let args = ["--transactions", "--format", "jsonl"];
    assert_eq!(key(decode_file(&published, &args)), key(decode(&args)));
}
