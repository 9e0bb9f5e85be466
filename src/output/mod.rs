//! Headless renderings of decoded frames: text lines, JSON lines, SDO
//! transactions and summaries. Pure formatting into strings; the caller writes.

pub mod jsonl;
pub mod summary;
pub mod text;
