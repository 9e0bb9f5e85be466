//! The interactive analyzer: panes, palette, keymaps and the terminal loop.
//!
//! Frames come from one capture task per source ([`source`]) in batches; the UI thread
//! puts them in the [`crate::analysis::trace::Trace`] under a time budget, scans filters in the background,
//! and redraws at most 30 times a second and only when something changed.

pub mod app;
pub mod bookmarks;
pub mod capture;
pub mod commands;
mod event;
pub mod expect;
pub mod export;
mod export_plot;
mod frame_feed;
pub mod fuzzy;
pub mod hosted;
pub mod keymap;
pub mod live;
pub mod messages;
pub mod palette;
pub mod panes;
pub mod prompt;
mod read_all;
pub mod record;
pub mod rows;
pub mod screen;
pub mod source;
mod stop;
pub mod term;
mod transmit;
pub mod trigger;
pub mod ui;
mod watch;
pub mod watch_board;
mod watch_run;
