//! `dcf save|load|diff`: a node's configuration as a CiA 306 DCF. `save` reads every
//! readable object the node's dictionary knows and writes the DCF; `load` writes back the
//! writable values that differ (PDOs by the CiA 301 remapping sequence, communication
//! objects last), verifies and optionally stores; `diff` shows what differs. What is read
//! and written, in which order, is planned by the pure [`plan`]; this module is the bus IO.

pub mod command;
pub mod expect;
pub mod plan;
mod report;

use super::error::{CommandError, ExitCode};
use super::report::Reported;
use super::sdo::{Timing, download_within, upload_within};
use super::spec::Outcome;
use crate::bus::Bus;
use crate::od::dcf::{DcfEntry, DeviceInfo};
use crate::od::{DataType, Dictionary};
use plan::{Compared, ReadResult, Step};
use report::{Diffed, Item, Loaded, Saved};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Read;

/// A `dcf` command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Dcf {
    pub node: u8,
    pub action: DcfAction,
    /// How long to wait for each SDO answer, in ms.
    pub timeout_ms: u64,
}

/// What a `dcf` command does.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DcfAction {
    /// `dcf save NODE -o FILE [--force]`.
    Save { output: String, force: bool },
    /// `dcf load NODE FILE [--store] [--dry-run]`.
    Load { file: String, store: bool, dry_run: bool },
    /// `dcf diff NODE FILE`.
    Diff { file: String },
}

/// How many SDO timeouts in a row end a command: the node has stopped answering.
const SILENT_LIMIT: u32 = 3;

/// Runs a `dcf` command on `bus` with the node's dictionary.
pub async fn execute(bus: &Bus, dict: &Dictionary, cmd: &Dcf) -> Result<Outcome, CommandError> {
    let mut sdo = Sdo {
        bus,
        node: cmd.node,
        timing: Timing::answer(cmd.timeout_ms),
        answered: false,
        silent: 0,
    };
    match &cmd.action {
        DcfAction::Save { output, force } => save(&mut sdo, dict, output, *force).await,
        DcfAction::Load { file, store, dry_run } => load(&mut sdo, dict, file, *store, *dry_run).await,
        DcfAction::Diff { file } => diff(&mut sdo, dict, file).await,
    }
}

/// The SDO client of one command, noticing a node that does not (or no longer) answers.
struct Sdo<'a> {
    bus: &'a Bus,
    node: u8,
    timing: Timing,
    /// Whether the node answered anything yet.
    answered: bool,
    /// Timeouts in a row.
    silent: u32,
}

impl Sdo<'_> {
    /// Reads (index, sub): the bytes, or the abort code (the server's, or ours after a
    /// protocol error or a single timeout). A node that never answered, or that stopped
    /// answering, ends the command.
    async fn read(&mut self, index: u16, sub: u8) -> Result<ReadResult, CommandError> {
        let r = upload_within(self.bus, self.node, index, sub, false, self.timing).await;
        self.judge(r, index, sub)
    }

    /// Writes (index, sub): `Ok(Ok(()))`, or the abort code; see [`Sdo::read`].
    async fn write(&mut self, index: u16, sub: u8, bytes: &[u8]) -> Result<Result<(), u32>, CommandError> {
        let r = download_within(self.bus, self.node, index, sub, bytes.to_vec(), false, self.timing).await;
        self.judge(r, index, sub)
    }

    fn judge<T>(&mut self, r: Result<T, CommandError>, index: u16, sub: u8) -> Result<Result<T, u32>, CommandError> {
        match r {
            Ok(v) => {
                (self.answered, self.silent) = (true, 0);
                Ok(Ok(v))
            }
            Err(CommandError::Abort { code, by_server, .. }) => {
                if by_server {
                    (self.answered, self.silent) = (true, 0);
                }
                Ok(Err(code))
            }
            Err(CommandError::Timeout(why)) => {
                self.silent += 1;
                if !self.answered {
                    return Err(CommandError::Timeout(format!(
                        "node {} does not answer (SDO {index:04X}:{sub:02X}: {why}); nothing done",
                        self.node
                    )));
                }
                if self.silent >= SILENT_LIMIT {
                    return Err(CommandError::Timeout(format!(
                        "node {} stopped answering ({SILENT_LIMIT} SDO timeouts in a row, the last at \
                         {index:04X}:{sub:02X}); stopped there",
                        self.node
                    )));
                }
                Ok(Err(0x0504_0000))
            }
            Err(e) => Err(e),
        }
    }
}

