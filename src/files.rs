//! Reading the files a user names (profiles, EDS/DCF, keymaps) at the edge, with a size cap
//! so that a wrong path (`/dev/zero`, a capture) fails at once instead of filling memory.

use std::io::Read;
use std::path::Path;

/// The largest profile, EDS/DCF or keymap file read (the largest real EDS files are a few MB).
pub const MAX_FILE: u64 = 64 << 20;

/// Reads a file, refusing one larger than [`MAX_FILE`] (or endless, like `/dev/zero`).
pub fn read_capped(path: &Path) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.take(MAX_FILE + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE {
        return Err(std::io::Error::other(format!(
            "larger than {} MiB, not a dictionary file",
            MAX_FILE >> 20
        )));
    }
    Ok(bytes)
}
