//! Loader tests: good files, located errors, warnings.
use super::*;
use crate::od::{Access, DataType, MappedEntry, Value};

const GOOD: &str = r#"{
  "format": 1,
  "name": "demo",
  "description": "Demo drive",
  "extends": ["cia402"],
  "identification": [
    { "object": "0x1000", "value": 402, "mask": "0xFFFF" },
    { "object": "0x1008", "text": "DEV", "match": "prefix" }
  ],
  "objects": {
    "0x606C": { "name": "Velocity actual value", "type": "INTEGER32", "access": "ro", "pdo": "tpdo",
                "unit": "rpm", "scale": 0.1, "alias": "D0.04" },
    "0x6060": { "name": "Modes of operation", "type": "i8", "values": { "3": "Profile velocity", "-1": "Vendor" } },
    "0x1018": { "name": "Identity object", "subs": {
        "0": { "name": "Highest sub-index supported", "type": "u8", "access": "const", "default": 4 },
        "1": { "name": "Vendor-ID", "type": "u32", "access": "ro" } } },
    "0x1016": { "name": "Consumer heartbeat time", "subs": {
        "1..3": { "name": "Consumer heartbeat time {n}", "type": "u32" } } },
    "0x1008": { "name": "Manufacturer device name", "type": "visible_string", "default": "DEV" },
    "0x1800..0x19FF": { "name": "TPDO{i} communication parameter", "subs": {
        "1": { "name": "COB-ID used by TPDO{i}", "type": "u32" } } },
    "0x1801": { "name": "Special TPDO", "subs": { "2": { "name": "Transmission type", "type": "u8" } } },
    "0x1A00:0": { "name": "Number of mapped objects", "type": "u8" },
    "0x1600..0x17FF": { "name": "RPDO{i} mapping parameter", "subs": {
        "0": { "name": "Number of mapped objects", "type": "u8" },
        "1..64": { "name": "Mapped object {n}", "type": "u32" } } },
    "0x1601:0": { "name": "Number of entries", "type": "u8", "access": "ro" }
  },
  "aliases": { "P-speed": "0x2005:3" },
  "alias_rules": [ { "pattern": "H{xx:hex}-{yy}", "index": "0x2000 + xx", "sub": "yy + 1" } ],
  "emcy": {
    "codes": { "0x8681": "Axis A following error" },
    "manufacturer_fields": [ { "name": "M1 alarm code", "offset": 6, "values": { "1": "Over-current" } },
                             { "name": "M2 alarm code", "offset": 7 } ]
  },
  "pdo_sets": [
    { "name": "mapping-0", "selected_by": { "object": "09-26", "value": 0 },
      "tpdo": { "1": { "cob_id": "0x180 + node", "entries": ["0x6041/16", "0x606C:0/32"] } } },
    { "name": "mapping-1", "default": true,
      "tpdo": { "1": { "cob_id": "0x1A0", "transmission_type": 255, "entries": ["0x30460108"] } } }
  ],
  "sdo_commands": [ { "command": "0xE8", "direction": "response", "name": "Axis A and B",
    "fields": [ { "name": "index", "offset": 1, "length": 2, "format": "hex" },
                { "name": "A", "offset": 4, "length": 2, "signed": true, "object": "index" } ] } ],
  "procedures": { "pv": {
    "params": [ { "name": "speed", "unit": "rpm" } ],
    "steps": [ { "nmt": "start" },
               { "sdo_write": { "object": "0x60FF", "value": "speed * 10", "type": "i32" } },
               { "wait": { "mask": "0x6F", "equals": "0x27" } },
               { "frame": { "id": "0x600 + node", "data": "2B 40 60 00 {u16:0x0F} 00 00" } },
               { "delay_ms": 10 } ] } },
  "axes": [ { "name": "M1", "objects": ["0x3046", "0x303F:0x11", "0x6000..0x67FF"], "emcy_field": "M1 alarm code" } ]
}"#;

