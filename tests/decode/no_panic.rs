//! Arbitrary text never makes the profile loader, the EDS importer or the
//! expression/alias parsers panic.

use cotui::od::bind::BUILTIN;
use cotui::od::eds::import;
use cotui::od::expr::Expr;
use cotui::od::json::load_profile;
use cotui::od::procedure::parse_frame_data;
use cotui::od::{Bindings, resolve_object};
use proptest::prelude::*;

/// Lines that look like EDS content, to reach deeper than random bytes do.
fn eds_line() -> impl Strategy<Value = String> {
    prop_oneof![
        "\\[[0-9A-Fa-f]{4}(sub[0-9A-Fa-f]{1,3})?\\]",
        "\\[(DeviceInfo|DeviceComissioning|OptionalObjects|MandatoryObjects|[0-9A-F]{4}(Name|Value))\\]",
        "(ParameterName|ObjectType|DataType|AccessType|DefaultValue|ParameterValue|PDOMapping|CompactSubObj|SubNumber|LowLimit|HighLimit|NodeID|[0-9]{1,3})=.{0,12}",
        "(DefaultValue|ParameterValue)=(\\$NODEID)?\\+?(0x[0-9A-F]{1,10}|0[0-7]{1,12}|-?[0-9]{1,20})(\\+\\$NODEID)?",
        "(ObjectType|CompactSubObj|DataType)=(0x)?[0-9A-F]{1,4}",
        ".{0,30}",
    ]
}

/// JSON fragments that look like profile content.
fn json_piece() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("{".to_string()),
        Just("}".to_string()),
        Just("[".to_string()),
        Just("]".to_string()),
        Just(",".to_string()),
        Just(":".to_string()),
        "\"(name|objects|subs|type|values|alias_rules|pattern|index|sub|emcy|codes|manufacturer_fields|offset|length|pdo_sets|rpdo|tpdo|entries|cob_id|procedures|steps|sdo_write|wait|frame|data|axes|0x[0-9A-F]{4}(:[0-9]{1,3})?|[0-9]{1,3}(\\.\\.[0-9]{1,3})?|0x[0-9A-F]{4}\\.\\.0x[0-9A-F]{4})\"",
        "\"[-+*/()?:a-z0-9 {}.x]{0,16}\"",
        "-?[0-9]{1,20}(\\.[0-9]{1,3})?",
        Just("null".to_string()),
        Just("true".to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn eds_import_never_panics(text in ".{0,400}", node in 1u8..=127) {
        let _ = import("fuzz.eds", &text, node);
    }

    #[test]
    fn eds_bytes_of_any_encoding_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600), node in 1u8..=127) {
        let (text, fallback) = cotui::od::text::decode(&bytes);
        prop_assert!(fallback.iter().all(|l| *l >= 1 && *l <= text.lines().count().max(1)));
        let mut b = cotui::od::Bindings::new();
        b.bind_eds_bytes(node, "fuzz.eds", &bytes);
    }

    #[test]
    fn eds_like_text_never_panics(lines in prop::collection::vec(eds_line(), 0..60), node in 1u8..=127) {
        let (_, warnings) = import("fuzz.eds", &lines.join("\n"), node);
        for w in warnings {
            prop_assert!(w.at.starts_with("line "));
        }
    }

    #[test]
    fn json_loader_never_panics(text in ".{0,400}") {
        let _ = load_profile("fuzz.json", &text);
    }

    #[test]
    fn json_like_text_never_panics(pieces in prop::collection::vec(json_piece(), 0..80)) {
        let _ = load_profile("fuzz.json", &pieces.join(" "));
    }

    #[test]
    fn expressions_never_panic(text in "[-+*/%()<>=!&|^~?: a-z0-9x]{0,40}", x in any::<i64>()) {
        if let Ok(e) = Expr::parse(&text) {
            let _ = e.eval(&|_| Some(x));
        }
        let _ = parse_frame_data(&text);
    }

    #[test]
    fn resolving_never_panics(text in ".{0,30}") {
        let b = Bindings::new();
        let _ = resolve_object(b.dictionary(1), &text);
    }

    #[test]
    fn triggers_never_panic(text in "(incident|then|within|hb lost|emcy|node|\"|é|[ 0-9a-z_]){0,12}") {
        use cotui::analysis::filter::NoNames;
        if let Err(e) = cotui::analysis::trigger::Trigger::parse(&text, &NoNames) {
            prop_assert!(e.column >= 1 && e.column <= text.chars().count() + 2, "{text:?}: {e}");
        }
    }
}

proptest! {
    // Each case loads every built-in profile, so fewer cases.
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn mutated_builtin_profiles_never_panic(at in 0usize..40_000, len in 0usize..40, with in ".{0,3}") {
        for (_, text) in BUILTIN {
            let start = floor_char(text, at.min(text.len()));
            let end = floor_char(text, (start + len).min(text.len()));
            let mutated = format!("{}{with}{}", &text[..start], &text[end..]);
            let _ = load_profile("mutated.json", &mutated);
        }
    }
}

/// The largest char boundary at or below `i`.
fn floor_char(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    let text = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    assert!(load_profile("deep.json", &text).is_err());
    let text = format!("{{\"name\": \"x\", \"objects\": {}}}", "{\"a\":".repeat(10_000));
    assert!(load_profile("deep.json", &text).is_err());
}

/// JSON fragments that look like a transmit list (`send --list FILE`).
fn list_piece() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("{".to_string()),
        Just("}".to_string()),
        Just("[".to_string()),
        Just("]".to_string()),
        Just(",".to_string()),
        Just(":".to_string()),
        Just("\n".to_string()),
        "\"(entries|frame|rpdo|node|signals|every_ms|enabled|count|comment|Controlword|0x6040|rpdo[0-9]{1,3}|tpdo1|[0-9A-F]{3,8}#[0-9A-FR#]{0,17}|[0-9]{1,4}(ms|s)?)\"",
        "-?[0-9]{1,20}(\\.[0-9]{1,3})?",
        Just("null".to_string()),
        Just("true".to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn transmit_lists_never_panic(pieces in prop::collection::vec(list_piece(), 0..40), text in ".{0,200}") {
        let b = Bindings::new();
        let joined = pieces.concat();
        let _ = cotui::command::transmit_list::load(&format!("{{\"entries\": [{joined}]}}"), &b);
        let _ = cotui::command::transmit_list::load(&joined, &b);
        let _ = cotui::command::transmit_list::load(&text, &b);
    }
}
