//! What `dcf save` reads and what `dcf load` writes, in which order: pure functions of
//! dictionaries, DCF text and values read, so they are tested without a bus.

use crate::command::pdo::remap::{Action, Mapping, Remap, RemapWrite, remap_sequence};
use crate::od::eds::{ParameterValue, parse_number};
use crate::od::{Access, DataType, Dictionary, Profile};
use std::collections::{BTreeMap, BTreeSet};

/// "save" (0x65766173), written to 0x1010:01 to store all parameters.
pub const STORE_SIGNATURE: u32 = 0x6576_6173;

/// Abort code: the object does not exist in the object dictionary.
pub const NO_OBJECT: u32 = 0x0602_0000;
/// Abort code: the sub-index does not exist.
pub const NO_SUB: u32 = 0x0609_0011;

/// One index `dcf save` reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadTarget {
    pub index: u16,
    /// The readable subs the dictionary knows, ascending. When there are subs besides 0,
    /// sub 0 (highest sub-index supported / number of entries) is read first and bounds the rest.
    pub subs: Vec<u8>,
    /// The index range (position in [`SavePlan::ranges`]) the index belongs to: a range is
    /// walked from its first index until an index the node does not have.
    pub range: Option<usize>,
}

/// What `dcf save` reads of a node, from its dictionary.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SavePlan {
    /// Every index, ascending.
    pub targets: Vec<ReadTarget>,
    /// The index ranges of the layers (PDO and SDO parameters), `(first, last)`.
    pub ranges: Vec<(u16, u16)>,
}

/// The subs a layer knows at `index`: its own entries, else its index range's.
fn layer_subs(p: &Profile, index: u16) -> Vec<u8> {
    let own: Vec<u8> = p.entries_at(index).into_iter().map(|(sub, _)| sub).collect();
    if !own.is_empty() {
        return own;
    }
    p.ranges
        .iter()
        .rev()
        .find(|r| (r.first..=r.last).contains(&index))
        .map(|r| r.subs.keys().copied().collect())
        .unwrap_or_default()
}

/// Every readable object the dictionary knows (all layers: EDS, profile, CiA 402, CiA 301),
/// as `dcf save` reads them.
pub fn save_plan(dict: &Dictionary) -> SavePlan {
    let mut ranges: Vec<(u16, u16)> = Vec::new();
    let mut explicit = BTreeSet::new();
    for p in dict.layers() {
        explicit.extend(p.objects.keys().chain(p.families.keys()).map(|k| k.0));
        for r in &p.ranges {
            if !ranges.contains(&(r.first, r.last)) {
                ranges.push((r.first, r.last));
            }
        }
    }
    let mut indices: BTreeSet<u16> = explicit;
    for (first, last) in &ranges {
        indices.extend(*first..=*last);
    }
    let targets = indices
        .into_iter()
        .filter_map(|index| {
            let mut subs: BTreeSet<u8> = BTreeSet::new();
            for p in dict.layers() {
                subs.extend(layer_subs(p, index));
            }
            let subs: Vec<u8> = subs
                .into_iter()
                .filter(|s| dict.object(index, *s).is_some_and(|o| o.access != Access::Wo))
                .collect();
            let range = ranges.iter().position(|(f, l)| (*f..=*l).contains(&index));
            (!subs.is_empty()).then_some(ReadTarget { index, subs, range })
        })
        .collect();
    SavePlan { targets, ranges }
}

/// Whether an index is a PDO mapping parameter, whose sub 0 is the number of mapped
/// objects rather than the highest sub-index supported.
pub fn is_mapping(index: u16) -> bool {
    matches!(index, 0x1600..=0x17FF | 0x1A00..=0x1BFF)
}

/// The subs to read after sub 0 answered `highest`: those known up to it, and for a PDO
/// mapping also the (unused) entries after its count, read until one the node does not have.
pub fn subs_after(target: &ReadTarget, highest: u8) -> Vec<u8> {
    target
        .subs
        .iter()
        .copied()
        .filter(|s| *s != 0 && (*s <= highest || is_mapping(target.index)))
        .collect()
}

