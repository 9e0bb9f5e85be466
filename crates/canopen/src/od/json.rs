//! Loads device profiles from JSON (`decoders/*.json`, format in `docs/PROFILE_FORMAT.md`).
//!
//! The JSON is read into DTOs with serde; everything a DTO field can hold in
//! more than one way (numbers as numbers or hex strings, expressions) is kept
//! as a JSON value and checked while converting to a [`Profile`]. Wrong JSON
//! syntax or types are a [`LoadError`] with path and line; anything else is a
//! [`Warning`] and the offending item is skipped.

use std::collections::BTreeMap;
use std::fmt;
use std::ops::RangeInclusive;

use serde_json::Value as Json;

use super::alias::{AliasRule, parse_object_ref};
use super::device::{Axis, IdCondition, IdTest, IndexRange, PdoSet, PdoTemplate, TextMatch};
use super::expr::{Expr, parse_int};
use super::family::{Numbered, SubFamily, fill};
use super::fields::{ByteField, SdoCommand, SdoDirection};
use super::mapping::MappingSource;
use super::object::{ObjectInfo, PdoMappable, Warning};
use super::procedure::{
    FailIf, NmtCommand, ProcParam, Procedure, ProcedureError, Step, object_variables, parse_frame_data,
};
use super::profile::Profile;

/// The newest profile format this loader knows.
pub(crate) const FORMAT_VERSION: u64 = 1;

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

mod dto;
#[cfg(test)]
mod tests;
mod values;

use dto::*;
use values::{ValueError, byte, default_value, expr, float, index_range, int, mapped_entry, object_range, sub_range};
pub use values::{parse_access, parse_type};

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

/// Loads a built-in profile: as [`load_profile`], but unknown fields are not tracked
/// (a built-in has none, its tests check that with [`load_profile`]), which makes it
/// several times cheaper. Malformed text falls back to [`load_profile`] for a located error.
pub fn load_builtin_profile(file: &str, text: &str) -> Result<(Profile, Vec<Warning>), LoadError> {
    let Ok(dto) = serde_json::from_str::<ProfileDto>(text) else {
        return load_profile(file, text);
    };
    let mut cx = Cx {
        file,
        warnings: Vec::new(),
    };
    let profile = cx.profile(dto);
    Ok((profile, cx.warnings))
}

/// Most entries one index-range key may expand to.
const MAX_RANGE_ENTRIES: usize = 100_000;

/// The entries of one `objects` key before they are placed at an index.
struct Built {
    /// A record/array (replaces every sub of its index).
    record: bool,
    /// The record's name.
    name: Option<String>,
    /// The record's alias.
    alias: Option<String>,
    /// Entries by sub, given one by one; they win over a family covering the same sub.
    entries: Vec<(u8, ObjectInfo)>,
    /// Sub ranges (`"1..254"`), each kept as one template.
    families: Vec<SubFamily>,
}

impl Built {
    /// Every entry by sub, the families' made one by one.
    fn subs(&self) -> BTreeMap<u8, ObjectInfo> {
        let mut subs: BTreeMap<u8, ObjectInfo> = self
            .families
            .iter()
            .flat_map(|f| f.iter().map(|(n, info)| (n, info.clone())))
            .collect();
        subs.extend(self.entries.iter().cloned());
        subs
    }

    /// How many entries it stands for.
    fn len(&self) -> usize {
        let families: usize = self.families.iter().map(|f| f.subs().count()).sum();
        self.entries.len() + families
    }

    /// Whether any name depends on the index (`{i}`).
    fn names_index(&self) -> bool {
        let templates = self.families.iter().map(SubFamily::template);
        self.entries
            .iter()
            .map(|(_, e)| e)
            .chain(templates)
            .any(|e| e.name.contains("{i}"))
    }
}

/// Puts built entries at `index`; `nth` (1-based place in an index range) replaces `{i}` in names.
fn place(p: &mut Profile, index: u16, nth: Option<u32>, b: &Built, subs: &BTreeMap<u8, ObjectInfo>) {
    place_names(p, index, nth, b);
    for (sub, info) in subs {
        let mut info = info.clone();
        if let Some(i) = nth {
            info.name = nth_name(&info.name, i);
        }
        p.objects.insert((index, *sub), info);
    }
}

