//! The Objects pane: the object dictionary of one node (every object its dictionary layers
//! know: EDS/DCF, vendor profile, CiA 402, CiA 301, the first layer that knows an entry
//! wins) as a tree of index and sub-index with name, vendor alias, type, access, unit and
//! the last value seen of that node on its own interface, with its age
//! ([`crate::analysis::values`]).
//!
//! Records and arrays fold (`expand` opens and closes them); `expand` on an entry reads it,
//! `edit_object` opens the palette with its write command, `read_all` reads every readable
//! entry one after the other. The find prompt filters the rows by name, alias or index
//! while typing; `next_match`/`prev_match` go from match to match. The catalog of objects
//! is rebuilt only when the node or its dictionary changes; row texts only for the rows
//! shown.

use super::{Component, Ctx, ListState, block, fit, header, selected};
use crate::analysis::values::Entry;
use crate::frame::NodeKey;
use crate::od::{Access, DataType, Dictionary, ObjectInfo, Profile};
use crate::sdo::abort::{AbortClass, abort_class};
use crate::tui::event::{Event, ObjectRequest, Queue};
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::sync::Arc;

/// PDO parameter ranges of CiA 301 (communication and mapping, RPDO and TPDO): the pane
/// lists their first [`RANGE_SHOWN`] records (PDOs 1-4, the predefined connection set).
const PDO_RANGES: [u16; 4] = [0x1400, 0x1600, 0x1800, 0x1A00];
/// Records listed of each PDO parameter range (more when values of others were seen).
const RANGE_SHOWN: u16 = 4;

/// One object (index) of the catalog.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Obj {
    index: u16,
    /// Its entries' sub-indexes, rising.
    subs: Vec<u8>,
    /// A record or array (folds), not a single variable at sub 0.
    record: bool,
}

/// Every object the node's dictionary knows, in index order.
fn catalog(dict: &Dictionary, seen: &BTreeSet<u16>) -> Vec<Obj> {
    let mut subs: BTreeMap<u16, BTreeSet<u8>> = BTreeMap::new();
    let mut records: BTreeSet<u16> = BTreeSet::new();
    for layer in dict.layers() {
        for ((i, s), _) in layer.entries() {
            subs.entry(i).or_default().insert(s);
        }
        records.extend(layer.names().into_keys());
        for r in &layer.ranges {
            // The first PDOs of a PDO range; of other ranges (e.g. 127 more SDO servers)
            // only what was seen.
            let shown = r.first..r.first.saturating_add(RANGE_SHOWN).min(r.last.saturating_add(1));
            let shown = shown.filter(|_| PDO_RANGES.contains(&r.first));
            for i in shown.chain(seen.range(r.first..=r.last).copied()) {
                subs.entry(i).or_default().extend(r.subs.keys());
                records.insert(i);
            }
        }
    }
    subs.into_iter()
        .map(|(index, s)| {
            let subs: Vec<u8> = s.into_iter().collect();
            let record = records.contains(&index) || subs != [0];
            Obj { index, subs, record }
        })
        .collect()
}

/// A row of the tree as shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Row {
    /// A record's own row (catalog position); `open` when its entries are shown.
    Record { obj: usize, open: bool },
    /// An entry; `child` when it is shown under its record.
    Entry { index: u16, sub: u8, child: bool },
}

/// The type as the command language writes it (`u16`, `string`, `octets`).
pub fn type_word(t: DataType) -> &'static str {
    use DataType::*;
    match t {
        Boolean => "bool",
        I8 => "i8",
        I16 => "i16",
        I24 => "i24",
        I32 => "i32",
        I40 => "i40",
        I48 => "i48",
        I56 => "i56",
        I64 => "i64",
        U8 => "u8",
        U16 => "u16",
        U24 => "u24",
        U32 => "u32",
        U40 => "u40",
        U48 => "u48",
        U56 => "u56",
        U64 => "u64",
        F32 => "f32",
        F64 => "f64",
        VisibleString => "string",
        OctetString => "octets",
        UnicodeString => "unicode",
        TimeOfDay => "time",
        TimeDifference => "timediff",
        Domain => "domain",
    }
}

/// A record's name: the dictionary's, else for the CiA 301 parameter ranges what the
/// record is (`TPDO3 communication parameter`), else its sub 0 entry's.
fn record_name(dict: &Dictionary, index: u16) -> String {
    if let Some(n) = dict.layers().iter().find_map(|p| p.object_name(index)) {
        return n.to_string();
    }
    let ranged = [
        (0x1200, "SDO server", "parameter"),
        (0x1280, "SDO client", "parameter"),
        (0x1400, "RPDO", "communication parameter"),
        (0x1600, "RPDO", "mapping parameter"),
        (0x1800, "TPDO", "communication parameter"),
        (0x1A00, "TPDO", "mapping parameter"),
    ];
    for (first, what, kind) in ranged {
        let span = if first < 0x1400 { 0x80 } else { 0x200 };
        if (first..first + span).contains(&index) {
            return format!("{what}{} {kind}", index - first + 1);
        }
    }
    dict.object_name(index).unwrap_or("").to_string()
}

/// Access as EDS files write it.
fn access_word(a: Access) -> &'static str {
    match a {
        Access::Rw => "rw",
        Access::Ro => "ro",
        Access::Wo => "wo",
        Access::Const => "const",
        Access::Rww => "rww",
        Access::Rwr => "rwr",
    }
}

/// The vendor alias of an entry: its own, else one of the `aliases` tables.
fn alias(dict: &Dictionary, index: u16, sub: u8) -> Option<String> {
    if let Some(a) = dict.object(index, sub).and_then(|o| o.alias.clone()) {
        return Some(a);
    }
    dict.layers().iter().find_map(|p| {
        p.aliases
            .iter()
            .find(|(_, at)| **at == (index, sub))
            .map(|(a, _)| a.clone())
    })
}

