//! EDS/DCF (CiA 306) import: INI-style text in, a [`Profile`] and warnings out.
//!
//! Tolerant by design: sections and keys in any case, `$NODEID+0x180` and
//! `0x180+$NODEID`, hex/octal/decimal numbers, `CompactSubObj`, both spellings
//! of `[DeviceComissioning]`, inline ` ; comments` after values (dropped with a warning),
//! hex limits and defaults of signed types as two's complement (`LowLimit=0x80000000` on
//! an INTEGER32 is -2147483648). Every problem is a warning with its line number; nothing
//! here panics or fails.

use std::collections::BTreeMap;

use super::device::{IdCondition, IdTest};
use super::json::parse_access;
use super::mapping::{MappedEntry, MappingSource, PdoMapping};
use super::object::{Access, ObjectInfo, PdoMappable, Warning};
use super::profile::Profile;
use super::value::{DataType, Value};

/// One `[section]` with its `key=value` lines (keys lower-cased).
#[derive(Debug, Default)]
struct Section {
    line: usize,
    keys: Vec<(String, String, usize)>,
}

impl Section {
    /// The value and line of a key (case-insensitive; the last one wins).
    fn get(&self, key: &str) -> Option<(&str, usize)> {
        self.keys
            .iter()
            .rev()
            .find(|(k, _, _)| k == key)
            .map(|(_, v, l)| (v.as_str(), *l))
    }
}

/// The parsed file: sections by lower-cased name.
struct Ini {
    sections: BTreeMap<String, Section>,
}

impl Ini {
    /// The `[IIIIsubS]` sections of an object, by sub.
    fn sub_sections(&self, index: u16) -> BTreeMap<u8, &Section> {
        let prefix = format!("{index:04x}sub");
        self.sections
            .range(prefix.clone()..)
            .take_while(|(name, _)| name.starts_with(&prefix))
            .filter_map(|(name, sec)| match section_index(name) {
                Some((i, Some(sub))) if i == index => Some((sub, sec)),
                _ => None,
            })
            .collect()
    }
}

/// Sections read of one file: the largest real EDS files have about 1,200 (a section per
/// object and sub-object), so this is ~25 times that; memory stays proportional to it.
pub const MAX_SECTIONS: usize = 32_768;
/// `key=value` lines read of one file (real files have a few thousand).
pub const MAX_KEYS: usize = 131_072;

/// Splits the text into sections; malformed lines become warnings. Beyond
/// [`MAX_SECTIONS`] sections or [`MAX_KEYS`] keys, the rest of the file is not read (a
/// warning at the line where reading stopped).
fn parse_ini(text: &str, w: &mut Vec<(usize, String)>) -> Ini {
    let mut sections: BTreeMap<String, Section> = BTreeMap::new();
    let mut current: Option<String> = None;
    let mut keys = 0;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with(';') || t.starts_with('#') {
            continue;
        }
        let new_section = t.starts_with('[');
        if (new_section && sections.len() >= MAX_SECTIONS) || (!new_section && keys >= MAX_KEYS) {
            let (n, what) = match new_section {
                true => (MAX_SECTIONS, "sections"),
                false => (MAX_KEYS, "key=value lines"),
            };
            w.push((
                line,
                format!("more than {n} {what} (real EDS files have a few thousand): the rest of the file, from here, is not read"),
            ));
            break;
        }
        keys += usize::from(!new_section);
        if let Some(rest) = t.strip_prefix('[') {
            let Some(name) = rest.split_once(']').map(|(n, _)| n.trim().to_ascii_lowercase()) else {
                w.push((line, format!("section header `{t}` has no `]`, skipped")));
                current = None;
                continue;
            };
            if sections.contains_key(&name) {
                w.push((
                    line,
                    format!("section [{name}] appears again; its keys are merged, later ones win"),
                ));
            }
            sections
                .entry(name.clone())
                .or_insert(Section { line, keys: Vec::new() });
            current = Some(name);
            continue;
        }
        let Some((k, v)) = t.split_once('=') else {
            w.push((line, format!("`{t}` is neither [section] nor key=value, skipped")));
            continue;
        };
        // `DefaultValue=0x3ED ; prevent homing`: a comment after a blank is not the value.
        let v = match v.find(" ;").or_else(|| v.find("\t;")) {
            Some(at) => {
                w.push((
                    line,
                    format!("inline comment `{}` after the value, ignored", v[at..].trim()),
                ));
                &v[..at]
            }
            None => v,
        };
        match current.as_ref().and_then(|c| sections.get_mut(c)) {
            Some(sec) => sec
                .keys
                .push((k.trim().to_ascii_lowercase(), v.trim().to_string(), line)),
            None => w.push((line, format!("`{t}` is outside any section, skipped"))),
        }
    }
    Ini { sections }
}

