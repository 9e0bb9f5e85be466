//! Values shown for people: labels of decoded values, EMCY manufacturer fields, and
//! which writes are no configuration.

use super::dictionary::Dictionary;
use super::number::format_number;
use super::object::ObjectInfo;
use super::value::Value;

/// Why writing an object is no configuration, whatever a DCF says: commands (store and
/// restore, program control, clearing the error history, the CiA 402 controlword) and the
/// CiA 402 set-points that move a motor (target position, velocity, torque). None: it may
/// be configuration.
pub fn not_configuration(index: u16) -> Option<&'static str> {
    match index {
        0x1010 => Some("store command (use --store)"),
        0x1011 => Some("restore-defaults command"),
        0x1003 => Some("error history (writing clears it)"),
        0x1F50..=0x1F57 => Some("program download/control"),
        0x6040 => Some("controlword (a command, not configuration)"),
        0x6042 | 0x6071 | 0x607A | 0x60C1 | 0x60FF => Some("set-point (moves the motor), not configuration"),
        _ => None,
    }
}

/// Formats a decoded value for a label: enum text, scaled value with unit, or the raw value.
///
/// `0x0006` of a U16 with values {6: "Shutdown"} -> `6 (Shutdown)`;
/// `15000` of an I32 with scale 0.1 and unit "rpm" -> `1500 rpm`.
pub fn format_value(info: Option<&ObjectInfo>, value: &Value) -> String {
    let Some(info) = info else { return value.to_string() };
    if let Some(raw) = value.as_i64()
        && let Some(text) = info.values.get(&raw)
    {
        return format!("{raw} ({text})");
    }
    match (value.as_f64(), info.scale, &info.unit) {
        (Some(x), scale, unit) if scale.is_some() || unit.is_some() => {
            let scaled = x * scale.unwrap_or(1.0);
            let mut s = format_number(scaled);
            if let Some(u) = unit {
                s.push(' ');
                s.push_str(u);
            }
            s
        }
        _ => value.to_string(),
    }
}

/// The EMCY manufacturer fields of an 8-byte frame through the node's layout,
/// as (name, shown value) pairs; empty when no profile describes them.
pub fn emcy_fields(dict: &Dictionary, frame: &[u8; 8]) -> Vec<(String, String)> {
    dict.emcy_fields()
        .iter()
        .filter_map(|f| f.raw(frame).map(|raw| (f.name.clone(), f.format(raw))))
        .collect()
}
