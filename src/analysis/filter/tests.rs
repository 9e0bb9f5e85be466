//! Parser and evaluator tests.

use super::*;
use crate::decode::{Decoder, Kind};
use crate::frame::{Flags, Frame};
use std::collections::HashMap;

fn decoder() -> Decoder {
    Decoder::from_bindings(&crate::od::bind::Bindings::new())
}

fn parse(s: &str) -> Expr {
    Filter::parse_with(s, &decoder()).unwrap().expr.unwrap()
}

fn term(t: Term) -> Expr {
    Expr::Term(t)
}

fn err(s: &str) -> String {
    Filter::parse_with(s, &decoder()).unwrap_err().to_string()
}

#[test]
fn parses_every_word_form() {
    assert_eq!(
        parse("node 3 kind=sdo 6041:00 abort id 0x181 \"Boot up\" emcy \"warn\""),
        Expr::And(vec![
            term(Term::Node(3, 3)),
            term(Term::Kinds(vec![Kind::SdoTx, Kind::SdoRx])),
            term(Term::Object {
                index: 0x6041,
                sub: Some(0),
                test: None
            }),
            term(Term::Abort(None)),
            term(Term::Id(IdMatch::Range(0x181, 0x181))),
            term(Term::Text("boot up".into())),
            term(Term::Kinds(vec![Kind::Emcy])),
            term(Term::Text("warn".into())),
        ])
    );
    assert_eq!(parse("node=0x7f"), term(Term::Node(127, 127)));
    assert_eq!(parse("node 2-5"), term(Term::Node(2, 5)));
    assert_eq!(
        parse("6041"),
        term(Term::Object {
            index: 0x6041,
            sub: None,
            test: None
        })
    );
    assert_eq!(
        parse("0x1018:1"),
        term(Term::Object {
            index: 0x1018,
            sub: Some(1),
            test: None
        })
    );
    assert_eq!(parse("hb"), term(Term::Kinds(vec![Kind::Heartbeat])));
    assert!(Filter::parse("   ").unwrap().is_empty());
}

#[test]
fn parses_operators_with_precedence() {
    let (n2, n3) = (term(Term::Node(2, 2)), term(Term::Node(3, 3)));
    let sdo = term(Term::Kinds(vec![Kind::SdoTx, Kind::SdoRx]));
    assert_eq!(parse("node 2 or node 3"), Expr::Or(vec![n2.clone(), n3.clone()]));
    assert_eq!(parse("!sdo"), Expr::Not(Box::new(sdo.clone())));
    assert_eq!(parse("NOT sdo"), Expr::Not(Box::new(sdo.clone())));
    // and binds tighter than or; juxtaposition is and.
    assert_eq!(
        parse("sdo node 2 or node 3"),
        Expr::Or(vec![Expr::And(vec![sdo.clone(), n2.clone()]), n3.clone()])
    );
    assert_eq!(
        parse("sdo and (node 2 or node 3)"),
        Expr::And(vec![sdo.clone(), Expr::Or(vec![n2.clone(), n3.clone()])])
    );
    assert_eq!(
        parse("not node 2 and sdo"),
        Expr::And(vec![Expr::Not(Box::new(n2)), sdo])
    );
}

