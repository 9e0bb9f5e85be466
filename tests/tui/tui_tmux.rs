//! End-to-end: the real binary in a tmux pane. `cotui demo` shows the simulated drives
//! reach their states, help opens, a filter narrows the trace, `q` quits and the terminal
//! comes back (the shell after cotui prints and the alternate screen is gone). A replay
//! marks a node LOST while its log is silent (the replay clock); replay step, step back,
//! `:goto`, `:time` (also after the end) and rewind move it as docs/TUI.md says. The
//! demo with chosen drives takes `:sim` failures and `:lss` against its LSS slave. Ctrl-z,
//! SIGTSTP and SIGQUIT give the shell its terminal back; `fg` redraws.
//! Needs tmux (scripts/install-test-deps.sh installs it).

use crate::tmux::Session;
use std::process::Command;

#[test]
fn demo_runs_filters_helps_and_quits_cleanly() {
    let bin = env!("CARGO_BIN_EXE_cotui");
    let home = std::env::temp_dir().join(format!("cotui-e2e-{}", std::process::id()));
    std::fs::create_dir_all(&home).unwrap();
    let cmd = format!(
        "env XDG_CONFIG_HOME={} {bin} demo; echo cotui-exit=$?; sleep 60",
        home.display()
    );
    let s = Session::start(&format!("cotui-e2e-{}", std::process::id()), &cmd);

    // The simulated drives boot and go operational; the status bar counts frames.
    s.wait_for("the nodes to be operational", |t| {
        t.contains("  2 Operational") && t.contains("  3 Operational") && t.contains("demo bus |")
    });

    // Enable drive 2 from the palette: the preview shows the exact frames, then the result.
    s.keys(&[":", "drive 2 enable"]);
    s.wait_for("the frame preview", |t| t.contains("will send: 602#2B40600006000000"));
    s.keys(&["Enter"]);
    s.wait_for("the drive to be enabled", |t| {
        t.contains("node 2: Operation enabled (statusword")
    });
    s.wait_for("the nodes pane to show it", |t| {
        t.contains("2 Operational     Operation enabled")
    });

    // Help opens from the keymap in force and closes again.
    s.keys(&["?"]);
    s.wait_for("help", |t| {
        t.contains("Show or hide this help") && t.contains("ctrl-c, q")
    });
    s.keys(&["Escape"]);
    s.wait_for("help to close", |t| !t.contains("Show or hide this help"));

    // A filter keeps only matching rows and shows in the status bar.
    s.keys(&["/", "kind hb node 3", "Enter"]);
    let t = s.wait_for("the filter", |t| t.contains("filter: kind hb node 3 ("));
    let rows: Vec<&str> = t.lines().filter(|l| l.contains(" 703 ")).collect();
    assert!(!rows.is_empty(), "{t}");
    assert!(!t.contains(" 702 ") && !t.contains(" 080 "), "{t}");

    // Broadcast NMT asks first (and says that the demo's simulated master sent an NMT start
    // in the last 2 s, when the test gets here that soon); `n` cancels.
    s.keys(&[":", "nmt stop 0", "Enter"]);
    s.wait_for("the confirmation", |t| {
        t.contains("broadcast NMT stop to every node") && t.contains("000#0200")
    });
    s.keys(&["n"]);
    s.wait_for("the cancel", |t| t.contains("not sent"));

    // q asks first while drive 2, which cotui enabled, is still powered; y quits and the
    // shell gets its screen back.
    s.keys(&["q"]);
    s.wait_for("the quit confirmation", |t| {
        t.contains("y quit · s stop them first · any other key stays")
            && t.contains("drive(s) 2 that cotui commanded are still powered")
    });
    s.keys(&["y"]);
    let t = s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    assert!(!t.contains("Trace ["), "alternate screen left behind:\n{t}");
    let _ = std::fs::remove_dir_all(&home);
}

