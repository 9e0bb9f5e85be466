//! The panes, one module each: each owns its state, handles the actions meant for it
//! ([`Component::handle`], answering with events of [`crate::tui::event`]) and draws
//! itself; plus the shared styles.

mod boots;
mod cycles;
pub mod detail;
pub mod help;
pub mod messages;
pub mod nodes;
pub mod objects;
pub mod pdo;
pub mod picker;
pub mod plot;
pub mod problems;
pub mod sdo;
mod sdo_seq;
pub mod stats;
pub mod status;
pub mod trace;
pub mod trace_time;
pub mod transmit;
pub mod watch;

use crate::analysis::trace::Trace;
use crate::decode::Kind;
use crate::tui::event::Queue;
use crate::tui::keymap::Action;
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::widgets::{Block, BorderType, Borders};

/// The main-area panes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pane {
    Trace,
    Nodes,
    Sdo,
    Stats,
    Plot,
    Objects,
    Pdo,
    Problems,
    Transmit,
    Watch,
}

impl Pane {
    /// Every pane in tab order.
    pub const ALL: [Pane; 10] = [
        Pane::Trace,
        Pane::Nodes,
        Pane::Sdo,
        Pane::Stats,
        Pane::Plot,
        Pane::Objects,
        Pane::Pdo,
        Pane::Problems,
        Pane::Transmit,
        Pane::Watch,
    ];
    /// Tab title, `short` on a narrow tab bar (`Probl`, `Trans`).
    pub fn title_fit(self, short: bool) -> &'static str {
        match self {
            Pane::Problems if short => "Probl",
            Pane::Transmit if short => "Trans",
            p => p.title(),
        }
    }

    /// Tab title.
    pub fn title(self) -> &'static str {
        match self {
            Pane::Trace => "Trace",
            Pane::Nodes => "Nodes",
            Pane::Sdo => "SDO",
            Pane::Stats => "Stats",
            Pane::Plot => "Plot",
            Pane::Objects => "Objects",
            Pane::Pdo => "PDO",
            Pane::Problems => "Problems",
            Pane::Transmit => "Transmit",
            Pane::Watch => "Watch",
        }
    }
}

/// The main-area panes' states, one of each.
#[derive(Default)]
pub struct Panes {
    /// One row per frame of the filtered view.
    trace: trace::TracePane,
    /// One row per node.
    nodes: nodes::NodesPane,
    /// One row per SDO transfer, or the sequence diagram of one.
    sdo: sdo::SdoPane,
    /// One row per COB-ID.
    stats: stats::StatsPane,
    /// Numeric signals over one time axis.
    plot: plot::PlotPane,
    /// The object dictionary of one node with the last values seen.
    objects: objects::ObjectsPane,
    /// One row per known PDO of each node.
    pdo: pdo::PdoPane,
    /// One row per incident of the diagnosis.
    problems: problems::ProblemsPane,
    /// One row per entry of the transmit list.
    transmit: transmit::TransmitPane,
    /// One row per watched object.
    watch: watch::WatchPane,
}

impl Panes {
    /// The Trace pane (its view, filter, selection, follow mode).
    pub fn trace(&self) -> &trace::TracePane {
        &self.trace
    }

    /// The Trace pane, to change.
    pub(crate) fn trace_mut(&mut self) -> &mut trace::TracePane {
        &mut self.trace
    }

    /// The Nodes pane.
    pub fn nodes(&self) -> &nodes::NodesPane {
        &self.nodes
    }

    /// The SDO pane.
    pub fn sdo(&self) -> &sdo::SdoPane {
        &self.sdo
    }

    /// The Objects pane.
    pub fn objects(&self) -> &objects::ObjectsPane {
        &self.objects
    }

    /// The Objects pane, to change (reads, read-all, the find text).
    pub(crate) fn objects_mut(&mut self) -> &mut objects::ObjectsPane {
        &mut self.objects
    }

    /// The Plot pane, to change (the series shown, the picker).
    pub(crate) fn plot_mut(&mut self) -> &mut plot::PlotPane {
        &mut self.plot
    }