#[test]
fn parses_ids_direction_time_and_aborts() {
    assert_eq!(parse("id 700-77f"), term(Term::Id(IdMatch::Range(0x700, 0x77F))));
    assert_eq!(
        parse("id 180/780"),
        term(Term::Id(IdMatch::Mask {
            value: 0x180,
            mask: 0x780
        }))
    );
    assert_eq!(parse("tx"), term(Term::Tx(true)));
    assert_eq!(parse("rx"), term(Term::Tx(false)));
    assert_eq!(
        parse("time 1.5-3.0"),
        Expr::And(vec![term(Term::Time(Cmp::Ge, 1.5)), term(Term::Time(Cmp::Le, 3.0))])
    );
    assert_eq!(parse("time 10-"), term(Term::Time(Cmp::Ge, 10.0)));
    assert_eq!(parse("time < 2"), term(Term::Time(Cmp::Lt, 2.0)));
    // Alone, `time` is still the TIME kind.
    assert_eq!(parse("time"), term(Term::Kinds(vec![Kind::Time])));
    assert_eq!(
        parse("abort 0x0602"),
        term(Term::Abort(Some(CodePrefix {
            value: 0x0602,
            digits: 4
        })))
    );
    // A bare object after `abort` stays an object.
    assert_eq!(
        parse("abort 6041"),
        Expr::And(vec![
            term(Term::Abort(None)),
            term(Term::Object {
                index: 0x6041,
                sub: None,
                test: None
            })
        ])
    );
    assert!(
        CodePrefix {
            value: 0x0602,
            digits: 4
        }
        .matches(0x0602_0000)
    );
    assert!(
        !CodePrefix {
            value: 0x0602,
            digits: 4
        }
        .matches(0x0601_0000)
    );
    assert!(
        CodePrefix {
            value: 0x0602_0000,
            digits: 8
        }
        .matches(0x0602_0000)
    );
}

#[test]
fn parses_names_aliases_and_value_tests() {
    assert_eq!(
        parse("Statusword & 0x0008"),
        term(Term::Object {
            index: 0x6041,
            sub: Some(0),
            test: Some(Test {
                mask: Some(8),
                cmp: None
            })
        })
    );
    assert_eq!(
        parse("Velocity actual value > 1000"),
        term(Term::Object {
            index: 0x606C,
            sub: Some(0),
            test: Some(Test {
                mask: None,
                cmp: Some((Cmp::Gt, 1000.0))
            })
        })
    );
    assert_eq!(
        parse("6041:00 == 0x0237"),
        term(Term::Object {
            index: 0x6041,
            sub: Some(0),
            test: Some(Test {
                mask: None,
                cmp: Some((Cmp::Eq, 567.0))
            })
        })
    );
    assert_eq!(
        parse("statusword & 0x6f = 0x27 node 2"),
        Expr::And(vec![
            term(Term::Object {
                index: 0x6041,
                sub: Some(0),
                test: Some(Test {
                    mask: Some(0x6F),
                    cmp: Some((Cmp::Eq, 39.0))
                })
            }),
            term(Term::Node(2, 2)),
        ])
    );
    assert_eq!(
        parse("6064 < -5.5"),
        term(Term::Object {
            index: 0x6064,
            sub: None,
            test: Some(Test {
                mask: None,
                cmp: Some((Cmp::Lt, -5.5))
            })
        })
    );
}

#[test]
fn errors_say_where() {
    assert_eq!(
        err("node 3 kind bogus"),
        "column 13: unknown kind `bogus` (nmt sync emcy time tpdo rpdo pdo sdo heartbeat lss error other)"
    );
    assert_eq!(Filter::parse("node").unwrap_err().column, 5);
    assert_eq!(err("node=200"), "column 6: `200` is not a node-ID (0..127)");
    assert_eq!(Filter::parse("x \"abc").unwrap_err().column, 3);
    assert_eq!(
        err("node 2 zz"),
        "column 8: unknown word `zz` (not a keyword, kind, object or alias; free text goes in quotes: \"zz\")"
    );
    assert_eq!(
        err("6041:zz"),
        "column 6: `zz` is not a sub-index (hex 00..FF) in `6041:zz`"
    );
    assert_eq!(err("node 2 or"), "column 10: a condition is missing here");
    assert_eq!(err("or node 2"), "column 1: `or` needs a condition before it");
    assert_eq!(err("(node 2"), "column 1: `(` is never closed");
    assert_eq!(err("node 2)"), "column 7: `)` without its `(`");
    assert_eq!(err("!"), "column 2: `not` needs a condition after it");
    assert_eq!(err("id 77f-700").split(':').next(), Some("column 4"));
    assert_eq!(
        err("time 3-x"),
        "column 6: `3-x` is not a time range in seconds from the first frame (e.g. 1.5-3.0 or 10-)"
    );
    assert_eq!(err("Statusword &"), "column 13: expected a mask after the operator");
    assert_eq!(err("6041 > fast"), "column 8: `fast` is not a number");
    assert_eq!(
        err("> 5"),
        "column 1: a comparison needs an object before it (e.g. `Statusword & 0x8`)"
    );
    assert_eq!(
        err("abort 0xZZ"),
        "column 7: `0xzz` is not an abort code (up to 8 hex digits, e.g. 0x0602)"
    );
    assert_eq!(err(&"(".repeat(100)), "column 65: nested too deeply");
    // Words that used to be free text are errors now: quote them.
    assert!(err("upload").starts_with("column 1: unknown word `upload`"));
}

