//! EDS/DCF import against fixture files in `tests/fixtures/eds/`.

use cotui::od::eds::{import, parse_number};
use cotui::od::{Access, Bindings, DataType, MappedEntry, MappingSource, PdoMappable, Value, resolve_object};

fn fixture(name: &str) -> String {
    std::fs::read_to_string(format!("{}/tests/fixtures/eds/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn entry(index: u16, sub: u8, bits: u8) -> MappedEntry {
    MappedEntry { index, sub, bits }
}

#[test]
fn realistic_vendor_eds() {
    let (p, w) = import("servo-ds.eds", &fixture("servo-ds.eds"), 2);
    assert_eq!(w, vec![]);
    assert_eq!(p.name, "servo-ds.eds");
    assert_eq!(p.description, "Example Motion Co. SERVO-DS");
    assert_eq!(p.object_names[&0x1018], "Identity object");
    let vendor = p.object(0x1018, 1).unwrap();
    assert_eq!(
        (vendor.name.as_str(), vendor.data_type, vendor.access),
        ("Vendor ID", DataType::U32, Access::Ro)
    );
    assert_eq!(vendor.default, Some(Value::Unsigned(0x2E1)));
    assert_eq!(p.object(0x1014, 0).unwrap().default, Some(Value::Unsigned(0x82)));
    assert_eq!(p.object(0x1200, 1).unwrap().default, Some(Value::Unsigned(0x602)));
    assert_eq!(
        p.object(0x1008, 0).unwrap().default,
        Some(Value::Text("SERVO-DS".into()))
    );
    let sw = p.object(0x6041, 0).unwrap();
    assert_eq!((sw.data_type, sw.pdo), (DataType::U16, PdoMappable::Tpdo));
    assert_eq!(p.object(0x6040, 0).unwrap().pdo, PdoMappable::Rpdo);
    assert_eq!(p.object(0x6060, 0).unwrap().data_type, DataType::I8);
    let gain = p.object(0x2318, 0).unwrap();
    assert_eq!(
        (gain.min, gain.max, gain.default.clone()),
        (Some(0), Some(5000), Some(Value::Unsigned(200)))
    );

    let eds = MappingSource::Eds("servo-ds.eds".into());
    assert_eq!(p.rpdo[&1].entries, vec![entry(0x6040, 0, 16), entry(0x6060, 0, 8)]);
    assert_eq!(p.rpdo[&1].cob_id, Some(0x202));
    assert_eq!(p.rpdo[&1].source, eds);
    assert_eq!(p.rpdo[&4].entries, vec![entry(0x60FF, 0, 32)]);
    assert_eq!(p.rpdo[&4].cob_id, Some(0x502));
    assert_eq!(
        p.tpdo[&1].entries,
        vec![entry(0x6041, 0, 16), entry(0x6060, 0, 8), entry(0x603F, 0, 16)]
    );
    assert_eq!(p.tpdo[&2].cob_id, Some(0x282));
    assert_eq!(p.tpdo[&3].entries, vec![entry(0x60FD, 0, 32)]);
    // TPDO4 is disabled (bit 31) and has no entries.
    assert!(!p.tpdo.contains_key(&4));
    // The identity in [DeviceInfo] identifies the device.
    let id = |i: u16, s: u8| match (i, s) {
        (0x1018, 1) => Some(Value::Unsigned(0x2E1)),
        (0x1018, 2) => Some(Value::Unsigned(0x0001_0042)),
        _ => None,
    };
    assert!(p.identifies(&id));
}

#[test]
fn dcf_tolerances() {
    let (p, w) = import("quirks.dcf", &fixture("quirks.dcf"), 5);
    let at = |line: usize| {
        w.iter()
            .find(|x| x.at == format!("line {line}"))
            .map(|x| x.message.clone())
            .unwrap_or_else(|| panic!("no warning at line {line}: {w:#?}"))
    };
    assert!(at(2).contains("outside any section"));
    assert!(at(15).contains("0x1001 is listed but has no [1001] section"));
    assert!(at(25).contains("0x1003 is listed but has no [1003] section"));
    assert!(at(29).contains("not-a-number"));
    assert!(at(133).contains("unknown DataType 0x0042"));
    assert!(at(134).contains("unknown AccessType `readwrite`"));
    assert!(at(135).contains("`zz`"));
    assert!(at(136).contains("neither [section] nor key=value"));
    assert!(at(137).contains("[2200sub1] has no parent"));
    assert_eq!(w.len(), 9, "{w:#?}");
    assert!(w[0].to_string().starts_with("quirks.dcf: line 2: "));

    // [DeviceComissioning] (CiA 306 spelling) gives node id and name.
    assert_eq!((p.node_id, p.node_name.as_deref()), (Some(5), Some("left wheel")));
    // Any section/key case; ParameterValue wins over DefaultValue.
    assert_eq!(p.object(0x1018, 1).unwrap().name, "Vendor-ID");
    assert_eq!(p.object(0x1018, 1).unwrap().default, Some(Value::Unsigned(0x13)));
    assert_eq!(p.object(0x1018, 0).unwrap().access, Access::Const);
    // Octal and negative numbers, limits, rwr/rww.
    let gain = p.object(0x2000, 0).unwrap();
    assert_eq!(
        (gain.default.clone(), gain.access, gain.pdo),
        (Some(Value::Unsigned(8)), Access::Rwr, PdoMappable::Tpdo)
    );
    let off = p.object(0x2001, 0).unwrap();
    assert_eq!(
        (off.default.clone(), off.min, off.max),
        (Some(Value::Signed(-12)), Some(-100), Some(100))
    );
    assert_eq!((off.access, off.pdo), (Access::Rww, PdoMappable::Rpdo));
    // Unknown type/access fall back and the rest of the object loads.
    let weird = p.object(0x2100, 0).unwrap();
    assert_eq!(
        (weird.name.as_str(), weird.data_type, weird.access),
        ("Weird", DataType::Domain, Access::Rw)
    );
    // A present but unlisted section is imported; floats parse.
    assert_eq!(p.object(0x2300, 0).unwrap().default, Some(Value::Float(1.5)));
    // CompactSubObj: sub 0 = count, names/values from [1016Name]/[1016Value].
    assert_eq!(p.object(0x1016, 0).unwrap().default, Some(Value::Unsigned(3)));
    assert_eq!(p.object(0x1016, 1).unwrap().name, "Consumer heartbeat time 1");
    assert_eq!(p.object(0x1016, 1).unwrap().default, Some(Value::Unsigned(0x0009_03E8)));
    assert_eq!(p.object(0x1016, 2).unwrap().name, "Heartbeat of node 9");
    assert_eq!(p.object(0x1016, 3).unwrap().data_type, DataType::U32);
    assert!(p.object(0x1016, 4).is_none());
    // 0x200+$NODEID, $NODEID + 0x190 (ParameterValue), mapping count from ParameterValue,
    // [1a00sub01] with a leading zero.
    assert_eq!(p.rpdo[&1].cob_id, Some(0x205));
    assert_eq!(p.rpdo[&1].entries, vec![entry(0x6040, 0, 16), entry(0x6060, 0, 8)]);
    assert_eq!(p.tpdo[&1].cob_id, Some(0x195));
    assert_eq!(p.tpdo[&1].entries, vec![entry(0x6041, 0, 16)]);
}

#[test]
fn dcf_node_id_differing_from_binding_is_a_warning() {
    let (p, w) = import("quirks.dcf", &fixture("quirks.dcf"), 6);
    assert!(
        w.iter()
            .any(|x| x.at == "line 8" && x.message.contains("NodeID 5 in the file, bound to node 6"))
    );
    assert_eq!(p.rpdo[&1].cob_id, Some(0x206));
}

#[test]
fn correct_spelling_of_commissioning_section() {
    let text = "[DeviceInfo]\n[DeviceCommissioning]\nNodeID=0x0A\nNodeName=arm\n";
    let (p, _) = import("a.dcf", text, 10);
    assert_eq!((p.node_id, p.node_name.as_deref()), (Some(10), Some("arm")));
}

#[test]
fn missing_sections_are_warnings() {
    let (p, w) = import("minimal.eds", &fixture("minimal.eds"), 1);
    let messages: Vec<String> = w.iter().map(|x| x.to_string()).collect();
    assert!(messages.iter().any(|m| m.contains("no [DeviceInfo]")), "{messages:#?}");
    assert!(
        messages.iter().any(|m| m.contains("importing every object section")),
        "{messages:#?}"
    );
    assert!(
        messages
            .iter()
            .any(|m| m.starts_with("minimal.eds: line 6:") && m.contains("no `]`")),
        "{messages:#?}"
    );
    assert_eq!(p.object(0x1017, 0).unwrap().default, Some(Value::Unsigned(1000)));
    let (p, w) = import("empty.eds", "", 1);
    assert!(p.objects.is_empty() && !w.is_empty());
}

#[test]
fn numbers() {
    assert_eq!(parse_number("$NODEID+0x180", 3), Ok(0x183));
    assert_eq!(parse_number("0x180+$NODEID", 3), Ok(0x183));
    assert_eq!(parse_number("$nodeid", 3), Ok(3));
    assert_eq!(parse_number(" $NODEID + 0x600 ", 127), Ok(0x67F));
    assert_eq!(parse_number("017", 0), Ok(15));
    assert_eq!(parse_number("0", 0), Ok(0));
    assert_eq!(parse_number("42", 0), Ok(42));
    assert_eq!(parse_number("-0x10", 0), Ok(-16));
    assert_eq!(parse_number("0XFF", 0), Ok(255));
    assert!(parse_number("09", 0).is_err());
    assert!(parse_number("", 0).is_err());
    assert!(parse_number("0x+", 0).is_err());
}

#[test]
fn eds_binding_puts_the_eds_first() {
    let read = |path: &std::path::Path| std::fs::read(path);
    let file = format!("3={}/tests/fixtures/eds/servo-ds.eds", env!("CARGO_MANIFEST_DIR"));
    let b = Bindings::from_args(&[], &[file], &read).unwrap();
    let d = b.dictionary(3);
    assert_eq!(d.profile_name(), "servo-ds.eds");
    assert_eq!(d.name(0x5004, 0), Some("Motor speed A"));
    assert_eq!(d.name(0x6502, 0), Some("Supported drive modes"));
    assert_eq!(d.default_pdos(true).unwrap()[&1].cob_id, Some(0x183));
    assert_eq!(resolve_object(d, "speed loop gain a"), Ok((0x2318, 0)));
    assert!(b.warnings().is_empty());
}

#[test]
fn vendor_quirks_inline_comments_signed_hex_limits_and_latin1_lines() {
    let text = b"[DeviceInfo]\nProductName=X\n[MandatoryObjects]\nSupportedObjects=1\n1=0x2000\n\
        [2000]\nParameterName=Offset\nDataType=0x0004\nAccessType=rw\nLowLimit=0x80000000\n\
        HighLimit=0x7FFFFFFF\nDefaultValue=0xFFFFFFFE ; two below zero\n\
        [Comments]\nLines=1\nLine1=Copyright \xA9 Gr\xFC\xDFe\n";
    let mut b = Bindings::new();
    b.bind_eds_bytes(4, "quirks.eds", text);
    let o = b.dictionary(4).object(0x2000, 0).unwrap();
    assert_eq!((o.min, o.max), (Some(-2147483648), Some(2147483647)));
    assert_eq!(o.default, Some(Value::Signed(-2)));
    let w: Vec<String> = b.warnings().iter().map(|w| w.to_string()).collect();
    assert_eq!(
        w,
        [
            "quirks.eds: line 15: not UTF-8, read as Windows-1252 (CP1252)",
            "quirks.eds: line 12: inline comment `; two below zero` after the value, ignored",
        ]
    );
    // Unsigned hex stays unsigned; decimal stays as written; INTEGER8 0xFF is -1.
    let (p, _) = import(
        "t.eds",
        "[MandatoryObjects]\nSupportedObjects=2\n1=0x2001\n2=0x2002\n[2001]\nParameterName=A\nDataType=0x0007\n\
         DefaultValue=0x80000000\n[2002]\nParameterName=B\nDataType=0x0002\nLowLimit=-128\nDefaultValue=0xFF\n",
        1,
    );
    assert_eq!(p.object(0x2001, 0).unwrap().default, Some(Value::Unsigned(0x8000_0000)));
    let i8 = p.object(0x2002, 0).unwrap();
    assert_eq!((i8.min, i8.default.clone()), (Some(-128), Some(Value::Signed(-1))));
}

/// The public EDS/DCF files in `../shared/realworld/eds/` (not part of this repository).
fn realworld_eds() -> Vec<std::path::PathBuf> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/eds");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (the shared real-world files sit beside the checkout)",
                dir.display()
            )
        })
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("eds") || x.eq_ignore_ascii_case("dcf"))
        })
        .collect();
    files.sort();
    files
}

