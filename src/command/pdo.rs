//! `pdo NODE`: reads every PDO's communication and mapping parameters by SDO and prints
//! them in words; `pdo NODE map PDO OBJECT...`: the CiA 301 remapping sequence of
//! [`remap`] (invalidate the COB-ID, communication parameters, count 0, entries, count,
//! COB-ID valid again), each answer checked, the result read back, a refusal explained.

pub mod command;
pub mod remap;

use super::error::{CommandError, ExitCode};
use super::report::Reported;
use super::sdo::{download, first_download_frame, first_upload_frame, upload};
use super::spec::candump;
use crate::bus::{Bus, Subscription};
use crate::cob;
use crate::decode::pdo::entry_from_u32;
use crate::decode::pdo_config::{
    COMM_SUBS, Cob, CommJson, CommParams, EntryJson, PdoId, entry_text, event_text, inhibit_text, transmission_text,
};
use crate::od::resolve_object;
use crate::od::{Dictionary, MappedEntry, PdoMappable};
use crate::sdo::abort_text;
use remap::{Action, Mapping, Remap, remap_sequence};
use serde::Serialize;
use std::time::Duration;

/// Abort 0x06020000: the object does not exist (the PDO is not there).
const NO_OBJECT: u32 = 0x0602_0000;
/// Abort 0x06090011: the sub-index does not exist.
const NO_SUB: u32 = 0x0609_0011;
/// The most bits a classic CAN PDO carries.
const MAX_BITS: u32 = 64;
/// How long a refusal waits for a heartbeat to tell the node's NMT state.
const HEARTBEAT_WAIT: Duration = Duration::from_millis(1500);

/// What `pdo NODE map PDO OBJECT...` asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct MapSpec {
    pub node: u8,
    pub pdo: PdoId,
    /// The objects to map, in order: index:sub, name or alias (`OBJECT/BITS` gives the
    /// length of an object the dictionary does not size).
    pub objects: Vec<String>,
    /// `--type`: the transmission type to write (sub 2).
    pub transmission: Option<u8>,
    /// `--event`: the event timer in ms (sub 5).
    pub event_ms: Option<u16>,
    /// `--inhibit`: the inhibit time in 100 µs units (sub 3).
    pub inhibit_100us: Option<u16>,
    /// `--cob-id`: the COB-ID to use (else the PDO's own).
    pub cob_id: Option<u32>,
    /// `--dry-run`: print the frames, send nothing.
    pub dry_run: bool,
    /// `--force`: map objects the dictionary says are not mappable.
    pub force: bool,
    /// The wait for each SDO answer, in ms.
    pub timeout_ms: u64,
}

/// One SDO write of a remapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Write {
    pub index: u16,
    pub sub: u8,
    pub data: Vec<u8>,
    /// What it does: `invalidate the COB-ID`, `mapping entry 1: 0x6041:00 Statusword, 16 bits`.
    pub what: String,
}

impl Write {
    fn new(index: u16, sub: u8, data: &[u8], what: impl Into<String>) -> Write {
        Write {
            index,
            sub,
            data: data.to_vec(),
            what: what.into(),
        }
    }
    /// The SDO request frame that writes it to `node` (expedited).
    pub fn frame(&self, node: u8) -> crate::frame::Frame {
        first_download_frame(node, self.index, self.sub, &self.data, false).0
    }
}

