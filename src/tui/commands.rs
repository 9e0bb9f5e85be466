//! The palette's built-in commands (those that are not commander lines: `goto`, `time`,
//! `speed`, `plot`, `export`, `record`, `stop`, `jobs`, `sim`, ...): their names, how they
//! run on the capture and the screen, and why they fail.

use super::capture::{Capture, SourceKind};
use super::event::{Event, Queue};
use super::keymap::Action;
use super::live::Request;
use super::messages::Level;
use super::palette::commander_words;
use super::panes::plot::PlotMode;
use super::panes::trace_time::TimeMode;
use super::screen::Screen;
use super::source::Control;
use super::{export, record};
use crate::analysis::trace::Trace;
use crate::command::Command;

/// Names the palette completes.
pub const PALETTE_COMMANDS: &[&str] = &[
    "filter",
    "search",
    "goto",
    "time",
    "speed",
    "pause",
    "resume",
    "rewind",
    "loop",
    "plot",
    "export",
    "help",
    "messages",
    "quit",
    "jobs",
    "sim",
    "trigger",
    "bookmarks",
    "expect",
];

/// Why a built-in palette command (`goto`, `time`, `speed`, `plot`, `export`, ...) failed;
/// the text is what the status bar shows.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// `goto` without a frame number.
    #[error("goto: `{0}` is not a frame number")]
    NotAFrame(String),
    /// `time` without seconds or a time mode.
    #[error("time: `{0}` is not seconds nor a time mode (start, absolute, delta, delta-id, mark)")]
    NotSeconds(String),
    /// `speed` without a factor.
    #[error("speed: `{0}` is not a factor from 0.01 to 1000 (0 = as fast as possible)")]
    NotAFactor(String),
    /// A replay command on a source that is not a replay.
    #[error("{0}: only a replay can do that")]
    NoReplay(&'static str),
    /// `speed` on a source that is not a replay.
    #[error("speed: only a replay has a speed")]
    NoSpeed,
    /// `plot` without a node and an object.
    #[error("plot: usage `plot NODE INDEX[:SUB]` (e.g. `plot 1 6064:00`) or `plot mode MODE`")]
    PlotUsage,
    /// `plot mode` without a mode.
    #[error("plot: usage `plot mode lanes|normalised|shared|range LO HI` (LO < HI)")]
    PlotModeUsage,
    /// `plot` with a bad node-ID.
    #[error("plot: `{0}` is not a node-ID")]
    NotANode(String),
    /// `plot` with a bad index.
    #[error("plot: bad index `{0}`")]
    BadIndex(String),
    /// `plot` with a bad sub-index.
    #[error("plot: bad sub-index `{0}`")]
    BadSub(String),
    /// `plot` of an object with no numeric value seen.
    #[error("plot: no numeric values of node {node} 0x{index:04X}:{sub:02X} seen")]
    NoSeries { node: u8, index: u16, sub: u8 },
    /// `export` failed (its words, or writing the file).
    #[error(transparent)]
    Export(#[from] super::export::ExportError),
    /// A word that is no command.
    #[error("unknown command `{0}` (commands: {palette} {commander})", palette = PALETTE_COMMANDS.join(" "), commander = commander_words().join(" "))]
    Unknown(String),
}

/// What to add to an export error: how to overwrite an existing file.
/// What [`run`] made of a palette line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ran {
    /// A built-in command (or an unknown word): done, its result on the status line.
    Done,
    /// A commander line (`sdo`, `nmt`, `drive`, ...): for the commander to plan and send.
    Commander,
}