/// True when the entry matches a find text (lower case): a part of its name or alias, or
/// the start of its index written `6041`, `0x6041`, `6041:00`. (An entry the text names
/// through an alias rule, such as `F0.3.018`, is matched by the caller.)
fn matches(query: &str, index: u16, sub: Option<u8>, name: &str, alias: Option<&str>) -> bool {
    let q = query.strip_prefix("0x").unwrap_or(query);
    let at = match sub {
        Some(s) => format!("{index:04x}:{s:02x}"),
        None => format!("{index:04x}"),
    };
    at.starts_with(q) || name.to_lowercase().contains(query) || alias.is_some_and(|a| a.to_lowercase().contains(query))
}

/// A read-all in progress.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReadAll {
    /// The node read (on its interface).
    node: NodeKey,
    /// Entries still to read.
    queue: VecDeque<(u16, u8)>,
    /// The line sent and waiting for its result.
    current: Option<(String, (u16, u8))>,
    /// Entries read so far (answered, ok or not).
    done: usize,
    /// Entries in all.
    total: usize,
    /// Entries left out: sub-indexes beyond what sub 0 says the node has, the rest of an
    /// object the node does not have.
    skipped: usize,
    /// Entries that failed, with what went wrong.
    failed: Vec<((u16, u8), String)>,
    /// Entries the node answered it does not have (an abort of
    /// [`crate::sdo::abort::NOT_PRESENT`]): not failures.
    not_present: usize,
}

impl ReadAll {
    /// Leaves out the queued entries of `index` whose sub-index is above `last`.
    fn skip_above(&mut self, index: u16, last: Option<u8>) {
        let before = self.queue.len();
        self.queue.retain(|(i, s)| *i != index || last.is_some_and(|n| *s <= n));
        self.skipped += before - self.queue.len();
    }
}

/// The bytes of a read's result text (`... = 5 (data 05)`).
fn result_data(text: &str) -> Option<Vec<u8>> {
    let hex: String = text
        .rsplit_once("(data ")?
        .1
        .split(')')
        .next()?
        .chars()
        .filter(char::is_ascii_hexdigit)
        .collect();
    (0..hex.len() / 2)
        .map(|k| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).ok())
        .collect()
}

/// What a command result meant to the pane.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Step {
    /// Not a result of the pane's reads.
    NotOurs,
    /// Noted.
    Noted,
    /// Read-all goes on: send this line.
    Next(String),
    /// Read-all is over: this summary (and the failures, one line each).
    Finished(String),
}

/// The palette line that reads an entry (the sub-index in hex: bare digits would be decimal).
pub fn read_line(node: u8, index: u16, sub: u8) -> String {
    format!("sdo read {node} 0x{index:04X}:0x{sub:02X}")
}

/// The Objects pane's state.
#[derive(Default)]
pub struct ObjectsPane {
    /// Scroll state.
    list: ListState,
    /// The node picked in the pane (overrides the Nodes selection until that changes).
    picked: Option<NodeKey>,
    /// The Nodes pane's selection, as the application last told.
    from_nodes: Option<NodeKey>,
    /// Records shown open.
    open: BTreeSet<u16>,
    /// The find text (filters the rows while typed).
    query: String,
    /// The find text changed since the rows were last built.
    fresh_query: bool,
    /// The catalog, and what it was built from (node, layers, indexes seen in ranges).
    catalog: Vec<Obj>,
    built: Option<(NodeKey, Vec<usize>, BTreeSet<u16>)>,
    /// The rows shown, as last built.
    rows: Vec<Row>,
    /// The read-all in progress.
    read_all: Option<ReadAll>,
    /// Single reads sent and not answered yet: line -> (node, index, sub).
    reading: BTreeMap<String, (NodeKey, u16, u8)>,
    /// The last failure of a read the pane sent, per (node on its interface, index, sub),
    /// with the capture time it was told (a value seen after it shows instead).
    errors: BTreeMap<(NodeKey, u16, u8), (String, u64)>,
}

impl ObjectsPane {
    /// The node shown (on its interface): the one picked in the pane, else the Nodes
    /// pane's selection.
    pub fn node(&self) -> Option<NodeKey> {
        self.picked.or(self.from_nodes)
    }

    /// True while a read-all goes on.
    pub fn reading_all(&self) -> bool {
        self.read_all.is_some()
    }

    /// Tells the pane the Nodes pane's selection; a new one replaces a node picked here.
    pub fn set_nodes_selection(&mut self, node: Option<NodeKey>) {
        if node != self.from_nodes {
            self.from_nodes = node;
            self.picked = None;
        }
    }

    /// Shows `node` (until the Nodes pane's selection changes), as `[`/`]` would pick it.
    pub(crate) fn pick(&mut self, node: NodeKey) {
        self.picked = Some(node);
    }

    /// Sets the find text (as typed: the rows follow each key).
    pub fn set_query(&mut self, text: &str) {
        self.query = text.trim().to_lowercase();
        self.list = ListState::default();
        self.fresh_query = true;
    }

    /// Rebuilds the catalog when the node or its dictionary changed, then the rows.
    fn refresh(&mut self, ctx: &Ctx) {
        let Some(key) = self.node() else {
            self.catalog.clear();
            self.rows.clear();
            self.built = None;
            return;
        };
        let dict = ctx.trace.decoder().dictionary(key.node);
        let layers: Vec<usize> = dict.layers().iter().map(|l| Arc::as_ptr(l) as usize).collect();
        let seen: BTreeSet<u16> = ctx
            .trace
            .values
            .node(key)
            .map(|((i, _), _)| i)
            .filter(|i| in_range(dict.layers(), *i))
            .collect();
        let key = (key, layers, seen);
        if self.built.as_ref() != Some(&key) {
            self.catalog = catalog(dict, &key.2);
            self.built = Some(key);
        }
        self.rows = self.build_rows(dict);
        // A new find text selects the first row that matches it.
        if std::mem::take(&mut self.fresh_query) {
            self.list.selected = (0..self.rows.len())
                .find(|k| self.row_matches(self.rows[*k], dict))
                .unwrap_or(0);
        }
    }

