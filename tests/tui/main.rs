//! The interactive analyzer end to end: the real binary in tmux, and its command line.

mod filter_search;
mod problems;
mod tui_cli;
mod tui_tmux;