#[test]
fn good_profile_loads_everything() {
    let (p, w) = load_profile("demo.json", GOOD).unwrap();
    assert_eq!(w, vec![]);
    assert_eq!(p.name, "demo");
    assert_eq!(p.extends, vec!["cia402"]);
    let v = p.object(0x606C, 0).unwrap();
    assert_eq!(
        (v.data_type, v.access, v.pdo),
        (DataType::I32, Access::Ro, PdoMappable::Tpdo)
    );
    assert_eq!(super::super::format_value(Some(v), &Value::Signed(15000)), "1500 rpm");
    assert_eq!(
        p.object(0x6060, 0).unwrap().values.get(&-1).map(String::as_str),
        Some("Vendor")
    );
    assert_eq!(p.object_names.get(&0x1018).map(String::as_str), Some("Identity object"));
    assert_eq!(p.object(0x1018, 1).unwrap().name, "Vendor-ID");
    assert_eq!(p.object(0x1018, 0).unwrap().default, Some(Value::Unsigned(4)));
    assert_eq!(p.object(0x1016, 3).unwrap().name, "Consumer heartbeat time 3");
    assert_eq!(p.object(0x1008, 0).unwrap().default, Some(Value::Text("DEV".into())));
    assert_eq!(p.object_name(0x19FF), Some("TPDO512 communication parameter"));
    assert_eq!(p.object(0x1800, 1).unwrap().name, "COB-ID used by TPDO1");
    assert_eq!(p.object_name(0x1801), Some("Special TPDO"));
    assert_eq!(p.object(0x1801, 1), None);
    assert_eq!(p.object(0x1801, 2).unwrap().name, "Transmission type");
    assert_eq!(p.object(0x1A00, 0).unwrap().name, "Number of mapped objects");
    // A record range without {i} in its subs is kept once, not per index.
    assert_eq!(p.ranges.len(), 1);
    assert_eq!(p.object_name(0x17FF), Some("RPDO512 mapping parameter"));
    assert_eq!(p.object(0x17FF, 64).unwrap().name, "Mapped object 64");
    assert_eq!(p.object(0x17FF, 65), None);
    // A flat key inside the range changes one sub and keeps the others.
    assert_eq!(p.object(0x1601, 0).unwrap().name, "Number of entries");
    assert_eq!(p.object(0x1601, 0).unwrap().access, Access::Ro);
    assert_eq!(p.object(0x1601, 2).unwrap().name, "Mapped object 2");
    assert_eq!(p.object(0x1602, 0).unwrap().name, "Number of mapped objects");
    assert_eq!(p.aliases.get("P-speed"), Some(&(0x2005, 3)));
    assert_eq!(p.alias_rules[0].apply("H12-20"), Some((0x2012, 21)));
    assert_eq!(
        p.emcy_codes.get(&0x8681).map(String::as_str),
        Some("Axis A following error")
    );
    assert_eq!(p.emcy_fields[0].format(1), "1 (Over-current)");
    // mapping-1 is the default; its constant COB-ID is known without a node.
    assert_eq!(p.tpdo[&1].cob_id, Some(0x1A0));
    assert_eq!(
        p.tpdo[&1].entries,
        vec![MappedEntry {
            index: 0x3046,
            sub: 1,
            bits: 8
        }]
    );
    let set0 = &p.pdo_sets[0];
    assert_eq!(set0.selected_by, Some(("09-26".to_string(), 0)));
    let m = set0.mappings(true, Some(5), &MappingSource::Profile("demo".into()));
    assert_eq!(m[&1].cob_id, Some(0x185));
    assert_eq!(
        m[&1].entries[1],
        MappedEntry {
            index: 0x606C,
            sub: 0,
            bits: 32
        }
    );
    assert_eq!(
        set0.mappings(true, None, &MappingSource::Eds("x".into()))[&1].cob_id,
        None
    );
    let d = p
        .sdo_command(0xE8, SdoDirection::Response)
        .unwrap()
        .decode(&[0xE8, 4, 0x50, 0, 0xB7, 0x13]);
    assert_eq!(d[1].object, Some((0x5004, 0)));
    let proc = &p.procedures["pv"];
    assert_eq!(proc.steps.len(), 5);
    assert!(matches!(
        proc.steps[0],
        Step::Nmt {
            command: NmtCommand::Start,
            node: None
        }
    ));
    assert!(matches!(&proc.steps[2], Step::Wait { object, timeout_ms: 1000, .. } if object == "0x6041"));
    assert_eq!(p.axis_of(0x303F, 0x11).map(|a| a.name.as_str()), Some("M1"));
    assert_eq!(p.axis_of(0x303F, 0x12), None);
    assert_eq!(p.axis_of(0x6041, 0).map(|a| a.name.as_str()), Some("M1"));
    let ident = |i: u16, _s: u8| match i {
        0x1000 => Some(Value::Unsigned(0x0002_0192)),
        0x1008 => Some(Value::Text("DEV-200\0".into())),
        _ => None,
    };
    assert!(p.identifies(&ident));
    assert!(!p.identifies(&|i, s| if i == 0x1000 {
        Some(Value::Unsigned(0x191))
    } else {
        ident(i, s)
    }));
}