    /// The rows shown: every object (open records with their entries), or with a find
    /// text only the matching entries and the records that hold them.
    fn build_rows(&self, dict: &Dictionary) -> Vec<Row> {
        let mut rows = Vec::new();
        let q = self.query.as_str();
        let named = (!q.is_empty())
            .then(|| crate::od::resolve_object(dict, q).ok())
            .flatten();
        let hit = |index: u16, sub: u8, name: &str| {
            q.is_empty()
                || named == Some((index, sub))
                || matches(q, index, Some(sub), name, alias(dict, index, sub).as_deref())
        };
        for (k, o) in self.catalog.iter().enumerate() {
            if !o.record {
                let sub = o.subs[0];
                if hit(o.index, sub, dict.name(o.index, sub).unwrap_or("")) {
                    rows.push(Row::Entry {
                        index: o.index,
                        sub,
                        child: false,
                    });
                }
                continue;
            }
            let own = !q.is_empty() && matches(q, o.index, None, &record_name(dict, o.index), None);
            let subs: Vec<u8> = o
                .subs
                .iter()
                .copied()
                .filter(|s| own || hit(o.index, *s, dict.name(o.index, *s).unwrap_or("")))
                .collect();
            if !q.is_empty() && subs.is_empty() {
                continue;
            }
            let open = self.open.contains(&o.index) || (!q.is_empty() && !own);
            rows.push(Row::Record { obj: k, open });
            if open {
                rows.extend(subs.into_iter().map(|sub| Row::Entry {
                    index: o.index,
                    sub,
                    child: true,
                }));
            }
        }
        rows
    }

    /// True when the row itself matches the find text (not only entries under it).
    fn row_matches(&self, r: Row, dict: &Dictionary) -> bool {
        match r {
            Row::Entry { index, sub, .. } => {
                let name = dict.name(index, sub).unwrap_or("");
                matches(&self.query, index, Some(sub), name, alias(dict, index, sub).as_deref())
            }
            Row::Record { obj, .. } => {
                let index = self.catalog[obj].index;
                matches(&self.query, index, None, &record_name(dict, index), None)
            }
        }
    }

    /// The entry of the selected row, if it is one.
    fn selected_entry(&self) -> Option<(u16, u8)> {
        match self.rows.get(self.list.selected)? {
            Row::Entry { index, sub, .. } => Some((*index, *sub)),
            Row::Record { .. } => None,
        }
    }

    /// Every readable entry of the node, in index order.
    fn readable(&self, dict: &Dictionary) -> Vec<(u16, u8)> {
        self.catalog
            .iter()
            .flat_map(|o| o.subs.iter().map(move |s| (o.index, *s)))
            .filter(|(i, s)| dict.object(*i, *s).is_some_and(|o| o.access != Access::Wo))
            .collect()
    }

    /// Moves the selection to the next (or previous) row whose own text matches the find text.
    fn jump(&mut self, forward: bool, ctx: &Ctx, q: &mut Queue) -> bool {
        let Some(key) = self.node() else { return true };
        if self.query.is_empty() {
            return note(q, "no find text: press the filter or search key to find an object");
        }
        let dict = ctx.trace.decoder().dictionary(key.node);
        let n = self.rows.len();
        let own = |r: &Row| self.row_matches(*r, dict);
        for step in 1..=n {
            let k = if forward {
                (self.list.selected + step) % n
            } else {
                (self.list.selected + n * 2 - step) % n
            };
            if own(&self.rows[k]) {
                self.list.selected = k;
                self.list.clamp(n, ctx.page);
                return true;
            }
        }
        note(q, &format!("no object matches `{}`", self.query))
    }

    /// The palette line writing the selected entry: `sdo write N 0xIIII:SS VALUE --type T`,
    /// the value the last one seen (else the dictionary's default), raw.
    fn edit(&self, key: NodeKey, index: u16, sub: u8, ctx: &Ctx) -> ObjectRequest {
        let node = key.node;
        let dict = ctx.trace.decoder().dictionary(node);
        let Some(info) = dict.object(index, sub) else {
            return ObjectRequest::Note(format!("0x{index:04X}:{sub:02X}: not in the dictionary"));
        };
        if matches!(info.access, Access::Ro | Access::Const) {
            return ObjectRequest::Note(format!(
                "0x{index:04X}:{sub:02X} {} is read-only ({})",
                info.name,
                access_word(info.access)
            ));
        }
        let last = ctx.trace.values.get(key, index, sub).and_then(|e| e.last.as_ref());
        let value = last
            .map(|s| &s.value)
            .or(info.default.as_ref())
            .map(raw_text)
            .unwrap_or_default();
        let head = format!("sdo write {node} 0x{index:04X}:0x{sub:02X} {value}");
        let cursor = head.chars().count();
        let text = match info.data_type {
            DataType::UnicodeString | DataType::TimeOfDay | DataType::TimeDifference => head,
            t => format!("{head} --type {}", type_word(t)),
        };
        ObjectRequest::Edit {
            text,
            cursor,
            note: scaling_note(info),
        }
    }

    /// Notes a command result told at capture time `now_ns`; read-all goes on with the
    /// next entry.
    pub fn result(&mut self, text: &str, now_ns: u64) -> Step {
        if let Some(r) = self.read_all.as_mut()
            && let Some((line, at)) = r.current.clone()
            && let Some(rest) = text.strip_prefix(&format!("{line}: "))
        {
            r.done += 1;
            let key = (r.node, at.0, at.1);
            match failure(rest) {
                Some(why) => {
                    let code = abort_code(why);
                    // An object the node does not have: none of its entries is read.
                    if code == Some(crate::sdo::abort::codes::NO_OBJECT) {
                        r.skip_above(at.0, None);
                    }
                    if code.is_some_and(|c| abort_class(c) == AbortClass::NotPresent) {
                        r.not_present += 1;
                    } else {
                        r.failed.push((at, why.to_string()));
                    }
                    self.errors.insert(key, (why.to_string(), now_ns));
                }
                None => {
                    // Sub 0 of a record: its highest sub-index; the ones above are not read.
                    if at.1 == 0
                        && let Some(n) = result_data(rest).and_then(|d| d.first().copied())
                    {
                        r.skip_above(at.0, Some(n));
                    }
                    self.errors.remove(&key);
                }
            }
            return self.next_read();
        }
        let Some((line, key)) = self
            .reading
            .iter()
            .find(|(l, _)| text.starts_with(&format!("{l}: ")))
            .map(|(l, k)| (l.clone(), *k))
        else {
            return Step::NotOurs;
        };
        self.reading.remove(&line);
        match failure(&text[line.len() + 2..]) {
            Some(why) => self.errors.insert(key, (why.to_string(), now_ns)),
            None => self.errors.remove(&key),
        };
        Step::Noted
    }