/// `dcf save`: reads the node and writes the DCF.
async fn save(sdo: &mut Sdo<'_>, dict: &Dictionary, output: &str, force: bool) -> Result<Outcome, CommandError> {
    if !force && output != "-" && std::path::Path::new(output).exists() {
        return Err(CommandError::Usage(format!(
            "{output} exists; give --force to overwrite it"
        )));
    }
    let plan = plan::save_plan(dict);
    let mut values: BTreeMap<(u16, u8), Vec<u8>> = BTreeMap::new();
    let mut refused = Vec::new();
    let mut absent = 0usize;
    let mut ended: BTreeSet<usize> = BTreeSet::new();
    let item = |index, sub| Item::new(index, sub, dict.name(index, sub).unwrap_or(""));
    for t in &plan.targets {
        if t.range.is_some_and(|r| ended.contains(&r)) {
            continue;
        }
        let first = t.subs[0];
        let (rest, highest) = match sdo.read(t.index, first).await? {
            Ok(bytes) => {
                let highest = bytes.first().copied().unwrap_or(0);
                let rest = if first == 0 && t.subs.len() > 1 {
                    plan::subs_after(t, highest)
                } else {
                    t.subs[1..].to_vec()
                };
                values.insert((t.index, first), bytes);
                (rest, highest)
            }
            Err(plan::NO_OBJECT | plan::NO_SUB) => {
                absent += 1;
                if let Some(r) = t.range {
                    ended.insert(r);
                }
                continue;
            }
            Err(code) => {
                refused.push(item(t.index, first).abort(code));
                continue;
            }
        };
        for sub in rest {
            match sdo.read(t.index, sub).await? {
                Ok(bytes) => {
                    values.insert((t.index, sub), bytes);
                }
                // The unused entries of a PDO mapping end where the node's do.
                Err(plan::NO_SUB) if sub > highest => break,
                Err(plan::NO_OBJECT | plan::NO_SUB) => absent += 1,
                Err(code) => refused.push(item(t.index, sub).abort(code)),
            }
        }
    }
    let mut warnings = Vec::new();
    let entries: Vec<DcfEntry> = values
        .iter()
        .map(|(&(index, sub), bytes)| {
            let info = dict.object(index, sub);
            let data_type = info.map_or(DataType::Domain, |o| o.data_type);
            if let Some(n) = data_type.size()
                && bytes.len() > n
            {
                warnings.push(format!(
                    "0x{index:04X}:{sub:02X}: the node sent {} bytes, the dictionary says {data_type:?} ({n} bytes)",
                    bytes.len()
                ));
            }
            DcfEntry {
                index,
                sub,
                name: info.map_or_else(|| format!("Object {index:04X}sub{sub:X}"), |o| o.name.clone()),
                data_type,
                access: info.map(|o| o.access).unwrap_or_default(),
                default: None,
                value: Some(bytes.clone()),
            }
        })
        .collect();
    let u32_at = |index, sub| {
        values.get(&(index, sub)).map_or(0, |b: &Vec<u8>| {
            let mut le = [0u8; 4];
            let n = b.len().min(4);
            le[..n].copy_from_slice(&b[..n]);
            u32::from_le_bytes(le)
        })
    };
    let info = DeviceInfo {
        vendor_name: String::new(),
        vendor_number: u32_at(0x1018, 1),
        product_name: values
            .get(&(0x1008, 0))
            .map(|b| String::from_utf8_lossy(b).trim_end_matches('\0').to_string())
            .unwrap_or_else(|| dict.profile_name().to_string()),
        product_number: u32_at(0x1018, 2),
        revision_number: u32_at(0x1018, 3),
        node_id: Some(sdo.node),
        description: format!("configuration of node {} read by cotui", sdo.node),
        file_name: match output {
            "-" => String::new(),
            path => std::path::Path::new(path)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        },
    };
    let text = crate::od::dcf::write(&info, &entries);
    crate::command::write::write_output(output, text.as_bytes())?;
    let saved = Saved {
        ok: true,
        node: sdo.node,
        output: output.to_string(),
        objects: entries.len(),
        refused,
        absent,
        warnings,
    };
    let text = saved.text();
    Ok(Outcome::new(saved, text))
}

/// Reads a DCF (at most 64 MiB).
fn read_file(path: &str) -> Result<String, CommandError> {
    let cap = crate::files::MAX_FILE;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(cap + 1).read_to_end(&mut bytes))
        .map_err(|e| CommandError::Usage(format!("cannot read {path}: {e}")))?;
    if bytes.len() as u64 > cap {
        return Err(CommandError::Usage(format!(
            "{path}: larger than {} MiB, not a DCF",
            cap >> 20
        )));
    }
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// The file's values against the node's (read now), with the file's problems.
async fn compare_node(
    sdo: &mut Sdo<'_>,
    dict: &Dictionary,
    file: &str,
) -> Result<(Vec<Compared>, Vec<String>), CommandError> {
    let dcf = plan::read_dcf(file, &read_file(file)?, sdo.node, dict);
    if dcf.values.is_empty() && dcf.problems.is_empty() {
        return Err(CommandError::Usage(format!(
            "{file} has no ParameterValue: not a DCF (an EDS has no values to load)"
        )));
    }
    let mut problems: Vec<String> = dcf.problems.iter().map(ToString::to_string).collect();
    if let Some(n) = dcf.node_id.filter(|n| *n != sdo.node) {
        problems.push(format!(
            "{file}: the file is node {n}'s, compared with node {}: node-ID based values (COB-IDs) are taken as written",
            sdo.node
        ));
    }
    let mut reads = BTreeMap::new();
    for v in dcf.values.iter().filter(|v| plan::needs_read(v)) {
        reads.insert((v.index, v.sub), sdo.read(v.index, v.sub).await?);
    }
    Ok((plan::compare(&dcf.values, &reads), problems))
}

