//! One command language: the palette and the command line parse the same declaration, so
//! the same line gives the same command or the same error in both; `--json` failures are
//! one JSON object; the palette's preview is the frame the SDO client really sends.

use crate::run::cotui;
use clap::Parser;
use cotui::bus::Event;
use cotui::cli::{Cli, Command as CliCommand};
use cotui::command::{Command, ParseError, parse_command};
use cotui::frame::Direction;
use cotui::od::bind::Bindings;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;

/// The command line's result for a palette line: IFACE after the command word(s).
fn cli(line: &str) -> Result<Command, String> {
    let words = shlex::split(line).ok_or("unterminated quote")?;
    let at = if words.first().map(String::as_str) == Some("sdo") {
        2
    } else {
        1
    };
    let mut argv = vec!["cotui".to_string()];
    argv.extend(words.iter().take(at).cloned());
    argv.push("demo".into());
    argv.extend(words.iter().skip(at).cloned());
    match Cli::try_parse_from(&argv) {
        Ok(Cli {
            command: Some(CliCommand::Commander(c)),
            ..
        }) => c.command().map_err(|e| e.to_string()),
        Ok(other) => panic!("{line}: not a commander command: {other:?}"),
        Err(e) => Err(ParseError::from(e).to_string()),
    }
}

fn palette(line: &str) -> Result<Command, String> {
    parse_command(line).map_err(|e| e.to_string())
}

#[test]
fn the_palette_and_the_command_line_give_the_same_command_or_the_same_error() {
    let good = [
        "nmt start 2",
        "nmt reset-node 0 --wait --timeout 500",
        "nmt pre-op 0x7F",
        "sdo read 2 0x6041",
        "sdo read 2 0x1018:1 --block --timeout 300 --deadline 60000 -o out.bin",
        "sdo read 3 \"Manufacturer device name\"",
        "sdo write 2 0x6060 3 --type i8",
        "sdo write 2 0x6060 3 --type i8 --block",
        "sdo write 2 0x60FF -100 -t i32",
        "sdo write 2 0x1008 \"my drive\" --type string",
        "drive 2 enable",
        "drive 3 mode csv --timeout 200",
        "drive 2 quickstop",
        "run 2 pv speed=100 accel=0x10 --dry-run",
        "run 3 --list",
        "run 3",
        "scan --probe --listen 500",
        "record -o out.log --append --count 5 --format pcapng",
        "stop",
        "stop 2 3 --ramp 300",
        "stop --node 2 --node 4 --listen 100",
        "lss switch global config",
        "lss select 0x3A 0x1234 2 0x99",
        "lss set-bitrate 250 --timeout 50",
        "lss inquire",
        "lss fastscan --vendor 0x3A --product 0x1234",
        "lss assign 10 --store",
        "lss assign 12 --vendor 0 --product 0x04020001",
    ];
    for line in good {
        let (p, c) = (palette(line), cli(line));
        assert!(p.is_ok(), "{line}: {p:?}");
        assert_eq!(p, c, "{line}");
    }
    let bad = [
        // Flags a command does not take.
        ("nmt start 2 --block", "unexpected argument '--block' found"),
        ("scan --wait", "unexpected argument '--wait' found"),
        ("sdo read 2 0x6041 --bogus", "unexpected argument '--bogus' found"),
        // Extra words.
        ("drive 2 enable extra", "`drive enable` takes no MODE (got `extra`)"),
        ("nmt start 2 3", "unexpected argument '3' found"),
        ("sdo read 2 0x6041 5", "unexpected argument '5' found"),
        ("scan now", "unexpected argument 'now' found"),
        // Missing words.
        (
            "nmt start",
            "the following required arguments were not provided: <NODE>",
        ),
        (
            "sdo write 2 0x6060",
            "the following required arguments were not provided: <VALUE>",
        ),
        ("drive 2 mode", "drive mode needs a MODE (e.g. pv, csp, 3)"),
        (
            "record",
            "the following required arguments were not provided: --output <OUTPUT>",
        ),
        // Bad numbers and words.
        (
            "sdo read 0 0x6041",
            "invalid value '0' for '<NODE>': node `0` must be a number 1..127 (decimal or 0x hex)",
        ),
        (
            "nmt start 128",
            "invalid value '128' for '<NODE>': node `128` must be a number 0..127 (decimal or 0x hex)",
        ),
        (
            "sdo read 2 0x6041 --timeout 0",
            "invalid value '0' for '--timeout <TIMEOUT>': `0` is not a duration above 0: a number of ms, or a number with a unit (500ms, 30s, 1.5s, 2min, 1h)",
        ),
        (
            "scan --listen soon",
            "invalid value 'soon' for '--listen <LISTEN>': `soon` is not a duration above 0: a number of ms, or a number with a unit (500ms, 30s, 1.5s, 2min, 1h)",
        ),
        (
            "nmt go 2",
            "invalid value 'go' for '<ACTION>': unknown NMT command `go`: use start, stop, preop, reset-node or reset-comm",
        ),
        (
            "drive 2 mode warp",
            "unknown mode `warp`: use pp, pv, pt, hm, ip, csp, csv, cst or a number",
        ),
        (
            "sdo read 2 0x6041 --type u7",
            "invalid value 'u7' for '--type <DATA_TYPE>': unknown type `u7`: use u8..u64, i8..i64, f32, f64, bool, string, octets or domain",
        ),
        (
            "record -o x --force --append",
            "the argument '--force' cannot be used with '--append'",
        ),
        (
            "run 2 pv speed",
            "`speed` is not a parameter: write NAME=VALUE, e.g. speed=100",
        ),
        ("run 2 pv --list", "run: give a PROCEDURE or --list, not both"),
        (
            "stop 0",
            "invalid value '0' for '[NODES]...': node `0` must be a number 1..127 (decimal or 0x hex)",
        ),
        (
            "lss set-node 200",
            "invalid value '200' for '<NODE>': node-ID `200` must be 1..127 (or 255 = unconfigured)",
        ),
        ("lss store --vendor 1", "unexpected argument '--vendor' found"),
        (
            "lss select 1 2 3",
            "the following required arguments were not provided: <SERIAL>",
        ),
    ];
    for (line, want) in bad {
        let (p, c) = (palette(line), cli(line));
        assert_eq!(p, Err(want.to_string()), "{line}");
        assert_eq!(c, p, "{line}");
    }
}