/// A value in an EDS/DCF that does not read as its type.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EdsValueError {
    #[error("empty number")]
    Empty,
    #[error("`{0}` is not a number")]
    NotANumber(String),
    #[error("`{0}` overflows")]
    Overflow(String),
    #[error("`{0}` is not hex bytes")]
    NotHex(String),
}

/// Parses a CiA 306 number: `0x1A` hex, `017` octal, `42` decimal, `-5`, and
/// sums with `$NODEID` (`$NODEID+0x180`, `0x180+$NODEID`, `$NODEID`).
pub fn parse_number(text: &str, node: u8) -> Result<i64, EdsValueError> {
    let t = text.trim();
    if t.is_empty() {
        return Err(EdsValueError::Empty);
    }
    let mut total: i64 = 0;
    for term in t.split('+') {
        let term = term.trim();
        let v = if term.eq_ignore_ascii_case("$nodeid") {
            i64::from(node)
        } else {
            parse_plain(term).ok_or_else(|| EdsValueError::NotANumber(t.to_string()))?
        };
        total = total
            .checked_add(v)
            .ok_or_else(|| EdsValueError::Overflow(t.to_string()))?;
    }
    Ok(total)
}

fn parse_plain(t: &str) -> Option<i64> {
    let (neg, t) = match t.strip_prefix('-') {
        Some(r) => (true, r.trim_start()),
        None => (false, t),
    };
    let v = if let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        u64::from_str_radix(h, 16).ok()?
    } else if t.len() > 1 && t.starts_with('0') {
        u64::from_str_radix(&t[1..], 8).ok()?
    } else {
        t.parse::<u64>().ok()?
    };
    if neg {
        0i64.checked_sub_unsigned(v)
    } else {
        Some(v as i64)
    }
}

/// An object or sub-object section name: `1018` or `1018sub1` (hex, any case,
/// leading zeros allowed: `1018sub01`).
fn section_index(name: &str) -> Option<(u16, Option<u8>)> {
    let hex4 = |t: &str| {
        (t.len() == 4 && t.bytes().all(|b| b.is_ascii_hexdigit())).then(|| u16::from_str_radix(t, 16).ok())?
    };
    match name.split_once("sub") {
        Some((i, s)) if !s.is_empty() && s.len() <= 4 => Some((hex4(i)?, Some(u8::from_str_radix(s, 16).ok()?))),
        Some(_) => None,
        None => Some((hex4(name)?, None)),
    }
}

/// Context for one import.
struct Importer<'a> {
    file: &'a str,
    node: u8,
    warnings: Vec<Warning>,
    /// The line of each imported entry's section, for later warnings.
    lines: BTreeMap<(u16, u8), usize>,
}

/// The longest text quoted in a warning (between backticks) before it is cut.
const QUOTE_MAX: usize = 60;

/// `message` with every text between backticks longer than [`QUOTE_MAX`] characters cut to
/// its start, an ellipsis and its length (`` `1111…` (10000 characters) ``): a warning names
/// the value, it does not repeat a huge one.
fn clip_quoted(message: String) -> String {
    if message.len() <= QUOTE_MAX {
        return message;
    }
    let parts: Vec<&str> = message.split('`').collect();
    let mut out = String::with_capacity(message.len().min(512));
    for (i, part) in parts.iter().enumerate() {
        if i % 2 == 0 {
            out.push_str(part);
            continue;
        }
        let n = part.chars().count();
        if n > QUOTE_MAX {
            let head: String = part.chars().take(QUOTE_MAX - 20).collect();
            out.push_str(&format!("`{head}…` ({n} characters)"));
        } else {
            out.push('`');
            out.push_str(part);
            if i + 1 < parts.len() {
                out.push('`');
            }
        }
    }
    out
}