/// One value of a DCF, typed, with where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct FileValue {
    pub index: u16,
    pub sub: u8,
    pub name: String,
    pub data_type: DataType,
    pub access: Access,
    /// The value as written in the file.
    pub text: String,
    /// The value encoded as its type.
    pub bytes: Vec<u8>,
    pub line: usize,
}

/// A problem at a line of a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Located {
    pub file: String,
    pub line: usize,
    pub message: String,
}

impl std::fmt::Display for Located {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: {}", self.file, self.line, self.message)
    }
}

/// A DCF as a load or diff uses it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DcfFile {
    /// The typed `ParameterValue`s, by (index, sub).
    pub values: Vec<FileValue>,
    /// The values left out, and why.
    pub problems: Vec<Located>,
    /// `[DeviceComissioning] NodeID`: the node the file was made for.
    pub node_id: Option<u8>,
}

/// The `ParameterValue`s of a DCF, typed by the DCF's own `DataType` (else the node's
/// dictionary); a value that does not fit its type, or an object of no known type, is a
/// located problem and left out. `node` replaces `$NODEID`.
pub fn read_dcf(file: &str, text: &str, node: u8, dict: &Dictionary) -> DcfFile {
    let (own, _) = crate::od::eds::import(file, text, node);
    let mut values = Vec::new();
    let mut problems = Vec::new();
    for ParameterValue { index, sub, text, line } in crate::od::eds::parameter_values(text) {
        let Some(info) = own.object(index, sub).or_else(|| dict.object(index, sub)) else {
            problems.push(Located {
                file: file.to_string(),
                line,
                message: format!("0x{index:04X}:{sub:02X}: no DataType in the file or the node's dictionary, skipped"),
            });
            continue;
        };
        match value_bytes(&text, info.data_type, node) {
            Ok(bytes) => values.push(FileValue {
                index,
                sub,
                name: info.name.clone(),
                data_type: info.data_type,
                access: info.access,
                text,
                bytes,
                line,
            }),
            Err(e) => problems.push(Located {
                file: file.to_string(),
                line,
                message: format!("0x{index:04X}:{sub:02X} {}: ParameterValue {e}, skipped", info.name),
            }),
        }
    }
    values.sort_by_key(|v| (v.index, v.sub));
    DcfFile {
        values,
        problems,
        node_id: own.node_id,
    }
}

/// A DCF value text as the bytes of `ty`: CiA 306 numbers (`0x` hex, octal, decimal,
/// `$NODEID+...`; hex of a signed type as two's complement), floats, visible strings as
/// written, octet strings and domains as hex digits.
pub fn value_bytes(text: &str, ty: DataType, node: u8) -> Result<Vec<u8>, String> {
    use DataType::*;
    let number = || parse_number(text, node).map_err(|e| e.to_string());
    match ty {
        VisibleString => Ok(text.as_bytes().to_vec()),
        UnicodeString => Ok(text.encode_utf16().flat_map(|u| u.to_le_bytes()).collect()),
        OctetString | Domain | TimeOfDay | TimeDifference => {
            let digits = text.trim().trim_start_matches("0x").trim_start_matches("0X");
            crate::command::value::parse_hex(digits).map_err(|e| e.to_string())
        }
        F32 | F64 => {
            let x: f64 = text.trim().parse().map_err(|_| format!("`{text}` is not a number"))?;
            Ok(if ty == F32 {
                (x as f32).to_le_bytes().to_vec()
            } else {
                x.to_le_bytes().to_vec()
            })
        }
        Boolean => match number()? {
            0 => Ok(vec![0]),
            1 => Ok(vec![1]),
            v => Err(format!("{v} does not fit BOOLEAN (0 or 1)")),
        },
        _ => {
            let size = ty.size().unwrap_or(8);
            let bits = 8 * size as u32;
            let v = number()?;
            let signed = matches!(ty, I8 | I16 | I24 | I32 | I40 | I48 | I56 | I64);
            let hex = text.trim().to_ascii_lowercase().starts_with("0x");
            let fits = bits == 64
                || if signed {
                    let half = 1i64 << (bits - 1);
                    (-half..half).contains(&v) || (hex && (0..2 * half).contains(&v))
                } else {
                    (0..1i64 << bits).contains(&v)
                };
            if !fits {
                return Err(format!("`{text}` does not fit {} ({bits} bits)", type_name(ty)));
            }
            Ok(v.to_le_bytes()[..size].to_vec())
        }
    }
}