/// The entries `spec` maps, checked before anything is sent: every object resolved and
/// sized, mappable in this direction per the dictionary (unless `--force`), 64 bits at most.
pub fn entries(dict: &Dictionary, spec: &MapSpec) -> Result<Vec<MappedEntry>, CommandError> {
    let pdo = spec.pdo.title();
    let mut out = Vec::with_capacity(spec.objects.len());
    for text in &spec.objects {
        let (object, bits) = match text.rsplit_once('/') {
            Some((o, b)) if b.parse::<u8>().is_ok() => (o, b.parse::<u8>().ok()),
            _ => (text.as_str(), None),
        };
        let (index, sub) = resolve_object(dict, object).map_err(|e| CommandError::Usage(e.to_string()))?;
        let info = dict.object(index, sub);
        let name = || {
            format!(
                "0x{index:04X}:{sub:02X}{}",
                info.map(|o| format!(" {}", o.name)).unwrap_or_default()
            )
        };
        let bits = match bits.or_else(|| info.and_then(|o| o.data_type.size()).map(|s| (s * 8) as u8)) {
            Some(b) if b > 0 && u32::from(b) <= MAX_BITS => b,
            Some(b) => return Err(CommandError::Usage(format!("{}: {b} bits cannot be mapped", name()))),
            None => {
                return Err(CommandError::Usage(format!(
                    "the length of {} is not known from the node's dictionary: give it as {object}/BITS \
                     (e.g. {object}/16), or bind the node's EDS (--eds {}=FILE)",
                    name(),
                    spec.node
                )));
            }
        };
        if let Some(why) = entry_refusal(dict, spec.pdo.transmit, (index, sub), bits, spec.force) {
            return Err(CommandError::Usage(format!(
                "{} cannot be mapped into {pdo}: {why}; nothing sent (--force maps it anyway)",
                name()
            )));
        }
        out.push(MappedEntry { index, sub, bits });
    }
    if out.is_empty() {
        return Err(CommandError::Usage(format!(
            "map {}: name the objects to map",
            spec.pdo.name()
        )));
    }
    let total: u32 = out.iter().map(|e| u32::from(e.bits)).sum();
    if total > MAX_BITS {
        let list: Vec<String> = out.iter().map(|e| format!("{} bits", e.bits)).collect();
        return Err(CommandError::Usage(format!(
            "{pdo} of node {}: {total} bits mapped ({}), more than the 64 bits a PDO carries; nothing sent",
            spec.node,
            list.join(" + ")
        )));
    }
    Ok(out)
}

/// Why `bits` bits of the object at `(index, sub)` cannot go into a PDO (a TPDO when
/// `transmit`) by the node's dictionary: a length other than its type's (a BOOLEAN takes 1
/// or 8 bits; strings and domains any length up to 64 bits), or a direction the dictionary
/// does not map it in. `force` skips both checks. An object the dictionary does not know
/// (or a dummy entry) is the node's to judge: `None`.
pub fn entry_refusal(
    dict: &Dictionary,
    transmit: bool,
    (index, sub): (u16, u8),
    bits: u8,
    force: bool,
) -> Option<String> {
    let o = dict.object(index, sub).filter(|_| !force)?;
    let size_ok = match o.data_type.size() {
        _ if o.data_type == crate::od::DataType::Boolean => matches!(bits, 1 | 8),
        Some(size) => usize::from(bits) == size * 8,
        None => true,
    };
    if !size_ok {
        return Some(format!(
            "{bits} bits given, but the node's dictionary ({}) types it {:?}, {} bits",
            dict.profile_name(),
            o.data_type,
            o.data_type.size().unwrap_or(0) * 8
        ));
    }
    let into = match o.pdo {
        PdoMappable::Both => return None,
        PdoMappable::Tpdo if transmit => return None,
        PdoMappable::Rpdo if !transmit => return None,
        PdoMappable::No => "into no PDO",
        PdoMappable::Tpdo => "only into TPDOs",
        PdoMappable::Rpdo => "only into RPDOs",
    };
    Some(format!(
        "the node's dictionary ({}) maps it {into}",
        dict.profile_name()
    ))
}

/// Why a PDO COB-ID value (sub 1) cannot be given to a PDO: an 11-bit id (bit 29 clear)
/// above 0x7FF or with bits 11..28 set, id 0, or an id another service owns
/// ([`crate::decode::cob_id::reserved_for`]). A value with bit 31 set (PDO not valid)
/// carries no id in use and passes.
pub fn cob_refusal(raw: u32) -> Option<String> {
    let cob = Cob::new(raw);
    if !cob.valid {
        return None;
    }
    if !cob.extended && raw & 0x1FFF_F800 != 0 {
        return Some(format!(
            "COB-ID 0x{raw:08X} has bit 29 clear (11-bit) but bits above 0x7FF set"
        ));
    }
    if cob.id == 0 {
        return Some(format!("COB-ID 0x{raw:08X} has CAN-ID 0 (NMT)"));
    }
    if cob.extended {
        return None;
    }
    crate::decode::cob_id::reserved_for(cob.id)
        .map(|owner| format!("COB-ID 0x{raw:08X}: CAN-ID 0x{:03X} is {owner}", cob.id))
}