    /// The Problems pane.
    pub fn problems(&self) -> &problems::ProblemsPane {
        &self.problems
    }

    /// The Problems pane, to change.
    pub(crate) fn problems_mut(&mut self) -> &mut problems::ProblemsPane {
        &mut self.problems
    }

    /// The Transmit pane.
    pub fn transmit(&self) -> &transmit::TransmitPane {
        &self.transmit
    }

    /// The Transmit pane, to change (its entries, what they sent).
    pub(crate) fn transmit_mut(&mut self) -> &mut transmit::TransmitPane {
        &mut self.transmit
    }

    /// The Watch pane.
    pub fn watch(&self) -> &watch::WatchPane {
        &self.watch
    }

    /// The Watch pane, to change (its board, what is polled).
    pub(crate) fn watch_mut(&mut self) -> &mut watch::WatchPane {
        &mut self.watch
    }

    /// The Watch pane and the Objects pane, to change both.
    pub(crate) fn watch_and_objects(&mut self) -> (&mut watch::WatchPane, &mut objects::ObjectsPane) {
        (&mut self.watch, &mut self.objects)
    }

    /// The Plot pane.
    pub fn plot(&self) -> &plot::PlotPane {
        &self.plot
    }

    /// Tells the Objects pane the Nodes pane's selection (its node, unless one is picked
    /// there).
    pub(crate) fn sync_objects_node(&mut self, trace: &Trace) {
        let n = self.nodes.selected_node(trace);
        self.objects.set_nodes_selection(n);
    }

    /// The pane `p`.
    pub(crate) fn get(&self, p: Pane) -> &dyn Component {
        match p {
            Pane::Trace => &self.trace,
            Pane::Nodes => &self.nodes,
            Pane::Sdo => &self.sdo,
            Pane::Stats => &self.stats,
            Pane::Plot => &self.plot,
            Pane::Objects => &self.objects,
            Pane::Pdo => &self.pdo,
            Pane::Problems => &self.problems,
            Pane::Transmit => &self.transmit,
            Pane::Watch => &self.watch,
        }
    }

    /// The pane `p`, to change.
    pub(crate) fn get_mut(&mut self, p: Pane) -> &mut dyn Component {
        match p {
            Pane::Trace => &mut self.trace,
            Pane::Nodes => &mut self.nodes,
            Pane::Sdo => &mut self.sdo,
            Pane::Stats => &mut self.stats,
            Pane::Plot => &mut self.plot,
            Pane::Objects => &mut self.objects,
            Pane::Pdo => &mut self.pdo,
            Pane::Problems => &mut self.problems,
            Pane::Transmit => &mut self.transmit,
            Pane::Watch => &mut self.watch,
        }
    }
}

/// What a pane sees of the application when it handles an action or draws.
#[derive(Clone, Copy)]
pub struct Ctx<'a> {
    /// Frames and what is derived from them.
    pub(crate) trace: &'a Trace,
    /// Rows a page holds (the visible height of the main table).
    pub(crate) page: usize,
    /// The capture is paused.
    pub(crate) paused: bool,
}

/// What the selected row of a pane is, for the Detail view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Selected {
    /// A frame (trace position).
    Frame(usize),
    /// An SDO transfer (index into the transactions).
    Transfer(usize),
}

/// A main-area pane.
pub(crate) trait Component {
    /// Handles `action` while the pane has the focus; false when it is not for this pane
    /// (the screen handles it). What the pane asks of the rest of the application (show
    /// the trace filtered, open the Detail view, read an object...) it pushes to `q`.
    fn handle(&mut self, action: Action, ctx: &Ctx, q: &mut Queue) -> bool;
    /// Moves the selection by `delta` rows (mouse wheel); panes without rows ignore it.
    fn scroll(&mut self, _delta: isize, _ctx: &Ctx) {}
    /// Selects the `row`-th visible row (mouse click); panes without rows ignore it.
    fn click(&mut self, _row: usize, _ctx: &Ctx) {}
    /// Keeps the selection within the rows and visible in `height` rows (before drawing).
    fn fit(&mut self, _height: usize, _ctx: &Ctx) {}
    /// What the Detail view shows for this pane; None: the trace's selected frame.
    fn selected(&self, _ctx: &Ctx) -> Option<Selected> {
        None
    }
    /// Draws the pane into `area`.
    fn render(&self, f: &mut Frame, area: Rect, ctx: &Ctx, focused: bool);
}

