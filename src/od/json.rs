//! Loads device profiles from JSON (`decoders/*.json`, format in `docs/PROFILE_FORMAT.md`).
//!
//! The JSON is read into DTOs with serde; everything a DTO field can hold in
//! more than one way (numbers as numbers or hex strings, expressions) is kept
//! as a JSON value and checked while converting to a [`Profile`]. Wrong JSON
//! syntax or types are a [`LoadError`] with path and line; anything else is a
//! [`Warning`] and the offending item is skipped.

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde_json::Value as Json;

use super::alias::{AliasRule, parse_object_ref};
use super::expr::{Expr, parse_int};
use super::fields::{ByteField, SdoCommand, SdoDirection};
use super::procedure::{NmtCommand, ProcParam, Procedure, Step, parse_frame_data};
use super::{
    Access, Axis, DataType, IdCondition, IdTest, IndexRange, MappedEntry, MappingSource, ObjectInfo, ObjectRange,
    PdoMappable, PdoSet, PdoTemplate, Profile, TextMatch, Value, Warning,
};

/// The newest profile format this loader knows.
pub const FORMAT_VERSION: u64 = 1;

/// A profile that could not be loaded at all.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadError {
    /// The file (or built-in name).
    pub file: String,
    /// JSON path of the problem, e.g. `objects.0x6041.subs`, or `.` for the root.
    pub path: String,
    /// 1-based line, 0 when unknown.
    pub line: usize,
    /// 1-based column, 0 when unknown.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: at {}: {}",
            self.file, self.line, self.column, self.path, self.message
        )
    }
}

impl std::error::Error for LoadError {}

#[derive(Deserialize)]
struct ProfileDto {
    #[serde(default)]
    format: Option<u64>,
    name: String,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    extends: Vec<String>,
    #[serde(default)]
    identification: Vec<IdDto>,
    #[serde(default)]
    objects: BTreeMap<String, EntryDto>,
    #[serde(default)]
    aliases: BTreeMap<String, String>,
    #[serde(default)]
    alias_rules: Vec<AliasRuleDto>,
    #[serde(default)]
    emcy: Option<EmcyDto>,
    #[serde(default)]
    rpdo: BTreeMap<String, PdoDto>,
    #[serde(default)]
    tpdo: BTreeMap<String, PdoDto>,
    #[serde(default)]
    pdo_sets: Vec<PdoSetDto>,
    #[serde(default)]
    sdo_commands: Vec<SdoCommandDto>,
    #[serde(default)]
    procedures: BTreeMap<String, ProcedureDto>,
    #[serde(default)]
    axes: Vec<AxisDto>,
}

#[derive(Deserialize)]
struct EntryDto {
    #[serde(default)]
    name: Option<String>,
    #[serde(default, rename = "type")]
    data_type: Option<String>,
    #[serde(default)]
    access: Option<String>,
    #[serde(default)]
    pdo: Option<String>,
    #[serde(default)]
    unit: Option<String>,
    #[serde(default)]
    scale: Option<Json>,
    #[serde(default)]
    values: BTreeMap<String, String>,
    #[serde(default)]
    bits: BTreeMap<String, String>,
    #[serde(default)]
    default: Option<Json>,
    #[serde(default)]
    min: Option<Json>,
    #[serde(default)]
    max: Option<Json>,
    #[serde(default)]
    alias: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    subs: Option<BTreeMap<String, EntryDto>>,
}

#[derive(Deserialize)]
struct IdDto {
    object: String,
    #[serde(default)]
    value: Option<Json>,
    #[serde(default)]
    mask: Option<Json>,
    #[serde(default)]
    text: Option<String>,
    #[serde(default, rename = "match")]
    mode: Option<String>,
}

#[derive(Deserialize)]
struct AliasRuleDto {
    pattern: String,
    index: Json,
    #[serde(default)]
    sub: Option<Json>,
    #[serde(default)]
    description: Option<String>,
}

#[derive(Deserialize)]
struct EmcyDto {
    #[serde(default)]
    codes: BTreeMap<String, String>,
    #[serde(default)]
    manufacturer_fields: Vec<FieldDto>,
}

#[derive(Deserialize)]
struct FieldDto {
    name: String,
    offset: Json,
    #[serde(default)]
    length: Option<Json>,
    #[serde(default)]
    signed: bool,
    #[serde(default)]
    format: Option<String>,
    #[serde(default)]
    values: BTreeMap<String, String>,
    #[serde(default)]
    unit: Option<String>,
    #[serde(default)]
    scale: Option<Json>,
    #[serde(default)]
    object: Option<Json>,
    #[serde(default)]
    object_sub: Option<Json>,
}

#[derive(Deserialize)]
struct PdoDto {
    #[serde(default)]
    cob_id: Option<Json>,
    #[serde(default)]
    transmission_type: Option<Json>,
    #[serde(default)]
    entries: Vec<Json>,
}