/// The COB-ID value the PDO gets back at the end: `--cob-id` (bit 29 for a 29-bit one),
/// else the one it has, else the predefined one; bit 30 kept, bit 31 clear.
fn new_cob(spec: &MapSpec, current: u32) -> Result<u32, CommandError> {
    let rtr = current & (1 << 30);
    if let Some(id) = spec.cob_id {
        return Ok(if id > 0x7FF { id | (1 << 29) } else { id } | rtr);
    }
    let kept = current & 0x7FFF_FFFF;
    if kept & 0x1FFF_FFFF != 0 {
        return Ok(kept);
    }
    spec.pdo.predefined_cob(spec.node).map(|c| c | rtr).ok_or_else(|| {
        CommandError::Usage(format!(
            "{} of node {} has no COB-ID: give one with --cob-id",
            spec.pdo.title(),
            spec.node
        ))
    })
}

/// The writes of the remapping, in order ([`remap::remap_sequence`]), for a PDO whose
/// COB-ID is `current` now.
pub fn plan(dict: &Dictionary, spec: &MapSpec, current: u32) -> Result<Vec<Write>, CommandError> {
    let entries = entries(dict, spec)?;
    let raw: Vec<u32> = entries
        .iter()
        .map(|e| u32::from(e.index) << 16 | u32::from(e.sub) << 8 | u32::from(e.bits))
        .collect();
    // The communication parameters asked for: sub, bytes, what it sets in words.
    let comm: Vec<(u8, Vec<u8>, String)> = [
        spec.transmission
            .map(|t| (2, vec![t], format!("transmission type {}", transmission_text(t)))),
        spec.inhibit_100us
            .map(|t| (3, t.to_le_bytes().to_vec(), format!("inhibit time {}", inhibit_text(t)))),
        spec.event_ms
            .map(|ms| (5, ms.to_le_bytes().to_vec(), format!("event timer {}", event_text(ms)))),
    ]
    .into_iter()
    .flatten()
    .collect();
    let cob = new_cob(spec, current)?;
    let remap = Remap {
        comm: spec.pdo.comm_index(),
        mapping: spec.pdo.map_index(),
        current_cob: Some(current),
        final_cob: Some(cob),
        comm_subs: comm.iter().map(|(sub, data, _)| (*sub, data.clone())).collect(),
        mapping_entries: Some(Mapping::of(&raw)),
    };
    let writes = remap_sequence(&remap).into_iter().map(|w| {
        let what = match w.action {
            Action::Invalidate => "invalidate the COB-ID (bit 31)".to_string(),
            Action::Comm => comm
                .iter()
                .find(|(sub, ..)| *sub == w.sub)
                .map(|(.., what)| what.clone())
                .unwrap_or_default(),
            Action::ClearMapping => "mapping count 0".to_string(),
            Action::Entry => {
                let k = usize::from(w.sub);
                format!("mapping entry {k}: {}", entry_text(&entries[k - 1], dict))
            }
            Action::Count => format!("mapping count {}", entries.len()),
            Action::Cob => format!("COB-ID {}, valid again", Cob::new(cob).text()),
        };
        Write::new(w.index, w.sub, &w.data, what)
    });
    Ok(writes.collect())
}

/// The COB-ID a dry run or preview assumes the PDO has (it is read first for real).
pub fn assumed_cob(dict: &Dictionary, spec: &MapSpec) -> u32 {
    let known = dict
        .default_pdos(spec.pdo.transmit)
        .and_then(|m| u8::try_from(spec.pdo.num).ok().and_then(|n| m.get(&n)))
        .and_then(|m| m.cob_id);
    known
        .or_else(|| spec.pdo.predefined_cob(spec.node))
        .or(spec.cob_id)
        .unwrap_or(0)
        & 0x7FFF_FFFF
}

