//! The command line: clap definitions and one module per subcommand.

pub mod bind;
pub mod bus_run;
pub mod commander;
pub mod decode;
pub mod decode_args;
mod decode_filter;
mod decode_out;
mod decode_parquet;
mod decode_records;
mod decode_sync;
pub mod diagnose;
pub mod explain;
pub mod gateway;
pub mod host;
pub mod input;
mod merge;
pub mod open_logs;
pub mod record;
pub mod serve;
pub mod sim;
pub mod trigger;
pub mod trigger_live;
pub mod tui;

use crate::command::{CommandError, ExitCode, ParseError};
use clap::{Parser, Subcommand};

/// cotui: a terminal CANopen bus analyzer and commander.
#[derive(Parser, Debug)]
#[command(name = "cotui", version, about, long_about = None, arg_required_else_help = false)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Print every warning (by default, one line per kind with a count).
    #[arg(long, global = true)]
    pub verbose: bool,
}

/// Set from `--verbose` at start.
static VERBOSE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// True when `--verbose` was given.
pub fn verbose() -> bool {
    VERBOSE.load(std::sync::atomic::Ordering::Relaxed)
}

/// The subcommands. Each one's arguments are declared when it is parsed or its help is
/// shown (`defer`): a command line pays only for its own subcommand.
#[derive(Subcommand, Debug)]
#[command(defer = true)]
pub enum Command {
    /// Decode candump / ASC logs to text, JSON lines, SDO transactions, a summary or pcapng.
    Decode(decode_args::DecodeArgs),
    /// What went wrong on the bus, in plain words: incidents with cause, timeline and what to check.
    Diagnose(diagnose::DiagnoseArgs),
    /// Explain frames: identifier split, CANopen meaning, data bits by field, and the frame
    /// on the wire (stuff bits, CRC, bits and time at the bit rate).
    Explain(explain::ExplainArgs),
    /// Print throughput and memory figures of the decoder on a generated log.
    Bench(crate::bench::BenchArgs),
    /// Open a log in the interactive analyzer (loads at once; browse, filter, search).
    Open(tui::OpenArgs),
    /// Replay a log in the interactive analyzer, paced by its timestamps.
    Replay(tui::ReplayArgs),
    /// Capture a SocketCAN interface in the interactive analyzer, with the command palette.
    Live(tui::LiveArgs),
    /// The interactive analyzer on an in-process bus with simulated CiA 402 drives.
    Demo(tui::DemoArgs),
    /// The commander: nmt, sdo, drive, run, scan, record, stop, lss (see docs/COMMANDER.md).
    #[command(flatten)]
    Commander(commander::CliCommander),
    /// Simulated CiA 402 drives on a SocketCAN interface for other tools to talk to (SDO,
    /// NMT, PDO, SYNC, EMCY, LSS); stdin lines make them fail: fault/silence/reboot NODE.
    Sim(sim::SimArgs),
    /// A CiA 309-3 ASCII gateway (CANopenNode canopend's commands and answers) on stdio, a
    /// Unix socket or TCP, for scripts: `[1] 2 read 0x1017 0 u16`. Read-only unless
    /// --allow-writes.
    Gateway(gateway::GatewayArgs),
    /// Serve a bus (SocketCAN, `demo`) over the socketcand protocol to python-can, SavvyCAN
    /// or `cotui ... socketcand://HOST:PORT/IFACE` on other machines; loopback and receive-only
    /// unless --bind and --allow-send.
    Serve(serve::ServeArgs),
}

/// Short usage printed by `cotui` without arguments.
pub const USAGE: &str = "\
cotui: a terminal CANopen bus analyzer and commander

Try it without hardware:   cotui demo
Browse a log:              cotui open FILE
Replay a log:              cotui replay FILE [--speed 2]
Decode a candump log:      cotui decode FILE [--format jsonl] [--transactions] [--summary]
What went wrong:           cotui diagnose FILE [--format jsonl] [--check]
A frame bit by bit:        cotui explain 185#2500EA00 [--bitrate 250k]
All commands:              cotui --help
";