/// Scroll state of a list pane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListState {
    /// Selected row.
    selected: usize,
    /// First visible row.
    offset: usize,
}

impl ListState {
    /// Keeps `selected` within `len` rows and visible in `height` rows.
    pub fn clamp(&mut self, len: usize, height: usize) {
        self.selected = self.selected.min(len.saturating_sub(1));
        let h = height.max(1);
        if self.selected < self.offset {
            self.offset = self.selected;
        } else if self.selected >= self.offset + h {
            self.offset = self.selected + 1 - h;
        }
        self.offset = self.offset.min(len.saturating_sub(h));
    }

    /// Moves the selection by `delta` rows within `len`, visible in `page` rows.
    pub fn scroll(&mut self, delta: isize, len: usize, page: usize) {
        self.selected = (self.selected as isize + delta).clamp(0, len.saturating_sub(1) as isize) as usize;
        self.clamp(len, page);
    }

    /// Selects the `row`-th visible row, if there is one.
    pub fn click(&mut self, row: usize, len: usize, page: usize) {
        let want = self.offset + row;
        if want < len {
            self.selected = want;
            self.clamp(len, page);
        }
    }

    /// The list movement an action asks for, if it is one: Some(delta in rows).
    pub fn movement(action: Action, page: usize) -> Option<isize> {
        let page = page as isize;
        Some(match action {
            Action::Down => 1,
            Action::Up => -1,
            Action::PageDown => page,
            Action::PageUp => -page,
            Action::Top => isize::MIN / 2,
            Action::Bottom => isize::MAX / 2,
            _ => return None,
        })
    }
}

/// The colour of a kind in the trace.
pub fn kind_color(kind: Kind) -> Color {
    match kind {
        Kind::Nmt => Color::Magenta,
        Kind::Sync => Color::DarkGray,
        Kind::Emcy => Color::Red,
        Kind::Time => Color::Gray,
        Kind::Tpdo => Color::Green,
        Kind::Rpdo => Color::LightGreen,
        Kind::SdoTx => Color::Cyan,
        Kind::SdoRx => Color::LightCyan,
        Kind::Heartbeat => Color::Blue,
        Kind::Lss => Color::Yellow,
        Kind::ErrorFrame => Color::LightRed,
        Kind::Other => Color::White,
    }
}

/// The timestamp of the first frame (0 while there is none).
pub fn start_ns(trace: &Trace) -> u64 {
    if trace.is_empty() {
        0
    } else {
        trace.store.packed(0).ts_ns
    }
}

/// Style of the selected row.
pub fn selected() -> Style {
    Style::default().add_modifier(Modifier::REVERSED)
}

/// Style of a table header.
pub fn header() -> Style {
    Style::default().add_modifier(Modifier::BOLD)
}

/// A pane frame with a title; focused panes get a thick border.
pub fn block(title: &str, focused: bool) -> Block<'_> {
    Block::default()
        .borders(Borders::ALL)
        .border_type(if focused { BorderType::Thick } else { BorderType::Plain })
        .title(title)
}

/// Seconds as `1.234 s`, `12.3 ms` or `45 µs`.
pub fn duration(secs: f64) -> String {
    if secs >= 1.0 {
        format!("{secs:.3} s")
    } else if secs >= 1e-3 {
        format!("{:.1} ms", secs * 1e3)
    } else {
        format!("{:.0} µs", secs * 1e6)
    }
}

/// Cuts `s` to `width` characters, marking the cut with `…`.
pub fn fit(s: &str, width: usize) -> String {
    if s.chars().count() <= width {
        s.to_string()
    } else if width == 0 {
        String::new()
    } else {
        s.chars().take(width - 1).chain(std::iter::once('…')).collect()
    }
}

