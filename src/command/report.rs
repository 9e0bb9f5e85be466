//! A command's typed report, kept as its `#[derive(Serialize)]` type until written: in an
//! `Outcome`, or in the failure that carries one (`CommandError::Step`, `NotStopped`,
//! `Report`).

use std::fmt;
use std::sync::Arc;

/// A command's `--json` report: a `#[derive(Serialize)]` type, made JSON when it is written.
pub trait Report: Send + Sync {
    /// The JSON object written (keys sorted, as `--json` prints them).
    fn to_json(&self) -> serde_json::Value;
}

impl<T: serde::Serialize + Send + Sync> Report for T {
    fn to_json(&self) -> serde_json::Value {
        // Serializing these plain structs cannot fail; a failure would give null.
        serde_json::to_value(self).unwrap_or_default()
    }
}

/// A typed report, shared (an [`Outcome`], or the report a failure carries).
#[derive(Clone)]
pub struct Reported(Arc<dyn Report>);

impl Reported {
    /// Keeps `report` as it is until written.
    pub fn new(report: impl Report + 'static) -> Reported {
        Reported(Arc::new(report))
    }

    /// The JSON object written.
    pub fn to_json(&self) -> serde_json::Value {
        self.0.to_json()
    }
}

/// Shown as the JSON it writes.
impl fmt::Debug for Reported {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.to_json())
    }
}

/// Two reports are equal when they write the same JSON.
impl PartialEq for Reported {
    fn eq(&self, other: &Self) -> bool {
        self.to_json() == other.to_json()
    }
}

impl serde::Serialize for Reported {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(s)
    }
}

/// A command's `--json` object from its `#[derive(Serialize)]` form (serializing these plain
/// structs cannot fail; a failure would give null).
pub(crate) fn to_json(v: &impl serde::Serialize) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or_default()
}