/// Runs a built-in palette command (`goto`, `time`, `speed`, `plot`, `export`, `record`,
/// `stop`, `jobs`, `sim`, ...) on the two sides of the application; what the rest must do
/// (follow, quit, stop-all, the loop key) goes to `q`, the result to the status line.
pub(crate) fn run(line: &str, capture: &mut Capture, screen: &mut Screen, q: &mut Queue) -> Ran {
    let (cmd, rest) = line.split_once(' ').unwrap_or((line, ""));
    let rest = rest.trim();
    let result: Result<String, CommandError> = match cmd {
        "" => Ok(String::new()),
        "filter" => {
            let _ = screen.apply_filter(capture.trace(), rest);
            return Ran::Done;
        }
        "search" => {
            let _ = screen.apply_search(capture.trace(), rest);
            return Ran::Done;
        }
        "goto" => rest
            .parse::<usize>()
            .map_err(|_| CommandError::NotAFrame(rest.to_string()))
            .map(|n| {
                if !capture.replay_control(Control::GotoFrame(n as u64), q) {
                    screen.select_position(capture.trace(), n.saturating_sub(1));
                }
                format!("frame {n}")
            }),
        "time" if TimeMode::from_name(rest).is_some() || rest.is_empty() => {
            let mode = TimeMode::from_name(rest).unwrap_or_else(|| screen.time_mode().next());
            screen.set_time_mode(mode);
            Ok(format!("time column: {}", mode.name()))
        }
        "time" => rest
            .parse::<f64>()
            .map_err(|_| CommandError::NotSeconds(rest.to_string()))
            .map(|s| {
                let at = (s.max(0.0) * 1e9) as u64;
                if !capture.replay_control(Control::GotoTime(at), q) {
                    let trace = capture.trace();
                    let pos = trace.store.position_at(super::panes::start_ns(trace) + at);
                    screen.select_position(trace, pos);
                }
                format!("t = {s} s")
            }),
        "rewind" if capture.replay_control(Control::Rewind, q) => Ok("rewind".into()),
        "rewind" => Err(CommandError::NoReplay("rewind")),
        "speed" => match rest.parse::<f64>() {
            Ok(x) if super::source::valid_speed(x) => capture.set_speed(x).ok_or(CommandError::NoSpeed),
            _ => Err(CommandError::NotAFactor(rest.to_string())),
        },
        "pause" | "resume" => {
            capture.set_paused(cmd == "pause", q);
            Ok(String::new())
        }
        "plot" => plot(rest, capture.trace(), screen),
        "help" => {
            screen.show_help();
            Ok(String::new())
        }
        "export" if rest.starts_with("plot") && rest.split_whitespace().next() == Some("plot") => {
            super::export_plot::command(rest.trim_start_matches("plot"), capture.trace(), screen.panes().plot())
                .map_err(CommandError::from)
                .inspect(|text| screen.log(Level::Info, text))
        }
        "export" if rest.split_whitespace().next() == Some("watch") => {
            super::watch::export(rest.trim_start_matches("watch"), screen.panes().watch())
                .map_err(CommandError::from)
                .inspect(|text| screen.log(Level::Info, text))
        }
        "export" => export::command(rest, capture.trace(), screen.view())
            .map_err(CommandError::from)
            .inspect(|text| screen.log(Level::Info, text)),
        "messages" => {
            screen.log_popup_mut().open();
            Ok(String::new())
        }
        "loop" => {
            q.push(Event::Act(Action::Loop));
            return Ran::Done;
        }
        "quit" => {
            q.push(Event::Quit);
            return Ran::Done;
        }
        "jobs" => {
            jobs(rest, capture, q);
            return Ran::Done;
        }
        "trigger" => {
            match screen.apply_trigger(capture.trace(), rest) {
                Ok(text) => screen.set_message(Some(text)),
                Err(e) => {
                    screen.log(Level::Error, &e);
                    screen.set_message(Some(e));
                }
            }
            return Ran::Done;
        }
        "expect" => {
            match capture.expect(rest) {
                Ok((text, warnings)) => {
                    for w in &warnings {
                        screen.log(Level::Warn, &format!("expect: {w}"));
                    }
                    screen.log(Level::Info, &text);
                    screen.set_message(Some(text));
                }
                Err(e) => {
                    screen.log(Level::Error, &e);
                    screen.set_message(Some(e));
                }
            }
            return Ran::Done;
        }
        "bookmarks" => {
            let lines = screen.bookmark_lines(capture.trace());
            if lines.is_empty() {
                Ok("no bookmarks (the bookmark key sets one on the selected frame)".into())
            } else {
                for l in &lines {
                    screen.log(Level::Info, &format!("bookmark {l}"));
                }
                screen.log_popup_mut().open();
                Ok(format!("{} bookmarks: {}", lines.len(), lines.join(", ")))
            }
        }
        "record" => {
            let gate = screen
                .trigger()
                .filter(|_| rest.starts_with("start"))
                .map(|t| record::Gate::new(&t.trigger, t.pre_ms, t.post_ms, capture.trace().decoder()));
            record::command(capture.has_bus(), capture.recording_mut(), rest, gate, q);
            return Ran::Done;
        }
        "sim" => {
            sim(line, rest, capture, q);
            return Ran::Done;
        }
        "stop" => {
            match crate::command::parse_command(line) {
                Ok(Command::Stop(s)) => q.push(Event::StopAll(s.nodes, s.options)),
                Ok(_) => {}
                Err(e) => q.push(Event::Say(Level::Error, format!("stop: {e}"))),
            }
            return Ran::Done;
        }
        w if commander_words().contains(&w) => return Ran::Commander,
        other => Err(CommandError::Unknown(other.to_string())),
    };
    let message = match result {
        Ok(s) if s.is_empty() => None,
        Ok(s) => Some(s),
        Err(e) => {
            screen.log(Level::Error, &format!("{line}: {e}"));
            Some(e.to_string())
        }
    };
    screen.set_message(message);
    Ran::Done
}