#[test]
fn every_real_world_eds_and_dcf_imports_with_names_types_and_few_warning_kinds() {
    let files = realworld_eds();
    assert!(files.len() >= 40, "{} files", files.len());
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mut b = Bindings::new();
        b.bind_eds_bytes(5, &name, &std::fs::read(&path).unwrap());
        let d = b.dictionary(5);
        // Every file names the mandatory objects from its own text.
        let dt = d.object(0x1000, 0).unwrap_or_else(|| panic!("{name}: no 0x1000"));
        assert_eq!(dt.data_type, DataType::U32, "{name}");
        assert!(!dt.name.is_empty(), "{name}");
        // Grouped as the command line prints them, a file has a handful of warning lines.
        let lines = cotui::cli::bind::warning_lines(b.warnings(), false);
        assert!(lines.len() <= 6, "{name}: {lines:#?}");
    }
}

/// The python `canopen` library's reading of the real-world files (tests/realworld/eds_dump.py).
fn python_reference(files: &[std::path::PathBuf]) -> serde_json::Value {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/realworld/eds_dump.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .args(files)
        .stderr(std::process::Stdio::null())
        .output()
        .expect("python3 runs (scripts/install-test-deps.sh installs it with canopen)");
    assert!(
        out.status.success(),
        "eds_dump.py failed: is canopen installed? (scripts/install-test-deps.sh)"
    );
    serde_json::from_slice(&out.stdout).expect("eds_dump.py prints JSON")
}

