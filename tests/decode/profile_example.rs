//! The complete example profile (`tests/fixtures/profiles/example.json`, cited
//! by docs/PROFILE_FORMAT.md) loads without warnings and every part works.

use cotui::od::fields::SdoDirection;
use cotui::od::json::load_profile;
use cotui::od::procedure::{FrameItem, NmtCommand, Step, frame_bytes};
use cotui::od::{Bindings, Value, format_value, resolve_object};

const PATH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/profiles/example.json");

fn bindings() -> Bindings {
    let read = |p: &std::path::Path| std::fs::read(p);
    Bindings::from_args(&[format!("4={PATH}")], &[], &read).unwrap()
}

#[test]
fn loads_without_warnings() {
    let (p, w) = load_profile(PATH, &std::fs::read_to_string(PATH).unwrap()).unwrap();
    assert_eq!(w, vec![]);
    assert_eq!(p.name, "example-dual");
    assert!(bindings().warnings().is_empty());
}

#[test]
fn aliases_and_rules_resolve() {
    let b = bindings();
    let d = b.dictionary(4);
    assert_eq!(resolve_object(d, "F0.3.018"), Ok((0x2318, 0)));
    assert_eq!(resolve_object(d, "F1.1.002"), Ok((0x3102, 0)));
    assert_eq!(resolve_object(d, "D1.04"), Ok((0x5104, 0)));
    assert_eq!(resolve_object(d, "R0040"), Ok((0x4040, 0)));
    assert_eq!(resolve_object(d, "R7060"), Ok((0x5060, 0)));
    assert_eq!(resolve_object(d, "09-26"), Ok((0x2009, 27)));
    assert_eq!(resolve_object(d, "12-20"), Ok((0x200C, 21)));
    assert_eq!(resolve_object(d, "speed-a"), Ok((0x5004, 0)));
    assert_eq!(resolve_object(d, "Motor speed B"), Ok((0x5104, 0)));
    assert_eq!(resolve_object(d, "statusword"), Ok((0x6041, 0)));
    assert_eq!(format_value(d.object(0x5004, 0), &Value::Signed(15000)), "1500 rpm");
    assert_eq!(d.object(0x2009, 27).unwrap().alias.as_deref(), Some("09-26"));
}

#[test]
fn pdo_sets_emcy_and_axes() {
    let b = bindings();
    let d = b.dictionary(4);
    let rpdo = d.default_pdos(false).unwrap();
    assert_eq!(rpdo[&1].cob_id, None);
    assert_eq!(rpdo[&2].cob_id, Some(0x304));
    assert_eq!(d.default_pdos(true).unwrap()[&1].entries.len(), 3);
    let p = &d.layers()[1];
    assert_eq!(p.pdo_sets.len(), 2);
    assert_eq!(p.pdo_sets[1].selected_by, Some(("09-26".to_string(), 1)));
    assert_eq!(p.pdo_sets[1].tpdo[&1].entries[3].index, 0x304A);
    let emcy = [0x10, 0x23, 0x80, 0, 0, 0, 1, 2];
    let texts: Vec<String> = d
        .emcy_fields()
        .iter()
        .map(|f| f.format(f.raw(&emcy).unwrap()))
        .collect();
    assert_eq!(texts, vec!["1 (Over-current)", "2 (Over-voltage)"]);
    assert_eq!(d.emcy_text(0x8682), Some("Axis B following error"));
    assert_eq!(d.emcy_text(0x8611), Some("Following error"));
    assert_eq!(d.axis_of(0x304A, 5).map(|a| a.name.as_str()), Some("M2"));
    assert_eq!(d.axis_of(0x2318, 0).map(|a| a.name.as_str()), Some("M1"));
    assert_eq!(d.axis_of(0x6041, 0), None);
}

