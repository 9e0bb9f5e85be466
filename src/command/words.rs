//! The words of the commander's commands: what a palette line has in front of a command
//! ([`Session`]: nothing) or the command line has (its bus options), [`On`] joining them to a
//! command's own words, and the value parsers the declarations share (nodes, ms, frames,
//! PDOs, COB-IDs, words with completion). Each command declares its words in its own
//! module; `super::registry` lists them.

use super::cyclic::Schedule;
pub use super::error::ParseError;
pub(crate) use super::grammar::parse_type;
use super::grammar::{parse_int, parse_node};
use super::spec::{CommandArgs, Declared};
use crate::decode::pdo_config::PdoId;
use crate::frame::Frame;
use clap::Args;
use clap::builder::{PossibleValue, TypedValueParser};

/// Nothing: what a palette line has where the command line has its bus options (IFACE,
/// `--listen-only`, `--json`) and dictionary options (`--profile`, `--eds`). The palette
/// runs on the session's bus with the session's dictionaries.
#[derive(Args, Clone, Debug, Default, PartialEq, Eq)]
#[group(skip)]
pub struct Session {}

/// A command's own arguments `A` after the options `B` every command takes where it is
/// parsed (the command line's IFACE and flags; nothing in the palette).
#[derive(Args, Clone, Debug)]
#[group(skip)]
pub struct On<B: Args, A: Args> {
    #[command(flatten)]
    pub bus: B,
    #[command(flatten)]
    pub args: A,
}

/// Parses a 32-bit number (decimal or 0x hex).
pub(crate) fn u32_arg(text: &str) -> Result<u32, ParseError> {
    parse_int(text)
        .filter(|v| (0..=i64::from(u32::MAX)).contains(v))
        .map(|v| v as u32)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a number 0..0xFFFFFFFF")))
}

/// How often `send`, `sync` and `pdo` send.
#[derive(Args, Clone, Debug)]
pub struct Repeat {
    /// Send every DUR (`100`: ms, or `500ms`, `1s`) until stopped: Ctrl-C, or stop-all /
    /// `jobs stop ID` in the TUI.
    #[arg(long, value_parser = ms_arg)]
    pub every: Option<u64>,
    /// Send this many frames (with --every: then stop).
    #[arg(long, value_parser = count_arg)]
    pub count: Option<u64>,
}

impl Repeat {
    pub(crate) fn schedule(&self) -> Schedule {
        Schedule {
            every_ms: self.every,
            count: self.count,
        }
    }
}

/// A command's words after the options in front.
impl<B: Args, D, A: CommandArgs<D>> Declared<B, D> for On<B, A> {
    type Spec = A::Spec;

    fn bus(&self) -> &B {
        &self.bus
    }

    fn dict(&self) -> Option<&D> {
        self.args.dict()
    }

    fn name(&self) -> &'static str {
        A::NAME
    }

    fn spec(&self) -> Result<A::Spec, ParseError> {
        self.args.spec()
    }
}

/// A value parser that checks a word with `parse` and offers `words` for help and completion.
#[derive(Clone)]
pub(crate) struct TypedWords<T> {
    words: &'static [&'static str],
    parse: fn(&str) -> Result<T, ParseError>,
}

impl<T> TypedWords<T> {
    pub(crate) fn new(words: &'static [&'static str], parse: fn(&str) -> Result<T, ParseError>) -> TypedWords<T> {
        TypedWords { words, parse }
    }
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for TypedWords<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        self.parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.words.iter().map(|w| PossibleValue::new(*w))))
    }
}

pub(crate) const NMT_WORDS: &[&str] = &["start", "stop", "preop", "reset-node", "reset-comm"];
pub(crate) const DRIVE_WORDS: &[&str] = &["enable", "disable", "quick-stop", "fault-reset", "status", "mode"];
pub(crate) const TYPE_WORDS: &[&str] = &[
    "u8", "u16", "u32", "u64", "i8", "i16", "i32", "i64", "f32", "f64", "bool", "string", "octets", "domain",
];

/// Parses NODE 1..127 (decimal or 0x hex).
pub fn node_arg(text: &str) -> Result<u8, ParseError> {
    parse_node(text, false)
}

/// Parses NODE allowing 0 (all nodes).
pub fn node_or_all_arg(text: &str) -> Result<u8, ParseError> {
    parse_node(text, true)
}

/// Parses a positive duration, in ms: a bare number is ms (decimal or 0x hex, as always);
/// with a unit, `500ms`, `30s`, `1.5s`, `2min`, `1h` (decimals allowed, rounded to the ms).
pub fn ms_arg(text: &str) -> Result<u64, ParseError> {
    crate::analysis::duration::ms(text, 1.0)
        .filter(|v| *v > 0)
        .ok_or_else(|| ParseError::Invalid(duration_error(text, "ms")))
}