/// `dcf diff`: exit 0 when the node has the file's writable values, else 6.
async fn diff(sdo: &mut Sdo<'_>, dict: &Dictionary, file: &str) -> Result<Outcome, CommandError> {
    let (compared, problems) = compare_node(sdo, dict, file).await?;
    let d = Diffed::new(sdo.node, file, &compared, problems);
    let text = d.text();
    if d.equal {
        Ok(Outcome::new(d, text))
    } else {
        Err(CommandError::Report {
            exit: ExitCode::Differs,
            error: "differs",
            report: Reported::new(d),
            text,
        })
    }
}

/// `dcf load`: writes the differing writable values in plan order, verifies, stores.
async fn load(
    sdo: &mut Sdo<'_>,
    dict: &Dictionary,
    file: &str,
    store: bool,
    dry_run: bool,
) -> Result<Outcome, CommandError> {
    let (compared, problems) = compare_node(sdo, dict, file).await?;
    // The checks `pdo map` makes, before anything is sent: a refused PDO is left out whole.
    let invalid = plan::pdo_refusals(&compared, dict);
    let groups = plan::load_plan(&compared, &invalid);
    let mut l = Loaded::new(sdo.node, file, &compared, problems, dry_run);
    for r in &invalid {
        let pdo = crate::decode::pdo_config::PdoId {
            transmit: r.comm >= 0x1800,
            num: (r.comm & 0x1FF) + 1,
        };
        let mut item = Item::new(r.comm, 0, &pdo.title());
        item.reason = Some(r.reason.clone());
        item.note = Some(format!(
            "nothing of this PDO (0x{:04X}, 0x{:04X}) was sent",
            r.comm, r.mapping
        ));
        l.refused.push(item);
    }
    let name = |index: u16, sub: u8| {
        compared
            .iter()
            .find(|c| c.file.index == index && c.file.sub == sub)
            .map_or_else(
                || dict.name(index, sub).unwrap_or("").to_string(),
                |c| c.file.name.clone(),
            )
    };
    let ty = |index: u16, sub: u8| {
        compared
            .iter()
            .find(|c| c.file.index == index && c.file.sub == sub)
            .map(|c| c.file.data_type)
    };
    let mut done: Vec<(u16, u8, Vec<u8>)> = Vec::new();
    for group in &groups {
        for (i, w) in group.iter().enumerate() {
            let item = Item::new(w.index, w.sub, &name(w.index, w.sub)).step(w.step, ty(w.index, w.sub), &w.bytes);
            if dry_run {
                l.writes.push(item);
                continue;
            }
            match sdo.write(w.index, w.sub, &w.bytes).await? {
                Ok(()) => {
                    l.writes.push(item);
                    if w.step == Step::Value {
                        done.retain(|(x, s, _)| (*x, *s) != (w.index, w.sub));
                        done.push((w.index, w.sub, w.bytes.clone()));
                    }
                }
                Err(code) => {
                    let mut refused = item.abort(code);
                    if group.len() > 1 && i + 1 < group.len() {
                        refused.note = Some(format!(
                            "the remaining {} steps of this PDO were not sent",
                            group.len() - i - 1
                        ));
                    }
                    l.refused.push(refused);
                    break;
                }
            }
        }
    }
    for (index, sub, bytes) in &done {
        let t = ty(*index, *sub).unwrap_or(DataType::Domain);
        match sdo.read(*index, *sub).await? {
            Ok(back) if plan::same_value(t, bytes, &back) => l.verified += 1,
            Ok(back) => l
                .not_verified
                .push(Item::new(*index, *sub, &name(*index, *sub)).values(t, bytes, Some(&back))),
            Err(code) => l
                .not_verified
                .push(Item::new(*index, *sub, &name(*index, *sub)).abort(code)),
        }
    }
    if store && !dry_run {
        match sdo.write(0x1010, 1, &plan::STORE_SIGNATURE.to_le_bytes()).await? {
            Ok(()) => l.stored = true,
            Err(code) => l.refused.push(Item::new(0x1010, 1, "Save all parameters").abort(code)),
        }
    }
    l.ok = l.refused.is_empty() && l.not_verified.is_empty();
    let text = l.text();
    if l.ok {
        return Ok(Outcome::new(l, text));
    }
    // An SDO abort first; then a PDO of the file refused before sending (a bad file: usage).
    let (exit, error) = if l.refused.iter().any(|r| r.abort_code.is_some()) {
        (ExitCode::Abort, "refused")
    } else if !l.refused.is_empty() {
        (ExitCode::Usage, "invalid")
    } else {
        (ExitCode::Differs, "differs")
    };
    Err(CommandError::Report {
        exit,
        error,
        report: Reported::new(l),
        text,
    })
}
