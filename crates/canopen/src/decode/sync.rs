//! SYNC (0x080 by default): with or without the CiA 301 counter byte.

use serde::Serialize;

/// A SYNC frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sync {
    /// Counter 1..=240 when the producer uses one (0x1019 > 1).
    pub counter: Option<u8>,
}

impl Sync {
    /// One-line label.
    pub fn label(&self) -> String {
        match self.counter {
            Some(c) => format!("SYNC counter {c}"),
            None => "SYNC".into(),
        }
    }
    /// The kind-specific JSON object.
    pub fn to_json(&self) -> SyncJson {
        SyncJson { counter: self.counter }
    }
}

/// The `sync` object of a JSONL frame record.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SyncJson {
    /// `null` when the producer sends no counter.
    pub counter: Option<u8>,
}

/// Decodes a SYNC payload; the second value explains a rule broken.
pub fn decode(payload: &[u8]) -> (Sync, Option<String>) {
    let sync = Sync {
        counter: payload.first().copied(),
    };
    let problem = match (payload.len(), sync.counter) {
        (0, _) => None,
        (1, Some(1..=240)) => None,
        (1, Some(c)) => Some(format!("SYNC counter {c} outside 1..240")),
        (n, _) => Some(format!("SYNC frame has {n} data bytes, expected 0 or 1")),
    };
    (sync, problem)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn with_and_without_counter() {
        assert_eq!(decode(&[]).0.label(), "SYNC");
        assert_eq!(
            serde_json::to_value(decode(&[]).0.to_json()).unwrap(),
            json!({"counter": null})
        );
        assert_eq!(decode(&[12]).0.label(), "SYNC counter 12");
        assert_eq!(decode(&[12]).1, None);
        assert!(decode(&[0]).1.unwrap().contains("outside"));
        assert!(decode(&[1, 2]).1.unwrap().contains("2 data bytes"));
    }
}