impl Importer<'_> {
    fn warn(&mut self, line: usize, message: impl Into<String>) {
        self.warnings.push(Warning {
            file: self.file.to_string(),
            at: format!("line {line}"),
            message: clip_quoted(message.into()),
        });
    }

    fn number(&mut self, sec: &Section, key: &str) -> Option<i64> {
        let (v, line) = sec.get(key)?;
        if v.is_empty() {
            return None;
        }
        match parse_number(v, self.node) {
            Ok(n) => Some(n),
            Err(e) => {
                self.warn(line, format!("{key}: {e}"));
                None
            }
        }
    }

    /// The entry a VAR section (or sub-object section) describes.
    fn entry(&mut self, sec: &Section, fallback_name: &str) -> ObjectInfo {
        let name = match sec.get("parametername") {
            Some((n, _)) if !n.is_empty() => n.to_string(),
            _ => {
                self.warn(sec.line, "no ParameterName");
                fallback_name.to_string()
            }
        };
        let mut info = ObjectInfo {
            name,
            ..Default::default()
        };
        match self.number(sec, "datatype") {
            Some(code) => match u16::try_from(code).ok().and_then(DataType::from_code) {
                Some(t) => info.data_type = t,
                None => {
                    let line = sec.get("datatype").map_or(sec.line, |(_, l)| l);
                    self.warn(line, format!("unknown DataType 0x{code:04X}, read as domain"));
                }
            },
            None if sec.get("datatype").is_none() => self.warn(sec.line, "no DataType, read as domain"),
            None => {}
        }
        if let Some((a, line)) = sec.get("accesstype") {
            match parse_access(a) {
                Some(a) => info.access = a,
                None => self.warn(line, format!("unknown AccessType `{a}`, using rw")),
            }
        }
        if self.number(sec, "pdomapping").is_some_and(|m| m != 0) {
            info.pdo = match info.access {
                Access::Ro | Access::Rwr | Access::Const => PdoMappable::Tpdo,
                Access::Wo | Access::Rww => PdoMappable::Rpdo,
                Access::Rw => PdoMappable::Both,
            };
        }
        let t = info.data_type;
        info.min = self
            .number(sec, "lowlimit")
            .map(|v| twos_complement(sec, "lowlimit", v, t));
        info.max = self
            .number(sec, "highlimit")
            .map(|v| twos_complement(sec, "highlimit", v, t));
        // A DCF's configured value wins over the EDS default.
        let value = sec
            .get("parametervalue")
            .filter(|(v, _)| !v.is_empty())
            .or_else(|| sec.get("defaultvalue").filter(|(v, _)| !v.is_empty()));
        if let Some((v, line)) = value {
            match self.value(v, info.data_type) {
                Ok(v) => info.default = Some(v),
                Err(e) => self.warn(line, e.to_string()),
            }
        }
        if let Some((d, _)) = sec.get("denotation").filter(|(d, _)| !d.is_empty()) {
            info.description = Some(d.to_string());
        }
        info
    }

    fn value(&self, text: &str, t: DataType) -> Result<Value, EdsValueError> {
        use DataType::*;
        Ok(match t {
            VisibleString | UnicodeString => Value::Text(text.to_string()),
            OctetString | Domain | TimeOfDay | TimeDifference => {
                let digits = text.trim().trim_start_matches("0x").trim_start_matches("0X");
                if !digits.len().is_multiple_of(2) || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
                    return Err(EdsValueError::NotHex(text.to_string()));
                }
                Value::Bytes(
                    digits
                        .as_bytes()
                        .chunks(2)
                        .filter_map(|p| Some(crate::frame::hex::nibble(p[0])? << 4 | crate::frame::hex::nibble(p[1])?))
                        .collect(),
                )
            }
            F32 | F64 => match parse_number(text, self.node) {
                Ok(i) => Value::Float(i as f64),
                Err(_) => Value::Float(
                    text.trim()
                        .parse()
                        .map_err(|_| EdsValueError::NotANumber(text.to_string()))?,
                ),
            },
            Boolean => Value::Bool(parse_number(text, self.node)? != 0),
            I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => {
                Value::Signed(signed_hex(text, parse_number(text, self.node)?, t))
            }
            _ => Value::Unsigned(parse_number(text, self.node)? as u64),
        })
    }
}

/// `v` parsed from `key` of `sec`, as a value of type `t` (see [`signed_hex`]).
fn twos_complement(sec: &Section, key: &str, v: i64, t: DataType) -> i64 {
    sec.get(key).map_or(v, |(text, _)| signed_hex(text, v, t))
}