#[test]
fn real_world_files_agree_with_python_canopen_on_names_types_and_pdo_mappings() {
    let files = realworld_eds();
    let reference = python_reference(&files);
    let mut compared = 0;
    let mut mismatches = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let py = &reference[path.to_string_lossy().as_ref()];
        let Some(objects) = py["objects"].as_object() else {
            continue; // the library cannot read this file: no reference
        };
        let mut b = Bindings::new();
        b.bind_eds_bytes(5, &name, &std::fs::read(path).unwrap());
        let d = b.dictionary(5);
        compared += 1;
        for (key, v) in objects {
            let (i, s) = key.split_once(':').unwrap();
            let (index, sub) = (u16::from_str_radix(i, 16).unwrap(), u8::from_str_radix(s, 16).unwrap());
            if index < 0x1000 {
                continue; // [DummyUsage] data type entries: type definitions, not objects on the bus
            }
            let Some(o) = d.object(index, sub) else {
                mismatches.push(format!("{name} {key}: python has `{}`, cotui has nothing", v[0]));
                continue;
            };
            let py_name = v[0].as_str().unwrap_or("");
            // Where the file gives no name python has "", cotui "<object> sub N"; array and
            // CompactSubObj entries python names like the object, cotui adds the sub-index.
            let numbered = o.name.strip_suffix(&format!(" {sub}")) == Some(py_name);
            if o.name != py_name && !py_name.is_empty() && !numbered {
                mismatches.push(format!("{name} {key}: name `{}` vs python `{py_name}`", o.name));
            }
            let code = v[1].as_u64().unwrap_or(0) as u16;
            if DataType::from_code(code).is_some_and(|t| t != o.data_type) {
                mismatches.push(format!("{name} {key}: type {:?} vs python 0x{code:04X}", o.data_type));
            }
        }
        for (key, v) in py["mapping"].as_object().unwrap() {
            let (i, s) = key.split_once(':').unwrap();
            let o = d.object(u16::from_str_radix(i, 16).unwrap(), u8::from_str_radix(s, 16).unwrap());
            let want = Some(Value::Unsigned(v.as_u64().unwrap()));
            if o.map(|o| o.default.clone()) != Some(want.clone()) {
                mismatches.push(format!(
                    "{name} {key}: mapping {:?} vs python {want:?}",
                    o.map(|o| &o.default)
                ));
            }
        }
    }
    assert!(compared >= 35, "python read only {compared} files");
    assert!(
        mismatches.is_empty(),
        "{} differences:\n{}",
        mismatches.len(),
        mismatches.join("\n")
    );
}

