//! Runs the real `cotui` binary, as the CLI tests of this binary do.

use std::process::Command;

/// Runs `cotui ARGS`; gives (exit status, stdout, stderr). A status of -1: killed by a signal.
pub fn cotui(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cotui")).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

/// [`cotui`] with stdout parsed as one JSON value (`Null` when it is not JSON).
pub fn cotui_json(args: &[&str]) -> (i32, serde_json::Value, String) {
    let (code, stdout, stderr) = cotui(args);
    let json = serde_json::from_str(stdout.trim()).unwrap_or(serde_json::Value::Null);
    (code, json, stderr)
}