/// Decodes `frames` in order and returns the positions `text` matches, with every frame
/// decoded and every transfer known.
fn matches(text: &str, frames: &[Frame]) -> Vec<usize> {
    let mut dec = decoder();
    let f = Filter::parse_with(text, &dec).unwrap();
    let mut decoded = Vec::new();
    let mut txs = Vec::new();
    for (i, fr) in frames.iter().enumerate() {
        dec.set_seq(i as u64);
        decoded.push(dec.decode(fr));
        txs.extend(dec.take_transactions());
    }
    let mut of: HashMap<usize, usize> = HashMap::new();
    for (k, t) in txs.iter().enumerate() {
        for s in &t.frames {
            of.insert(*s as usize - 1, k);
        }
    }
    let t0 = frames[0].ts_ns;
    (0..frames.len())
        .filter(|&i| {
            let d = &decoded[i];
            let facts = Facts {
                ts_ns: frames[i].ts_ns,
                id: frames[i].id,
                flags: frames[i].flags.0,
                kind: d.kind,
                node: d.node,
            };
            // Without the decoded frame, the result is the same or not known yet.
            let cheap = f.eval(&Subject {
                facts,
                t0_ns: t0,
                iface: IFACES[usize::from(frames[i].iface)],
                decoded: None,
                transfer: Transfer::Unknown,
            });
            let full = f.eval(&Subject {
                facts,
                t0_ns: t0,
                iface: IFACES[usize::from(frames[i].iface)],
                decoded: Some(d),
                transfer: Transfer::Known(of.get(&i).map(|&k| Ended::of(&txs[k].outcome))),
            });
            assert_ne!(full, Tri::Unknown, "{text} at {i}");
            assert!(cheap == Tri::Unknown || cheap == full, "{text} at {i}");
            full == Tri::True
        })
        .collect()
}

/// Node 1 maps its TPDO1 to the statusword by SDO, sends it twice; node 2 aborts an
/// upload of 0x6041; node 1 answers an expedited read of the velocity; one frame is ours.
fn capture() -> Vec<Frame> {
    let mut v = Vec::new();
    let mut add = |id: u32, data: &[u8]| {
        let mut f = Frame::classic(id, data);
        f.ts_ns = 1_000_000_000 + v.len() as u64 * 500_000_000;
        v.push(f);
    };
    add(0x701, &[0x00]); // 0 t=0.0
    add(0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0]); // 1
    add(0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0]); // 2
    add(0x601, &[0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60]); // 3
    add(0x581, &[0x60, 0x00, 0x1A, 0x01, 0, 0, 0, 0]); // 4
    add(0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x01, 0, 0, 0]); // 5
    add(0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0]); // 6
    add(0x181, &[0x33, 0x02]); // 7 t=3.5 statusword 0x0233
    add(0x181, &[0x37, 0x02]); // 8 t=4.0 statusword 0x0237
    add(0x602, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]); // 9
    add(0x582, &[0x80, 0x41, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06]); // 10 abort 0x06020000
    add(0x601, &[0x40, 0x6C, 0x60, 0x00, 0, 0, 0, 0]); // 11
    add(0x581, &[0x43, 0x6C, 0x60, 0x00, 0xE8, 0x03, 0, 0]); // 12 velocity 1000
    add(0x702, &[0x05]); // 13
    let mut ours = Frame::classic(0x000, &[0x01, 0x00]);
    ours.ts_ns = v[13].ts_ns + 1;
    ours.flags.set(Flags::TX, true);
    v.push(ours); // 14
    v
}