#[derive(Deserialize)]
struct PdoSetDto {
    name: String,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    default: bool,
    #[serde(default)]
    selected_by: Option<SelectorDto>,
    #[serde(default)]
    rpdo: BTreeMap<String, PdoDto>,
    #[serde(default)]
    tpdo: BTreeMap<String, PdoDto>,
}

#[derive(Deserialize)]
struct SelectorDto {
    object: String,
    value: Json,
}

#[derive(Deserialize)]
struct SdoCommandDto {
    command: Json,
    direction: String,
    name: String,
    #[serde(default)]
    fields: Vec<FieldDto>,
}

#[derive(Deserialize)]
struct ProcedureDto {
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    params: Vec<ParamDto>,
    #[serde(default)]
    steps: Vec<Json>,
}

#[derive(Deserialize)]
struct ParamDto {
    name: String,
    #[serde(default)]
    unit: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    default: Option<Json>,
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
enum StepDto {
    SdoWrite {
        object: String,
        value: Json,
        #[serde(default, rename = "type")]
        data_type: Option<String>,
    },
    SdoRead {
        object: String,
    },
    Nmt(NmtDto),
    Wait {
        #[serde(default)]
        object: Option<String>,
        #[serde(default)]
        mask: Option<Json>,
        equals: Json,
        #[serde(default)]
        timeout_ms: Option<Json>,
    },
    Frame {
        id: Json,
        data: String,
    },
    DelayMs(Json),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum NmtDto {
    Name(String),
    Full {
        command: String,
        #[serde(default)]
        node: Option<Json>,
    },
}

#[derive(Deserialize)]
struct AxisDto {
    name: String,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    objects: Vec<String>,
    #[serde(default)]
    emcy_field: Option<String>,
}

/// Loads a profile from JSON text. `file` names the source in messages.
///
/// Returns the profile and its warnings, or a located error when the JSON
/// cannot be read at all (syntax, wrong JSON types, missing `name`).
pub fn load_profile(file: &str, text: &str) -> Result<(Profile, Vec<Warning>), LoadError> {
    let located = |path: String, e: &serde_json::Error| LoadError {
        file: file.to_string(),
        path,
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    };
    let mut ignored = Vec::new();
    let mut de = serde_json::Deserializer::from_str(text);
    let mut on_unknown = |path: serde_ignored::Path| ignored.push(path.to_string());
    let dto: ProfileDto = serde_path_to_error::deserialize(serde_ignored::Deserializer::new(&mut de, &mut on_unknown))
        .map_err(|e| located(e.path().to_string(), e.inner()))?;
    de.end().map_err(|e| located(".".to_string(), &e))?;
    let mut cx = Cx {
        file,
        warnings: Vec::new(),
    };
    for path in ignored {
        cx.warn(&path, "unknown field, ignored");
    }
    let profile = cx.profile(dto);
    Ok((profile, cx.warnings))
}

/// Most entries one index-range key may expand to.
const MAX_RANGE_ENTRIES: usize = 100_000;

/// The entries of one `objects` key before they are placed at an index.
#[derive(Clone)]
struct Built {
    /// A record/array (replaces every sub of its index).
    record: bool,
    /// The record's name.
    name: Option<String>,
    /// The record's alias.
    alias: Option<String>,
    /// Entries by sub.
    entries: Vec<(u8, ObjectInfo)>,
}

/// Puts built entries at `index`; `nth` (1-based place in an index range) replaces `{i}` in names.
fn place(p: &mut Profile, index: u16, nth: Option<u32>, b: &Built) {
    let name = |n: &str| match nth {
        Some(i) => n.replace("{i}", &i.to_string()),
        None => n.to_string(),
    };
    if let Some(n) = &b.name {
        p.object_names.insert(index, name(n));
    }
    if let Some(a) = &b.alias {
        p.aliases.insert(name(a), (index, 0));
    }
    for (sub, info) in &b.entries {
        let mut info = info.clone();
        if nth.is_some() {
            info.name = name(&info.name);
        }
        p.objects.insert((index, *sub), info);
    }
}

/// Conversion context: collects warnings.
struct Cx<'a> {
    file: &'a str,
    warnings: Vec<Warning>,
}

impl Cx<'_> {
    fn warn(&mut self, at: &str, message: impl Into<String>) {
        self.warnings.push(Warning {
            file: self.file.to_string(),
            at: at.to_string(),
            message: message.into(),
        });
    }

    /// Runs a conversion; an error becomes a warning at `at` and `None`.
    fn ok<T>(&mut self, at: &str, r: Result<T, String>) -> Option<T> {
        r.map_err(|e| self.warn(at, e)).ok()
    }