#[test]
fn syntax_error_is_located() {
    let text = "{\n  \"name\": \"x\",\n  \"objects\": {\n    \"0x6041\": { \"name\": \"S\" },,\n  }\n}";
    let e = load_profile("bad.json", text).unwrap_err();
    assert_eq!((e.file.as_str(), e.line), ("bad.json", 4));
    assert!(e.to_string().starts_with("bad.json:4:"), "{e}");
}

#[test]
fn wrong_json_type_names_the_path() {
    let e = load_profile(
        "t.json",
        r#"{"name": "x", "objects": {"0x6041": {"name": "S", "subs": [1]}}}"#,
    )
    .unwrap_err();
    assert_eq!(e.path, "objects.0x6041.subs");
    let e = load_profile("t.json", r#"{"objects": {}}"#).unwrap_err();
    assert!(e.message.contains("missing field `name`"), "{e}");
    let e = load_profile("t.json", r#"{"name": "x"} trailing"#).unwrap_err();
    assert_eq!(e.line, 1);
}

#[test]
fn unknown_fields_types_and_bad_values_are_warnings() {
    let text = r#"{ "name": "x", "colour": "red",
      "objects": {
        "0x6041": { "name": "Statusword", "type": "u17", "acess": "ro" },
        "0x6060": { "name": "Modes", "type": "i8", "access": "rx", "values": { "three": "PV", "3": "PV" } },
        "nonsense": { "name": "N" },
        "0x2000": { "type": "u8" },
        "0x2001": { "name": "COB", "type": "u16", "meaning": "cobid" },
        "0x1016": { "name": "HB", "subs": { "9..1": { "name": "x" }, "1": { "name": "Consumer 1" } } },
        "0x0000..0xFFFF": { "name": "huge", "subs": { "0..255": { "name": "x{i}" } } },
        "0x3000..0x2000": { "name": "backwards" }
      },
      "alias_rules": [ { "pattern": "F{x}{y}", "index": "x" }, { "pattern": "P{x}", "index": "x +" } ],
      "emcy": { "codes": { "0x1FFFF": "too big" }, "manufacturer_fields": [ { "name": "b", "offset": 7, "length": 2 } ] },
      "tpdo": { "1": { "entries": ["0x6041/0", "0x6041:0/16"] }, "600": { "entries": [] } },
      "procedures": { "bad": { "steps": [ { "jump": 3 } ] },
                      "unknown_var": { "steps": [ { "sdo_write": { "object": "0x6040", "value": "spd" } } ] } }
    }"#;
    let (p, w) = load_profile("w.json", text).unwrap();
    let at: Vec<&str> = w.iter().map(|w| w.at.as_str()).collect();
    for expected in [
        "colour",
        "objects.0x6041.acess",
        "objects.0x6041.type",
        "objects.0x6060.access",
        "objects.0x6060.values.three",
        "objects.nonsense",
        "objects.0x2000",
        "objects.0x2001.meaning",
        "objects.0x1016.subs.9..1",
        "objects.0x0000..0xFFFF",
        "objects.0x3000..0x2000",
        "alias_rules.0",
        "alias_rules.1",
        "emcy.codes.0x1FFFF",
        "emcy.manufacturer_fields.0",
        "tpdo.1.entries.0",
        "tpdo.600",
        "procedures.bad.steps.0",
        "procedures.unknown_var",
    ] {
        assert!(at.contains(&expected), "no warning at {expected}: {w:#?}");
    }
    assert_eq!(w.len(), 19, "{w:#?}");
    assert_eq!(p.object(0x2001, 0).unwrap().meaning, None);
    // The rest loaded.
    assert_eq!(p.object(0x6041, 0).unwrap().data_type, DataType::Domain);
    assert_eq!(
        p.object(0x6060, 0).unwrap().values.get(&3).map(String::as_str),
        Some("PV")
    );
    assert_eq!(p.object(0x1016, 1).unwrap().name, "Consumer 1");
    assert_eq!(p.tpdo[&1].entries.len(), 1);
    assert!(p.procedures.is_empty());
    assert!(w[0].to_string().starts_with("w.json: "));
}

#[test]
fn single_subs_win_over_ranges_and_overlaps_are_located() {
    // JSON key order puts the single sub first and the range after it; the single sub still wins.
    let text = r#"{ "name": "x", "objects": {
        "0x3046": { "name": "Monitor", "subs": {
            "1": { "name": "Motor State", "type": "u8" },
            "1..32": { "name": "Monitor Data {n}", "type": "u16" },
            "0x02": { "name": "Alarm Code", "type": "u8" } } },
        "0x304A": { "name": "Clash", "subs": {
            "1..8": { "name": "A {n}", "type": "u8" },
            "5..9": { "name": "B {n}", "type": "u8" },
            "3": { "name": "Three", "type": "u8" },
            "0x03": { "name": "Also three", "type": "u8" } } }
    } }"#;
    let (p, w) = load_profile("o.json", text).unwrap();
    let m = p.object(0x3046, 1).unwrap();
    assert_eq!((m.name.as_str(), m.data_type), ("Motor State", DataType::U8));
    assert_eq!(p.object(0x3046, 2).unwrap().name, "Alarm Code");
    let d = p.object(0x3046, 3).unwrap();
    assert_eq!((d.name.as_str(), d.data_type), ("Monitor Data 3", DataType::U16));
    assert_eq!(p.object(0x3046, 32).unwrap().name, "Monitor Data 32");
    // Overlapping ranges and duplicate single subs: located warnings, the later key skipped.
    let located: Vec<String> = w.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 2, "{located:#?}");
    assert!(located[0].starts_with("o.json: objects.0x304A.subs.5..9: range `5..9` overlaps `1..8`"));
    assert!(located[1].starts_with("o.json: objects.0x304A.subs.3: sub `3` overlaps `0x03`"));
    assert_eq!(p.object(0x304A, 8).unwrap().name, "A 8");
    assert!(p.object(0x304A, 9).is_none());
}