/// One step of a remapping as reported.
#[derive(Serialize)]
struct StepJson {
    step: usize,
    object: String,
    what: String,
    data: String,
    frame: String,
    result: &'static str,
}

/// The report of a remapping (or its dry run).
#[derive(Serialize)]
pub struct MapJson {
    ok: bool,
    node: u8,
    pdo: String,
    dry_run: bool,
    /// The COB-ID value read first (null in a dry run, which assumes one).
    cob_id_before: Option<u32>,
    steps: Vec<StepJson>,
    mapping: Vec<EntryJson>,
    /// The communication parameters read back (null in a dry run).
    comm: Option<CommJson>,
    verified: bool,
    /// Why what was read back differs from what was written.
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
}

fn steps_json(node: u8, writes: &[Write], result: &'static str) -> Vec<StepJson> {
    writes
        .iter()
        .enumerate()
        .map(|(k, w)| StepJson {
            step: k + 1,
            object: format!("0x{:04X}:{:02X}", w.index, w.sub),
            what: w.what.clone(),
            data: crate::frame::hex::upper(&w.data),
            frame: candump(&w.frame(node)),
            result,
        })
        .collect()
}

/// `pdo NODE map ... --dry-run`: the frames, nothing sent (needs no bus).
pub fn dry_run(dict: &Dictionary, spec: &MapSpec) -> Result<(MapJson, String), CommandError> {
    let cob = assumed_cob(dict, spec);
    let writes = plan(dict, spec, cob)?;
    let entries = entries(dict, spec)?;
    let json = MapJson {
        ok: true,
        node: spec.node,
        pdo: spec.pdo.name(),
        dry_run: true,
        cob_id_before: None,
        steps: steps_json(spec.node, &writes, "not sent"),
        mapping: entries.iter().map(|e| EntryJson::new(e, dict)).collect(),
        comm: None,
        verified: false,
        reason: None,
    };
    let mut lines = vec![format!(
        "dry run: {} of node {}: reads 0x{:04X}:01 (assumed COB-ID 0x{cob:08X}), then {} writes, then reads back",
        spec.pdo.title(),
        spec.node,
        spec.pdo.comm_index(),
        writes.len()
    )];
    lines.push(format!(
        "  read  {}",
        candump(&first_upload_frame(spec.node, spec.pdo.comm_index(), 1, false))
    ));
    for (k, w) in writes.iter().enumerate() {
        lines.push(format!("  {:>2}. {}  {}", k + 1, candump(&w.frame(spec.node)), w.what));
    }
    Ok((json, lines.join("\n")))
}

/// Reads a value of up to 4 bytes as an unsigned integer.
async fn read_u32(bus: &Bus, node: u8, index: u16, sub: u8, timeout_ms: u64) -> Result<u32, CommandError> {
    let data = upload(bus, node, index, sub, false, timeout_ms).await?;
    let mut b = [0u8; 4];
    let n = data.len().min(4);
    b[..n].copy_from_slice(&data[..n]);
    Ok(u32::from_le_bytes(b))
}

/// The abort code of a server abort.
fn server_abort(e: &CommandError) -> Option<u32> {
    match e {
        CommandError::Abort {
            code, by_server: true, ..
        } => Some(*code),
        _ => None,
    }
}

