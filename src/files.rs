//! Reading the files a user names (profiles, EDS/DCF, keymaps) at the edge, with a size cap
//! so that a wrong path (`/dev/zero`, a capture) fails at once instead of filling memory.

use std::io::Read;
use std::path::Path;

/// The largest profile, EDS/DCF or keymap file read (the largest real EDS files are a few MB).
pub const MAX_FILE: u64 = 64 << 20;

/// The largest domain value an SDO write reads from a file (`sdo write ... --type domain`):
/// 16 MiB, the most the SDO client takes in an upload too.
pub const MAX_DOMAIN: u64 = 16 << 20;

/// Reads a file, refusing one larger than [`MAX_FILE`] (or endless, like `/dev/zero`).
pub fn read_capped(path: &Path) -> std::io::Result<Vec<u8>> {
    read_at_most(path, MAX_FILE, "not a dictionary file")
}

/// Reads a file, refusing one larger than `cap` bytes (or endless) with "larger than N
/// MiB, `why`".
pub fn read_at_most(path: &Path, cap: u64, why: &str) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.take(cap + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > cap {
        return Err(std::io::Error::other(format!("larger than {} MiB, {why}", cap >> 20)));
    }
    Ok(bytes)
}
