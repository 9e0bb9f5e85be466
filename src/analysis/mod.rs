//! Analyses over the decoded stream that span many frames: node liveness, the bus events
//! derived from it, and the incidents a diagnosis makes of them. Pure like the decoders:
//! frames and their timestamps in, typed events and incidents out; time only advances
//! through frame timestamps and explicit ticks.

pub mod diagnose;
pub mod events;
pub mod incident;
pub mod liveness;
mod texts;

pub use diagnose::Diagnoser;
pub use events::{Event, PeriodSource, What};
pub use incident::{Incident, Problem, Status};
pub use liveness::{EventTracker, NodeLiveness};