    fn profile(&mut self, d: ProfileDto) -> Profile {
        if let Some(f) = d.format.filter(|f| *f > FORMAT_VERSION) {
            self.warn(
                "format",
                format!("format {f} is newer than {FORMAT_VERSION}; unknown parts are skipped"),
            );
        }
        let mut p = Profile {
            name: d.name,
            description: d.description.unwrap_or_default(),
            extends: d.extends,
            ..Default::default()
        };
        // Index ranges first, so that single objects written next can override them.
        let (ranges, singles): (Vec<_>, Vec<_>) = d.objects.into_iter().partition(|(k, _)| k.contains(".."));
        for (key, entry) in ranges {
            let at = format!("objects.{key}");
            let Some((first, last)) = index_range(&key) else {
                self.warn(&at, format!("`{key}` is not an index range (0xFIRST..0xLAST), skipped"));
                continue;
            };
            let built = self.build(&at, 0, entry);
            // Records whose sub names do not depend on the index are kept once as a
            // template (PDO parameters would otherwise be 70000 entries).
            if built.record && !built.entries.iter().any(|(_, e)| e.name.contains("{i}")) {
                for index in first..=last {
                    let nth = u32::from(index - first) + 1;
                    place(
                        &mut p,
                        index,
                        Some(nth),
                        &Built {
                            entries: vec![],
                            ..built.clone()
                        },
                    );
                }
                let subs = built.entries.into_iter().collect();
                p.ranges.push(IndexRange { first, last, subs });
                continue;
            }
            let size = (usize::from(last - first) + 1) * built.entries.len().max(1);
            if size > MAX_RANGE_ENTRIES {
                self.warn(
                    &at,
                    format!("range expands to {size} entries, more than {MAX_RANGE_ENTRIES}; skipped"),
                );
                continue;
            }
            for index in first..=last {
                place(&mut p, index, Some(u32::from(index - first) + 1), &built);
            }
        }
        for (key, entry) in singles {
            let at = format!("objects.{key}");
            let Some((index, sub)) = parse_object_ref(&key) else {
                self.warn(
                    &at,
                    format!("`{key}` is not an object (use 0xINDEX or 0xINDEX:SUB), skipped"),
                );
                continue;
            };
            let built = self.build(&at, sub, entry);
            if !built.record {
                p.materialize(index);
            }
            if built.record {
                let stale: Vec<(u16, u8)> = p.objects.range((index, 0)..=(index, 255)).map(|(k, _)| *k).collect();
                for k in stale {
                    p.objects.remove(&k);
                }
            }
            place(&mut p, index, None, &built);
        }
        for (alias, target) in d.aliases {
            let at = format!("aliases.{alias}");
            match parse_object_ref(&target) {
                Some(r) => {
                    p.aliases.insert(alias, r);
                }
                None => self.warn(&at, format!("`{target}` is not an object (use 0xINDEX or 0xINDEX:SUB)")),
            }
        }
        for (i, r) in d.alias_rules.into_iter().enumerate() {
            let at = format!("alias_rules.{i}");
            let index = self.ok(&at, expr(&r.index));
            let sub = match &r.sub {
                Some(s) => self.ok(&at, expr(s)),
                None => Some(Expr::constant(0)),
            };
            if let (Some(index), Some(sub)) = (index, sub)
                && let Some(rule) = self.ok(&at, AliasRule::new(&r.pattern, index, sub, r.description))
            {
                p.alias_rules.push(rule);
            }
        }
        for (i, c) in d.identification.into_iter().enumerate() {
            if let Some(c) = self.id_condition(&format!("identification.{i}"), c) {
                p.identification.push(c);
            }
        }
        if let Some(emcy) = d.emcy {
            for (code, text) in emcy.codes {
                let at = format!("emcy.codes.{code}");
                match parse_int(&code).and_then(|c| u16::try_from(c).ok()) {
                    Some(c) => {
                        p.emcy_codes.insert(c, text);
                    }
                    None => self.warn(&at, format!("`{code}` is not an EMCY code (0x0000..0xFFFF)")),
                }
            }
            for (i, f) in emcy.manufacturer_fields.into_iter().enumerate() {
                let at = format!("emcy.manufacturer_fields.{i}");
                if f.object.is_some() || f.object_sub.is_some() {
                    self.warn(&at, "`object` only applies to sdo_commands fields, ignored");
                }
                if let Some(field) = self.field(&at, f, &[]) {
                    if field.offset < 3 {
                        self.warn(&at, "offset below 3 overlaps the error code and error register");
                    }
                    p.emcy_fields.push(field);
                }
            }
        }
        self.pdo_sets(&mut p, d.rpdo, d.tpdo, d.pdo_sets);
        for (i, c) in d.sdo_commands.into_iter().enumerate() {
            if let Some(c) = self.sdo_command(&format!("sdo_commands.{i}"), c) {
                p.sdo_commands.push(c);
            }
        }
        for (name, proc) in d.procedures {
            if let Some(proc) = self.procedure(&format!("procedures.{name}"), &name, proc) {
                p.procedures.insert(name, proc);
            }
        }
        for (i, a) in d.axes.into_iter().enumerate() {
            let at = format!("axes.{i}");
            let mut axis = Axis {
                name: a.name,
                description: a.description,
                emcy_field: a.emcy_field,
                objects: vec![],
            };
            for (j, o) in a.objects.iter().enumerate() {
                if let Some(r) = self.ok(&format!("{at}.objects.{j}"), object_range(o)) {
                    axis.objects.push(r);
                }
            }
            if let Some(f) = &axis.emcy_field
                && !p.emcy_fields.iter().any(|e| &e.name == f)
            {
                self.warn(
                    &format!("{at}.emcy_field"),
                    format!("no emcy.manufacturer_fields entry named `{f}`"),
                );
            }
            p.axes.push(axis);
        }
        p
    }