/// A plain hex number written for a signed type of N bits is its two's complement
/// (`0x80000000` on INTEGER32 is -2147483648, `0xFF` on INTEGER8 is -1); decimal numbers
/// and anything beyond N bits stay as written.
fn signed_hex(text: &str, v: i64, t: DataType) -> i64 {
    let t_text = text.trim();
    let hex = t_text.starts_with("0x") || t_text.starts_with("0X");
    use DataType::*;
    let bits = match (t, t.size()) {
        (I8 | I16 | I24 | I32 | I40 | I48 | I56, Some(n)) => n as u32 * 8,
        _ => return v,
    };
    if hex && !t_text.contains('+') && (1i64 << (bits - 1)..1i64 << bits).contains(&v) {
        v - (1i64 << bits)
    } else {
        v
    }
}

/// Imports an EDS or DCF. `node` replaces `$NODEID`. Never fails: problems
/// (with line numbers) are in the returned warnings.
pub fn import(file: &str, text: &str, node: u8) -> (Profile, Vec<Warning>) {
    let mut raw_warnings = Vec::new();
    let ini = parse_ini(text, &mut raw_warnings);
    let mut im = Importer {
        file,
        node,
        warnings: Vec::new(),
        lines: BTreeMap::new(),
    };
    for (line, m) in raw_warnings {
        im.warn(line, m);
    }
    let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
    let mut p = Profile {
        name: base.to_string(),
        ..Default::default()
    };

    match ini.sections.get("deviceinfo") {
        Some(info) => {
            let vendor = info.get("vendorname").map(|(v, _)| v).unwrap_or("");
            let product = info.get("productname").map(|(v, _)| v).unwrap_or("");
            p.description = format!("{vendor} {product}").trim().to_string();
            for (key, sub) in [("vendornumber", 1u8), ("productnumber", 2)] {
                if let Some(v) = im.number(info, key) {
                    let test = IdTest::Number {
                        expected: v as u64,
                        mask: u64::from(u32::MAX),
                    };
                    p.identification.push(IdCondition {
                        index: 0x1018,
                        sub,
                        test,
                    });
                }
            }
        }
        None => im.warn(1, "no [DeviceInfo] section"),
    }
    let commissioning = ini
        .sections
        .get("devicecommissioning")
        .or(ini.sections.get("devicecomissioning"));
    if let Some(c) = commissioning {
        if let Some(id) = im.number(c, "nodeid") {
            match u8::try_from(id).ok().filter(|n| (1..=127).contains(n)) {
                Some(n) => {
                    p.node_id = Some(n);
                    if n != node {
                        let line = c.get("nodeid").map_or(c.line, |(_, l)| l);
                        im.warn(
                            line,
                            format!("NodeID {n} in the file, bound to node {node}; $NODEID = {node}"),
                        );
                    }
                }
                None => im.warn(c.line, format!("NodeID {id} is not 1..127")),
            }
        }
        p.node_name = c.get("nodename").map(|(v, _)| v.to_string()).filter(|v| !v.is_empty());
    }

    // Objects listed in the object lists, plus any object section present.
    let mut indices: BTreeMap<u16, usize> = BTreeMap::new();
    let mut lists = 0;
    for list in ["mandatoryobjects", "optionalobjects", "manufacturerobjects"] {
        let Some(sec) = ini.sections.get(list) else { continue };
        lists += 1;
        for (k, v, line) in &sec.keys {
            if k == "supportedobjects" {
                continue;
            }
            match parse_number(v, node).ok().and_then(|i| u16::try_from(i).ok()) {
                Some(i) => {
                    indices.entry(i).or_insert(*line);
                }
                None => im.warn(*line, format!("`{v}` is not an object index")),
            }
        }
    }
    if lists == 0 {
        im.warn(
            1,
            "no [MandatoryObjects]/[OptionalObjects]/[ManufacturerObjects] lists; importing every object section",
        );
    }
    for (name, sec) in &ini.sections {
        if let Some((i, None)) = section_index(name) {
            indices.entry(i).or_insert(sec.line);
        }
    }
    for (index, line) in indices {
        let Some(sec) = ini.sections.get(&format!("{index:04x}")) else {
            im.warn(
                line,
                format!("object 0x{index:04X} is listed but has no [{index:04X}] section"),
            );
            continue;
        };
        import_object(&mut im, &ini, &mut p, index, sec);
    }
    for name in ini.sections.keys() {
        if let Some((i, Some(_))) = section_index(name)
            && !ini.sections.contains_key(&format!("{i:04x}"))
        {
            im.warn(
                ini.sections[name].line,
                format!("[{name}] has no parent [{i:04X}] section, skipped"),
            );
        }
    }
    let source = MappingSource::Eds(file.to_string());
    p.rpdo = pdos(&mut im, &p, 0x1400, 0x1600, &source);
    p.tpdo = pdos(&mut im, &p, 0x1800, 0x1A00, &source);
    (p, im.warnings)
}