/// Label of an expedited SDO download of `value` (u16) to 0x6072 on node 3.
fn max_torque_label(dict: &cotui::od::Dictionary, value: u16) -> String {
    let [lo, hi] = value.to_le_bytes();
    let frame = cotui::frame::Frame::classic(0x603, &[0x2B, 0x72, 0x60, 0x00, lo, hi, 0, 0]);
    cotui::decode::Decoder::new(dict.clone(), vec![]).decode(&frame).label
}

#[test]
fn an_eds_without_units_takes_them_from_cia402() {
    let read = |path: &std::path::Path| std::fs::read(path);
    // A real vendor EDS (no units, like every EDS) and a minimal one written here.
    let dir = std::env::temp_dir().join(format!("cotui-eds-units-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let small = dir.join("small.eds");
    std::fs::write(
        &small,
        "[MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n[1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n\
         [OptionalObjects]\nSupportedObjects=1\n1=0x6072\n[6072]\nParameterName=Max torque (vendor)\nObjectType=0x7\nDataType=0x0006\nAccessType=rw\nDefaultValue=1000\n",
    )
    .unwrap();
    let real = format!(
        "{}/../shared/realworld/eds/kacanopen_cia402.eds",
        env!("CARGO_MANIFEST_DIR")
    );
    for file in [small.display().to_string(), real] {
        let b = Bindings::from_args(&[], &[format!("3={file}")], &read).unwrap();
        let d = b.dictionary(3);
        let o = d.object(0x6072, 0).unwrap();
        assert_eq!((o.unit.as_deref(), o.scale), (Some("%"), Some(0.1)), "{file}");
        let label = max_torque_label(d, 10000);
        assert!(label.contains("1000 %"), "{file}: {label}");
    }
    // The EDS's own name stays: only presentation is merged.
    let b = Bindings::from_args(&[], &[format!("3={}", small.display())], &read).unwrap();
    assert_eq!(b.dictionary(3).name(0x6072, 0), Some("Max torque (vendor)"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_huge_value_in_a_warning_is_cut_with_its_length() {
    let v = "1".repeat(10_000);
    let text = format!(
        "[DeviceInfo]\nVendorName=x\n\n[MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n\n[1000]\n\
         ParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\nDefaultValue={v}\n\nzz{v}\n"
    );
    let (_, warnings) = import("long.eds", &text, 1);
    let all: Vec<&str> = warnings.iter().map(|w| w.message.as_str()).collect();
    assert!(all.len() >= 2, "{all:?}");
    for m in &all {
        assert!(m.len() < 300, "{m}");
    }
    assert!(all.iter().any(|m| m.contains("…` (10002 characters)")), "{all:?}");
    assert!(all.iter().any(|m| m.contains("…` (10000 characters)")), "{all:?}");
}