#[test]
fn vendor_sdo_command_decodes_both_axes() {
    let b = bindings();
    let d = b.dictionary(4);
    let cmd = d.sdo_command(0xE8, SdoDirection::Response).unwrap();
    let fields = cmd.decode(&[0xE8, 0x04, 0x50, 0x00, 0xB7, 0x13, 0xAB, 0x12]);
    let shown: Vec<String> = fields
        .iter()
        .filter_map(|f| {
            let (i, s) = f.object?;
            Some(format!(
                "{}={}",
                d.name(i, s)?,
                format_value(d.object(i, s), &Value::Signed(f.raw))
            ))
        })
        .collect();
    assert_eq!(shown, vec!["Motor speed A=504.7 rpm", "Motor speed B=477.9 rpm"]);
    let write = d
        .sdo_command(0xE9, SdoDirection::Request)
        .unwrap()
        .decode(&[0xE9, 0x18, 0x23, 0, 0x36, 0, 0xCA, 0xFF]);
    assert_eq!((write[2].raw, write[2].object), (54, Some((0x2318, 0))));
    assert_eq!((write[3].raw, write[3].object), (-54, Some((0x3318, 0))));
}

#[test]
fn procedures_and_identification() {
    let b = bindings();
    let d = b.dictionary(4);
    let pp = d.procedure("pp").unwrap();
    assert_eq!(pp.params[1].default, Some(100));
    let Step::Frame { id, data } = &pp.steps[2] else {
        panic!("{:?}", pp.steps[2])
    };
    let vars = |v: &str| match v {
        "node" => Some(4),
        "position" => Some(-2),
        _ => None,
    };
    assert_eq!(id.eval(&vars), Ok(0x604));
    assert!(matches!(data[4], FrameItem::Value(..)));
    assert_eq!(
        frame_bytes(data, &vars),
        Ok(vec![0x23, 0x7A, 0x60, 0x00, 0xFE, 0xFF, 0xFF, 0xFF])
    );
    assert!(matches!(
        &pp.steps[7],
        Step::Nmt {
            command: NmtCommand::PreOperational,
            node: Some(_)
        }
    ));
    assert_eq!(d.procedure("pv").unwrap().steps.len(), 8);
    assert!(d.procedure("nope").is_none());
    let id = |i: u16, s: u8| match (i, s) {
        (0x1000, 0) => Some(Value::Unsigned(0x0002_0192)),
        (0x1018, 1) => Some(Value::Unsigned(0x2E1)),
        (0x1008, 0) => Some(Value::Text("EXD-2A".into())),
        _ => None,
    };
    assert!(d.layers()[1].identifies(&id));
}

#[test]
fn doc_examples_load_without_warnings() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/PROFILE_FORMAT.md")).unwrap();
    let blocks: Vec<&str> = doc
        .split("```json\n")
        .skip(1)
        .filter_map(|b| b.split("```").next())
        .collect();
    // The fragments (except the top-level outline) together form one profile.
    let (mut objects, mut top, mut rules) = (Vec::new(), Vec::new(), Vec::new());
    for block in blocks.iter().map(|b| b.trim()).filter(|b| !b.contains("...")) {
        if block.starts_with("\"0x") {
            objects.push(block);
        } else if block.starts_with("{ \"pattern\"") {
            rules.push(block);
        } else {
            top.push(block);
        }
    }
    assert_eq!((objects.len(), rules.len(), top.len()), (1, 1, 6));
    let text = format!(
        "{{\"name\": \"doc\", \"objects\": {{ {} }}, {} }}",
        objects.join(","),
        top.join(",")
    );
    let (p, w) = load_profile("doc", &text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(w, vec![]);
    assert_eq!(p.procedures["pv"].steps.len(), 10);
    assert_eq!(p.axes.len(), 2);
    let text = format!("{{\"name\": \"doc\", \"alias_rules\": [ {} ] }}", rules.join(","));
    let (p, w) = load_profile("doc", &text).unwrap();
    assert_eq!(w, vec![]);
    assert_eq!(p.alias_rules[0].apply("R7060"), Some((0x5060, 0)));
}
