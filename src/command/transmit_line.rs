//! A transmit list entry typed on one line, as the Transmit pane's prompt takes it besides
//! the JSON of the file: `601#4041600000000000 every 100ms`, `rpdo1 2 Controlword=0x0F
//! Target velocity=500 every 10ms count 50 off # a comment`. Pure: the line in, the entry's
//! JSON text (as the file holds it) out, or why not.

use serde_json::{Map, Value, json};

/// The entry's JSON text of `line`: a JSON object as it is, else the words. `every DUR`,
/// `count N`, `off` (disabled) and `# comment` may follow a frame or an RPDO's signals;
/// a signal's name may hold spaces (`Target velocity=500`).
pub fn entry_json(line: &str) -> Result<String, String> {
    let line = line.trim();
    if line.starts_with('{') {
        return Ok(line.to_string());
    }
    // A `#` after a space starts the comment (a frame's own `#` follows its identifier).
    let (words, comment) = match line.find(" #") {
        Some(i) => (&line[..i], Some(line[i + 2..].trim())),
        None => (line, None),
    };
    let mut it = words.split_whitespace().peekable();
    let first = it
        .next()
        .ok_or("type a frame (601#4041600000000000) or an RPDO (rpdo1 NODE NAME=VALUE...)")?;
    let mut entry = Map::new();
    if first.to_ascii_lowercase().starts_with("rpdo") {
        entry.insert("rpdo".into(), json!(first));
        let node = it
            .next()
            .ok_or(format!("`{first}` needs a NODE, then NAME=VALUE signals"))?;
        let node: u8 = node
            .parse()
            .map_err(|_| format!("`{node}` is not a node-ID (1..127) after `{first}`"))?;
        entry.insert("node".into(), json!(node));
        let mut signals = Map::new();
        let mut name: Vec<&str> = Vec::new();
        while let Some(w) = it.peek().copied() {
            if name.is_empty() && matches!(w, "every" | "count" | "off") {
                break;
            }
            it.next();
            match w.split_once('=') {
                Some((tail, value)) => {
                    name.push(tail);
                    let full = name.join(" ");
                    if full.is_empty() || value.is_empty() {
                        return Err(format!("`{full}={value}`: give NAME=VALUE"));
                    }
                    signals.insert(full, json!(value));
                    name.clear();
                }
                None => name.push(w),
            }
        }
        if !name.is_empty() {
            return Err(format!("`{}`: give NAME=VALUE", name.join(" ")));
        }
        entry.insert("signals".into(), Value::Object(signals));
    } else {
        entry.insert("frame".into(), json!(first));
    }
    while let Some(w) = it.next() {
        match w {
            "every" => {
                let d = it.next().ok_or("`every` needs a period (100ms, 1s)")?;
                entry.insert("every_ms".into(), json!(d));
            }
            "count" => {
                let n = it.next().ok_or("`count` needs a number")?;
                let n: u64 = n.parse().map_err(|_| format!("count `{n}` is not a number"))?;
                entry.insert("count".into(), json!(n));
            }
            "off" => {
                entry.insert("enabled".into(), json!(false));
            }
            other => {
                return Err(format!(
                    "`{other}`: after the frame come every DUR, count N, off and # comment"
                ));
            }
        }
    }
    if let Some(c) = comment.filter(|c| !c.is_empty()) {
        entry.insert("comment".into(), json!(c));
    }
    Ok(Value::Object(entry).to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_or_an_rpdo_by_its_signals_on_one_line() {
        assert_eq!(
            entry_json("601#4041600000000000 every 100ms # poll the statusword").unwrap(),
            r#"{"comment":"poll the statusword","every_ms":"100ms","frame":"601#4041600000000000"}"#
        );
        assert_eq!(
            entry_json("rpdo1 2 Controlword=0x0F Target velocity=500 every 10ms count 50 off").unwrap(),
            r#"{"count":50,"enabled":false,"every_ms":"10ms","node":2,"rpdo":"rpdo1","signals":{"Controlword":"0x0F","Target velocity":"500"}}"#
        );
        assert_eq!(entry_json("000#0100").unwrap(), r#"{"frame":"000#0100"}"#);
        let json = r#"{"frame": "123#01", "every_ms": 100}"#;
        assert_eq!(entry_json(json).unwrap(), json);
    }

    #[test]
    fn what_is_missing_is_said() {
        assert!(entry_json("").unwrap_err().starts_with("type a frame"));
        assert_eq!(
            entry_json("rpdo1").unwrap_err(),
            "`rpdo1` needs a NODE, then NAME=VALUE signals"
        );
        assert_eq!(
            entry_json("rpdo1 x A=1").unwrap_err(),
            "`x` is not a node-ID (1..127) after `rpdo1`"
        );
        assert_eq!(
            entry_json("rpdo1 2 Target velocity").unwrap_err(),
            "`Target velocity`: give NAME=VALUE"
        );
        assert_eq!(
            entry_json("123#01 every").unwrap_err(),
            "`every` needs a period (100ms, 1s)"
        );
        assert!(
            entry_json("123#01 soon")
                .unwrap_err()
                .starts_with("`soon`: after the frame")
        );
    }
}