/// `pdo NODE map ...`: runs the remapping on the node, then reads it back.
pub async fn map(bus: &Bus, dict: &Dictionary, spec: &MapSpec) -> Result<(MapJson, String), CommandError> {
    let entries = entries(dict, spec)?;
    let (node, t) = (spec.node, spec.timeout_ms);
    let mut heartbeats = bus.subscribe();
    let comm = spec.pdo.comm_index();
    let current = match read_u32(bus, node, comm, 1, t).await {
        Ok(c) => c,
        Err(e) => {
            let hint = refusal_hint(bus, &mut heartbeats, spec, &e, comm, 1, false).await;
            return Err(with_hint(e, hint));
        }
    };
    let writes = plan(dict, spec, current)?;
    for (k, w) in writes.iter().enumerate() {
        if let Err(e) = download(bus, node, w.index, w.sub, w.data.clone(), false, t).await {
            let hint = refusal_hint(bus, &mut heartbeats, spec, &e, w.index, w.sub, k > 0).await;
            let mut steps = steps_json(node, &writes[..=k], "written");
            steps[k].result = "refused";
            let report = MapJson {
                ok: false,
                node,
                pdo: spec.pdo.name(),
                dry_run: false,
                cob_id_before: Some(current),
                steps,
                mapping: entries.iter().map(|e| EntryJson::new(e, dict)).collect(),
                comm: None,
                verified: false,
                reason: None,
            };
            return Err(CommandError::Step {
                procedure: format!("pdo map {}", spec.pdo.name()),
                step: k + 1,
                of: writes.len(),
                report: Reported::new(report),
                cause: Box::new(with_hint(e, hint)),
            });
        }
    }
    let back = read_back(bus, spec, t).await?;
    let differs = verify(&back, &entries, spec, &writes);
    let json = MapJson {
        ok: differs.is_none(),
        node,
        pdo: spec.pdo.name(),
        dry_run: false,
        cob_id_before: Some(current),
        steps: steps_json(node, &writes, "written"),
        mapping: entries.iter().map(|e| EntryJson::new(e, dict)).collect(),
        comm: Some(back.comm.to_json()),
        verified: differs.is_none(),
        reason: differs.clone(),
    };
    if let Some(reason) = differs {
        return Err(CommandError::Report {
            exit: ExitCode::Differs,
            error: "differs",
            report: Reported::new(json),
            text: format!(
                "{} of node {node} differs from what was written: {reason}",
                spec.pdo.title()
            ),
        });
    }
    let mut lines = vec![format!(
        "{} of node {} mapped ({} writes, read back): {}",
        spec.pdo.title(),
        node,
        writes.len(),
        back.comm.text()
    )];
    lines.extend(entries.iter().map(|e| format!("  {}", entry_text(e, dict))));
    Ok((json, lines.join("\n")))
}

/// What a node holds for one PDO after a remapping.
struct ReadBack {
    comm: CommParams,
    entries: Vec<u32>,
}

async fn read_back(bus: &Bus, spec: &MapSpec, t: u64) -> Result<ReadBack, CommandError> {
    let (node, comm, map) = (spec.node, spec.pdo.comm_index(), spec.pdo.map_index());
    let mut c = CommParams::default();
    for sub in [1u8, 2, 3, 5] {
        let asked = match sub {
            3 => spec.inhibit_100us.is_some(),
            5 => spec.event_ms.is_some(),
            _ => true,
        };
        if asked {
            c.set(sub, read_u32(bus, node, comm, sub, t).await?);
        }
    }
    let count = read_u32(bus, node, map, 0, t).await? as usize;
    let mut entries = Vec::with_capacity(count);
    for k in 1..=count.min(64) {
        entries.push(read_u32(bus, node, map, k as u8, t).await?);
    }
    Ok(ReadBack { comm: c, entries })
}

/// Why the node's values differ from what was written, if they do.
fn verify(back: &ReadBack, entries: &[MappedEntry], spec: &MapSpec, writes: &[Write]) -> Option<String> {
    let got: Vec<MappedEntry> = back.entries.iter().map(|v| entry_from_u32(*v)).collect();
    if got != entries {
        let list = |v: &[MappedEntry]| {
            v.iter()
                .map(|e| format!("0x{:04X}:{:02X}/{}", e.index, e.sub, e.bits))
                .collect::<Vec<_>>()
                .join(" ")
        };
        return Some(format!(
            "the node maps [{}] after writing [{}]",
            list(&got),
            list(entries)
        ));
    }
    let cob = writes
        .last()
        .map(|w| u32::from_le_bytes([w.data[0], w.data[1], w.data[2], w.data[3]]));
    let checks = [
        ("COB-ID", back.comm.cob_id, cob),
        (
            "transmission type",
            back.comm.transmission.map(u32::from),
            spec.transmission.map(u32::from),
        ),
        (
            "inhibit time",
            back.comm.inhibit_100us.map(u32::from),
            spec.inhibit_100us.map(u32::from),
        ),
        (
            "event timer",
            back.comm.event_ms.map(u32::from),
            spec.event_ms.map(u32::from),
        ),
    ];
    checks.into_iter().find_map(|(what, got, want)| match (got, want) {
        (Some(g), Some(w)) if g != w => Some(format!("{what} reads 0x{g:X} after writing 0x{w:X}")),
        _ => None,
    })
}

