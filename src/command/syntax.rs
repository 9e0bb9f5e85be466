//! A palette line: the commander's declaration ([`Commander`]) with nothing in front. The
//! command line parses [`Commander`] with its bus options in front (`cotui sdo read IFACE 2
//! 0x6041`, see `crate::cli`); the TUI palette parses the same declaration with nothing in
//! front ([`parse_command`]: `sdo read 2 0x6041`, split like a shell line). So both accept
//! the same lines and refuse the same ones with the same error: unknown flags, extra words,
//! missing words, bad numbers. Completion and the help's syntax list come from it too.

use super::error::ParseError;
use super::grammar::parse_int;
use super::registry::{Command, Commander};
use super::words::Session;
use clap::{CommandFactory, Parser};
use std::sync::OnceLock;

/// The palette's parser: the commander declaration with nothing in front.
#[derive(Parser, Debug)]
#[command(
    name = ":",
    no_binary_name = true,
    disable_help_subcommand = true,
    disable_version_flag = true
)]
struct Palette {
    #[command(subcommand)]
    command: Commander<Session, Session>,
}

/// The palette's clap command, built once.
fn palette() -> &'static clap::Command {
    static CMD: OnceLock<clap::Command> = OnceLock::new();
    CMD.get_or_init(|| declared(Palette::command()))
}

/// `cmd` with its deferred subcommands declared, each keeping its own help text: clap
/// gives a deferred subcommand the doc comment of its arguments' type when it declares
/// them (`Arguments of cotui decode`), over the subcommand's own.
pub fn declared(mut cmd: clap::Command) -> clap::Command {
    use clap::builder::Resettable;
    let texts: Vec<_> = cmd
        .get_subcommands()
        .map(|s| {
            (
                s.get_name().to_string(),
                s.get_about().cloned(),
                s.get_long_about().cloned(),
            )
        })
        .collect();
    cmd.build();
    for (name, about, long_about) in texts {
        let text = |t: Option<clap::builder::StyledStr>| t.map_or(Resettable::Reset, Resettable::Value);
        cmd = cmd.mut_subcommand(name, |s| s.about(text(about)).long_about(text(long_about)));
    }
    cmd
}

/// Parses one palette line (the command line's words without IFACE and its flags), e.g.
/// `sdo read 2 0x6041`, `nmt start 0 --wait`, `sdo write 2 0x6060 3 --type i8`,
/// `drive 2 mode pv`, `run 2 pv speed=100`, `stop 2 3`. Split like a shell line (quotes
/// keep words together: `sdo write 2 0x1008 "my drive" --type string`).
pub fn parse_command(line: &str) -> Result<Command, ParseError> {
    let words = shlex::split(line).ok_or(ParseError::Quote)?;
    if words.is_empty() {
        return Err(ParseError::Empty(commander_words().join(", ")));
    }
    let matches = palette().clone().try_get_matches_from(words)?;
    let parsed = <Palette as clap::FromArgMatches>::from_arg_matches(&matches)?;
    parsed.command.command()
}

/// The first words of the commander commands, from the declaration.
pub fn commander_words() -> Vec<&'static str> {
    palette().get_subcommands().map(clap::Command::get_name).collect()
}

/// The syntax of every commander command as the palette takes it, one line each, from the
/// declaration: `(usage, about)`, e.g. `("sdo read [OPTIONS] <NODE> <OBJECT>", "Read ...")`.
pub fn usages() -> Vec<(String, String)> {
    fn walk(cmd: &clap::Command, path: &str, out: &mut Vec<(String, String)>) {
        for sub in cmd.get_subcommands() {
            let name = format!("{path}{}", sub.get_name()).trim_start().to_string();
            if sub.has_subcommands() {
                walk(sub, &format!("{name} "), out);
                continue;
            }
            let usage = sub.clone().render_usage().to_string();
            // clap says "Usage: : sdo read ..." (the palette's name is `:`).
            let args = usage.split_once(sub.get_name()).map_or("", |(_, rest)| rest.trim());
            let about = sub.get_about().map(ToString::to_string).unwrap_or_default();
            out.push((format!("{name} {args}").trim_end().to_string(), about));
        }
    }
    let mut out = Vec::new();
    walk(palette(), "", &mut out);
    out
}