/// Parses a duration of 0 or more ms (0: off), as [`ms_arg`].
pub fn ms_or_zero_arg(text: &str) -> Result<u64, ParseError> {
    crate::analysis::duration::ms(text, 1.0).ok_or_else(|| ParseError::Invalid(duration_error(text, "ms")))
}

/// Parses a positive duration where a bare number is seconds (`diagnose --duration`,
/// seconds since before units), in ms: `30`, `0.5`, `500ms`, `2min`.
pub fn seconds_arg(text: &str) -> Result<u64, ParseError> {
    crate::analysis::duration::ms(text, 1e3)
        .filter(|v| *v > 0)
        .ok_or_else(|| ParseError::Invalid(duration_error(text, "seconds")))
}

fn duration_error(text: &str, bare: &str) -> String {
    format!(
        "`{text}` is not a duration above 0: a number of {bare}, or a number with a unit (500ms, 30s, 1.5s, 2min, 1h)"
    )
}

/// Parses a frame in candump's compact form with the log reader's parser.
///
/// Blanks around the frame (a quoting artifact) are ignored; a `0x` before the id is
/// refused with the cansend form to write instead (cansend's grammar is hex already); an FD
/// flags digit must be 0..7 (1 BRS, 2 ESI, 4 FDF: bit 3 is no flag, and would be dropped).
pub(crate) fn frame_arg(text: &str) -> Result<Frame, ParseError> {
    let text = text.trim();
    if let Some(rest) = text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        return Err(ParseError::Invalid(format!(
            "`{text}`: the CAN id is hex without 0x, as cansend takes it: `{rest}`"
        )));
    }
    if let Some((_, after)) = text.split_once("##")
        && let Some(digit) = after.chars().next()
        && digit.to_digit(16).is_some_and(|d| d > 7)
    {
        return Err(ParseError::Invalid(format!(
            "`{text}`: CAN FD flags digit `{digit}` is not 0..7 (1 = bit rate switch, 2 = error state \
             indicator, 4 = FD format; add them): e.g. `##1` for BRS"
        )));
    }
    match crate::log::candump::parse_compact(text.as_bytes()) {
        Ok(Some(f)) => Ok(f),
        Ok(None) => Err(ParseError::Invalid(format!("`{text}`: CAN XL frames cannot be sent"))),
        Err(e) => Err(ParseError::Invalid(format!(
            "`{text}` is not a frame ({e}); write ID#DATA, e.g. 601#4041600000000000, 123#R, 12345678#00"
        ))),
    }
}

/// The `pdo` action word: `send` (an RPDO; TPDOs are the nodes' to send) or `map`.
pub(crate) fn pdo_word(word: &str) -> Result<String, ParseError> {
    match word {
        "send" | "map" => Ok(word.to_string()),
        _ => Err(ParseError::Invalid(format!(
            "unknown pdo command `{word}`: use send or map (or nothing, to read the PDOs)"
        ))),
    }
}

