//! Analyses over the decoded stream that span many frames: node liveness and the bus
//! events derived from it. Pure like the decoders: frames and their timestamps in, typed
//! events out; time only advances through frame timestamps and explicit ticks.

pub mod events;
pub mod liveness;

pub use events::{Event, PeriodSource, What};
pub use liveness::{EventTracker, NodeLiveness};