/// The interface names of the test captures (`Frame::iface` indexes it).
const IFACES: [&str; 2] = ["can0", "can1"];

#[test]
fn iface_picks_the_frames_of_one_interface() {
    assert_eq!(parse("iface can1"), term(Term::Iface("can1".into())));
    assert_eq!(parse("iface=vcan0"), term(Term::Iface("vcan0".into())));
    assert_eq!(err("node 5 iface"), "column 13: `iface` needs an interface name");
    // Node 5 on both buses: a heartbeat and an SDO read on each.
    let mut c = Vec::new();
    for (k, (iface, id, data)) in [
        (0u16, 0x705, &[0x05][..]),
        (1, 0x705, &[0x7F][..]),
        (1, 0x605, &[0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0][..]),
        (1, 0x585, &[0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00][..]),
        (0, 0x706, &[0x05][..]),
    ]
    .into_iter()
    .enumerate()
    {
        let mut f = Frame::classic(id, data);
        f.iface = iface;
        f.ts_ns = 1_000 + k as u64;
        c.push(f);
    }
    assert_eq!(matches("iface can1 and node 5", &c), [1, 2, 3]);
    assert_eq!(matches("iface can0 node 5", &c), [0]);
    assert_eq!(matches("node 5 not iface can1", &c), [0]);
    assert_eq!(matches("iface can9", &c), Vec::<usize>::new());
    // A transfer is judged by its own interface.
    let mut dec = decoder();
    let mut txs = Vec::new();
    for (i, fr) in c.iter().enumerate() {
        dec.set_seq(i as u64);
        dec.decode(fr);
        txs.extend(dec.take_transactions());
    }
    assert_eq!(txs.len(), 1);
    let on = |text: &str| {
        let f = Filter::parse(text).unwrap();
        f.matches_transaction(&txs[0], IFACES[usize::from(txs[0].iface)], dec.dictionary(5), 0)
    };
    assert!(on("iface can1 node 5"));
    assert!(!on("iface can0"));
}

#[test]
fn object_terms_match_sdo_transfers_and_mapped_pdos() {
    let c = capture();
    assert_eq!(matches("6041", &c), [7, 8, 9, 10]);
    assert_eq!(matches("Statusword", &c), [7, 8, 9, 10]);
    assert_eq!(matches("6041 pdo", &c), [7, 8]);
    assert_eq!(matches("1a00", &c), [1, 2, 3, 4, 5, 6]);
    assert_eq!(matches("1a00:00", &c), [1, 2, 5, 6]);
    assert_eq!(matches("1a00:01", &c), [3, 4]);
}

#[test]
fn value_comparisons_on_pdo_signals_and_sdo_values() {
    let c = capture();
    assert_eq!(matches("Statusword & 0x0004", &c), [8]);
    assert_eq!(matches("Statusword & 0x6f == 0x23", &c), [7]);
    assert_eq!(matches("6041:00 == 0x0237", &c), [8]);
    assert_eq!(matches("6041 != 0x0237", &c), [7]);
    assert_eq!(matches("Velocity actual value >= 1000", &c), [12]);
    assert_eq!(matches("Velocity actual value > 1000", &c), Vec::<usize>::new());
}