    /// The entries one `objects` key describes (one entry, or a record's subs).
    fn build(&mut self, at: &str, sub: u8, e: EntryDto) -> Built {
        let Some(subs) = e.subs else {
            let entries = self.entry(at, e).map(|info| vec![(sub, info)]).unwrap_or_default();
            return Built {
                record: false,
                name: None,
                alias: None,
                entries,
            };
        };
        if sub != 0 {
            self.warn(&format!("{at}.subs"), "a sub-entry cannot have subs, ignored");
            return Built {
                record: false,
                name: None,
                alias: None,
                entries: vec![],
            };
        }
        if e.name.is_none() {
            self.warn(at, "record or array without a name");
        }
        if e.data_type.is_some() || e.access.is_some() || !e.values.is_empty() || e.unit.is_some() {
            self.warn(at, "type/access/unit/values of a record belong on its subs, ignored");
        }
        let mut entries = Vec::new();
        for (key, s) in subs {
            let at = format!("{at}.subs.{key}");
            let Some(range) = self.ok(&at, sub_range(&key)) else {
                continue;
            };
            if s.subs.is_some() {
                self.warn(&format!("{at}.subs"), "subs cannot nest, ignored");
            }
            let Some(info) = self.entry(&at, s) else { continue };
            for n in range.clone() {
                let mut info = info.clone();
                if key.contains("..") {
                    info.name = info.name.replace("{n}", &n.to_string());
                }
                entries.push((n, info));
            }
        }
        Built {
            record: true,
            name: e.name,
            alias: e.alias,
            entries,
        }
    }

    fn entry(&mut self, at: &str, e: EntryDto) -> Option<ObjectInfo> {
        let Some(name) = e.name else {
            self.warn(at, "entry without `name`, skipped");
            return None;
        };
        let mut info = ObjectInfo {
            name,
            unit: e.unit,
            alias: e.alias,
            description: e.description,
            ..Default::default()
        };
        if let Some(t) = &e.data_type {
            match parse_type(t) {
                Some(t) => info.data_type = t,
                None => self.warn(&format!("{at}.type"), format!("unknown type `{t}`, using domain")),
            }
        }
        if let Some(a) = &e.access {
            match parse_access(a) {
                Some(a) => info.access = a,
                None => self.warn(&format!("{at}.access"), format!("unknown access `{a}`, using rw")),
            }
        }
        if let Some(m) = &e.pdo {
            match m.to_ascii_lowercase().as_str() {
                "no" => info.pdo = PdoMappable::No,
                "tpdo" => info.pdo = PdoMappable::Tpdo,
                "rpdo" => info.pdo = PdoMappable::Rpdo,
                "both" => info.pdo = PdoMappable::Both,
                _ => self.warn(
                    &format!("{at}.pdo"),
                    format!("unknown pdo `{m}` (no, tpdo, rpdo, both)"),
                ),
            }
        }
        if let Some(s) = &e.scale {
            info.scale = self.ok(&format!("{at}.scale"), float(s));
        }
        for (k, v) in e.values {
            match parse_int(&k) {
                Some(raw) => {
                    info.values.insert(raw, v);
                }
                None => self.warn(&format!("{at}.values.{k}"), format!("`{k}` is not a number, skipped")),
            }
        }
        for (k, v) in e.bits {
            match k.trim().parse::<u8>().ok().filter(|b| *b < 64) {
                Some(b) => {
                    info.bits.insert(b, v);
                }
                None => self.warn(
                    &format!("{at}.bits.{k}"),
                    format!("`{k}` is not a bit number 0..63, skipped"),
                ),
            }
        }
        if let Some(d) = &e.default {
            info.default = self.ok(&format!("{at}.default"), default_value(d, info.data_type));
        }
        if let Some(m) = &e.min {
            info.min = self.ok(&format!("{at}.min"), int(m));
        }
        if let Some(m) = &e.max {
            info.max = self.ok(&format!("{at}.max"), int(m));
        }
        Some(info)
    }