#[test]
fn deeply_nested_expressions_are_located_errors() {
    let parens = format!("{}1{}", "(".repeat(20_000), ")".repeat(20_000));
    let minus = format!("{}1", "-".repeat(100_000));
    let conds = format!("{}0", "1 ? 0 : ".repeat(20_000));
    let text = serde_json::json!({
        "name": "deep",
        "alias_rules": [
            { "pattern": "P{x}", "index": parens },
            { "pattern": "Q{x}", "index": "0x2000 + x", "sub": conds },
            { "pattern": "R{x}", "index": "0x2000 + x" }
        ],
        "procedures": {
            "minus": { "steps": [ { "sdo_write": { "object": "0x6040", "value": minus } } ] },
            "cond": { "steps": [ { "wait": { "equals": conds } } ] },
            "frame": { "steps": [ { "frame": { "id": "0x600", "data": format!("{{u8:{parens}}}") } } ] },
            "object": { "steps": [ { "sdo_read": { "object": format!("0x3000:{{{minus}}}") } } ] },
            "fine": { "steps": [ { "sdo_write": { "object": "0x6040", "value": "-(-(15))" } } ] }
        }
    })
    .to_string();
    let (p, w) = load_profile("deep.json", &text).unwrap();
    let at: Vec<&str> = w.iter().map(|w| w.at.as_str()).collect();
    assert_eq!(
        at,
        [
            "alias_rules.0",
            "alias_rules.1",
            "procedures.cond.steps.0",
            "procedures.frame.steps.0",
            "procedures.minus.steps.0",
            "procedures.object.steps.0"
        ]
    );
    assert!(
        w.iter().all(|w| w.message.contains("nests deeper than 200 levels")),
        "{w:?}"
    );
    assert_eq!(p.alias_rules.len(), 1);
    assert_eq!(p.procedures.keys().collect::<Vec<_>>(), ["fine"]);
}

