//! A command's data (a domain read, a DCF saved) to its file or stdout.

use super::error::CommandError;

/// Writes a command's data to `path`; `-` is stdout (the command's report then goes to
/// stderr, see [`super::spec::Spec::data_to_stdout`]).
pub(crate) fn write_output(path: &str, data: &[u8]) -> Result<(), CommandError> {
    use std::io::Write;
    let written = if path == "-" {
        let mut out = std::io::stdout().lock();
        out.write_all(data).and_then(|()| out.flush())
    } else {
        std::fs::write(path, data)
    };
    written.map_err(|e| {
        let path = if path == "-" { "stdout" } else { path };
        CommandError::Usage(format!("cannot write {path}: {e}"))
    })
}