    fn id_condition(&mut self, at: &str, c: IdDto) -> Option<IdCondition> {
        let Some((index, sub)) = parse_object_ref(&c.object) else {
            self.warn(&format!("{at}.object"), format!("`{}` is not an object", c.object));
            return None;
        };
        let test = match (&c.value, &c.text) {
            (Some(v), None) => {
                let expected = self.ok(&format!("{at}.value"), int(v))? as u64;
                let mask = match &c.mask {
                    Some(m) => self.ok(&format!("{at}.mask"), int(m))? as u64,
                    None => u64::MAX,
                };
                IdTest::Number { expected, mask }
            }
            (None, Some(t)) => {
                let mode = match c.mode.as_deref().map(str::to_ascii_lowercase).as_deref() {
                    None | Some("exact") => TextMatch::Exact,
                    Some("prefix") => TextMatch::Prefix,
                    Some("contains") => TextMatch::Contains,
                    Some(m) => {
                        self.warn(
                            &format!("{at}.match"),
                            format!("unknown match `{m}` (exact, prefix, contains)"),
                        );
                        return None;
                    }
                };
                IdTest::Text {
                    expected: t.clone(),
                    mode,
                }
            }
            _ => {
                self.warn(at, "give exactly one of `value` and `text`, skipped");
                return None;
            }
        };
        Some(IdCondition { index, sub, test })
    }

    fn field(&mut self, at: &str, f: FieldDto, earlier: &[String]) -> Option<ByteField> {
        let offset = self.ok(&format!("{at}.offset"), int(&f.offset))?;
        let length = match &f.length {
            Some(l) => self.ok(&format!("{at}.length"), int(l))?,
            None => 1,
        };
        if !(1..=4).contains(&length) || !(0..8).contains(&offset) || offset + length > 8 {
            self.warn(
                at,
                format!("field at offset {offset} length {length} does not fit 8 bytes, skipped"),
            );
            return None;
        }
        let hex = match f.format.as_deref().map(str::to_ascii_lowercase).as_deref() {
            None | Some("dec") => false,
            Some("hex") => true,
            Some(other) => {
                self.warn(&format!("{at}.format"), format!("unknown format `{other}` (dec, hex)"));
                false
            }
        };
        let mut values = BTreeMap::new();
        for (k, v) in f.values {
            match parse_int(&k) {
                Some(raw) => {
                    values.insert(raw, v);
                }
                None => self.warn(&format!("{at}.values.{k}"), format!("`{k}` is not a number, skipped")),
            }
        }
        let scale = match &f.scale {
            Some(s) => self.ok(&format!("{at}.scale"), float(s)),
            None => None,
        };
        let mut field_expr = |key: &str, v: &Option<Json>| -> Option<Option<Expr>> {
            let Some(v) = v else { return Some(None) };
            let e = self.ok(&format!("{at}.{key}"), expr(v))?;
            if let Some(bad) = e.variables().into_iter().find(|n| !earlier.iter().any(|x| x == n)) {
                self.warn(
                    &format!("{at}.{key}"),
                    format!("`{bad}` is not an earlier field of this frame"),
                );
                return None;
            }
            Some(Some(e))
        };
        let object = field_expr("object", &f.object)?;
        let object_sub = field_expr("object_sub", &f.object_sub)?;
        Some(ByteField {
            name: f.name,
            offset: offset as u8,
            length: length as u8,
            signed: f.signed,
            hex,
            values,
            unit: f.unit,
            scale,
            object,
            object_sub,
        })
    }

    fn sdo_command(&mut self, at: &str, c: SdoCommandDto) -> Option<SdoCommand> {
        let command = self.ok(&format!("{at}.command"), int(&c.command).and_then(byte))?;
        let direction = match c.direction.to_ascii_lowercase().as_str() {
            "request" => SdoDirection::Request,
            "response" => SdoDirection::Response,
            other => {
                self.warn(
                    &format!("{at}.direction"),
                    format!("unknown direction `{other}` (request, response)"),
                );
                return None;
            }
        };
        let mut fields: Vec<ByteField> = Vec::new();
        for (i, f) in c.fields.into_iter().enumerate() {
            let earlier: Vec<String> = fields.iter().map(|f| f.name.clone()).collect();
            if let Some(f) = self.field(&format!("{at}.fields.{i}"), f, &earlier) {
                fields.push(f);
            }
        }
        Some(SdoCommand {
            command,
            direction,
            name: c.name,
            fields,
        })
    }

