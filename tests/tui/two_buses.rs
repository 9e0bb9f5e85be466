//! One live session on two buses (`cotui live demo demo2`: two independent simulated
//! buses, each with the standard demo drives): the frames of each come tagged with its
//! interface, node 2 is known twice (once per bus), and the status bar and the Stats pane
//! show each bus's load and state.

use cotui::analysis::trace::Trace;
use cotui::decode::Decoder;
use cotui::frame::NodeKey;
use cotui::tui::app::{App, SourceInfo, SourceKind};
use cotui::tui::keymap::Keymap;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

fn until(a: &mut App, what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    crate::screen::until_at(a, (200, 40), what, f)
}

fn two_demo_buses() -> App {
    let bindings = cotui::cli::bind::bindings_on("demo", &[], &[]).unwrap();
    let trace = Trace::new(Decoder::from_bindings(&bindings), 500_000);
    let ifaces = ["demo".to_string(), "demo2".to_string()];
    let (rx, req) = cotui::tui::live::start(&ifaces, true, bindings.clone(), None, Default::default());
    let src = SourceInfo::live("demo demo2", SourceKind::Live { listen_only: true }, rx, req);
    let mut a = App::new(trace, Keymap::default_map(), src);
    a.set_bindings(bindings);
    a
}

/// The status bar: the line that starts with the source.
fn status_bar(s: &str) -> String {
    s.lines()
        .find(|l| l.starts_with("live demo demo2"))
        .unwrap_or_default()
        .to_string()
}

#[test]
fn two_buses_in_one_session_each_with_its_load_state_and_nodes() {
    let mut a = two_demo_buses();
    let s = until(&mut a, "frames of node 2 on both buses", |a, _| {
        let n = &a.trace().nodes;
        [0, 1].iter().all(|&i| n.iter().any(|(k, _)| *k == NodeKey::new(i, 2))) && a.source().buses.len() == 2
    });
    assert_eq!(a.trace().ifaces.names(), ["demo", "demo2"]);
    let bar = status_bar(&s);
    for bus in ["demo", "demo2"] {
        let field = bar.split(" | ").find(|f| f.starts_with(&format!("{bus} ")));
        let field = field.unwrap_or_else(|| panic!("no field for {bus}: {bar}"));
        // `demo 1.2% capturing`: the load over the last second, then the state.
        let words: Vec<&str> = field.split(' ').collect();
        assert_eq!(words.len(), 3, "{field}");
        assert!(
            words[1].ends_with('%') && words[1].trim_end_matches('%').parse::<f64>().is_ok(),
            "{field}"
        );
        assert_eq!(words[2], "capturing", "{bar}");
    }
    // The Stats pane names each bus's load in its title.
    a.key(KeyEvent::new(KeyCode::Char('4'), KeyModifiers::NONE));
    let s = until(&mut a, "the Stats pane", |_, s| s.contains("Receive list by"));
    let title = s.lines().find(|l| l.contains("Receive list by")).unwrap();
    assert!(
        title.contains("bus load demo ") && title.contains(", demo2 "),
        "{title}"
    );
}

/// Enter on a Nodes row filters that node on its own interface: on a log of two buses,
/// each with a node 5, can1's node 5 shows its three frames and none of can0's.
#[test]
fn enter_on_a_node_of_one_bus_filters_that_node_on_that_bus_only() {
    let dir = std::env::temp_dir().join(format!("cotui-enter-node-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("two.log");
    std::fs::write(
        &log,
        "(1700000000.000000) can0 705#05\n\
         (1700000000.100000) can1 705#7F\n\
         (1700000000.200000) can0 706#05\n\
         (1700000000.300000) can1 605#4000100000000000\n\
         (1700000000.400000) can1 585#4300100092010200\n\
         (1700000000.500000) can0 705#05\n",
    )
    .unwrap();
    let (name, rx) = cotui::cli::open_logs::open(&[log], false, None).unwrap();
    let trace = Trace::new(Decoder::new(Default::default(), Vec::new()), 500_000);
    let mut a = App::new(
        trace,
        Keymap::default_map(),
        SourceInfo::new(&name, SourceKind::Open, rx, None),
    );
    until(&mut a, "the six frames", |a, _| a.trace().len() == 6);
    let key = |a: &mut App, c: KeyCode| a.key(KeyEvent::new(c, KeyModifiers::NONE));
    key(&mut a, KeyCode::Char('2'));
    // Rows by interface, then node-ID: can0 5, can0 6, can1 5.
    key(&mut a, KeyCode::Down);
    key(&mut a, KeyCode::Down);
    key(&mut a, KeyCode::Enter);
    until(&mut a, "the filtered view", |a, s| {
        a.screen().view().scanned() == 6 && s.contains("iface can1 and node 5")
    });
    let shown: Vec<(u16, u32)> = a
        .screen()
        .view()
        .positions()
        .iter()
        .map(|&p| {
            let f = a.trace().store.frame(p as usize);
            (f.iface, f.id)
        })
        .collect();
    let can1 = a.trace().ifaces.find("can1").unwrap();
    assert_eq!(shown, [(can1, 0x705), (can1, 0x605), (can1, 0x585)]);
    std::fs::remove_dir_all(&dir).ok();
}