/// Parses `rpdo1`..`rpdo512`, `tpdo1`..`tpdo512`.
pub(crate) fn pdo_arg(text: &str) -> Result<PdoId, ParseError> {
    let lower = text.to_ascii_lowercase();
    let (transmit, n) = match (lower.strip_prefix("rpdo"), lower.strip_prefix("tpdo")) {
        (Some(n), _) => (false, n),
        (_, Some(n)) => (true, n),
        _ => (false, ""),
    };
    n.parse::<u16>()
        .ok()
        .filter(|n| (1..=512).contains(n))
        .map(|num| PdoId { transmit, num })
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` is not a PDO: use rpdo1, tpdo1, ... (1..512)")))
}

/// Parses a transmission type: a number 0..255 or its word.
pub(crate) fn transmission_arg(text: &str) -> Result<u8, ParseError> {
    let t = text.to_ascii_lowercase();
    let bad = || {
        ParseError::Invalid(format!(
            "`{text}` is not a transmission type: use acyclic, sync, sync:N (1..240), rtr-sync, rtr, event-mfr, \
             event or a number 0..255"
        ))
    };
    Ok(match t.as_str() {
        "acyclic" => 0,
        "sync" => 1,
        "rtr-sync" => 252,
        "rtr" => 253,
        "event-mfr" => 254,
        "event" => 255,
        _ => match t.strip_prefix("sync:") {
            Some(n) => parse_int(n).filter(|n| (1..=240).contains(n)).ok_or_else(bad)? as u8,
            None => parse_int(&t).filter(|n| (0..=255).contains(n)).ok_or_else(bad)? as u8,
        },
    })
}

/// Parses a 16-bit number (ms of an event timer).
pub(crate) fn u16_arg(text: &str) -> Result<u16, ParseError> {
    parse_int(text)
        .filter(|v| (0..=0xFFFF).contains(v))
        .map(|v| v as u16)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a number 0..65535")))
}

/// Parses an inhibit time: 100 us units, or `2.5ms` / `500us`.
pub(crate) fn inhibit_arg(text: &str) -> Result<u16, ParseError> {
    let t = text.trim().to_ascii_lowercase();
    let units = if let Some(ms) = t.strip_suffix("ms") {
        ms.trim().parse::<f64>().ok().map(|v| v * 10.0)
    } else if let Some(us) = t.strip_suffix("us") {
        us.trim().parse::<f64>().ok().map(|v| v / 100.0)
    } else {
        parse_int(&t).map(|v| v as f64)
    };
    units
        .filter(|u| (0.0..=65535.0).contains(u) && u.fract() == 0.0)
        .map(|u| u as u16)
        .ok_or_else(|| {
            ParseError::Invalid(format!(
                "`{text}`: the inhibit time is 0..65535 units of 100 us (`25`), or `2.5ms`, `500us` (multiples of 0.1 ms)"
            ))
        })
}

/// Parses a PDO COB-ID: 11-bit, or 29-bit above 0x7FF.
pub(crate) fn pdo_cob_arg(text: &str) -> Result<u32, ParseError> {
    parse_int(text)
        .filter(|v| (1..=0x1FFF_FFFF).contains(v))
        .map(|v| v as u32)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a COB-ID 0x001..0x1FFFFFFF")))
}

/// Refuses a COB-ID another service owns ([`crate::decode::cob_id::reserved_for`]) for `user`.
pub(crate) fn not_reserved(id: u32, user: &str) -> Result<(), ParseError> {
    match crate::decode::cob_id::reserved_for(id) {
        Some(owner) => Err(ParseError::Invalid(format!(
            "--cob-id 0x{id:03X} is {owner}: {user} would collide with it; nothing sent (--force uses it anyway)"
        ))),
        None => Ok(()),
    }
}

/// Parses the SYNC counter's overflow value 2..=240.
pub(crate) fn counter_arg(text: &str) -> Result<u8, ParseError> {
    parse_int(text)
        .filter(|v| (2..=240).contains(v))
        .map(|v| v as u8)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}`: the SYNC counter counts to 2..240")))
}

/// Parses an 11-bit COB-ID.
pub(crate) fn cob_arg(text: &str) -> Result<u32, ParseError> {
    parse_int(text)
        .filter(|v| (1..=0x7FF).contains(v))
        .map(|v| v as u32)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be an 11-bit COB-ID 0x001..0x7FF")))
}

/// Parses a positive count.
pub(crate) fn count_arg(text: &str) -> Result<u64, ParseError> {
    parse_int(text)
        .filter(|v| *v > 0)
        .map(|v| v as u64)
        .ok_or_else(|| ParseError::Invalid(format!("`{text}` must be a positive number")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_take_a_unit_and_a_bare_number_is_ms() {
        let ok = |t: &str| ms_arg(t).unwrap();
        assert_eq!(
            [
                ok("250"),
                ok("0x10"),
                ok("500ms"),
                ok("30s"),
                ok("1.5s"),
                ok("2min"),
                ok("1h"),
                ok(" 2s ")
            ],
            [250, 16, 500, 30_000, 1_500, 120_000, 3_600_000, 2_000]
        );
        assert_eq!(seconds_arg("30").unwrap(), 30_000);
        assert_eq!(seconds_arg("0.5").unwrap(), 500);
        assert_eq!(seconds_arg("250ms").unwrap(), 250);
        assert_eq!(ms_or_zero_arg("0").unwrap(), 0);
        for bad in ["0", "0s", "-5", "5x", "1.5", "s", "", "2 mins", "1e3ms"] {
            let e = ms_arg(bad).unwrap_err().to_string();
            assert!(e.contains("500ms, 30s, 1.5s, 2min, 1h"), "{bad}: {e}");
        }
    }

    /// Through clap (the command line and the palette), the error names the flag and its value.
    #[test]
    fn a_bad_duration_names_the_flag() {
        #[derive(clap::Parser, Debug)]
        struct T {
            #[arg(long, value_parser = ms_arg)]
            every: u64,
        }
        use clap::Parser;
        assert_eq!(T::try_parse_from(["t", "--every", "2min"]).unwrap().every, 120_000);
        let e = T::try_parse_from(["t", "--every", "2mn"]).unwrap_err().to_string();
        assert!(e.contains("'2mn' for '--every <EVERY>'"), "{e}");
        assert!(e.contains("with a unit (500ms"), "{e}");
    }
}