    fn pdo_sets(
        &mut self,
        p: &mut Profile,
        rpdo: BTreeMap<String, PdoDto>,
        tpdo: BTreeMap<String, PdoDto>,
        sets: Vec<PdoSetDto>,
    ) {
        let mut out = Vec::new();
        if !rpdo.is_empty() || !tpdo.is_empty() {
            if sets.is_empty() {
                let rpdo = self.pdos("rpdo", rpdo);
                let tpdo = self.pdos("tpdo", tpdo);
                out.push(PdoSet {
                    name: "default".into(),
                    default: true,
                    rpdo,
                    tpdo,
                    ..Default::default()
                });
            } else {
                self.warn("rpdo", "top-level rpdo/tpdo are ignored when pdo_sets is given");
            }
        }
        for (i, s) in sets.into_iter().enumerate() {
            let at = format!("pdo_sets.{i}");
            let selected_by = match s.selected_by {
                Some(sel) => self
                    .ok(&format!("{at}.selected_by.value"), int(&sel.value))
                    .map(|v| (sel.object, v)),
                None => None,
            };
            let rpdo = self.pdos(&format!("{at}.rpdo"), s.rpdo);
            let tpdo = self.pdos(&format!("{at}.tpdo"), s.tpdo);
            out.push(PdoSet {
                name: s.name,
                description: s.description,
                default: s.default,
                selected_by,
                rpdo,
                tpdo,
            });
        }
        let defaults = out.iter().filter(|s| s.default).count();
        if defaults > 1 {
            self.warn("pdo_sets", "several sets are marked default; the first one is used");
        }
        if defaults == 0 && out.len() > 1 {
            self.warn("pdo_sets", "no set is marked default; the first one is used");
        }
        let first_default = out.iter().position(|s| s.default).unwrap_or(0);
        for (i, s) in out.iter_mut().enumerate() {
            s.default = i == first_default;
        }
        p.pdo_sets = out;
        let source = MappingSource::Profile(p.name.clone());
        if let Some((rpdo, tpdo)) = p
            .default_pdo_set()
            .map(|set| (set.mappings(false, None, &source), set.mappings(true, None, &source)))
        {
            p.rpdo = rpdo;
            p.tpdo = tpdo;
        }
    }

    fn pdos(&mut self, at: &str, pdos: BTreeMap<String, PdoDto>) -> BTreeMap<u8, PdoTemplate> {
        let mut out = BTreeMap::new();
        for (num, pdo) in pdos {
            let at = format!("{at}.{num}");
            let Some(n) = parse_int(&num).and_then(|n| u8::try_from(n).ok()).filter(|n| *n >= 1) else {
                self.warn(&at, format!("`{num}` is not a PDO number 1..255, skipped"));
                continue;
            };
            let cob_id = match &pdo.cob_id {
                Some(c) => match self.ok(&format!("{at}.cob_id"), expr(c)) {
                    Some(e) => Some(e),
                    None => continue,
                },
                None => None,
            };
            let transmission_type = match &pdo.transmission_type {
                Some(t) => self.ok(&format!("{at}.transmission_type"), int(t).and_then(byte)),
                None => None,
            };
            let mut entries = Vec::new();
            let mut total_bits = 0u32;
            for (i, e) in pdo.entries.iter().enumerate() {
                if let Some(m) = self.ok(&format!("{at}.entries.{i}"), mapped_entry(e)) {
                    total_bits += m.bits as u32;
                    entries.push(m);
                }
            }
            if total_bits > 64 {
                self.warn(
                    &at,
                    format!("mapping is {total_bits} bits, more than a classic PDO's 64"),
                );
            }
            out.insert(
                n,
                PdoTemplate {
                    cob_id,
                    transmission_type,
                    entries,
                },
            );
        }
        out
    }

    fn procedure(&mut self, at: &str, name: &str, d: ProcedureDto) -> Option<Procedure> {
        let mut params = Vec::new();
        for (i, p) in d.params.into_iter().enumerate() {
            let default = match &p.default {
                Some(v) => Some(self.ok(&format!("{at}.params.{i}.default"), int(v))?),
                None => None,
            };
            params.push(ProcParam {
                name: p.name,
                unit: p.unit,
                description: p.description,
                default,
            });
        }
        let mut steps = Vec::new();
        for (i, s) in d.steps.into_iter().enumerate() {
            let step_at = format!("{at}.steps.{i}");
            let mut unknown = Vec::new();
            let dto: Result<StepDto, _> = serde_ignored::deserialize(s, |p| unknown.push(p.to_string()));
            for u in unknown {
                self.warn(&format!("{step_at}.{u}"), "unknown field, ignored");
            }
            let step = dto.map_err(|e| e.to_string()).and_then(step);
            match step {
                Ok(s) => steps.push(s),
                Err(e) => {
                    self.warn(&step_at, format!("{e}; procedure `{name}` skipped"));
                    return None;
                }
            }
        }
        let proc = Procedure {
            name: name.to_string(),
            description: d.description,
            params,
            steps,
        };
        if let Err(e) = proc.check_variables() {
            self.warn(at, format!("{e}; procedure `{name}` skipped"));
            return None;
        }
        Some(proc)
    }
}

