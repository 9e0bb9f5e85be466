//! The request parser and the data types never panic, whatever the line.

use cotui::gateway::line::parse;
use cotui::gateway::types::GwType;
use proptest::prelude::*;

const WORDS: &[&str] = &[
    "[1]",
    "[",
    "]",
    "4",
    "0x",
    "read",
    "r",
    "write",
    "w",
    "set",
    "node",
    "sdo_block",
    "reset",
    "comm",
    "lss_set_node",
    "lss_inquire_addr",
    "_lss_fastscan",
    "help",
    "u8",
    "i64",
    "x16",
    "r32",
    "vs",
    "d",
    "hex",
    "\"",
    "\"\"",
    "#",
    "-1",
    "0x1017",
    "0",
    "999999999999999999999",
    "é",
    "\t",
];

proptest! {
    #[test]
    fn any_text_parses_or_is_refused(line in "\\PC{0,200}") {
        let _ = parse(&line);
    }

    #[test]
    fn word_soup_parses_or_is_refused(words in proptest::collection::vec(proptest::sample::select(WORDS), 0..12)) {
        let _ = parse(&words.join(" "));
    }

    #[test]
    fn every_type_encodes_or_refuses_any_value(value in "\\PC{0,60}", ty in 0usize..20) {
        let words = ["b", "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64", "x8", "x16", "x32", "x64", "r32", "r64", "vs", "os", "us", "d", "hex"];
        let t = GwType::parse(words[ty]).unwrap();
        if let Ok(bytes) = t.encode(&value) {
            let _ = t.print(&bytes);
        }
    }

    #[test]
    fn any_bytes_print_as_every_type(data in proptest::collection::vec(any::<u8>(), 0..20), ty in 0usize..20) {
        let words = ["b", "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64", "x8", "x16", "x32", "x64", "r32", "r64", "vs", "os", "us", "d", "hex"];
        let text = GwType::parse(words[ty]).unwrap().print(&data);
        prop_assert!(!text.contains('\n') && !text.contains('\r'), "{text:?}");
    }
}