/// Runs the command line and returns the process exit status.
pub fn run() -> ExitCode {
    use clap::FromArgMatches;
    // The help texts' examples are rewritten (`cli_command`) only when clap has something
    // to show: a command line that parses never prints them.
    let mut plain = <Cli as clap::CommandFactory>::command();
    let parsed = plain.try_get_matches_from_mut(std::env::args_os());
    // The declaration is not looked at again: freeing its thousand allocations would cost
    // a tenth of a short decode's start-up, the process's exit frees them at no cost.
    std::mem::forget(plain);
    let cli = match parsed.and_then(|m| Cli::from_arg_matches(&m)) {
        Ok(c) => c,
        Err(_) => match cli_command().try_get_matches().and_then(|m| Cli::from_arg_matches(&m)) {
            Ok(c) => c,
            Err(e) => return refused(e, std::env::args_os().skip(1)),
        },
    };
    VERBOSE.store(cli.verbose, std::sync::atomic::Ordering::Relaxed);
    match cli.command {
        None => {
            print!("{USAGE}");
            ExitCode::Ok
        }
        Some(Command::Decode(args)) if args.trigger.is_some() => trigger::run_decode(&args),
        Some(Command::Decode(args)) => decode::run(&args),
        Some(Command::Diagnose(args)) => diagnose::run(&args),
        Some(Command::Explain(args)) => explain::run(&args),
        Some(Command::Bench(args)) => crate::bench::run(&args),
        Some(Command::Open(args)) => tui::run_open(&args),
        Some(Command::Replay(args)) => tui::run_replay(&args),
        Some(Command::Live(args)) => tui::run_live(&args),
        Some(Command::Demo(args)) => tui::run_demo(&args),
        Some(Command::Sim(args)) => sim::run_sim(&args),
        Some(Command::Gateway(args)) => gateway::run_gateway(&args),
        Some(Command::Serve(args)) => serve::run_serve(&args),
        Some(Command::Commander(c)) => commander::run_commander(&c),
    }
}

/// Prints why the command line was refused (or the help it asked for) and gives the exit
/// status. With `--json` among the `args` a refusal is also one JSON object on stdout, as
/// every other failure of a command that takes `--json`.
pub fn refused(e: clap::Error, args: impl IntoIterator<Item = std::ffi::OsString>) -> ExitCode {
    let _ = e.print();
    if !e.use_stderr() {
        return ExitCode::Ok;
    }
    let args: Vec<String> = args.into_iter().map(|a| a.to_string_lossy().into_owned()).collect();
    if let Some(h) = hint(&args, e.kind()) {
        eprintln!("hint: {h}");
    }
    if args.iter().take_while(|a| *a != "--").any(|a| a == "--json") {
        println!("{}", CommandError::Syntax(ParseError::from(e)).to_json());
    }
    ExitCode::Usage
}

/// The command line's declaration, with the commander examples in its help as the command
/// line takes them: the declaration is the palette's too, whose lines have no IFACE
/// (`sdo read 2 0x6041`); here IFACE goes in (`sdo read can0 2 0x6041`).
pub fn cli_command() -> clap::Command {
    fn with_iface(cmd: clap::Command, path: &str) -> clap::Command {
        let example = format!("`{path} ");
        let fix = |t: &clap::builder::StyledStr| t.to_string().replace(&example, &format!("`{path} can0 "));
        let (about, long) = (cmd.get_about().map(fix), cmd.get_long_about().map(fix));
        let mut cmd = cmd;
        if let Some(a) = about {
            cmd = cmd.about(a);
        }
        if let Some(a) = long {
            cmd = cmd.long_about(a);
        }
        let subs: Vec<String> = cmd.get_subcommands().map(|s| s.get_name().to_string()).collect();
        for sub in subs {
            let path = format!("{path} {sub}");
            cmd = cmd.mut_subcommand(&sub, |c| with_iface(c, &path));
        }
        cmd
    }
    let mut cmd = crate::command::syntax::declared(<Cli as clap::CommandFactory>::command());
    for sub in ON_A_BUS {
        if cmd.find_subcommand(sub).is_some() {
            cmd = cmd.mut_subcommand(sub, |c| with_iface(c, sub));
        }
    }
    cmd
}

/// The subcommands whose first word is IFACE (after the action word of `sdo` and `dcf`).
const ON_A_BUS: [&str; 12] = [
    "nmt", "sdo", "drive", "run", "scan", "record", "stop", "lss", "send", "sync", "pdo", "dcf",
];