fn step(d: StepDto) -> Result<Step, String> {
    Ok(match d {
        StepDto::SdoWrite {
            object,
            value,
            data_type,
        } => {
            let data_type = match data_type {
                Some(t) => Some(parse_type(&t).ok_or_else(|| format!("unknown type `{t}`"))?),
                None => None,
            };
            Step::SdoWrite {
                object,
                value: expr(&value)?,
                data_type,
            }
        }
        StepDto::SdoRead { object } => Step::SdoRead { object },
        StepDto::Nmt(n) => {
            let (command, node) = match n {
                NmtDto::Name(c) => (c, None),
                NmtDto::Full { command, node } => (command, node),
            };
            let command = NmtCommand::parse(&command).ok_or_else(|| format!("unknown NMT command `{command}`"))?;
            let node = node.as_ref().map(expr).transpose()?;
            Step::Nmt { command, node }
        }
        StepDto::Wait {
            object,
            mask,
            equals,
            timeout_ms,
        } => Step::Wait {
            object: object.unwrap_or_else(|| "0x6041".to_string()),
            mask: mask.as_ref().map(expr).transpose()?.unwrap_or(Expr::constant(-1)),
            equals: expr(&equals)?,
            timeout_ms: match timeout_ms {
                Some(t) => u32::try_from(int(&t)?).map_err(|_| "timeout_ms out of range".to_string())?,
                None => 1000,
            },
        },
        StepDto::Frame { id, data } => Step::Frame {
            id: expr(&id)?,
            data: parse_frame_data(&data)?,
        },
        StepDto::DelayMs(ms) => Step::Delay {
            ms: u32::try_from(int(&ms)?).map_err(|_| "delay out of range")?,
        },
    })
}

/// A number given as a JSON number or a string (`0x..`, `0b..`, decimal).
fn int(v: &Json) -> Result<i64, String> {
    match v {
        Json::Number(n) => n
            .as_i64()
            .or_else(|| n.as_u64().map(|u| u as i64))
            .ok_or_else(|| format!("{n} is not an integer")),
        Json::String(s) => parse_int(s).ok_or_else(|| format!("`{s}` is not a number")),
        other => Err(format!("{other} is not a number")),
    }
}

fn byte(v: i64) -> Result<u8, String> {
    u8::try_from(v).map_err(|_| format!("{v} is not a byte (0..255)"))
}

fn float(v: &Json) -> Result<f64, String> {
    match v {
        Json::Number(n) => n.as_f64().ok_or_else(|| format!("{n} is not a number")),
        Json::String(s) => s.trim().parse().map_err(|_| format!("`{s}` is not a number")),
        other => Err(format!("{other} is not a number")),
    }
}

fn expr(v: &Json) -> Result<Expr, String> {
    match v {
        Json::String(s) => Expr::parse(s),
        Json::Number(_) => int(v).map(Expr::constant),
        other => Err(format!("{other} is not an expression")),
    }
}

fn default_value(v: &Json, t: DataType) -> Result<Value, String> {
    use DataType::*;
    match t {
        VisibleString | UnicodeString => match v {
            Json::String(s) => Ok(Value::Text(s.clone())),
            other => Err(format!("{other} is not a text")),
        },
        F32 | F64 => float(v).map(Value::Float),
        Boolean => int(v).map(|x| Value::Bool(x != 0)),
        I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64 => int(v).map(Value::Signed),
        OctetString | Domain | TimeOfDay | TimeDifference => match v {
            Json::String(s) => hex_bytes(s)
                .map(Value::Bytes)
                .ok_or_else(|| format!("`{s}` is not hex bytes")),
            other => Err(format!("{other} is not hex bytes")),
        },
        _ => int(v).map(|x| Value::Unsigned(x as u64)),
    }
}

/// `"01 02 0A"` or `"01020A"` as bytes.
fn hex_bytes(s: &str) -> Option<Vec<u8>> {
    let digits: Vec<u8> = s.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
    if !digits.len().is_multiple_of(2) {
        return None;
    }
    digits
        .chunks(2)
        .map(|p| Some(crate::hex::nibble(p[0])? << 4 | crate::hex::nibble(p[1])?))
        .collect()
}

/// `"0x6041:0/16"`, `"0x6041/16"` or a CiA mapping value `"0x60410010"` / number.
fn mapped_entry(v: &Json) -> Result<MappedEntry, String> {
    let from_raw = |raw: i64| -> Result<MappedEntry, String> {
        let raw = u32::try_from(raw).map_err(|_| format!("{raw} is not a 32-bit mapping value"))?;
        Ok(MappedEntry {
            index: (raw >> 16) as u16,
            sub: (raw >> 8) as u8,
            bits: raw as u8,
        })
    };
    let e = match v {
        Json::Number(_) => from_raw(int(v)?)?,
        Json::String(s) => match s.split_once('/') {
            Some((obj, bits)) => {
                let (index, sub) = parse_object_ref(obj).ok_or_else(|| format!("`{obj}` is not an object"))?;
                let bits = bits
                    .trim()
                    .parse::<u8>()
                    .map_err(|_| format!("`{bits}` is not a bit length"))?;
                MappedEntry { index, sub, bits }
            }
            None => from_raw(parse_int(s).ok_or_else(|| format!("`{s}` is not a mapping (use 0xINDEX:SUB/BITS)"))?)?,
        },
        other => return Err(format!("{other} is not a mapping entry")),
    };
    if e.bits == 0 || e.bits > 64 {
        return Err(format!(
            "bit length {} of 0x{:04X}:{} is not 1..64",
            e.bits, e.index, e.sub
        ));
    }
    Ok(e)
}