    /// Notes a single read sent for (node, index, sub) by `line`.
    pub fn sent(&mut self, line: &str, node: NodeKey, index: u16, sub: u8) {
        self.errors.remove(&(node, index, sub));
        self.reading.insert(line.to_string(), (node, index, sub));
    }

    /// Starts reading `objects` of `node`; the first line to send.
    pub fn start_read_all(&mut self, node: NodeKey, objects: Vec<(u16, u8)>) -> Step {
        self.read_all = Some(ReadAll {
            node,
            total: objects.len(),
            queue: objects.into(),
            ..ReadAll::default()
        });
        self.next_read()
    }

    /// Stops a read-all; its summary.
    pub fn stop_read_all(&mut self) -> Option<String> {
        let r = self.read_all.take()?;
        Some(format!(
            "read all node {}: stopped after {} of {} entries ({} not present, {} failed)",
            r.node.node,
            r.done + r.skipped,
            r.total,
            r.not_present,
            r.failed.len()
        ))
    }

    /// The next read of the read-all, or its summary when all are done.
    fn next_read(&mut self) -> Step {
        let Some(r) = self.read_all.as_mut() else {
            return Step::Noted;
        };
        match r.queue.pop_front() {
            Some((i, s)) => {
                let line = read_line(r.node.node, i, s);
                r.current = Some((line.clone(), (i, s)));
                Step::Next(line)
            }
            None => {
                let r = self.read_all.take().unwrap_or_default();
                let mut text = format!(
                    "read all node {}: {} entries read, {} not present, {} failed",
                    r.node.node,
                    r.done - r.failed.len() - r.not_present,
                    r.not_present,
                    r.failed.len()
                );
                if r.skipped > 0 {
                    text.push_str(&format!(
                        "; {} more of the {} the dictionary knows left out (not on the node)",
                        r.skipped, r.total
                    ));
                }
                for ((i, s), why) in &r.failed {
                    text.push_str(&format!("\n0x{i:04X}:{s:02X}: {why}"));
                }
                Step::Finished(text)
            }
        }
    }

    /// The pane title: node, profile, object count, find text, read-all progress.
    fn title(&self, ctx: &Ctx) -> String {
        let Some(key) = self.node() else {
            return " Objects ".into();
        };
        let node = key.node;
        let dict = ctx.trace.decoder().dictionary(node);
        let entries: usize = self.catalog.iter().map(|o| o.subs.len()).sum();
        let mut layers: Vec<&str> = dict.layers().iter().map(|l| l.name.as_str()).collect();
        layers.dedup();
        // Several interfaces: which one's node this is.
        let on = if ctx.trace.ifaces.names().len() > 1 {
            format!(" on {}", ctx.trace.ifaces.name(key.iface))
        } else {
            String::new()
        };
        let mut t = format!(" Objects · node {node}{on} {} · {entries} entries", layers.join(" > "));
        if !self.query.is_empty() {
            t.push_str(&format!(" · find `{}`", self.query));
        }
        if let Some(r) = &self.read_all {
            t.push_str(&format!(" · read all {} of {}", r.done + r.skipped, r.total));
            if !r.failed.is_empty() {
                t.push_str(&format!(" ({} failed)", r.failed.len()));
            }
        }
        t.push(' ');
        t
    }

    /// The text and colour of a row, `now_ns` the capture time.
    fn row(&self, r: Row, key: NodeKey, ctx: &Ctx, w: &Widths) -> (String, Style) {
        let node = key.node;
        let dict = ctx.trace.decoder().dictionary(node);
        match r {
            Row::Record { obj, open } => {
                let o = &self.catalog[obj];
                let mark = if open { '▾' } else { '▸' };
                let text = format!(
                    "{mark} {:04X}    {}",
                    o.index,
                    fit(&record_name(dict, o.index), w.name + 1 + w.alias)
                );
                (text, Style::default().fg(Color::White))
            }
            Row::Entry { index, sub, child } => {
                let info = dict.object(index, sub);
                let entry = ctx.trace.values.get(key, index, sub);
                let (value, style) = self.value_cell(key, index, sub, entry, dict);
                let age = entry
                    .and_then(|e| e.last.as_ref())
                    .map(|s| age(ctx.trace.nodes.now_ns().saturating_sub(s.ts_ns)))
                    .unwrap_or_default();
                let at = if child {
                    format!("  {index:04X}:{sub:02X}")
                } else {
                    format!("{index:04X}:{sub:02X}  ")
                };
                let mut text = format!(
                    "{at:<9} {:<nw$} {:<aw$}",
                    fit(dict.name(index, sub).unwrap_or(""), w.name),
                    fit(alias(dict, index, sub).as_deref().unwrap_or(""), w.alias),
                    nw = w.name,
                    aw = w.alias
                );
                if w.wide {
                    text.push_str(&format!(
                        " {:<6} {:<5} {:<6}",
                        info.map(|i| type_word(i.data_type)).unwrap_or("?"),
                        info.map(|i| access_word(i.access)).unwrap_or(""),
                        fit(info.and_then(|i| i.unit.as_deref()).unwrap_or(""), 6)
                    ));
                } else {
                    text.push_str(&format!(" {:<5}", info.map(|i| access_word(i.access)).unwrap_or("")));
                }
                text.push_str(&format!(" {:<vw$} {age:>7}", fit(&value, w.value), vw = w.value));
                (text, style)
            }
        }
    }