fn import_object(im: &mut Importer, ini: &Ini, p: &mut Profile, index: u16, sec: &Section) {
    let object_type = im.number(sec, "objecttype").unwrap_or(7);
    match object_type {
        // NULL, DOMAIN, VAR: one entry at sub 0.
        0 | 2 | 7 => {
            let info = im.entry(sec, &format!("Object 0x{index:04X}"));
            p.objects.insert((index, 0), info);
            im.lines.insert((index, 0), sec.line);
        }
        // DEFTYPE / DEFSTRUCT describe data types, not device objects.
        5 | 6 => {}
        8 | 9 => {
            let name = sec
                .get("parametername")
                .map(|(n, _)| n.to_string())
                .unwrap_or_else(|| format!("Object 0x{index:04X}"));
            p.object_names.insert(index, name.clone());
            let compact = im.number(sec, "compactsubobj").unwrap_or(0);
            if compact > 0 {
                compact_subs(im, ini, p, index, sec, &name, compact);
                return;
            }
            let mut found = 0;
            for (sub, s) in ini.sub_sections(index) {
                let info = im.entry(s, &format!("{name} sub {sub}"));
                p.objects.insert((index, sub), info);
                im.lines.insert((index, sub), s.line);
                found += 1;
            }
            if found == 0 {
                im.warn(
                    sec.line,
                    format!("record/array 0x{index:04X} has no sub-object sections"),
                );
            }
        }
        other => im.warn(
            sec.line,
            format!("unknown ObjectType {other} of 0x{index:04X}, skipped"),
        ),
    }
}

/// `CompactSubObj=N`: sub 0 holds N, subs 1..N share the parent's type and access;
/// names and values may come from `[IIIIName]` / `[IIIIValue]`.
fn compact_subs(im: &mut Importer, ini: &Ini, p: &mut Profile, index: u16, sec: &Section, name: &str, n: i64) {
    let Ok(n) = u8::try_from(n).map(|n| n.min(254)) else {
        im.warn(sec.line, format!("CompactSubObj {n} is not 1..254, skipped"));
        return;
    };
    let template = im.entry(sec, name);
    let count = ObjectInfo {
        name: "Number of entries".into(),
        data_type: DataType::U8,
        access: Access::Ro,
        default: Some(Value::Unsigned(u64::from(n))),
        ..Default::default()
    };
    p.objects.insert((index, 0), count);
    let names = ini.sections.get(&format!("{index:04x}name"));
    let values = ini.sections.get(&format!("{index:04x}value"));
    for sub in 1..=n {
        let mut info = template.clone();
        info.name = names
            .and_then(|s| s.get(&sub.to_string()))
            .map(|(v, _)| v.to_string())
            .unwrap_or_else(|| format!("{name} {sub}"));
        if let Some((v, line)) = values.and_then(|s| s.get(&sub.to_string())) {
            match im.value(v, info.data_type) {
                Ok(v) => info.default = Some(v),
                Err(e) => im.warn(line, e.to_string()),
            }
        }
        p.objects.insert((index, sub), info);
        im.lines.insert((index, sub), sec.line);
    }
}

