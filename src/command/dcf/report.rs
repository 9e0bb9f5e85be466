//! What `dcf save|load|diff` report: the `--json` objects and their text.

use super::plan::{Compared, State, Step};
use crate::od::DataType;
use crate::od::dcf::value_text;
use serde::Serialize;
use std::collections::BTreeMap;

/// One object in a report.
#[derive(Clone, Debug, Serialize)]
pub struct Item {
    /// `0x6083:00`.
    pub object: String,
    pub index: u16,
    pub sub: u8,
    pub name: String,
    /// The file's value (as a DCF writes it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The node's value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub node: Option<String>,
    /// The value written (or to be written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<String>,
    /// What a write is for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step: Option<Step>,
    /// The line of the value in the file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub abort_code: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub abort_text: Option<&'static str>,
    /// Why it was skipped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A value as a DCF writes it, else hex.
fn shown(t: DataType, bytes: &[u8]) -> String {
    value_text(t, bytes).unwrap_or_else(|| crate::frame::hex::upper(bytes))
}

impl Item {
    pub fn new(index: u16, sub: u8, name: &str) -> Item {
        Item {
            object: format!("0x{index:04X}:{sub:02X}"),
            index,
            sub,
            name: name.to_string(),
            file: None,
            node: None,
            value: None,
            step: None,
            line: None,
            abort_code: None,
            abort_text: None,
            reason: None,
            note: None,
        }
    }
    /// A compared file value, with both values and its line.
    fn compared(c: &Compared) -> Item {
        let mut i = Item::new(c.file.index, c.file.sub, &c.file.name).values(
            c.file.data_type,
            &c.file.bytes,
            c.node.as_deref(),
        );
        i.line = Some(c.file.line);
        i
    }
    /// With the file's and the node's values.
    pub fn values(mut self, t: DataType, file: &[u8], node: Option<&[u8]>) -> Item {
        self.file = Some(shown(t, file));
        self.node = node.map(|b| shown(t, b));
        self
    }
    /// With an abort code and its text.
    pub fn abort(mut self, code: u32) -> Item {
        self.abort_code = Some(code);
        self.abort_text = Some(crate::sdo::abort_text(code));
        self
    }
    /// With a write's step and value.
    pub fn step(mut self, step: Step, t: Option<DataType>, bytes: &[u8]) -> Item {
        let t = match (step, t) {
            (Step::Value, Some(t)) => t,
            (Step::ClearMapping, _) => DataType::U8,
            _ => DataType::U32,
        };
        self.step = Some(step);
        self.value = Some(shown(t, bytes));
        self
    }
    /// `0x6083:00 Profile acceleration`.
    fn label(&self) -> String {
        format!("{} {}", self.object, self.name).trim_end().to_string()
    }
    /// `: 0x06090030 Value range of parameter exceeded`, or nothing.
    fn abort_suffix(&self) -> String {
        match (self.abort_code, self.abort_text) {
            (Some(c), Some(t)) => format!(": 0x{c:08X} {t}"),
            _ => String::new(),
        }
    }
}

/// `dcf save --json`.
#[derive(Serialize)]
pub struct Saved {
    pub ok: bool,
    pub node: u8,
    pub output: String,
    /// Entries written to the DCF.
    pub objects: usize,
    /// Entries the node refused to read (not in the DCF).
    pub refused: Vec<Item>,
    /// Entries of the dictionary the node does not have.
    pub absent: usize,
    /// Where the node and its dictionary disagree.
    pub warnings: Vec<String>,
}

impl Saved {
    pub fn text(&self) -> String {
        let mut lines = vec![format!(
            "node {}: {} objects saved to {} ({} of the dictionary not in the node, {} refused)",
            self.node,
            self.objects,
            self.output,
            self.absent,
            self.refused.len()
        )];
        for r in &self.refused {
            lines.push(format!("  refused {}{}", r.label(), r.abort_suffix()));
        }
        lines.extend(self.warnings.iter().map(|w| format!("  warning: {w}")));
        lines.join("\n")
    }
}

/// `dcf diff --json`.
#[derive(Serialize)]
pub struct Diffed {
    pub ok: bool,
    /// Whether the node has every writable value of the file.
    pub equal: bool,
    pub node: u8,
    pub file: String,
    /// Writable objects whose values differ (what `dcf load` would write).
    pub differences: Vec<Item>,
    /// Read-only objects whose values differ (a load cannot change them).
    pub read_only_differences: Vec<Item>,
    /// Values the node has.
    pub unchanged: usize,
    /// Objects not compared: not in the node, unreadable, commands, write-only.
    pub skipped: Vec<Item>,
    /// Values of the file left out (file:line), and other notes.
    pub problems: Vec<String>,
}

/// The item of a skipped value, with why.
fn skipped_item(c: &Compared) -> Option<Item> {
    let reason = match &c.state {
        State::Skipped(why) => why.to_string(),
        State::NotInNode(text) => format!("not in the node ({text})"),
        State::Unreadable(text) => format!("the node refused to read it ({text})"),
        State::ReadOnly { .. } => "read-only".to_string(),
        State::Unchanged | State::Differs => return None,
    };
    let mut i = Item::compared(c);
    i.reason = Some(reason);
    Some(i)
}

/// Skipped items, one line per reason with their objects.
fn skipped_lines(items: &[Item]) -> Vec<String> {
    let mut by: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for i in items {
        by.entry(i.reason.as_deref().unwrap_or("")).or_default().push(&i.object);
    }
    by.into_iter()
        .map(|(why, objects)| match objects.len() {
            n @ 9.. => format!(
                "  skipped, {why} ({n}): {} and {} more (--json lists them)",
                objects[..6].join(" "),
                n - 6
            ),
            _ => format!("  skipped, {why}: {}", objects.join(" ")),
        })
        .collect()
}

impl Diffed {
    pub fn new(node: u8, file: &str, compared: &[Compared], problems: Vec<String>) -> Diffed {
        let differences: Vec<Item> = compared
            .iter()
            .filter(|c| c.state == State::Differs)
            .map(Item::compared)
            .collect();
        Diffed {
            ok: differences.is_empty(),
            equal: differences.is_empty(),
            node,
            file: file.to_string(),
            read_only_differences: compared
                .iter()
                .filter(|c| c.state == State::ReadOnly { differs: true })
                .map(Item::compared)
                .collect(),
            unchanged: compared
                .iter()
                .filter(|c| matches!(c.state, State::Unchanged | State::ReadOnly { differs: false }))
                .count(),
            skipped: compared
                .iter()
                .filter(|c| !matches!(c.state, State::ReadOnly { .. }))
                .filter_map(skipped_item)
                .collect(),
            differences,
            problems,
        }
    }