    /// The value cell: the pane's read failure, the last failure seen after the last
    /// value, or the last value's text.
    fn value_cell(&self, node: NodeKey, index: u16, sub: u8, e: Option<&Entry>, dict: &Dictionary) -> (String, Style) {
        let red = Style::default().fg(Color::LightRed);
        if let Some((why, at)) = self.errors.get(&(node, index, sub))
            && e.and_then(|e| e.last.as_ref()).is_none_or(|s| s.ts_ns <= *at)
        {
            return (format!("✗ {why}"), red);
        }
        let Some(e) = e else {
            return (String::new(), Style::default().fg(Color::Gray));
        };
        if let Some(f) = &e.failed {
            return (format!("✗ {}", f.text), red);
        }
        (
            e.text(dict, index, sub).unwrap_or_default(),
            Style::default().fg(Color::Cyan),
        )
    }
}

/// Whether an index lies in one of the layers' index ranges.
fn in_range(layers: &[Arc<Profile>], index: u16) -> bool {
    layers
        .iter()
        .any(|l| l.ranges.iter().any(|r| (r.first..=r.last).contains(&index)))
}

/// The abort code of a failure text (`... aborted by the server: 0x06020000 ...`): its
/// first `0x` with eight hex digits.
fn abort_code(why: &str) -> Option<u32> {
    why.split(|c: char| !c.is_ascii_alphanumeric())
        .filter_map(|w| w.strip_prefix("0x"))
        .find(|h| h.len() == 8 && h.chars().all(|c| c.is_ascii_hexdigit()))
        .and_then(|h| u32::from_str_radix(h, 16).ok())
}

/// What went wrong, when a command result says so (`error: ...`, `not sent: ...`).
fn failure(rest: &str) -> Option<&str> {
    rest.strip_prefix("error: ")
        .or_else(|| rest.starts_with("not sent").then_some(rest))
}

/// A raw value as the command language takes it: numbers in decimal, text quoted, bytes hex.
fn raw_text(v: &crate::od::Value) -> String {
    use crate::od::Value;
    match v {
        Value::Bool(b) => (*b as u8).to_string(),
        Value::Text(t) => format!("\"{}\"", t.replace('"', "'")),
        Value::Bytes(b) => crate::frame::hex::upper(b),
        v => v.to_string(),
    }
}

/// The note shown with a prefilled write: the raw type, and how the shown value scales.
fn scaling_note(info: &ObjectInfo) -> String {
    let t = type_word(info.data_type);
    match (info.scale, info.unit.as_deref()) {
        (Some(s), Some(u)) => format!(
            "raw {t} value (shown as raw × {} {u}): edit it and press enter",
            crate::od::format_number(s)
        ),
        (Some(s), None) => format!(
            "raw {t} value (shown as raw × {}): edit it and press enter",
            crate::od::format_number(s)
        ),
        (None, Some(u)) => format!("{t} value in {u}: edit it and press enter"),
        (None, None) => format!("{t} value: edit it and press enter"),
    }
}

/// An age: `850 ms`, `12.5 s`, `3 min`, `2 h`.
fn age(ns: u64) -> String {
    let s = ns as f64 / 1e9;
    if s < 1.0 {
        format!("{:.0} ms", s * 1e3)
    } else if s < 60.0 {
        format!("{s:.1} s")
    } else if s < 3600.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.0} h", s / 3600.0)
    }
}

/// Answers with `text` for the status line: the action was taken.
fn note(q: &mut Queue, text: &str) -> bool {
    q.answer(Event::Object(ObjectRequest::Note(text.to_string())))
}

/// Column widths for a pane width.
struct Widths {
    name: usize,
    alias: usize,
    value: usize,
    /// Type and unit columns shown.
    wide: bool,
}

impl Widths {
    fn new(width: usize) -> Widths {
        let wide = width >= 100;
        // index, access (+ type, unit), age and the separators.
        let fixed = 9 + 1 + 6 + 8 + if wide { 7 + 7 } else { 0 };
        let alias = if wide { 12 } else { 9 };
        let rest = width.saturating_sub(fixed + alias + 2);
        let name = (rest * 9 / 20).max(8);
        Widths {
            name,
            alias,
            value: rest.saturating_sub(name).max(6),
            wide,
        }
    }
}

impl Component for ObjectsPane {
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool {
        self.refresh(ctx);
        if let Some(delta) = ListState::movement(action, ctx.page) {
            self.scroll(delta, ctx);
            return true;
        }
        let nodes: Vec<NodeKey> = ctx.trace.nodes.iter().map(|(n, _)| *n).collect();
        let Some(key) = self.node() else {
            return match action {
                Action::NextSeries | Action::PrevSeries | Action::Expand | Action::EditObject | Action::ReadAll => {
                    note(q, "no node seen yet")
                }
                _ => false,
            };
        };
        let node = key.node;
        let dict = ctx.trace.decoder().dictionary(node);
        match action {
            Action::NextSeries | Action::PrevSeries => {
                if nodes.is_empty() {
                    return note(q, "no node seen yet");
                }
                let at = nodes.iter().position(|n| *n == key);
                let k = match (at, action == Action::NextSeries) {
                    (Some(k), true) => (k + 1) % nodes.len(),
                    (Some(k), false) => (k + nodes.len() - 1) % nodes.len(),
                    (None, _) => 0,
                };
                self.picked = Some(nodes[k]);
                self.list = ListState::default();
                true
            }
            Action::Expand => match self.rows.get(self.list.selected).copied() {
                Some(Row::Record { obj, open }) => {
                    let index = self.catalog[obj].index;
                    if open {
                        self.open.remove(&index);
                    } else {
                        self.open.insert(index);
                    }
                    true
                }
                Some(Row::Entry { index, sub, .. }) => {
                    if dict.object(index, sub).is_some_and(|o| o.access == Access::Wo) {
                        return note(q, &format!("0x{index:04X}:{sub:02X} is write-only: it cannot be read"));
                    }
                    q.answer(Event::Object(ObjectRequest::Read { node: key, index, sub }))
                }
                None => true,
            },
            Action::EditObject => match self.selected_entry() {
                Some((index, sub)) => q.answer(Event::Object(self.edit(key, index, sub, ctx))),
                None => note(q, "select an entry (open the record with enter) to write it"),
            },
            Action::ReadAll => match self.stop_read_all() {
                Some(summary) => note(q, &summary),
                None => q.answer(Event::Object(ObjectRequest::ReadAll {
                    node: key,
                    objects: self.readable(dict),
                })),
            },
            Action::Filter | Action::Search => q.answer(Event::Object(ObjectRequest::Find(self.query.clone()))),
            Action::NextMatch | Action::PrevMatch => self.jump(action == Action::NextMatch, ctx, q),
            Action::Back if !self.query.is_empty() => {
                self.set_query("");
                true
            }
            _ => false,
        }
    }