#[test]
fn sigterm_restores_the_terminal() {
    let bin = env!("CARGO_BIN_EXE_cotui");
    let name = format!("cotui-term-{}", std::process::id());
    let pidfile = std::env::temp_dir().join(format!("{name}.pid"));
    let cmd = format!(
        "sh -c 'echo $$ > {}; exec {bin} demo'; echo cotui-exit=$?; sleep 60",
        pidfile.display()
    );
    let s = Session::start(&name, &cmd);
    s.wait_for("the demo", |t| t.contains("demo bus |"));
    let pid = std::fs::read_to_string(&pidfile).unwrap();
    assert!(
        Command::new("kill")
            .args(["-TERM", pid.trim()])
            .status()
            .unwrap()
            .success()
    );
    let t = s.wait_for("cotui to stop on SIGTERM", |t| t.contains("cotui-exit="));
    assert!(t.contains("cotui-exit=0"), "{t}");
    assert!(!t.contains("Trace ["), "{t}");
    let _ = std::fs::remove_file(&pidfile);
}

/// Ctrl-z and SIGTSTP give the shell a usable terminal (no alternate screen, no mouse
/// reports) and `fg` brings the screen back, redrawn and reading keys at once; SIGQUIT
/// restores the terminal before cotui exits.
#[test]
fn suspend_resume_and_sigquit_restore_the_terminal() {
    let bin = env!("CARGO_BIN_EXE_cotui");
    let name = format!("cotui-tstp-{}", std::process::id());
    let home = std::env::temp_dir().join(&name);
    std::fs::create_dir_all(&home).unwrap();
    let pidfile = home.join("pid");
    let s = Session::start(&name, "env PS1='shell$ ' bash --norc --noprofile -i");
    s.wait_for("the shell", |t| t.contains("shell$"));
    s.type_text(&format!(
        "sh -c 'echo $$ > {}; exec env XDG_CONFIG_HOME={} {bin} demo'",
        pidfile.display(),
        home.display()
    ));
    s.keys(&["Enter"]);
    s.wait_for("the demo", |t| t.contains("demo bus |"));
    assert_eq!(
        (s.format("#{alternate_on}"), s.format("#{mouse_any_flag}")),
        ("1".into(), "1".into())
    );
    let pid = std::fs::read_to_string(&pidfile).unwrap().trim().to_string();
    let signal = |sig: &str| assert!(Command::new("kill").args([sig, &pid]).status().unwrap().success());
    let shell_back = |what: &str| {
        let t = s.wait_for(what, |t| t.contains("Stopped"));
        assert!(!t.contains("demo bus |"), "alternate screen left behind:\n{t}");
        assert_eq!(
            (s.format("#{alternate_on}"), s.format("#{mouse_any_flag}")),
            ("0".into(), "0".into()),
            "{what}"
        );
    };
    let resumed = |what: &str| {
        s.type_text("clear; fg");
        s.keys(&["Enter"]);
        s.wait_for(what, |t| t.contains("demo bus |") && !t.contains("shell$"));
        assert_eq!(
            (s.format("#{alternate_on}"), s.format("#{mouse_any_flag}")),
            ("1".into(), "1".into())
        );
        // Keys reach cotui one by one again (raw mode), no Enter needed.
        s.keys(&["?"]);
        s.wait_for("help after fg", |t| t.contains("Show or hide this help"));
        s.keys(&["Escape"]);
        s.wait_for("help to close", |t| !t.contains("Show or hide this help"));
    };
    s.keys(&["C-z"]);
    shell_back("the shell after ctrl-z");
    resumed("the screen redrawn after fg");
    signal("-TSTP");
    shell_back("the shell after SIGTSTP");
    resumed("the screen redrawn after the second fg");
    signal("-QUIT");
    s.wait_for("the shell after SIGQUIT", |t| {
        t.contains("shell$") && !t.contains("demo bus |")
    });
    assert_eq!(
        (s.format("#{alternate_on}"), s.format("#{mouse_any_flag}")),
        ("0".into(), "0".into())
    );
    let _ = std::fs::remove_dir_all(&home);
}

#[test]
fn a_missing_interface_shows_its_fix_in_the_status_bar() {
    let bin = env!("CARGO_BIN_EXE_cotui");
    let name = format!("cotui-live-{}", std::process::id());
    let s = Session::start(&name, &format!("{bin} live cotuinosuch0; echo cotui-exit=$?; sleep 60"));
    s.wait_for("the interface error", |t| {
        t.contains("cotuinosuch0: no such CAN interface; fix: ")
    });
    s.keys(&["q"]);
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
}