#[test]
fn value_fields_must_fit_the_type() {
    let text = r#"{ "name": "f", "objects": {
        "0x1016:1": { "name": "HB", "type": "u32", "fields": [
            { "name": "node", "offset": 2 }, { "name": "time", "offset": 0, "length": 2, "unit": "ms" },
            { "name": "beyond", "offset": 3, "length": 2 }, { "name": "odd", "offset": 0, "format": "bcd" } ] }
    } }"#;
    let (p, w) = load_profile("f.json", text).unwrap();
    let at: Vec<&str> = w.iter().map(|w| w.at.as_str()).collect();
    assert_eq!(
        at,
        ["objects.0x1016:1.fields.2", "objects.0x1016:1.fields.3.format"],
        "{w:?}"
    );
    let names: Vec<&str> = p
        .object(0x1016, 1)
        .unwrap()
        .fields
        .iter()
        .map(|f| f.name.as_str())
        .collect();
    assert_eq!(names, ["node", "time", "odd"]);
}

#[test]
fn range_names_fill_every_slot_and_keep_other_braces() {
    assert_eq!(super::fill("TPDO{i} map {i}", "{i}", 512), "TPDO512 map 512");
    assert_eq!(super::fill("A {n} {x} {", "{n}", 0), "A 0 {x} {");
    assert_eq!(super::fill("none", "{n}", 7), "none");
    assert_eq!(super::fill("{n}", "{n}", u32::MAX), "4294967295");
}

/// Every entry of `p` by (index, sub), as `object` gives it, with its name.
fn all_entries(p: &Profile) -> Vec<((u16, u8), String)> {
    let indexes = [0x1003, 0x1016, 0x3046, 0x3047];
    let looked_up = indexes
        .iter()
        .flat_map(|&i| (0..=255).map(move |s| (i, s)))
        .filter_map(|(i, s)| p.object(i, s).map(|o| ((i, s), o.name.clone())));
    let listed: Vec<((u16, u8), String)> = p.entries().map(|(k, o)| (k, o.name.clone())).collect();
    assert_eq!(
        listed,
        looked_up.collect::<Vec<_>>(),
        "entries() lists what object() finds"
    );
    listed
}

#[test]
fn sub_ranges_give_the_same_entries_as_the_subs_written_out() {
    let ranges = r#"{ "name": "x", "objects": {
        "0x1003": { "name": "Errors", "subs": {
            "0": { "name": "Count", "type": "u8" },
            "1..254": { "name": "Error {n}", "type": "u32", "values": { "1": "one" } } } },
        "0x1003:7": { "name": "Seventh", "type": "u16" },
        "0x3046": { "name": "Monitor", "subs": {
            "1..3": { "name": "Low {n}", "type": "u8" },
            "2": { "name": "Two", "type": "u8" },
            "10..11": { "name": "High {n}", "type": "u8" } } },
        "0x3047": { "name": "Old", "subs": { "1..9": { "name": "Old {n}", "type": "u8" } } },
        "0x3047:0": { "name": "Replaced", "subs": { "1": { "name": "New", "type": "u8" } } }
    } }"#;
    let mut subs: Vec<String> = vec![r#""0": { "name": "Count", "type": "u8" }"#.into()];
    subs.extend(
        (1..=254).map(|n| format!(r#""{n}": {{ "name": "Error {n}", "type": "u32", "values": {{ "1": "one" }} }}"#)),
    );
    let written_out = format!(
        r#"{{ "name": "x", "objects": {{
        "0x1003": {{ "name": "Errors", "subs": {{ {} }} }},
        "0x1003:7": {{ "name": "Seventh", "type": "u16" }},
        "0x3046": {{ "name": "Monitor", "subs": {{
            "1": {{ "name": "Low 1", "type": "u8" }}, "2": {{ "name": "Two", "type": "u8" }},
            "3": {{ "name": "Low 3", "type": "u8" }},
            "10": {{ "name": "High 10", "type": "u8" }}, "11": {{ "name": "High 11", "type": "u8" }} }} }},
        "0x3047": {{ "name": "Replaced", "subs": {{ "1": {{ "name": "New", "type": "u8" }} }} }}
    }} }}"#,
        subs.join(",")
    );
    let (p, w) = load_profile("r.json", ranges).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let (q, w) = load_profile("o.json", &written_out).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let got = all_entries(&p);
    assert_eq!(got, all_entries(&q));
    assert_eq!(got.len(), 255 + 5 + 1, "each entry once");
    assert_eq!(
        p.object(0x1003, 7).unwrap().data_type,
        DataType::U16,
        "a later single key wins"
    );
    assert_eq!(p.object(0x1003, 254).unwrap().values[&1], "one");
    assert!(p.object(0x1003, 255).is_none() && p.object(0x3046, 4).is_none() && p.object(0x3047, 2).is_none());
    let at: Vec<(u8, &str)> = p
        .entries_at(0x3046)
        .into_iter()
        .map(|(s, o)| (s, o.name.as_str()))
        .collect();
    assert_eq!(
        at,
        [(1, "Low 1"), (2, "Two"), (3, "Low 3"), (10, "High 10"), (11, "High 11")]
    );
}