    fn scroll(&mut self, delta: isize, ctx: &Ctx) {
        self.list.scroll(delta, self.rows.len(), ctx.page);
    }

    fn click(&mut self, row: usize, ctx: &Ctx) {
        self.list.click(row, self.rows.len(), ctx.page);
    }

    fn fit(&mut self, height: usize, ctx: &Ctx) {
        self.refresh(ctx);
        self.list.clamp(self.rows.len(), height);
    }

    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool) {
        f.render_widget(block(&self.title(ctx), focused), area);
        let inner = block("", true).inner(area);
        if inner.height == 0 {
            return;
        }
        let Some(node) = self.node() else {
            f.render_widget(Paragraph::new("no node seen yet"), inner);
            return;
        };
        let width = inner.width as usize;
        let w = Widths::new(width);
        let mut head = format!(
            "{:<9} {:<nw$} {:<aw$}",
            "index",
            "name",
            "alias",
            nw = w.name,
            aw = w.alias
        );
        if w.wide {
            head.push_str(&format!(" {:<6} {:<5} {:<6}", "type", "acc", "unit"));
        } else {
            head.push_str(&format!(" {:<5}", "acc"));
        }
        head.push_str(&format!(" {:<vw$} {:>7}", "last value", "age", vw = w.value));
        let mut lines = vec![Line::styled(fit(&head, width), header())];
        for (k, r) in self
            .rows
            .iter()
            .enumerate()
            .skip(self.list.offset)
            .take(inner.height as usize - 1)
        {
            let (text, style) = self.row(*r, node, ctx, &w);
            let line = Line::styled(fit(&text, width), style);
            lines.push(if k == self.list.selected && focused {
                line.style(selected())
            } else {
                line
            });
        }
        if self.rows.is_empty() {
            lines.push(Line::raw(if self.query.is_empty() {
                "no object known for this node".to_string()
            } else {
                format!("no object matches `{}`", self.query)
            }));
        }
        f.render_widget(Paragraph::new(lines), inner);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::bind::Bindings;

    fn dict() -> Dictionary {
        let read = |p: &std::path::Path| std::fs::read(p);
        let b = Bindings::from_args(&["2=syntron-ds".to_string()], &[], &read).unwrap();
        b.dictionary(2).clone()
    }

    #[test]
    fn the_catalog_has_every_layer_records_fold_and_pdo_ranges_show_four() {
        let d = dict();
        let c = catalog(&d, &BTreeSet::new());
        let find = |i: u16| c.iter().find(|o| o.index == i);
        // CiA 301 (identity record), CiA 402 (statusword), the vendor's own objects.
        let id = find(0x1018).unwrap();
        assert!(id.record && id.subs.starts_with(&[0, 1, 2]), "{id:?}");
        let sw = find(0x6041).unwrap();
        assert_eq!((sw.record, sw.subs.as_slice()), (false, &[0u8][..]));
        assert!(c.iter().any(|o| (0x2000..0x6000).contains(&o.index)));
        // PDO parameter ranges: PDOs 1-4 listed; another one once a value of it was seen.
        let tpdo_maps: Vec<u16> = c
            .iter()
            .map(|o| o.index)
            .filter(|i| (0x1A00..0x1C00).contains(i))
            .collect();
        assert_eq!(tpdo_maps, [0x1A00, 0x1A01, 0x1A02, 0x1A03]);
        let c = catalog(&d, &BTreeSet::from([0x1A07, 0x1280]));
        assert!(c.iter().any(|o| o.index == 0x1A07 && o.record));
        assert!(c.iter().any(|o| o.index == 0x1280));
        assert!(!c.iter().any(|o| o.index == 0x1281));
    }

    #[test]
    fn find_matches_name_alias_and_index_forms() {
        assert!(matches("statusw", 0x6041, Some(0), "Statusword", None));
        assert!(matches("6041", 0x6041, Some(0), "Statusword", None));
        assert!(matches("0x6041:00", 0x6041, Some(0), "Statusword", None));
        assert!(matches("1018", 0x1018, None, "Identity object", None));
        assert!(matches("f0.3", 0x2003, Some(0x12), "Speed command", Some("F0.3.018")));
        assert!(!matches("6041:01", 0x6041, Some(0), "Statusword", None));
        assert!(!matches("speed", 0x6041, Some(0), "Statusword", Some("H01-02")));
    }

    #[test]
    fn a_read_all_goes_on_result_by_result_and_sums_up_failures() {
        let mut p = ObjectsPane::default();
        let first = p.start_read_all(NodeKey::new(0, 2), vec![(0x1000, 0), (0x1008, 0), (0x6041, 0)]);
        assert_eq!(first, Step::Next("sdo read 2 0x1000:0x00".into()));
        // Someone else's result changes nothing.
        assert_eq!(p.result("nmt start 2: NMT start sent to node 2", 0), Step::NotOurs);
        assert_eq!(
            p.result("sdo read 2 0x1000:0x00: node 2 0x1000:00 Device type = 0x00020192", 0),
            Step::Next("sdo read 2 0x1008:0x00".into())
        );
        // An object the node does not have is not present, not a failure.
        assert_eq!(
            p.result(
                "sdo read 2 0x1008:0x00: error: SDO 1008:00 on node 2 aborted by the server: 0x06020000 Object does not exist in the object dictionary",
                0
            ),
            Step::Next("sdo read 2 0x6041:0x00".into())
        );
        let r = p.read_all.as_ref().unwrap();
        assert_eq!((r.done, r.total, r.failed.len(), r.not_present), (2, 3, 0, 1));
        assert_eq!(
            p.result(
                "sdo read 2 0x6041:0x00: error: SDO 6041:00 on node 2 aborted by the server: 0x08000022 Data cannot be transferred",
                0
            ),
            Step::Finished(
                "read all node 2: 1 entries read, 1 not present, 1 failed\n\
                 0x6041:00: SDO 6041:00 on node 2 aborted by the server: 0x08000022 Data cannot be transferred"
                    .into()
            )
        );
        assert!(p.read_all.is_none());
        assert_eq!(
            p.errors.get(&(NodeKey::new(0, 2), 0x1008, 0)).map(|(e, _)| e.as_str()),
            Some(
                "SDO 1008:00 on node 2 aborted by the server: 0x06020000 Object does not exist in the object dictionary"
            )
        );
        // Stopped half-way: a summary, and later results are no longer ours.
        p.start_read_all(NodeKey::new(0, 3), vec![(0x1000, 0), (0x1001, 0)]);
        assert_eq!(
            p.stop_read_all().as_deref(),
            Some("read all node 3: stopped after 0 of 2 entries (0 not present, 0 failed)")
        );
        assert_eq!(p.result("sdo read 3 0x1000:0x00: node 3 ...", 0), Step::NotOurs);
        // Sub 0 of a record bounds the sub-indexes read; an absent object is left whole.
        let all = vec![
            (0x1003, 0),
            (0x1003, 1),
            (0x1003, 2),
            (0x1003, 3),
            (0x1010, 0),
            (0x1010, 1),
        ];
        p.start_read_all(NodeKey::new(0, 2), all);
        assert_eq!(
            p.result(
                "sdo read 2 0x1003:0x00: node 2 0x1003:00 Number of errors = 1 (data 01)",
                0
            ),
            Step::Next("sdo read 2 0x1003:0x01".into())
        );
        assert_eq!(
            p.result(
                "sdo read 2 0x1003:0x01: node 2 0x1003:01 Standard error field = 0 (data 00 00 00 00)",
                0
            ),
            Step::Next("sdo read 2 0x1010:0x00".into())
        );
        assert_eq!(
            p.result("sdo read 2 0x1010:0x00: error: SDO abort 0x06020000: Object does not exist", 0),
            Step::Finished(
                "read all node 2: 2 entries read, 1 not present, 0 failed; 3 more of the 6 the dictionary knows left out (not on the node)"
                    .into()
            )
        );
    }

    #[test]
    fn read_errors_are_kept_per_interface() {
        let (can0, can1) = (NodeKey::new(0, 5), NodeKey::new(1, 5));
        let line = read_line(5, 0x1008, 0);
        let mut p = ObjectsPane::default();
        p.sent(&line, can1, 0x1008, 0);
        assert_eq!(p.result(&format!("{line}: error: SDO timeout"), 7), Step::Noted);
        // Node 5 of can0 reads the same entry fine: can1's node 5 keeps its error.
        p.sent(&line, can0, 0x1008, 0);
        assert_eq!(
            p.result(&format!("{line}: node 5 0x1008:00 Device name = \"x\""), 8),
            Step::Noted
        );
        let dict = Dictionary::default();
        let cell = |p: &ObjectsPane, k| p.value_cell(k, 0x1008, 0, None, &dict).0;
        assert_eq!(cell(&p, can1), "✗ SDO timeout");
        assert_eq!(cell(&p, can0), "");
        // A read-all of can0's node 5 that fails leaves can1's error as it was.
        p.start_read_all(can0, vec![(0x1008, 0)]);
        p.result(&format!("{line}: error: SDO abort 0x08000000: General error"), 9);
        assert_eq!(cell(&p, can0), "✗ SDO abort 0x08000000: General error");
        assert_eq!(cell(&p, can1), "✗ SDO timeout");
    }

    /// The test capture with node 1 bound to the aimotor profile (CiA 402, CiA 301 below it)
    /// and a few more transfers: the vendor-ID read, a write of an H parameter, an abort.
    fn objects_app() -> crate::tui::app::App {
        use crate::analysis::trace::Trace;
        use crate::decode::Decoder;
        use crate::frame::Frame;
        use crate::tui::app::{App, SourceInfo, SourceKind};
        let read = |p: &std::path::Path| std::fs::read(p);
        let b = Bindings::from_args(&["1=aimotor".to_string()], &[], &read).unwrap();
        let mut trace = Trace::new(Decoder::from_bindings(&b), 500_000);
        trace.ifaces.intern("can0");
        let mut frames = crate::tui::panes::testutil::frames();
        let mut t = frames.last().unwrap().ts_ns;
        for (id, data) in [
            (0x601, [0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0]),
            (0x581, [0x43, 0x18, 0x10, 0x01, 0x78, 0x56, 0x34, 0x12]),
            (0x601, [0x2B, 0x02, 0x20, 0x01, 0x2C, 0x01, 0, 0]),
            (0x581, [0x60, 0x02, 0x20, 0x01, 0, 0, 0, 0]),
            (0x601, [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]),
            (0x581, [0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x02, 0x06]),
        ] {
            t += 2_000_000;
            let mut f = Frame::classic(id, &data);
            f.ts_ns = t;
            frames.push(f);
        }
        for f in &frames {
            trace.push(f);
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("test.log", SourceKind::Open, rx, None);
        src.done = true;
        let mut a = App::new(trace, crate::tui::keymap::Keymap::default_map(), src);
        a.set_bindings(b);
        a.screen_mut().focus_on(crate::tui::panes::Pane::Objects);
        a
    }

    #[test]
    fn the_pane_shows_the_nodes_dictionary_with_last_values_at_160x48() {
        use crate::tui::panes::testutil::screen;
        let mut a = objects_app();
        let s = screen(&mut a, 160, 48);
        assert!(
            s.contains("Objects · node 1 aimotor > cia402 > cia301 · 4607 entries"),
            "{s}"
        );
        assert!(s.contains("▸ 1018    Identity object"), "{s}");
        // 0x1017 was read (100 ms, in the test capture); 0x1008 aborted.
        assert!(s.contains("1017:00   Producer heartbeat time"), "{s}");
        assert!(s.contains("✗ abort 06020000: Object does not"), "{s}");
        insta::assert_snapshot!(s);
        // Open the identity record: the vendor-ID read shows with its age.
        for _ in 0..40 {
            if a.screen().panes().objects.selected_entry().is_none()
                && matches!(a.screen().panes().objects.rows.get(a.screen().panes().objects.list.selected), Some(Row::Record { obj, .. }) if a.screen().panes().objects.catalog[*obj].index == 0x1018)
            {
                break;
            }
            a.act(Action::Down);
        }
        a.act(Action::Expand);
        let s = screen(&mut a, 160, 48);
        assert!(s.contains("▾ 1018"), "{s}");
        assert!(s.contains("  1018:01 Vendor-ID"), "{s}");
        // An identifier, in hex (not 305419896).
        assert!(s.contains("0x12345678"), "{s}");
        assert!(!s.contains("305419896"), "{s}");
    }

    #[test]
    fn find_while_typing_narrows_the_rows_at_80x24() {
        use crate::tui::panes::testutil::screen;
        use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
        let mut a = objects_app();
        let _ = screen(&mut a, 80, 24);
        a.key(KeyEvent::new(KeyCode::Char('/'), KeyModifiers::NONE));
        for c in "h02".chars() {
            a.key(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE));
        }
        // The rows follow each key, before enter.
        let s = screen(&mut a, 80, 24);
        assert!(s.contains("find object: h02"), "{s}");
        assert!(s.contains("2002:01 "), "{s}");
        assert!(s.contains("H02-00"), "{s}");
        assert!(!s.contains("1017:00"), "{s}");
        insta::assert_snapshot!(s);
        a.key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
        assert_eq!(a.screen().panes().objects.query, "h02");
        // n goes to the next match; esc clears the find text.
        a.act(Action::NextMatch);
        assert!(a.screen().panes().objects.selected_entry().is_some());
        a.act(Action::Back);
        assert_eq!(a.screen().panes().objects.query, "");
    }

    #[test]
    fn enter_and_read_all_on_a_log_say_there_is_no_bus_and_e_prefills_the_write() {
        use crate::tui::panes::testutil::screen;
        let mut a = objects_app();
        a.run_command("filter node 1");
        a.screen_mut().focus_on(crate::tui::panes::Pane::Objects);
        a.screen_mut().objects_mut().set_query("1017");
        let _ = screen(&mut a, 160, 48);
        assert_eq!(a.screen().panes().objects.selected_entry(), Some((0x1017, 0)));
        a.act(Action::Expand);
        assert_eq!(
            a.message(),
            Some(
                "sdo read 1 0x1017:0x00: this source is a log file, there is no bus to read from (use `cotui live IFACE` or `cotui demo`)"
            )
        );
        a.act(Action::ReadAll);
        assert!(
            a.message()
                .unwrap_or("")
                .starts_with("read all node 1: this source is a log file")
        );
        assert!(a.screen().panes().objects.read_all.is_none());
        a.act(Action::EditObject);
        let p = a.screen().prompt().editing.as_ref().expect("the palette is open");
        assert_eq!(p.text, "sdo write 1 0x1017:0x00 100 --type u16");
        assert_eq!(p.cursor, "sdo write 1 0x1017:0x00 100".len());
        let m = a.message().map(str::to_string).unwrap_or_default();
        assert!(
            m.starts_with(
                "u16 value in ms: edit it and press enter · blocked: this source has no bus — would send 601#2B17100064000000"
            ),
            "{m}"
        );
        // A read-only entry is not offered for writing.
        a.screen_mut().prompt_mut().editing = None;
        a.screen_mut().objects_mut().set_query("1018:01");
        let _ = screen(&mut a, 160, 48);
        a.act(Action::EditObject);
        assert!(a.screen().prompt().editing.is_none());
        assert_eq!(a.message(), Some("0x1018:01 Vendor-ID is read-only (ro)"));
    }

    #[test]
    fn listen_only_reads_nothing_and_says_so() {
        let (_ftx, frx) = std::sync::mpsc::channel();
        let (rtx, mut rrx) = tokio::sync::mpsc::unbounded_channel();
        let mut a = objects_app();
        *a.capture_mut().source_mut() = crate::tui::app::SourceInfo::live(
            "vcan0",
            crate::tui::app::SourceKind::Live { listen_only: true },
            frx,
            rtx,
        );
        a.screen_mut().objects_mut().set_query("1017");
        let _ = crate::tui::panes::testutil::screen(&mut a, 160, 48);
        a.act(Action::Expand);
        a.act(Action::ReadAll);
        assert!(rrx.try_recv().is_err(), "nothing requested");
        assert_eq!(
            a.message(),
            Some("read all node 1: listen-only — nothing can be sent, so no object can be read")
        );
        a.act(Action::EditObject);
        assert!(a.screen().prompt().editing.is_none(), "no write offered");
        assert_eq!(
            a.message(),
            Some("write: listen-only — nothing can be sent, so no object can be written")
        );
    }
}