/// The CiA 301 name of a type, for messages.
fn type_name(ty: DataType) -> String {
    format!("{ty:?}").to_uppercase()
}

/// Whether the node's bytes hold the file's value: numbers compared at the type's size
/// (a node may answer with fewer bytes), strings without trailing NULs.
pub fn same_value(ty: DataType, file: &[u8], node: &[u8]) -> bool {
    match (ty, ty.size()) {
        (DataType::VisibleString, _) => trim_nul(file) == trim_nul(node),
        (_, Some(size)) => {
            let at = |b: &[u8], i: usize| b.get(i).copied().unwrap_or(0);
            (0..size.max(node.len()).max(file.len())).all(|i| at(file, i) == at(node, i))
        }
        _ => file == node,
    }
}

fn trim_nul(b: &[u8]) -> &[u8] {
    let end = b.iter().rposition(|c| *c != 0).map_or(0, |i| i + 1);
    &b[..end]
}

/// Why a load never writes an object, whatever the file says (commands and set-points,
/// not configuration): [`crate::od::not_configuration`].
pub use crate::od::not_configuration as never_written;

/// What a file value is against the node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum State {
    /// The node has the file's value.
    Unchanged,
    /// Writable, and the node has another value: to be written.
    Differs,
    /// Read-only (or const): never written; `differs` when the node has another value.
    ReadOnly { differs: bool },
    /// Never written (see [`never_written`]), or write-only (nothing to compare).
    Skipped(&'static str),
    /// The node does not have the object (abort text).
    NotInNode(String),
    /// The node refused to read it (abort text).
    Unreadable(String),
}

/// A file value with the node's value and what that makes it.
#[derive(Clone, Debug, PartialEq)]
pub struct Compared {
    pub file: FileValue,
    /// The node's bytes, when read.
    pub node: Option<Vec<u8>>,
    pub state: State,
}

/// What the node said to a read: its bytes, or an abort code.
pub type ReadResult = Result<Vec<u8>, u32>;

/// Whether a file value is read from the node at all (not for the objects never written,
/// nor write-only ones).
pub fn needs_read(v: &FileValue) -> bool {
    v.access != Access::Wo && never_written(v.index).is_none()
}

/// Compares the file's values with what the node answered (`reads`, by (index, sub)).
pub fn compare(values: &[FileValue], reads: &BTreeMap<(u16, u8), ReadResult>) -> Vec<Compared> {
    values
        .iter()
        .map(|v| {
            let read = reads.get(&(v.index, v.sub));
            let state = if let Some(why) = never_written(v.index) {
                State::Skipped(why)
            } else if v.access == Access::Wo {
                State::Skipped("write-only (nothing to compare)")
            } else {
                match read {
                    None => State::Skipped("not read"),
                    Some(Err(code @ (NO_OBJECT | NO_SUB))) => {
                        State::NotInNode(crate::sdo::abort_text(*code).to_string())
                    }
                    Some(Err(code)) => State::Unreadable(format!("0x{code:08X} {}", crate::sdo::abort_text(*code))),
                    Some(Ok(bytes)) => {
                        let differs = !same_value(v.data_type, &v.bytes, bytes);
                        match v.access {
                            Access::Ro | Access::Const => State::ReadOnly { differs },
                            _ if differs => State::Differs,
                            _ => State::Unchanged,
                        }
                    }
                }
            };
            Compared {
                file: v.clone(),
                node: read.and_then(|r| r.as_ref().ok()).cloned(),
                state,
            }
        })
        .collect()
}

/// One SDO write of a load.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Write {
    pub index: u16,
    pub sub: u8,
    pub bytes: Vec<u8>,
    /// Why: `value` for a file value, else the step of a PDO sequence.
    pub step: Step,
}