#[cfg(test)]
pub(crate) mod testutil {
    //! Helpers for the pane rendering tests.
    use crate::analysis::trace::Trace;
    use crate::decode::Decoder;
    use crate::frame::Frame;
    use crate::od::Dictionary;
    use crate::tui::app::{App, SourceInfo, SourceKind};
    use crate::tui::keymap::Keymap;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    /// `app()` fed by a live source whose requests the test reads, with demo bindings.
    pub fn live_app(listen_only: bool) -> (App, tokio::sync::mpsc::UnboundedReceiver<crate::tui::live::Request>) {
        let (_ftx, frx) = std::sync::mpsc::channel();
        let (rtx, rrx) = tokio::sync::mpsc::unbounded_channel();
        let mut a = app();
        *a.capture_mut().source_mut() = SourceInfo::live("vcan0", SourceKind::Live { listen_only }, frx, rtx);
        a.set_bindings(crate::cli::bind::bindings_on(crate::connect::DEMO, &[], &[]).unwrap());
        (a, rrx)
    }

    /// A small fixed capture: boot-ups, NMT start, a PDO mapping written by SDO, heartbeats,
    /// statusword PDOs (switched on, then operation enabled), an SDO abort, an EMCY.
    pub fn frames() -> Vec<Frame> {
        let mut v = Vec::new();
        let mut t = 1_700_000_000_000_000_000u64;
        let mut add = |id: u32, data: &[u8], dt_ms: u64| {
            t += dt_ms * 1_000_000;
            let mut f = Frame::classic(id, data);
            f.ts_ns = t;
            v.push(f);
        };
        add(0x701, &[0x00], 0);
        add(0x702, &[0x00], 1);
        add(0x000, &[0x01, 0x00], 5);
        add(0x601, &[0x40, 0x17, 0x10, 0x00, 0, 0, 0, 0], 1);
        add(0x581, &[0x4B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0], 1);
        // Map TPDO1 of node 1 to the statusword (the decoder learns it from these writes).
        add(0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0], 1);
        add(0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0], 1);
        add(0x601, &[0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60], 1);
        add(0x581, &[0x60, 0x00, 0x1A, 0x01, 0, 0, 0, 0], 1);
        add(0x601, &[0x2F, 0x00, 0x1A, 0x00, 0x01, 0, 0, 0], 1);
        add(0x581, &[0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0], 1);
        add(0x602, &[0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0], 1);
        add(0x582, &[0x80, 0x41, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06], 2);
        for i in 0..6u8 {
            add(0x080, &[], 10);
            add(0x181, &[0x37 - (i < 3) as u8 * 4, 0x02], 1);
            add(0x201, &[0x0F, 0x00, i, 0, 0, 0], 1);
            add(0x701, &[0x05], 1);
            add(0x702, &[0x7F], 1);
        }
        add(0x082, &[0x10, 0x23, 0x11, 0, 0, 0, 0, 0], 3);
        v
    }

    /// An app holding [`frames`] (fully ingested), default keymap.
    pub fn app() -> App {
        app_of(&frames())
    }

    /// An app holding `frames` (fully ingested, on can0), default keymap.
    pub fn app_of(frames: &[Frame]) -> App {
        app_at(frames, 500_000.into())
    }

    /// [`app_of`] with the bus load counted at `bitrate`.
    pub fn app_at(frames: &[Frame], bitrate: crate::output::busload::Bitrate) -> App {
        let mut trace = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), bitrate);
        trace.ifaces.intern("can0");
        for f in frames {
            trace.push(f);
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("test.log", SourceKind::Open, rx, None);
        src.done = true;
        App::new(trace, Keymap::default_map(), src)
    }

    /// An app holding the frames of the candump log at `path` (relative to the checkout).
    pub fn app_of_log(path: &str) -> App {
        let path = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read(&path).unwrap();
        let mut reader = crate::log::LogReader::new(std::io::BufReader::new(text.as_slice())).unwrap();
        let mut trace = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        trace.ifaces.intern("can0");
        while let Some((_, outcome)) = reader.next_line().unwrap() {
            if let crate::log::Outcome::Frame(f) = outcome {
                trace.push(&f);
            }
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("boot.log", SourceKind::Open, rx, None);
        src.done = true;
        App::new(trace, Keymap::default_map(), src)
    }

    /// A drive (node 1, CiA 402 dictionary) whose TPDO1 carries the statusword, the vl
    /// velocity actual value (rpm) and the mode display: 40 PDOs 10 ms apart, enabled at
    /// the 10th, a speed ramp, profile velocity mode from the 20th, a fault at the 35th.
    pub fn plot_app() -> App {
        let bindings = crate::od::bind::Bindings::new();
        let mut trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
        trace.ifaces.intern("can0");
        let mut t = 1_700_000_000_000_000_000u64;
        let mut add = |id: u32, data: &[u8], dt_ms: u64| {
            t += dt_ms * 1_000_000;
            let mut f = Frame::classic(id, data);
            f.ts_ns = t;
            trace.push(&f);
        };
        add(0x701, &[0x00], 0);
        for (sub, value) in [
            (0u8, 0u32),
            (1, 0x6041_0010),
            (2, 0x6044_0010),
            (3, 0x6061_0008),
            (0, 3),
        ] {
            let v = value.to_le_bytes();
            add(0x601, &[0x23, 0x00, 0x1A, sub, v[0], v[1], v[2], v[3]], 1);
            add(0x581, &[0x60, 0x00, 0x1A, sub, 0, 0, 0, 0], 1);
        }
        for i in 0..40u16 {
            let sw: u16 = match i {
                0..10 => 0x0231,
                10..35 => 0x0237,
                _ => 0x0238,
            };
            let speed: i16 = if (10..35).contains(&i) { (i as i16 - 10) * 40 } else { 0 };
            let mode: u8 = if i >= 20 { 3 } else { 2 };
            let (s, v) = (sw.to_le_bytes(), speed.to_le_bytes());
            add(0x181, &[s[0], s[1], v[0], v[1], mode], 10);
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("drive.log", SourceKind::Open, rx, None);
        src.done = true;
        App::new(trace, Keymap::default_map(), src)
    }

    /// Node 1's TPDO1 mapped (sniffed SDO writes) to the position actual value, a constant
    /// 0x1000, and the velocity actual value, a ramp 0 to 975 over 40 frames 10 ms apart.
    pub fn constant_and_ramp_app() -> App {
        let bindings = crate::od::bind::Bindings::new();
        let mut trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
        trace.ifaces.intern("can0");
        let mut t = 1_700_000_000_000_000_000u64;
        let mut add = |id: u32, data: &[u8], dt_ms: u64| {
            t += dt_ms * 1_000_000;
            let mut f = Frame::classic(id, data);
            f.ts_ns = t;
            trace.push(&f);
        };
        add(0x701, &[0x00], 0);
        for (sub, value) in [(0u8, 0u32), (1, 0x6064_0020), (2, 0x606C_0020), (0, 2)] {
            let v = value.to_le_bytes();
            add(0x601, &[0x23, 0x00, 0x1A, sub, v[0], v[1], v[2], v[3]], 1);
            add(0x581, &[0x60, 0x00, 0x1A, sub, 0, 0, 0, 0], 1);
        }
        for i in 0..40i32 {
            let (p, v) = (0x1000i32.to_le_bytes(), (i * 25).to_le_bytes());
            add(0x181, &[p[0], p[1], p[2], p[3], v[0], v[1], v[2], v[3]], 10);
        }
        let (_tx, rx) = std::sync::mpsc::channel();
        let mut src = SourceInfo::new("ramp.log", SourceKind::Open, rx, None);
        src.done = true;
        App::new(trace, Keymap::default_map(), src)
    }

    /// Renders the whole screen of `app` at `w`×`h` and returns the text.
    pub fn screen(app: &mut App, w: u16, h: u16) -> String {
        let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
        term.draw(|f| crate::tui::ui::draw(f, app)).unwrap();
        let buf = term.backend().buffer().clone();
        let mut out = String::new();
        for y in 0..buf.area.height {
            let line: String = (0..buf.area.width).map(|x| buf[(x, y)].symbol().to_string()).collect();
            out.push_str(line.trim_end());
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod render_tests;
#[cfg(test)]
mod trigger_tests;