/// `plot NODE INDEX[:SUB]`: shows that series in the Plot pane; `plot mode
/// lanes|normalised|shared|range LO HI`: lays out its y axes.
fn plot(rest: &str, trace: &Trace, screen: &mut Screen) -> Result<String, CommandError> {
    if let Some(words) = rest.strip_prefix("mode") {
        let mode = PlotMode::parse(words).ok_or(CommandError::PlotModeUsage)?;
        screen.set_plot_mode(mode);
        return Ok(format!("plot: {}", mode.name()));
    }
    let mut it = rest.split_whitespace();
    let (Some(node), Some(obj)) = (it.next(), it.next()) else {
        return Err(CommandError::PlotUsage);
    };
    let node: u8 = node.parse().map_err(|_| CommandError::NotANode(node.to_string()))?;
    let (i, s) = obj.split_once(':').unwrap_or((obj, "0"));
    let index =
        u16::from_str_radix(i.trim_start_matches("0x"), 16).map_err(|_| CommandError::BadIndex(i.to_string()))?;
    let sub = u8::from_str_radix(s, 16).map_err(|_| CommandError::BadSub(s.to_string()))?;
    if screen.plot(trace, node, index, sub) {
        Ok(String::new())
    } else {
        Err(CommandError::NoSeries { node, index, sub })
    }
}

/// `jobs` (list the running palette commands) or `jobs stop ID`: asks the live task.
fn jobs(rest: &str, capture: &Capture, q: &mut Queue) {
    let request = match rest.split_whitespace().collect::<Vec<_>>()[..] {
        [] => Request::ListJobs,
        ["stop", id] if id.parse::<u32>().is_ok() => Request::StopJob(id.parse().unwrap_or(0)),
        _ => return q.push(Event::Say(Level::Error, "jobs: use `jobs` or `jobs stop ID`".into())),
    };
    if !capture.request(request) {
        q.push(Event::Say(
            Level::Info,
            "jobs: this source has no bus, nothing runs".into(),
        ));
    }
}

/// `sim fault NODE CODE`, `sim silence NODE`, `sim reboot NODE`, ... on the demo's
/// simulated drives (the words of `cotui sim`'s stdin): asks the live task.
fn sim(line: &str, rest: &str, capture: &Capture, q: &mut Queue) {
    let control = match crate::sim::control::Control::parse(rest) {
        Ok(c) => c,
        Err(e) => return q.push(Event::Say(Level::Error, format!("sim: {e}"))),
    };
    let demo = matches!(capture.source().kind, SourceKind::Demo { .. });
    let request = Request::Sim {
        line: line.to_string(),
        control,
    };
    if !(demo && capture.request(request)) {
        q.push(Event::Say(
            Level::Error,
            "sim: only the demo's drives are simulated (`cotui demo`)".into(),
        ));
    }
}