/// What a write is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Step {
    /// A value of the file.
    Value,
    /// COB-ID bit 31 set: the PDO is invalid while it is changed.
    Invalidate,
    /// Mapping count 0: the mapping may be changed.
    ClearMapping,
}

impl From<RemapWrite> for Write {
    fn from(w: RemapWrite) -> Write {
        let step = match w.action {
            Action::Invalidate => Step::Invalidate,
            Action::ClearMapping => Step::ClearMapping,
            Action::Comm | Action::Entry | Action::Count | Action::Cob => Step::Value,
        };
        Write {
            index: w.index,
            sub: w.sub,
            bytes: w.data,
            step,
        }
    }
}

/// Whether an index is a PDO parameter: `(comm index, mapping index)` of its PDO.
fn pdo_of(index: u16) -> Option<(u16, u16)> {
    match index {
        0x1400..=0x15FF => Some((index, index + 0x200)),
        0x1600..=0x17FF => Some((index - 0x200, index)),
        0x1800..=0x19FF => Some((index, index + 0x200)),
        0x1A00..=0x1BFF => Some((index - 0x200, index)),
        _ => None,
    }
}

fn u32_of(b: &[u8]) -> u32 {
    let mut le = [0u8; 4];
    let n = b.len().min(4);
    le[..n].copy_from_slice(&b[..n]);
    u32::from_le_bytes(le)
}

/// A PDO of the file that a load does not touch (nothing of it is sent), and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PdoRefused {
    /// Its communication parameter index (0x1400.., 0x1800..).
    pub comm: u16,
    /// Its mapping parameter index (0x1600.., 0x1A00..).
    pub mapping: u16,
    pub reason: String,
}

/// Why the file's configuration of the PDO `(comm, mapping)` must not be loaded: the checks
/// `pdo map` makes ([`crate::command::pdo::entry_refusal`], [`crate::command::pdo::cob_refusal`]):
/// at most 64 mapped bits and 64 entries, each entry's length its object's type and the
/// object mappable in the PDO's direction per `dict`, a COB-ID that is valid and not another
/// service's. Entries and COB-ID as they would be after the load (the file's, else the node's).
fn pdo_refusal(compared: &[Compared], dict: &Dictionary, (comm, mapping): (u16, u16)) -> Option<String> {
    let at = |index: u16, sub: u8| compared.iter().find(|c| c.file.index == index && c.file.sub == sub);
    let differs = |index: u16, sub: u8| at(index, sub).is_some_and(|c| c.state == State::Differs);
    if differs(comm, 1)
        && let Some(why) = at(comm, 1).and_then(|c| crate::command::pdo::cob_refusal(u32_of(&c.file.bytes)))
    {
        return Some(why);
    }
    if !compared
        .iter()
        .any(|c| c.file.index == mapping && c.state == State::Differs)
    {
        return None;
    }
    let count = at(mapping, 0).and_then(|c| c.file.bytes.first().copied()).unwrap_or(0);
    if count > 64 {
        return Some(format!("0x{mapping:04X}:00 maps {count} entries, more than 64"));
    }
    let transmit = comm >= 0x1800;
    let mut total = 0u32;
    for sub in 1..=count {
        // An entry the file does not give keeps the node's value, which the node accepted.
        let Some(c) = at(mapping, sub) else { continue };
        let raw = u32_of(&c.file.bytes);
        let e = crate::decode::pdo::entry_from_u32(raw);
        total += u32::from(e.bits);
        // The dictionary's own default mapping is not refused: EDS files often map an object
        // by default into a direction its access type does not name (SERVO-DS maps 0x6060,
        // `rww`, into TPDO1), and the node, which took that default, judges it on the bus.
        let default = dict.object(mapping, sub).and_then(|o| o.default.as_ref());
        let dictionary_default = matches!(default, Some(crate::od::Value::Unsigned(d)) if *d == u64::from(raw));
        if !dictionary_default
            && let Some(why) = crate::command::pdo::entry_refusal(dict, transmit, (e.index, e.sub), e.bits, false)
        {
            return Some(format!(
                "entry {sub} (0x{:04X}:{:02X}, {} bits): {why}",
                e.index, e.sub, e.bits
            ));
        }
    }
    (total > 64).then(|| format!("{count} entries map {total} bits, more than the 64 bits a PDO carries"))
}