/// Adds `hint` to an error's reason (an abort) or message (a timeout).
fn with_hint(e: CommandError, hint: String) -> CommandError {
    if hint.is_empty() {
        return e;
    }
    match e {
        CommandError::Abort {
            node,
            index,
            sub,
            code,
            by_server,
            reason,
        } => CommandError::Abort {
            node,
            index,
            sub,
            code,
            by_server,
            reason: Some(match reason {
                Some(r) => format!("{r}; {hint}"),
                None => hint,
            }),
        },
        CommandError::Timeout(m) => CommandError::Timeout(format!("{m}; {hint}")),
        other => other,
    }
}

/// The NMT state the node's last heartbeat showed (waits for one up to [`HEARTBEAT_WAIT`]).
async fn nmt_state(heartbeats: &mut Subscription, node: u8) -> Option<u8> {
    let id = cob::heartbeat(node);
    let mut last = None;
    while let Some(Ok(f)) = heartbeats.try_recv() {
        if f.id == id && f.len == 1 && !f.is_ext() {
            last = Some(f.data[0] & 0x7F);
        }
    }
    if last.is_some() {
        return last;
    }
    tokio::time::timeout(HEARTBEAT_WAIT, async {
        loop {
            match heartbeats.recv().await {
                Ok(f) if f.id == id && f.len == 1 && !f.is_ext() => return Some(f.data[0] & 0x7F),
                Ok(_) => {}
                Err(_) => return None,
            }
        }
    })
    .await
    .ok()
    .flatten()
}

/// Why a step of the remapping may have been refused, from the abort code, the node's NMT
/// state and what was already done.
async fn refusal_hint(
    bus: &Bus,
    heartbeats: &mut Subscription,
    spec: &MapSpec,
    e: &CommandError,
    index: u16,
    sub: u8,
    invalidated: bool,
) -> String {
    let Some(code) = server_abort(e) else {
        return String::new();
    };
    let (node, pdo) = (spec.node, spec.pdo.title());
    let mut hints = Vec::new();
    match code {
        0x0604_0041 => hints.push(format!(
            "the node says 0x{index:04X}:{sub:02X}'s object cannot be mapped"
        )),
        0x0604_0042 => hints.push("the node says the objects are too long for one PDO".to_string()),
        0x0609_0030..=0x0609_0032 => hints.push(format!("0x{index:04X}:{sub:02X} is out of the node's range")),
        NO_OBJECT | NO_SUB => hints.push(format!("the node has no 0x{index:04X}:{sub:02X}: {pdo} may not exist")),
        _ => {}
    }
    match nmt_state(heartbeats, node).await {
        Some(0x05) => hints.push(format!(
            "node {node} is operational (its heartbeat says so): many devices change PDOs only in \
             pre-operational (`cotui nmt {} preop {node}`, then map again)",
            bus.name()
        )),
        Some(0x7F) => hints.push(format!("node {node} is pre-operational")),
        Some(0x04) => hints.push(format!("node {node} is stopped (NMT): it answers no SDO")),
        Some(s) => hints.push(format!("node {node}'s heartbeat shows NMT state 0x{s:02X}")),
        None => hints.push(format!("node {node}'s NMT state is not known (no heartbeat heard)")),
    }
    if invalidated {
        hints.push(format!("{pdo} is left invalid (COB-ID bit 31 set) until mapped again"));
    }
    hints.join("; ")
}

/// One PDO as read from a node.
#[derive(Clone, Debug, PartialEq)]
pub struct PdoRead {
    pub id: PdoId,
    /// False when its communication object does not exist (abort 0x06020000).
    pub exists: bool,
    pub comm: CommParams,
    /// The mapped objects (sub 1..count of the mapping record).
    pub entries: Vec<MappedEntry>,
    /// What could not be read, with the abort text.
    pub problems: Vec<String>,
}