/// PDO mappings from the mapping objects' values, COB-IDs from the communication objects.
fn pdos(im: &mut Importer, p: &Profile, comm: u16, map: u16, source: &MappingSource) -> BTreeMap<u8, PdoMapping> {
    let value = |i: u16, s: u8| p.object(i, s).and_then(|o| o.default.as_ref()).and_then(Value::as_i64);
    let mut out = BTreeMap::new();
    for n in 0..0x200u16 {
        let (ci, mi) = (comm + n, map + n);
        if p.object(mi, 0).is_none() && p.object(mi, 1).is_none() {
            continue;
        }
        let cob = value(ci, 1);
        if cob.is_some_and(|c| c & 0x8000_0000 != 0) {
            continue; // PDO not valid.
        }
        let count = value(mi, 0).unwrap_or(64).clamp(0, 64) as u8;
        let mut entries = Vec::new();
        for sub in 1..=count {
            let Some(raw) = value(mi, sub) else { continue };
            if raw == 0 {
                continue;
            }
            let raw = raw as u32;
            let e = MappedEntry {
                index: (raw >> 16) as u16,
                sub: (raw >> 8) as u8,
                bits: raw as u8,
            };
            if e.bits == 0 || e.bits > 64 {
                let line = im.lines.get(&(mi, sub)).copied().unwrap_or(0);
                im.warn(
                    line,
                    format!(
                        "0x{mi:04X}:{sub} maps 0x{raw:08X} with a bit length of {}, skipped",
                        e.bits
                    ),
                );
                continue;
            }
            entries.push(e);
        }
        if entries.is_empty() {
            continue;
        }
        let Ok(number) = u8::try_from(n + 1) else {
            let line = im.lines.get(&(mi, 0)).copied().unwrap_or(0);
            im.warn(line, format!("PDO mapping 0x{mi:04X} is beyond PDO 255, skipped"));
            continue;
        };
        let cob_id = cob.map(|c| (c & 0x1FFF_FFFF) as u32);
        out.insert(
            number,
            PdoMapping {
                cob_id,
                entries,
                source: source.clone(),
            },
        );
    }
    out
}

/// One `ParameterValue` of a DCF: the entry it configures, its text as written, its line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParameterValue {
    pub index: u16,
    pub sub: u8,
    pub text: String,
    pub line: usize,
}

/// Every non-empty `ParameterValue` of a DCF (`[IIII]` is sub 0, `[IIIIsubS]` sub S), by
/// (index, sub). Problems of the text itself are [`import`]'s warnings.
pub fn parameter_values(text: &str) -> Vec<ParameterValue> {
    key_values(text, "parametervalue")
}

/// Every non-empty value of `key` (lower case, e.g. `datatype`) in the object sections of
/// `text`, as [`parameter_values`] reads `ParameterValue`.
pub fn key_values(text: &str, key: &str) -> Vec<ParameterValue> {
    let ini = parse_ini(text, &mut Vec::new());
    ini.sections
        .iter()
        .filter_map(|(name, sec)| {
            let (index, sub) = section_index(name)?;
            let (v, line) = sec.get(key).filter(|(v, _)| !v.is_empty())?;
            Some(ParameterValue {
                index,
                sub: sub.unwrap_or(0),
                text: v.to_string(),
                line,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_of_too_many_sections_is_read_up_to_the_bound_with_a_located_warning() {
        let mut text = String::from("[DeviceInfo]\nVendorName=x\n");
        for i in 0..MAX_SECTIONS as u32 + 10 {
            text.push_str(&format!(
                "[{:04X}]\nParameterName=p{i}\nObjectType=7\nDataType=7\nAccessType=rw\n",
                0x2000 + i
            ));
        }
        let (p, w) = import("big.eds", &text, 1);
        // [DeviceInfo] and MAX_SECTIONS - 1 objects are read, the next one is not.
        let stop = 3 + 5 * (MAX_SECTIONS - 1);
        let said: Vec<String> = w
            .iter()
            .filter(|w| w.message.starts_with("more than"))
            .map(|w| format!("{} {}", w.at, w.message))
            .collect();
        assert_eq!(
            said,
            [format!(
                "line {stop} more than {MAX_SECTIONS} sections (real EDS files have a few thousand): the rest of the file, from here, is not read"
            )]
        );
        assert_eq!(p.objects.len(), MAX_SECTIONS - 1);
        let mut keys = String::from("[DeviceInfo]\n");
        keys.push_str(&"VendorName=x\n".repeat(MAX_KEYS + 1));
        let (_, w) = import("keys.eds", &keys, 1);
        assert!(
            w.iter().any(|w| w.at == format!("line {}", MAX_KEYS + 2)
                && w.message.starts_with(&format!("more than {MAX_KEYS} key=value lines"))),
            "{:?}",
            w.last()
        );
    }
}