/// Puts a single object's built entries and families at `index`, moving them (no `{i}` to replace).
fn place_single(p: &mut Profile, index: u16, b: Built) {
    place_names(p, index, None, &b);
    for (sub, info) in b.entries {
        p.objects.insert((index, sub), info);
    }
    for family in b.families {
        p.add_family(index, family);
    }
}

/// Puts the record name and alias of `b` at `index`.
fn place_names(p: &mut Profile, index: u16, nth: Option<u32>, b: &Built) {
    let name = |n: &str| match nth {
        Some(i) => nth_name(n, i),
        None => n.to_string(),
    };
    if let Some(n) = &b.name {
        p.object_names.insert(index, name(n));
    }
    if let Some(a) = &b.alias {
        p.aliases.insert(name(a), (index, 0));
    }
}

/// Puts the record alias of `b` at every index of `first..=last`, `{i}` in it standing for
/// the 1-based place in the range. (The record names stay in the [`IndexRange`].)
fn place_range_aliases(p: &mut Profile, first: u16, last: u16, b: &Built) {
    if let Some(a) = &b.alias {
        let alias = Numbered::new(a, "{i}");
        for index in first..=last {
            p.aliases.insert(alias.with(u32::from(index - first) + 1), (index, 0));
        }
    }
}

/// `name` with `{i}` replaced by `i`.
fn nth_name(name: &str, i: u32) -> String {
    fill(name, "{i}", i)
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
    fn ok<T, E: std::fmt::Display>(&mut self, at: &str, r: Result<T, E>) -> Option<T> {
        r.map_err(|e| self.warn(at, e.to_string())).ok()
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
            if built.record && !built.names_index() {
                // Only the names go to each index; the subs stay in the template.
                place_range_aliases(&mut p, first, last, &built);
                p.ranges.push(IndexRange::new(first, last, built.subs(), built.name));
                continue;
            }
            let size = (usize::from(last - first) + 1) * built.len().max(1);
            if size > MAX_RANGE_ENTRIES {
                self.warn(
                    &at,
                    format!("range expands to {size} entries, more than {MAX_RANGE_ENTRIES}; skipped"),
                );
                continue;
            }
            let subs = built.subs();
            for index in first..=last {
                place(&mut p, index, Some(u32::from(index - first) + 1), &built, &subs);
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
                p.remove_index(index);
            }
            place_single(&mut p, index, built);
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
            for (code, steps) in emcy.check {
                let at = format!("emcy.check.{code}");
                match parse_int(&code).and_then(|c| u16::try_from(c).ok()) {
                    Some(c) => {
                        p.emcy_check.insert(c, steps);
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
                families: vec![],
            };
        };
        if sub != 0 {
            self.warn(&format!("{at}.subs"), "a sub-entry cannot have subs, ignored");
            return Built {
                record: false,
                name: None,
                alias: None,
                entries: vec![],
                families: vec![],
            };
        }
        if e.name.is_none() {
            self.warn(at, "record or array without a name");
        }
        if e.data_type.is_some() || e.access.is_some() || !e.values.is_empty() || e.unit.is_some() {
            self.warn(at, "type/access/unit/values of a record belong on its subs, ignored");
        }
        // Ranges first, then single subs: a single sub wins over a range that covers it.
        // Two ranges, or two single keys, giving the same sub cannot be resolved.
        let (ranges, singles): (Vec<_>, Vec<_>) = subs.into_iter().partition(|(k, _)| k.contains(".."));
        // The subs taken so far: range, whether by a single key, and the key.
        let mut taken: Vec<(RangeInclusive<u8>, bool, String)> = Vec::new();
        let mut entries: BTreeMap<u8, ObjectInfo> = BTreeMap::new();
        let mut families = Vec::new();
        for (key, s) in ranges.into_iter().chain(singles) {
            let at = format!("{at}.subs.{key}");
            let Some(range) = self.ok(&at, sub_range(&key)) else {
                continue;
            };
            let single = !key.contains("..");
            // The key holding the lowest sub of `range` already taken by the same kind of key.
            let overlapped = taken
                .iter()
                .filter(|(r, was_single, _)| {
                    *was_single == single && r.start() <= range.end() && range.start() <= r.end()
                })
                .min_by_key(|(r, _, _)| *r.start().max(range.start()));
            if let Some((_, _, other)) = overlapped {
                let what = if single { "sub" } else { "range" };
                self.warn(&at, format!("{what} `{key}` overlaps `{other}`, skipped"));
                continue;
            }
            if s.subs.is_some() {
                self.warn(&format!("{at}.subs"), "subs cannot nest, ignored");
            }
            let Some(info) = self.entry(&at, s) else { continue };
            taken.push((range.clone(), single, key));
            if single {
                entries.insert(*range.start(), info);
            } else {
                families.push(SubFamily::new(*range.start(), *range.end(), info));
            }
        }
        Built {
            record: true,
            name: e.name,
            alias: e.alias,
            entries: entries.into_iter().collect(),
            families,
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
        if let Some(m) = &e.meaning {
            match super::Meaning::parse(m) {
                Some(m) => info.meaning = Some(m),
                None => self.warn(
                    &format!("{at}.meaning"),
                    format!("unknown meaning `{m}` (cob_id, transmission_type, object_index)"),
                ),
            }
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
        for (i, f) in e.fields.into_iter().enumerate() {
            let at = format!("{at}.fields.{i}");
            if f.object.is_some() || f.object_sub.is_some() {
                self.warn(&at, "`object` only applies to sdo_commands fields, ignored");
            }
            if let Some(field) = self.field(&at, f, &[]) {
                match info.data_type.size() {
                    Some(n) if usize::from(field.offset + field.length) <= n => info.fields.push(field),
                    _ => self.warn(
                        &at,
                        format!("field does not fit the {:?} value, skipped", info.data_type),
                    ),
                }
            }
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
        let (hex, emcy) = match f.format.as_deref().map(str::to_ascii_lowercase).as_deref() {
            None | Some("dec") => (false, false),
            Some("hex") => (true, false),
            Some("emcy") => (true, true),
            Some(other) => {
                self.warn(
                    &format!("{at}.format"),
                    format!("unknown format `{other}` (dec, hex, emcy)"),
                );
                (false, false)
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
            emcy,
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
            let step = dto.map_err(StepError::from).and_then(step);
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

/// What is wrong with a procedure step of a profile.
#[derive(Debug, thiserror::Error)]
enum StepError {
    /// Not the shape of a step.
    #[error(transparent)]
    Shape(#[from] serde_json::Error),
    #[error("unknown type `{0}`")]
    UnknownType(String),
    #[error("unknown NMT command `{0}`")]
    UnknownNmt(String),
    /// The named number does not fit.
    #[error("{0} out of range")]
    OutOfRange(&'static str),
    #[error(transparent)]
    Value(#[from] ValueError),
    #[error(transparent)]
    Procedure(#[from] ProcedureError),
}

fn step(d: StepDto) -> Result<Step, StepError> {
    if let StepDto::SdoWrite { object, .. } | StepDto::SdoRead { object } = &d {
        object_variables(object)?;
    }
    if let StepDto::Wait {
        object: Some(object), ..
    } = &d
    {
        object_variables(object)?;
    }
    Ok(match d {
        StepDto::SdoWrite {
            object,
            value,
            data_type,
        } => {
            let data_type = match data_type {
                Some(t) => Some(parse_type(&t).ok_or(StepError::UnknownType(t))?),
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
            let command = NmtCommand::parse(&command).ok_or(StepError::UnknownNmt(command))?;
            let node = node.as_ref().map(expr).transpose()?;
            Step::Nmt { command, node }
        }
        StepDto::Wait {
            object,
            mask,
            equals,
            timeout_ms,
            fail_if,
        } => Step::Wait {
            fail_if: fail_if
                .map(|f| -> Result<FailIf, StepError> {
                    Ok(FailIf {
                        mask: f.mask.as_ref().map(expr).transpose()?.unwrap_or(Expr::constant(-1)),
                        equals: expr(&f.equals)?,
                        text: f.text,
                    })
                })
                .transpose()?,
            object: object.unwrap_or_else(|| "0x6041".to_string()),
            mask: mask.as_ref().map(expr).transpose()?.unwrap_or(Expr::constant(-1)),
            equals: expr(&equals)?,
            timeout_ms: match timeout_ms {
                Some(t) => u32::try_from(int(&t)?).map_err(|_| StepError::OutOfRange("timeout_ms"))?,
                None => 1000,
            },
        },
        StepDto::Frame { id, data } => Step::Frame {
            id: expr(&id)?,
            data: parse_frame_data(&data)?,
        },
        StepDto::DelayMs(ms) => Step::Delay {
            ms: u32::try_from(int(&ms)?).map_err(|_| StepError::OutOfRange("delay"))?,
        },
    })
}
