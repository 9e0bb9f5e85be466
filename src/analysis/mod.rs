//! Analyses over the decoded stream that span many frames, usable without a terminal:
//! the trace store and its filtered views, the node table, statistics and plot series
//! (what the TUI panes show), node liveness, the bus events derived from it, and the
//! incidents a diagnosis makes of them. Pure like the decoders:
//! frames and their timestamps in, typed events and incidents out; time only advances
//! through frame timestamps and explicit ticks.

pub mod boot_story;
pub mod diagnose;
pub mod duration;
pub mod events;
pub mod filter;
pub mod incident;
pub mod liveness;
pub mod nodes;
pub mod pdos;
pub mod producers;
pub mod search;
pub mod series;
pub mod stats;
pub mod store;
pub mod sync_cycles;
pub mod timing;
pub mod trace;
pub mod transfer_list;
pub mod transfers;
pub mod trigger;
pub mod values;
pub mod view;

pub use diagnose::Diagnoser;
pub use events::{Event, PeriodSource, What};
pub use incident::{Incident, Problem, Status};
pub use liveness::{EventTracker, NodeLiveness};