/// Reads one PDO's records (`exists` false when its communication object does not exist).
async fn read_one(bus: &Bus, node: u8, id: PdoId, t: u64) -> Result<PdoRead, CommandError> {
    let mut p = PdoRead {
        id,
        exists: false,
        comm: CommParams::default(),
        entries: Vec::new(),
        problems: Vec::new(),
    };
    let (comm, map) = (id.comm_index(), id.map_index());
    let problem = |index: u16, sub: u8, code: u32| format!("0x{index:04X}:{sub:02X}: {}", abort_text(code));
    let highest = match read_u32(bus, node, comm, 0, t).await {
        Ok(h) => h as u8,
        Err(e) => match server_abort(&e) {
            Some(NO_OBJECT) => return Ok(p),
            Some(code) => {
                p.problems.push(problem(comm, 0, code));
                6
            }
            None => return Err(e),
        },
    };
    p.exists = true;
    for sub in COMM_SUBS.into_iter().filter(|s| *s <= highest) {
        match read_u32(bus, node, comm, sub, t).await {
            Ok(v) => {
                p.comm.set(sub, v);
            }
            Err(e) => match server_abort(&e) {
                Some(NO_SUB) if sub > 1 => {}
                Some(code) => p.problems.push(problem(comm, sub, code)),
                None => return Err(e),
            },
        }
    }
    match read_u32(bus, node, map, 0, t).await {
        Ok(count) => {
            for k in 1..=(count as u8).min(64) {
                match read_u32(bus, node, map, k, t).await {
                    Ok(v) => p.entries.push(entry_from_u32(v)),
                    Err(e) => match server_abort(&e) {
                        Some(code) => p.problems.push(problem(map, k, code)),
                        None => return Err(e),
                    },
                }
            }
        }
        Err(e) => match server_abort(&e) {
            Some(code) => p.problems.push(problem(map, 0, code)),
            None => return Err(e),
        },
    }
    Ok(p)
}

/// Reads every RPDO and TPDO of `node`: 1..4 always, then on until the first whose
/// communication object does not exist.
pub async fn read_all(bus: &Bus, node: u8, timeout_ms: u64) -> Result<Vec<PdoRead>, CommandError> {
    let mut out = Vec::new();
    for transmit in [false, true] {
        for num in 1..=512u16 {
            let p = read_one(bus, node, PdoId { transmit, num }, timeout_ms).await?;
            if !p.exists && num > 4 {
                break;
            }
            out.push(p);
        }
    }
    Ok(out)
}

/// One PDO of `pdo NODE --json`.
#[derive(Serialize)]
struct PdoJson {
    pdo: String,
    exists: bool,
    #[serde(flatten)]
    comm: CommJson,
    mapping: Vec<EntryJson>,
    mapped_bits: u32,
    problems: Vec<String>,
}

/// `pdo NODE --json`.
#[derive(Serialize)]
pub struct PdosRead {
    ok: bool,
    node: u8,
    pdos: Vec<PdoJson>,
}

