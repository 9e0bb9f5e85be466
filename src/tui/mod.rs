//! The interactive analyzer: trace store, panes, keymaps and the terminal loop.
//!
//! Frames come from one capture task per source ([`source`]) in batches; the UI thread
//! puts them in the [`trace::Trace`] under a time budget, scans filters in the background,
//! and redraws at most 30 times a second and only when something changed.

pub mod app;
pub mod export;
pub mod filter;
pub mod keymap;
pub mod live;
pub mod messages;
pub mod nodes;
pub mod palette;
pub mod panes;
pub mod prompt;
pub mod rows;
pub mod series;
pub mod source;
pub mod stats;
pub mod store;
pub mod term;
pub mod trace;
pub mod ui;
pub mod view;