#[test]
fn a_replay_marks_a_node_lost_while_the_log_is_silent() {
    // Node 5 heartbeats every 100 ms for 1 s, then nothing until one SYNC at 60 s: between
    // the two, only the replay clock can find node 5 lost.
    let bin = env!("CARGO_BIN_EXE_cotui");
    let name = format!("cotui-lost-{}", std::process::id());
    let log = std::env::temp_dir().join(format!("{name}.log"));
    let mut text: String = (0..=10u64)
        .map(|i| {
            let us = i * 100_000;
            format!(
                "({}.{:06}) can0 705#05\n",
                1_700_000_000 + us / 1_000_000,
                us % 1_000_000
            )
        })
        .collect();
    text.push_str("(1700000060.000000) can0 080#\n");
    std::fs::write(&log, text).unwrap();
    let s = Session::start(
        &name,
        &format!("{bin} replay {}; echo cotui-exit=$?; sleep 60", log.display()),
    );
    s.keys(&["2"]);
    let t = s.wait_for("node 5 to be marked lost", |t| t.contains("  5 LOST "));
    assert!(
        t.contains("node 5 heartbeat lost: no heartbeat for 150.0 ms, expected every 100.0 ms"),
        "{t}"
    );
    assert!(t.contains("| 11 frames |"), "{t}");
    s.keys(&["q"]);
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    let _ = std::fs::remove_file(&log);
}

#[test]
fn replay_steps_seeks_and_rewinds_as_documented() {
    // Ten frames 0.1 s apart, then one at 2 s; played so slowly that only the keys move it.
    let bin = env!("CARGO_BIN_EXE_cotui");
    let name = format!("cotui-seek-{}", std::process::id());
    let log = std::env::temp_dir().join(format!("{name}.log"));
    let mut text: String = (0..10u64)
        .map(|i| format!("(1700000000.{:06}) can0 181#{i:02X}\n", i * 100_000))
        .collect();
    text.push_str("(1700000002.000000) can0 181#FF\n");
    std::fs::write(&log, text).unwrap();
    let s = Session::start(
        &name,
        &format!(
            "{bin} replay {} --speed 0.01; echo cotui-exit=$?; sleep 60",
            log.display()
        ),
    );
    s.wait_for("the first frame", |t| t.contains("| 1 frames |"));
    s.keys(&["space", ":", "goto 5", "Enter"]);
    s.wait_for("frame 5", |t| {
        t.contains("replay") && t.contains("45% 0.4 s / 2.0 s ×0.01 (paused) | 5 frames |")
    });
    s.keys(&["."]);
    s.wait_for("one step", |t| {
        t.contains("| 6 frames |") && t.contains("frame 6  t 0.500000 s")
    });
    s.keys(&[","]);
    s.wait_for("one step back", |t| {
        t.contains("| 5 frames |") && t.contains("frame 5  t 0.400000 s")
    });
    s.keys(&[":", "time 10", "Enter"]);
    s.wait_for("the end", |t| {
        t.contains("100% 2.0 s / 2.0 s ×0.01 (end) | 11 frames |")
    });
    // After the end a step back and a seek back work (the end note goes), the rewind
    // shows nothing.
    s.wait_for("the end note", |t| t.contains("replay finished"));
    s.keys(&[","]);
    let t = s.wait_for("a step back from the end", |t| t.contains("| 10 frames |"));
    assert!(!t.contains("replay finished"), "{t}");
    s.keys(&[":", "time 0.25", "Enter"]);
    s.wait_for("0.25 s", |t| {
        t.contains("| 3 frames |") && t.contains("frame 3  t 0.200000 s")
    });
    s.keys(&["r"]);
    s.wait_for("the rewind", |t| {
        t.contains("0% 0.0 s / 2.0 s ×0.01 (paused) | 0 frames |")
    });
    s.keys(&["q"]);
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    let _ = std::fs::remove_file(&log);
}