/// The PDOs of the file a load refuses ([`pdo_refusal`]), before anything is sent.
pub fn pdo_refusals(compared: &[Compared], dict: &Dictionary) -> Vec<PdoRefused> {
    let pdos: BTreeSet<(u16, u16)> = compared
        .iter()
        .filter(|c| c.state == State::Differs)
        .filter_map(|c| pdo_of(c.file.index))
        .collect();
    pdos.into_iter()
        .filter_map(|pdo| {
            pdo_refusal(compared, dict, pdo).map(|reason| PdoRefused {
                comm: pdo.0,
                mapping: pdo.1,
                reason,
            })
        })
        .collect()
}

/// The writes of a load, in an order that works: application objects first (index order),
/// then the communication objects 0x1000-0x1FFF, each PDO's communication and mapping
/// parameters together by the sequence `pdo map` writes too ([`remap_sequence`]; RPDOs,
/// then TPDOs) last. The PDOs in `refused` are left out whole.
pub fn load_plan(compared: &[Compared], refused: &[PdoRefused]) -> Vec<Vec<Write>> {
    let value = |c: &Compared| Write {
        index: c.file.index,
        sub: c.file.sub,
        bytes: c.file.bytes.clone(),
        step: Step::Value,
    };
    let differs = |c: &&Compared| c.state == State::Differs;
    let mut groups: Vec<Vec<Write>> = Vec::new();
    let app = compared
        .iter()
        .filter(differs)
        .filter(|c| !(0x1000..=0x1FFF).contains(&c.file.index));
    let comm = compared
        .iter()
        .filter(differs)
        .filter(|c| (0x1000..=0x1FFF).contains(&c.file.index) && pdo_of(c.file.index).is_none());
    groups.extend(app.chain(comm).map(|c| vec![value(c)]));
    let mut pdos: BTreeSet<(u16, u16)> = BTreeSet::new();
    pdos.extend(compared.iter().filter(differs).filter_map(|c| pdo_of(c.file.index)));
    for (comm, mapping) in pdos {
        if refused.iter().any(|r| r.comm == comm) {
            continue;
        }
        let at = |index: u16, sub: u8| compared.iter().find(|c| c.file.index == index && c.file.sub == sub);
        let mapping_changes = compared
            .iter()
            .any(|c| c.file.index == mapping && c.state == State::Differs);
        // The active entries (1..count) all, the unused ones after them where they differ.
        let count = at(mapping, 0).and_then(|c| c.file.bytes.first().copied()).unwrap_or(0);
        let mapping_entries = mapping_changes.then(|| Mapping {
            entries: compared
                .iter()
                .filter(|c| c.file.index == mapping && c.file.sub > 0)
                .filter(|c| c.file.sub <= count || c.state == State::Differs)
                .map(|c| (c.file.sub, u32_of(&c.file.bytes)))
                .collect(),
            count,
        });
        let (node_cob, file_cob) = (
            at(comm, 1).and_then(|c| c.node.as_deref()).map(u32_of),
            at(comm, 1).map(|c| u32_of(&c.file.bytes)),
        );
        let remap = Remap {
            comm,
            mapping,
            current_cob: node_cob.or(file_cob),
            final_cob: file_cob.or(node_cob),
            comm_subs: compared
                .iter()
                .filter(|c| c.file.index == comm && c.file.sub > 1 && c.state == State::Differs)
                .map(|c| (c.file.sub, c.file.bytes.clone()))
                .collect(),
            mapping_entries,
        };
        groups.push(remap_sequence(&remap).into_iter().map(Write::from).collect());
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fv(index: u16, sub: u8, ty: DataType, access: Access, bytes: &[u8]) -> FileValue {
        FileValue {
            index,
            sub,
            name: format!("{index:04X}:{sub}"),
            data_type: ty,
            access,
            text: String::new(),
            bytes: bytes.to_vec(),
            line: 1,
        }
    }

    #[test]
    fn dcf_value_texts_become_typed_bytes() {
        assert_eq!(value_bytes("0x185", DataType::U32, 5), Ok(vec![0x85, 1, 0, 0]));
        assert_eq!(value_bytes("$NODEID+0x180", DataType::U32, 5), Ok(vec![0x85, 1, 0, 0]));
        assert_eq!(value_bytes("-2", DataType::I16, 5), Ok(vec![0xFE, 0xFF]));
        assert_eq!(value_bytes("0xFFFE", DataType::I16, 5), Ok(vec![0xFE, 0xFF]));
        assert_eq!(value_bytes("drive", DataType::VisibleString, 5), Ok(b"drive".to_vec()));
        assert_eq!(value_bytes("01AB", DataType::OctetString, 5), Ok(vec![1, 0xAB]));
        assert_eq!(value_bytes("1.5", DataType::F32, 5), Ok(1.5f32.to_le_bytes().to_vec()));
        assert_eq!(
            value_bytes("300", DataType::U8, 5),
            Err("`300` does not fit U8 (8 bits)".into())
        );
        assert_eq!(
            value_bytes("-1", DataType::U16, 5),
            Err("`-1` does not fit U16 (16 bits)".into())
        );
        assert_eq!(value_bytes("x1", DataType::U16, 5), Err("`x1` is not a number".into()));
        assert!(value_bytes("2", DataType::Boolean, 5).is_err());
    }

    #[test]
    fn a_dcf_gives_typed_values_and_located_problems() {
        let text = "[DeviceInfo]\nVendorName=x\n\n[OptionalObjects]\nSupportedObjects=2\n1=0x1017\n2=0x6060\n\n\
            [1017]\nParameterName=Producer heartbeat time\nDataType=0x0006\nAccessType=rw\nParameterValue=0x3E8\n\n\
            [6060]\nParameterName=Modes of operation\nDataType=0x0002\nAccessType=rw\nParameterValue=200\n\n\
            [2001]\nParameterName=Gain\nAccessType=rw\nParameterValue=0x10\n";
        let dict = Dictionary::default();
        let DcfFile { values, problems, .. } = read_dcf("n5.dcf", text, 5, &dict);
        assert_eq!(values.len(), 2, "{values:?}");
        assert_eq!(
            (values[0].index, values[0].bytes.clone(), values[0].line),
            (0x1017, vec![0xE8, 3], 13)
        );
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert_eq!(
            problems[0].to_string(),
            "n5.dcf:19: 0x6060:00 Modes of operation: ParameterValue `200` does not fit I8 (8 bits), skipped"
        );
        // 0x2001 has no DataType: the importer reads it as a domain, 0x10 as hex bytes.
        assert_eq!(values[1].index, 0x2001);
        assert_eq!(values[1].data_type, DataType::Domain);
    }

    #[test]
    fn values_compare_at_their_type_size() {
        assert!(same_value(DataType::U32, &[1, 0, 0, 0], &[1]));
        assert!(!same_value(DataType::U32, &[1, 0, 0, 0], &[1, 0, 0, 1]));
        assert!(same_value(DataType::VisibleString, b"ab", b"ab\0\0"));
        assert!(!same_value(DataType::U16, &[1, 0], &[1, 0, 0, 1]));
    }

    #[test]
    fn comparison_sorts_values_into_states() {
        let values = [
            fv(0x1017, 0, DataType::U16, Access::Rw, &[0xE8, 3]),
            fv(0x1018, 1, DataType::U32, Access::Ro, &[1, 0, 0, 0]),
            fv(0x6040, 0, DataType::U16, Access::Rw, &[6, 0]),
            fv(0x6083, 0, DataType::U32, Access::Rw, &[1, 0, 0, 0]),
            fv(0x2100, 0, DataType::U8, Access::Rw, &[1]),
            fv(0x2101, 0, DataType::U8, Access::Rw, &[1]),
        ];
        let reads: BTreeMap<(u16, u8), ReadResult> = [
            ((0x1017, 0), Ok(vec![0xE8, 3])),
            ((0x1018, 1), Ok(vec![2, 0, 0, 0])),
            ((0x6083, 0), Ok(vec![2, 0, 0, 0])),
            ((0x2100, 0), Err(NO_OBJECT)),
            ((0x2101, 0), Err(0x0601_0001)),
        ]
        .into_iter()
        .collect();
        let states: Vec<State> = compare(&values, &reads).into_iter().map(|c| c.state).collect();
        assert_eq!(
            states,
            [
                State::Unchanged,
                State::ReadOnly { differs: true },
                State::Skipped("controlword (a command, not configuration)"),
                State::Differs,
                State::NotInNode("Object does not exist in the object dictionary".into()),
                State::Unreadable("0x06010001 Attempt to read a write only object".into()),
            ]
        );
        assert!(!needs_read(&values[2]));
    }

    #[test]
    fn load_order_puts_communication_last_and_pdos_as_units() {
        let mut values = vec![
            fv(0x1017, 0, DataType::U16, Access::Rw, &[0xE8, 3]),
            fv(0x1A00, 0, DataType::U8, Access::Rw, &[1]),
            fv(0x1A00, 1, DataType::U32, Access::Rw, &[0x10, 0, 0x41, 0x60]),
            // Unused entries after the count: written where they differ only.
            fv(0x1A00, 2, DataType::U32, Access::Rw, &[0, 0, 0, 0]),
            fv(0x1A00, 3, DataType::U32, Access::Rw, &[0, 0, 0, 0]),
            fv(0x1800, 1, DataType::U32, Access::Rw, &[0x85, 1, 0, 0]),
            fv(0x1800, 2, DataType::U8, Access::Rw, &[0xFF]),
            fv(0x6083, 0, DataType::U32, Access::Rw, &[1, 0, 0, 0]),
        ];
        values.sort_by_key(|v| (v.index, v.sub));
        let reads: BTreeMap<(u16, u8), ReadResult> = [
            ((0x1017, 0), Ok(vec![0, 0])),
            ((0x1A00, 0), Ok(vec![1])),
            ((0x1A00, 1), Ok(vec![0x10, 0, 0x40, 0x60])),
            ((0x1A00, 2), Ok(vec![0x20, 0, 0x64, 0x60])),
            ((0x1A00, 3), Ok(vec![0, 0, 0, 0])),
            ((0x1800, 1), Ok(vec![0x85, 1, 0, 0])),
            ((0x1800, 2), Ok(vec![0xFF])),
            ((0x6083, 0), Ok(vec![2, 0, 0, 0])),
        ]
        .into_iter()
        .collect();
        let plan = load_plan(&compare(&values, &reads), &[]);
        let order: Vec<Vec<(u16, u8, Step)>> = plan
            .iter()
            .map(|g| g.iter().map(|w| (w.index, w.sub, w.step)).collect())
            .collect();
        assert_eq!(
            order,
            [
                vec![(0x6083, 0, Step::Value)],
                vec![(0x1017, 0, Step::Value)],
                vec![
                    (0x1800, 1, Step::Invalidate),
                    (0x1A00, 0, Step::ClearMapping),
                    (0x1A00, 1, Step::Value),
                    (0x1A00, 2, Step::Value),
                    (0x1A00, 0, Step::Value),
                    (0x1800, 1, Step::Value),
                ],
            ]
        );
    }

    #[test]
    fn save_reads_what_the_dictionaries_know() {
        let dict = crate::od::bind::Bindings::new().dictionary(5).clone();
        let plan = save_plan(&dict);
        let t = |i: u16| plan.targets.iter().find(|t| t.index == i).cloned();
        assert_eq!(t(0x1000).map(|t| t.subs), Some(vec![0]));
        assert_eq!(t(0x1018).map(|t| t.subs), Some(vec![0, 1, 2, 3, 4]));
        let tpdo1 = t(0x1800).unwrap();
        assert!(tpdo1.range.is_some() && tpdo1.subs.starts_with(&[0, 1, 2]));
        assert!(t(0x6041).is_some() && t(0x6040).is_some());
        assert_eq!(subs_after(&t(0x1018).unwrap(), 2), [1, 2]);
        // A mapping's unused entries too (read until the node has no more).
        assert_eq!(subs_after(&t(0x1A00).unwrap(), 2).len(), 64);
    }
}