    pub fn text(&self) -> String {
        let mut lines = vec![if self.equal {
            format!(
                "node {} has the values of {} ({} equal)",
                self.node, self.file, self.unchanged
            )
        } else {
            format!(
                "node {} differs from {} in {} objects ({} equal):",
                self.node,
                self.file,
                self.differences.len(),
                self.unchanged
            )
        }];
        let line = |i: &Item, tag: &str| {
            format!(
                "  {tag}{}: file {}, node {} ({}:{})",
                i.label(),
                i.file.as_deref().unwrap_or("-"),
                i.node.as_deref().unwrap_or("-"),
                self.file,
                i.line.unwrap_or(0)
            )
        };
        lines.extend(self.differences.iter().map(|i| line(i, "")));
        lines.extend(self.read_only_differences.iter().map(|i| line(i, "read-only ")));
        lines.extend(skipped_lines(&self.skipped));
        lines.extend(self.problems.iter().map(|p| format!("  {p}")));
        lines.join("\n")
    }
}

/// `dcf load --json`.
#[derive(Serialize)]
pub struct Loaded {
    pub ok: bool,
    pub node: u8,
    pub file: String,
    pub dry_run: bool,
    /// The writes sent, in order (with `--dry-run`: the writes that would be sent).
    pub writes: Vec<Item>,
    /// Values the node already had.
    pub unchanged: usize,
    /// Writes the node refused.
    pub refused: Vec<Item>,
    /// Objects not written: read-only, not in the node, commands, write-only.
    pub skipped: Vec<Item>,
    /// Values read back equal to the file's.
    pub verified: usize,
    /// Values read back different from what was written.
    pub not_verified: Vec<Item>,
    /// Whether "save" was written to 0x1010:01.
    pub stored: bool,
    /// Values of the file left out (file:line), and other notes.
    pub problems: Vec<String>,
}

impl Loaded {
    pub fn new(node: u8, file: &str, compared: &[Compared], problems: Vec<String>, dry_run: bool) -> Loaded {
        Loaded {
            ok: true,
            node,
            file: file.to_string(),
            dry_run,
            writes: Vec::new(),
            unchanged: compared.iter().filter(|c| c.state == State::Unchanged).count(),
            refused: Vec::new(),
            skipped: compared.iter().filter_map(skipped_item).collect(),
            verified: 0,
            not_verified: Vec::new(),
            stored: false,
            problems,
        }
    }

    pub fn text(&self) -> String {
        let verb = if self.dry_run { "would write" } else { "written" };
        let mut head = format!(
            "node {} from {}: {} {verb}, {} unchanged, {} refused, {} skipped",
            self.node,
            self.file,
            self.writes.len(),
            self.unchanged,
            self.refused.len(),
            self.skipped.len()
        );
        if !self.dry_run {
            head.push_str(&format!("; {} verified", self.verified));
        }
        if self.stored {
            head.push_str("; stored (0x1010:01 = save)");
        }
        let mut lines = vec![head];
        for w in &self.writes {
            let why = match w.step {
                Some(Step::Invalidate) => " (PDO invalid while it changes)",
                Some(Step::ClearMapping) => " (mapping cleared while it changes)",
                _ => "",
            };
            lines.push(format!(
                "  {verb} {} = {}{why}",
                w.label(),
                w.value.as_deref().unwrap_or("")
            ));
        }
        for r in &self.refused {
            let note = r.note.as_deref().map(|n| format!("; {n}")).unwrap_or_default();
            let why = r.reason.as_deref().map(|w| format!(": {w}")).unwrap_or_default();
            lines.push(format!("  refused {}{}{why}{note}", r.label(), r.abort_suffix()));
        }
        for n in &self.not_verified {
            lines.push(format!(
                "  NOT verified {}: wrote {}, reads back {}{}",
                n.label(),
                n.file.as_deref().unwrap_or("-"),
                n.node.as_deref().unwrap_or("-"),
                n.abort_suffix()
            ));
        }
        lines.extend(skipped_lines(&self.skipped));
        lines.extend(self.problems.iter().map(|p| format!("  {p}")));
        lines.join("\n")
    }
}
