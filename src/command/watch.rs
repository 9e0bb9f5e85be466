//! `watch NODE OBJECT... [NODE OBJECT...] [--every MS] [--duration MS] [--format
//! text|csv|jsonl]`: CANopen Magic's watch list on the command line. Objects are read by
//! SDO upload ([`super::sdo`]) every MS ms, the nodes of a round in parallel and the objects
//! of one node one after the other, so polls never overlap per node; a round still running
//! when the next is due makes that one skipped (never a burst): the round and its period
//! are [`super::watch_poll`]'s, which the TUI's Watch pane runs too. A timeout or an abort shows
//! in that round's row and the rest goes on; an object the node lacks (abort 0x06020000, or
//! 0x06090011 for a sub) is shown as absent once and not polled again. Rows are written as
//! they come ([`super::watch_table`] for the three formats); the report sums each object up.

use super::error::{CommandError, ParseError};
use super::grammar::DEFAULT_TIMEOUT_MS;
use super::sdo::first_upload_frame;
use super::spec::{CommandArgs, Ctx, Known, Outcome, Preview, Spec};
use super::watch_poll::{Schedule, Target, round};
use super::watch_table::{WatchFormat, Watched, csv_header, csv_row, jsonl_rows, text_table};
use super::words::{TypedWords, ms_arg, node_arg};
use crate::od::bind::Bindings;
use crate::od::resolve_object;
use serde::Serialize;
use std::time::Duration;
use tokio::time::Instant;

/// The default poll period, ms.
pub const DEFAULT_EVERY_MS: u64 = 500;

/// `watch NODE OBJECT... [NODE OBJECT...]`.
#[derive(clap::Args, Clone, Debug)]
pub struct WatchArgs<D: clap::Args> {
    /// A node, then the objects to watch on it (0x6041, 0x1018:1, a name of the node's
    /// profile or EDS); another node and its objects may follow: `2 0x6041 0x6064 3 0x6041`.
    /// A word of 1 to 3 decimal digits is a node, anything else an object.
    #[arg(value_name = "NODE OBJECT", num_args = 1.., required = true)]
    pub words: Vec<String>,
    /// Poll every MS ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_EVERY_MS)]
    pub every: u64,
    /// Stop after this many ms (else at Ctrl-C).
    #[arg(long, value_parser = ms_arg)]
    pub duration: Option<u64>,
    /// How rounds are written: text (a table per round), csv (a header naming the objects,
    /// then time and one column per object), jsonl (one object per line).
    #[arg(long, default_value = "text", value_parser = TypedWords::new(&["text", "csv", "jsonl"], WatchFormat::parse))]
    pub format: WatchFormat,
    /// How long to wait for each SDO answer, in ms.
    #[arg(long, value_parser = ms_arg, default_value_t = DEFAULT_TIMEOUT_MS)]
    pub timeout: u64,
    #[command(flatten)]
    pub dict: D,
}

/// A watch list: objects of nodes, polled on a period.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Watch {
    /// (node, object as typed), in the order given.
    pub objects: Vec<(u8, String)>,
    pub every_ms: u64,
    pub duration_ms: Option<u64>,
    pub format: WatchFormat,
    pub timeout_ms: u64,
}

/// True for a word that names a node (1 to 3 decimal digits).
fn is_node_word(w: &str) -> bool {
    (1..=3).contains(&w.len()) && w.bytes().all(|b| b.is_ascii_digit())
}

/// The (node, object) pairs of `NODE OBJECT... [NODE OBJECT...]`.
pub fn targets(words: &[String]) -> Result<Vec<(u8, String)>, ParseError> {
    let mut node = None;
    let mut out = Vec::new();
    for w in words {
        if is_node_word(w) {
            if let Some(n) = node
                && !out.iter().any(|(o, _)| *o == n)
            {
                return Err(ParseError::Invalid(format!(
                    "node {n}: name its objects before the next node"
                )));
            }
            node = Some(node_arg(w)?);
            continue;
        }
        let Some(n) = node else {
            return Err(ParseError::Invalid(format!(
                "`{w}`: give the node first (`watch IFACE 2 {w}`)"
            )));
        };
        out.push((n, w.clone()));
    }
    match node {
        Some(n) if !out.iter().any(|(o, _)| *o == n) => Err(ParseError::Invalid(format!(
            "node {n}: name the objects to watch on it"
        ))),
        _ => Ok(out),
    }
}

impl<D: clap::Args> CommandArgs<D> for WatchArgs<D> {
    type Spec = Watch;
    const NAME: &'static str = "watch";

    fn dict(&self) -> Option<&D> {
        Some(&self.dict)
    }

    fn spec(&self) -> Result<Watch, ParseError> {
        Ok(Watch {
            objects: targets(&self.words)?,
            every_ms: self.every,
            duration_ms: self.duration,
            format: self.format,
            timeout_ms: self.timeout,
        })
    }
}

/// `watch --json`: each object summed up.
#[derive(Debug, Serialize)]
pub struct WatchReport {
    ok: bool,
    every_ms: u64,
    /// Poll rounds run, and those skipped because the previous one was still running.
    rounds: u64,
    skipped: u64,
    objects: Vec<Watched>,
}