/// `"0x1400..0x15FF"` as (first, last).
fn index_range(key: &str) -> Option<(u16, u16)> {
    let (a, b) = key.split_once("..")?;
    let idx = |t: &str| {
        parse_object_ref(t)
            .filter(|(_, s)| *s == 0 && !t.contains(':'))
            .map(|(i, _)| i)
    };
    let (first, last) = (idx(a)?, idx(b)?);
    (first <= last).then_some((first, last))
}

/// `"3"`, `"0x1A"` or `"1..127"`.
fn sub_range(key: &str) -> Result<std::ops::RangeInclusive<u8>, String> {
    let one = |t: &str| {
        parse_int(t)
            .and_then(|v| u8::try_from(v).ok())
            .ok_or_else(|| format!("`{t}` is not a sub 0..255"))
    };
    match key.split_once("..") {
        Some((a, b)) => {
            let (a, b) = (one(a)?, one(b)?);
            if a > b {
                return Err(format!("empty sub range `{key}`"));
            }
            Ok(a..=b)
        }
        None => one(key).map(|s| s..=s),
    }
}

/// `"0x3046"` (all subs), `"0x303F:0x11"` (one sub) or `"0x6000..0x67FF"`.
fn object_range(text: &str) -> Result<ObjectRange, String> {
    if let Some((a, b)) = text.split_once("..") {
        let idx = |t: &str| parse_object_ref(t).filter(|(_, s)| *s == 0).map(|(i, _)| i);
        let (Some(first), Some(last)) = (idx(a), idx(b)) else {
            return Err(format!("`{text}` is not an index range (0xFIRST..0xLAST)"));
        };
        if first > last {
            return Err(format!("empty index range `{text}`"));
        }
        return Ok(ObjectRange { first, last, sub: None });
    }
    let (index, sub) = parse_object_ref(text).ok_or_else(|| format!("`{text}` is not an object"))?;
    let one_sub = text.contains(':') || text.to_ascii_lowercase().contains("sub");
    Ok(ObjectRange {
        first: index,
        last: index,
        sub: one_sub.then_some(sub),
    })
}

/// A data type by profile name (`u16`) or CiA name (`UNSIGNED16`), case-insensitive.
pub fn parse_type(name: &str) -> Option<DataType> {
    use DataType::*;
    let n: String = name
        .chars()
        .filter(|c| *c != '_' && *c != ' ')
        .collect::<String>()
        .to_ascii_lowercase();
    Some(match n.as_str() {
        "boolean" | "bool" => Boolean,
        "i8" | "integer8" => I8,
        "i16" | "integer16" => I16,
        "i24" | "integer24" => I24,
        "i32" | "integer32" => I32,
        "i40" | "integer40" => I40,
        "i48" | "integer48" => I48,
        "i56" | "integer56" => I56,
        "i64" | "integer64" => I64,
        "u8" | "unsigned8" => U8,
        "u16" | "unsigned16" => U16,
        "u24" | "unsigned24" => U24,
        "u32" | "unsigned32" => U32,
        "u40" | "unsigned40" => U40,
        "u48" | "unsigned48" => U48,
        "u56" | "unsigned56" => U56,
        "u64" | "unsigned64" => U64,
        "f32" | "real32" => F32,
        "f64" | "real64" => F64,
        "visiblestring" => VisibleString,
        "octetstring" => OctetString,
        "unicodestring" => UnicodeString,
        "timeofday" => TimeOfDay,
        "timedifference" => TimeDifference,
        "domain" => Domain,
        _ => return None,
    })
}

/// An access name: `ro`, `wo`, `rw`, `rwr`, `rww`, `const` (case-insensitive).
pub fn parse_access(name: &str) -> Option<Access> {
    Some(match name.trim().to_ascii_lowercase().as_str() {
        "ro" => Access::Ro,
        "wo" => Access::Wo,
        "rw" => Access::Rw,
        "rwr" => Access::Rwr,
        "rww" => Access::Rww,
        "const" => Access::Const,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(p.object_names[&0x19FF], "TPDO512 communication parameter");
        assert_eq!(p.object(0x1800, 1).unwrap().name, "COB-ID used by TPDO1");
        assert_eq!(p.object_names[&0x1801], "Special TPDO");
        assert_eq!(p.object(0x1801, 1), None);
        assert_eq!(p.object(0x1801, 2).unwrap().name, "Transmission type");
        assert_eq!(p.object(0x1A00, 0).unwrap().name, "Number of mapped objects");
        // A record range without {i} in its subs is kept once, not per index.
        assert_eq!(p.ranges.len(), 1);
        assert_eq!(p.object_names[&0x17FF], "RPDO512 mapping parameter");
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
        assert_eq!(w.len(), 18, "{w:#?}");
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
}