/// A hint for a refused command line (`args` without the program name), for the mistakes
/// clap cannot name: a commander line without IFACE (`sdo read 2 0x6041`: the node where
/// IFACE goes), an object name with blanks not in quotes (`sdo write can0 2 Target velocity
/// 3000`).
fn hint(args: &[String], kind: clap::error::ErrorKind) -> Option<String> {
    let words: Vec<&str> = args
        .iter()
        .map(String::as_str)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let sub = *words.first()?;
    if !ON_A_BUS.contains(&sub) {
        return None;
    }
    let action = matches!(sub, "sdo" | "dcf");
    let at = if action { 2 } else { 1 };
    let iface = words.get(at)?;
    if crate::command::grammar::parse_int(iface).is_some() {
        // The user's line with `can0` where IFACE goes (before the at-th word).
        let pos = args.iter().position(|a| std::ptr::eq(a.as_str(), *iface))?;
        let mut line: Vec<String> = args
            .iter()
            .map(|a| if a.contains(' ') { format!("\"{a}\"") } else { a.clone() })
            .collect();
        line.insert(pos, "can0".into());
        return Some(format!(
            "did you forget IFACE? It comes first: `cotui {}` (or `demo` for the simulated bus)",
            line.join(" ")
        ));
    }
    if sub == "sdo" && kind == clap::error::ErrorKind::UnknownArgument && words.len() > 5 {
        let (object, value) = match words[1] {
            "write" => (
                words[4..words.len() - 1].join(" "),
                format!(" {}", words[words.len() - 1]),
            ),
            _ => (words[4..].join(" "), String::new()),
        };
        return Some(format!(
            "an object name with blanks goes in quotes: `cotui sdo {} {iface} {} \"{object}\"{value}`",
            words[1], words[3]
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_declaration_is_consistent() {
        // Duplicate names, flags or argument groups (e.g. from flattening the commander's
        // declaration) would only panic when that subcommand is parsed.
        Cli::command().debug_assert();
    }

    /// Every (sub)command's `--help`, with its path (`cotui sdo read`).
    fn every_help(cmd: &mut clap::Command, path: &str, out: &mut Vec<(String, String)>) {
        out.push((path.to_string(), cmd.render_long_help().to_string()));
        for sub in cmd.get_subcommands_mut() {
            let name = format!("{path} {}", sub.get_name());
            every_help(sub, &name, out);
        }
    }

    /// The overview (`cotui --help`) gives each subcommand's own line, not the doc comment
    /// of its arguments' type that declaring a deferred subcommand brings along.
    #[test]
    fn the_overview_lists_each_subcommand_by_its_own_text() {
        let help = cli_command().render_help().to_string();
        assert!(help.contains("decode    Decode candump / ASC logs"), "{help}");
        assert!(help.contains("nmt       "), "{help}");
        for own in ["Arguments of", "A command's own arguments"] {
            assert!(!help.contains(own), "`{own}` in the overview:\n{help}");
        }
        let mut decode = cli_command();
        let decode = decode
            .find_subcommand_mut("decode")
            .unwrap()
            .render_long_help()
            .to_string();
        assert!(decode.starts_with("Decode candump / ASC logs"), "{decode}");
    }

    #[test]
    fn no_help_text_shows_developer_notes() {
        let mut helps = Vec::new();
        every_help(&mut cli_command(), "cotui", &mut helps);
        assert!(helps.len() > 20, "the walk reaches the subcommands");
        let decode = &helps.iter().find(|(p, _)| p == "cotui decode").unwrap().1;
        assert!(
            decode.contains("A pcapng capture for Wireshark"),
            "value docs are checked too: {decode}"
        );
        let internal = [
            "decode_out",
            "decode_parquet",
            "fn ",
            "crate::",
            "::",
            "the matches below",
            "TODO",
            "FIXME",
        ];
        for (path, help) in &helps {
            for word in internal {
                assert!(!help.contains(word), "`{path} --help` shows `{word}`:\n{help}");
            }
            // A backticked identifier with an underscore (`decode_out`, `run_record`) is
            // code, not something a user types.
            for quoted in help.split('`').skip(1).step_by(2) {
                let code = quoted.contains('_')
                    && quoted
                        .chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
                assert!(!code, "`{path} --help` quotes the identifier `{quoted}`:\n{help}");
            }
        }
    }

    #[test]
    fn hints_for_a_forgotten_iface_and_an_unquoted_name() {
        let words = |line: &str| line.split(' ').map(String::from).collect::<Vec<_>>();
        let kind = clap::error::ErrorKind::ValueValidation;
        assert_eq!(
            hint(&words("sdo read 2 0x6041"), kind).as_deref(),
            Some(
                "did you forget IFACE? It comes first: `cotui sdo read can0 2 0x6041` (or `demo` for the simulated bus)"
            )
        );
        assert!(
            hint(&words("nmt 2 start"), kind)
                .unwrap()
                .contains("`cotui nmt can0 2 start`")
        );
        assert_eq!(hint(&words("sdo read demo 2 0x6041"), kind), None);
        assert_eq!(hint(&words("decode 2"), kind), None);
        assert_eq!(
            hint(
                &words("sdo write demo 2 Target velocity 3000"),
                clap::error::ErrorKind::UnknownArgument
            )
            .as_deref(),
            Some("an object name with blanks goes in quotes: `cotui sdo write demo 2 \"Target velocity\" 3000`")
        );
    }

    #[test]
    fn a_refused_line_gives_exit_status_1_and_help_0() {
        let refused_with = |args: &[&str]| {
            let e = Cli::try_parse_from(args).unwrap_err();
            refused(e, args.iter().map(std::ffi::OsString::from))
        };
        assert_eq!(
            refused_with(&["cotui", "nmt", "demo", "start", "2", "--block", "--json"]),
            ExitCode::Usage
        );
        assert_eq!(refused_with(&["cotui", "nmt", "--help"]), ExitCode::Ok);
    }
}