#[test]
fn the_first_layer_with_an_entry_wins_over_a_lower_layers_sub_range() {
    let vendor = r#"{ "name": "v", "objects": {
        "0x1003:5": { "name": "Vendor fifth", "type": "u32" },
        "0x1016": { "name": "Heartbeats", "subs": { "1..2": { "name": "Vendor heartbeat {n}", "type": "u32" } } } } }"#;
    let (vendor, _) = load_profile("v.json", vendor).unwrap();
    let (cia301, _) = crate::od::bind::load_builtin("cia301").unwrap().unwrap();
    let dict = crate::od::Dictionary::new(vec![std::sync::Arc::new(vendor), std::sync::Arc::new(cia301)]);
    let name = |i, s| dict.object(i, s).map(|o| o.name.as_str());
    assert_eq!(name(0x1003, 5), Some("Vendor fifth"));
    assert_eq!(name(0x1003, 6), Some("Standard error field 6"));
    assert_eq!(name(0x1016, 2), Some("Vendor heartbeat 2"));
    assert_eq!(name(0x1016, 3), Some("Consumer heartbeat time 3"));
    assert_eq!(name(0x1016, 128), None);
}

#[test]
fn index_range_names_are_listed_and_resolved_like_record_names() {
    let (p, _) = load_profile("g.json", GOOD).unwrap();
    let names = p.names();
    assert_eq!(names[&0x1600], "RPDO1 mapping parameter");
    assert_eq!(names[&0x17FF], "RPDO512 mapping parameter");
    assert_eq!(names[&0x1801], "Special TPDO", "a record's own name wins");
    assert_eq!(names[&0x1018], "Identity object");
    assert!(p.object_name(0x15FF).is_none() && !names.contains_key(&0x1A01));
    let dict = crate::od::Dictionary::new(vec![std::sync::Arc::new(p)]);
    assert_eq!(dict.object_name(0x1602), Some("RPDO3 mapping parameter"));
    assert_eq!(
        crate::od::resolve_object(&dict, "rpdo3 mapping parameter:2"),
        Ok((0x1602, 2))
    );
}

#[test]
fn finding_an_entry_or_a_name_gives_the_first_in_index_order() {
    let text = r#"{ "name": "x", "objects": {
        "0x1003": { "name": "Errors", "subs": { "1..254": { "name": "Error {n}", "type": "u32" } } },
        "0x1003:7": { "name": "Error 9", "type": "u16", "alias": "E7" },
        "0x1002": { "name": "Error 200", "type": "u8" },
        "0x1A00": { "name": "Special", "subs": { "0": { "name": "Error 8", "type": "u8" } } },
        "0x1A00..0x1A03": { "name": "Map {i}", "subs": { "0": { "name": "Count", "type": "u8" } } },
        "0x1A02": { "name": "Map 1", "subs": { "0": { "name": "Count", "type": "u8" } } }
    } }"#;
    let (p, w) = load_profile("f.json", text).unwrap();
    assert!(w.is_empty(), "{w:?}");
    for name in [
        "Error 9",
        "Error 8",
        "Error 200",
        "Error 7",
        "Error 254",
        "Count",
        "Nothing",
    ] {
        let found = p.find_entry(|o| o.name == name).map(|(k, _)| k);
        assert_eq!(
            found,
            p.entries().find(|(_, o)| o.name == name).map(|(k, _)| k),
            "{name}"
        );
    }
    assert_eq!(p.find_entry(|o| o.name == "Error 9").unwrap().0, (0x1003, 7));
    assert_eq!(
        p.find_entry(|o| o.name == "Error 7"),
        None,
        "overridden by the single key"
    );
    let names = p.names();
    for name in ["Map 1", "Map 2", "Map 4", "Special", "Errors", "Map 5"] {
        let first = names.iter().find(|(_, n)| **n == name).map(|(i, _)| *i);
        assert_eq!(p.find_name(|n| n == name), first, "{name}");
    }
    assert_eq!(p.find_name(|n| n == "Map 1"), Some(0x1A02), "0x1A00 has its own name");
}