/// `cotui demo --node` picks the simulated drives (one without node-ID); `:sim` makes them
/// fail (EMCY and Fault, heartbeat lost, boot-up after a reboot) and `:lss` finds and
/// configures the one without node-ID; the message log keeps every answer.
#[test]
fn demo_nodes_sim_words_and_lss_from_the_palette() {
    let bin = env!("CARGO_BIN_EXE_cotui");
    let home = std::env::temp_dir().join(format!("cotui-sim-{}", std::process::id()));
    std::fs::create_dir_all(&home).unwrap();
    let cmd = format!(
        "env XDG_CONFIG_HOME={} {bin} demo --node 2=aimotor --node 5=aqmd2405 --node ff=servo@0x1234; \
         echo cotui-exit=$?; sleep 60",
        home.display()
    );
    let s = Session::start(&format!("cotui-sim-{}", std::process::id()), &cmd);
    s.wait_for("the chosen nodes to be operational", |t| {
        t.contains("  2 Operational") && t.contains("  5 Operational")
    });

    s.keys(&[":", "sim fault 2 0x2310", "Enter"]);
    s.wait_for("the fault", |t| t.contains("node 2: fault 0x2310 (EMCY, then Fault)"));
    s.wait_for("the nodes pane to show it", |t| t.contains("  2 Operational     Fault"));
    s.keys(&[":", "sim silence 5", "Enter"]);
    s.wait_for("node 5 lost", |t| t.contains("  5 LOST"));
    s.keys(&[":", "sim reboot 5", "Enter"]);
    s.wait_for("node 5 back", |t| t.contains("  5 Pre-operational"));
    s.keys(&[":", "sim fault 2", "Enter"]);
    s.wait_for("the usage", |t| {
        t.contains("sim: usage: fault NODE CODE | silence NODE")
    });

    // LSS: fastscan finds the drive without node-ID (it asks first), inquire reads its
    // serial, set-node gives it node 9, in use after a reset communication.
    s.keys(&[":", "lss fastscan", "Enter"]);
    s.wait_for("the confirmation", |t| {
        t.contains("LSS fastscan addresses every LSS slave")
    });
    s.keys(&["y"]);
    s.wait_for("the fastscan result", |t| {
        t.contains(
            "lss fastscan: found a non-configured slave, now in configuration state: vendor 0x00000000 \
             product 0x04020001 revision 0x00010000 serial 0x00001234",
        )
    });
    s.keys(&[":", "lss inquire serial", "Enter"]);
    s.wait_for("the serial", |t| {
        t.contains("lss inquire serial: serial 0x00001234 (4660)")
    });
    s.keys(&[":", "lss set-node 9", "Enter"]);
    s.wait_for("the confirmation", |t| {
        t.contains("LSS set-node addresses every LSS slave")
    });
    s.keys(&["y"]);
    s.wait_for("node-ID 9", |t| t.contains("lss set-node 9: node-ID 9 configured"));
    s.keys(&[":", "nmt reset-comm 0", "Enter"]);
    s.wait_for("the confirmation", |t| t.contains("y send · any other key cancels"));
    s.keys(&["y"]);
    s.wait_for("node 9 on the bus", |t| t.contains("  9 Pre-operational"));

    s.keys(&[":", "messages", "Enter"]);
    let lines = [
        "sim fault 2 0x2310: node 2: fault 0x2310 (EMCY, then Fault)",
        "node 2 EMCY: 0x2310 Continuous over-current",
        "node 5 heartbeat lost",
        "node 5 rebooted: boot-up #2, node seen before; it was lost",
        "lss set-node 9: node-ID 9 configured",
        "node 9 boot-up",
    ];
    // Waits for the whole popup: tmux may show it half drawn first.
    s.wait_for("the message log with every line", |t| {
        t.contains("Messages (") && lines.iter().all(|l| t.contains(l))
    });
    // One key at a time: an escape followed at once by `q` can reach cotui as alt-q.
    s.keys(&["Escape"]);
    s.wait_for("the message log to close", |t| !t.contains("Messages ("));
    s.keys(&["q"]);
    let t = s.wait_for("cotui to exit or ask", |t| {
        t.contains("cotui-exit=") || t.contains("y quit ·")
    });
    if !t.contains("cotui-exit=") {
        s.keys(&["y"]);
    }
    s.wait_for("cotui to exit", |t| t.contains("cotui-exit=0"));
    let _ = std::fs::remove_dir_all(&home);
}