/// The `--json` object and the text of `pdo NODE`.
pub fn read_report(node: u8, dict: &Dictionary, pdos: &[PdoRead]) -> (PdosRead, String) {
    let json = PdosRead {
        ok: true,
        node,
        pdos: pdos
            .iter()
            .map(|p| PdoJson {
                pdo: p.id.name(),
                exists: p.exists,
                comm: p.comm.to_json(),
                mapping: p.entries.iter().map(|e| EntryJson::new(e, dict)).collect(),
                mapped_bits: p.entries.iter().map(|e| u32::from(e.bits)).sum(),
                problems: p.problems.clone(),
            })
            .collect(),
    };
    let count = |transmit: bool| pdos.iter().filter(|p| p.exists && p.id.transmit == transmit).count();
    let mut lines = vec![format!("node {node}: {} RPDOs, {} TPDOs", count(false), count(true))];
    for p in pdos {
        if !p.exists {
            lines.push(format!("{:<6} absent (no 0x{:04X})", p.id.title(), p.id.comm_index()));
            continue;
        }
        let mapped = if p.entries.is_empty() { ", nothing mapped" } else { "" };
        lines.push(format!("{:<6} {}{mapped}", p.id.title(), p.comm.text()));
        lines.extend(p.entries.iter().map(|e| format!("         {}", entry_text(e, dict))));
        lines.extend(p.problems.iter().map(|m| format!("         cannot read {m}")));
    }
    (json, lines.join("\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(objects: &[&str]) -> MapSpec {
        MapSpec {
            node: 2,
            pdo: PdoId { transmit: true, num: 1 },
            objects: objects.iter().map(|s| s.to_string()).collect(),
            transmission: None,
            event_ms: None,
            inhibit_100us: None,
            cob_id: None,
            dry_run: false,
            force: false,
            timeout_ms: 100,
        }
    }

    fn dict() -> Dictionary {
        crate::od::bind::Bindings::new().default_dictionary().clone()
    }

    #[test]
    fn the_remapping_writes_in_cia301_order() {
        let mut s = spec(&["0x6041", "Position actual value"]);
        s.transmission = Some(5);
        s.event_ms = Some(100);
        s.inhibit_100us = Some(25);
        let w = plan(&dict(), &s, 0x4000_0182).unwrap();
        let frames: Vec<String> = w.iter().map(|w| candump(&w.frame(2))).collect();
        assert_eq!(
            frames,
            [
                "602#23001801820100C0", // COB-ID | bit 31 (bit 30 kept)
                "602#2F00180205000000", // transmission type 5, while invalid
                "602#2B00180319000000", // inhibit 2.5 ms
                "602#2B00180564000000", // event timer 100 ms
                "602#2F001A0000000000", // count 0
                "602#23001A0110004160", // 0x6041:00, 16 bits
                "602#23001A0220006460", // 0x6064:00, 32 bits
                "602#2F001A0002000000", // count 2
                "602#2300180182010040", // valid again
            ]
        );
        assert_eq!(w[1].what, "transmission type synchronous, every 5 SYNCs (5)");
        assert_eq!(w[3].what, "event timer 100 ms");
        assert_eq!(w[5].what, "mapping entry 1: 0x6041:00 Statusword, 16 bits");
        assert_eq!(w[7].what, "mapping count 2");
        assert_eq!(w[8].what, "COB-ID 0x182 (no RTR), valid again");
    }

    #[test]
    fn cob_id_from_the_flag_or_the_predefined_set() {
        let mut s = spec(&["0x6041"]);
        s.cob_id = Some(0x0001_2345);
        let w = plan(&dict(), &s, 0x8000_0000).unwrap();
        assert_eq!(w.last().unwrap().data, 0x2001_2345u32.to_le_bytes());
        s.cob_id = None;
        let w = plan(&dict(), &s, 0x8000_0000).unwrap();
        assert_eq!(
            w.last().unwrap().data,
            0x182u32.to_le_bytes(),
            "an empty COB-ID gets the predefined one"
        );
        s.pdo.num = 9;
        assert!(
            plan(&dict(), &s, 0x8000_0000)
                .unwrap_err()
                .to_string()
                .contains("--cob-id")
        );
    }

    #[test]
    fn refused_before_sending() {
        let err = |s: &MapSpec| entries(&dict(), s).unwrap_err().to_string();
        assert_eq!(
            err(&spec(&["0x6064", "0x606C", "0x6041"])),
            "TPDO1 of node 2: 80 bits mapped (32 bits + 32 bits + 16 bits), more than the 64 bits a PDO carries; nothing sent"
        );
        assert!(
            err(&spec(&["Controlword"])).contains("0x6040:00 Controlword cannot be mapped into TPDO1"),
            "{}",
            err(&spec(&["Controlword"]))
        );
        let mut forced = spec(&["Controlword"]);
        forced.force = true;
        assert_eq!(entries(&dict(), &forced).unwrap()[0].bits, 16);
        assert!(err(&spec(&["0x2345:01"])).contains("give it as 0x2345:01/BITS"));
        assert_eq!(entries(&dict(), &spec(&["0x2345:01/8"])).unwrap()[0].bits, 8);
        assert!(err(&spec(&[])).contains("name the objects"));
    }
}