#[test]
fn boolean_ranges_direction_time_and_aborts() {
    let c = capture();
    assert_eq!(matches("hb or nmt", &c), [0, 13, 14]);
    assert_eq!(matches("!sdo !pdo", &c), [0, 13, 14]);
    assert_eq!(matches("not (sdo or pdo or hb)", &c), [14]);
    assert_eq!(matches("id 700-77f", &c), [0, 13]);
    assert_eq!(matches("id 580/f80", &c), [2, 4, 6, 10, 12]);
    assert_eq!(matches("node 2", &c), [9, 10, 13]);
    assert_eq!(matches("tx", &c), [14]);
    assert_eq!(matches("rx hb", &c), [0, 13]);
    assert_eq!(matches("time 3.5-4.0", &c), [7, 8]);
    assert_eq!(matches("time > 6", &c), [13, 14]);
    assert_eq!(matches("abort", &c), [9, 10]);
    assert_eq!(matches("abort 0x0602", &c), [9, 10]);
    assert_eq!(matches("abort 0x0601", &c), Vec::<usize>::new());
    assert_eq!(matches("sdo !abort node 2", &c), Vec::<usize>::new());
    assert_eq!(matches("\"boot-up\"", &c), [0]);
}

#[test]
fn transactions_are_judged_by_their_object_value_and_outcome() {
    let c = capture();
    let mut dec = decoder();
    let mut txs = Vec::new();
    for (i, fr) in c.iter().enumerate() {
        dec.set_seq(i as u64);
        dec.decode(fr);
        txs.extend(dec.take_transactions());
    }
    let pick = |text: &str| -> Vec<(u16, u8)> {
        let f = Filter::parse_with(text, &dec).unwrap();
        txs.iter()
            .filter(|t| f.matches_transaction(t, IFACES[usize::from(t.iface)], dec.dictionary(t.node), c[0].ts_ns))
            .map(|t| (t.index, t.node))
            .collect()
    };
    assert_eq!(pick("abort"), [(0x6041, 2)]);
    assert_eq!(pick("Velocity actual value == 1000"), [(0x606C, 1)]);
    assert_eq!(pick("node 1 not 1a00"), [(0x606C, 1)]);
    assert_eq!(pick("pdo"), Vec::<(u16, u8)>::new());
}

/// Names that count the lookups made of them (each scans the dictionaries).
struct Counted(std::cell::Cell<usize>);

impl Names for Counted {
    fn object(&self, text: &str) -> Option<(u16, u8)> {
        self.0.set(self.0.get() + 1);
        (text == "status word").then_some((0x6041, 0))
    }
}

#[test]
fn conditions_side_by_side_look_each_name_up_once() {
    // 16,000 words: each tries the names of up to 8 words it starts, but the same text
    // is looked up once (this was 112,000 dictionary scans).
    let text = vec!["sdo hb"; 8_000].join(" ");
    let names = Counted(std::cell::Cell::new(0));
    let f = Filter::parse_with(&text, &names).unwrap();
    assert!(matches!(f.expr(), Some(Expr::And(parts)) if parts.len() == 16_000));
    assert!(names.0.get() <= 16, "{} lookups", names.0.get());
    let f = Filter::parse_with("sdo status word", &names).unwrap();
    assert!(matches!(f.expr(), Some(Expr::And(parts)) if parts.len() == 2));
}

#[test]
fn an_error_in_a_long_filter_quotes_a_window_around_its_column() {
    let long = "x".repeat(10_000);
    let text = format!(
        "{} zz {} {long}",
        vec!["sdo"; 5_000].join(" "),
        vec!["hb"; 5_000].join(" ")
    );
    let e = Filter::parse_with(&text, &decoder()).unwrap_err();
    assert_eq!(e.column, 20_001);
    let window = e.excerpt(&text);
    assert_eq!(window, format!("…{}zz {}h…", "sdo ".repeat(10), "hb ".repeat(12)));
    // A word of 10,000 characters is quoted by its start.
    let e = Filter::parse_with(&long, &decoder()).unwrap_err();
    assert!(e.to_string().len() < 300, "{e}");
    assert!(
        e.to_string()
            .starts_with(&format!("column 1: unknown word `{}…`", "x".repeat(39))),
        "{e}"
    );
    // A short filter is quoted whole.
    let e = Filter::parse_with("node 3 zz", &decoder()).unwrap_err();
    assert_eq!(e.excerpt("node 3 zz"), "node 3 zz");
}