#[test]
fn argument_errors_with_json_print_exactly_one_json_object() {
    for (args, message) in [
        (
            &["nmt", "demo", "start", "2", "--block", "--json"][..],
            "unexpected argument '--block' found",
        ),
        (
            &["drive", "demo", "2", "enable", "extra", "--json"][..],
            "`drive enable` takes no MODE (got `extra`)",
        ),
        (
            &["sdo", "read", "demo", "2", "--json"][..],
            "the following required arguments were not provided: <OBJECT>",
        ),
        (
            &["scan", "demo", "--listen", "-5", "--json"][..],
            "unexpected argument '-5' found",
        ),
    ] {
        let (rc, out, err) = cotui(args);
        assert_eq!(rc, 1, "{args:?}: {err}");
        let mut objects = serde_json::Deserializer::from_str(&out).into_iter::<serde_json::Value>();
        let v = objects.next().expect("one JSON object").unwrap();
        assert!(objects.next().is_none(), "{args:?}: more than one object: {out}");
        assert_eq!(v["ok"], false, "{v}");
        assert_eq!(v["error"], "usage", "{v}");
        assert_eq!(v["message"], message, "{v}");
        assert!(!err.is_empty(), "the message also goes to stderr");
    }
    // Without --json the refusal is clap's text on stderr only.
    let (rc, out, err) = cotui(&["nmt", "demo", "start", "2", "--block"]);
    assert_eq!((rc, out.as_str()), (1, ""));
    assert!(err.contains("unexpected argument '--block' found"), "{err}");
}

#[tokio::test(start_paused = true)]
async fn the_preview_of_a_block_write_is_the_frame_the_client_sends() {
    let d = Demo::spawn(Simulation::demo(), false);
    let b = Bindings::new();
    for (line, blocked) in [
        ("sdo write 2 0x6060 3 --type i8 --block", true),
        ("sdo write 2 0x6060 3 --type i8", false),
        (
            "sdo write 3 0x2000 \"01 02 03 04 05 06 07 08 09\" --type octets --block",
            true,
        ),
        ("sdo write 3 0x2000 \"01 02 03 04 05 06 07 08 09\" --type octets", false),
        ("sdo read 2 0x6041 --block", true),
    ] {
        let planned = cotui::tui::palette::plan(line, &b, |_| None).unwrap();
        let mut rx = d.bus.subscribe();
        cotui::command::execute(&d.bus, &planned.command, &b)
            .await
            .unwrap_or_else(|e| panic!("{line}: {e}"));
        let first = loop {
            match rx.next().await.unwrap() {
                Event::Frame(f) if f.direction() == Direction::Tx => break f,
                _ => {}
            }
        };
        let sent = cotui::command::candump(&first);
        assert!(
            planned.preview.starts_with(&sent),
            "{line}: preview {} but sent {sent}",
            planned.preview
        );
        // Block transfers start with command specifier 6 (download) or 5 (upload).
        let ccs = first.payload()[0] >> 5;
        assert_eq!(matches!(ccs, 5 | 6), blocked, "{line}: {sent}");
    }
}