impl WatchReport {
    /// One line per object: reads, failures, min/max, absent.
    fn text(&self) -> String {
        let mut lines = vec![format!(
            "watch: {} rounds every {} ms ({} skipped: the round before was still running)",
            self.rounds, self.every_ms, self.skipped
        )];
        for o in &self.objects {
            let state = if o.absent {
                format!("absent ({})", o.last_error.as_deref().unwrap_or(""))
            } else {
                format!(
                    "{} reads, {} failed{}",
                    o.reads,
                    o.failures,
                    o.last_error
                        .as_ref()
                        .map(|e| format!(" (last: {e})"))
                        .unwrap_or_default()
                )
            };
            lines.push(format!("  {}: {state}", o.title()));
        }
        lines.join("\n")
    }
}

impl Watch {
    /// The objects resolved through the node dictionaries.
    pub fn resolve(&self, bindings: &Bindings) -> Result<Vec<Watched>, CommandError> {
        self.objects
            .iter()
            .map(|(node, text)| {
                let dict = bindings.dictionary(*node);
                let (index, sub) =
                    resolve_object(dict, text).map_err(|e| CommandError::Usage(format!("node {node}: {e}")))?;
                Ok(Watched::new(dict, *node, index, sub))
            })
            .collect()
    }
}

/// What a round reads of `objects`: each one not found absent before (None: skipped).
fn targets_of(objects: &[Watched], bindings: &Bindings) -> Vec<Option<Target>> {
    objects
        .iter()
        .map(|o| (!o.absent).then(|| Target::of(o, bindings.dictionary(o.node))))
        .collect()
}

impl Spec for Watch {
    /// The first request of every object, and the period.
    fn preview(&self, known: &Known<'_>) -> Result<Preview, CommandError> {
        let objs = self.resolve(known.bindings)?;
        let frames: Vec<String> = objs
            .iter()
            .map(|o| super::spec::candump(&first_upload_frame(o.node, o.index, o.sub, false)))
            .collect();
        Ok(Preview::sends(format!(
            "{} every {} ms{}",
            frames.join(", "),
            self.every_ms,
            self.duration_ms.map(|d| format!(" for {d} ms")).unwrap_or_default()
        )))
    }

    async fn run(&self, mut ctx: Ctx<'_>) -> Result<Outcome, CommandError> {
        let mut objects = self.resolve(ctx.bindings)?;
        let bus = ctx.bus;
        if bus.is_listen_only() {
            return Err(crate::bus::BusError::ListenOnly.into());
        }
        let mut say = |line: &str| {
            if let Some(l) = ctx.lines.as_mut() {
                l(line);
            }
        };
        if self.format == WatchFormat::Csv {
            say(&csv_header(&objects));
        }
        let start_ns = bus.now_ns();
        let deadline = self.duration_ms.map(|ms| Instant::now() + Duration::from_millis(ms));
        let until = async {
            match deadline {
                Some(d) => tokio::time::sleep_until(d).await,
                None => std::future::pending().await,
            }
        };
        tokio::pin!(until);
        let mut schedule = Schedule::every(self.every_ms);
        let mut rounds = 0u64;
        loop {
            tokio::select! {
                _ = &mut ctx.stop => break,
                _ = &mut until => break,
                _ = schedule.next() => {}
            };
            let t_s = bus.now_ns().saturating_sub(start_ns) as f64 / 1e9;
            let targets = targets_of(&objects, ctx.bindings);
            let samples = tokio::select! {
                _ = &mut ctx.stop => break,
                _ = &mut until => break,
                s = round(bus, &targets, self.timeout_ms) => s,
            };
            rounds += 1;
            for (o, s) in objects.iter_mut().zip(&samples) {
                o.take(ctx.bindings.dictionary(o.node), s);
            }
            match self.format {
                WatchFormat::Csv => say(&csv_row(t_s, &objects, &samples)),
                WatchFormat::Jsonl => jsonl_rows(t_s, &objects, &samples).iter().for_each(|l| say(l)),
                WatchFormat::Text => say(&text_table(t_s, &objects, &samples)),
            }
            if objects.iter().all(|o| o.absent) {
                break;
            }
        }
        let report = WatchReport {
            ok: true,
            every_ms: self.every_ms,
            rounds,
            skipped: schedule.skipped,
            objects,
        };
        // Machine-readable rows are the output; the summary is for text (and --json).
        let text = if self.format == WatchFormat::Text {
            report.text()
        } else {
            String::new()
        };
        Ok(Outcome::new(report, text))
    }

    fn cyclic(&self) -> bool {
        true
    }

    /// The objects are resolved before the bus is opened.
    fn answers_offline(&self) -> bool {
        true
    }

    fn offline(&self, bindings: &Bindings) -> Option<Result<Outcome, CommandError>> {
        self.resolve(bindings).err().map(Err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(w: &[&str]) -> Vec<String> {
        w.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn nodes_and_their_objects() {
        assert_eq!(
            targets(&words(&["2", "0x6041", "Statusword", "3", "0x6064"])).unwrap(),
            [(2, "0x6041".into()), (2, "Statusword".into()), (3, "0x6064".into())]
        );
        assert!(
            targets(&words(&["0x6041"]))
                .unwrap_err()
                .to_string()
                .contains("node first")
        );
        assert!(
            targets(&words(&["2", "3", "0x6041"]))
                .unwrap_err()
                .to_string()
                .contains("node 2")
        );
        assert!(
            targets(&words(&["2", "0x6041", "3"]))
                .unwrap_err()
                .to_string()
                .contains("node 3")
        );
        assert!(targets(&words(&["200", "0x6041"])).is_err());
    }
}
