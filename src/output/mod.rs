//! Headless renderings of decoded frames: text lines, JSON lines, SDO
//! transactions and summaries, and pcapng capture files. Pure formatting; the caller writes.

pub mod jsonl;
pub mod pcapng;
pub mod summary;
pub mod text;