/// The words that may complete the last (partial) word of `before`, a palette line up to
/// the cursor: subcommands, flags (when the word starts with `-`), the values of the flag
/// before it or of the positional argument it stands for (NMT and drive actions, types),
/// and what `known` offers for nodes, objects, procedures and their parameters
/// ([`super::complete::values`]).
pub fn completions(before: &str, known: &dyn super::complete::Known) -> Vec<String> {
    let split = shlex::split(before).unwrap_or_else(|| before.split_whitespace().map(String::from).collect());
    let mut words: Vec<&str> = split.iter().map(String::as_str).collect();
    let partial = if before.ends_with(char::is_whitespace) || words.is_empty() {
        ""
    } else {
        words.pop().unwrap_or("")
    };
    let mut cmd = palette();
    let mut positional = 0;
    let mut expecting: Option<&clap::Arg> = None;
    let mut node: Option<u8> = None;
    let mut given: Vec<(String, String)> = Vec::new();
    // The positional argument at `i`; past the last, the last when it takes many values.
    let at = |cmd: &'static clap::Command, i: usize| -> Option<&'static clap::Arg> {
        let all: Vec<&clap::Arg> = cmd.get_positionals().collect();
        all.get(i)
            .or(all.last().filter(|a| matches!(a.get_action(), clap::ArgAction::Append)))
            .copied()
    };
    for w in &words {
        if expecting.take().is_some() {
            continue;
        }
        if let Some(sub) = cmd.find_subcommand(w) {
            cmd = sub;
            positional = 0;
        } else if let Some(long) = w.strip_prefix("--") {
            expecting = cmd
                .get_arguments()
                .find(|a| a.get_long() == Some(long))
                .filter(|a| a.get_action().takes_values());
        } else if w.starts_with('-') && w.len() == 2 && parse_int(w).is_none() {
            let short = w.chars().nth(1);
            expecting = cmd
                .get_arguments()
                .find(|a| a.get_short() == short)
                .filter(|a| a.get_action().takes_values());
        } else {
            if let Some(a) = at(cmd, positional) {
                if a.get_id() == "node" {
                    node = parse_int(w).and_then(|n| u8::try_from(n).ok());
                }
                given.push((a.get_id().to_string(), w.to_string()));
            }
            positional += 1;
        }
    }
    if std::ptr::eq(cmd, palette()) && !words.is_empty() {
        return Vec::new();
    }
    let values = |a: &clap::Arg| -> Vec<String> {
        a.get_possible_values()
            .iter()
            .map(|v| v.get_name().to_string())
            .collect()
    };
    if let Some(arg) = expecting {
        return values(arg);
    }
    if partial.starts_with('-') {
        return cmd
            .get_arguments()
            .filter_map(|a| a.get_long())
            .filter(|l| *l != "help")
            .map(|l| format!("--{l}"))
            .collect();
    }
    if cmd.has_subcommands() {
        return cmd.get_subcommands().map(|s| s.get_name().to_string()).collect();
    }
    let Some(arg) = at(cmd, positional) else {
        return Vec::new();
    };
    let listed = values(arg);
    if !listed.is_empty() {
        return listed;
    }
    super::complete::values(arg.get_id().as_str(), node, &given, known).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::DriveAction;
    use crate::command::cyclic::Schedule;
    use crate::command::grammar::{DEFAULT_TIMEOUT_MS, SCAN_TIMEOUT_MS};
    use crate::command::object::{Sdo, SdoOptions, SdoRead, SdoWrite};
    use crate::command::pdo::command::{Pdo, RpdoSend};
    use crate::command::record::{Limits, LogFormat, Record, WriteMode};
    use crate::command::stop::{DEFAULT_LISTEN_MS, Stop, StopOptions};
    use crate::command::words::{DRIVE_WORDS, NMT_WORDS};
    use crate::decode::pdo_config::PdoId;
    use crate::od::DataType;

    /// Completions with nothing known of the bus.
    fn completions_of(before: &str) -> Vec<String> {
        completions(before, &crate::command::complete::Nothing::new())
    }

    #[test]
    fn palette_lines() {
        assert_eq!(
            parse_command("sdo read 2 0x6041").unwrap(),
            Command::Sdo(Sdo::Read(SdoRead {
                node: 2,
                object: "0x6041".into(),
                options: SdoOptions::default(),
                output: None,
            }))
        );
        assert_eq!(
            parse_command("sdo write 0x02 0x1008 \"my drive\" --type string --block --timeout 300").unwrap(),
            Command::Sdo(Sdo::Write(SdoWrite {
                node: 2,
                object: "0x1008".into(),
                value: "my drive".into(),
                options: SdoOptions {
                    data_type: Some(DataType::VisibleString),
                    block: true,
                    timeout_ms: 300,
                    deadline_ms: None
                }
            }))
        );
        assert_eq!(
            parse_command("nmt reset-node 0 --wait").unwrap(),
            Command::Nmt(crate::command::nmt::Nmt {
                action: crate::command::NmtAction::ResetNode,
                node: 0,
                wait: true,
                timeout_ms: crate::command::grammar::NMT_WAIT_MS,
                listen: crate::command::listen_first::Listen { ms: 300, force: false },
            })
        );
        assert_eq!(
            parse_command("drive 3 mode csv").unwrap(),
            Command::Drive(crate::command::drive::Drive {
                node: 3,
                action: DriveAction::Mode(9),
                timeout_ms: DEFAULT_TIMEOUT_MS
            })
        );
        assert_eq!(
            parse_command("sdo write 2 0x60FF -100 --type i32")
                .map(|c| matches!(c, Command::Sdo(Sdo::Write(w)) if w.value == "-100")),
            Ok(true)
        );
        assert_eq!(
            parse_command("scan --probe --listen 500").unwrap(),
            Command::Scan(crate::command::scan::Scan {
                listen_ms: 500,
                probe: true,
                timeout_ms: SCAN_TIMEOUT_MS
            })
        );
        assert_eq!(
            parse_command("record -o out.log").unwrap(),
            Command::Record(Record {
                more: Vec::new(),
                output: "out.log".into(),
                limits: Limits::default(),
                mode: WriteMode::New,
                format: LogFormat::Candump,
                trigger: None,
            })
        );
        assert_eq!(
            parse_command("record -o out.log --append --count 5").unwrap(),
            Command::Record(Record {
                more: Vec::new(),
                output: "out.log".into(),
                limits: Limits {
                    count: Some(5),
                    duration_ms: None
                },
                mode: WriteMode::Append,
                format: LogFormat::Candump,
                trigger: None,
            })
        );
        assert!(matches!(
            parse_command("record --force -o out.log"),
            Ok(Command::Record(Record {
                mode: WriteMode::Overwrite,
                ..
            }))
        ));
        assert!(
            parse_command("record -o x --force --append")
                .unwrap_err()
                .to_string()
                .contains("cannot be used with")
        );
        assert_eq!(
            parse_command("stop 2 --node 3 --ramp 300").unwrap(),
            Command::Stop(Stop {
                nodes: vec![2, 3],
                listen_ms: DEFAULT_LISTEN_MS,
                options: StopOptions {
                    timeout_ms: DEFAULT_TIMEOUT_MS,
                    ramp_ms: 300
                }
            })
        );
    }

    #[test]
    fn errors_say_what_is_wrong() {
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(
            err("sdo read 0 0x6041").contains("node `0` must be a number 1..127 (decimal or 0x hex)"),
            "{}",
            err("sdo read 0 0x6041")
        );
        assert!(err("nmt go 2").contains("unknown NMT command `go`"));
        assert!(err("sdo read 2 0x6041 --type u7").contains("unknown type `u7`"));
        assert!(err("drive 2 fly").contains("unknown drive command"));
        assert!(err("record").contains("--output <OUTPUT>"));
        assert!(err("").starts_with("empty command"));
        assert_eq!(err("nmt start 2 --block"), "unexpected argument '--block' found");
        assert_eq!(
            err("drive 2 enable extra"),
            "`drive enable` takes no MODE (got `extra`)"
        );
        assert!(err("drive 2 mode fly").contains("unknown mode `fly`"));
        assert_eq!(err("drive 2 mode"), "drive mode needs a MODE (e.g. pv, csp, 3)");
        assert_eq!(err("scan extra"), "unexpected argument 'extra' found");
        assert_eq!(parse_command("sdo read 2 \"0x6041"), Err(ParseError::Quote));
        assert_eq!(err("lss fly"), "unrecognized subcommand 'fly'");
        assert_eq!(
            err("lss set-node"),
            "the following required arguments were not provided: <NODE>"
        );
        assert_eq!(err("lss inquire node --store"), "unexpected argument '--store' found");
        assert_eq!(
            err("lss select 1 2 3"),
            "the following required arguments were not provided: <SERIAL>"
        );
    }

    #[test]
    fn lss_lines() {
        use crate::command::lss::{FASTSCAN_TIMEOUT_MS, Inquiry, Lss, LssAction};
        assert_eq!(
            parse_command("lss assign 10 --store").unwrap(),
            Command::Lss(Lss {
                action: LssAction::Assign {
                    node: 10,
                    store: true,
                    vendor: None,
                    product: None
                },
                timeout_ms: FASTSCAN_TIMEOUT_MS
            })
        );
        assert_eq!(
            parse_command("lss inquire serial --timeout 50").unwrap(),
            Command::Lss(Lss {
                action: LssAction::Inquire(Inquiry::Part(crate::lss::Part::Serial)),
                timeout_ms: 50
            })
        );
        assert!(completions_of("lss ").contains(&"fastscan".to_string()));
    }

    #[test]
    fn run_lines() {
        assert_eq!(
            parse_command("run 2 pv speed=100 accel=0x10 --dry-run").unwrap(),
            Command::Run(crate::command::RunSpec {
                node: 2,
                procedure: Some("pv".into()),
                args: vec![("speed".into(), "100".into()), ("accel".into(), "0x10".into())],
                dry_run: true,
                timeout_ms: DEFAULT_TIMEOUT_MS,
            })
        );
        assert!(matches!(
            parse_command("run 3 --list").unwrap(),
            Command::Run(crate::command::RunSpec {
                node: 3,
                procedure: None,
                ..
            })
        ));
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(err("run 2 pv speed").contains("NAME=VALUE"));
        assert!(err("run 2 speed=1").contains("PROCEDURE before"));
        assert!(err("run 2 pv --list").contains("not both"));
    }

    #[test]
    fn cyclic_lines() {
        let every = |every_ms, count| Schedule { every_ms, count };
        assert!(matches!(
            parse_command("send 12345678#DEAD --every 5").unwrap(),
            Command::Send(crate::command::send::Send::Frame { frame, schedule }) if frame.id == 0x1234_5678
                && frame.is_ext() && schedule == every(Some(5), None)
        ));
        assert_eq!(
            parse_command("sync --period 10 --counter 240 --count 3").unwrap(),
            Command::Sync(crate::command::sync::Sync {
                cob_id: 0x080,
                counter: Some(240),
                schedule: every(Some(10), Some(3)),
                listen: crate::command::listen_first::Listen { ms: 300, force: false },
            })
        );
        assert_eq!(
            parse_command("pdo 2 send rpdo1 Controlword=0x0F \"Target velocity=-5\" --count 2").unwrap(),
            Command::Pdo(Pdo::Send(RpdoSend {
                node: 2,
                num: 1,
                assignments: vec![
                    ("Controlword".into(), "0x0F".into()),
                    ("Target velocity".into(), "-5".into())
                ],
                schedule: every(None, Some(2))
            }))
        );
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(err("sync --period 10 --counter 1").contains("counts to 2..240"));
        assert!(
            err("send 601#4G").contains("is not a frame (column"),
            "{}",
            err("send 601#4G")
        );
        assert!(err("pdo 2 send tpdo1").contains("use rpdo1"));
        assert!(err("pdo 2 read rpdo1").contains("use send or map"));
        assert!(err("sync").contains("--period"));
    }

    #[test]
    fn pdo_lines() {
        assert_eq!(
            parse_command("pdo 2 --timeout 300").unwrap(),
            Command::Pdo(Pdo::Read {
                node: 2,
                timeout_ms: 300
            })
        );
        let Command::Pdo(Pdo::Map(m)) = parse_command(
            "pdo 2 map TPDO3 Statusword 0x6064 --type sync:4 --event 100 --inhibit 2.5ms --cob-id 0x12345",
        )
        .unwrap() else {
            panic!("not a map");
        };
        assert_eq!(m.pdo, PdoId { transmit: true, num: 3 });
        assert_eq!(m.objects, ["Statusword", "0x6064"]);
        assert_eq!(
            (m.transmission, m.event_ms, m.inhibit_100us, m.cob_id),
            (Some(4), Some(100), Some(25), Some(0x12345))
        );
        let kind = |t: &str| match parse_command(&format!("pdo 2 map rpdo1 0x6040 --type {t}")) {
            Ok(Command::Pdo(Pdo::Map(m))) => m.transmission,
            _ => None,
        };
        assert_eq!(
            ["acyclic", "sync", "rtr-sync", "rtr", "event-mfr", "event", "0xFE"].map(kind),
            [0, 1, 252, 253, 254, 255, 254].map(Some)
        );
        let inhibit = |t: &str| match parse_command(&format!("pdo 2 map rpdo1 0x6040 --inhibit {t}")) {
            Ok(Command::Pdo(Pdo::Map(m))) => m.inhibit_100us,
            _ => None,
        };
        assert_eq!(["25", "500us", "1ms", "0"].map(inhibit), [25, 5, 10, 0].map(Some));
        let err = |line: &str| parse_command(line).unwrap_err().to_string();
        assert!(err("pdo 2 map rpdo1 0x6040 --type sync:241").contains("not a transmission type"));
        assert!(err("pdo 2 map rpdo1 0x6040 --inhibit 0.05ms").contains("multiples of 0.1 ms"));
        assert!(err("pdo 2 map").contains("needs the PDO"));
        assert!(err("pdo 2 map xpdo1 0x6040").contains("is not a PDO"));
        assert!(err("pdo 2 send rpdo1 Controlword=1 --dry-run").contains("--dry-run does not go with `pdo send`"));
        assert!(err("pdo 2 --event 5").contains("--event does not go with `pdo NODE`"));
        assert!(completions_of("pdo 2 ").contains(&"map".to_string()));
    }

    #[test]
    fn completion_comes_from_the_declaration() {
        assert_eq!(
            commander_words(),
            [
                "nmt", "sdo", "drive", "run", "scan", "record", "stop", "lss", "send", "sync", "pdo", "dcf", "watch"
            ]
        );
        assert_eq!(completions_of("sdo "), ["read", "write"]);
        assert_eq!(completions_of("nmt re"), NMT_WORDS);
        assert_eq!(completions_of("drive 2 "), DRIVE_WORDS);
        assert!(completions_of("sdo write 2 0x6060 3 --t").contains(&"--type".to_string()));
        assert!(completions_of("sdo write 2 0x6060 3 --type ").contains(&"i8".to_string()));
        assert!(!completions_of("nmt start 2 --").contains(&"--block".to_string()));
        assert!(completions_of("filter x").is_empty());
    }
}
